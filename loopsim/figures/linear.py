"""Fig. 3 (growth rates and critical q of the translating circle); the steady branch of Fig. 8."""
import numpy as np
import pandas as pd

from ..stability import circle
from .style import new_figure


def stability_data(n=16, q_values=None, n_values=range(3, 17), theta0_deg=90.0):
    """The numbers of Fig. 3 as two DataFrames: ``growth`` (q, paper, corrected, in_plane,
    out_of_plane: largest growth rates at truncation n) and ``critical`` (n, in_plane,
    out_of_plane, paper, corrected: critical q against n; NaN where none)."""
    q_values = np.linspace(0.0, 20.0, 81) if q_values is None else np.asarray(q_values, float)
    growth = pd.DataFrame(circle.paper_comparison(q_values, n, theta0_deg))
    critical = pd.DataFrame(circle.critical_q_table(list(n_values), theta0_deg),
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
    """The steady branch from ``stability.branch.steady_branch`` (a DataFrame), or None
    with the reason when that module or function is not there."""
    try:
        from ..stability import branch as steady
    except ImportError as exc:
        return None, f"no steady branch: {exc}"
    function = getattr(steady, "steady_branch", None)
    if function is None:
        return None, "no steady branch: loopsim.stability.branch has no steady_branch()"
    frame = function(n=n, q_max=q_max)
    frame.attrs.setdefault("n", n)
    return frame, None
