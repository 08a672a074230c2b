"""The nonlocal model beside the local one: thresholds against ε, outcomes side by side."""
import matplotlib.pyplot as plt
import numpy as np

from .. import models
from ..stability import full_linear
from .style import REGIME_STYLE, frame_model, order_column, orders_text, single_axes


def nonlocal_thresholds(eps_values=(1e-2, 3e-3, 1e-3, 1e-4, 1e-6, 1e-9, 1e-12), n=8, ax=None):
    """Critical q of the translating circle (θ0 = 90°, in-plane and out-of-plane) under
    nonlocal SBT against the slenderness ε, with the local model's thresholds (ε → 0)."""
    fig, ax = single_axes(ax, (6.4, 4.2))
    eps = np.sort(np.asarray(eps_values, dtype=float))
    for sector, color in (("in-plane", "C3"), ("out-of-plane", "C0")):
        local = full_linear.critical_q(n, sector)
        q = [full_linear.critical_q(n, sector, model=models.choose("nonlocal", e)) for e in eps]
        ax.semilogx(eps, q, "o-", color=color, label=f"nonlocal SBT, {sector}")
        ax.axhline(local, color=color, ls="--", lw=1.0, label=f"local SBT, {sector}: {local:.4f}")
    ax.invert_xaxis()
    ax.set_xlabel("slenderness ε = a / L")
    ax.set_ylabel("critical q = g0 sin θ0 / 3")
    ax.set_title(f"translating circle at θ0 = 90°, n = {n}", fontsize=10)
    ax.legend(frameon=False, fontsize=8)
    return fig


def model_outcomes(frames):
    """One column per results table (one model each, ``frame_model``): terminal tilt
    θ_final against θ0 (top) and terminal aspect ratio against q0 = g0 sin θ0 / 3 (bottom),
    coloured by regime, with the model's thresholds of the translating circle at the
    table's largest truncation (θ0 = 90° values for the nonlocal model) as vertical lines."""
    fig, axes = plt.subplots(2, len(frames), figsize=(1.0 + 3.3 * len(frames), 6.2),
                             sharex="row", sharey="row", constrained_layout=True,
                             squeeze=False)
    for column, frame in enumerate(frames):
        model = frame_model(frame)
        tilt, aspect = axes[0, column], axes[1, column]
        for regime, style in REGIME_STYLE.items():
            rows = frame[frame["regime"] == regime]
            if regime == "failed" or not len(rows):
                continue  # a failed row has no terminal state
            for ax, x, y in ((tilt, "theta0_deg", "theta_final_deg"),
                             (aspect, "q0", "aspect_ratio")):
                ax.scatter(rows[x], rows[y], s=20, facecolors="none", lw=1.1,
                           edgecolors=style["color"], marker=style["marker"],
                           label=style["label"])
        tilt.plot([0, 90], [0, 90], color="0.8", lw=0.8, zorder=1)
        order = max(int(frame[order_column(frame)].max()), 3)
        for sector, style in (("in-plane", "--"), ("out-of-plane", ":")):
            aspect.axvline(full_linear.critical_q(order, sector, model=model), color="k", ls=style,
                           lw=1.0, label=f"circle, {sector}")
        failed = int((frame["regime"] == "failed").sum())
        name = "local SBT" if model.name == "local" else f"nonlocal SBT, ε = {model.slenderness:g}"
        tilt.set_title(f"{name}\n{orders_text(frame)}" + (f", {failed} failed" if failed else ""),
                       fontsize=9)
        tilt.set_xlabel(r"initial tilt $\theta_0$ (deg)")
        aspect.set_xlabel(r"$q_0 = g_0 \sin\theta_0 / 3$")
    axes[0, 0].set_ylabel(r"terminal tilt $\theta_{final}$ (deg)")
    axes[1, 0].set_ylabel("terminal aspect ratio")
    axes[1, -1].legend(fontsize=7, frameon=False, loc="upper left")
    return fig
