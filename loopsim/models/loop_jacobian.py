"""The exact Jacobian of the local model's velocity (``loop_maps.loop_velocity``)."""
import numpy as np

from ..jit import kernel
from .loop_maps import loop_velocity_blocks


@kernel
def loop_jacobian(x, g0, w, ops, ws, jac):
    """Exact Jacobian J = ∂u/∂x (3K × 3K, component-major) of :func:`loop_velocity`.

    The chain rule through the three maps and the least-squares tension
    (derivation: docs/stability.md §1; tested against a NumPy twin in tests/naive.py).
    For the coordinate direction δx = e_c φ_k (δt = e_c φ_k', δκ = e_c φ_k''):

        δf = P[T' δt + T δκ − δx''''],   δm = δf + (δt·f + t·δf) t + (t·f) δt,
        δε = δt·(P1 m) + t·(P1 δm) + 2w t·δt,
        δT = −(AᵀA)⁻¹ [Aᵀ δε + δAᵀ r],   δu = F(δm + m_T δT),

    with ε = A T + b, r = ε(T) the residual and m_T the tension columns of m.
    """
    u = np.empty_like(x)
    loop_velocity_blocks(x, g0, w, ops, ws, u)  # fills the column blocks and ws.tension
    m, k = ops.m, ops.S0.shape[1]
    d = 3 * k
    tau = ws.tension
    t = ws.tangent
    S0, S1, S2, S4, P, P1 = ops.S0, ops.S1, ops.S2, ops.S4, ops.P, ops.P1
    t_grid = np.dot(S0, tau)
    dt_grid = np.dot(S1, tau)
    # fields at the solved tension: f, m and P1 m (3, M); residual r (M)
    f = np.empty((3, m))
    mob = np.empty((3, m))
    dmob = np.empty((3, m))
    for i in range(m):
        for c in range(3):
            acc_f = ws.force[i, c, k]
            acc_m = ws.mobile[i, c, k]
            acc_d = ws.dmobile[i, c, k]
            for j in range(k):
                acc_f += ws.force[i, c, j] * tau[j]
                acc_m += ws.mobile[i, c, j] * tau[j]
                acc_d += ws.dmobile[i, c, j] * tau[j]
            f[c, i] = acc_f
            mob[c, i] = acc_m
            dmob[c, i] = acc_d
    tf = np.empty(m)
    r = np.empty(m)
    a = np.empty((m, k))
    tfj = np.empty((m, k))
    for i in range(m):
        tf[i] = t[0, i] * f[0, i] + t[1, i] * f[1, i] + t[2, i] * f[2, i]
        stretch = t[0, i] ** 2 + t[1, i] ** 2 + t[2, i] ** 2
        r[i] = (t[0, i] * dmob[0, i] + t[1, i] * dmob[1, i] + t[2, i] * dmob[2, i]
                - w * (1.0 - stretch))
        for j in range(k):
            a[i, j] = (t[0, i] * ws.dmobile[i, 0, j] + t[1, i] * ws.dmobile[i, 1, j]
                       + t[2, i] * ws.dmobile[i, 2, j])
            tfj[i, j] = (t[0, i] * ws.force[i, 0, j] + t[1, i] * ws.force[i, 1, j]
                         + t[2, i] * ws.force[i, 2, j])
    # δf for δx = φ_k in one component (the same for every component): DF = P R
    raw = np.empty((m, k))
    for i in range(m):
        for j in range(k):
            raw[i, j] = dt_grid[i] * S1[i, j] + t_grid[i] * S2[i, j] - S4[i, j]
    big_f = np.dot(P, raw)
    # δm for every direction, stored (M, 3, D) with D index = c k + j
    dm = np.zeros((m, 3, d))
    for i in range(m):
        for c in range(3):
            for j in range(k):
                col = c * k + j
                s_ck = S1[i, j] * f[c, i] + t[c, i] * big_f[i, j]
                for cc in range(3):
                    dm[i, cc, col] = s_ck * t[cc, i]
                dm[i, c, col] += big_f[i, j] + tf[i] * S1[i, j]
    pdm = np.dot(P1, dm.reshape((m, 3 * d))).reshape((m, 3, d))
    # δε (M, D)
    deps = np.empty((m, d))
    for i in range(m):
        for c in range(3):
            for j in range(k):
                col = c * k + j
                deps[i, col] = (S1[i, j] * dmob[c, i] + 2.0 * w * t[c, i] * S1[i, j]
                                + t[0, i] * pdm[i, 0, col] + t[1, i] * pdm[i, 1, col]
                                + t[2, i] * pdm[i, 2, col])
    # δAᵀ r for every direction, without forming δA
    rt_vec = np.empty((m, 3))
    for i in range(m):
        for c in range(3):
            rt_vec[i, c] = r[i] * t[c, i]
    rho = np.dot(P1.T, rt_vec)  # (M, 3): P1ᵀ (r t)
    rt = np.empty(m)
    for i in range(m):
        rt[i] = rho[i, 0] * t[0, i] + rho[i, 1] * t[1, i] + rho[i, 2] * t[2, i]
    pre = np.empty((m, 3))
    for i in range(m):
        for c in range(3):
            pre[i, c] = rho[i, c] + rt[i] * t[c, i]
    sig = np.dot(P.T, pre)  # (M, 3)
    rhs_t = np.dot(a.T, deps)  # (K, D): Aᵀ δε
    inner = np.empty((m, k))
    inner2 = np.empty((m, k))
    for c in range(3):
        for i in range(m):
            for j in range(k):
                inner[i, j] = (sig[i, c] * S1[i, j] + rt[i] * ws.force[i, c, j]
                               + rho[i, c] * tfj[i, j] + r[i] * ws.dmobile[i, c, j])
                inner2[i, j] = sig[i, c] * S0[i, j]
        block = np.dot(S1.T, inner) + np.dot(S2.T, inner2)  # (K dir, K col) for component c
        for kk in range(k):
            for j in range(k):
                rhs_t[j, c * k + kk] += block[kk, j]
    dtau = -np.linalg.solve(np.dot(a.T, a), rhs_t)  # (K, D)
    # δu = F (δm + m_T δT), then arrange as J[(c', k'), (c, k)]
    m_t = np.empty((m * 3, k))
    for i in range(m):
        for c in range(3):
            for j in range(k):
                m_t[i * 3 + c, j] = ws.mobile[i, c, j]
    total = dm.reshape((m * 3, d)) + np.dot(m_t, dtau)
    du = np.dot(ops.F, total.reshape((m, 3 * d))).reshape((k, 3, d))
    for cc in range(3):
        for kk in range(k):
            for col in range(d):
                jac[cc * k + kk, col] = du[kk, cc, col]
