"""Publication-style figures from result tables (reads data, never computes dynamics)."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from . import full_stability, linear_stability  # noqa: E402

REGIME_STYLE = {
    "stable": dict(color="#3b0f70", marker="o", label="stable"),
    "in-plane": dict(color="#21918c", marker="s", label="in-plane"),
    "3d": dict(color="#f0c419", marker="^", label="3D"),
    "failed": dict(color="#d62728", marker="x", label="failed"),
}


def phase_diagram(frame, path, n=None):
    """g0 against θ0 coloured by regime, with the curves g0 = 3 q_c / sin θ0 of the
    paper's linear stability (q_c = 14.561) and of the full linearisation of the
    circle at the sweep's truncation (in-plane q_c ≈ 8.90, out-of-plane ≈ 10.65)."""
    q_crit = linear_stability.critical_q(20)
    order = int(frame["n"].max())
    fig, ax = plt.subplots(figsize=(6.6, 4.0), constrained_layout=True)
    for regime, style in REGIME_STYLE.items():
        rows = frame[frame["regime"] == regime]
        if len(rows):
            ax.scatter(rows["theta0_deg"], rows["g0"], s=22, linewidths=1.2, **style)
    theta = np.linspace(1.0, 90.0, 300)
    ax.plot(theta, 3 * q_crit / np.sin(np.radians(theta)), "k-", lw=1.2,
            label=f"paper's linear\nstability, q = {q_crit:.3f}")
    for sector, style in (("in-plane", "--"), ("out-of-plane", ":")):
        q_sector = full_stability.critical_q(max(order, 3), sector)
        ax.plot(theta, 3 * q_sector / np.sin(np.radians(theta)), "k", ls=style, lw=1.2,
                label=f"full linearisation,\n{sector}, q = {q_sector:.3f}")
    ax.set_xlim(0, 92)
    ax.set_ylim(0, 1.05 * frame["g0"].max())
    ax.set_xlabel(r"initial tilt $\theta_0$ (deg)")
    ax.set_ylabel(r"$g_0$ (gravity / stiffness)")
    orders = sorted(frame["n"].unique())
    ax.set_title(f"sedimentation regimes, n = {', '.join(map(str, orders))}, "
                 f"t = {frame['t_end'].max():g}", fontsize=10)
    ax.legend(fontsize=8, frameon=False, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.savefig(path, dpi=200)
    plt.close(fig)
