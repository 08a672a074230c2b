"""The documentation site (mkdocs.yml, docs/) builds in strict mode: a broken link, a
missing #anchor or an API reference to a name that no longer exists fails the suite.
The API page is read from the source by mkdocstrings (griffe, statically: nothing of
loopsim is imported).

What a strict build does not catch is read from the Markdown itself: a table row whose
cells do not match its header, a list that Python-Markdown reads as paragraph text, a
page over 400 lines, internal work items or dates on a page, a fact stated on more than
one page, and a grid under another grid's name."""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def test_docs_build_strict(tmp_path):
    site = tmp_path / "site"
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")  # Material's notice about its end of life
    run = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert (site / "index.html").is_file()
    api = site / "api" / "index.html"
    assert api.is_file()
    html = api.read_text(encoding="utf-8")
    assert "simulate" in html
    assert not sphinx_roles(html), sphinx_roles(html)
    internal = [name for name in api_objects(html) if not api_object_is_public(name)]
    assert not internal, internal


#: A Sphinx role as MkDocs renders it: literally (mkdocstrings reads Markdown, not reST).
SPHINX_ROLE = re.compile(r":(?:func|class|meth|data|mod|attr|exc|obj|py:\w+):(?:<code>|`)")
#: What the API page documents besides loopsim.__all__ and SimulationResult's members:
#: the modules whose docstrings define the results' terms (their functions are internal),
#: the thresholds a result carries, and the stop table of --seeds auto.
API_EXTRAS = ("loopsim.seeds_auto_rule", "loopsim.outcomes", "loopsim.outcomes.Thresholds",
              "loopsim.columns", "loopsim.refinement", "loopsim.storage.read_stop_table",
              "loopsim.survival.settling_statistics",
              "loopsim.stability.rest_window.rest_window",
              "loopsim.stability.rest_window.stability_losses")


def sphinx_roles(html):
    return SPHINX_ROLE.findall(html)


def api_objects(html):
    """The objects of a built API page (mkdocstrings' headings), by full name."""
    return re.findall(r'<h\d id="([^"]+)" class="doc doc-heading"', html)


def api_object_is_public(name):
    import loopsim

    return (name.rsplit(".", 1)[-1] in loopsim.__all__ or name in API_EXTRAS
            or name.startswith("loopsim.result.SimulationResult."))


def test_the_api_page_checks_catch_what_they_are_for():
    """As the page rendered: a role in a docstring, and a module's internal functions."""
    assert sphinx_roles("<p>see :func:<code>simulate</code>, :data:`SAME`.</p>") == [
        ":func:<code>", ":data:`"]
    html = ('<h2 id="loopsim.api.simulate" class="doc doc-heading">'
            '<h3 id="loopsim.seeds_auto_rule.widths" class="doc doc-heading">'
            '<h3 id="loopsim.result.SimulationResult.summary" class="doc doc-heading">')
    assert [n for n in api_objects(html) if not api_object_is_public(n)] == [
        "loopsim.seeds_auto_rule.widths"]


# ---------------------------------------------------------------------------------
# The pages' Markdown, read as text: what MkDocs (Python-Markdown) would render wrongly
# without failing the build, and the rules that keep the reference a reference.

DOCS = os.path.join(ROOT, "docs")
MAX_LINES = 400
LIST_ITEM = re.compile(r"^\s*(?:[*+-]|\d+[.)])\s+\S")
TABLE_RULE = re.compile(r"^\s*\|?\s*:?-{3,}:?\s*(?:\|\s*:?-{3,}:?\s*)*\|?\s*$")


def pages():
    """Every Markdown page under docs/ (the study reports of docs/studies/ included), by
    its path relative to docs/."""
    return sorted(os.path.relpath(os.path.join(folder, name), DOCS)
                  for folder, _, names in os.walk(DOCS) for name in names if name.endswith(".md"))


def page_text(name):
    with open(os.path.join(DOCS, name), encoding="utf-8") as handle:
        return handle.read()


def prose_lines(text):
    """(line number, line) outside fenced code blocks; fenced lines come back as None, so
    that a fence still separates the blocks around it."""
    fenced = False
    for number, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("```"):
            fenced = not fenced
            yield number, None
        else:
            yield number, None if fenced else line


def cells(row):
    """The cells of a table row: split at every `|` but an escaped one (`\\|`, text).
    Python-Markdown would keep a `|` inside backticks as text, GitHub would not: a
    row must read the same on both, so a code span does not protect its `|`."""
    row = row.strip().replace("\\|", "")
    if row.startswith("|"):
        row = row[1:]
    if row.endswith("|"):
        row = row[:-1]
    return row.split("|")


def table_errors(text):
    """Table rows whose number of cells differs from their header's."""
    errors, lines = [], list(prose_lines(text))
    for (number, line), (_, rule) in zip(lines, lines[1:]):
        if line is None or rule is None or "|" not in line or not TABLE_RULE.match(rule):
            continue
        width = len(cells(line))
        for row_number, row in lines[number + 1:]:
            if row is None or not row.strip() or "|" not in row:
                break
            if len(cells(row)) != width:
                errors.append(f"line {row_number}: {len(cells(row))} cells, header {width}")
    return errors


def unrendered_lists(text):
    """List items that Python-Markdown reads as the paragraph above them continued (a
    list must follow a blank line, a heading or another list item; GitHub renders it
    either way, MkDocs does not), and paragraph lines read into the list item above
    them (a list item's continuation lines are indented)."""
    errors, state = [], "blank"  # of the previous line: blank, heading, para, list
    after_list = False  # the last block before the blank lines was a list
    for number, line in prose_lines(text):
        if line is None or not line.strip():
            after_list = after_list if state == "blank" else state == "list"
            state = "blank"
        elif line.lstrip().startswith("#"):
            state = "heading"
        elif LIST_ITEM.match(line):
            if state == "para":
                errors.append(f"line {number}: {line.strip()[:60]}")
            state = "list"
        elif state == "list" and not line.startswith(" "):
            errors.append(f"line {number}: not indented, read into the item above: "
                          f"{line.strip()[:40]}")
        elif state == "list" or (state == "blank" and after_list and line.startswith("  ")):
            state = "list"  # a list item's continuation
        else:
            state = "para"
    return errors


# Internal work items and a narrated development history have no place in a reference.
INTERNAL = re.compile(
    r"\bthe issue\b|\bissue's\b|\bissue \d+|\bthis session\b|\b(?:same|earlier|a) session\b"
    r"|\btoday's\b|\b(?:January|February|March|April|May|June|July|August|September"
    r"|October|November|December) \d{4}\b", re.I)


def test_table_rows_have_their_headers_number_of_cells():
    bad = {name: table_errors(page_text(name)) for name in pages()}
    bad = {name: errors for name, errors in bad.items() if errors}
    assert not bad, bad


def test_lists_follow_a_blank_line():
    bad = {name: unrendered_lists(page_text(name)) for name in pages()}
    bad = {name: errors for name, errors in bad.items() if errors}
    assert not bad, bad


def test_no_page_is_over_400_lines():
    long = {name: page_text(name).count("\n") for name in pages()}
    assert not {name: n for name, n in long.items() if n > MAX_LINES}


def test_no_page_speaks_of_internal_work_items_or_dates():
    found = {name: [m.group(0) for m in INTERNAL.finditer(page_text(name))] for name in pages()}
    assert not {name: words for name, words in found.items() if words}


def test_the_checks_catch_what_they_are_for():
    """Each check on a known-bad snippet, so that a check that can no longer fail
    fails here."""
    assert table_errors("| a | b |\n|---|---|\n| x | a | b |\n") == ["line 3: 3 cells, header 2"]
    assert table_errors("| a | b |\n|---|---|\n| `x` | a \\| b |\n") == []
    assert unrendered_lists("Read it:\n* one\n* two\n") == ["line 2: * one"]
    assert unrendered_lists("Read it:\n\n* one\n  more\n* two\n\n  still two\n") == []
    assert unrendered_lists("* one\nNot the item.\n") == [
        "line 2: not indented, read into the item above: Not the item."]
    assert unrendered_lists("## Head\n1. one\n```\ntext\n* not a list\n```\n") == []
    assert INTERNAL.search("the issue's target") and INTERNAL.search("measured in December 2026")
    assert not INTERNAL.search("issued by the sweep")


# ---------------------------------------------------------------------------------
# One value per fact: a fact that several pages need is stated on one and linked from
# the others. Each pattern matches any statement of its fact, whatever the value; the
# fact may be stated on its page only (README.md counts as a page).

FACTS = {
    # where the stable half of the steady in-plane branch loses stability out of plane
    "the steady branch's loss of stability": (
        r"37\.55|q_loss_out_of_plane = \d|(?:stays?|is|remains?) stable[^.|]{0,60}?\bto q = \d"
        r"|stable[^.|]{0,40}(?:up )?to (?:its|the) end"
        r"|los\w+ (?:its )?(?:out-of-plane )?stability (?:out of (?:its )?plane )?at (?:q = )?\d",
        "stability.md"),
    # the resolved reference's orders and resolved rows
    "the resolved reference's n_used and resolved counts": (
        r"n_used:? \d+ \(\d+ cases?\)|\d+ of (?:the|its) 20 (?:rows|cases) are `resolved`"
        r"|\d+ rows are `resolved`", os.path.join("studies", "figure-runs.md")),
    # the n --n auto chooses for each regime
    "--n auto's n per regime": (
        r"stable loops (?:are resolved|need) at n = \d|in-plane loops need n = \d"
        r"|\| stable \(q0 below 8\.9001\) \| \d", os.path.join("studies", "n-auto.md")),
    # what the twin costs
    "the twin's cost": (
        r"halves the cost|about doubles|twin adds|2\.0[–-]3\.5|case costs [\d.–-]+ times"
        r"|twin costs [\d.]+[–-][\d.]+ times",
        os.path.join("studies", "n-auto.md")),
    # how far a 1e-6 change of the start moves the terminal tilt
    "a changed start's effect on the tilt": (
        r"(?:start|perturb)[^.]{0,80}?by up to \d+°", os.path.join("studies", "n-auto.md")),
}


# Each fact as the pages stated it when they disagreed: every pattern must still match.
OLD_STATEMENTS = {
    "the steady branch's loss of stability": [
        "The stable branch starts at q = 8.9001 and stays stable\nto q = 30 (the end of the",
        "the steady in-plane shapes stay stable out of plane to q = 25 at least (n = 12)",
        "lies along the stable branch up to its end at q = 25",
        "below the branch's loss of out-of-plane stability at 37.55."],
    "the resolved reference's n_used and resolved counts": [
        "n_used: 16 (6 cases), 20 (5), 24 (4), 32 (5); 17 of the 20 rows are\n`resolved`",
        "n_used: 12 (5 cases), 16 (5), 20 (3), 24 (4),\n  32 (3); ... 18 rows are `resolved`"],
    "--n auto's n per regime": [
        "| stable (q0 below 8.9001) | 16 | radau5 | 1e-6 | 0.05 s |",
        "stable loops are resolved\nat n = 6; in-plane loops need n = 12"],
    "the twin's cost": [
        "the run's cost per case (main job; its twin adds 1–2.5×)",
        "With the twin, a case costs 2.0–3.5 times as\nmuch as without"],
    "a changed start's effect on the tilt": [
        "Perturbing the *start* by 1e-6 moves\n  the terminal tilt by up to 57°",
        "a 1e-6 change of the\nstart moves determined 3D tilts by up to 26°"],
}


def test_the_fact_patterns_match_the_statements_that_disagreed():
    for fact, statements in OLD_STATEMENTS.items():
        pattern = FACTS[fact][0]
        assert all(re.search(pattern, text) for text in statements), fact


#: A number rendered from a committed table (scripts/render_numbers.py): it cannot drift
#: from its source, whose agreement tests/test_render_numbers.py checks, so it is not a
#: second statement of a fact.
RENDERED = re.compile(r"<!-- num:[\w.\-]+ -->.*?<!-- /num -->", re.S)


def fact_pages(pattern):
    """The pages (docs/*.md and README.md) on which a fact's pattern matches, outside
    rendered numbers."""
    texts = {name: page_text(name) for name in pages()}
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as handle:
        texts["README.md"] = handle.read()
    return sorted(name for name, text in texts.items()
                  if re.search(pattern, RENDERED.sub("", text)))


def test_each_fact_is_stated_on_one_page():
    wrong = {}
    for fact, (pattern, home) in FACTS.items():
        found = fact_pages(pattern)
        if found != [home]:
            wrong[fact] = found
    assert not wrong, wrong


def test_the_n6_grid_and_the_main_job_have_one_name_each():
    """`runs/phase` is the README's main job; the n = 6 grid is `runs/phase_n6`; "main
    job" never names another grid."""
    for name in pages():
        for line in page_text(name).splitlines():
            assert not ("6:90:15" in line and "runs/phase " in line + " "), (name, line)
    for name in pages():
        text = page_text(name)
        assert not re.search(r"main job \(n = 6\)|main job's curve|former main job"
                             r"|main-job grid|Main job:", text), name


def tension_solve_sentence(text):
    """The model page's sentence on how T is solved for (from "T minimises" to its end)."""
    flat = " ".join(text.split())
    return re.search(r"T minimises.*?\.(?: |$)", flat).group(0).strip()


def test_the_model_page_names_the_tension_solve_the_velocity_runs():
    """docs/model.md names the solve ``loop_velocity`` calls: linalg's Cholesky on the
    normal equations first, its QR only when that fails (it once said "Householder least
    squares" for all of it)."""
    import inspect

    from loopsim import linalg
    from loopsim.models import loop_maps

    source = inspect.getsource(loop_maps.loop_velocity)
    calls = [source.index(name) for name in ("least_squares_normal", "least_squares_affine")]
    assert calls == sorted(calls)  # normal equations first, QR as the fallback
    assert "Cholesky" in linalg.least_squares_normal.__doc__
    assert "QR" in linalg.least_squares_affine.__doc__
    sentence = tension_solve_sentence(page_text("model.md"))
    assert 0 <= sentence.find("Cholesky") < sentence.find("QR"), sentence
    assert "normal equations" in sentence


def test_the_model_page_gives_each_symbol_one_meaning():
    """ε is the slenderness a/L there; the length creation has a symbol of its own."""
    text = page_text("model.md")
    slenderness = re.search(r"(\S+) = a/L", text).group(1)
    creation = re.search(r"length creation (\S+)", text).group(1)
    assert creation != slenderness
    assert f"∫{slenderness}²" not in text


def test_the_model_page_checks_catch_the_old_text():
    old = ("length creation ε kept to order 2n;\n  T minimises ∫ε² ds (Householder least "
           "squares on a 4n+1 point grid, which\n  resolves ε exactly).\n")
    assert "Cholesky" not in tension_solve_sentence(old)
    assert re.search(r"length creation (\S+)", old).group(1) == "ε"


def test_no_page_says_the_summary_figure_draws_p3d_alone():
    """The summary's figure (``loopsim summary --figure``, ``sweep --seeds auto --figure``)
    draws a pie of the regime probabilities per cell, not P(3D)."""
    claim = re.compile(r"--figure`? (?:draws?|also draws?) P\(3D\)|draw P\(3D\) per")
    assert claim.search("`--figure` draws P(3D) per point and")
    found = {name: claim.findall(" ".join(page_text(name).split())) for name in pages()}
    assert not {name: hits for name, hits in found.items() if hits}

