"""What the end of a run means: its regime, whether its truncation resolved it, and
whether its terminal outcome is *determined*.

Determinacy.  A 3D transient can amplify small errors so much that its terminal
tilt is a sample of an ill-conditioned transient rather than an outcome of the
inputs.  Every case is therefore run twice from the same start: the run itself,
and a *twin* with every tolerance ``TWIN_FACTOR`` times stricter (rtol, atol
and, with ``n="auto"``, the spectral-tail tolerance).  When both runs converge,
the twin's error is about a tenth of the run's, so their difference estimates the
run's own error at the tolerances used::

    theta_uncertainty_deg = |θ_final − θ_final(twin)|
    aspect_uncertainty    = |aspect ratio − aspect ratio(twin)|

A case is *determined* when the twin ends in the same regime with both
differences at or below ``Thresholds.determined_tilt_deg`` and
``Thresholds.determined_aspect``.  Where the transient is chaotic the two runs
part ways and the row says so.  The evidence that the estimate tracks the real
error (against fixed high-order runs from the same start, and against a
perturbed start) is in docs/auto-and-determinacy.md.
"""
import dataclasses
import math

import numpy as np

from . import diagnostics
from .defaults import RESOLVED_LENGTH_ERROR, RESOLVED_TAIL

#: The regimes (paper §6) and the label of a failed run.
REGIMES = ("stable", "in-plane", "3d", "failed")
#: The twin's tolerances are the run's divided by this.
TWIN_FACTOR = 10.0


@dataclasses.dataclass(frozen=True)
class Thresholds:
    """Regime, resolution and determinacy thresholds (``SimulationResult.thresholds``;
    stored in a sweep's table metadata).

    Attributes
    ----------
    tilt_change_deg : float, default 1.0
        |θ_final − θ0| (degrees) above which the tilt has changed: regime 3d.
    shape_change : float, default 0.01
        |aspect ratio_final − aspect ratio_initial| above which the shape has changed:
        regime in-plane (paper §6: stable = shape and tilt unchanged).
    resolved_length_error, resolved_tail : float
        A case is resolved at its n when its worst transient relative length error and
        its largest spectral tail along the run stay at or below these
        (``defaults.RESOLVED_LENGTH_ERROR``, ``defaults.RESOLVED_TAIL``).
    determined_tilt_deg, determined_aspect : float, default 0.01 and 2e-4
        The largest run–twin differences (degrees; aspect ratio) of a determined case
        (module docstring): a fifth of the accuracy users ask of a terminal state
        (0.05 deg, 1e-3), so that the run's error, about the difference, stays well
        inside it.
    """

    tilt_change_deg: float = 1.0
    shape_change: float = 0.01
    resolved_length_error: float = RESOLVED_LENGTH_ERROR
    resolved_tail: float = RESOLVED_TAIL
    determined_tilt_deg: float = 0.01
    determined_aspect: float = 2e-4

    def resolved(self, length_error_max, tail_max):
        """Whether a case with these diagnostics is resolved at its n."""
        return bool(length_error_max <= self.resolved_length_error
                    and tail_max <= self.resolved_tail)


def classify(theta0_deg, theta_final_deg, aspect_initial, aspect_final, ok,
             thresholds=Thresholds()):
    """Regime label of one case: 'stable', 'in-plane', '3d' or 'failed' (status not ok)."""
    if not ok:
        return "failed"
    if abs(theta_final_deg - theta0_deg) > thresholds.tilt_change_deg:
        return "3d"
    if abs(aspect_final - aspect_initial) > thresholds.shape_change:
        return "in-plane"
    return "stable"


def end_state(theta0_deg, aspect_initial, x, ok, thresholds=Thresholds()):
    """{regime, theta_final_deg, aspect_ratio} of a final shape x (3, 2n+1); ``ok``: the
    run succeeded.  A non-finite shape (a failed run) has NaN measures."""
    if not np.all(np.isfinite(x)):
        return dict(regime="failed", theta_final_deg=math.nan, aspect_ratio=math.nan)
    theta, aspect = diagnostics.tilt_deg(x), diagnostics.aspect_ratio(x)
    return dict(regime=classify(theta0_deg, theta, aspect_initial, aspect, ok, thresholds),
                theta_final_deg=theta, aspect_ratio=aspect)


def twin_tolerances(rtol, atol, tail_tol):
    """(rtol, atol, tail_tol) of a run's twin: each TWIN_FACTOR times stricter."""
    return rtol / TWIN_FACTOR, atol / TWIN_FACTOR, tail_tol / TWIN_FACTOR


#: The determinacy fields of a row, and their values when no twin ran.
DETERMINACY_FIELDS = ("determined", "theta_uncertainty_deg", "aspect_uncertainty",
                      "twin_nfev", "twin_regime", "twin_theta_final_deg", "twin_aspect_ratio")
NO_TWIN = dict(determined=None, theta_uncertainty_deg=math.nan, aspect_uncertainty=math.nan,
               twin_nfev=0, twin_regime=None, twin_theta_final_deg=math.nan,
               twin_aspect_ratio=math.nan)


def determinacy(run, twin, twin_nfev, thresholds=Thresholds()):
    """Determinacy fields from the run's and its twin's outcomes (dicts with
    ``regime``, ``theta_final_deg``, ``aspect_ratio``).  A failed run has no outcome: it
    is not determined, with no uncertainty to give (``determined`` is empty only where no
    twin was asked for, so a column never mixes empty and False).  The twin's own outcome
    is kept (``twin_regime``, ``twin_theta_final_deg``, ``twin_aspect_ratio``): over a
    cell's seeds the twins are a sample at the stricter tolerances (``sweeps.seeds_auto``
    checks distributions against them)."""
    outcome = dict(twin_regime=twin["regime"], twin_theta_final_deg=float(
        twin["theta_final_deg"]), twin_aspect_ratio=float(twin["aspect_ratio"]))
    if run["regime"] == "failed":
        return dict(NO_TWIN, determined=False, twin_nfev=int(twin_nfev), **outcome)
    tilt = abs(run["theta_final_deg"] - twin["theta_final_deg"])
    aspect = abs(run["aspect_ratio"] - twin["aspect_ratio"])
    determined = (run["regime"] == twin["regime"] != "failed"
                  and tilt <= thresholds.determined_tilt_deg
                  and aspect <= thresholds.determined_aspect)  # False for NaN
    return dict(determined=bool(determined), theta_uncertainty_deg=float(tilt),
                aspect_uncertainty=float(aspect), twin_nfev=int(twin_nfev), **outcome)
