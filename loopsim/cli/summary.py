"""``loopsim summary``: one row per cell of a sweep (regime probabilities, medians, with
intervals), printed and optionally written and drawn."""
from ..defaults import PERTURBATION_ENSEMBLE
from .common import HelpFormatter, directory_name, print_and_write, use_agg


def add_parser(commands):
    """The ``summary`` command and its options."""
    summary = commands.add_parser(
        "summary", help="one row per cell of a sweep: regime probabilities, tilt and aspect "
        "ratio medians, with 95%% intervals",
        description="Summarise a sweep over its seeds: per cell (g0, theta0 and every other "
        "swept input), the number of seeds, resolved, determined and steady rows "
        "(determined: empty, unknown, for a sweep run with --no-twin; steady: a terminal "
        "state reached before --t-end, empty for a sweep run with --no-early-stop), each "
        "regime's "
        "probability with its Wilson interval, the median and quartiles of the terminal "
        "tilt and aspect ratio with bootstrap intervals of the medians, how long the loops "
        "took to come to rest (P(at rest by t = 10), the median settling time, the escape "
        "rate; docs/sweeps.md#run-to-rest) and where they rest against the stable branch's "
        "tilt window, and the cost (loopsim/outcome_statistics.py).",
        formatter_class=HelpFormatter,
    )
    summary.add_argument("sweep_dir", metavar="SWEEP_DIR", help="a sweep directory")
    summary.add_argument("--out", metavar="FILE.parquet", help="also write the table to Parquet")
    summary.add_argument("--seed", type=int, default=0, metavar="SEED",
                         help="seed of the bootstrap (>= 0)")
    summary.add_argument("--figure", metavar="PNG",
                         help="also draw the regime probabilities of each cell (a pie "
                         "each), the terminal tilt over seeds and the aspect ratio over the "
                         "steady branch")
    return summary


def command(args):
    from .. import columns, outcome_statistics, storage, validation

    validation.check_integer("--seed", args.seed, 0)
    for name, path in (("--out", args.out), ("--figure", args.figure)):
        if path is not None:
            validation.check_output_file(name, path)
    frame = storage.read_results(args.sweep_dir)
    window = None
    if "stop_reason" in frame and frame["stop_reason"].eq("steady").any():
        from ..stability import rest_window  # where the loops at rest lie

        window = rest_window.window_for(frame)
    table = outcome_statistics.summarize(frame, seed=args.seed, rest_window=window)
    if args.figure is not None:  # refused before anything is written
        from .. import figures

        figures.frame_model(frame)
        figures.check_one_cell_per_point(table)
    shown = [c for c in table.columns if c in outcome_statistics.CELL_INPUTS] + [
        c for c in ("seeds", "determined", "steady") if c in table] + [
        "p_stable", "p_in_plane", "p_3d", "p_3d_low", "p_3d_high",
        "tilt_median", "tilt_median_low", "tilt_median_high"] + [
        c for c in ("at_rest", "p_rest_t10", "t_rest_median", "rest_inside", "rest_below",
                    "rest_outside") if c in table]
    print_and_write(table, args.out, dict(table.attrs["loopsim_summary"],
                                           summary_of=directory_name(args.sweep_dir),
                                           perturbation_ensemble=PERTURBATION_ENSEMBLE),
                    shown, declarations=columns.SUMMARY_COLUMNS)
    if args.figure is not None:
        use_agg()
        figures.save_distribution_figure(table, frame, args.figure)
        print(f"figure: {args.figure}")
    return 0
