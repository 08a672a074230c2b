"""The one root finder of the stability analyses: scan for a sign change, then brentq."""
import numpy as np
from scipy.optimize import brentq


def first_crossing(fun, q_max, step, xtol, q_min=0.0):
    """Smallest q in (q_min, q_max] where fun goes from negative to ≥ 0.

    Scans q_min, q_min + step, ... and refines the first bracketing interval
    with ``scipy.optimize.brentq`` (xtol, rtol = 4 eps).  Returns q_min if
    fun(q_min) ≥ 0 already, NaN if there is no crossing on the scan.
    """
    q_lo, f_lo = q_min, fun(q_min)
    if f_lo >= 0.0:
        return float(q_min)
    for q_hi in np.arange(q_min + step, q_max + step / 2, step):
        f_hi = fun(q_hi)
        if f_hi >= 0.0:
            if f_hi == 0.0:
                return float(q_hi)
            return float(brentq(fun, q_lo, q_hi, xtol=xtol, rtol=4 * np.finfo(float).eps,
                                maxiter=200))
        q_lo, f_lo = q_hi, f_hi
    return float("nan")
