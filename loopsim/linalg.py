"""Dense linear algebra in Numba: LAPACK's LU (implicit integrators) and QR (tension solve).

The factorisations, the O(n³) parts, are scipy's LAPACK getrf and geqrf,
reached through the ``numba_xxgetrf`` and ``numba_ez_geqrf`` wrappers that
Numba itself uses for ``np.linalg`` (external symbols, so kernels calling
them stay cacheable; real and complex LU by the array's dtype).  The O(n²)
work with those factors (triangular solves, applying the reflectors) is
written here, since Numba wraps no getrs or ormqr.

Convention.  Arrays are row-major (C order); LAPACK reads a row-major a as
the column-major aᵀ and factorises it, P aᵀ = L U.  Hence a = Uᵀ Lᵀ P, and in
the row-major buffer ``lu`` left by :func:`lu_factor`, Uᵀ is the lower
triangle with the diagonal and Lᵀ the strict upper triangle (unit diagonal);
``piv`` holds LAPACK's 1-based row swaps.  :func:`lu_solve` solves a x = b:
Uᵀ z = b (forward), Lᵀ w = z (backward), x = Pᵀ w (the swaps in reverse).
:func:`least_squares_affine` takes its block already column-major: row j of
the row-major buffer is column j of the matrix.
"""
import numba
import numpy as np
from numba import types
from numba.extending import overload
from numba.np.linalg import F_INT_nbtype, F_INT_nptype, ensure_lapack

from .config import JIT
from .jit import kernel

ensure_lapack()
#: Integer type of the pivot array (LAPACK's Fortran integer).
PIVOT_DTYPE = F_INT_nptype
_KIND = {types.float64: ord("d"), types.complex128: ord("z")}


def _getrf(dtype):
    """numba_xxgetrf(kind, m, n, a, lda, ipiv) -> info (Numba's helper library)."""
    signature = types.intc(types.char, types.intp, types.intp, types.CPointer(dtype), types.intp,
                           types.CPointer(F_INT_nbtype))
    return types.ExternalFunction("numba_xxgetrf", signature)


_GETRF = {dtype: _getrf(dtype) for dtype in _KIND}
#: numba_ez_geqrf(kind, m, n, a, lda, tau) -> info, real only.
_GEQRF = types.ExternalFunction("numba_ez_geqrf", types.intc(
    types.char, types.intp, types.intp, types.CPointer(types.float64), types.intp,
    types.CPointer(types.float64)))
_REAL = ord("d")
_UPPER = ord("U")


def lu_factor(a, piv):
    """Factorise the square row-major a in place (module doc); piv: (n,) of PIVOT_DTYPE.
    Returns LAPACK's info: 0, or k > 0 when the k-th pivot is exactly zero."""
    raise NotImplementedError("only callable from jitted code")


@overload(lu_factor, jit_options=JIT)
def _lu_factor(a, piv):
    getrf, kind = _GETRF[a.dtype], _KIND[a.dtype]

    def factor(a, piv):
        n = a.shape[0]
        return getrf(kind, n, n, a.ctypes, n, piv.ctypes)
    return factor


@kernel
def copy_into(dst, src):
    """dst[i] = src[i] for i < len(src), src 1-D.  Kernels copy with this loop, not a
    slice assignment (``dst[:] = src``), which makes Numba compile its broadcasting
    check's error message: seconds of compile time per call site's signature."""
    for i in range(src.shape[0]):
        dst[i] = src[i]


@kernel
def lu_solve(lu, piv, b):
    """Solve a x = b in place of b from :func:`lu_factor`'s lu and piv."""
    n = lu.shape[0]
    for i in range(n):  # Uᵀ z = b: lower triangle with the diagonal
        acc = b[i]
        for j in range(i):
            acc -= lu[i, j] * b[j]
        b[i] = acc / lu[i, i]
    for i in range(n - 1, -1, -1):  # Lᵀ w = z: strict upper triangle, unit diagonal
        acc = b[i]
        for j in range(i + 1, n):
            acc -= lu[i, j] * b[j]
        b[i] = acc
    for k in range(n - 1, -1, -1):  # x = Pᵀ w
        p = piv[k] - 1
        if p != k:
            tmp = b[k]
            b[k] = b[p]
            b[p] = tmp


@kernel
def factor(a, piv):
    """:func:`lu_factor` callable from Python (tests, benchmarks)."""
    return lu_factor(a, piv)


@kernel
def least_squares_affine(block, out, tau):
    """Solve min_τ ||A τ + b||₂ for the block stored column-major: rows 0..K-1 of
    ``block`` (K+1, M) are the columns of A (M, K), row K is b; block is destroyed.

    LAPACK's Householder QR of A in place (geqrf; tau (K,) scratch), the same
    reflectors H_j = I − tau_j v_j v_jᵀ applied to b, then back substitution
    R τ = −(Qᵀ b)[:K].  A must have full column rank.
    """
    k = block.shape[0] - 1
    m = block.shape[1]
    _GEQRF(_REAL, m, k, block.ctypes, m, tau.ctypes)
    b = block[k]
    for j in range(k):  # b <- H_j b, v_j = [1, block[j, j+1:]]
        dot = b[j]
        for i in range(j + 1, m):
            dot += block[j, i] * b[i]
        dot *= tau[j]
        b[j] -= dot
        for i in range(j + 1, m):
            b[i] -= dot * block[j, i]
    for i in range(k - 1, -1, -1):  # R[i, j] = block[j, i] for j >= i
        acc = -b[i]
        for j in range(i + 1, k):
            acc -= block[j, i] * out[j]
        out[i] = acc / block[i, i]


#: numba_xxpotrf(kind, uplo, n, a, lda) -> info, real only (Cholesky).
_POTRF = types.ExternalFunction("numba_xxpotrf", types.intc(
    types.char, types.char, types.intp, types.CPointer(types.float64), types.intp))


@kernel
def _cholesky_solve(factor, rhs):
    """Solve L Lᵀ y = rhs in place, L the row-major lower triangle of ``factor``."""
    k = rhs.shape[0]
    for i in range(k):
        acc = rhs[i]
        for j in range(i):
            acc -= factor[i, j] * rhs[j]
        rhs[i] = acc / factor[i, i]
    for i in range(k - 1, -1, -1):
        acc = rhs[i]
        for j in range(i + 1, k):
            acc -= factor[j, i] * rhs[j]
        rhs[i] = acc / factor[i, i]


@kernel
def _scaled_normal_residual(block, scale, tau, residual, out):
    """out = −D Aᵀ (A τ + b): the normal equations' residual in the scaled unknowns
    (``residual`` (M,) scratch: A τ + b)."""
    k = block.shape[0] - 1
    m = block.shape[1]
    copy_into(residual, block[k])
    for j in range(k):
        for p in range(m):
            residual[p] += block[j, p] * tau[j]
    for j in range(k):
        acc = 0.0
        for p in range(m):
            acc += block[j, p] * residual[p]
        out[j] = -scale[j] * acc


@kernel
def least_squares_normal(block, scale, out, gram, residual, correction):
    """Solve min_τ ||A τ + b||₂ (block as in :func:`least_squares_affine`, not destroyed)
    by Björck's corrected semi-normal equations on the column-scaled problem:

        (D Aᵀ A D) y = −D Aᵀ b,   τ = D y,   D = diag(scale),

    by LAPACK's Cholesky (potrf, in ``gram`` (K, K); ``residual`` (M,) and ``correction``
    (K,) are scratch), then one refinement step with
    the residual −D Aᵀ(A τ + b) of the normal equations.  The step restores QR's
    accuracy while cond(A D) ≪ 1/√eps (``models.local_sbt``: cond(A D) ≈ 20 on run
    shapes, 2·10³ on a strongly stretched one).  Returns potrf's info: 0, or k > 0
    when D Aᵀ A D is not numerically positive definite (``out`` is then not a
    solution; the caller falls back to QR).
    """
    k = block.shape[0] - 1
    a_t = block[:k]
    np.dot(a_t, a_t.T, gram)
    for i in range(k):
        for j in range(k):
            gram[i, j] *= scale[i] * scale[j]
    # Row-major gram is LAPACK's column-major gramᵀ = gram; uplo "U" there leaves
    # gram = L Lᵀ with L in the row-major lower triangle.
    info = _POTRF(_REAL, _UPPER, k, gram.ctypes, k)
    if info != 0:
        return info
    out[:] = 0.0
    for _ in range(2):  # the solve, then one refinement step
        _scaled_normal_residual(block, scale, out, residual, correction)
        _cholesky_solve(gram, correction)
        for i in range(k):
            out[i] += scale[i] * correction[i]
    return 0
