"""Linear stability of the translating circle, as analysed in the paper (§4).

Waszkiewicz, Szymczak & Lisicki, "Stability of sedimenting flexible loops",
JFM 2021, section 4.  Out-of-plane perturbations ζ(s, t) of the planar circle
obey ∂t ζ = L[ζ] with

    L = -∂⁴ + ∂² + q (sin s ∂ + cos s ∂²),      q = g0 sin θ0 / 3.

Product-to-sum formulas give, for k ≥ 1,

    L[sin ks] = -(k² + k⁴) sin ks - q k(k+1)/2 sin (k-1)s - q k(k-1)/2 sin (k+1)s

(the paper's text prints + on the two q terms; its printed matrix has the
signs above, and flipping them is the similarity D M D with D = diag((-1)^k),
so the spectrum is the same).  On span{sin ks, k = 1..n} the matrix M
(column k = image of sin ks) is tridiagonal:

    M[k, k]   = -(k² + k⁴)                      -2, -20, -90, -272, ...
    M[k-1, k] = -q k(k+1)/2   (superdiagonal)   -3q, -6q, -10q, -15q, ...
    M[k+1, k] = -q k(k-1)/2   (subdiagonal)      0,  -q,  -3q,  -6q, ...

(indices 1-based).  The products of the off-diagonal pairs,
q² (k-1)k(k+1)(k+2)/4 (k = 1..n-1, pair between rows k and k+1), are ≥ 0,
so M is similar to the symmetric tridiagonal T with off-diagonal
-|q| sqrt((k-1)k(k+1)(k+2))/2: all eigenvalues are real, and they are
computed from T (LAPACK bisection, near-underflow absolute tolerance), which
pins the eigenvalue near zero to ~1e-15 even for large n.  The cos ks
subspace gives the same matrix.

Because T = A + |q| B, the largest eigenvalue is a convex function of q ≥ 0
(and even in q); with λ_max(0) = -2 it crosses zero at most once for q > 0.
The paper's critical value is q_c = 14.56105439107 (n ≥ 10); n = 3 gives
sqrt(300), n = 4: 14.8106, n = 6: 14.56146, n = 8: 14.5610545; for n ≤ 2 the
matrix is upper triangular (M[2, 1] = 0), the eigenvalues stay -2, -20 and
there is no crossing.

Note: this reproduces the *paper's* analysis; see the project's physics notes
on whether the paper's operator is the correct linearisation.
"""

from __future__ import annotations

import math
import numbers

import numpy as np
from scipy.linalg import eigh_tridiagonal
from scipy.optimize import brentq

__all__ = [
    "paper_operator",
    "largest_growth_rate",
    "critical_q",
    "critical_q_table",
    "paper_growth_rates",
]

# Absolute tolerance for LAPACK's bisection (dstebz): 2 * underflow threshold
# is its recommended value for the most accurate eigenvalues.
_EIG_TOL = 2.0 * np.finfo(float).tiny
# Grid step (in q) of the bracketing scan in critical_q.
_SCAN_STEP = 1.0


def _check_n(n, name="n"):
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, numbers.Integral):
        raise ValueError(f"{name} must be an int >= 1, got {n!r}")
    if n < 1:
        raise ValueError(f"{name} must be an int >= 1, got {n!r}")
    return int(n)


def _check_q(q, name="q"):
    if isinstance(q, (bool, np.bool_)) or not isinstance(q, numbers.Real):
        raise ValueError(f"{name} must be a finite real number, got {q!r}")
    qf = float(q)
    if not math.isfinite(qf):
        raise ValueError(f"{name} must be a finite real number, got {q!r}")
    return qf


def _symmetric_tridiagonal(q, n):
    """Diagonal d and off-diagonal e of T, the symmetric form of M (see module doc)."""
    k = np.arange(1, n + 1, dtype=float)
    d = -(k**2 + k**4)
    km = k[:-1]
    e = -0.5 * abs(q) * np.sqrt((km - 1.0) * km * (km + 1.0) * (km + 2.0))
    return d, e


def _lambda_max(q, n):
    """Largest eigenvalue of M(q) for validated q, n (no input checks)."""
    d, e = _symmetric_tridiagonal(q, n)
    if n == 1:
        return float(d[0])
    w = eigh_tridiagonal(d, e, eigvals_only=True, select="i",
                         select_range=(n - 1, n - 1), tol=_EIG_TOL)
    return float(w[0])


def paper_operator(q, n):
    """Matrix of L = -∂⁴ + ∂² + q(sin s ∂ + cos s ∂²) on span{sin ks, k = 1..n}.

    Column k holds the coefficients of L[sin ks]: M[k,k] = -(k²+k⁴),
    M[k-1,k] = -q k(k+1)/2, M[k+1,k] = -q k(k-1)/2 (1-based), truncated at n.
    Identical to the paper's printed matrix.  Returns an (n, n) float array.
    """
    q = _check_q(q)
    n = _check_n(n)
    k = np.arange(1, n + 1, dtype=float)
    m = np.diag(-(k**2 + k**4))
    if n > 1:
        kc = k[1:]   # columns 2..n: superdiagonal M[k-1, k]
        m[np.arange(n - 1), np.arange(1, n)] = -q * kc * (kc + 1.0) / 2.0
        kc = k[:-1]  # columns 1..n-1: subdiagonal M[k+1, k]
        m[np.arange(1, n), np.arange(n - 1)] = -q * kc * (kc - 1.0) / 2.0
    return m


def largest_growth_rate(q, n):
    """Largest real part of the eigenvalues of paper_operator(q, n).

    The eigenvalues are real (M is similar to a symmetric tridiagonal matrix)
    and are computed from that symmetric form by bisection.
    """
    return _lambda_max(_check_q(q), _check_n(n))


def paper_growth_rates(q_values, n):
    """Largest growth rate λ_max(q) of the truncated L for each q in q_values.

    Returns a float array with the shape of ``np.asarray(q_values)``.
    """
    n = _check_n(n)
    try:
        qs = np.asarray(q_values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"q_values must be real numbers, got {q_values!r}") from None
    if not np.all(np.isfinite(qs)):
        raise ValueError(f"q_values must all be finite, got {q_values!r}")
    out = np.empty(qs.shape)
    for idx, qv in np.ndenumerate(qs):
        out[idx] = _lambda_max(float(qv), n)
    return out


def critical_q(n, q_max=100.0):
    """Smallest q > 0 at which λ_max of the n-mode truncation crosses zero.

    Brackets the crossing by scanning q = 0, 1, 2, ... up to q_max, then
    refines with scipy.optimize.brentq (xtol 1e-15, rtol 4 eps); the result is
    accurate to ~1e-15 relative.  Returns NaN if λ_max stays ≤ 0 on [0, q_max]
    (always the case for n ≤ 2, where the eigenvalues are -2 and -20).
    """
    n = _check_n(n)
    q_max = _check_q(q_max, "q_max")
    if q_max <= 0.0:
        raise ValueError(f"q_max must be > 0, got {q_max!r}")
    grid = np.linspace(0.0, q_max, max(2, int(math.ceil(q_max / _SCAN_STEP)) + 1))
    q_lo, f_lo = grid[0], _lambda_max(grid[0], n)
    for q_hi in grid[1:]:
        f_hi = _lambda_max(q_hi, n)
        if f_hi == 0.0:
            return float(q_hi)
        if f_hi > 0.0:
            if f_lo == 0.0:  # cannot happen for q_lo = 0 (λ_max(0) = -2)
                return float(q_lo)
            return float(brentq(_lambda_max, q_lo, q_hi, args=(n,),
                                xtol=1e-15, rtol=4.0 * np.finfo(float).eps,
                                maxiter=200))
        q_lo, f_lo = q_hi, f_hi
    return float("nan")


def critical_q_table(n_max=60):
    """List of (n, critical_q(n)) for n = 1..n_max (NaN where no crossing)."""
    n_max = _check_n(n_max, "n_max")
    return [(n, critical_q(n)) for n in range(1, n_max + 1)]
