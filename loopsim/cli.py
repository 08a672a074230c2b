"""Command-line interface: ``loopsim run`` and ``loopsim stability``.

Errors in the input end with one line ``loopsim: error: ...`` on stderr and
exit status 2; a run that fails numerically exits 1 after printing its summary.
"""
import argparse
import json
import math
import sys

from . import __version__
from .config import (
    DEFAULT_ATOL, DEFAULT_N, DEFAULT_PERTURBATION, DEFAULT_RTOL, DEFAULT_SEED,
    DEFAULT_T_END, DEFAULT_W,
)

EXIT_FAILED_RUN = 1
EXIT_USAGE = 2


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
                        help="RMS size of the seeded initial perturbation (0: exact circle)")
    parser.add_argument("--method", default="rkf45", help="time integrator")


def _build_parser():
    parser = _Parser(
        prog="loopsim",
        description="Flexible elastic loops sedimenting in a viscous fluid "
        "(local slender-body theory, spectral in arc length).",
        epilog="Examples:\n  loopsim run --g0 60 --theta0 30\n"
        "  loopsim run --g0 150 --theta0 60 --n 8 --json\n"
        "  loopsim sweep --g0 10:350:8 --theta0 10:90:5 --out runs/phase --figure phase.png\n"
        "  loopsim stability --n-max 20",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"loopsim {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    run = commands.add_parser(
        "run", help="simulate one loop released as a tilted, perturbed circle",
        description="Simulate one loop released as a circle tilted by THETA0 degrees "
        "(plus a seeded perturbation) and print its terminal summary.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    run.add_argument("--g0", type=_real, required=True,
                     help="gravity over bending stiffness, g0 = L^3 g rho_L / (8 pi^3 EI) >= 0")
    run.add_argument("--theta0", type=_real, required=True, metavar="DEG",
                     help="initial tilt of the loop's plane to the horizontal, in [0, 90] degrees")
    run.add_argument("--n", type=int, default=DEFAULT_N, help="Fourier truncation order (>= 1)")
    _add_integration_options(run)
    run.add_argument("--seed", type=int, default=DEFAULT_SEED, help="perturbation seed (>= 0)")
    run.add_argument("--snapshots", type=int, default=2, metavar="K",
                     help="number of equally spaced snapshots stored, ends included")
    run.add_argument("--out", metavar="FILE.parquet",
                     help="write the snapshots (and the summary as metadata) to Parquet")
    run.add_argument("--json", action="store_true", help="print the summary as one JSON object")

    sweep = commands.add_parser(
        "sweep", help="run (or resume) an ensemble over (g0, theta0, n, seed) into Parquet",
        description="Integrate many loops in parallel and write one row per case into "
        "chunk files in DIR. Re-running the same command resumes; results are read with "
        "loopsim.read_results(DIR).",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    grid = sweep.add_argument_group("cases (a grid, or --cases FILE)")
    grid.add_argument("--g0", metavar="START:STOP:NUM|v1,v2,...", help="g0 values")
    grid.add_argument("--theta0", metavar="START:STOP:NUM|v1,v2,...", help="theta0 values (deg)")
    grid.add_argument("--n", default=str(DEFAULT_N), metavar="N[,N...]", help="truncation orders")
    grid.add_argument("--seeds", type=int, default=1, metavar="K", help="seeds 0..K-1 per point")
    grid.add_argument("--cases", metavar="FILE", help="CSV/Parquet with columns g0, theta0_deg "
                      "[, n, seed, perturbation] instead of a grid")
    _add_integration_options(sweep)
    sweep.add_argument("--no-early-stop", action="store_true",
                       help="always integrate to --t-end (default: stop once the shape and tilt "
                       "are steady, see README)")
    sweep.add_argument("--snapshots-for", metavar="CASE_IDS", default="",
                       help="case ids (v1,v2,...) whose trajectories are stored as snapshots")
    sweep.add_argument("--snapshots", type=int, default=101, metavar="K",
                       help="snapshots per selected trajectory")
    sweep.add_argument("--threads", type=int, default=None, help="threads (default: all cores)")
    sweep.add_argument("--chunk-size", type=int, default=32, help="cases per chunk file")
    sweep.add_argument("--out", required=True, metavar="DIR", help="sweep directory")
    sweep.add_argument("--figure", metavar="PNG", help="also draw the phase diagram")
    sweep.add_argument("--quiet", action="store_true", help="no progress line, only a summary")

    stability = commands.add_parser(
        "stability", help="critical q of the paper's linear stability operator",
        description="Critical stability parameter q = g0 sin(theta0)/3 of the paper's "
        "truncated operator L (out-of-plane perturbations), for n = 1..N_MAX.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    stability.add_argument("--n-max", type=int, default=60, help="largest truncation order")
    stability.add_argument("--json", action="store_true", help="print one JSON object")
    return parser


def _format_summary(summary):
    width = max(len(key) for key in summary)
    lines = []
    for key, value in summary.items():
        text = f"{value:.10g}" if isinstance(value, float) else str(value)
        lines.append(f"{key:<{width}}  {text}")
    return "\n".join(lines)


def _cmd_run(args):
    from . import api, io

    result = api.simulate(
        args.g0, args.theta0, n=args.n, t_span=(0.0, args.t_end), snapshots=args.snapshots,
        rtol=args.rtol, atol=args.atol, w=args.w, perturbation=args.perturbation,
        seed=args.seed, method=args.method,
    )
    summary = result.summary()
    if args.out:
        io.write_trajectory(result, args.out, command_line=sys.argv)
    print(json.dumps(summary) if args.json else _format_summary(summary))
    return 0 if result.ok else EXIT_FAILED_RUN


def _cmd_sweep(args):
    from . import ensemble, figures

    if args.cases:
        if args.g0 or args.theta0:
            raise ValueError("give either --cases or --g0/--theta0, not both")
        orders = ensemble.parse_values(args.n, "--n", integer=True)
        cases = ensemble.read_cases_file(args.cases, args.perturbation, orders[0])
    else:
        if not (args.g0 and args.theta0):
            raise ValueError("a sweep needs --g0 and --theta0 (or --cases FILE)")
        if args.seeds < 1:
            raise ValueError(f"--seeds must be >= 1, got {args.seeds}")
        cases = ensemble.grid_cases(
            ensemble.parse_values(args.g0, "--g0"), ensemble.parse_values(args.theta0, "--theta0"),
            ensemble.parse_values(args.n, "--n", integer=True), args.seeds, args.perturbation)
    if args.threads is not None and args.threads < 1:
        raise ValueError(f"--threads must be >= 1, got {args.threads}")
    config = ensemble.SweepConfig(cases=cases, t_end=args.t_end, rtol=args.rtol, atol=args.atol,
                                  w=args.w, method=args.method, chunk_size=args.chunk_size,
                                  early_stop=not args.no_early_stop,
                                  snapshots_for=ensemble.parse_values(
                                      args.snapshots_for, "--snapshots-for", integer=True)
                                  if args.snapshots_for else [],
                                  snapshot_count=args.snapshots)
    frame = ensemble.run_sweep(config, args.out, threads=args.threads, quiet=args.quiet,
                               command_line=sys.argv)
    counts = frame["regime"].value_counts().to_dict()
    print(f"{len(frame)} cases in {args.out}: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    if args.figure:
        figures.phase_diagram(frame, args.figure)
        print(f"phase diagram: {args.figure}")
    return 0


def _cmd_stability(args):
    from . import linear_stability

    if args.n_max < 1:
        raise ValueError(f"--n-max must be >= 1, got {args.n_max}")
    table = linear_stability.critical_q_table(args.n_max)
    if args.json:
        print(json.dumps({"operator": "paper", "critical_q": {
            str(n): (None if math.isnan(q) else q) for n, q in table}}))
    else:
        print("# critical q of the paper's operator L on span{sin ks, k <= n}")
        print(f"{'n':>3}  q_crit")
        for n, q in table:
            print(f"{n:>3}  {'no crossing' if math.isnan(q) else f'{q:.11f}'}")
    return 0


def main(argv=None):
    parser = _build_parser()
    args = parser.parse_args(argv)
    handlers = {"run": _cmd_run, "sweep": _cmd_sweep, "stability": _cmd_stability}
    try:
        return handlers[args.command](args)
    except (ValueError, OSError) as exc:
        print(f"loopsim: error: {exc}", file=sys.stderr)
        return EXIT_USAGE


if __name__ == "__main__":
    sys.exit(main())
