"""The paper's figures, or their corrected counterparts, from result tables.

Waszkiewicz, Szymczak & Lisicki, "Stability of sedimenting flexible loops"
(JFM 919, A14, 2021).  One function per figure; each draws into ``ax`` /
``axes`` (a new figure when None) and returns the figure.  Nothing here
integrates dynamics or changes the matplotlib backend (``loopsim figures``
chooses Agg).  Inputs are the tables loopsim writes: a sweep's
``read_results`` frame (one row per case, terminal coefficients ``x_final``)
and a run's trajectory table (one row per snapshot: ``t``, ``x``,
``multiplier``).  Computed inputs (growth rates, the steady branch) come in
as DataFrames, so every function can be drawn from stored numbers:

* Fig. 1  :func:`tension_on_shape` - the axial force N(s) = T + |x''|² along the loop;
* Fig. 3  :func:`stability_data`, :func:`stability` - growth rates against q and
  critical q against n: the paper's operator beside the full linearisation;
* Fig. 4  :func:`gallery` - terminal shapes at one θ0 across g0;
* Fig. 5  ``plots.phase_diagram(frame, paper_band=True)``;
* Fig. 6  :func:`evolution` - one trajectory: 3D, side and top views;
  :func:`evolution_rows` - several, one row each, on one time scale;
* Fig. 7  :func:`q_and_tilt` - q_final against q0, θ_final against θ0;
* Fig. 8  :func:`aspect_ratio` - terminal aspect ratio against q_final, with the
  steady branch (``stability.branch.steady_branch``) when given;
* Fig. 9  :func:`phase_diagrams` - phase diagrams of several sweeps side by side;
* :func:`seed_distributions` - terminal tilt and aspect ratio over seeds;
* :func:`write_figures` - all of them from files (``loopsim figures``).

The modules: ``style`` (shared helpers and styles), ``gallery`` (Fig. 4),
``evolution`` (Figs. 6 and 1), ``terminal`` (Figs. 7, 8, seeds), ``phase``
(Figs. 5, 9), ``linear`` (Fig. 3, the steady branch), ``suite`` (files to PNGs).
Regime colours are ``plots.REGIME_STYLE`` (the paper's: stable dark purple,
in-plane green-blue, 3D yellow); cases not resolved at their n are hollow.
"""
from .. import diagnostics, spectral, validation  # noqa: F401  (names of the former module)
from ..plots import (
    PAPER_BAND, REGIME_STYLE, mark_undetermined, order_column, orders_text, phase_diagram,
)
from ..stability import circle, paper  # noqa: F401  (names of the former module)
from .evolution import (
    evolution, evolution_rows, settling_index, snapshot_indices, tension_figure, tension_on_shape,
    time_colours,
)
from .gallery import gallery, plane_view, side_view_basis, unit_circle
from .linear import load_branch, stability, stability_data
from .phase import phase_diagrams
from .style import (
    ASPECT_LABEL, CURVE_POINTS, TIME_CMAP, centred_curve, coefficients, default_thresholds,
    merged_legend_entries, new_figure, q_lines, regime_key, regime_style, resolved_mask,
    scatter_regimes, single_axes,
)
from .suite import (
    FIGURE_NAMES, read_run, read_sweep, run_title, sweep_kind, sweep_label, write_figures,
)
from .terminal import aspect_ratio, q_and_tilt, seed_distributions

__all__ = [
    "ASPECT_LABEL", "CURVE_POINTS", "FIGURE_NAMES", "PAPER_BAND", "REGIME_STYLE", "TIME_CMAP",
    "aspect_ratio", "centred_curve", "coefficients", "default_thresholds", "evolution",
    "evolution_rows", "gallery", "load_branch", "mark_undetermined", "merged_legend_entries",
    "new_figure",
    "order_column", "orders_text", "phase_diagram", "phase_diagrams", "plane_view", "q_and_tilt",
    "q_lines", "read_run", "read_sweep", "regime_key", "regime_style", "resolved_mask",
    "run_title", "scatter_regimes", "seed_distributions", "settling_index", "side_view_basis",
    "single_axes", "snapshot_indices", "stability", "stability_data", "sweep_kind", "sweep_label",
    "tension_figure", "tension_on_shape", "time_colours", "unit_circle", "write_figures",
]
