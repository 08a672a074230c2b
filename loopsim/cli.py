"""Command-line interface: ``loopsim run``, ``loopsim sweep`` and ``loopsim stability``.

Errors in the input end with one line ``loopsim: error: ...`` on stderr and
exit status 2; a run that fails numerically exits 1 after printing its summary.
"""
import argparse
import json
import math
import sys

from ._version import __version__
from .config import (
    RESOLVED_LENGTH_ERROR, RESOLVED_TAIL, DEFAULT_ATOL, DEFAULT_N, DEFAULT_PERTURBATION, DEFAULT_RTOL, DEFAULT_SEED,
    DEFAULT_T_END, DEFAULT_W,
)

from .integrators import METHODS  # noqa: E402 - the names only; no kernel is compiled here

EXIT_FAILED_RUN = 1
EXIT_USAGE = 2


class _HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Shows each option's default once: not for flags, None, or help that names its own."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "default" in text or action.default in (None, False, argparse.SUPPRESS):
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
                        f"default {DEFAULT_PERTURBATION:g}, or 0 with --initial)")
    parser.add_argument("--method", default="rkf45", choices=sorted(METHODS),
                        help="time integrator: rkf45 (explicit, the paper's) or radau5 "
                        "(implicit, for stiff stable and in-plane loops)")


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
    run.add_argument("--n", type=int, default=None,
                     help=f"Fourier truncation order (>= 1; default {DEFAULT_N}, or the stored "
                     "order of --initial results)")
    run.add_argument("--initial", metavar="FILE|DIR",
                     help="start from a shape: a CSV/Parquet point file (columns x, y, z, in "
                     "order along the closed curve) or results (run --out file, sweep dir)")
    run.add_argument("--case-id", type=int, default=None, metavar="K",
                     help="with --initial results: the case whose terminal shape starts the run")
    _add_integration_options(run)
    run.set_defaults(perturbation=None)
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
        formatter_class=_HelpFormatter,
    )
    grid = sweep.add_argument_group("cases (a grid, or --cases FILE)")
    grid.add_argument("--g0", metavar="START:STOP:NUM|v1,v2,...", help="g0 values")
    grid.add_argument("--theta0", metavar="START:STOP:NUM|v1,v2,...", help="theta0 values (deg)")
    grid.add_argument("--n", default=str(DEFAULT_N), metavar="N[,N...]", help="truncation orders")
    grid.add_argument("--seeds", type=int, default=1, metavar="K", help="seeds 0..K-1 per point")
    grid.add_argument("--cases", metavar="FILE", help="CSV/Parquet with columns g0, theta0_deg "
                      "[, n, seed, perturbation, initial, initial_case_id] instead of a grid "
                      "(initial: a point file or results per row, paths relative to FILE; "
                      "theta0_deg then left empty)")
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
                      help="truncation order of the full linearisation (>= 3; default 16)")
    full.add_argument("--theta0", type=_real, default=None, metavar="DEG",
                      help="tilt of the circle in (0, 90] (default 90; the rates depend on q only)")
    full.add_argument("--w", type=_real, default=None,
                      help=f"length-penalty rate (default {DEFAULT_W:g})")
    full.add_argument("--q-scan", metavar="START:STOP:NUM|v1,v2,...",
                      help="also the largest growth rate of each sector, the paper's and the "
                      "corrected operator at these q")
    full.add_argument("--g0", type=_real, metavar="G",
                      help="also the spectrum at (G, --theta0): the --top largest eigenvalues "
                      "with sector labels")
    full.add_argument("--top", type=int, default=None,
                      help="eigenvalues listed with --g0 (default 12)")
    full.add_argument("--onset", type=_real, nargs=3, metavar=("EPS", "T_END", "DETECT"),
                      help="also the q where a mode of size EPS reaches DETECT at T_END, per sector")
    full.add_argument("--figure", metavar="PNG",
                      help="draw growth rates vs q (paper's operator beside the full sectors)")
    paper_group = stability.add_argument_group("the paper's operator (--paper)")
    paper_group.add_argument("--paper", action="store_true",
                             help="the table of the paper's operator for n = 1..--n-max instead")
    paper_group.add_argument("--n-max", type=int, default=None,
                             help="largest truncation order of the --paper table (default 60)")
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
    if args.n is not None and args.n < 1:
        raise ValueError(f"n must be an integer >= 1, got {args.n}")
    x, info = shapes.load_initial(args.initial, args.n, args.case_id)
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


def _cmd_run(args):
    from . import api, ensemble, io, validation

    if args.out is not None:
        validation.check_output_file("--out", args.out)
    g0, start, info = args.g0, None, None
    if args.initial is not None:
        start, info, g0 = _load_initial_for_run(args)
    elif args.case_id is not None:
        raise ValueError("--case-id needs --initial RESULTS")
    elif args.theta0 is None or args.g0 is None:
        raise ValueError(f"give {'--g0' if args.g0 is None else '--theta0'} (or --initial FILE)")
    result = api.simulate(
        g0, args.theta0, n=args.n, t_span=(0.0, args.t_end), snapshots=args.snapshots,
        rtol=args.rtol, atol=args.atol, w=args.w, perturbation=args.perturbation,
        seed=args.seed, method=args.method, initial=start,
    )
    summary = result.summary()
    if info is not None:
        info = dict(info, perturbation=summary["perturbation"])
        result.initial_info = info
        for warning in info["warnings"]:
            print(f"loopsim: warning: {warning}", file=sys.stderr)
    if not ensemble.Thresholds().resolved(result.length_error_max, summary["spectral_tail"]):
        print(f"loopsim: warning: not resolved at n = {summary['n']} (length error up to "
              f"{result.length_error_max:.2g}, limit {RESOLVED_LENGTH_ERROR:g}; terminal spectral "
              f"tail {summary['spectral_tail']:.2g}, limit {RESOLVED_TAIL:g}): the terminal tilt "
              "and shape are not converged; increase --n", file=sys.stderr)
    if args.out and info is None:
        io.write_trajectory(result, args.out, command_line=sys.argv)
    elif args.out:  # the initial shape's diagnostics (scale, source) as metadata "initial"
        table = io.trajectory_table(result, command_line=sys.argv)
        meta = dict(table.schema.metadata or {})
        meta[b"initial"] = json.dumps(info).encode()
        io.write_table_atomically(table.replace_schema_metadata(meta), args.out)
    if args.json:
        print(json.dumps(summary if info is None else dict(summary, initial=info)))
    else:
        print(_format_summary(summary) if info is None
              else _format_initial(info) + "\n" + _format_summary(summary))
    return 0 if result.success else EXIT_FAILED_RUN


def _cmd_sweep(args):
    import numba

    from . import ensemble, plots, validation

    if args.figure is not None:
        validation.check_output_file("--figure", args.figure)
    if args.threads is not None and not 1 <= args.threads <= numba.config.NUMBA_NUM_THREADS:
        raise ValueError(f"--threads must be in 1..{numba.config.NUMBA_NUM_THREADS} (the "
                         f"cores Numba may use), got {args.threads}")
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
    unresolved = frame[~frame["resolved"]]
    if len(unresolved):
        print(f"{len(unresolved)} of {len(frame)} cases NOT resolved at their n (transient length "
              f"error > {config.thresholds.resolved_length_error:g} or terminal spectral tail > "
              f"{config.thresholds.resolved_tail:g}; column 'resolved'): their "
              f"terminal tilt and shape are not converged; rerun them with a larger --n "
              f"(regimes among them: " + ", ".join(
                  f"{k} {v}" for k, v in sorted(unresolved["regime"].value_counts().items())) + ")")
    if args.figure:
        _use_agg()
        plots.save(plots.phase_diagram(frame), args.figure)
        print(f"phase diagram: {args.figure}")
    return 0


FULL_DEFAULTS = dict(n=16, theta0=90.0, w=DEFAULT_W, top=12)
FULL_ONLY = ("n", "theta0", "w", "q_scan", "g0", "top", "onset", "figure")


def _cmd_stability_full(args):
    from . import ensemble, plots, validation
    from .stability import circle, onset, paper

    if args.figure is not None:
        validation.check_output_file("--figure", args.figure)
    if args.n_max is not None:
        raise ValueError("--n-max applies only to the --paper table")
    for key, value in FULL_DEFAULTS.items():
        if getattr(args, key) is None:
            setattr(args, key, value)
    if args.n < 3:
        raise ValueError(f"--n must be >= 3 for the full linearisation, got {args.n}")
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
            ensemble.parse_values(args.q_scan, "--q-scan"), args.n, args.theta0, args.w)
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

    if not args.paper:
        return _cmd_stability_full(args)
    given = [key for key in FULL_ONLY if getattr(args, key) is not None]
    if given:
        raise ValueError(f"--{given[0].replace('_', '-')} applies only to the full linearisation "
                         "(drop --paper)")
    n_max = 60 if args.n_max is None else args.n_max
    if n_max < 1:
        raise ValueError(f"--n-max must be >= 1, got {n_max}")
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


def _use_agg():
    """Figures from the command line are files: the non-interactive Agg backend."""
    import matplotlib

    matplotlib.use("Agg")


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
