"""Dense linear algebra in Numba: LAPACK's LU (implicit integrators), QR and Cholesky
(tension solve), gesv (the exact Jacobian's tension derivative), and BLAS's matrix
product by blocks.

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

Products.  :func:`add_product` and :func:`gram_upper` call BLAS's gemm through
``numba_xxgemm`` (``np.dot`` calls it too) by blocks of rows: at the tension solve's
sizes (K = 2n + 1 ≤ 65 rows, M = 4n + 1 columns) scipy's OpenBLAS then takes its
small-matrix kernels, and the Gram matrix costs only its upper triangle
(docs/studies/performance.md, "Fewer products for the tension").
"""
import numba
import numpy as np
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic, overload
from numba.np.linalg import F_INT_nbtype, F_INT_nptype, ensure_lapack

from .jit import JIT, kernel

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
_LOWER = ord("L")


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


#: numba_xgesv(kind, n, nrhs, a, lda, ipiv, b, ldb) -> info: LAPACK's gesv, the routine
#: ``np.linalg.solve`` calls in compiled code (Numba's helper library), real only.
_GESV = types.ExternalFunction("numba_xgesv", types.intc(
    types.char, types.intp, types.intp, types.CPointer(types.float64), types.intp,
    types.CPointer(F_INT_nbtype), types.CPointer(types.float64), types.intp))


@kernel
def solve(a, b):
    """``np.linalg.solve(a, b)`` for a (n, n) and b (n, r), both 2-D float64: the same
    LAPACK call (gesv) on the same column-major copies, so the same solution bit for bit,
    returned as Numba's is (column-major, (n, r)), with the same errors.

    Without Numba's version, whose copy of b is a slice assignment: its broadcasting
    check's error message compiles string formatting code, and every library holding the
    exact Jacobian held it (docs/studies/performance.md, "Compilation").
    """
    n = a.shape[0]
    nrhs = b.shape[1]
    if a.shape[1] != n or b.shape[0] != n:
        raise np.linalg.LinAlgError("solve: incompatible dimensions")
    for i in range(n):
        for j in range(n):
            if not np.isfinite(a[i, j]):
                raise np.linalg.LinAlgError("Array must not contain infs or NaNs.")
    for i in range(n):
        for j in range(nrhs):
            if not np.isfinite(b[i, j]):
                raise np.linalg.LinAlgError("Array must not contain infs or NaNs.")
    acpy = np.empty((n, n)).T
    bcpy = np.empty((nrhs, n)).T
    for j in range(n):
        for i in range(n):
            acpy[i, j] = a[i, j]
    for j in range(nrhs):
        for i in range(n):
            bcpy[i, j] = b[i, j]
    ipiv = np.empty(n, dtype=PIVOT_DTYPE)
    info = _GESV(_REAL, n, nrhs, acpy.ctypes, n, ipiv.ctypes, bcpy.ctypes, n)
    if info != 0:
        raise np.linalg.LinAlgError("Matrix is singular to machine precision.")
    return bcpy


#: numba_xxpotrf(kind, uplo, n, a, lda) -> info, real only (Cholesky).
_POTRF = types.ExternalFunction("numba_xxpotrf", types.intc(
    types.char, types.char, types.intp, types.CPointer(types.float64), types.intp))


#: numba_xxgemm(kind, transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc): BLAS's
#: column-major C = alpha op(A) op(B) + beta C (Numba's helper library), real only.
_GEMM = types.ExternalFunction("numba_xxgemm", types.intc(
    types.char, types.char, types.char, types.intp, types.intp, types.intp,
    types.CPointer(types.float64), types.CPointer(types.float64), types.intp,
    types.CPointer(types.float64), types.intp, types.CPointer(types.float64),
    types.CPointer(types.float64), types.intp))
_NO = ord("n")
_TRANSPOSED = ord("t")
#: Rows per block of :func:`add_product` and :func:`gram_upper` (measured: module doc).
PRODUCT_ROWS = 32
GRAM_ROWS = 24


@intrinsic
def _by_reference(typingctx, value):
    """A pointer to a copy of the float64 ``value`` on the caller's stack (BLAS takes its
    scalars by reference)."""
    if value != types.float64:
        return None

    def codegen(context, builder, signature, args):
        return cgutils.alloca_once_value(builder, args[0])
    return types.CPointer(types.float64)(types.float64), codegen


@kernel
def add_product(left, right, out):
    """out += left @ right for C-contiguous left (R, N), right (N, C), out (R, C):
    BLAS's gemm with beta = 1 on blocks of at most :data:`PRODUCT_ROWS` rows of left and out.

    Row-major x is column-major xᵀ, so each block is outᵀ += rightᵀ leftᵀ: gemm "N", "N".
    """
    rows, inner = left.shape
    columns = right.shape[1]
    one = _by_reference(1.0)
    blocks = (rows + PRODUCT_ROWS - 1) // PRODUCT_ROWS
    for q in range(blocks):
        first = (q * rows) // blocks
        count = ((q + 1) * rows) // blocks - first
        _GEMM(_REAL, _NO, _NO, columns, count, inner, one, right.ctypes, columns,
              left[first:].ctypes, inner, one, out[first:].ctypes, columns)


@kernel
def gram_upper(a_t, gram):
    """The upper triangle (diagonal included) of gram = a_t a_tᵀ, a_t (K, M) C-contiguous,
    by blocks of at most :data:`GRAM_ROWS` rows: for row blocks I ≤ J, gram[I, J] = a_I a_Jᵀ,
    whose column-major form is a_J a_Iᵀ, gemm "T", "N".  The strict lower triangle is
    not written."""
    k, m = a_t.shape
    one = _by_reference(1.0)
    zero = _by_reference(0.0)
    blocks = (k + GRAM_ROWS - 1) // GRAM_ROWS
    for p in range(blocks):
        first_i = (p * k) // blocks
        count_i = ((p + 1) * k) // blocks - first_i
        for q in range(p, blocks):
            first_j = (q * k) // blocks
            count_j = ((q + 1) * k) // blocks - first_j
            _GEMM(_REAL, _TRANSPOSED, _NO, count_j, count_i, m, one, a_t[first_j:].ctypes, m,
                  a_t[first_i:].ctypes, m, zero, gram[first_i, first_j:].ctypes, k)


@kernel
def _cholesky_solve(factor, rhs):
    """Solve L Lᵀ y = rhs in place, Lᵀ the row-major upper triangle of ``factor`` (row j
    holds column j of L from the diagonal on).

    L z = rhs column by column (z_j = rhs_j / L_jj, then rhs_i −= L_ij z_j along row j: a
    loop without a chain of dependent additions, which vectorises), then Lᵀ y = z row by
    row, each dot product in four partial sums (one chain of dependent additions runs at a
    quarter of the speed)."""
    k = rhs.shape[0]
    for j in range(k):
        row = factor[j]
        z = rhs[j] / row[j]
        rhs[j] = z
        for i in range(j + 1, k):
            rhs[i] -= row[i] * z
    for i in range(k - 1, -1, -1):
        row = factor[i]
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        s3 = 0.0
        j = i + 1
        while j + 3 < k:
            s0 += row[j] * rhs[j]
            s1 += row[j + 1] * rhs[j + 1]
            s2 += row[j + 2] * rhs[j + 2]
            s3 += row[j + 3] * rhs[j + 3]
            j += 4
        while j < k:
            s0 += row[j] * rhs[j]
            j += 1
        rhs[i] = (rhs[i] - ((s0 + s1) + (s2 + s3))) / row[i]


@kernel
def _scaled_normal_residual(block, scale, tau, residual, out):
    """out = −D Aᵀ (A τ + b): the normal equations' residual in the scaled unknowns
    (``residual`` (M,) scratch: A τ + b); both products are BLAS's gemv."""
    k = block.shape[0] - 1
    m = block.shape[1]
    a_t = block[:k]
    b = block[k]
    np.dot(tau, a_t, residual)
    for p in range(m):
        residual[p] += b[p]
    np.dot(a_t, residual, out)
    for j in range(k):
        out[j] *= -scale[j]


@kernel(inline=True)
def least_squares_normal(block, scale, out, gram, residual, correction):
    """Solve min_τ ||A τ + b||₂ (block as in :func:`least_squares_affine`, not destroyed)
    by Björck's corrected semi-normal equations on the column-scaled problem:

        (D Aᵀ A D) y = −D Aᵀ b,   τ = D y,   D = diag(scale),

    by LAPACK's Cholesky (potrf, in the upper triangle of ``gram`` (K, K), filled by
    :func:`gram_upper`; ``residual`` (M,) and ``correction`` (K,) are scratch), then one
    refinement step with
    the residual −D Aᵀ(A τ + b) of the normal equations.  The step restores QR's
    accuracy while cond(A D) ≪ 1/√eps (``models.local_sbt``: cond(A D) ≈ 20 on run
    shapes, 2·10³ on a strongly stretched one).  Returns potrf's info: 0, or k > 0
    when D Aᵀ A D is not numerically positive definite (``out`` is then not a
    solution; the caller falls back to QR).
    """
    k = block.shape[0] - 1
    gram_upper(block[:k], gram)
    for i in range(k):
        for j in range(i, k):
            gram[i, j] *= scale[i] * scale[j]
    # Row-major gram is LAPACK's column-major gramᵀ = gram; uplo "L" there leaves
    # gram = L Lᵀ with Lᵀ in the row-major upper triangle.
    info = _POTRF(_REAL, _LOWER, k, gram.ctypes, k)
    if info != 0:
        return info
    np.dot(block[:k], block[k], correction)  # the solve: −D Aᵀ b, the residual at τ = 0
    for i in range(k):
        correction[i] *= -scale[i]
    _cholesky_solve(gram, correction)
    for i in range(k):
        out[i] = scale[i] * correction[i]
    _scaled_normal_residual(block, scale, out, residual, correction)  # one refinement step
    _cholesky_solve(gram, correction)
    for i in range(k):
        out[i] += scale[i] * correction[i]
    return 0
