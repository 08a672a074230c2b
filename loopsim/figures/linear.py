"""Fig. 3 (growth rates and critical q of the translating circle); the steady branch of Fig. 8."""
import numpy as np
import pandas as pd

from .. import models
from ..stability import branch, full_linear, paper
from .style import model_text, new_figure, single_axes


def stability_data(n=16, q_values=None, n_values=range(3, 17), theta0_deg=90.0):
    """The numbers of Fig. 3 as two DataFrames: ``growth`` (q, paper, corrected, in_plane,
    out_of_plane: largest growth rates at truncation n) and ``critical`` (n, in_plane,
    out_of_plane, paper, corrected: critical q against n; NaN where none)."""
    q_values = np.linspace(0.0, 20.0, 81) if q_values is None else np.asarray(q_values, float)
    growth = pd.DataFrame(full_linear.paper_comparison(q_values, n, theta0_deg))
    critical = pd.DataFrame(full_linear.critical_q_table(list(n_values), theta0_deg),
                            columns=["n", "in_plane", "out_of_plane", "paper", "corrected"])
    growth.attrs["n"] = int(n)
    return growth, critical


def stability(growth, critical, axes=None):
    """Fig. 3, corrected.  Left: largest growth rate σ against q (the paper's operator, the
    full linearisation's in-plane and out-of-plane sectors); right: critical q against the
    truncation n for the same three.  Inputs from :func:`stability_data`."""
    fig, (left, right) = new_figure(axes, (1, 2), (9.0, 3.6))
    n = growth.attrs.get("n")
    curves = (("paper", "k", "--", "paper's operator (§4)"),
              ("in_plane", "C3", "-", "full linearisation, in-plane"),
              ("out_of_plane", "C0", "-", "full linearisation, out-of-plane"))
    for key, colour, style, label in curves:
        left.plot(growth["q"], growth[key], color=colour, ls=style, lw=1.6, label=label)
    left.axhline(0.0, color="0.6", lw=0.8)
    left.set_ylim(-15.0, 15.0)
    left.set_xlim(growth["q"].min(), growth["q"].max())
    left.set_xlabel(r"$q = g_0 \sin\theta_0 / 3$")
    left.set_ylabel(r"largest growth rate $\sigma$")
    left.set_title("translating circle" + (f", n = {n}" if n else ""), fontsize=10)
    left.legend(fontsize=8, frameon=False, loc="upper left")
    for key, colour, style, label in curves:
        rows = critical[np.isfinite(critical[key])]
        right.plot(rows["n"], rows[key], color=colour, ls=style, marker="o", ms=3.5, lw=1.2,
                   label=f"{label}: {rows[key].iloc[-1]:.4f}" if len(rows) else label)
    right.set_xlabel("truncation order n")
    right.set_ylabel(r"critical $q$")
    right.set_title("critical q against n", fontsize=10)
    right.legend(fontsize=8, frameon=False)
    return fig


def load_branch(n=12, q_max=25.0):
    """(``stability.branch.steady_branch(n, q_max)``, None): the pair the figures once
    took, when the branch module was optional.  Deprecated: call ``steady_branch``."""
    from .._moved import warn_moved

    warn_moved("loopsim.figures.load_branch", "loopsim.stability.branch.steady_branch")
    return branch.steady_branch(n=n, q_max=q_max), None


def growth_rates(n=16, q_values=None, theta0_deg=90.0, w=None, ax=None, model=None):
    """Largest growth rates vs q: the paper's operator, the corrected operator and both
    sectors of the full Jacobian (of ``model``, a ``models.Model``; default local), with
    the critical q of each marked."""
    kwargs = dict({} if w is None else dict(w=w), **({} if model is None else dict(model=model)))
    fig, ax = single_axes(ax, (6.4, 4.2))
    q_values = np.linspace(0.0, 20.0, 81) if q_values is None else np.asarray(q_values, float)
    rows = full_linear.paper_comparison(q_values, n, theta0_deg, **kwargs)
    get = lambda key: [r[key] for r in rows]  # noqa: E731
    ax.plot(q_values, get("paper"), "k--", label="paper's operator (§4)")
    ax.plot(q_values, get("out_of_plane"), "C0-", lw=2, label="full J, out-of-plane")
    ax.plot(q_values, get("corrected"), "C1:", lw=1.5, label="corrected operator")
    ax.plot(q_values, get("in_plane"), "C3-", lw=2, label="full J, in-plane")
    ax.axhline(0.0, color="0.6", lw=0.8)
    for sector, color in (("in-plane", "C3"), ("out-of-plane", "C0")):
        qc = full_linear.critical_q(n, sector, theta0_deg, **kwargs)
        ax.axvline(qc, color=color, lw=0.8, ls="--")
        ax.annotate(f"{qc:.4f}", (qc, -14), color=color, rotation=90, ha="right", va="bottom")
    qp = paper.critical_q(n)
    ax.annotate(f"{qp:.4f}", (qp, -14), color="k", rotation=90, ha="right", va="bottom")
    ax.set_ylim(-15, 15)
    ax.set_xlabel("q = g0 sin θ0 / 3")
    ax.set_ylabel("largest growth rate σ")
    ax.set_title(f"translating circle, n = {n}{model_text(model or models.LOCAL)}")
    ax.legend(frameon=False)
    return fig


def branch_lines(ax, branch):
    """The steady branch: solid where stable in and out of plane, dashed elsewhere."""
    stable = (branch["stable_in_plane"].to_numpy(bool)
              & branch["stable_out_of_plane"].to_numpy(bool))
    q, ar = branch["q"].to_numpy(float), branch["aspect_ratio"].to_numpy(float)
    order = branch.attrs.get("n")
    for flag, style, label in ((True, "-", "steady shapes, stable"),
                               (False, "--", "steady shapes, unstable")):
        y = np.where(stable == flag, ar, np.nan)
        # keep the segments joined where stability changes
        joined = y.copy()
        change = np.nonzero(stable[1:] != stable[:-1])[0]
        joined[change + (0 if flag else 1)] = ar[change + (0 if flag else 1)]
        joined[change + (1 if flag else 0)] = ar[change + (1 if flag else 0)]
        if np.any(np.isfinite(joined)):
            ax.plot(q, joined, color="k", ls=style, lw=1.3,
                    label=label + (f" (n = {order})" if order else ""), zorder=2)
