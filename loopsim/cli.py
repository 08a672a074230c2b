"""Command-line interface: ``loopsim run``, ``loopsim sweep`` and ``loopsim stability``.

Errors in the input end with one line ``loopsim: error: ...`` on stderr and
exit status 2; a run that fails numerically exits 1 after printing its summary; the
machine refusing to go on (disk full, read-only filesystem, I/O error) exits 3.
"""
import argparse
import contextlib
import json
import math
import os
import sys
import warnings

from ._version import __version__
from .config import (
    ENVIRONMENT_ERRNOS,
    DEFAULT_ATOL, DEFAULT_AUTO_CHUNK_SIZE, DEFAULT_CHUNK_SIZE, DEFAULT_N, DEFAULT_N_MAX,
    DEFAULT_PERTURBATION, DEFAULT_RTOL, DEFAULT_SEED, DEFAULT_T_END, DEFAULT_TAIL_TOL, DEFAULT_W,
)

#: The integrators' names (``loopsim.integrators.METHODS``, tested equal): named here so
#: that the command line loads no kernel, nor Numba, before it has work to do.
METHODS = ("radau5", "rkf45")

EXIT_FAILED_RUN = 1
EXIT_USAGE = 2
EXIT_ENVIRONMENT = 3


class _HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Shows each option's default once: not for flags, None, or help that names its own."""

    def _get_help_string(self, action):
        text = action.help or ""
        if ("default" in text or action.default is None or action.default is False
                or action.default == "" or action.default is argparse.SUPPRESS):
            return text
        return super()._get_help_string(action)


class _Parser(argparse.ArgumentParser):
    """argparse with a one-line error instead of usage + message."""

    def error(self, message):
        self.exit(EXIT_USAGE, f"loopsim: error: {message} (see '{self.prog} --help')\n")


def _real(text):
    """float that rejects nan and inf (argparse type)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return value


def _add_integration_options(parser):
    """Options shared by every command that integrates loops."""
    parser.add_argument("--t-end", type=_real, default=DEFAULT_T_END, help="final time")
    parser.add_argument("--rtol", type=_real, default=DEFAULT_RTOL, help="relative tolerance")
    parser.add_argument("--atol", type=_real, default=DEFAULT_ATOL, help="absolute tolerance")
    parser.add_argument("--w", type=_real, default=DEFAULT_W, help="length-penalty rate")
    parser.add_argument("--perturbation", type=_real, default=DEFAULT_PERTURBATION, metavar="EPS",
                        help="RMS size of the seeded initial perturbation (0: exact circle; "
                        f"default: {DEFAULT_PERTURBATION:g}, or 0 with --initial)")
    parser.add_argument("--method", default=None, choices=sorted(METHODS) + ["auto"],
                        help="time integrator: rkf45 (explicit, the paper's), radau5 "
                        "(implicit: stiff stable and in-plane loops, any n >= 8) or auto "
                        "(chosen per case; recorded in the column method) (default: rkf45 at "
                        "a fixed n, auto with --n auto)")
    parser.add_argument("--no-twin", action="store_true",
                        help="skip the twin run at 10x stricter tolerances that says whether "
                        "each outcome is determined (about halves the cost; 'determined' is "
                        "then empty)")
    parser.add_argument("--n-max", type=int, default=None,
                        help=f"with --n auto: the highest truncation order a case may reach "
                        f"(default: {DEFAULT_N_MAX})")
    parser.add_argument("--tail-tol", type=_real, default=None,
                        help="with --n auto: restart a case at the next order when its "
                        "spectral tail (the top two modes' share of the deformation) passes "
                        f"this (default: {DEFAULT_TAIL_TOL:g})")


def _order(text):
    """A truncation order (argparse type): an integer, or 'auto'."""
    if text == "auto":
        return text
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer or 'auto': {text!r}") from None


def _build_parser():
    parser = _Parser(
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
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    run = commands.add_parser(
        "run", help="simulate one loop released as a tilted, perturbed circle",
        description="Simulate one loop released as a circle tilted by THETA0 degrees "
        "(plus a seeded perturbation) and print its terminal summary.",
        formatter_class=_HelpFormatter,
    )
    run.add_argument("--g0", type=_real,
                     help="gravity over bending stiffness, g0 = L^3 g rho_L / (8 pi^3 EI) >= 0 "
                     "(required, except when continuing from results: then their g0)")
    run.add_argument("--theta0", type=_real, metavar="DEG",
                     help="initial tilt of the loop's plane to the horizontal, in [0, 90] degrees "
                     "(not with --initial: the tilt is measured)")
    run.add_argument("--n", type=_order, default=None,
                     help=f"Fourier truncation order (1..128; default: {DEFAULT_N}, or the stored "
                     "order of --initial results), or auto: start there and raise n during "
                     "the run whenever the spectral tail passes --tail-tol")
    run.add_argument("--initial", metavar="FILE|DIR",
                     help="start from a shape: a CSV/Parquet point file (columns x, y, z, in "
                     "order along the closed curve) or results (run --out file, sweep dir)")
    run.add_argument("--case-id", type=int, default=None, metavar="K",
                     help="with --initial results: the case whose terminal shape starts the run")
    _add_integration_options(run)
    run.set_defaults(perturbation=None)
    run.add_argument("--seed", type=int, default=DEFAULT_SEED, help="perturbation seed (>= 0)")
    run.add_argument("--snapshots", type=int, default=2, metavar="K",
                     help="states stored of the trajectory: K equally spaced times, both "
                     "ends included (as sweep --snapshots; here the start and the end by "
                     "default)")
    run.add_argument("--out", metavar="FILE.parquet",
                     help="write the snapshots (and the summary as metadata) to Parquet")
    run.add_argument("--json", action="store_true", help="print the summary as one JSON object")

    sweep = commands.add_parser(
        "sweep", help="run (or resume) an ensemble over (g0, theta0, n, seed) into Parquet",
        description="Integrate many loops in parallel and write one row per case into "
        "chunk files in DIR, a Parquet dataset (pandas.read_parquet(DIR); checked: "
        "loopsim.read_results(DIR)). Re-running the same command resumes (also with another "
        "--chunk-size). Exit status: 0 every case ok; 1 some case failed (its row says why; "
        "see --rerun-failed); 2 bad input; 3 disk full, read-only filesystem or I/O error "
        "(re-run to resume once fixed); 130 / 143 stopped by SIGINT / SIGTERM (finished "
        "cases kept: re-run to resume).",
        formatter_class=_HelpFormatter,
    )
    grid = sweep.add_argument_group("cases (a grid, or --cases FILE)")
    grid.add_argument("--g0", metavar="START:STOP:NUM|v1,v2,...", help="g0 values")
    grid.add_argument("--theta0", metavar="START:STOP:NUM|v1,v2,...", help="theta0 values (deg)")
    grid.add_argument("--n", default=str(DEFAULT_N), metavar="N[,N...]|auto",
                      help="truncation orders, or auto: every case starts at n = "
                      f"{DEFAULT_N} and climbs (up to --n-max) whenever its spectral tail passes "
                      "--tail-tol")
    grid.add_argument("--seeds", type=int, default=1, metavar="K", help="seeds 0..K-1 per point")
    grid.add_argument("--cases", metavar="FILE", help="CSV/Parquet with columns g0, theta0_deg "
                      "[, n, seed, perturbation, initial, initial_case_id] instead of a grid "
                      "(initial: a point file or results per row, paths relative to FILE; "
                      "theta0_deg then left empty)")
    _add_integration_options(sweep)
    sweep.add_argument("--no-early-stop", action="store_true",
                       help="always integrate to --t-end (default: stop once the shape and tilt "
                       "are steady, see docs/sweeps.md)")
    sweep.add_argument("--snapshots-for", metavar="CASE_IDS", default="",
                       help="case ids (v1,v2,...) whose trajectories are stored as snapshots")
    sweep.add_argument("--snapshots", type=int, default=101, metavar="K",
                       help="states stored of each --snapshots-for trajectory: K equally "
                       "spaced times, both ends included (as run --snapshots)")
    sweep.add_argument("--threads", type=int, default=None, help="threads (default: all cores)")
    sweep.add_argument("--chunk-size", type=int, default=None,
                       help="cases per chunk file (and per Dask task; default "
                       f"{DEFAULT_CHUNK_SIZE}, or {DEFAULT_AUTO_CHUNK_SIZE} with --n auto, "
                       "whose cases take minutes: a SIGKILL loses the unwritten chunks); may "
                       "change on resume")
    sweep.add_argument("--out", metavar="DIR",
                       help="sweep directory, made if absent (required, except with "
                       "--rerun-failed)")
    sweep.add_argument("--figure", metavar="PNG", help="also draw the phase diagram")
    sweep.add_argument("--quiet", action="store_true", help="no progress line, only a summary")
    sweep.add_argument("--progress-every", type=_real, default=30.0, metavar="SECONDS",
                       help="progress line interval when stderr is not a terminal (a log file)")
    where = sweep.add_argument_group("where the cases run (default: this machine's threads)")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="send chunks as tasks to the Dask scheduler at ADDRESS "
                       "(tcp://host:8786); finished chunks come back and are written here")
    where.add_argument("--dask", action="store_true",
                       help="start a Dask LocalCluster here and send chunks to it")
    where.add_argument("--workers", type=int, default=None,
                       help="with --dask: worker processes, at most the cores (default: "
                       "cores / --threads)")
    where.add_argument("--shard", metavar="I/N",
                       help="only chunks k with k %% N == I (0 <= I < N), for job arrays: "
                       "N jobs with the same command and I = the array index fill DIR together")
    where.add_argument("--rerun-failed", metavar="DIR",
                       help="rerun only DIR's failed cases with this command's --method, --rtol "
                       "and --atol; rows replaced, earlier rows kept in DIR/_reruns/ "
                       "(resumable: re-run the same command)")

    stability = commands.add_parser(
        "stability", help="critical q of the translating circle (full linearisation)",
        description="Critical stability parameter q = g0 sin(theta0)/3 of the translating "
        "circle from the full linearisation of loopsim's own equations: the in-plane and "
        "out-of-plane thresholds at truncation --n (docs/stability.md). --paper prints the "
        "paper's operator instead (its q_c = 14.561 rests on a sign error).",
        formatter_class=_HelpFormatter,
    )
    stability.add_argument("--json", action="store_true", help="print one JSON object")
    full = stability.add_argument_group("full linearisation (default)")
    full.add_argument("--n", type=int, default=None,
                      help="truncation order of the full linearisation (>= 3; default: 16)")
    full.add_argument("--theta0", type=_real, default=None, metavar="DEG",
                      help="tilt of the circle in (0, 90] (default: 90; the rates depend on q only)")
    full.add_argument("--w", type=_real, default=None,
                      help=f"length-penalty rate (default: {DEFAULT_W:g})")
    full.add_argument("--q-scan", metavar="START:STOP:NUM|v1,v2,...",
                      help="also the largest growth rate of each sector, the paper's and the "
                      "corrected operator at these q")
    full.add_argument("--g0", type=_real, metavar="G",
                      help="also the spectrum at (G, --theta0): the --top largest eigenvalues "
                      "with sector labels")
    full.add_argument("--top", type=int, default=None,
                      help="eigenvalues listed with --g0 (default: 12)")
    full.add_argument("--onset", type=_real, nargs=3, metavar=("EPS", "T_END", "DETECT"),
                      help="also the q where a mode of size EPS reaches DETECT at T_END, per sector")
    full.add_argument("--figure", metavar="PNG",
                      help="draw growth rates vs q (paper's operator beside the full sectors)")
    paper_group = stability.add_argument_group("the paper's operator (--paper)")
    paper_group.add_argument("--paper", action="store_true",
                             help="the table of the paper's operator for n = 1..--n-max instead")
    paper_group.add_argument("--n-max", type=int, default=None,
                             help="largest truncation order of the --paper table (default: 60)")

    summary = commands.add_parser(
        "summary", help="one row per cell of a sweep: regime probabilities, tilt and aspect "
        "ratio medians, with 95%% intervals",
        description="Summarise a sweep over its seeds: per cell (g0, theta0 and every other "
        "swept input), the number of seeds, resolved and determined rows, each regime's "
        "probability with its Wilson interval, the median and quartiles of the terminal "
        "tilt and aspect ratio with bootstrap intervals of the medians, and the cost "
        "(loopsim/summary.py).",
        formatter_class=_HelpFormatter,
    )
    summary.add_argument("sweep_dir", metavar="SWEEP_DIR", help="a sweep directory")
    summary.add_argument("--out", metavar="FILE.parquet", help="also write the table to Parquet")
    summary.add_argument("--seed", type=int, default=0, help="seed of the bootstrap (>= 0)")
    summary.add_argument("--figure", metavar="PNG",
                         help="also draw P(3D) per cell and the terminal tilt over seeds")

    compare = commands.add_parser(
        "compare", help="do two sweeps of the same cells differ in distribution?",
        description="Per cell of two sweeps (say n = 24 and n = 32, or rtol 1e-6 and 1e-8, "
        "each with several seeds): Kolmogorov-Smirnov tests of the terminal tilt and "
        "aspect ratio, the tilt's Wasserstein distance with a bootstrap interval, a "
        "chi-square test of the regime counts, and a verdict (loopsim/summary.py).",
        formatter_class=_HelpFormatter,
    )
    compare.add_argument("sweep_a", metavar="SWEEP_A", help="a sweep directory")
    compare.add_argument("sweep_b", metavar="SWEEP_B", help="another, of the same cells")
    compare.add_argument("--alpha", type=_real, default=0.05,
                         help="significance level of the verdict (Bonferroni over 3 tests)")
    compare.add_argument("--out", metavar="FILE.parquet", help="also write the table to Parquet")
    compare.add_argument("--seed", type=int, default=0, help="seed of the bootstrap (>= 0)")

    branch = commands.add_parser(
        "branch", help="steady in-plane shapes from the circle's bifurcation, and their stability",
        description="Relative equilibria (shapes that translate without changing) of the "
        "loop in its plane, continued in q = g0 sin(theta0)/3 from the circle's in-plane "
        "threshold, with their aspect ratio and leading in-plane and out-of-plane "
        "eigenvalues (loopsim/stability/branch.py, docs/stability.md).",
        formatter_class=_HelpFormatter,
    )
    branch.add_argument("--n", type=int, default=12, help="Fourier truncation order (>= 4)")
    branch.add_argument("--q-max", type=_real, default=25.0, metavar="Q",
                        help="continue up to this q (> the in-plane threshold 8.9001)")
    branch.add_argument("--json", action="store_true", help="print one JSON object")

    figures = commands.add_parser(
        "figures", help="draw the paper's figures (or corrected counterparts) from Parquet",
        description="Draw the paper's figures from stored results into DIR as PNG: Fig. 3 "
        "(stability, computed), from SWEEP_DIR Figs. 4, 5, 7, 8; from more sweep "
        "directories Fig. 9 (a grid at another n), seed distributions (several seeds of one "
        "point) or a reference overlay (any other); from run files (loopsim run --out) "
        "Fig. 6 and the tension colouring (loopsim/figures.py).",
        formatter_class=_HelpFormatter,
    )
    figures.add_argument("sweep_dir", metavar="SWEEP_DIR", help="the main sweep directory")
    figures.add_argument("paths", nargs="*", metavar="PATH",
                         help="more sweep directories and run files (RUN.parquet)")
    figures.add_argument("--out", required=True, metavar="DIR", help="output directory (made if absent)")
    figures.add_argument("--only", metavar="NAME[,NAME...]",
                         help="draw only these: stability, gallery, phase, q_tilt, aspect, "
                         "phase_n, seeds, evolution, tension")
    figures.add_argument("--gallery-theta0", type=_real, default=30.0, metavar="DEG",
                         help="initial tilt of the Fig. 4 gallery (nearest in the sweep)")
    figures.add_argument("--branch-n", type=int, default=12, metavar="N",
                         help="truncation of the steady branch drawn in Fig. 8")
    figures.add_argument("--no-branch", action="store_true", help="Fig. 8 without the steady branch")
    figures.add_argument("--dpi", type=int, default=110, help="resolution of the PNG files")
    return parser


def _format_summary(summary):
    width = max(len(key) for key in summary)
    lines = []
    for key, value in summary.items():
        text = f"{value:.10g}" if isinstance(value, float) else str(value)
        lines.append(f"{key:<{width}}  {text}")
    return "\n".join(lines)


def _load_initial_for_run(args):
    """(start shape, info, g0) for ``run --initial``; one-line errors for bad combinations."""
    from . import shapes

    if args.theta0 is not None:
        raise ValueError("give --theta0 or --initial, not both (the tilt of an --initial shape "
                         "is measured from it)")
    if args.n not in (None, "auto") and args.n < 1:
        raise ValueError(f"n must be an integer >= 1, got {args.n}")
    x, info = shapes.load_initial(args.initial, None if args.n == "auto" else args.n,
                                  args.case_id)
    g0 = args.g0 if args.g0 is not None else info.get("g0")
    if g0 is None:
        raise ValueError("--g0 is required (only results carry a g0 to continue with)")
    return x, info, g0


def _format_initial(info):
    keys = ("kind", "source", "case_id", "points", "n", "length", "scale", "tilt_deg",
            "aspect_ratio", "spectral_tail", "truncation", "t_final")
    return "\n".join(["# initial shape"] + [
        f"#   {k:<13}  {info[k]:.10g}" if isinstance(info[k], float) else f"#   {k:<13}  {info[k]}"
        for k in keys if k in info])


def _check_auto_options(args, n_start=DEFAULT_N):
    """--n-max and --tail-tol only with --n auto (refused otherwise: they would do
    nothing), --n-max not below the ladder's start; then their defaults filled in."""
    from . import validation

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


def _check_run_sizes(args):
    """--n, --n-max and --snapshots within their documented bounds, before any work."""
    from . import validation

    if args.n not in (None, "auto"):
        validation.check_order("--n", args.n)
    _check_auto_options(args)
    validation.check_count("--snapshots", args.snapshots, 1, validation.MAX_SNAPSHOTS,
                           "each is a step end and a stored state")


def _cmd_run(args):
    try:
        return _run(args)
    except KeyboardInterrupt:  # a Ctrl-C while loading, before the integration's handler
        return _interrupted(2, "the run was stopped; nothing written")


def _run(args):
    import functools

    from . import api, io, sweeps, validation

    _check_run_sizes(args)
    if args.out is not None:
        validation.check_output_file("--out", args.out)
        io.remove_stale_temporaries(os.path.dirname(os.path.abspath(args.out)))
    g0, start, info = args.g0, None, None
    if args.initial is not None:
        start, info, g0 = _load_initial_for_run(args)
    elif args.case_id is not None:
        raise ValueError("--case-id needs --initial RESULTS")
    elif args.theta0 is None or args.g0 is None:
        raise ValueError(f"give {'--g0' if args.g0 is None else '--theta0'} (or --initial FILE)")
    simulate = functools.partial(
        api.simulate, g0, args.theta0, n=args.n, t_span=(0.0, args.t_end),
        snapshots=args.snapshots, rtol=args.rtol, atol=args.atol, w=args.w,
        perturbation=args.perturbation, seed=args.seed, method=args.method, initial=start,
        n_max=args.n_max, tail_tol=args.tail_tol, twin=not args.no_twin)
    for warning in [] if info is None else info["warnings"]:  # the input's, before the run's
        print(f"loopsim: warning: {warning}", file=sys.stderr)
    stop = sweeps.stop_event()
    with sweeps.stop_on_signals(stop):  # the integration in a thread, a signal noticed
        result = sweeps.in_background(stop, simulate)  # within 0.1 s (see _interrupted)
        if result is None:
            return _interrupted(stop.signum, "the run was stopped; nothing written")
        summary = result.summary()
        if info is not None:
            info = dict(info, perturbation=summary["perturbation"])
            result.initial_info = info
        if args.out:  # a signal now waits for the (atomic) write to finish
            table = io.trajectory_table(result, command_line=sys.argv)
            if info is not None:  # the initial shape's diagnostics (scale, source)
                meta = dict(table.schema.metadata or {})
                meta[b"initial"] = json.dumps(info).encode()
                table = table.replace_schema_metadata(meta)
            io.write_table_atomically(table, args.out)
    summary["compile_s"] = result.compile_s
    if args.json:
        print(json.dumps(summary if info is None else dict(summary, initial=info)))
    else:
        print(_format_summary(summary) if info is None
              else _format_initial(info) + "\n" + _format_summary(summary))
    if stop.is_set():
        return _interrupted(stop.signum, "after the run finished; its results are complete"
                            + (f" in {args.out}" if args.out else ""))
    return 0 if result.success else EXIT_FAILED_RUN


def _interrupted(signum, detail):
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
        from ._signals import end_children

        end_children()
        os._exit(status)
    return status



RERUN_OPTIONS = ("method", "rtol", "atol")  # what --rerun-failed takes from the command line


def _parse_shard(text):
    """'I/N' -> (I, N) with 0 <= I < N, or a one-line error."""
    try:
        index, count = (int(part) for part in text.split("/"))
        if not 0 <= index < count:
            raise ValueError
    except ValueError:
        raise ValueError(f"--shard must be I/N with integers 0 <= I < N, got {text!r}") from None
    return index, count


def _sweep_config(args, sweeps):
    from . import validation

    _check_auto_options(args)
    if args.cases:
        if args.g0 or args.theta0:
            raise ValueError("give either --cases or --g0/--theta0, not both")
        orders = [DEFAULT_N] if args.n == "auto" else sweeps.parse_values(args.n, "--n",
                                                                           integer=True)
        cases = sweeps.read_cases_file(args.cases, args.perturbation, orders[0])
    else:
        if not (args.g0 and args.theta0):
            raise ValueError("a sweep needs --g0 and --theta0 (or --cases FILE)")
        if args.seeds < 1:
            raise ValueError(f"--seeds must be >= 1, got {args.seeds}")
        axes = (sweeps.parse_values(args.g0, "--g0"),
                sweeps.parse_values(args.theta0, "--theta0"),
                [DEFAULT_N] if args.n == "auto"
                else sweeps.parse_values(args.n, "--n", integer=True))
        count = math.prod(len(axis) for axis in axes) * args.seeds
        if count > validation.MAX_CASES:
            raise ValueError(f"the grid has {count} cases (--g0 x --theta0 x --n x --seeds), "
                             f"more than a sweep's {validation.MAX_CASES}: split it")
        cases = sweeps.grid_cases(*axes, args.seeds, args.perturbation)
    return sweeps.SweepConfig(cases=cases, t_end=args.t_end, rtol=args.rtol, atol=args.atol,
                              w=args.w, method=args.method or (
                                  "auto" if args.n == "auto" else "rkf45"),
                              twin=not args.no_twin,
                              chunk_size=(args.chunk_size if args.chunk_size is not None
                                          else DEFAULT_AUTO_CHUNK_SIZE if args.n == "auto"
                                          else DEFAULT_CHUNK_SIZE),
                              early_stop=not args.no_early_stop,
                              snapshots_for=sweeps.parse_values(
                                  args.snapshots_for, "--snapshots-for", integer=True)
                              if args.snapshots_for else [],
                              snapshot_count=args.snapshots, n_auto=args.n == "auto",
                              n_max=args.n_max, tail_tol=args.tail_tol)


def _check_rerun_options(args):
    """With --rerun-failed the cases and settings come from DIR: refuse the options that
    would be ignored (given with a value other than their default)."""
    parser = _build_parser()
    defaults = vars(parser.parse_args(["sweep"]))
    ignored = [key for key in ("g0", "theta0", "cases", "n", "seeds", "t_end", "w", "perturbation",
                               "no_early_stop", "snapshots_for", "snapshots", "chunk_size",
                               "shard", "out", "n_max", "tail_tol", "no_twin")
               if getattr(args, key) != defaults[key]]
    if ignored:
        raise ValueError(f"--{ignored[0].replace('_', '-')} does not apply with --rerun-failed "
                         f"(the cases and settings come from the sweep; only "
                         f"{', '.join('--' + k for k in RERUN_OPTIONS)} change)")


def _is_program():
    """Whether this process is the ``loopsim`` command (not a caller of :func:`main`)."""
    from ._signals import is_program

    return is_program()


def _cmd_sweep(args):
    import numba

    from . import plots, sweeps, validation

    if args.figure is not None:
        validation.check_output_file("--figure", args.figure)
    if args.threads is not None and not 1 <= args.threads <= numba.config.NUMBA_NUM_THREADS:
        raise ValueError(f"--threads must be in 1..{numba.config.NUMBA_NUM_THREADS} (the "
                         f"cores Numba may use), got {args.threads}")
    if args.workers is not None:
        if not args.dask:
            raise ValueError(f"--workers needs --dask, got --workers {args.workers} without it")
        validation.check_count("--workers", args.workers, 1, validation.MAX_WORKERS,
                               "this machine's cores: each worker is a process that compiles "
                               "its own kernels, and more than the cores only compete")
    if args.scheduler is not None and args.dask:
        raise ValueError("give --scheduler ADDRESS or --dask, not both")
    if not args.progress_every > 0:
        raise ValueError(f"--progress-every must be > 0, got {args.progress_every:g}")
    backend = dict(threads=args.threads, quiet=args.quiet, command_line=sys.argv,
                   scheduler=args.scheduler, local_cluster=args.dask, workers=args.workers,
                   progress_interval=args.progress_every)
    try:
        if args.rerun_failed is not None:
            _check_rerun_options(args)
            out = args.rerun_failed
            settings = {k: getattr(args, k) for k in RERUN_OPTIONS}
            frame, reran = sweeps.rerun_failed(out, **settings, **backend)
            print(f"reran {reran} failed case(s) with " + ", ".join(
                f"{k} {getattr(args, k)}" for k in RERUN_OPTIONS))
            config = sweeps.SweepConfig(cases=[])
        else:
            if args.out is None:
                raise ValueError("a sweep needs --out DIR (or --rerun-failed DIR)")
            out = validation.check_output_directory("--out", args.out)
            config = _sweep_config(args, sweeps)
            frame = sweeps.run_sweep(config, out, shard=None if args.shard is None
                                     else _parse_shard(args.shard), **backend)
    except KeyboardInterrupt as stopped:  # sweeps.SweepInterrupted, or a Ctrl-C before it
        done = (f"{stopped.done} of {stopped.total} cases done and kept in {stopped.out}; "
                if hasattr(stopped, "done") else "")
        return _interrupted(getattr(stopped, "signum", 2),
                            f"{done}re-run the same command to resume")
    counts = frame["regime"].value_counts().to_dict()
    print(f"{len(frame)} cases in {out}: "
          + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    unresolved = frame[~frame["resolved"]]
    if len(unresolved):
        print(f"{len(unresolved)} of {len(frame)} cases NOT resolved at their n (transient length "
              f"error > {config.thresholds.resolved_length_error:g} or spectral tail along the "
              f"run > {config.thresholds.resolved_tail:g}; column 'resolved'): their "
              f"terminal tilt and shape are not converged; rerun them with "
              + (f"a larger --n-max than {config.n_max} (a cases file of their g0, theta0_deg "
                 f"and seed)" if config.n_auto else "a larger --n or --n auto")
              + " (regimes among them: " + ", ".join(
                  f"{k} {v}" for k, v in sorted(unresolved["regime"].value_counts().items())) + ")")
    undetermined = frame[frame["determined"].eq(False)]
    if len(undetermined):
        print(f"{len(undetermined)} of {len(frame)} cases NOT determined (a twin at 10x "
              "stricter tolerances ends elsewhere; column 'determined'): their terminal tilt "
              "is a sample of an ill-conditioned transient, not an outcome (regimes among "
              "them: " + ", ".join(f"{k} {v}" for k, v in
                                   sorted(undetermined["regime"].value_counts().items())) + ")")
    if args.figure:
        _use_agg()
        plots.save(plots.phase_diagram(frame), args.figure)
        print(f"phase diagram: {args.figure}")
    failed = int((frame["status"] != "ok").sum())
    if failed:
        print(f"{failed} of {len(frame)} cases failed (column 'status'); exit status "
              f"{EXIT_FAILED_RUN}; rerun them with: loopsim sweep --rerun-failed {out} "
              "--method radau5 (or another --rtol)", file=sys.stderr)
        return EXIT_FAILED_RUN
    return 0


FULL_DEFAULTS = dict(n=16, theta0=90.0, w=DEFAULT_W, top=12)
FULL_ONLY = ("n", "theta0", "w", "q_scan", "g0", "top", "onset", "figure")


def _cmd_stability_full(args):
    from . import plots, sweeps, validation
    from .stability import circle, onset, paper

    if args.figure is not None:
        validation.check_output_file("--figure", args.figure)
    if args.n_max is not None:
        raise ValueError("--n-max applies only to the --paper table")
    for key, value in FULL_DEFAULTS.items():
        if getattr(args, key) is None:
            setattr(args, key, value)
    if not 3 <= args.n <= validation.MAX_N:
        raise ValueError(f"--n must be in 3..{validation.MAX_N} for the full linearisation, "
                         f"got {args.n}")
    if not 0.0 < args.theta0 <= 90.0:
        raise ValueError(f"--theta0 must be in (0, 90], got {args.theta0}")
    if args.w <= 0.0:
        raise ValueError(f"--w must be > 0, got {args.w}")
    nan_none = lambda v: None if math.isnan(v) else v  # noqa: E731
    out = {
        "operator": "full", "n": args.n, "theta0_deg": args.theta0, "w": args.w,
        "q_crit_in_plane": nan_none(circle.critical_q(args.n, "in-plane", args.theta0, args.w)),
        "q_crit_out_of_plane": nan_none(circle.critical_q(args.n, "out-of-plane", args.theta0,
                                                          args.w)),
        "q_crit_paper": nan_none(paper.critical_q(args.n)),
        "q_crit_corrected_operator": nan_none(paper.critical_q(args.n, corrected=True)),
    }
    if args.q_scan:
        out["q_scan"] = circle.paper_comparison(
            sweeps.parse_values(args.q_scan, "--q-scan"), args.n, args.theta0, args.w)
    if args.g0 is not None:
        if args.g0 < 0.0:
            raise ValueError(f"--g0 must be >= 0, got {args.g0}")
        spec = circle.full_spectrum(args.g0, args.theta0, args.n, args.w)
        top = (spec.sector != "neutral").nonzero()[0][:max(1, args.top)]
        out["spectrum"] = {
            "g0": args.g0, "q": spec.q, "neutral_modes": int((spec.sector == "neutral").sum()),
            "growth_rate": {s: spec.growth_rate(s) for s in circle.SECTORS},
            "eigenvalues_real": spec.eigenvalues.real[top].tolist(),
            "eigenvalues_imag": spec.eigenvalues.imag[top].tolist(),
            "sector": spec.sector[top].tolist(),
            "out_of_plane_fraction": spec.out_of_plane_fraction[top].tolist(),
        }
    if args.onset:
        eps, t_end, detect = args.onset
        out["onset"] = {"eps": eps, "t_end": t_end, "detect": detect, **{
            f"q_{s.replace('-', '_')}": nan_none(onset.onset_q(
                eps, t_end, detect, args.n, s, args.theta0, args.w)) for s in circle.SECTORS}}
    if args.figure:
        _use_agg()
        plots.save(plots.growth_rates(args.n, theta0_deg=args.theta0, w=args.w), args.figure, dpi=120)
        out["figure"] = args.figure
    if args.json:
        print(json.dumps(out))
        return 0
    print(f"# full linearisation about the translating circle, n = {args.n}, "
          f"theta0 = {args.theta0} deg, w = {args.w}")
    for key in ("q_crit_in_plane", "q_crit_out_of_plane", "q_crit_paper", "q_crit_corrected_operator"):
        print(f"{key:<26}  {'no crossing' if out[key] is None else f'{out[key]:.11f}'}")
    print(f"# q_crit_paper: {paper.SIGN_NOTE}")
    if "q_scan" in out:
        print(f"{'q':>10}  {'in-plane':>12}  {'out-of-plane':>12}  {'corrected':>12}  {'paper':>12}")
        for row in out["q_scan"]:
            print(f"{row['q']:>10.5g}  {row['in_plane']:>12.6g}  {row['out_of_plane']:>12.6g}  "
                  f"{row['corrected']:>12.6g}  {row['paper']:>12.6g}")
    if "spectrum" in out:
        sp = out["spectrum"]
        print(f"# spectrum at g0 = {sp['g0']}, q = {sp['q']:.6g} (largest, "
              f"{sp['neutral_modes']} neutral modes left out)")
        for re, im, sec in zip(sp["eigenvalues_real"], sp["eigenvalues_imag"], sp["sector"]):
            print(f"{re:>16.9g} {im:>+12.4g}i  {sec}")
    if "onset" in out:
        for key, value in out["onset"].items():
            print(f"onset {key:<16}  {value}")
    if args.figure:
        print(f"figure: {args.figure}")
    return 0


def _cmd_stability(args):
    from .stability import paper
    from .validation import MAX_N

    if not args.paper:
        return _cmd_stability_full(args)
    given = [key for key in FULL_ONLY if getattr(args, key) is not None]
    if given:
        raise ValueError(f"--{given[0].replace('_', '-')} applies only to the full linearisation "
                         "(drop --paper)")
    n_max = 60 if args.n_max is None else args.n_max
    if not 1 <= n_max <= MAX_N:  # the table to 128 took 2.5 s; 100 000 never ended
        raise ValueError(f"--n-max must be in 1..{MAX_N}, got {n_max}")
    table = paper.critical_q_table(n_max)
    if args.json:
        print(json.dumps({"operator": "paper", "note": paper.SIGN_NOTE, "critical_q": {
            str(n): (None if math.isnan(q) else q) for n, q in table}}))
    else:
        print("# critical q of the paper's operator L on span{sin ks, k <= n}")
        print(f"# note: {paper.SIGN_NOTE}")
        print(f"{'n':>3}  q_crit")
        for n, q in table:
            print(f"{n:>3}  {'no crossing' if math.isnan(q) else f'{q:.11f}'}")
    return 0


def _cmd_branch(args):
    from .stability import branch

    from . import validation

    validation.check_count("--n", args.n, 4, validation.MAX_BRANCH_N,
                           "the continuation's cost grows like n^3 per point")
    if not args.q_max > 9.0:
        raise ValueError(f"--q-max must be > 9 (the branch starts at q = 8.9001), got {args.q_max}")
    out = branch.branch_summary(args.n, args.q_max, q_min=0.0)
    if args.json:
        print(json.dumps(out))
        return 0
    loss = out["q_loss_out_of_plane"]
    print(f"# steady in-plane shapes, n = {out['n']}, w = {out['w']:g}: bifurcation off the circle "
          f"at q = {out['q_bifurcation']:.9f} (circle's in-plane threshold {out['q_circle']:.9f})")
    print(f"# q_loss_out_of_plane = {'none below --q-max' if loss is None else f'{loss:.6f}'}; "
          "side +1: the half leaving towards q > q_c, -1: the other half, 0: the circle")
    print(f"{'side':>4} {'q':>10} {'aspect':>9} {'in-plane':>11} {'out-of-plane':>13}  stable (in, out)")
    for row in out["branch"]:
        print(f"{row['side']:>4} {row['q']:>10.5f} {row['aspect_ratio']:>9.5f} "
              f"{row['leading_in_plane_real']:>11.5f} {row['leading_out_of_plane_real']:>13.5f}  "
              f"{row['stable_in_plane']!s:>5} {row['stable_out_of_plane']!s:>5}")
    return 0


def _cmd_figures(args):
    _use_agg()
    from . import figures

    only = [v.strip() for v in args.only.split(",") if v.strip()] if args.only else None
    written = figures.write_figures(args.sweep_dir, args.paths, args.out, only=only,
                                    gallery_theta0=args.gallery_theta0, branch_n=args.branch_n,
                                    branch=not args.no_branch, dpi=args.dpi)
    print(f"{len(written)} figures in {args.out}")
    return 0


def _cmd_summary(args):
    from . import io, summary, validation

    validation.check_integer("--seed", args.seed, 0)
    for name, path in (("--out", args.out), ("--figure", args.figure)):
        if path is not None:
            validation.check_output_file(name, path)
    frame = io.read_results(args.sweep_dir)
    table = summary.summarize(frame, seed=args.seed)
    shown = [c for c in table.columns if c in summary.CELL_INPUTS] + [
        "seeds", "determined", "p_stable", "p_in_plane", "p_3d", "p_3d_low", "p_3d_high",
        "tilt_median", "tilt_median_low", "tilt_median_high"]
    _print_and_write(table, args.out, dict(table.attrs["loopsim_summary"],
                                           summary_of=os.path.abspath(args.sweep_dir)), shown)
    if args.figure is not None:
        _use_agg()
        import matplotlib.pyplot as plt

        from . import plots

        fig, axes = plt.subplots(1, 2, figsize=(13.5, 4.2), constrained_layout=True)
        plots.probability_phase_diagram(table, ax=axes[0])
        plots.tilt_distribution(table, frame, ax=axes[1])
        plots.save(fig, args.figure, dpi=150)
        print(f"figure: {args.figure}")
    return 0


def _cmd_compare(args):
    from . import io, summary, validation

    validation.check_integer("--seed", args.seed, 0)
    validation.check_real("--alpha", args.alpha, low=0.0, high=1.0, low_open=True)
    if args.out is not None:
        validation.check_output_file("--out", args.out)
    table = summary.compare(io.read_results(args.sweep_a), io.read_results(args.sweep_b),
                            alpha=args.alpha, seed=args.seed)
    _print_and_write(table, args.out, dict(table.attrs["loopsim_compare"],
                                           compared=[args.sweep_a, args.sweep_b]))
    counts = table["verdict"].value_counts().to_dict()
    print(", ".join(f"{v} cell(s) {k}" for k, v in sorted(counts.items())))
    return 0


def _print_and_write(table, out, meta, shown=None):
    """Print ``table`` (its ``shown`` columns) and write it to ``out`` (Parquet, atomic,
    with loopsim's provenance and ``meta`` in its metadata) when given."""
    import pandas as pd
    import pyarrow as pa

    from . import io

    with pd.option_context("display.width", 160, "display.max_columns", 40):
        print(table[shown or list(table.columns)].to_string(
            index=False, float_format=lambda v: f"{v:.4g}"))
    if out is not None:
        io.write_table_atomically(pa.Table.from_pandas(table, preserve_index=False)
                                  .replace_schema_metadata(io.provenance(**meta)), out)
        print(f"table: {out}")


def _use_agg():
    """Figures from the command line are files: the non-interactive Agg backend."""
    import matplotlib

    matplotlib.use("Agg")


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
    handlers = {"run": _cmd_run, "sweep": _cmd_sweep, "stability": _cmd_stability,
                "branch": _cmd_branch, "figures": _cmd_figures, "summary": _cmd_summary,
                "compare": _cmd_compare}
    try:
        with _one_line_warnings():
            return handlers[args.command](args)
    except (ValueError, OSError) as exc:
        print(f"loopsim: error: {exc}", file=sys.stderr)
        if isinstance(exc, OSError) and exc.errno in ENVIRONMENT_ERRNOS:  # the machine's fault
            return EXIT_ENVIRONMENT
        return EXIT_USAGE


if __name__ == "__main__":
    sys.exit(main())
