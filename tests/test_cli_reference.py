"""docs/cli.md's reference is generated from the parsers (scripts/cli_reference.py), so it
cannot go stale; every --help ends with the exit codes; metavars and units are
consistent; the top-level examples are the README's."""
import argparse
import importlib.util
import os
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
    assert reference_script().main(["--check"]) == 0, \
        "docs/cli.md is stale: run python scripts/cli_reference.py"


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
    assert "probability_phase_diagram(cells, ax=axes[0])" in source  # the default style
    style = inspect.signature(distributions.probability_phase_diagram).parameters["style"]
    action = next(a for a in subcommands(cli.build_parser())["summary"]._actions
                  if "--figure" in a.option_strings)
    assert style.default == "pie" and "pie" in action.help and "P(3D)" not in action.help

