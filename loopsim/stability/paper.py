"""Linear stability of the translating circle as analysed in the paper (§4), and its correction.

Waszkiewicz, Szymczak & Lisicki, "Stability of sedimenting flexible loops",
JFM 2021, section 4.  Out-of-plane perturbations ζ(s, t) of the planar circle
obey ∂t ζ = L[ζ] with, in the paper,

    L = -∂⁴ + ∂² + q (sin s ∂ + cos s ∂²),      q = g0 sin θ0 / 3.

The paper's ∂² term has the wrong sign: its T0 = 1 + q cos s should be
-1 + q cos s (docs/stability.md).  The *corrected* operator

    L = -∂⁴ - ∂² + q (sin s ∂ + cos s ∂²)

reproduces the out-of-plane block of the full Jacobian (``stability.full_linear``).
Both are built here from one formula with ``corrected`` choosing the sign.

Product-to-sum formulas give, for k ≥ 1 and the sign σ of ∂² (+1 paper, -1
corrected),

    L[sin ks] = -(k⁴ + σk²) sin ks - q k(k+1)/2 sin (k-1)s - q k(k-1)/2 sin (k+1)s

(the paper's text prints + on the two q terms; its printed matrix has the
signs above, and flipping them is the similarity D M D with D = diag((-1)^k),
so the spectrum is the same).  On span{sin ks} the matrix M (column k = image
of sin ks) is tridiagonal with off-diagonal products q²(k-1)k(k+1)(k+2)/4 ≥ 0,
so M is similar to the symmetric tridiagonal T with off-diagonal
-|q| sqrt((k-1)k(k+1)(k+2))/2: all eigenvalues are real, computed from T
(LAPACK bisection, near-underflow absolute tolerance).  The paper's operator
acts on k = 1..n; the corrected one on k = 2..n (sin s is an exact null
vector, a rigid rotation).  The cos ks subspace gives the same matrices.

The paper's critical value is q_c = 14.56105439107 (n ≥ 10; n = 3 gives
sqrt(300)); for n ≤ 2 its matrix is upper triangular and never crosses.
The corrected operator's is 10.6493 (docs/stability.md).
"""
import numpy as np
from scipy.linalg import eigh_tridiagonal

from .. import validation
from .roots import first_crossing

__all__ = ["paper_operator", "largest_growth_rate", "critical_q", "critical_q_table",
           "paper_growth_rates", "SIGN_NOTE"]

#: One line on why the paper's threshold is wrong, printed with its values.
SIGN_NOTE = ("the paper's operator has the wrong sign on the d²/ds² term (T0 = 1 + q cos s "
             "instead of -1 + q cos s), so its q_c = 14.561 is not the loop's threshold; "
             "see docs/stability.md")
# Absolute tolerance for LAPACK's bisection (dstebz): 2 * underflow threshold
# is its recommended value for the most accurate eigenvalues.
_EIG_TOL = 2.0 * np.finfo(float).tiny
# Grid step (in q) of the bracketing scan in critical_q.
_SCAN_STEP = 0.5


def _wavenumbers(n, corrected):
    return np.arange(2 if corrected else 1, n + 1, dtype=float)


def _symmetric_tridiagonal(q, n, corrected):
    """Diagonal d and off-diagonal e of T, the symmetric form of M (see module doc)."""
    k = _wavenumbers(n, corrected)
    sign = -1.0 if corrected else 1.0
    d = -(k**4 + sign * k**2)
    km = k[:-1]
    e = -0.5 * abs(q) * np.sqrt((km - 1.0) * km * (km + 1.0) * (km + 2.0))
    return d, e


def _lambda_max(q, n, corrected=False):
    """Largest eigenvalue of M(q) for validated q, n (no input checks)."""
    d, e = _symmetric_tridiagonal(q, n, corrected)
    if d.size == 1:
        return float(d[0])
    w = eigh_tridiagonal(d, e, eigvals_only=True, select="i",
                         select_range=(d.size - 1, d.size - 1), tol=_EIG_TOL)
    return float(w[0])


def _check(q, n, corrected):
    q = validation.check_real("q", q)
    n = validation.check_integer("n", n, 2 if corrected else 1)
    return q, n


def paper_operator(q, n, corrected=False):
    """Matrix of L on span{sin ks, k = 1..n} (corrected: k = 2..n); column j is the image
    of the j-th basis function.  ``corrected=False`` is the paper's printed matrix."""
    q, n = _check(q, n, corrected)
    k = _wavenumbers(n, corrected)
    sign = -1.0 if corrected else 1.0
    m = np.diag(-(k**4 + sign * k**2))
    for i, kk in enumerate(k):
        if i > 0:
            m[i - 1, i] = -q * kk * (kk + 1.0) / 2.0
        if i < len(k) - 1:
            m[i + 1, i] = -q * kk * (kk - 1.0) / 2.0
    return m


def largest_growth_rate(q, n, corrected=False):
    """Largest eigenvalue of paper_operator(q, n, corrected) (all are real)."""
    q, n = _check(q, n, corrected)
    return _lambda_max(q, n, corrected)


def paper_growth_rates(q_values, n, corrected=False):
    """Largest growth rate λ_max(q) for each q in q_values (array of the same shape)."""
    n = validation.check_integer("n", n, 2 if corrected else 1)
    try:
        qs = np.asarray(q_values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"q_values must be real numbers, got {q_values!r}") from None
    if not np.all(np.isfinite(qs)):
        raise ValueError(f"q_values must all be finite, got {q_values!r}")
    out = np.empty(qs.shape)
    for idx, qv in np.ndenumerate(qs):
        out[idx] = _lambda_max(float(qv), n, corrected)
    return out


def critical_q(n, q_max=100.0, corrected=False):
    """Smallest q > 0 at which λ_max of the n-mode truncation crosses zero (to ~1e-15
    relative), or NaN if λ_max stays < 0 on [0, q_max] (always for the paper's n ≤ 2)."""
    n = validation.check_integer("n", n, 2 if corrected else 1)
    q_max = validation.check_real("q_max", q_max, low=0.0, low_open=True)
    return first_crossing(lambda q: _lambda_max(q, n, corrected), q_max, _SCAN_STEP, 1e-15)


def critical_q_table(n_max=60, corrected=False):
    """List of (n, critical_q(n)) for n = 1..n_max (NaN where no crossing)."""
    n_max = validation.check_integer("n_max", n_max, 1)
    low = 2 if corrected else 1
    return [(n, critical_q(n, corrected=corrected)) for n in range(low, n_max + 1)]
