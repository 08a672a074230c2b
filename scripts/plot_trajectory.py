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
from loopsim.figures.suite import read_run  # noqa: E402


def main(path, figure):
    try:  # checked as loopsim's own readers check it: a damaged file is named, not drawn
        trajectory, summary = read_run(path)
    except ValueError as exc:
        sys.exit(f"plot_trajectory: error: {exc}")
    title = f"g0 = {summary['g0']:g}, θ0 = {summary['theta0_deg']:g}°, n = {summary['n']}"
    fig = figures.trajectory(trajectory, summary["n"], title)
    figures.save(fig, figure, dpi=150)
    print(f"wrote {figure}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: python scripts/plot_trajectory.py RUN.parquet FIGURE.png")
    main(sys.argv[1], sys.argv[2])
