"""Plot a trajectory written by ``loopsim run --out FILE.parquet``.

Usage: python scripts/plot_trajectory.py RUN.parquet FIGURE.png

Left: the snapshots seen face-on (projected on the last shape's principal plane),
centred on the centre of mass, coloured by time with a colour bar; right: tilt and
aspect ratio against time (``loopsim.figures.trajectory``).
"""
import sys

import matplotlib

matplotlib.use("Agg")

from loopsim import figures  # noqa: E402
from loopsim.figures.suite import read_run, run_title  # noqa: E402


def main(path, figure):
    try:  # checked as loopsim's own readers check it: a damaged file is named, not drawn
        trajectory, summary = read_run(path)
    except ValueError as exc:
        sys.exit(f"plot_trajectory: error: {exc}")
    # the snapshots are stored at the order the run ended at (n_used), which with --n auto
    # is not the starting n: figures.trajectory reads it from the coefficients themselves
    fig = figures.trajectory(trajectory, title=run_title(summary))
    figures.save(fig, figure, dpi=150)
    print(f"wrote {figure}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: python scripts/plot_trajectory.py RUN.parquet FIGURE.png")
    main(sys.argv[1], sys.argv[2])
