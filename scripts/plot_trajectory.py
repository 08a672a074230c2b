"""Plot a trajectory written by ``loopsim run --out FILE.parquet``.

Usage: python scripts/plot_trajectory.py RUN.parquet FIGURE.png

Left: side views (x-z plane of the loop's own drift-free frame) of the
snapshots, coloured by time; right: tilt and aspect ratio against time.
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pyarrow.parquet as pq  # noqa: E402

from loopsim import io, spectral  # noqa: E402


def main(path, figure):
    table = pq.read_table(path).to_pandas()
    summary = io.read_metadata(path)["summary"]
    n = summary["n"]
    s = np.linspace(0, 2 * np.pi, 200)
    fig, (ax_shape, ax_time) = plt.subplots(1, 2, figsize=(9, 3.8), constrained_layout=True)
    colours = plt.cm.viridis(np.linspace(0, 1, len(table)))
    for colour, coeffs in zip(colours, table["x"]):
        x = np.asarray(coeffs).reshape(3, 2 * n + 1)
        points = spectral.evaluate(x - x[:, :1], s)  # centred on the centre of mass
        ax_shape.plot(points[1], points[2], color=colour, lw=1)
    ax_shape.set(xlabel="y (centred)", ylabel="z (centred)", aspect="equal",
                 title=f"g0 = {summary['g0']:g}, θ0 = {summary['theta0_deg']:g}°, n = {n}")
    ax_time.plot(table["t"], table["theta_deg"], label="tilt θ (deg)")
    ax_ratio = ax_time.twinx()
    ax_ratio.plot(table["t"], table["aspect_ratio"], color="C1", label="aspect ratio")
    ax_time.set(xlabel="t", ylabel="tilt θ (deg)")
    ax_ratio.set_ylabel("aspect ratio (variances)", color="C1")
    fig.savefig(figure, dpi=150)
    print(f"wrote {figure}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: python scripts/plot_trajectory.py RUN.parquet FIGURE.png")
    main(sys.argv[1], sys.argv[2])
