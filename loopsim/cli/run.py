"""``loopsim run``: one loop from a tilted circle (or a shape from a file), its summary
printed and its snapshots optionally written."""
import argparse
import json
import sys

from ..defaults import DEFAULT_N, DEFAULT_SEED
from .common import (
    EXIT_FAILED_RUN, HelpFormatter, add_integration_options, check_auto_options, interrupted,
    real,
)


def _order(text):
    """A truncation order (argparse type): an integer, or 'auto'."""
    if text == "auto":
        return text
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer or 'auto': {text!r}") from None


def add_parser(commands):
    """The ``run`` command and its options."""
    run = commands.add_parser(
        "run", help="simulate one loop released as a tilted, perturbed circle",
        description="Simulate one loop released as a circle tilted by THETA0 degrees "
        "(plus a seeded perturbation) and print its terminal summary.",
        formatter_class=HelpFormatter,
    )
    run.add_argument("--g0", type=real,
                     help="gravity over bending stiffness, g0 = L^3 g rho_L / (8 pi^3 EI) >= 0, "
                     "dimensionless (required, except when continuing from results: then their "
                     "g0)")
    run.add_argument("--theta0", type=real, metavar="DEG",
                     help="initial tilt of the loop's plane to the horizontal, in [0, 90] degrees "
                     "(not with --initial: the tilt is measured)")
    run.add_argument("--n", type=_order, default="auto", metavar="N|auto",
                     help="Fourier truncation order (1..128), or auto: start at n = "
                     f"{DEFAULT_N} (an --initial shape: at the order its content needs) and "
                     "restart the run from t = 0 at the next order whenever the spectral tail "
                     "passes --tail-tol (the paper's scheme: --n 6 --method rkf45)")
    run.add_argument("--initial", metavar="FILE|DIR",
                     help="start from a shape: a CSV/Parquet point file (columns x, y, z, in "
                     "order along the closed curve) or results (run --out file, sweep dir)")
    run.add_argument("--case-id", type=int, default=None, metavar="K",
                     help="with --initial results: the case whose terminal shape starts the run")
    add_integration_options(run)
    run.set_defaults(perturbation=None)
    run.add_argument("--seed", type=int, default=DEFAULT_SEED, metavar="SEED",
                     help="perturbation seed (>= 0)")
    run.add_argument("--snapshots", type=int, default=2, metavar="K",
                     help="states stored of the trajectory: K equally spaced times, both "
                     "ends included (as sweep --snapshots; here the start and the end by "
                     "default)")
    run.add_argument("--out", metavar="FILE.parquet",
                     help="write the snapshots (and the summary as metadata) to Parquet")
    run.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    return run


def _format_summary(summary):
    width = max(len(key) for key in summary)
    lines = []
    for key, value in summary.items():
        text = f"{value:.10g}" if isinstance(value, float) else str(value)
        lines.append(f"{key:<{width}}  {text}")
    return "\n".join(lines)


def _load_initial_for_run(args):
    """(start shape, info, g0) for ``run --initial``; one-line errors for bad combinations."""
    from .. import shapes

    if args.theta0 is not None:
        raise ValueError("give --theta0 or --initial, not both (the tilt of an --initial shape "
                         "is measured from it)")
    if args.n != "auto" and args.n < 1:
        raise ValueError(f"n must be an integer >= 1, got {args.n}")
    n = args.n
    if n == "auto":  # a point file at the order its content needs; results at their own
        from .. import api, models

        n = shapes.auto_start_order(args.initial, args.case_id, high=api.ladder_top(
            models.choose(args.model, args.slenderness), args.n_max))
    x, info = shapes.load_initial(args.initial, n, args.case_id)
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


def _check_run_sizes(args):
    """--n, --n-max and --snapshots within their documented bounds, before any work."""
    from .. import validation

    if args.n != "auto":
        validation.check_order("--n", args.n)
    check_auto_options(args)
    validation.check_count("--snapshots", args.snapshots, 1, validation.MAX_SNAPSHOTS,
                           "each is a step end and a stored state")


def command(args):
    try:
        return _run(args)
    except KeyboardInterrupt:  # a Ctrl-C while loading, before the integration's handler
        return interrupted(2, "the run was stopped; nothing written")


def _run(args):
    import functools

    from .. import api, storage, sweeps, validation

    _check_run_sizes(args)
    if args.out is not None:
        validation.check_output_file("--out", args.out)
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
        n_max=args.n_max, tail_tol=args.tail_tol, twin=not args.no_twin, model=args.model,
        slenderness=args.slenderness)
    for warning in [] if info is None else info["warnings"]:  # the input's, before the run's
        print(f"loopsim: warning: {warning}", file=sys.stderr)
    stop = sweeps.stop_event()
    with sweeps.stop_on_signals(stop):  # the integration in a thread, a signal noticed
        result = sweeps.in_background(stop, simulate)  # within 0.1 s (see interrupted)
        if result is None:
            return interrupted(stop.signum, "the run was stopped; nothing written")
        summary = result.summary()
        if info is not None:
            info = dict(info, perturbation=summary["perturbation"])
            result.initial_info = info
        if args.out:  # a signal now waits for the (atomic) write to finish
            table = storage.trajectory_table(result, command_line=sys.argv)
            if info is not None:  # the initial shape's diagnostics (scale, source)
                meta = dict(table.schema.metadata or {})
                meta[b"initial"] = json.dumps(info).encode()
                table = table.replace_schema_metadata(meta)
            storage.write_table_atomically(table, args.out)
    summary["compile_s"] = result.compile_s
    if args.json:
        print(json.dumps(summary if info is None else dict(summary, initial=info)))
    else:
        print(_format_summary(summary) if info is None
              else _format_initial(info) + "\n" + _format_summary(summary))
    if stop.is_set():
        return interrupted(stop.signum, "after the run finished; its results are complete"
                            + (f" in {args.out}" if args.out else ""))
    return 0 if result.success else EXIT_FAILED_RUN
