"""``loopsim figures``: the paper's figures (or corrected counterparts) drawn from stored
results."""
from .common import HelpFormatter, real, use_agg


def add_parser(commands):
    """The ``figures`` command and its options."""
    figures = commands.add_parser(
        "figures", help="draw the paper's figures (or corrected counterparts) from Parquet",
        description="Draw the paper's figures from stored results into DIR as PNG: Fig. 3 "
        "(stability, computed), from SWEEP_DIR Figs. 4, 5, 7, 8; from more sweep "
        "directories Fig. 9 (a grid at another n), seed distributions (several seeds of one "
        "point) or a reference overlay (any other); from run files (loopsim run --out) "
        "Fig. 6 and the tension colouring (loopsim/figures/).",
        formatter_class=HelpFormatter,
    )
    figures.add_argument("sweep_dir", metavar="SWEEP_DIR", help="the main sweep directory")
    figures.add_argument("paths", nargs="*", metavar="PATH",
                         help="more sweep directories and run files (RUN.parquet)")
    figures.add_argument("--out", required=True, metavar="DIR", help="output directory (made if absent)")
    figures.add_argument("--only", metavar="NAME[,NAME...]",
                         help="draw only these: stability, gallery, phase, q_tilt, aspect, "
                         "phase_n, seeds, evolution, tension")
    figures.add_argument("--gallery-theta0", type=real, default=30.0, metavar="DEG",
                         help="initial tilt of the Fig. 4 gallery (nearest in the sweep)")
    figures.add_argument("--branch-n", type=int, default=12, metavar="N",
                         help="truncation of the steady branch drawn in Fig. 8")
    figures.add_argument("--no-branch", action="store_true", help="Fig. 8 without the steady branch")
    figures.add_argument("--dpi", type=int, default=110, help="resolution of the PNG files")
    return figures


def command(args):
    use_agg()
    from .. import figures

    only = [v.strip() for v in args.only.split(",") if v.strip()] if args.only else None
    written = figures.write_figures(args.sweep_dir, args.paths, args.out, only=only,
                                    gallery_theta0=args.gallery_theta0, branch_n=args.branch_n,
                                    branch=not args.no_branch, dpi=args.dpi)
    print(f"{len(written)} figures in {args.out}")
    return 0
