"""Command-line interface: ``loopsim run``, ``loopsim sweep`` and ``loopsim stability``.

Errors in the input end with one line ``loopsim: error: ...`` on stderr and
exit status 2; a run that fails numerically exits 1 after printing its summary; the
machine refusing to go on (disk full, read-only filesystem, I/O error) exits 3.

One module per command (``run``, ``sweep``, ``stability``, ``summary``, ``compare``,
``branch``, ``figures``, ``report``, ``animate``), each with its ``add_parser`` (its
options) and ``command`` (its work); ``common`` holds what they share.  Modules load
nothing heavy until a command runs: ``loopsim --help`` imports neither NumPy nor Numba.
"""
import argparse
import contextlib
import sys
import warnings

from .._version import __version__
from ..config import ENVIRONMENT_ERRNOS
from . import animate, branch, compare, figures, report, run, stability, summary, sweep
from .common import EXIT_ENVIRONMENT, EXIT_FAILED_RUN, EXIT_USAGE, METHODS, Parser

__all__ = ["EXIT_ENVIRONMENT", "EXIT_FAILED_RUN", "EXIT_USAGE", "METHODS", "main"]

#: The commands, in the order ``loopsim --help`` lists them.
COMMANDS = {"run": run, "sweep": sweep, "stability": stability, "summary": summary,
            "compare": compare, "branch": branch, "figures": figures, "report": report,
            "animate": animate}


def _build_parser():
    parser = Parser(
        prog="loopsim",
        description="Flexible elastic loops sedimenting in a viscous fluid "
        "(local slender-body theory, spectral in arc length).",
        epilog="Examples:\n  loopsim run --g0 60 --theta0 30\n"
        "  loopsim run --g0 150 --theta0 60 --n 8 --json\n"
        "  loopsim sweep --g0 10:350:8 --theta0 10:90:5 --out runs/phase --figure phase.png\n"
        "  loopsim stability --n 16\n"
        "  loopsim stability --paper --n-max 20",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"loopsim {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for module in COMMANDS.values():
        module.add_parser(commands)
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
    parser = _build_parser()
    args = parser.parse_args(argv)
    try:
        with _one_line_warnings():
            return COMMANDS[args.command].command(args)
    except (ValueError, OSError) as exc:
        print(f"loopsim: error: {exc}", file=sys.stderr)
        if isinstance(exc, OSError) and exc.errno in ENVIRONMENT_ERRNOS:  # the machine's fault
            return EXIT_ENVIRONMENT
        return EXIT_USAGE
