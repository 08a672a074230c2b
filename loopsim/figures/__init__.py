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
* Fig. 5  :func:`phase_diagram` (``paper_band=True``);
* Fig. 6  :func:`evolution` - one trajectory: 3D, side and top views;
  :func:`evolution_rows` - several, one row each, on one time scale;
* Fig. 7  :func:`q_and_tilt` - q_final against q0, θ_final against θ0;
* Fig. 8  :func:`aspect_ratio` - terminal aspect ratio against q_final, with the
  steady branch (``stability.branch.steady_branch``) when given;
* Fig. 9  :func:`phase_diagrams` - phase diagrams of several sweeps side by side;
* :func:`seed_distributions` - terminal tilt and aspect ratio over seeds;
* :func:`probability_phase_diagram`, :func:`tilt_distribution`,
  :func:`aspect_distribution`, :func:`distribution_summary` - a seed sweep's summary
  table (``loopsim.summarize``) drawn as distributions;
* :func:`growth_rates`, :func:`nonlocal_thresholds`, :func:`model_outcomes` - the
  linearisation of the circle, the nonlocal model beside the local one;
* :func:`survival_curves`, :func:`pooled_survival`, :func:`rest_tilts` - how long loops take to come to rest
  (Kaplan–Meier) and where they rest against the stable branch's tilt window;
  :func:`range_overview` - the paper's range cell by cell, with P(not at rest by t = 10);
* :func:`trajectory` - one run's snapshots, face-on, with tilt and aspect ratio;
* :func:`save` - write a figure atomically;
* :func:`animate` - a GIF or MP4 of one run (``loopsim animate``, module ``animation``);
* :func:`write_figures` - all of them from files (``loopsim figures``).

The modules: ``style`` (shared helpers and styles, :func:`save`), ``gallery`` (Fig. 4),
``evolution`` (Figs. 6 and 1, a run's trajectory), ``terminal`` (Figs. 7, 8, seeds),
``phase`` (Figs. 5, 9), ``settling`` (settling times, rest window), ``linear`` (Fig. 3, the steady branch), ``nonlocal_sbt`` (the
nonlocal model), ``distributions`` (summary tables over seeds), ``suite`` (files to PNGs).
Regime colours are :data:`REGIME_STYLE` (the paper's: stable dark purple,
in-plane green-blue, 3D yellow); cases not resolved at their n are hollow.
"""
from .. import diagnostics, spectral, validation  # noqa: F401  (names of the former module)
from ..stability import full_linear, paper  # noqa: F401  (names of the former module)
from .animation import animate, animation_figure, frame_indices, load_trajectory, write_animation
from .distributions import (
    BRANCH_Q_MAX, aspect_distribution, check_one_cell_per_point, distribution_summary,
    probability_phase_diagram, regime_pies, save_distribution_figure, tilt_distribution,
    wedge_marker,
)
from .evolution import (
    evolution, evolution_rows, settling_index, snapshot_indices, tension_figure, tension_on_shape,
    time_colours, trajectory,
)
from .gallery import gallery, plane_view, side_view_basis, unit_circle
from .linear import branch_lines, growth_rates, load_branch, stability, stability_data
from .nonlocal_sbt import model_outcomes, nonlocal_thresholds
from .phase import phase_diagram, phase_diagrams
from .settling import pooled_survival, range_overview, rest_tilts, survival_curves
from .style import (
    ASPECT_LABEL, CURVE_POINTS, PAPER_BAND, REGIME_STYLE, TIME_CMAP, centred_curve, coefficients,
    default_thresholds, frame_model, mark_undetermined, merged_legend_entries, model_text,
    new_figure, order_column, orders_text, q_lines, regime_key, regime_style, resolved_mask,
    rest_window_curve, rest_window_for, save,
    scatter_regimes, single_axes,
)
from .suite import (
    FIGURE_NAMES, read_run, read_sweep, run_title, sweep_kind, sweep_label, write_figures,
)
from .terminal import aspect_ratio, q_and_tilt, seed_distributions

__all__ = [
    "ASPECT_LABEL", "BRANCH_Q_MAX", "CURVE_POINTS", "FIGURE_NAMES", "PAPER_BAND", "REGIME_STYLE", "TIME_CMAP",
    "animate", "animation_figure", "frame_indices", "load_trajectory", "write_animation",
    "aspect_distribution", "aspect_ratio", "branch_lines", "centred_curve",
    "check_one_cell_per_point", "coefficients", "default_thresholds", "distribution_summary",
    "evolution", "evolution_rows", "frame_model", "gallery", "growth_rates", "load_branch",
    "mark_undetermined", "merged_legend_entries", "model_outcomes", "model_text", "new_figure",
    "nonlocal_thresholds", "order_column", "orders_text", "phase_diagram", "phase_diagrams",
    "plane_view", "probability_phase_diagram", "q_and_tilt", "q_lines", "read_run", "read_sweep",
    "range_overview", "regime_key", "regime_pies", "regime_style", "resolved_mask", "rest_tilts",
    "rest_window_curve",
    "rest_window_for", "run_title", "save",
    "pooled_survival", "save_distribution_figure", "survival_curves",
    "scatter_regimes", "seed_distributions", "settling_index", "side_view_basis", "single_axes",
    "snapshot_indices", "stability", "stability_data", "sweep_kind", "sweep_label",
    "tension_figure", "tension_on_shape", "tilt_distribution", "time_colours", "trajectory",
    "unit_circle", "wedge_marker", "write_figures",
]
