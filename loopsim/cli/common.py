"""What the commands share: exit statuses, the parser's classes and argument types,
the integration options, and the ways a command prints, draws and ends."""
import argparse
import math
import os
import sys

from ..defaults import (
    DEFAULT_ATOL, DEFAULT_N, DEFAULT_N_MAX, DEFAULT_PERTURBATION, DEFAULT_RTOL, DEFAULT_T_END,
    DEFAULT_TAIL_TOL, DEFAULT_W, MAX_SLENDERNESS, MODEL_CHOICES,
)
from ..exit_codes import EXIT_BROKEN_PIPE


#: The integrators' names (``loopsim.integrators.METHODS``, tested equal): named here so
#: that the command line loads no kernel, nor Numba, before it has work to do.
METHODS = ("radau5", "rkf45")

EXIT_FAILED_RUN = 1
EXIT_USAGE = 2
EXIT_ENVIRONMENT = 3
#: Every command's exit statuses, in one table (docs/cli.md, "Exit codes"; each --help's
#: epilog): status, meaning.
EXIT_CODES = (
    (0, "success"),
    (EXIT_FAILED_RUN, "a run, or a sweep's case, failed numerically (its summary or row "
                      "says why)"),
    (EXIT_USAGE, "bad input: one line 'loopsim: error: ...' on stderr, nothing written"),
    (EXIT_ENVIRONMENT, "the machine's fault: disk full, read-only filesystem, I/O error, "
                       "no memory or file handles left, a file-size limit reached (re-run "
                       "once fixed: sweeps resume)"),
    (130, "stopped by SIGINT (Ctrl-C: a sweep keeps its finished cases)"),
    (EXIT_BROKEN_PIPE, "stdout's reader went away (a pipe into head): the output stops "
                       "there, without a message, as a Unix tool ended by SIGPIPE"),
    (143, "stopped by SIGTERM (as 130)"),
)
#: The epilog of every command's --help: the exit statuses in one paragraph.
EXIT_EPILOG = "Exit status: " + "; ".join(f"{code} {text}" for code, text in EXIT_CODES) + \
    " (docs/cli.md)."
#: Where the units of every option are defined.
UNITS = "docs/model.md#units"


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Shows each option's default once: not for flags, None, or help that names its own."""

    def _get_help_string(self, action):
        text = action.help or ""
        if ("default" in text or action.default is None or action.default is False
                or action.default == "" or action.default is argparse.SUPPRESS):
            return text
        return super()._get_help_string(action)


class Parser(argparse.ArgumentParser):
    """argparse with a one-line error instead of usage + message."""

    def error(self, message):
        self.exit(EXIT_USAGE, f"loopsim: error: {message} (see '{self.prog} --help')\n")


def real(text):
    """float that rejects nan and inf (argparse type)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return value


def add_model_options(parser):
    """--model and --slenderness: the hydrodynamics of the loop."""
    parser.add_argument("--model", default="local", choices=MODEL_CHOICES,
                        help="hydrodynamics: local (the paper's local slender-body theory) or "
                        "nonlocal (full slender-body theory, needs --slenderness; "
                        "docs/nonlocal.md)")
    parser.add_argument("--slenderness", type=real, default=None, metavar="EPS",
                        help="with --model nonlocal: the slenderness EPS = a/L, filament radius "
                        f"over loop length (dimensionless), in (0, {MAX_SLENDERNESS:g}]; n must "
                        "stay below the mode where "
                        "slender-body theory fails (n <= 10 at 1e-2, <= 108 at 1e-3)")


def add_integration_options(parser):
    """Options shared by every command that integrates loops."""
    add_model_options(parser)
    parser.add_argument("--t-end", type=real, default=DEFAULT_T_END, metavar="T",
                        help=f"final time, in t_u ({UNITS}); with a sweep's early stop a bound: "
                        "each loop stops once at rest, its settling time in t_final "
                        "(docs/sweeps.md#run-to-rest)")
    parser.add_argument("--rtol", type=real, default=DEFAULT_RTOL, metavar="RTOL",
                        help="relative tolerance of the time integration (dimensionless); keep "
                        "the default for a run's own tilt. Where loops tumble only the "
                        "distribution over seeds means anything, and there 1e-3 (with --atol "
                        "1e-6) gave the same distribution as 1e-6 for less cost: use it only "
                        "for distributions, with every cell of a study at one tolerance, after "
                        "a check of 16 seeds at both tolerances compared with loopsim compare "
                        "(docs/choosing-n-method-rtol.md, 'Above g0 ~ 250')")
    parser.add_argument("--atol", type=real, default=DEFAULT_ATOL, metavar="ATOL",
                        help="absolute tolerance of the time integration, on the shape "
                        "coefficients, in L/2pi")
    parser.add_argument("--w", type=real, default=DEFAULT_W, metavar="W",
                        help="length-penalty rate of the inextensibility constraint, in 1/t_u")
    parser.add_argument("--perturbation", type=real, default=DEFAULT_PERTURBATION,
                        metavar="SIZE",
                        help="RMS size of the seeded initial perturbation, in L/2pi (0: exact "
                        f"circle; default: {DEFAULT_PERTURBATION:g}, or 0 with --initial)")
    parser.add_argument("--method", default=None, choices=sorted(METHODS) + ["auto"],
                        help="time integrator: rkf45 (explicit, the paper's), radau5 "
                        "(implicit: stiff stable and in-plane loops, any n >= 8) or auto "
                        "(chosen per case; recorded in the column method) (default: rkf45 at "
                        "a fixed n, auto with --n auto)")
    parser.add_argument("--no-twin", action="store_true",
                        help="skip the twin run at 10x stricter tolerances that says whether "
                        "each outcome is determined (the twin costs more than the run "
                        "itself; 'determined' is then empty)")
    parser.add_argument("--n-max", type=int, default=None, metavar="N",
                        help=f"with --n auto: the highest truncation order a case may reach "
                        f"(default: {DEFAULT_N_MAX})")
    parser.add_argument("--tail-tol", type=real, default=None, metavar="TOL",
                        help="with --n auto: restart a case at the next order, from the start, "
                        "when its spectral tail (the top two modes' share of the deformation, "
                        f"dimensionless) passes TOL (default: {DEFAULT_TAIL_TOL:g})")


def check_auto_options(args, n_start=DEFAULT_N):
    """--n-max and --tail-tol only with --n auto (refused otherwise: they would do
    nothing), --n-max not below the ladder's start; then their defaults filled in."""
    from .. import validation

    if args.n != "auto":
        given = [f"--{k.replace('_', '-')}" for k in ("n_max", "tail_tol")
                 if getattr(args, k) is not None]
        if given:
            raise ValueError(f"{given[0]} applies only with --n auto (it would do nothing "
                             f"at --n {args.n if args.n is not None else DEFAULT_N})")
    if args.n_max is not None:
        validation.check_order("--n-max", args.n_max)
        if args.n == "auto" and args.n_max < n_start:
            raise ValueError(f"--n-max {args.n_max} is below the order --n auto starts at "
                             f"({n_start})")
    args.n_max = DEFAULT_N_MAX if args.n_max is None else args.n_max
    args.tail_tol = DEFAULT_TAIL_TOL if args.tail_tol is None else args.tail_tol


def interrupted(signum, detail):
    """The one way a command ends on SIGINT / SIGTERM: one line on stderr, no traceback,
    exit status 128 + signum (130 / 143).  As the ``loopsim`` program it exits at once
    (``os._exit``: a kernel may still run in a worker thread and cannot be cut short)."""
    import signal

    signum = signum or signal.SIGINT
    print(f"loopsim: interrupted by {signal.Signals(signum).name}: {detail}", file=sys.stderr)
    status = 128 + int(signum)
    if _is_program():
        sys.stdout.flush()
        sys.stderr.flush()
        from .._signals import end_children, remove_temporaries

        end_children()
        remove_temporaries()
        os._exit(status)
    return status


def _is_program():
    """Whether this process is the ``loopsim`` command (not a caller of :func:`main`)."""
    from .._signals import is_program

    return is_program()


def print_and_write(table, out, meta, shown=None, *, declarations):
    """Print ``table`` (its ``shown`` columns) and write it to ``out`` (Parquet, atomic,
    with loopsim's provenance and ``meta`` in its metadata, and each column's unit and
    description from ``declarations``, a table of ``loopsim.columns``: a column it does
    not declare is a KeyError, before anything is written) when given."""
    import pandas as pd
    import pyarrow as pa

    from .. import storage

    with pd.option_context("display.width", 160, "display.max_columns", 40):
        print(table[shown or list(table.columns)].to_string(
            index=False, float_format=lambda v: f"{v:.4g}"))
    if out is not None:
        storage.write_table_atomically(storage.described(
            pa.Table.from_pandas(table, preserve_index=False)
            .replace_schema_metadata(storage.provenance(**meta)), declarations), out)
        print(f"table: {out}")


def directory_name(path):
    """The last component of a directory's path: what a table's metadata records of the
    directory it came from (never the machine's full path)."""
    return os.path.basename(os.path.normpath(path))


def use_agg():
    """Figures from the command line are files: the non-interactive Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
