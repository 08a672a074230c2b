"""Command-line interface: ``loopsim run``, ``loopsim sweep``, ``loopsim summary`` ...

Errors in the input end with one line ``loopsim: error: ...`` on stderr and
exit status 2; a run that fails numerically exits 1 after printing its summary; the
machine refusing to go on (disk full, read-only filesystem, I/O error, a file-size
limit) exits 3; stdout's reader gone (``| head -1``) ends a command quietly with exit
status 141, as a Unix tool ended by SIGPIPE (``exit_codes.EXIT_BROKEN_PIPE``)
(``common.EXIT_CODES``; docs/cli.md is generated from these parsers by
scripts/cli_reference.py).

One module per command (``run``, ``sweep``, ``stability``, ``summary``, ``compare``,
``branch``, ``rest-window``, ``figures``, ``report``, ``animate``), each with its ``add_parser`` (its
options) and ``command`` (its work); ``common`` holds what they share.  Modules load
nothing heavy until a command runs: ``loopsim --help`` imports neither NumPy nor Numba.
"""
import argparse
import contextlib
import sys
import textwrap
import warnings

from .._version import __version__
from .._signals import stdout_gone
from ..exit_codes import ENVIRONMENT_ERRNOS, EXIT_BROKEN_PIPE
from . import (animate, branch, compare, figures, report, rest_window, run, stability, summary,
               sweep)
from .common import EXIT_ENVIRONMENT, EXIT_EPILOG, EXIT_FAILED_RUN, EXIT_USAGE, METHODS, Parser

__all__ = ["EXIT_ENVIRONMENT", "EXIT_FAILED_RUN", "EXIT_USAGE", "METHODS", "build_parser", "main"]

#: The commands, in the order ``loopsim --help`` lists them.
COMMANDS = {"run": run, "sweep": sweep, "stability": stability, "summary": summary,
            "compare": compare, "branch": branch, "rest-window": rest_window,
            "figures": figures, "report": report, "animate": animate}


#: ``loopsim --help``'s examples: the README's main job first (tests/test_cli_reference.py).
EXAMPLES = (
    ("a resolved run (n auto, the default)", "loopsim run --g0 150 --theta0 45"),
    ("the paper's scheme", "loopsim run --g0 150 --theta0 45 --n 6 --method rkf45"),
    ("the README's main job", "loopsim sweep --g0 10:150:8 --theta0 10:90:9 --n auto "
                              "--out runs/phase --figure runs/phase.png"),
    ("the paper's n = 6 grid: its 225 cases, as scripts/make_figures.py runs them",
     "loopsim sweep --g0 10:350:15 --theta0 6:90:15 --n 6 --method rkf45 --no-twin "
     "--out runs/phase_n6"),
    ("the circle's stability", "loopsim stability --n 16"),
)


def build_parser():
    """The ``loopsim`` parser: every command of :data:`COMMANDS` (and any other a command
    module registers), each --help ending with the exit statuses (``common.EXIT_EPILOG``)."""
    parser = Parser(
        prog="loopsim",
        description=textwrap.fill(
            "Flexible elastic loops sedimenting in a viscous fluid (local or nonlocal "
            "slender-body theory, spectral in arc length). Units: docs/model.md#units.", 88),
        epilog="Examples:\n" + "\n".join(f"  {command}\n      ({what})"
                                          for what, command in EXAMPLES)
        + "\n\n" + textwrap.fill(EXIT_EPILOG, 88),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"loopsim {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for module in COMMANDS.values():
        module.add_parser(commands)
    for command in commands.choices.values():
        command.epilog = command.epilog or EXIT_EPILOG
    return parser


@contextlib.contextmanager
def _one_line_warnings():
    """Warnings (a damaged file moved aside, a stray copy ignored) as one line each:
    ``loopsim: warning: ...``, without Python's source line."""
    with warnings.catch_warnings():
        warnings.showwarning = lambda message, *_, **__: print(
            f"loopsim: warning: {message}", file=sys.stderr)
        yield


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        with _one_line_warnings():
            status = COMMANDS[args.command].command(args)
            sys.stdout.flush()  # here, not at exit: a reader gone is seen below
            return status
    except (ValueError, OSError) as exc:
        if isinstance(exc, BrokenPipeError) and stdout_gone():  # `| head -1`: stop quietly
            return EXIT_BROKEN_PIPE
        print(f"loopsim: error: {exc}", file=sys.stderr)
        if isinstance(exc, OSError) and exc.errno in ENVIRONMENT_ERRNOS:  # the machine's fault
            return EXIT_ENVIRONMENT
        return EXIT_USAGE
