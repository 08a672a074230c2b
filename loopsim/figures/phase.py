"""Figs. 5 and 9: phase diagrams of one or several sweeps (g0 against θ0 by regime)."""
from ..plots import order_column, phase_diagram
from .style import merged_legend_entries, new_figure


def phase_diagrams(frames, axes=None):
    """Fig. 9: phase diagrams (``plots.phase_diagram`` with the paper's band) of several
    sweeps side by side, one per frame (for example n = 4 and n = 8), with one legend
    holding every panel's entries: a marker drawn in one panel only is in it too, and
    each panel's full-linearisation curves (at that panel's n) are named by their n."""
    frames = list(frames)
    if not frames:
        raise ValueError("no sweeps to draw")
    fig, flat = new_figure(axes, (1, len(frames)), (5.2 * len(frames) + 2.2, 4.2), squeeze=False)
    panels = flat[: len(frames)]
    for frame, ax in zip(frames, panels):
        phase_diagram(frame, ax=ax, paper_band=True)
        order = int(frame[order_column(frame)].max())
        for line in ax.get_lines():
            label = line.get_label()
            if label.startswith("full linearisation,"):
                line.set_label(label.replace("full linearisation,",
                                             f"full linearisation at n = {order},", 1))
    handles, labels = merged_legend_entries(panels)
    for ax in panels:
        ax.get_legend().remove()
    panels[-1].legend(handles, labels, fontsize=8, frameon=False, loc="upper left",
                      bbox_to_anchor=(1.01, 1.0))
    return fig
