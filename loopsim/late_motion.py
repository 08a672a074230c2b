"""Whether the end of a run is a terminal state: the loop's motion over its last time units.

A run that reaches t_end without passing the steady test (``steady_tol``) ends on one
moment of its motion, and its "terminal" tilt is a snapshot.  So every run also samples
its tilt and aspect ratio at ``MOTION_SAMPLES`` evenly spaced times over [t0, t_end] (by
the integrator's dense output: the steps, and every other column, are unchanged), and its
end is classified by the motion in the late window [t_final − LATE_FRACTION (t_end − t0),
t_final] (the terminal state itself included as the window's last sample):

* ``steady``: the steady test passed, and the run stopped early;
* ``quiet``: it ran to t_end, and within the window its tilt moved by at most the
  regimes' ``tilt_change_deg`` and its aspect ratio by at most their ``shape_change``
  (``outcomes.Thresholds``): settled as far as the regimes can tell, but not tested
  (``--no-early-stop``) or still drifting below the steady test's resolution;
* ``unsteady``: it moved by more within the window: no terminal state was reached, and
  the window's mean and range describe the motion instead;
* ``failed``: the run failed (the window's statistics then describe the motion up to its
  last finite state).

``time_since_swing`` is t_final minus the last sample time at which the tilt stood
more than ``tilt_change_deg`` from its terminal value (t_final − t0 when it never did):
how long the loop has held its final tilt.  Sample statistics: swings faster than the
sampling interval ((t_end − t0) / (MOTION_SAMPLES − 1), 0.025 t_u at t_end = 10) are seen
only where a sample falls on them.
"""
import math

import numpy as np

from . import diagnostics
from .storage import MOTION_FIELDS

#: Samples of tilt and aspect ratio per run, evenly spaced over [t0, t_end].
MOTION_SAMPLES = 401
#: Length of the late window, as a share of the run's requested span t_end − t0: the last
#: 2 t_u of a default run (t_end = 10), 80 sampling intervals at any t_end.
LATE_FRACTION = 0.2
#: The classes of a run's end (module docstring).
TERMINAL_STATES = ("steady", "quiet", "unsteady", "failed")


def sample_times(t0, t_end):
    """The ``MOTION_SAMPLES`` sample times of a run over [t0, t_end], in t_u."""
    return np.linspace(float(t0), float(t_end), MOTION_SAMPLES)


def failed_motion():
    """The late-motion fields of a run failed before any finite sample: nothing to
    describe."""
    return dict({name: math.nan for name in MOTION_FIELDS}, terminal_state="failed")


def late_window(t0, t_end):
    """Length of the late window of a run over [t0, t_end], in t_u."""
    return LATE_FRACTION * (float(t_end) - float(t0))


def late_motion(times, states, t0, t_end, t_final, x_final, ok, steady, thresholds):
    """The late-motion fields (``storage.MOTION_FIELDS``) of a run.

    Parameters
    ----------
    times : numpy.ndarray
        (K,) sample times, in t_u.
    states : numpy.ndarray
        (K, 3, 2n+1) shape coefficients at ``times`` (NaN rows: not reached).
    t0, t_end, t_final : float
        Start, requested end and end reached of the run, in t_u.
    x_final : numpy.ndarray
        (3, 2n+1) the terminal shape.
    ok, steady : bool
        The run succeeded; it stopped early at a steady state (``integrators.SUCCESS``,
        ``integrators.STEADY``).
    thresholds : loopsim.outcomes.Thresholds
        Their ``tilt_change_deg`` and ``shape_change`` separate quiet from unsteady.
    """
    reached = np.asarray(times) < t_final
    tilt, aspect = diagnostics.tilts_and_aspect_ratios(np.asarray(states)[reached])
    keep = np.isfinite(tilt)
    t, tilt, aspect = np.asarray(times)[reached][keep], tilt[keep], aspect[keep]
    if np.all(np.isfinite(x_final)):  # a failed run's end may not be
        t = np.append(t, t_final)
        tilt = np.append(tilt, diagnostics.tilt_deg(x_final))
        aspect = np.append(aspect, diagnostics.aspect_ratio(x_final))
    if not t.size:
        return failed_motion()
    late = t >= t[-1] - late_window(t0, t_end)
    swings = t[np.abs(tilt - tilt[-1]) > thresholds.tilt_change_deg]
    moved = (np.ptp(tilt[late]) > thresholds.tilt_change_deg
             or np.ptp(aspect[late]) > thresholds.shape_change)
    state = ("failed" if not ok else "steady" if steady else
             "unsteady" if moved else "quiet")
    return dict(terminal_state=state,
                late_tilt_mean_deg=float(tilt[late].mean()),
                late_tilt_min_deg=float(tilt[late].min()),
                late_tilt_max_deg=float(tilt[late].max()),
                late_aspect_mean=float(aspect[late].mean()),
                late_aspect_min=float(aspect[late].min()),
                late_aspect_max=float(aspect[late].max()),
                time_since_swing=float(t_final - (swings[-1] if swings.size else t0)))
