"""``loopsim animate``: a GIF or MP4 of one run's stored snapshots."""
from .common import HelpFormatter, use_agg


def add_parser(commands):
    """The ``animate`` command and its options."""
    from ..render_defaults import (
        ANIMATION_DPI as DPI, ANIMATION_DPI_RANGE, ANIMATION_FPS as FPS, ANIMATION_FRAMES as FRAMES,
        ANIMATION_MAX_FPS as MAX_FPS, ANIMATION_MAX_FRAMES as MAX_FRAMES,
    )

    MIN_DPI, MAX_DPI = ANIMATION_DPI_RANGE
    animate = commands.add_parser(
        "animate", help="a GIF (or MP4) of one run: the loop coloured by tension, its tilt "
        "and aspect ratio against time",
        description="Animate one run: the loop in 3D in the frame falling with its centre "
        "of mass, coloured by the axial force N = T + |x''|^2, with its shadows on the floor "
        "and on the y-z wall (the tilt seen edge-on); beside it the tilt and the aspect "
        "ratio against time with a moving marker, and the time stamp.  The frames are the "
        "run's stored snapshots (no interpolation between them): store many (loopsim run "
        "--snapshots 80 --out RUN.parquet, or sweep --snapshots 80 --snapshots-for K).  GIF "
        "through Pillow; MP4 needs ffmpeg on PATH (loopsim/figures/animation.py).",
        formatter_class=HelpFormatter,
    )
    animate.add_argument("run", metavar="RUN",
                         help="a run file (loopsim run --out) or a sweep directory (with "
                         "--case-id)")
    animate.add_argument("--out", required=True, metavar="FILE.gif|FILE.mp4",
                         help="the animation to write (atomically)")
    animate.add_argument("--case-id", type=int, default=None, metavar="K",
                         help="with a sweep directory: the case (recorded with --snapshots-for)")
    animate.add_argument("--frames", type=int, default=FRAMES, metavar="K",
                         help=f"most frames: evenly spaced stored snapshots (2..{MAX_FRAMES})")
    animate.add_argument("--fps", type=int, default=FPS,
                         help=f"frames per second (1..{MAX_FPS})")
    animate.add_argument("--dpi", type=int, default=DPI,
                         help=f"dots per inch of the 8.4 x 3.8 inch frames ({MIN_DPI}..{MAX_DPI})")
    return animate


def command(args):
    use_agg()
    from ..figures import animation

    written = animation.animate(args.run, args.out, case_id=args.case_id, frames=args.frames,
                                fps=args.fps, dpi=args.dpi)
    print(f"{written} frames: {args.out}")
    return 0
