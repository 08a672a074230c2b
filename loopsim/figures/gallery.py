"""Fig. 4: galleries of terminal shapes at one initial tilt θ0 across g0."""
import numpy as np
from matplotlib.lines import Line2D

from .. import diagnostics
from .style import (
    centred_curve, coefficients, new_figure, order_column, orders_text, regime_key, regime_style,
    resolved_mask,
)


def side_view_basis(x):
    """Unit horizontal vectors (h, p): h along the terminal plane's horizontal line
    (viewing direction), p perpendicular to it, so that the plane is seen edge-on."""
    _, vectors = diagnostics.principal_axes(x)
    normal = vectors[:, 0]
    horizontal = np.array([normal[0], normal[1], 0.0])
    if np.linalg.norm(horizontal) < 1e-12:  # horizontal loop: any direction
        horizontal = np.array([0.0, 1.0, 0.0])
    p = horizontal / np.linalg.norm(horizontal)
    if p[1] < 0:
        p = -p
    return np.cross([0.0, 0.0, 1.0], p), p


def plane_view(x, points=None):
    """The loop in its principal plane: (major, minor) coordinates, major axis pointing
    to the fore (lower) side on the right.  ``points``: other centred points (3, m) to
    project on the same axes (default: the loop's own curve)."""
    _, vectors = diagnostics.principal_axes(x)
    major, minor = vectors[:, 2], vectors[:, 1]
    if major[2] > 0 or (abs(major[2]) < 1e-12 and major[1] < 0):
        major = -major
    if np.cross(major, minor) @ vectors[:, 0] < 0:
        minor = -minor
    points = centred_curve(x) if points is None else points
    return major @ points, minor @ points


def unit_circle(ax, **kwargs):
    """The unit circle (the released loop's size), dashed grey."""
    s = np.linspace(0, 2 * np.pi, 200)
    ax.plot(np.cos(s), np.sin(s), **{"color": "0.5", "lw": 0.8, "ls": "--", **kwargs})


def gallery(frame, theta0_deg=30.0, max_shapes=8, axes=None):
    """Fig. 4: terminal shapes of the cases with θ0 nearest ``theta0_deg``, across g0,
    coloured by regime (a key below).  Top row: side view (gravity downwards; the
    terminal plane seen edge-on), with the unit circle and the initial tilt plane θ0
    dashed, titled by g0, q0 and the terminal tilt θ.  Bottom row: the loop in its
    terminal plane, principal axes aligned (fore side right), unit circle dashed,
    titled by its aspect ratio.  Grey titles mark cases not resolved at their n."""
    if not len(frame):
        raise ValueError("no cases to draw")
    theta = frame["theta0_deg"].to_numpy(float)
    chosen = np.unique(theta)[np.argmin(np.abs(np.unique(theta) - theta0_deg))]
    rows = frame[np.isclose(theta, chosen)].sort_values("g0")
    if len(rows) > max_shapes:
        rows = rows.iloc[np.unique(np.round(np.linspace(0, len(rows) - 1, max_shapes)).astype(int))]
    count = len(rows)
    fig, flat = new_figure(axes, (2, count), (max(1.45 * count + 0.5, 6.0), 4.1), squeeze=False)
    top, bottom = flat[:count], flat[count:]
    resolved = resolved_mask(rows)
    t0 = np.radians(chosen)
    for i, (_, row) in enumerate(rows.iterrows()):
        x = coefficients(row["x_final"], row[order_column(rows)])
        colour = regime_style(row["regime"])["color"]
        h, p = side_view_basis(x)
        points = centred_curve(x)
        grey = "k" if resolved[i] else "0.45"
        ax = top[i]
        unit_circle(ax)
        ax.plot([-np.cos(t0) * 1.3, np.cos(t0) * 1.3], [-np.sin(t0) * 1.3, np.sin(t0) * 1.3],
                color="0.5", lw=0.8, ls="--")
        ax.plot(p @ points, points[2], color=colour, lw=1.8)
        ax.annotate("", xy=(1.25, -1.05), xytext=(1.25, -0.35),
                    arrowprops=dict(arrowstyle="-|>", color="k", lw=0.8))
        ax.set_title(f"$g_0$ = {row['g0']:.0f}, $q_0$ = {row['q0']:.1f}\n"
                     f"terminal θ = {row['theta_final_deg']:.0f}°", fontsize=8, color=grey)
        ax = bottom[i]
        unit_circle(ax)
        major, minor = plane_view(x)
        ax.plot(major, minor, color=colour, lw=1.8)
        ax.set_title(f"aspect ratio {row['aspect_ratio']:.2f}"
                     + ("" if resolved[i] else "\n(not resolved)"), fontsize=8, color=grey)
    for ax in top + bottom:
        ax.set_aspect("equal")
        ax.set_xlim(-1.9, 1.9)
        ax.set_ylim(-1.9, 1.9)
        ax.set_xticks([])
        ax.set_yticks([])
        for spine in ax.spines.values():
            spine.set_linewidth(0.4)
    top[0].set_ylabel("side view", fontsize=9)
    bottom[0].set_ylabel("in its plane", fontsize=9)
    fig.suptitle(f"terminal shapes of loops released at θ0 = {chosen:g}° (initial tilt), "
                 f"{orders_text(rows)}", fontsize=10)
    key = regime_key(rows["regime"])
    key.append(Line2D([], [], color="0.5", lw=0.8, ls="--",
                      label="unit circle; initial tilt plane θ0 (side view)"))
    key.append(Line2D([], [], color="k", lw=0, marker=r"$\downarrow$", ms=9, label="gravity"))
    if not resolved.all():
        key.append(Line2D([], [], color="0.45", lw=0, marker="s", ms=5,
                          label="grey title: not resolved at n"))
    fig.legend(handles=key, loc="outside lower center", ncol=len(key) if count >= 7 else 3,
               fontsize=8, frameon=False, title="colour: regime", title_fontsize=8)
    return fig
