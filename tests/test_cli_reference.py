"""docs/cli.md's reference is generated from the parsers (scripts/cli_reference.py), so it
cannot go stale; every --help ends with the exit codes; metavars and units are
consistent; the top-level examples are the README's."""
import argparse
import importlib.util
import os
import re
import shlex
import types

import pytest

from loopsim import cli
from loopsim.cli.common import EXIT_CODES

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def reference_script():
    spec = importlib.util.spec_from_file_location(
        "cli_reference", os.path.join(ROOT, "scripts", "cli_reference.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def subcommands(parser):
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return action.choices


def test_cli_md_is_what_the_parsers_give_now():
    """The command reference, and the generated lists of docs/cli.md and docs/sweeps.md."""
    assert reference_script().main(["--check"]) == 0, \
        "docs/cli.md or docs/sweeps.md is stale: run python scripts/cli_reference.py"


def docs_page(name):
    with open(os.path.join(ROOT, "docs", name), encoding="utf-8") as handle:
        return handle.read()


def without_generated(text):
    """A page without its generated parts (the command reference and the lists)."""
    text = re.sub(r"<!-- BEGIN list .*?<!-- END list [^>]*-->", "", text, flags=re.S)
    return re.sub(r"<!-- BEGIN generated .*?<!-- END generated [^>]*-->", "", text, flags=re.S)


def named(names, text):
    """The names of ``names`` that ``text`` lists in code spans (`a, b` or `a`, `b`; not
    names inside code such as `f(a, b=1)`)."""
    listed = set()
    for span in re.findall(r"`([^`]*)`", text):
        items = [item.strip() for item in span.split(",")]
        if all(re.fullmatch(r"\w+", item) for item in items):
            listed.update(items)
    return listed & set(names)


def test_the_documented_field_and_column_lists_are_the_codes():
    """``run --json``'s fields and a cases file's columns are listed once each, generated
    from ``SUMMARY_FIELDS`` and ``CASE_COLUMNS`` where the docs describe them; no hand-kept
    list beside them (cli.md's lacked 5 fields, the cases file's columns were in three
    partial lists)."""
    from loopsim import SUMMARY_FIELDS
    from loopsim.columns import CASE_COLUMNS

    script = reference_script()
    for page, name, generator in script.LISTS:
        begin, end = script.list_markers(name)
        block = docs_page(page).split(begin, 1)[1].split(end, 1)[0]
        listed = re.findall(r"`([^`]+)`", block)
        assert listed == list({"loopsim.SUMMARY_FIELDS": SUMMARY_FIELDS,
                               "loopsim.columns.CASE_COLUMNS": CASE_COLUMNS}[name]), name
    cli_md, sweeps_md = docs_page("cli.md"), docs_page("sweeps.md")
    json_begin = script.list_markers("loopsim.SUMMARY_FIELDS")[0]
    assert 0 < cli_md.index(json_begin) - cli_md.index("`loopsim run --json` prints") < 300
    cases_begin = script.list_markers("loopsim.columns.CASE_COLUMNS")[0]
    assert 0 < sweeps_md.index(cases_begin) - sweeps_md.index("rows\nof a cases file") < 300
    cases = next(a for a in subcommands(cli.build_parser())["sweep"]._actions
                 if "--cases" in a.option_strings)
    assert all(re.search(rf"\b{name}\b", cases.help) for name in CASE_COLUMNS)
    for page in os.listdir(os.path.join(ROOT, "docs")):
        if page.endswith(".md"):
            for paragraph in without_generated(docs_page(page)).split("\n\n"):
                if not paragraph.lstrip().startswith("|"):  # column tables: tests/test_outcomes.py
                    assert len(named(SUMMARY_FIELDS, paragraph)) < 10, (page, paragraph[:80])
    for paragraph in without_generated(sweeps_md + cli_md).split("\n\n"):
        if "cases file" in " ".join(paragraph.split()):
            assert len(named(CASE_COLUMNS, paragraph)) < 5, paragraph[:80]


def test_the_list_checks_catch_the_old_lists():
    from loopsim import SUMMARY_FIELDS
    from loopsim.columns import CASE_COLUMNS

    old_json = ("`g0, theta0_deg, n, q0, t_end, rtol, atol, w, perturbation, seed, method, "
                "n_used,\nstatus` and `compile_s`")
    assert len(named(SUMMARY_FIELDS, old_json)) >= 10
    old_cases = ("of a cases file (columns `g0, theta0_deg` and optionally `n, seed,\n"
                 "perturbation`, and per row `method, rtol, t_end`: a given cell")
    assert len(named(CASE_COLUMNS, old_cases)) == 8


def test_the_reference_covers_every_registered_command(monkeypatch):
    """A command added to loopsim.cli.COMMANDS (as the animate and report commands will
    be) is in the generated reference without touching the script."""
    def add_parser(commands):
        extra = commands.add_parser("extra", help="a command for this test",
                                    description="An extra command.")
        extra.add_argument("--size", metavar="SIZE", help="its size, in L/2pi")
        return extra

    monkeypatch.setitem(cli.COMMANDS, "extra", types.SimpleNamespace(add_parser=add_parser))
    text = reference_script().generated()
    for name in subcommands(cli.build_parser()):
        assert f"### `loopsim {name}`" in text, name
    assert "<code>--size SIZE</code> | its size, in L/2pi |" in text
    for code, _ in EXIT_CODES:
        assert f"| {code} |" in text


def test_every_help_ends_with_the_exit_codes():
    parser = cli.build_parser()
    for name, command in subcommands(parser).items():
        assert command.format_help().rstrip().endswith("(docs/cli.md)."), name
        assert all(f"{code} " in command.epilog for code, _ in EXIT_CODES), name
    assert "Exit status: 0 success" in parser.epilog


def test_one_metavar_means_one_quantity():
    """EPS is the slenderness only (not the perturbation's size nor the onset's)."""
    for name, command in subcommands(cli.build_parser()).items():
        for action in command._actions:
            metavars = action.metavar if isinstance(action.metavar, tuple) else (action.metavar,)
            if "EPS" in metavars:
                assert action.option_strings == ["--slenderness"], (name, action.option_strings)


@pytest.mark.parametrize("option, unit", [("--t-end", "t_u"), ("--w", "1/t_u"),
                                          ("--atol", "L/2pi"), ("--perturbation", "L/2pi"),
                                          ("--rtol", "dimensionless"), ("--g0", "dimensionless"),
                                          ("--theta0", "degrees")])
def test_the_physical_options_give_their_units(option, unit):
    for name in ("run", "sweep"):
        command = subcommands(cli.build_parser())[name]
        action = next(a for a in command._actions if option in a.option_strings)
        assert unit in action.help, (name, option)


def test_sweep_help_lists_its_cases_before_the_tuning_options():
    text = subcommands(cli.build_parser())["sweep"].format_help()
    body = text[text.index("options:"):]
    first = [body.index("\n  " + option) for option in (
        "--g0 START", "--n N", "--model", "--rtol", "--p-halfwidth", "--out", "--scheduler")]
    assert first == sorted(first)  # the cases, how each runs, --seeds auto, output, where


def test_the_top_level_examples_include_the_readme_main_job():
    from test_readme import main_command

    epilog = cli.build_parser().epilog
    assert " ".join(shlex.quote(w) for w in main_command()) in epilog
    assert "--n 6 --method rkf45" in epilog  # the paper's scheme, one flag away
    assert "--out runs/phase_n6" in epilog and "--n 6 --method rkf45 --out runs/phase " not in epilog


def test_summary_figure_help_says_what_the_figure_draws():
    """The figure's first panel is ``probability_phase_diagram`` in its default style:
    pies of the regime probabilities (P(3D) alone is its "colour" style)."""
    import inspect

    from loopsim.figures import distributions

    source = inspect.getsource(distributions.distribution_summary)
    call = source[source.index("probability_phase_diagram(cells, ax=axes[0]"):].split(")")[0]
    assert "style" not in call  # the default style
    style = inspect.signature(distributions.probability_phase_diagram).parameters["style"]
    action = next(a for a in subcommands(cli.build_parser())["summary"]._actions
                  if "--figure" in a.option_strings)
    assert style.default == "pie" and "pie" in action.help and "P(3D)" not in action.help



def test_the_rtol_help_carries_the_conditions_of_a_loose_tolerance():
    """--rtol's help names a looser rtol for tumbling cells; it also says when that holds:
    distributions only, one tolerance per study, a 16-seed check first (it once gave the
    cost ratio alone)."""
    parser = cli.build_parser()
    for name in ("run", "sweep"):
        command = subcommands(parser)[name]
        (action,) = [a for a in command._actions if "--rtol" in a.option_strings]
        text = " ".join(action.help.split())
        for condition in ("only for distributions", "one tolerance", "16 seeds at both",
                          "run's own tilt"):
            assert condition in text, (name, condition)
