"""Dense linear algebra in Numba for the implicit methods: LU with partial pivoting.

The same code serves real and complex matrices; everything works in place.
"""
import numba

from ..config import JIT


@numba.njit(**JIT)
def lu_factor(a, piv):
    """In-place LU with partial pivoting: P a = L U (unit L below, U on and above).

    piv[k] is the row swapped with row k at step k (LAPACK's convention, 0-based).
    """
    n = a.shape[0]
    for k in range(n):
        p = k
        best = abs(a[k, k])
        for i in range(k + 1, n):
            if abs(a[i, k]) > best:
                best = abs(a[i, k])
                p = i
        piv[k] = p
        if p != k:
            for j in range(n):
                tmp = a[k, j]
                a[k, j] = a[p, j]
                a[p, j] = tmp
        pivot = a[k, k]
        if pivot == 0:
            continue
        for i in range(k + 1, n):
            a[i, k] /= pivot
            factor = a[i, k]
            if factor != 0:
                for j in range(k + 1, n):
                    a[i, j] -= factor * a[k, j]


@numba.njit(**JIT)
def lu_solve(lu, piv, b):
    """Solve (P⁻¹ L U) x = b in place of b."""
    n = lu.shape[0]
    for k in range(n):
        p = piv[k]
        if p != k:
            tmp = b[k]
            b[k] = b[p]
            b[p] = tmp
    for i in range(n):
        acc = b[i]
        for j in range(i):
            acc -= lu[i, j] * b[j]
        b[i] = acc
    for i in range(n - 1, -1, -1):
        acc = b[i]
        for j in range(i + 1, n):
            acc -= lu[i, j] * b[j]
        b[i] = acc / lu[i, i]
