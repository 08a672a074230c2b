"""The exact Jacobians of the loop's velocity, by the chain rule through its column blocks:
the local model's (``loop_maps.loop_velocity``) and, with the kernel K and its change with
the shape, the nonlocal one's (``nonlocal_maps.nonlocal_jacobian``)."""
import numpy as np

from ..jit import kernel
from ..linalg import solve
from .loop_maps import loop_velocity_blocks


@kernel
def loop_jacobian(x, g0, w, ops, ws, jac):
    """Exact Jacobian J = ∂u/∂x (3K × 3K, component-major) of :func:`loop_velocity`
    (the local mobility m[f] = f + (x'·f) x': :func:`mobility_jacobian` with 1, 1, 0)."""
    u = np.empty_like(x)
    loop_velocity_blocks(x, g0, w, ops, ws, u)  # fills the column blocks and ws.tension
    mobility_jacobian(w, 1.0, 1.0, 0.0, None, None, None, ops, ws, jac)


@kernel(inline=True)  # in its callers: a library of its own would compile it once more
def mobility_jacobian(w, isotropic, along, nonlocal_share, weight, direction, position, ops,
                      ws, jac):
    """J = ∂u/∂x (3K × 3K, component-major) of the loop velocity with mobility

        m[f] = isotropic f + along (t·f) t + nonlocal_share K[f]     (t = x'),

    K the rule of ``nonlocal_maps`` on the grid, its weight W, direction e and the grid
    positions (3, M) given; all three None for the local mobility (no K: Numba prunes the
    K branches at compile time, so the local model's Jacobian compiles none of them).
    ws holds the column blocks at x (``loop_velocity_blocks`` or
    ``nonlocal_maps.nonlocal_loop_velocity``: force, mobile, dmobile, tension).

    The chain rule through the three maps and the least-squares tension
    (derivation: docs/stability.md §1; tested against a NumPy twin in tests/naive.py).
    For the coordinate direction δx = e_c φ_k (δt = e_c φ_k', δκ = e_c φ_k''):

        δf = P[T' δt + T δκ − δx''''],
        δm = isotropic δf + along [(δt·f + t·δf) t + (t·f) δt]
             + nonlocal_share (K[δf] + δK[f]),
        δε = δt·(P1 m) + t·(P1 δm) + 2w t·δt,
        δT = −(AᵀA)⁻¹ [Aᵀ δε + δAᵀ r],   δu = F(δm + m_T δT),

    with ε = A T + b, r = ε(T) the residual and m_T the tension columns of m.  For the
    local mobility δm = s t + e_c g (s along the tangent, g along the direction's own
    component), so t·(P1 δm) = (P1 ∘ G) s + t_c P1 g, G_il = t_i·t_l: (M, M) products with
    4K columns instead of the 9K of P1 δm (the Jacobian in 0.86-0.90 of the time at
    n = 16-32, the same matrix to 5e-14 relative).

    Longer than a screen: one pass of the chain rule over temporaries every step shares
    (f, m, P1 m, the tension columns, their grids); the nonlocal parts are already kernels
    of their own (below).  Split further, each step would take a dozen work arrays, and
    a kernel split changes what LLVM inlines: the bit-identical bench counts this
    refactoring is held to (benchmarks/bench_step_control.py) would need a new check.
    """
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
    # δm for every direction, stored (M, 3, D) with D index = c k + j: δm = s t + e_c g,
    # s (M, D) along t, g (M, K) along the direction's own component
    dm = np.zeros((m, 3, d))
    s_t = np.empty((m, d))
    g = np.empty((m, k))
    for i in range(m):
        for j in range(k):
            g[i, j] = isotropic * big_f[i, j] + along * tf[i] * S1[i, j]
        for c in range(3):
            for j in range(k):
                col = c * k + j
                s_ck = along * (S1[i, j] * f[c, i] + t[c, i] * big_f[i, j])
                s_t[i, col] = s_ck
                for cc in range(3):
                    dm[i, cc, col] = s_ck * t[cc, i]
                dm[i, c, col] += g[i, j]
    # t·(P1 δm) (M, D)
    tpdm = np.empty((m, d))
    if weight is None:
        # = (P1 ∘ G) s + t_c (P1 g), G_il = t_i·t_l: (M, M) products with 4K columns, not
        # the 9K of P1 δm
        coupled = np.empty((m, m))
        for i in range(m):
            for l in range(m):
                coupled[i, l] = P1[i, l] * (t[0, i] * t[0, l] + t[1, i] * t[1, l]
                                            + t[2, i] * t[2, l])
        bs = np.dot(coupled, s_t)
        pg = np.dot(P1, g)
        for i in range(m):
            for c in range(3):
                for j in range(k):
                    tpdm[i, c * k + j] = bs[i, c * k + j] + t[c, i] * pg[i, j]
    else:
        inverse = inverse_distances(position)
        add_kernel_columns(nonlocal_share, weight, direction, big_f, dm)
        add_kernel_shape_columns(nonlocal_share, weight, direction, inverse, t, f, S0, S1, dm)
        pdm = np.dot(P1, dm.reshape((m, 3 * d))).reshape((m, 3, d))
        for i in range(m):
            for col in range(d):
                tpdm[i, col] = (t[0, i] * pdm[i, 0, col] + t[1, i] * pdm[i, 1, col]
                                + t[2, i] * pdm[i, 2, col])
    # δε (M, D)
    deps = np.empty((m, d))
    for i in range(m):
        for c in range(3):
            for j in range(k):
                col = c * k + j
                deps[i, col] = (S1[i, j] * dmob[c, i] + 2.0 * w * t[c, i] * S1[i, j]
                                + tpdm[i, col])
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
            pre[i, c] = isotropic * rho[i, c] + along * rt[i] * t[c, i]
    if weight is not None:
        add_adjoint_kernel(nonlocal_share, weight, direction, rho, pre)
    sig = np.dot(P.T, pre)  # (M, 3)
    rhs_t = np.dot(a.T, deps)  # (K, D): Aᵀ δε
    inner = np.empty((m, k))
    inner2 = np.empty((m, k))
    for c in range(3):
        for i in range(m):
            for j in range(k):
                inner[i, j] = (sig[i, c] * S1[i, j] + along * rt[i] * ws.force[i, c, j]
                               + along * rho[i, c] * tfj[i, j] + r[i] * ws.dmobile[i, c, j])
                inner2[i, j] = sig[i, c] * S0[i, j]
        block = np.dot(S1.T, inner) + np.dot(S2.T, inner2)  # (K dir, K col) for component c
        for kk in range(k):
            for j in range(k):
                rhs_t[j, c * k + kk] += block[kk, j]
    if weight is not None:
        add_kernel_shape_adjoint(nonlocal_share, weight, direction, inverse, t, rho, ws.force,
                                 S0, S1, rhs_t)
    dtau = -solve(np.dot(a.T, a), rhs_t)  # (K, D): np.linalg.solve's gesv, bit for bit
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


@kernel
def add_kernel_columns(share, weight, direction, big_f, dm):
    """dm[i, a, c K + j] += share K[e_c big_f[:, j]](s_i)_a: the kernel on the force change
    of every coordinate direction, K[g]_i = Σ_l W_il [g_l + e_il (e_il·g_l)]."""
    m, k = big_f.shape
    block = np.empty((3 * m, m))
    for c in range(3):
        for i in range(m):
            for a in range(3):
                for l in range(m):
                    block[3 * i + a, l] = weight[i, l] * (
                        (1.0 if a == c else 0.0) + direction[a, i, l] * direction[c, i, l])
        columns = np.dot(block, big_f)  # (3M, K)
        for i in range(m):
            for a in range(3):
                for j in range(k):
                    dm[i, a, c * k + j] += share * columns[3 * i + a, j]


@kernel
def add_adjoint_kernel(share, weight, direction, rho, pre):
    """pre[l] += share (Kᵀ rho)_l = share Σ_i W_il [rho_i + e_il (e_il·rho_i)] (rho (M, 3))."""
    m = rho.shape[0]
    for l in range(m):
        for i in range(m):
            w_il = weight[i, l]
            along = w_il * (direction[0, i, l] * rho[i, 0] + direction[1, i, l] * rho[i, 1]
                            + direction[2, i, l] * rho[i, 2])
            for a in range(3):
                pre[l, a] += share * (w_il * rho[i, a] + along * direction[a, i, l])


@kernel
def inverse_distances(position):
    """invR (M, M): 1/|x_l − x_i| off the diagonal, 0 on it."""
    m = position.shape[1]
    inverse = np.zeros((m, m))
    for l in range(m):
        for i in range(l + 1, m):
            d0 = position[0, l] - position[0, i]
            d1 = position[1, l] - position[1, i]
            d2 = position[2, l] - position[2, i]
            inverse[l, i] = 1.0 / np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            inverse[i, l] = inverse[l, i]
    return inverse


@kernel
def kernel_shape_term(weight, direction, c, l, i, g, out):
    """out = H^c_li g = W_li [−e_c g + ê_c (e·g) + e g_c − 3 e_c e (e·g)], e = e_li: the
    derivative of W_li [g + e (e·g)] along R_li = x_l − x_i in component c, times |R_li|
    (and along x'_l, times |x'_l|, on the diagonal).  H^c_li is symmetric."""
    e0 = direction[0, l, i]
    e1 = direction[1, l, i]
    e2 = direction[2, l, i]
    ec = direction[c, l, i]
    eg = e0 * g[0] + e1 * g[1] + e2 * g[2]
    w = weight[l, i]
    out[0] = w * (-ec * g[0] + e0 * g[c] - 3.0 * ec * e0 * eg)
    out[1] = w * (-ec * g[1] + e1 * g[c] - 3.0 * ec * e1 * eg)
    out[2] = w * (-ec * g[2] + e2 * g[c] - 3.0 * ec * e2 * eg)
    out[c] += w * eg


@kernel
def add_kernel_shape_columns(share, weight, direction, inverse, tangent, f, S0, S1, dm):
    """dm[l, a, c K + k] += share δK[f]_l,a for δx = e_c φ_k, the kernel's own change with
    the shape acting on the force f (3, M) at the solved tension:

        δK[f]_l = Σ_{i≠l} (φ_k(s_l) − φ_k(s_i)) H^c_li f_i / |R_li| + φ_k'(s_l) H^c_ll f_l / |x'_l|

    (:func:`kernel_shape_term`; δR_li = e_c (φ_k(s_l) − φ_k(s_i)), δx'_l = e_c φ_k'(s_l);
    inverse: :func:`inverse_distances` of the grid positions)."""
    m, k = S0.shape
    change = np.empty((3 * m, k))
    for c in range(3):
        shape_change(weight, direction, inverse, tangent, c, f, False, S0, S1, change)
        for l in range(m):
            for a in range(3):
                for j in range(k):
                    dm[l, a, c * k + j] += share * change[3 * l + a, j]


@kernel
def add_kernel_shape_adjoint(share, weight, direction, inverse, tangent, rho, force, S0, S1,
                             rhs_t):
    """rhs_t[j, c K + k] += share Σ_l rho_l · δK[f_j]_l, the tension columns' part of δAᵀ r
    from the kernel's change with the shape (f_j = force[:, :, j], j < K; δK as in
    :func:`add_kernel_shape_columns`).  With H symmetric, Σ_l rho_l·δK[f_j]_l =
    Σ_i z_i · f_j,i,  z_i = Σ_{l≠i} (φ_k(s_l) − φ_k(s_i)) H^c_li rho_l / |R_li|
    + φ_k'(s_i) H^c_ii rho_i / |x'_i|."""
    m, k = S0.shape
    field = rho.T.copy()
    z = np.empty((3 * m, k))
    columns = np.empty((3 * m, k))
    for i in range(m):
        for a in range(3):
            for j in range(k):
                columns[3 * i + a, j] = force[i, a, j]
    for c in range(3):
        shape_change(weight, direction, inverse, tangent, c, field, True, S0, S1, z)
        block = np.dot(columns.T, z)  # (tension column j, direction k)
        for j in range(k):
            for kk in range(k):
                rhs_t[j, c * k + kk] += share * block[j, kk]


@kernel
def shape_change(weight, direction, inverse, tangent, c, field, adjoint, S0, S1, out):
    """out (3M, K), row (p, a), column k: for δx = e_c φ_k,

        Σ_{q≠p} (φ_k(s_l) − φ_k(s_i)) (H^c_li g_q)_a / |R_li| + φ_k'(s_p) (H^c_pp g_p)_a / |x'_p|,

    g_q = field[:, q] (3, M), with (l, i) = (p, q): δK[field] at s_p; or, ``adjoint``,
    (l, i) = (q, p): the z_p of :func:`add_kernel_shape_adjoint`."""
    m, k = S0.shape
    scaled = np.empty((3 * m, m))  # (H g_q)_a / |R|, row (p, a), column q
    sums = np.zeros((3, m))
    diagonal = np.empty((3, m))
    g = np.empty(3)
    h = np.empty(3)
    for p in range(m):
        for q in range(m):
            for a in range(3):
                g[a] = field[a, q]
            if adjoint:
                kernel_shape_term(weight, direction, c, q, p, g, h)
            else:
                kernel_shape_term(weight, direction, c, p, q, g, h)
            if p == q:
                speed = np.sqrt(tangent[0, p] ** 2 + tangent[1, p] ** 2 + tangent[2, p] ** 2)
                for a in range(3):
                    diagonal[a, p] = h[a] / speed
                    scaled[3 * p + a, q] = 0.0
            else:
                for a in range(3):
                    scaled[3 * p + a, q] = h[a] * inverse[p, q]
                    sums[a, p] += scaled[3 * p + a, q]
    mixed = np.dot(scaled, S0)  # Σ_q scaled_(p,a),q φ_k(s_q)
    sign = -1.0 if adjoint else 1.0  # φ_k(s_l) − φ_k(s_i) = ±(φ_k(s_p) − φ_k(s_q))
    for p in range(m):
        for a in range(3):
            for j in range(k):
                out[3 * p + a, j] = (sign * (S0[p, j] * sums[a, p] - mixed[3 * p + a, j])
                                     + S1[p, j] * diagonal[a, p])
