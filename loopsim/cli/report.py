"""``loopsim report``: one self-contained HTML page of a sweep directory."""
from .common import HelpFormatter, use_agg


def add_parser(commands):
    """The ``report`` command and its options."""
    from ..render_defaults import REPORT_COSTLIEST

    report = commands.add_parser(
        "report", help="one self-contained HTML page of a sweep: provenance, counts, "
        "phase diagram, failures, cost, per-cell table",
        description="Write one HTML file that shows what a sweep directory holds: its "
        "command and provenance (version, creation times, machine), the counts by regime, "
        "resolved and determined (as the sweep's closing lines), the phase diagram (for "
        "--seeds auto directories the regime probabilities and distribution panels), the "
        "failed cases with the rerun command, the costliest cases and the total cost, and "
        "the per-cell table of 'loopsim summary'.  Images are embedded as data URIs: the "
        "file needs no network and no JavaScript (loopsim/sweep_report.py).",
        formatter_class=HelpFormatter,
    )
    report.add_argument("sweep_dir", metavar="SWEEP_DIR", help="a sweep directory")
    report.add_argument("--out", required=True, metavar="FILE.html",
                        help="the HTML file to write (atomically)")
    report.add_argument("--seed", type=int, default=0,
                        help="seed of the per-cell table's bootstrap (>= 0, as summary --seed)")
    report.add_argument("--costliest", type=int, default=REPORT_COSTLIEST, metavar="K",
                        help="how many of the costliest cases to list (>= 1)")
    return report


def command(args):
    from .. import sweep_report, validation

    validation.check_integer("--seed", args.seed, 0)
    validation.check_integer("--costliest", args.costliest, 1)
    validation.check_output_file("--out", args.out)
    use_agg()
    sweep_report.report(args.sweep_dir, args.out, seed=args.seed, costliest=args.costliest)
    print(f"report: {args.out}")
    return 0
