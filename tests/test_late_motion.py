"""Whether a run's end is a terminal state (loopsim.late_motion): the classification on
motions whose tilt and aspect ratio are known in closed form (tilted circles and
ellipses), the vectorised diagnostics against the per-shape ones, and the same fields
from simulate(), sweep rows and summaries."""
import math

import numpy as np
import pytest

import loopsim
from loopsim import diagnostics, late_motion, outcomes, shapes, storage

N = 4
THRESHOLDS = outcomes.Thresholds()


def circle(tilt_deg, stretch=1.0):
    """A circle tilted by tilt_deg (exactly: no perturbation), its first mode's in-plane
    horizontal axis stretched by ``stretch``: aspect ratio stretch² (an ellipse)."""
    x = shapes.start_shape(tilt_deg, N, 0.0, 0)[0].copy()
    x[:, 1] *= stretch  # the cos s axis: horizontal, along x
    return x


def motion(tilts, stretches=None, t_end=10.0, ok=True, steady=False):
    """late_motion of a run whose sampled shapes have these tilts (and stretches)."""
    times = late_motion.sample_times(0.0, t_end)
    tilt = np.broadcast_to(tilts, times.shape)
    stretch = np.broadcast_to(1.0 if stretches is None else stretches, times.shape)
    states = np.array([circle(a, s) for a, s in zip(tilt, stretch)])
    return late_motion.late_motion(times, states, 0.0, t_end, t_end, states[-1], ok, steady,
                                   THRESHOLDS)


def test_tilted_circles_and_ellipses_have_their_closed_form_tilt_and_aspect_ratio():
    """The circle's tilt is the angle it was built with, the ellipse's aspect ratio the
    square of its axis ratio (a ratio of variances), to rounding."""
    for tilt in (0.0, 12.0, 45.0, 89.0):
        for stretch in (1.0, 1.5, 3.0):
            x = circle(tilt, stretch)
            assert diagnostics.tilt_deg(x) == pytest.approx(tilt, abs=1e-9)
            assert diagnostics.aspect_ratio(x) == pytest.approx(stretch**2, rel=1e-12)


def test_the_vectorised_diagnostics_equal_the_per_shape_ones():
    rng = np.random.default_rng(3)
    xs = np.array([circle(a, s) + 0.05 * rng.standard_normal((3, 2 * N + 1))
                   for a, s in zip(rng.uniform(0, 90, 40), rng.uniform(1, 3, 40))])
    xs[7] = np.nan  # a time not reached
    tilt, aspect = diagnostics.tilts_and_aspect_ratios(xs)
    assert math.isnan(tilt[7]) and math.isnan(aspect[7])
    for i in np.delete(np.arange(len(xs)), 7):
        assert tilt[i] == pytest.approx(diagnostics.tilt_deg(xs[i]), abs=1e-9)
        assert aspect[i] == pytest.approx(diagnostics.aspect_ratio(xs[i]), rel=1e-12)


def test_a_loop_at_rest_is_quiet_and_has_held_its_tilt_for_the_whole_run():
    m = motion(30.0)
    assert m["terminal_state"] == "quiet" and m["time_since_swing"] == 10.0
    assert m["late_tilt_min_deg"] == pytest.approx(30.0) == m["late_tilt_max_deg"]
    assert m["late_aspect_mean"] == pytest.approx(1.0)


def test_a_tumbling_loop_is_unsteady_with_the_range_of_its_late_window():
    """Tilt 30 + 20 sin(2π t): the late window (t ≥ 8) sees the whole swing, 10-50 deg,
    mean 30; the tilt last stood more than 1 deg from its end value one sample before t_end."""
    t = late_motion.sample_times(0.0, 10.0)
    m = motion(30.0 + 20.0 * np.sin(2 * np.pi * t))
    assert m["terminal_state"] == "unsteady"
    assert m["late_tilt_min_deg"] == pytest.approx(10.0, abs=1e-6)
    assert m["late_tilt_max_deg"] == pytest.approx(50.0, abs=1e-6)
    assert m["late_tilt_mean_deg"] == pytest.approx(30.0, abs=0.3)
    assert m["time_since_swing"] == pytest.approx(t[1] - t[0])


def test_a_changing_aspect_ratio_alone_is_unsteady():
    t = late_motion.sample_times(0.0, 10.0)
    m = motion(30.0, stretches=1.0 + 0.02 * t)  # aspect 1.16^2 -> 1.2^2 over t >= 8
    assert m["terminal_state"] == "unsteady"
    assert m["late_aspect_min"] == pytest.approx(1.16**2) and m["late_aspect_max"] == 1.2**2
    assert m["time_since_swing"] == 10.0  # the tilt never moved


def test_the_time_since_the_last_swing_and_a_window_that_no_longer_sees_it():
    """Tilt 50 until t = 7, then 30: quiet (the window starts at t = 8), and the last
    sample more than 1 deg away is t = 6.975, 3.025 before the end."""
    t = late_motion.sample_times(0.0, 10.0)
    m = motion(np.where(t < 7.0, 50.0, 30.0))
    assert m["terminal_state"] == "quiet"
    assert m["time_since_swing"] == pytest.approx(10.0 - 6.975)
    assert m["late_tilt_max_deg"] == pytest.approx(30.0)
    late = motion(np.where(t < 9.0, 50.0, 30.0))  # inside the window: it moved
    assert late["terminal_state"] == "unsteady" and late["late_tilt_max_deg"] == pytest.approx(50)


def test_the_window_is_a_share_of_the_run():
    """A run of t_end = 1 judges its last 0.2 t_u: a swing at t = 0.7 is outside."""
    t = late_motion.sample_times(0.0, 1.0)
    assert late_motion.late_window(0.0, 1.0) == pytest.approx(0.2)
    assert motion(np.where(t < 0.7, 50.0, 30.0), t_end=1.0)["terminal_state"] == "quiet"
    assert motion(np.where(t < 0.9, 50.0, 30.0), t_end=1.0)["terminal_state"] == "unsteady"


def test_steady_and_failed_runs():
    t = late_motion.sample_times(0.0, 10.0)
    assert motion(np.where(t < 9.5, 50.0, 30.0), steady=True)["terminal_state"] == "steady"
    failed = motion(30.0, ok=False)  # the motion up to the failure, still described
    assert failed["terminal_state"] == "failed" and failed["late_tilt_max_deg"] == pytest.approx(30)
    times = late_motion.sample_times(0.0, 10.0)
    nothing = late_motion.late_motion(times, np.full((times.size, 3, 2 * N + 1), np.nan), 0.0,
                                      10.0, 0.0, np.full((3, 2 * N + 1), np.nan), False, False,
                                      THRESHOLDS)
    assert nothing["terminal_state"] == "failed"
    assert all(math.isnan(nothing[k]) for k in storage.MOTION_FIELDS[1:])


def test_an_early_stop_judges_the_window_before_it():
    """A run stopped at t = 5 of t_end = 10: samples after 5 are NaN (not reached); its
    window is [3, 5], and the terminal state is its last sample."""
    times = late_motion.sample_times(0.0, 10.0)
    states = np.array([circle(50.0 if ti < 2.0 else 30.0) for ti in times])
    states[times > 5.0] = np.nan
    m = late_motion.late_motion(times, states, 0.0, 10.0, 5.0, circle(30.0), True, True,
                                THRESHOLDS)
    assert m["terminal_state"] == "steady"
    assert m["late_tilt_max_deg"] == pytest.approx(30.0)
    assert m["time_since_swing"] == pytest.approx(5.0 - 1.975)


def test_simulate_and_a_sweep_row_give_the_same_late_motion(tmp_path):
    """The serial path (simulate: the samples merged with the output times) and the batch
    kernel (the sweep) sample the same trajectory; output times change nothing."""
    rows = loopsim.sweep([150.0], [60.0], str(tmp_path / "s"), n=6, t_end=1.0, seeds=2,
                         twin=False, quiet=True)
    runs = [loopsim.simulate(150.0, 60.0, n=6, t_span=(0.0, 1.0), seed=1, twin=False,
                             snapshots=k) for k in (2, 7)]
    assert runs[0].motion == runs[1].motion and runs[0].nfev == runs[1].nfev
    row = rows[rows["seed"] == 1].iloc[0]
    assert row["method"] == runs[0].method and row["nfev"] == runs[0].nfev
    assert row["terminal_state"] == runs[0].terminal_state == "unsteady"
    for name in storage.MOTION_FIELDS[1:]:
        assert row[name] == pytest.approx(runs[0].motion[name], rel=1e-12), name
    summary = loopsim.summarize(rows)
    unsteady = int(rows["terminal_state"].eq("unsteady").sum())
    assert summary["unsteady"].iloc[0] == unsteady
    assert summary["p_unsteady"].iloc[0] == unsteady / 2
    assert any("still moves" in line for line in runs[0].warnings())
