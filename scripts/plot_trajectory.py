"""Plot a trajectory written by ``loopsim run --out FILE.parquet``.

Usage: python scripts/plot_trajectory.py RUN.parquet FIGURE.png

Left: the snapshots seen face-on (projected on the last shape's principal plane),
centred on the centre of mass, coloured by time with a colour bar; right: tilt and
aspect ratio against time (``loopsim.figures.trajectory``).
"""
import sys

import matplotlib

matplotlib.use("Agg")

import pyarrow.parquet as pq  # noqa: E402

from loopsim import figures, storage  # noqa: E402


def main(path, figure):
    summary = storage.read_metadata(path)["summary"]
    title = f"g0 = {summary['g0']:g}, θ0 = {summary['theta0_deg']:g}°, n = {summary['n']}"
    fig = figures.trajectory(pq.read_table(path).to_pandas(), summary["n"], title)
    figures.save(fig, figure, dpi=150)
    print(f"wrote {figure}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: python scripts/plot_trajectory.py RUN.parquet FIGURE.png")
    main(sys.argv[1], sys.argv[2])
