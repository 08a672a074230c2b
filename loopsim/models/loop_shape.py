"""What the driver monitors on a loop (x the (3, 2n+1) position coefficients): its length
error, its spectral tail and the shape invariants that define a steady state."""
import numpy as np

from ..defaults import DEFORMATION_FLOOR
from ..jit import kernel
from ..linalg import copy_into


@kernel
def relative_length_error(x, ops, ws):
    """(L - 2π) / 2π with L = ∫|x'| ds by the trapezoid rule on the M-point grid.

    |x'| is smooth and periodic, so the rule converges spectrally, but |x'| is
    not a trigonometric polynomial: against a 256-point grid, random smooth shapes
    (amplitude 0.1) differ by up to 3.5e-8 at n = 6, 1.3e-10 at n = 8 and 1.1e-11 at
    n = 10 (tests/test_twins.py); near unit speed the error is far smaller.
    """
    np.dot(x, ops.S1T, ws.tangent)
    total = 0.0
    for i in range(ops.m):
        total += np.sqrt(ws.tangent[0, i] ** 2 + ws.tangent[1, i] ** 2 + ws.tangent[2, i] ** 2)
    return total / ops.m - 1.0


@kernel
def energy_sums(x):
    """(Σ_{k ≥ 1} E_k, Σ_{k ≥ 2} E_k, Σ_{k ≥ max(2, n-1)} E_k) of x (3, 2n+1), with
    E_k = ½ Σ_xyz (a_k² + b_k²) (the ½ cancels in every ratio: left out)."""
    n = (x.shape[1] - 1) // 2
    first = max(2, n - 1)
    total = 0.0
    deformation = 0.0
    top = 0.0
    for k in range(1, n + 1):
        energy = 0.0
        for c in range(3):
            energy += x[c, k] ** 2 + x[c, n + k] ** 2
        total += energy
        if k >= 2:
            deformation += energy
        if k >= first:
            top += energy
    return total, deformation, top


@kernel
def spectral_tail(x):
    """Share of the loop's deformation carried by its top modes k ≥ max(2, n − 1), x (3, 2n+1):

        sqrt(Σ_{k ≥ max(2, n-1)} E_k / (Σ_{k ≥ 2} E_k + φ² Σ_{k ≥ 1} E_k)),
        E_k = ½ Σ_xyz (a_k² + b_k²),  φ = ``defaults.DEFORMATION_FLOOR``

    (the same as ``diagnostics.spectral_tail``; 0 for a point).  Modes k ≥ 2 are what
    deforms a circle; relative to them, the tail measures what the truncation does to
    the deformation that a transient amplifies, not to the loop's size.
    """
    total, deformation, top = energy_sums(x)
    scale = deformation + DEFORMATION_FLOOR ** 2 * total
    return np.sqrt(top / scale) if scale > 0.0 else 0.0


@kernel
def top_mode_share(x):
    """RMS amplitude of the top modes k ≥ max(2, n − 1) of x relative to the loop's,
    sqrt(Σ_{k ≥ max(2, n-1)} E_k / Σ_{k ≥ 1} E_k): the absolute size of the tail."""
    total, _, top = energy_sums(x)
    return np.sqrt(top / total) if total > 0.0 else 0.0


@kernel
def shape_invariants(x):
    """Covariance eigenvalues (size and shape; invariant under rigid motions and
    arc-length shifts) and |n_z| of the best-fit plane's normal (the tilt), as one array.

    C = ½ Σ_k (a_k a_kᵀ + b_k b_kᵀ) over the modes k ≥ 1 (``diagnostics.covariance``).
    """
    k = x.shape[1]
    cov = np.zeros((3, 3))
    for a in range(3):
        for b in range(3):
            acc = 0.0
            for j in range(1, k):
                acc += x[a, j] * x[b, j]
            cov[a, b] = 0.5 * acc
    values, vectors = np.linalg.eigh(cov)
    out = np.empty(4)
    copy_into(out, values)  # out[:3]
    out[3] = abs(vectors[2, 0])
    return out
