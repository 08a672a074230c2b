"""``loopsim compare``: whether two sweeps of the same cells differ in distribution, cell
by cell."""
from .common import HelpFormatter, directory_name, print_and_write, real


def add_parser(commands):
    """The ``compare`` command and its options."""
    compare = commands.add_parser(
        "compare", help="do two sweeps of the same cells differ in distribution?",
        description="Per cell of two sweeps (say n = 24 and n = 32, or rtol 1e-6 and 1e-8, "
        "each with several seeds): Kolmogorov-Smirnov tests of the terminal tilt and "
        "aspect ratio, the tilt's Wasserstein distance with a bootstrap interval, a "
        "chi-square test of the regime counts, and a verdict (loopsim/outcome_statistics.py).",
        formatter_class=HelpFormatter,
    )
    compare.add_argument("sweep_a", metavar="SWEEP_A", help="a sweep directory")
    compare.add_argument("sweep_b", metavar="SWEEP_B", help="another, of the same cells")
    compare.add_argument("--alpha", type=real, default=0.05, metavar="P",
                         help="significance level (a probability) of the verdict (Bonferroni "
                         "over 3 tests)")
    compare.add_argument("--out", metavar="FILE.parquet", help="also write the table to Parquet")
    compare.add_argument("--seed", type=int, default=0, metavar="SEED",
                         help="seed of the bootstrap (>= 0)")
    return compare


def command(args):
    from .. import columns, outcome_statistics, storage, validation

    validation.check_integer("--seed", args.seed, 0)
    validation.check_real("--alpha", args.alpha, low=0.0, high=1.0, low_open=True)
    if args.out is not None:
        validation.check_output_file("--out", args.out)
    table = outcome_statistics.compare(storage.read_results(args.sweep_a),
                                       storage.read_results(args.sweep_b),
                                       alpha=args.alpha, seed=args.seed)
    print_and_write(table, args.out, dict(table.attrs["loopsim_compare"], compared=[
        directory_name(args.sweep_a), directory_name(args.sweep_b)]),
                    declarations=columns.COMPARE_COLUMNS)
    counts = table["verdict"].value_counts().to_dict()
    print(", ".join(f"{v} cell(s) {k}" for k, v in sorted(counts.items())))
    return 0
