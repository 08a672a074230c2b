"""Every column loopsim writes, declared once: its unit and what it means.

The units are those of the dimensionless equations (``loopsim.defaults``; docs/model.md,
"Units"): lengths in L/2π (the loop has length 2π), time in
t_u = ζ⊥ (L/2π)⁴ / EI (ζ⊥ = 8πμ/c the perpendicular drag coefficient per unit length),
forces (the axial force N, the multiplier T) in EI (2π/L)², force densities in
EI (2π/L)³ = 8π³EI/L³, angles in degrees at the interface.  The declarations go into
each Parquet field's metadata (keys ``unit`` and ``description``), into ``_sweep.json``
and a results frame's ``attrs["loopsim"]["columns"]``, and into the docs' column table
(``python -m loopsim.columns [results|trajectory|summary|compare|stops]`` prints one
as Markdown).
"""
LENGTH = "L/2pi"
TIME = "t_u"
VELOCITY = "(L/2pi)/t_u"
FORCE = "EI (2pi/L)^2"
ONE = "1"  # a pure number
DEG = "deg"
COUNT = "count"
TEXT = "text"
FLAG = "bool"
PROBABILITY = "1 (probability)"

#: name: (unit, description) of every column of a sweep's result files, in file order.
RESULT_COLUMNS = {
    "case_id": (COUNT, "the case's index in the sweep's case list (_sweep.json)"),
    "g0": (ONE, "gravity over bending stiffness, L^3 g rho_L / (8 pi^3 EI)"),
    "theta0_deg": (DEG, "initial tilt of the loop's plane to the horizontal (measured from "
                        "the shape for an --initial start)"),
    "n": (COUNT, "the truncation order the case started at (with --n auto: the ladder's "
                 "first)"),
    "q0": (ONE, "stability parameter of the start, g0 sin(theta0) / 3"),
    "t_end": (TIME, "requested final time"),
    "rtol": (ONE, "relative tolerance of the time integration"),
    "atol": (LENGTH, "absolute tolerance of the time integration (on coefficients)"),
    "w": ("1/t_u", "length-penalty rate of the inextensibility constraint"),
    "perturbation": (LENGTH, "RMS size of the seeded initial perturbation"),
    "seed": (COUNT, "seed of the initial perturbation"),
    "model": (TEXT, "the hydrodynamic model: local (the paper's local slender-body theory) "
                    "or nonlocal (full slender-body theory, docs/nonlocal.md)"),
    "slenderness": (ONE, "filament radius over loop length, a/L, of the nonlocal model "
                         "(null for the local one)"),
    "method": (TEXT, "the integrator that ran the case: rkf45 or radau5 (--method auto "
                     "chooses per case)"),
    "n_used": (COUNT, "the truncation order the case ended at (with --n auto: the order "
                      "whose run from the start stayed within --tail-tol)"),
    "status": (TEXT, "ok, or why the integration failed"),
    "t_final": (TIME, "time reached (t_end, or earlier at a steady state or a failure)"),
    "steps_accepted": (COUNT, "accepted time steps"),
    "steps_rejected": (COUNT, "rejected time steps"),
    "nfev": (COUNT, "right-hand-side evaluations of the steps (all orders of --n auto)"),
    "njev": (COUNT, "Jacobian evaluations (radau5)"),
    "nlu": (COUNT, "LU factorisations (radau5)"),
    "wall_s": ("s", "wall time of the case, compilation and the twin left out (a batch's "
                    "wall time x threads shared in proportion to nfev)"),
    "tail_max": (ONE, "largest spectral tail (the top two modes' share of the deformation) "
                      "along the run at n_used, once the top modes grew"),
    "theta_final_deg": (DEG, "terminal tilt of the best-fit plane to the horizontal"),
    "q_final": (ONE, "g0 sin(theta_final) / 3"),
    "aspect_ratio": (ONE, "largest / middle eigenvalue of the centreline's covariance (a "
                          "ratio of variances, as in the paper)"),
    "axis_ratio": (ONE, "sqrt(aspect_ratio): the ratio of the principal axes"),
    "u_x": (VELOCITY, "centre-of-mass velocity, x"),
    "u_y": (VELOCITY, "centre-of-mass velocity, y"),
    "u_z": (VELOCITY, "centre-of-mass velocity, z (gravity along -z: negative, falling)"),
    "settling_angle_deg": (DEG, "angle between the centre-of-mass velocity and gravity"),
    "tension_max": (FORCE, "largest axial force N = T + |x''|^2 (positive: stretched)"),
    "tension_min": (FORCE, "smallest axial force N"),
    "s_tension_max": (LENGTH, "arc length where N is largest"),
    "length_error": (ONE, "terminal relative length error (L - 2 pi) / 2 pi"),
    "spectral_tail": (ONE, "the terminal shape's top two modes' share of its deformation"),
    "regime": (TEXT, "stable | in-plane | 3d | failed (thresholds in _sweep.json)"),
    "resolved": (FLAG, "length_error_max and tail_max within the thresholds: n_used "
                       "resolves the case (False: its outcome is not converged in n)"),
    "determined": (FLAG, "a twin from the same start at 10x stricter tolerances ends in the "
                         "same regime within the determined_* thresholds (False: the terminal "
                         "tilt is a sample of an ill-conditioned transient, or the run "
                         "failed; null: no twin was asked for)"),
    "theta_uncertainty_deg": (DEG, "|theta_final_deg - the twin's|: the terminal tilt's "
                                   "error estimate at the tolerances used"),
    "aspect_uncertainty": (ONE, "|aspect_ratio - the twin's|"),
    "twin_nfev": (COUNT, "right-hand-side evaluations of the twin (0: none ran)"),
    "twin_regime": (TEXT, "the twin's regime (null: no twin ran)"),
    "twin_theta_final_deg": (DEG, "the twin's terminal tilt (NaN: no twin ran)"),
    "twin_aspect_ratio": (ONE, "the twin's terminal aspect ratio (NaN: no twin ran)"),
    "terminal_state": (TEXT, "steady (the steady test passed: stopped early) | quiet (ran to "
                             "t_end; the late window's tilt and aspect ranges within the "
                             "regime thresholds) | unsteady (they moved more: the terminal "
                             "values are a snapshot of motion) | failed (loopsim.late_motion; "
                             "null: written before it existed)"),
    "late_tilt_mean_deg": (DEG, "mean tilt over the late window [t_final - (t_end - t0) / 5, "
                                "t_final] (samples every (t_end - t0) / 400, and the "
                                "terminal state)"),
    "late_tilt_min_deg": (DEG, "smallest tilt in the late window"),
    "late_tilt_max_deg": (DEG, "largest tilt in the late window"),
    "late_aspect_mean": (ONE, "mean aspect ratio over the late window"),
    "late_aspect_min": (ONE, "smallest aspect ratio in the late window"),
    "late_aspect_max": (ONE, "largest aspect ratio in the late window"),
    "time_since_swing": (TIME, "t_final minus the last sampled time at which the tilt stood "
                               "more than tilt_change_deg (1 deg) from its terminal value "
                               "(t_final - t0 if never): how long the final tilt has held"),
    "stop_reason": (TEXT, "t_end | steady (terminal state reached early) | the failure"),
    "early_stop": (FLAG, "whether the run was tested for a steady state, so that "
                         "stop_reason steady could end it (False: --no-early-stop; rows "
                         "written before it existed: the sweep's setting)"),
    "aspect_ratio_initial": (ONE, "aspect ratio of the start"),
    "length_error_max": (ONE, "largest |relative length error| along the trajectory"),
    "x_final": (LENGTH, "terminal shape coefficients, row-major (3, 2 n_used + 1): "
                        "loopsim.coefficients(row) reshapes them"),
}

#: name: (unit, description) of the columns of a trajectory (``run --out``, snapshots).
TRAJECTORY_COLUMNS = {
    "case_id": RESULT_COLUMNS["case_id"],
    "t": (TIME, "time of the snapshot"),
    "theta_deg": (DEG, "tilt of the best-fit plane to the horizontal"),
    "aspect_ratio": RESULT_COLUMNS["aspect_ratio"],
    "tension_max": RESULT_COLUMNS["tension_max"],
    "tension_min": RESULT_COLUMNS["tension_min"],
    "length_error": (ONE, "relative length error (L - 2 pi) / 2 pi"),
    "spectral_tail": (ONE, "the top two modes' share of the deformation"),
    "x": (LENGTH, "shape coefficients, row-major (3, 2n + 1)"),
    "multiplier": (FORCE, "coefficients (2n + 1) of the tension multiplier T; the axial "
                          "force is N = T + |x''|^2"),
}


#: name: (unit, description) of every column a summary table (``loopsim.summarize``,
#: ``loopsim summary --out``) may hold: the cell's inputs (those of :data:`RESULT_COLUMNS`
#: that define its cells), then the statistics over its seeds.
SUMMARY_COLUMNS = {
    **{name: RESULT_COLUMNS[name] for name in (
        "g0", "theta0_deg", "model", "slenderness", "n", "t_end", "rtol", "atol", "w",
        "perturbation", "method")},
    "seeds": (COUNT, "rows (seeds) in the cell"),
    "resolved": (COUNT, "rows of the cell whose n_used resolves them"),
    "determined": (COUNT, "rows of the cell whose outcome is determined (a twin agreed; empty, "
                          "unknown, where no row of the cell ran a twin: --no-twin)"),
    "twinned": (COUNT, "rows of the cell that ran a twin, whose determinacy is known (--seeds "
                       "auto runs twins in its first round only)"),
    "steady": (COUNT, "rows of the cell that reached a steady state before t_end (stop_reason "
                      "steady); the others ran to t_end, their terminal values the state there, or "
                      "failed (empty, unknown, for a sweep run with --no-early-stop: no run was "
                      "tested)"),
    "unsteady": (COUNT, "rows of the cell still moving at their end (terminal_state "
                        "unsteady; empty where a row does not record it)"),
    **{f"p_unsteady{end}": (PROBABILITY, what) for end, what in (
        ("", "share of the cell's rows still moving at their end (terminal_state unsteady)"),
        ("_low", "lower end of the 95% Wilson score interval of the share"),
        ("_high", "upper end of the 95% Wilson score interval of the share"))},
    **{f"p_{regime}{end}": (PROBABILITY, f"{what} of the regime {label}")
       for regime, label in (("stable", "stable"), ("in_plane", "in-plane"), ("3d", "3d"),
                             ("failed", "failed"))
       for end, what in (("", "share of the cell's rows"),
                         ("_low", "lower end of the 95% Wilson score interval of the share"),
                         ("_high", "upper end of the 95% Wilson score interval of the share"))},
    **{f"{short}_{stat}": (unit, f"{what} of the cell's {label}")
       for short, unit, label in (("tilt", DEG, "terminal tilts (theta_final_deg)"),
                                  ("aspect", ONE, "terminal aspect ratios"),
                                  ("q_final", ONE, "terminal q = g0 sin(theta_final) / 3"))
       for stat, what in (("q25", "lower quartile"), ("median", "median"),
                          ("q75", "upper quartile"),
                          ("median_low", "lower end of the median's 95% percentile-bootstrap "
                                         "interval"),
                          ("median_high", "upper end of the median's 95% percentile-bootstrap "
                                          "interval"))},
    # settling (loopsim.survival): a run comes to rest at t_final when it stops early
    # (stop_reason steady) and is censored at t_end otherwise; failures left out
    "rest_observed": (COUNT, "rows of the cell with a settling or censoring time (failures "
                             "left out)"),
    "at_rest": (COUNT, "rows of the cell that came to rest (passed the steady test) before "
                       "t_end"),
    **{f"p_rest_t10{end}": (PROBABILITY, what) for end, what in (
        ("", "P(at rest by the paper's horizon t = 10 t_u), Kaplan-Meier (a plain share "
             "where no run stopped before t = 10 without coming to rest)"),
        ("_low", "lower end of its 95% interval (Wilson, or the Kaplan-Meier log-log band)"),
        ("_high", "upper end of its 95% interval"))},
    "t_rest_median": (TIME, "median settling time, Kaplan-Meier (NaN: fewer than half came "
                            "to rest within the runs' t_end)"),
    "t_rest_median_low": (TIME, "lower end of its 95% interval (where the log-log band's "
                                "lower limit crosses 1/2)"),
    "t_rest_median_high": (TIME, "upper end of its 95% interval (where the band's upper "
                                 "limit crosses 1/2; NaN: beyond the runs' t_end)"),
    "t_rest_q95": (TIME, "time by which 95% of the cell's runs come to rest, Kaplan-Meier "
                         "(NaN: not reached within the runs' t_end)"),
    "escape_events": (COUNT, "runs that came to rest after t = 10 (the tail)"),
    "tail_time": (TIME, "time observed after t = 10, summed over the cell's runs"),
    "escape_rate": ("1/t_u", "rate at which loops still moving after t = 10 come to rest, "
                             "escape_events / tail_time (NaN: fewer than 3 events)"),
    "escape_rate_low": ("1/t_u", "lower end of its exact 95% Poisson interval"),
    "escape_rate_high": ("1/t_u", "upper end of its exact 95% Poisson interval"),
    **{f"rest_{where}": (COUNT, f"rows that came to rest {what} (loopsim.stability."
                                "rest_window; only where a summary is asked for them)")
       for where, what in (("inside", "inside the stable branch's tilt window at their g0"),
                           ("below", "below the window: a tilted circle (q < 8.9001)"),
                           ("outside", "above the window, where no steady shape is stable "
                                       "(expected none)"))},
    "nfev": (COUNT, "right-hand-side evaluations of the cell's runs, summed"),
    "twin_nfev": (COUNT, "right-hand-side evaluations of the cell's twins, summed"),
    "wall_s": ("s", "wall time of the cell's runs, summed (compilation and twins left out)"),
}

#: name: (unit, description) of every column of a comparison table (``loopsim.compare``,
#: ``loopsim compare --out``): the pairing inputs, then the tests of one cell.
COMPARE_COLUMNS = {
    **{name: SUMMARY_COLUMNS[name] for name in (
        "g0", "theta0_deg", "model", "slenderness", "n", "t_end", "rtol", "atol", "w",
        "perturbation", "method")},
    "seeds_a": (COUNT, "rows of the cell in the first table"),
    "seeds_b": (COUNT, "rows of the cell in the second table"),
    "tilt_ks_p": (PROBABILITY, "p-value of the two-sample Kolmogorov-Smirnov test of the "
                               "terminal tilts"),
    "aspect_ks_p": (PROBABILITY, "p-value of the two-sample Kolmogorov-Smirnov test of the "
                                 "terminal aspect ratios"),
    "tilt_wasserstein": (DEG, "1-Wasserstein distance between the two samples of terminal "
                              "tilt"),
    "tilt_wasserstein_low": (DEG, "lower end of its 95% percentile-bootstrap interval"),
    "tilt_wasserstein_high": (DEG, "upper end of its 95% percentile-bootstrap interval"),
    "regime_p": (PROBABILITY, "p-value of the chi-square test of the regime counts (1 when "
                              "both samples hold one regime only)"),
    "verdict": (TEXT, "different (a p-value below alpha / 3) or indistinguishable at this "
                      "sample size"),
}

#: name: (unit, description) of every column of a ``--seeds auto`` stop table
#: (``seeds_auto.parquet``): one row per cell.
STOP_COLUMNS = {
    "g0": RESULT_COLUMNS["g0"],
    "theta0_deg": RESULT_COLUMNS["theta0_deg"],
    "n": RESULT_COLUMNS["n"],
    "perturbation": RESULT_COLUMNS["perturbation"],
    "seeds": (COUNT, "seeds run for the cell"),
    "rounds": (COUNT, "rounds the cell took part in"),
    "stop_reason": (TEXT, "why the cell stopped: failed (every seed failed: no distribution, "
                          "no check), deterministic, sharp or cap (--max-seeds reached), or "
                          "rescued (--rerun-failed replaced failed runs since: intervals "
                          "wider than the targets) (loopsim.seeds_auto_rule)"),
    "p_halfwidth": (PROBABILITY, "largest half-width of the regime shares' 95% Wilson "
                                 "intervals at the stop"),
    "tilt_halfwidth_deg": (DEG, "half-width of the median terminal tilt's 95% bootstrap "
                                "interval at the stop"),
    "runs": (TEXT, "trajectories (each run twin-checked or deterministic), samples (the "
                   "cell's outcome is a distribution) or none (every run failed)"),
    "twins": (COUNT, "rows of the cell with a twin run"),
    "check_seeds": (COUNT, "seeds of the distribution check of a sampled cell (0: none)"),
    "check_verdict": (TEXT, "the check's verdict (loopsim.compare; empty: no check)"),
    "check_tilt_ks_p": COMPARE_COLUMNS["tilt_ks_p"],
    "check_aspect_ks_p": COMPARE_COLUMNS["aspect_ks_p"],
    "check_regime_p": COMPARE_COLUMNS["regime_p"],
    "check_tilt_wasserstein": COMPARE_COLUMNS["tilt_wasserstein"],
}


def _difference_columns(stat, unit, what):
    """The four columns of one difference (setting − baseline) in a convergence table."""
    return {f"delta_{stat}": (unit, f"{what}: this setting's minus its baseline's"),
            f"delta_{stat}_low": (unit, "lower end of its 95% interval (Newcombe for a "
                                        "probability, percentile bootstrap for a quantile)"),
            f"delta_{stat}_high": (unit, "upper end of its 95% interval"),
            f"delta_{stat}_detectable": (unit, "smallest difference the comparison detects "
                                               "with 80% power at these sample sizes")}


#: name: (unit, description) of every column of the convergence table
#: (``scripts/convergence_study.py``, ``data/convergence_top.parquet``): one row per cell
#: and setting; the ``delta_*`` columns compare the setting with its baseline (column
#: ``baseline``; ``loopsim.distribution_differences``; empty on the default's own rows).
CONVERGENCE_COLUMNS = {
    "g0": RESULT_COLUMNS["g0"],
    "theta0_deg": RESULT_COLUMNS["theta0_deg"],
    "q0": RESULT_COLUMNS["q0"],
    "setting": (TEXT, "default, rtol1e-8, n40, amp1e-4, jmid, jmid_rtol1e-8, jmid_n40 or "
                      "jmid_rtol1e-3 "
                      "(the sweep options: the table's metadata, loopsim_convergence; the "
                      "code: STUDY_COMMITS.json)"),
    "baseline": (TEXT, "the setting the delta_* columns compare this one with: default, "
                       "or jmid (the defaults on the same code) for jmid_rtol1e-8, "
                       "jmid_n40 and jmid_rtol1e-3; jmid itself is compared with default "
                       "across two codes (STUDY_COMMITS.json); empty where no comparison was made"),
    "seeds": (COUNT, "seeds of the cell at this setting"),
    "failed": (COUNT, "of them, runs that failed"),
    **{f"p_{name}{end}": (PROBABILITY, f"share of the seeds {what}" + (
        "" if not end else f": {end[1:]} end of its 95% Wilson interval"))
       for name, what in (("stable", "ending stable"), ("in_plane", "ending in-plane"),
                          ("3d", "ending 3D"),
                          ("steady", "that reached a steady state before t_end"),
                          ("unsteady", "still moving at t_end (terminal_state unsteady; "
                                       "NaN where the sweep's code did not record it)"))
       for end in ("", "_low", "_high")},
    "certain_regime": (TEXT, "the regime whose 95% Wilson lower bound is >= 0.8, if any "
                             "(loopsim.distribution_differences.certain)"),
    "tilt_q25": (DEG, "terminal tilt, first quartile over the seeds"),
    "tilt_q50": (DEG, "terminal tilt, median over the seeds"),
    "tilt_q75": (DEG, "terminal tilt, third quartile over the seeds"),
    "tilt_q50_low": (DEG, "lower end of the median's 95% percentile-bootstrap interval"),
    "tilt_q50_high": (DEG, "upper end of the median's 95% percentile-bootstrap interval"),
    "nfev_mean": (COUNT, "right-hand-side evaluations per run, mean over the seeds"),
    "wall_s": ("s", "wall time of the cell's runs, summed (shared machine)"),
    **_difference_columns("p_in_plane", PROBABILITY, "P(in-plane)"),
    **_difference_columns("p_3d", PROBABILITY, "P(3D)"),
    **_difference_columns("p_steady", PROBABILITY, "P(steady before t_end)"),
    **_difference_columns("p_unsteady", PROBABILITY, "P(still moving at t_end)"),
    **{k: v for q in (25, 50, 75)
       for k, v in _difference_columns(f"tilt_q{q}", DEG, f"terminal tilt quantile {q}%")
       .items()},
    "verdict": (TEXT, "different (a Bonferroni interval excludes 0) or same (within the "
                      "intervals), against the baseline; empty on the default's rows"),
}


#: Optional per-case columns of a cases file (``sweep --cases``) that override the sweep's
#: option for that row (each is also a result column).
CASE_OVERRIDES = ("method", "rtol", "t_end", "model", "slenderness")
#: Every column a cases file may have: g0 and theta0_deg (empty for a row that starts from
#: its ``initial`` file), then the optional ones (``sweeps.read_cases_file``; docs/sweeps.md
#: lists them from here).
CASE_COLUMNS = ("g0", "theta0_deg", "n", "seed", "perturbation", "initial",
                "initial_case_id") + CASE_OVERRIDES


#: name: (unit, description) of every column of the run-to-rest study
#: (``scripts/rest_study.py``, ``data/rest_study.parquet``): one row per cell, its seeds
#: run until they come to rest or reach t_max; the ``delta_*`` columns compare the cell
#: at rest with a t = 10 sample of it (column ``baseline``; empty where none exists).
REST_STUDY_COLUMNS = {
    "g0": RESULT_COLUMNS["g0"],
    "theta0_deg": RESULT_COLUMNS["theta0_deg"],
    "q0": RESULT_COLUMNS["q0"],
    "sweep": (TEXT, "the sweep directory of the cell's runs (data/rest_runs; the code it ran "
                    "on: STUDY_COMMITS.json there)"),
    "t_max": (TIME, "the runs' t_end: a loop not at rest by then is censored there"),
    "window_low_deg": (DEG, "lower edge of the stable branch's tilt window at g0 (q = "
                            "8.9001; below it loops rest as tilted circles)"),
    "window_high_deg": (DEG, "upper edge of the window (the first loss of stability along "
                             "the branch, the out-of-plane Hopf point q = 37.5532)"),
    "seeds": SUMMARY_COLUMNS["seeds"],
    "failed": (COUNT, "of them, runs that failed"),
    "moving_at_t_max": (COUNT, "runs still moving at t_max (censored)"),
    **{name: SUMMARY_COLUMNS[name] for name in (
        "rest_observed", "at_rest", "rest_inside", "rest_below", "rest_outside",
        "p_rest_t10", "p_rest_t10_low", "p_rest_t10_high", "t_rest_median",
        "t_rest_median_low", "t_rest_median_high", "t_rest_q95", "escape_events",
        "tail_time", "escape_rate", "escape_rate_low", "escape_rate_high")},
    **{name: (unit, what.replace("the cell's rows", "the cell's loops at rest")
              .replace("the cell's terminal tilts", "the terminal tilts of the cell's loops "
                                                     "at rest"))
       for name, (unit, what) in SUMMARY_COLUMNS.items() if name in (
           "p_stable", "p_in_plane", "p_3d", "tilt_q25", "tilt_median", "tilt_q75",
           "tilt_median_low", "tilt_median_high")},
    "nfev_mean": CONVERGENCE_COLUMNS["nfev_mean"],
    "wall_s": CONVERGENCE_COLUMNS["wall_s"],
    "baseline": (TEXT, "the t = 10 sweep of the same cell compared with (16 seeds at the "
                       "defaults, data/convergence_runs), or empty"),
    "base_seeds": (COUNT, "seeds of the t = 10 sample"),
    "base_p_steady": (PROBABILITY, "share of the t = 10 sample at rest (passed the steady "
                                   "test) by t = 10"),
    "base_p_3d": (PROBABILITY, "share of the t = 10 sample ending 3D"),
    "base_tilt_median": (DEG, "median terminal tilt of the t = 10 sample"),
    **{k: (unit, what.replace("this setting's minus its baseline's", "at rest minus at t = 10"))
       for k, (unit, what) in {
           **_difference_columns("p_in_plane", PROBABILITY, "P(in-plane)"),
           **_difference_columns("p_3d", PROBABILITY, "P(3D)"),
           **{k: v for q in (25, 50, 75)
              for k, v in _difference_columns(f"tilt_q{q}", DEG, f"terminal tilt quantile {q}%")
              .items()}}.items()},
    # (at rest: over the loops that came to rest; at t = 10: over every row of the sample)
    "verdict": (TEXT, "different (a Bonferroni interval excludes 0) or same (within the "
                      "intervals), at rest against t = 10; empty where no t = 10 sample"),
}

#: ``data/paper_range_overview.parquet`` (``scripts/range_overview.py``): the paper's 225
#: cells, each from the one committed study that answers it best (a run-to-rest sweep first,
#: else a t = 10 table).
RANGE_OVERVIEW_COLUMNS = {
    **{name: REST_STUDY_COLUMNS[name] for name in ("g0", "theta0_deg", "q0")},
    "source": (TEXT, "the committed table or sweep the cell's row comes from (data/...; an "
                     "unfinished --seeds auto part with its finished rounds); empty where the "
                     "cell was never run"),
    "t_max": (TIME, "the horizon its runs had (10: the paper's; 40: run to rest); NaN if not run"),
    "seeds": (COUNT, "rows (seeds) of the cell in its source (0: not run)"),
    **{name: SUMMARY_COLUMNS[name] for name in (
        "p_stable", "p_stable_low", "p_stable_high", "p_in_plane", "p_in_plane_low",
        "p_in_plane_high", "p_3d", "p_3d_low", "p_3d_high", "p_failed")},
    **{f"p_not_rest_t10{end}": (PROBABILITY, what) for end, what in (
        ("", "P(not at rest by t = 10 t_u): the share of the runs that did not fail still "
             "moving at the paper's horizon; 1 - p_rest_t10, or 1 - steady / (seeds - failed) "
             "for a t = 10 table without it"),
        ("_low", "lower end of its 95% interval (Wilson, or the Kaplan-Meier log-log band)"),
        ("_high", "upper end of its 95% interval"))},
    "at_rest": (COUNT, "rows that passed the steady test before t_max"),
    **{name: SUMMARY_COLUMNS[name] for name in (
        "t_rest_median", "t_rest_q95", "rest_inside", "rest_below", "rest_outside",
        "tilt_median", "tilt_median_low", "tilt_median_high")},
}


def field_metadata(name, table=RESULT_COLUMNS):
    """Parquet field metadata of a column: {b"unit": ..., b"description": ...}."""
    unit, description = table[name]
    return {b"unit": unit.encode(), b"description": description.encode()}


def markdown(table=RESULT_COLUMNS):
    """The column table as Markdown (docs), a ``|`` inside a unit or a description
    escaped as ``\\|`` so that it does not end its cell."""
    def cell(text):
        return text.replace("|", "\\|")
    lines = ["| column | unit | meaning |", "|---|---|---|"]
    lines += [f"| `{name}` | {cell(unit)} | {cell(text)} |" for name, (unit, text) in table.items()]
    return "\n".join(lines)


#: The tables ``python -m loopsim.columns [NAME]`` prints.
TABLES = {"results": RESULT_COLUMNS, "trajectory": TRAJECTORY_COLUMNS,
          "summary": SUMMARY_COLUMNS, "compare": COMPARE_COLUMNS, "stops": STOP_COLUMNS,
          "convergence": CONVERGENCE_COLUMNS, "rest": REST_STUDY_COLUMNS,
          "range": RANGE_OVERVIEW_COLUMNS}

def main(argv=None):
    """``python -m loopsim.columns [NAME]``: print a column table as Markdown."""
    import argparse

    parser = argparse.ArgumentParser(
        prog="python -m loopsim.columns",
        description="Print the declared columns of one of loopsim's tables (unit and "
        "meaning of each) as a Markdown table.")
    parser.add_argument("table", nargs="?", default="results", choices=sorted(TABLES),
                        help="which table (default: results, the sweep's per-case table)")
    print(markdown(TABLES[parser.parse_args(argv).table]))


if __name__ == "__main__":
    main()
