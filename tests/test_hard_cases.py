"""Hard cases: each reaches its terminal state or stops with a recorded reason.

Never NaN in the summary, never a hang (the step budget bounds every run).
Fast cases run in CI; the long ones are marked slow (``pytest -m slow``).
"""
import math

import numpy as np
import pytest

from loopsim import api, integrators
from loopsim.defaults import DEFAULT_LENGTH_TOL
from loopsim.stability import paper

METHODS = sorted(integrators.METHODS)
Q_CRIT = paper.critical_q(20)  # the paper's threshold (14.561): a strongly deforming case


def check(result, benign):
    """Finite summary; a benign (shape-preserving or gently deforming) case that finished
    keeps its length to 1e-6.  The status and regime each caller asserts."""
    summary = result.summary()
    numbers = {k: v for k, v in summary.items() if isinstance(v, float)
               and k not in ("theta_uncertainty_deg", "aspect_uncertainty",
                             "twin_theta_final_deg", "twin_aspect_ratio")}  # NaN: no twin
    assert all(math.isfinite(v) for v in numbers.values()), numbers
    assert np.all(np.isfinite(result.x)) and result.x.dtype == np.float64
    assert math.isfinite(result.length_error_max)
    if benign and result.success:
        assert abs(summary["length_error"]) < 1e-6
    return summary


#: (label, g0, theta0, kwargs, expected status, expected regime, bound on the terminal
#: |relative length error|): bounds about 10-100x what both methods reach (measured:
#: very flexible 0.089 (transient 0.13, both methods: at t = 0.3 radau5's transient was
#: 0.18 on one machine and 0.251, a LENGTH_ERROR stop, on an AMD EPYC: at n = 6 this case
#: is so under-resolved that its length error follows the rounding), vertical 5.5e-6, horizontal 1.3e-11, high n
#: 6e-8, near critical 9.1e-6, large perturbation 1.8e-6, no penalty 6.4e-9, large
#: penalty 1.2e-10, early stop 1.3e-11, tiny budget 2.2e-5).
FAST = [
    ("very flexible", 1000.0, 45.0, dict(t_span=(0, 0.1)), "ok", "3d", 0.15),
    ("vertical", 100.0, 90.0, dict(t_span=(0, 1.0)), "ok", "3d", 1e-4),
    ("horizontal", 100.0, 0.0, dict(t_span=(0, 1.0)), "ok", "stable", 1e-9),
    ("high n", 60.0, 30.0, dict(n=16, t_span=(0, 0.05)), "ok", "stable", 1e-6),
    ("near critical q", 3 * (Q_CRIT + 0.005) / math.sin(math.radians(30)), 30.0,
     dict(t_span=(0, 2.0)), "ok", "3d", 1e-4),  # length error set by the truncation
    ("large perturbation", 60.0, 30.0, dict(perturbation=0.1, t_span=(0, 1.0)), "ok", "3d",
     1e-4),
    ("no penalty", 10.0, 30.0, dict(w=0.0, t_span=(0, 2.0)), "ok", "stable", 1e-7),
    ("large penalty", 10.0, 30.0, dict(w=1000.0, t_span=(0, 2.0)), "ok", "stable", 1e-8),
    ("long time, early stop", 10.0, 30.0, dict(t_span=(0, 100.0), steady_tol=1e-6), "ok",
     "stable", 1e-9),
    ("tiny step budget", 150.0, 60.0, dict(max_steps=30), "step budget exhausted", "failed",
     1e-3),
]


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("label, g0, theta0, kwargs, status, regime, length_bound", FAST,
                         ids=[c[0] for c in FAST])
def test_hard_case(method, label, g0, theta0, kwargs, status, regime, length_bound):
    """Each hard case ends with its expected status and regime and keeps its length
    within its bound; a failure mode changing (say, "no penalty" failing) fails here."""
    result = api.simulate(g0, theta0, method=method, twin=False, **{"n": 6, **kwargs})
    summary = check(result, benign=False)
    assert summary["status"] == status and result.regime == regime
    assert abs(summary["length_error"]) < length_bound
    assert result.length_error_max < DEFAULT_LENGTH_TOL
    if label == "vertical":  # tilts from 90 to about 24.7 degrees by t = 1, both methods
        assert 20.0 < summary["theta_final_deg"] < 30.0
    if label == "horizontal":  # q = 0: the circle stays level
        assert abs(summary["theta_final_deg"]) < 1e-3
    if label == "large perturbation":  # the penalty pulls the length back
        assert abs(summary["length_error"]) < 1e-2 * result.length_error_max
    if label == "tiny step budget":
        assert result.t_final < 0.1 and not result.success
    if label == "long time, early stop":
        assert result.stop_reason == "steady" and result.t_final < 100.0


#: (label, g0, theta0, kwargs, benign, expected status, regime, determined (None: not
#: asserted), terminal tilt range (deg), bound on the terminal |relative length error|),
#: as measured with both methods at the default n = 6: "very flexible" outgrows n = 6 and
#: stops on its length error (rkf45 at t = 0.09, radau5 at 2.2); "vertical" ends 3D at
#: 79.1 (radau5) and 10.9 deg (rkf45), each flagged not determined (twins 60-75 deg
#: away); the others end alike with both methods (tilts 44.981, 29.888, 65.870 deg;
#: length errors 1.3e-11, 8e-8, 7.9e-6).
SLOW = [
    ("very flexible, t = 10", 1000.0, 60.0, dict(), False, "length error too large", "failed",
     None, (0.0, 90.0), 1.0),
    ("vertical, t = 10", 200.0, 90.0, dict(), False, "ok", "3d", False, (0.0, 90.0), 0.05),
    ("long time", 30.0, 45.0, dict(t_span=(0, 100.0)), True, "ok", "stable", True,
     (44.97, 44.99), 1e-9),
    ("high n, t = 2", 60.0, 30.0, dict(n=16, t_span=(0, 2.0)), True, "ok", "in-plane", True,
     (29.88, 29.90), 1e-6),
    # just below the paper's 14.561, above both corrected thresholds (8.90 in plane, 10.65
    # out of it): it leaves its plane; its length error is set by the truncation
    ("near critical q, t = 10", 3 * (Q_CRIT - 0.005) / math.sin(math.radians(60)), 60.0,
     dict(), False, "ok", "3d", True, (65.86, 65.88), 1e-4),
]


@pytest.mark.slow
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("label, g0, theta0, kwargs, benign, status, regime, determined, "
                         "tilt, length_bound", SLOW, ids=[c[0] for c in SLOW])
def test_hard_case_long(method, label, g0, theta0, kwargs, benign, status, regime, determined,
                        tilt, length_bound):
    """Each long case ends with its expected status, regime and determinacy, its terminal
    tilt in its range and its length error within its bound."""
    result = api.simulate(g0, theta0, method=method, **{"n": 6, **kwargs})
    summary = check(result, benign)
    assert summary["status"] == status and result.regime == regime
    if determined is not None:
        assert result.determined is determined
    assert tilt[0] < summary["theta_final_deg"] < tilt[1]
    assert abs(summary["length_error"]) < length_bound
