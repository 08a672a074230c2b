"""The documented commands, checked as commands: every ``loopsim ...`` command of
README.md, docs/*.md and ``loopsim --help``'s examples parses with the real parser
(nothing is run), and a documented sweep of the paper's 225-case grid says which n it
runs: the default, ``--n auto``, runs that grid's every case up the ladder with its twin
(hours), the paper's n = 6 grid is minutes.  The n = 6 grid's command is the sweep
``scripts/make_figures.py`` runs into ``runs/phase_n6`` (same configuration fingerprint),
so a directory made by hand is one the figure script resumes, not one it refuses."""
import argparse
import glob
import importlib.util
import json
import os
import re
import shlex

import pytest

from loopsim import cli

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = os.path.join(ROOT, "docs")
#: The paper's Fig. 5 grid (225 cases): at n = 6 the "n = 6 grid" of the docs.
PAPER_GRID = ("10:350:15", "6:90:15")
N6_GRID_DIR = "runs/phase_n6"
#: Words that make a documented command a synopsis (placeholders), not a command line.
SYNOPSIS = re.compile(r"\.\.\.|…|\[|\]")
PLACEHOLDER = re.compile(r"^[A-Z][A-Z0-9_]*(?:\.[A-Za-z]+)?$")


def doc_texts():
    """{name: text} of README.md and every page under docs/ (docs/studies/ included)."""
    names = ["README.md"] + sorted(os.path.relpath(path, ROOT) for path in glob.glob(
        os.path.join(DOCS, "**", "*.md"), recursive=True))
    texts = {}
    for name in names:
        with open(os.path.join(ROOT, name), encoding="utf-8") as handle:
            texts[name] = handle.read()
    return texts


def commands_in(text):
    """The ``loopsim ...`` commands of a Markdown text, as word lists without "loopsim":
    the lines of fenced blocks (continuation lines joined, comments, pipes and what
    follows ``&&`` dropped) and the inline code spans that start with ``loopsim``."""
    found = []
    for block in re.findall(r"```[^\n]*\n(.*?)```", text, re.S):
        for line in block.replace("\\\n", " ").splitlines():
            for part in re.split(r"&&|\|\||;|\|", line):
                words = part.split("#", 1)[0].split()
                if words[:1] == ["loopsim"]:
                    found.append(" ".join(words))
    prose = re.sub(r"```.*?```", "", text, flags=re.S)
    found += [" ".join(span.split()) for span in re.findall(r"`(loopsim [^`]*)`", prose)]
    return [shlex.split(command)[1:] for command in found]


def documented_commands():
    """(where, words) of every documented command, --help's examples included."""
    commands = [(name, words) for name, text in doc_texts().items()
                for words in commands_in(text)]
    commands += [("loopsim --help", shlex.split(command)[1:]) for _, command in cli.EXAMPLES]
    return commands


def subcommands(parser):
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return action.choices


def command_errors(words, parser=None):
    """Why ``loopsim WORDS`` is not a command the parser takes ([] if it is).  A synopsis
    (placeholders: upper-case words such as DIR, FILE.gif or K, brackets, "...") and a
    mention of a command or of its options ("loopsim run --out") must name a command and
    only its options; anything else must parse whole."""
    parser = parser or cli.build_parser()
    commands = subcommands(parser)
    if not words or words[0] in ("--help", "--version") or PLACEHOLDER.match(words[0]):
        # "loopsim --help", "loopsim COMMAND --help"
        return [] if all(w in ("--help", "--version") or PLACEHOLDER.match(w)
                         for w in words) else [f"not a command: {words}"]
    if words[0] not in commands:
        return [f"no command {words[0]!r}"]
    command = commands[words[0]]
    options = {o for a in command._actions for o in a.option_strings}
    if "--help" in words or SYNOPSIS.search(" ".join(words)) or all(
            w.startswith("--") or PLACEHOLDER.match(w) for w in words[1:]):
        # a synopsis, a command's name, or options named ("loopsim run --out")
        given = [w.strip("[]").split("=")[0] for w in words[1:]]
        return [f"{words[0]} has no option {w}" for w in given
                if w.startswith("--") and w not in options]
    errors = []

    def refuse(message):
        errors.append(message)
        raise SystemExit(2)

    for p in (parser, command):  # the real parsers, their error turned into a value
        p.error = refuse
    try:
        parser.parse_args(words)
    except SystemExit:
        pass
    return errors


def test_every_documented_command_parses():
    commands = documented_commands()
    assert len(commands) > 60
    bad = {f"{where}: loopsim {' '.join(words)}": errors for where, words in commands
           if (errors := command_errors(words))}
    assert not bad, bad


def option(words, name):
    """The value of option ``name`` in a command's words (None if absent)."""
    return words[words.index(name) + 1] if name in words[:-1] else None


def paper_grid_sweeps(commands):
    return [(where, words) for where, words in commands if words[:1] == ["sweep"]
            and (option(words, "--g0"), option(words, "--theta0")) == PAPER_GRID]


def paper_grid_errors(words):
    """A sweep of the paper's grid must say its n (the default --n auto is the ladder
    with twins: hours, where the n = 6 grid is minutes); at n = 6 it is the paper's scheme
    (rkf45), and the one into runs/phase_n6 is the n = 6 grid."""
    n, out = option(words, "--n"), option(words, "--out")
    if n is None:
        return ["no --n: it would run --n auto, the ladder with twins"]
    if out == N6_GRID_DIR and n != "6":
        return [f"writes {N6_GRID_DIR} at --n {n}"]
    if n == "6" and option(words, "--method") != "rkf45":
        return ["the n = 6 grid without --method rkf45 (the paper's scheme)"]
    return []


def test_documented_sweeps_of_the_paper_grid_say_their_n():
    sweeps = paper_grid_sweeps(documented_commands())
    assert any(option(w, "--out") == N6_GRID_DIR for _, w in sweeps)  # the n = 6 grid is shown
    bad = {f"{where}: {' '.join(words)}": errors for where, words in sweeps
           if (errors := paper_grid_errors(words))}
    assert not bad, bad


def make_figures_steps():
    spec = importlib.util.spec_from_file_location(
        "make_figures", os.path.join(ROOT, "scripts", "make_figures.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.steps("runs", threads=2)


def sweep_fingerprint(words):
    """The configuration fingerprint a sweep command's directory would get (no case run)."""
    from loopsim import storage
    from loopsim.cli import sweep as sweep_command

    args = cli.build_parser().parse_args(words)
    config, targets = sweep_command.configuration(args)
    assert targets is None  # a fixed number of seeds
    return storage.config_fingerprint(json.loads(json.dumps(config.as_dict())))


def test_the_n6_grid_commands_are_the_figure_scripts_sweep():
    """What the docs and --help give for runs/phase_n6 is the sweep make_figures runs
    there: the same configuration, so the figure script resumes that directory."""
    path, arguments, _ = make_figures_steps()["phase_n6"]
    assert path == os.path.join("runs", "phase_n6")
    expected = sweep_fingerprint(arguments)
    shown = [(where, words) for where, words in documented_commands()
             if words[:1] == ["sweep"] and option(words, "--out") == N6_GRID_DIR]
    assert shown and {where for where, _ in shown} >= {"loopsim --help"}
    different = [f"{where}: {' '.join(words)}" for where, words in shown
                 if sweep_fingerprint(words) != expected]
    assert not different, different


@pytest.mark.parametrize("line, expected", [
    # the n = 6 grid as docs/choosing-n-method-rtol.md gave it: --n auto by default
    ("loopsim sweep --g0 10:350:15 --theta0 6:90:15 --out runs/phase_n6 --figure x.png",
     ["no --n: it would run --n auto, the ladder with twins"]),
    ("loopsim sweep --g0 10:350:15 --theta0 6:90:15 --n 6 --out runs/phase_n6",
     ["the n = 6 grid without --method rkf45 (the paper's scheme)"]),
    ("loopsim sweep --g0 10:350:15 --theta0 6:90:15 --n auto --out runs/grid225", []),
])
def test_the_grid_rule_catches_the_commands_that_ran_something_else(line, expected):
    (words,) = commands_in(f"```bash\n{line}\n```")
    assert paper_grid_sweeps([("x", words)])
    assert paper_grid_errors(words) == expected


def test_the_checks_catch_what_they_are_for():
    """Each check on a known-bad snippet, so that a check that can no longer fail fails
    here."""
    text = ("```bash\npip install -e . && loopsim run --g0 60 --theta0 30  # a comment\n"
            "loopsim sweep --g0 1,2 \\\n  --theta0 30 --out runs/x\n```\n"
            "Inline: `loopsim summary DIR [--out FILE]` and `loopsim run --gee 60`.\n")
    commands = commands_in(text)
    assert commands == [["run", "--g0", "60", "--theta0", "30"],
                        ["sweep", "--g0", "1,2", "--theta0", "30", "--out", "runs/x"],
                        ["summary", "DIR", "[--out", "FILE]"], ["run", "--gee", "60"]]
    assert [command_errors(c) for c in commands[:3]] == [[], [], []]
    assert command_errors(["run", "--gee", "60"])  # an unknown option
    assert command_errors(["run", "--g0", "sixty"])  # a value the option's type refuses
    assert command_errors(["summary", "DIR", "[--outt", "FILE]"]) == [
        "summary has no option --outt"]
    assert command_errors(["frobnicate"]) == ["no command 'frobnicate'"]


def test_the_compilation_table_names_what_its_run_runs():
    """docs/studies/performance.md times ``loopsim run`` commands: each row names the integrator
    the command runs (it once said "rkf45 at n = 6" for a run that is --n auto, radau5)."""
    from loopsim import refinement
    from loopsim.diagnostics import stability_parameter

    with open(os.path.join(DOCS, "studies", "performance.md"), encoding="utf-8") as handle:
        section = handle.read().split("## Compilation", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("| `loopsim run ")]
    assert rows
    for row in rows:
        (words,) = [shlex.split(c)[1:] for c in re.findall(r"`(loopsim run [^`]*)`", row)]
        args = cli.build_parser().parse_args(words)
        method = args.method or ("auto" if args.n == "auto" else "rkf45")
        if method == "auto":
            method = refinement.auto_method(stability_parameter(args.g0, args.theta0),
                                            6 if args.n == "auto" else args.n, args.n == "auto")
        others = set(refinement.METHOD_CHOICES) - {method, "auto"}
        assert method in row and not any(other in row for other in others), row
        assert ("--n auto" in row) == (args.n == "auto"), row

