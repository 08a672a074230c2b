"""Dense LU for the implicit methods: LAPACK's getrf from Numba, and the two triangular solves.

The factorisation, the O(n³) part, is LAPACK's blocked getrf from scipy's
LAPACK, reached through the ``numba_xxgetrf`` wrapper that Numba itself uses
for ``np.linalg`` (an external symbol, so kernels calling it stay cacheable;
real and complex by the array's dtype).  The O(n²) solve with those factors
is written here, since Numba wraps no getrs.

Convention.  Arrays are row-major (C order); LAPACK reads a row-major a as
the column-major aᵀ and factorises it, P aᵀ = L U.  Hence a = Uᵀ Lᵀ P, and in
the row-major buffer ``lu`` left by :func:`lu_factor`, Uᵀ is the lower
triangle with the diagonal and Lᵀ the strict upper triangle (unit diagonal);
``piv`` holds LAPACK's 1-based row swaps.  :func:`lu_solve` solves a x = b:
Uᵀ z = b (forward), Lᵀ w = z (backward), x = Pᵀ w (the swaps in reverse).
"""
import numba
import numpy as np
from numba import types
from numba.extending import overload
from numba.np.linalg import F_INT_nbtype, F_INT_nptype, ensure_lapack

from ..config import JIT

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


@numba.njit(**JIT)
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


@numba.njit(**JIT)
def factor(a, piv):
    """:func:`lu_factor` callable from Python (tests, benchmarks)."""
    return lu_factor(a, piv)
