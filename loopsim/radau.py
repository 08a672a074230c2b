"""Radau IIA (order 5) building blocks in Numba: tableau, LU, Jacobian, Newton.

The 3-stage Radau IIA collocation method (Hairer & Wanner, *Solving ODEs II*,
§IV.8) solves, for the stage increments Z_i = Y_i − y,

    Z = h (A ⊗ I) F(y + Z),      y_new = y + Z_3,

by simplified Newton iterations.  With A⁻¹ = T Λ T⁻¹, Λ = diag(μ_r, [[α, β],
[−β, α]]), the Newton matrix decouples into one real system (μ_r/h − J) and
one complex system (μ_c/h − J), μ_c = α − iβ, each LU-factorised once and
reused while h and J stay.  The embedded error estimate is Hairer's
(an order-3 companion using f(y)), filtered through the real LU.  The
transformation T and the error weights are computed here from A, not typed
in, and are tested as data.

J comes from ``problems.jacobian`` (exact for every problem type; for the
loop it is ``physics.loop_jacobian``), refreshed only when Newton converges
slowly, as in scipy's Radau.  :func:`fd_jacobian` is kept as a
forward-difference fallback for new problem types.  Everything writes into
caller-owned arrays.
"""
import numpy as np
import numba

from .config import JIT
from .problems import rhs

_S6 = np.sqrt(6.0)
C = np.array([(4.0 - _S6) / 10.0, (4.0 + _S6) / 10.0, 1.0])
A = np.array([
    [(88.0 - 7.0 * _S6) / 360.0, (296.0 - 169.0 * _S6) / 1800.0, (-2.0 + 3.0 * _S6) / 225.0],
    [(296.0 + 169.0 * _S6) / 1800.0, (88.0 + 7.0 * _S6) / 360.0, (-2.0 - 3.0 * _S6) / 225.0],
    [(16.0 - _S6) / 36.0, (16.0 + _S6) / 36.0, 1.0 / 9.0],
])
ERROR_ORDER = 3  # the embedded estimate is O(h^4): factor err^(-1/4)
NEWTON_MAXITER = 6
#: Refresh the Jacobian after an accepted step whose Newton iteration took more
#: than JACOBIAN_ITERATIONS iterations at a contraction rate above JACOBIAN_RATE.
JACOBIAN_ITERATIONS = 2
JACOBIAN_RATE = 1e-3


def _transformation():
    """T, T⁻¹, μ_r, μ_c with T⁻¹ A⁻¹ T = diag(μ_r, [[α, β], [−β, α]]), μ_c = α − iβ."""
    values, vectors = np.linalg.eig(np.linalg.inv(A))
    real = int(np.argmin(np.abs(values.imag)))
    pair = int(np.argmax(values.imag))  # α + iβ with β > 0
    v = vectors[:, pair]
    t = np.column_stack([vectors[:, real].real, v.real, v.imag])
    t = t / t[2, 0]  # any scaling works; this one makes row 3 of T start with 1
    return t, np.linalg.inv(t), float(values[real].real), complex(values[pair].conjugate())


def _embedded_weights(mu_real):
    """E with err = (μ_r/h − J)⁻¹ (f(y) + Σ E_i Z_i / h) (Hairer's order-3 companion).

    The companion uses b̂_0 = γ0 = 1/μ_r on f(y) and b̂_1..3 from the order
    conditions Σ b̂_i c_i^(k−1) = 1/k, k = 1..3; E = μ_r (b̂ − b) A⁻¹, b = A[2].
    """
    gamma0 = 1.0 / mu_real
    powers = np.vstack([C**k for k in range(3)])
    rhs_k = np.array([1.0, 1.0 / 2.0, 1.0 / 3.0]) - np.array([gamma0, 0.0, 0.0])
    b_hat = np.linalg.solve(powers, rhs_k)
    return mu_real * (b_hat - A[2]) @ np.linalg.inv(A)


T, TI, MU_REAL, MU_COMPLEX = _transformation()
E = _embedded_weights(MU_REAL)
#: Z_i = Σ_k q_k c_i^(k+1): the collocation polynomial's coefficients are q = V⁻¹ Z.
VINV = np.linalg.inv(np.vander(C, 4, increasing=True)[:, 1:])


@numba.njit(**JIT)
def collocation_polynomial(z, q):
    """q (3, n) with y(t_old + x h) = y_old + Σ_k q_k x^(k+1), from the stage increments z."""
    for k in range(3):
        for i in range(z.shape[1]):
            q[k, i] = VINV[k, 0] * z[0, i] + VINV[k, 1] * z[1, i] + VINV[k, 2] * z[2, i]


@numba.njit(**JIT)
def extrapolated_guess(q, ratio, z):
    """Newton start for the next step (h_new = ratio · h_old): the last step's collocation
    polynomial evaluated at the new stage times, minus its end value."""
    for r in range(3):
        x = 1.0 + ratio * C[r]
        for i in range(z.shape[1]):
            z[r, i] = (q[0, i] * (x - 1.0) + q[1, i] * (x * x - 1.0)
                       + q[2, i] * (x * x * x - 1.0))


# ---- dense linear algebra (real and complex, same code) -------------------
@numba.njit(**JIT)
def lu_factor(a, piv):
    """In-place LU with partial pivoting: P a = L U (unit L below, U on and above)."""
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


@numba.njit(**JIT)
def fd_jacobian(problem, y, f, jac, y_work, f_work):
    """jac[:, j] = (F(y + δ_j e_j) − F(y)) / δ_j, δ_j = √eps · max(1, |y_j|)."""
    root_eps = np.sqrt(np.finfo(np.float64).eps)
    y_work[:] = y
    for j in range(y.shape[0]):
        delta = root_eps * max(1.0, abs(y[j]))
        y_work[j] = y[j] + delta
        delta = y_work[j] - y[j]  # the step actually representable
        rhs(problem, y_work, f_work)
        for i in range(y.shape[0]):
            jac[i, j] = (f_work[i] - f[i]) / delta
        y_work[j] = y[j]


@numba.njit(**JIT)
def newton_matrices(jac, h, lu_real, piv_real, lu_complex, piv_complex):
    """Factorise μ_r/h − J and μ_c/h − J."""
    n = jac.shape[0]
    for i in range(n):
        for j in range(n):
            lu_real[i, j] = -jac[i, j]
            lu_complex[i, j] = -jac[i, j]
        lu_real[i, i] += MU_REAL / h
        lu_complex[i, i] += MU_COMPLEX / h
    lu_factor(lu_real, piv_real)
    lu_factor(lu_complex, piv_complex)


@numba.njit(**JIT)
def _scaled_rms(v, scale):
    acc = 0.0
    for i in range(v.shape[0]):
        acc += (v[i] / scale[i]) ** 2
    return np.sqrt(acc / v.shape[0])


@numba.njit(**JIT)
def solve_collocation(problem, y, h, z, scale, tol, lu_real, piv_real, lu_complex, piv_complex,
                      w, fz, stage, real_rhs, complex_rhs):
    """Simplified Newton for Z = h A F(y + Z), from the guess in z (3, n), updated in place.

    Returns (converged, iterations, rate); 3 RHS evaluations per iteration.
    """
    n = y.shape[0]
    m_real = MU_REAL / h
    m_complex = MU_COMPLEX / h
    for r in range(3):
        for i in range(n):
            w[r, i] = TI[r, 0] * z[0, i] + TI[r, 1] * z[1, i] + TI[r, 2] * z[2, i]
    norm_old = -1.0
    rate = -1.0
    for iteration in range(NEWTON_MAXITER):
        for r in range(3):
            for i in range(n):
                stage[i] = y[i] + z[r, i]
            rhs(problem, stage, fz[r])
        for r in range(3):
            for i in range(n):
                if not np.isfinite(fz[r, i]):
                    return False, iteration + 1, rate
        for i in range(n):
            tf0 = TI[0, 0] * fz[0, i] + TI[0, 1] * fz[1, i] + TI[0, 2] * fz[2, i]
            tf1 = TI[1, 0] * fz[0, i] + TI[1, 1] * fz[1, i] + TI[1, 2] * fz[2, i]
            tf2 = TI[2, 0] * fz[0, i] + TI[2, 1] * fz[1, i] + TI[2, 2] * fz[2, i]
            real_rhs[i] = tf0 - m_real * w[0, i]
            complex_rhs[i] = (tf1 + 1j * tf2) - m_complex * (w[1, i] + 1j * w[2, i])
        lu_solve(lu_real, piv_real, real_rhs)
        lu_solve(lu_complex, piv_complex, complex_rhs)
        acc = 0.0
        for i in range(n):
            acc += (real_rhs[i] / scale[i]) ** 2 + (complex_rhs[i].real / scale[i]) ** 2 \
                + (complex_rhs[i].imag / scale[i]) ** 2
        norm = np.sqrt(acc / (3 * n))
        if norm_old >= 0.0:
            rate = norm / norm_old
        if rate >= 0.0 and (rate >= 1.0 or
                            rate ** (NEWTON_MAXITER - iteration) / (1.0 - rate) * norm > tol):
            return False, iteration + 1, rate
        for i in range(n):
            w[0, i] += real_rhs[i]
            w[1, i] += complex_rhs[i].real
            w[2, i] += complex_rhs[i].imag
        for r in range(3):
            for i in range(n):
                z[r, i] = T[r, 0] * w[0, i] + T[r, 1] * w[1, i] + T[r, 2] * w[2, i]
        if norm == 0.0 or (rate >= 0.0 and rate / (1.0 - rate) * norm < tol):
            return True, iteration + 1, rate
        norm_old = norm
    return False, NEWTON_MAXITER, rate


@numba.njit(**JIT)
def error_estimate(f0, z, h, lu_real, piv_real, out):
    """out = (μ_r/h − J)⁻¹ (f(y) + Σ E_i Z_i / h)."""
    for i in range(f0.shape[0]):
        out[i] = f0[i] + (E[0] * z[0, i] + E[1] * z[1, i] + E[2] * z[2, i]) / h
    lu_solve(lu_real, piv_real, out)
