"""Local slender-body theory: the loop's velocity as three affine maps and a tension solve
(paper §5); the kernels of ``models.local_sbt``.

    T --(1) Euler–Bernoulli--> f --(2) local SBT--> u --(3) inextensibility--> ε

    (1) f = P_n[ -x'''' + (T x')' - g0 e_z ]
    (2) u = P_n[ f + (x'·f) x' ]
    (3) ε = x'·u' - w (1 - x'·x')            (order 2n, not truncated)

x, f, u and T are series of order n (``spectral`` layout); P_n is the
projection onto order n.  The maps are affine in T, so for a given shape we
evaluate them once on each of the 2n + 1 tension basis functions φ_j (the
linear part) and once with T = 0 (the affine part), as the columns of one
block: column j < K carries T = φ_j, column K carries T = 0 with gravity,
bending and the penalty.  The tension is then the real least-squares
solution of  min_T ||ε(T)||²_{L²}.

All products are formed on the grid of M = 4n + 1 points: it resolves ε
(order 2n) exactly, so the grid sum of ε² is its exact L² norm (up to the
factor 2π / M), and the projections of f (order 2n) and of (x'·f) x'
(order 3n) onto order n are alias-free there.

The right-hand side (:func:`loop_velocity`) does not build the column blocks.
On that grid the maps compose into one operator on the tension's grid values
(derivation in :func:`tension_operator`):

    ε(T) = (B₂ + B B) T + b,   B = P1 ∘ G,  B₂ = P2 ∘ G,  G_il = x'(s_i)·x'(s_l),

with P1 = S1 F and P2 = S2 F the projected first and second derivatives and ∘
the elementwise product.  A = (B₂ + B B) S0 costs one (K, M) @ (M, M) product,
B (B S0): B S0 and B₂ S0 take O(n M) operations (:func:`tension_columns`: the
product of the tangent with one basis function loses, on projection, only the modes
above n, which come from the tangent's top modes), where forming them took two
more such products (docs/studies/performance.md, "Fewer products for the tension").  The
column-block form (:func:`compose_maps`, :func:`loop_velocity_blocks`) stays
for the Jacobian and as the reference the fast path is tested against.
"""
import collections
import functools

import numpy as np

from .. import spectral
from ..jit import entry, kernel
from ..linalg import add_product, copy_into, least_squares_affine, least_squares_normal

#: the map T -> ε (leading order 2 T'') for the normal-equations solve.
LoopOperators = collections.namedtuple(
    "LoopOperators", "n m S0 S1 S2 S4 F P P1 S1T FT S0T P1T column_scale"
)

#: Per-case scratch arrays, so the right-hand side never allocates.  Column
#: blocks are stored (M, 3, J): grid point, component, column, so that each
#: map is one matrix product (M, M) @ (M, 3J).
#: ``length_rate`` (K+1, M) is the affine map T -> ε stored column by column (row j:
#: the column of T = φ_j; row K: the affine part), as LAPACK's QR wants it; ``tau``
#: is the QR's scratch.
#: The fast path's scratch: ``coupling`` (M, M) holds Bᵀ (tension_operator),
#: ``partial`` (K, M) is S0ᵀ Bᵀ, ``fields`` (3, 3, M) and
#: ``grid_force`` (3, M) grid fields, ``tension_grid`` (M,), and ``gram`` (K, K),
#: ``residual`` (M,), ``correction`` (K,) the normal equations' (linalg.least_squares_normal);
#: ``shape_modes`` (4, 3, K) the coefficients of x', x'', x''', x'''' and ``shape_grid``
#: (4, 3, M) their grid values (shape_on_grid; ``tangent``, ``curvature``, ``x3`` and
#: ``x4`` are its rows), ``mode_sums`` (8, M) the running sums of :func:`tension_columns`.
Workspace = collections.namedtuple(
    "Workspace",
    "tangent curvature x4 raw force mobile dmobile length_rate velocity tension tau "
    "coupling partial fields grid_force tension_grid gram residual correction "
    "x3 shape_modes shape_grid mode_sums"
)


def grid_size(n):
    """Collocation points used by the maps: M = 4n + 1."""
    return 4 * n + 1


@functools.lru_cache(maxsize=64)
def make_operators(n):
    """The constant matrices for truncation order n (built once per n and shared: never
    written to)."""
    m = grid_size(n)
    S = [spectral.synthesis_matrix(n, m, d) for d in (0, 1, 2, 4)]
    F = spectral.analysis_matrix(n, m)
    c = np.ascontiguousarray
    return LoopOperators(
        n, m, c(S[0]), c(S[1]), c(S[2]), c(S[3]), c(F), c(S[0] @ F), c(S[1] @ F),
        c(S[1].T), c(F.T), c(S[0].T), c((S[1] @ F).T),
        1.0 / (1.0 + 2.0 * spectral.wavenumbers(n) ** 2),
    )


@entry
def make_workspace(n):
    m = 4 * n + 1
    k = 2 * n + 1
    grid = np.empty((4, 3, m))
    return Workspace(
        grid[0], grid[1], grid[3],
        np.empty((m, 3, k + 1)), np.empty((m, 3, k + 1)), np.empty((m, 3, k + 1)),
        np.empty((m, 3, k + 1)), np.empty((k + 1, m)), np.empty((3, m)), np.empty(k),
        np.empty(k), np.empty((m, m)), np.empty((k, m)), np.empty((3, 3, m)),
        np.empty((3, m)), np.empty(m), np.empty((k, k)), np.empty(m), np.empty(k),
        grid[2], np.empty((4, 3, k)), grid, np.empty((8, m)),
    )


@kernel
def shape_on_grid(x, ops, ws):
    """Coefficients of x', x'', x''', x'''' from coefficients x (3, K), into ws.shape_modes,
    and their grid values, into ws.shape_grid (ws.tangent, ws.curvature, ws.x3, ws.x4):
    one (12, K) @ (K, M) product.  Per mode k, (a cos ks + b sin ks)' =
    k b cos ks − k a sin ks."""
    n, m, k = ops.n, ops.m, x.shape[1]
    modes = ws.shape_modes
    for p in range(4):
        for c in range(3):
            modes[p, c, 0] = 0.0
    for c in range(3):
        for mode in range(1, n + 1):
            a, b = x[c, mode], x[c, n + mode]
            for p in range(4):
                a, b = mode * b, -mode * a
                modes[p, c, mode] = a
                modes[p, c, n + mode] = b
    np.dot(modes.reshape((12, k)), ops.S0T, ws.shape_grid.reshape((12, m)))


@kernel
def force_map(g0, ops, ws):
    """Map (1): f = P_n[(T x')' - x'''' - g0 e_z], as a block of columns.

    (T x')' = T' x' + T x''; column j < K uses T = φ_j (no gravity, no
    bending: the linear part), column K uses T = 0 (the affine part).
    """
    m, k = ops.m, ops.S0.shape[1]
    raw = ws.raw
    for i in range(m):
        for c in range(3):
            t, kap = ws.tangent[c, i], ws.curvature[c, i]
            for j in range(k):
                raw[i, c, j] = t * ops.S1[i, j] + kap * ops.S0[i, j]
            raw[i, c, k] = -ws.x4[c, i] - (g0 if c == 2 else 0.0)
    np.dot(ops.P, raw.reshape((m, 3 * (k + 1))), ws.force.reshape((m, 3 * (k + 1))))


@kernel
def velocity_map(ws):
    """Map (2) before projection: u = f + (x'·f) x'  (stored in ws.mobile)."""
    t, f = ws.tangent, ws.force
    m, cols = f.shape[0], f.shape[2]
    for i in range(m):
        for j in range(cols):
            h = t[0, i] * f[i, 0, j] + t[1, i] * f[i, 1, j] + t[2, i] * f[i, 2, j]
            for c in range(3):
                ws.mobile[i, c, j] = f[i, c, j] + h * t[c, i]


@kernel
def length_creation_map(w, ops, ws):
    """Map (3): ε = x'·(P_n u)' - w (1 - x'·x'), as a block of columns (stored as rows)."""
    m, cols = ops.m, ws.mobile.shape[2]
    np.dot(ops.P1, ws.mobile.reshape((m, 3 * cols)), ws.dmobile.reshape((m, 3 * cols)))
    t, du = ws.tangent, ws.dmobile
    k = cols - 1
    for i in range(m):
        for j in range(cols):
            ws.length_rate[j, i] = t[0, i] * du[i, 0, j] + t[1, i] * du[i, 1, j] + t[2, i] * du[i, 2, j]
        stretch = t[0, i] ** 2 + t[1, i] ** 2 + t[2, i] ** 2
        ws.length_rate[k, i] -= w * (1.0 - stretch)


@kernel(inline=True)
def compose_maps(x, g0, w, ops, ws):
    """Maps (1)-(3) for shape x: the affine map T -> ε as the block ws.length_rate."""
    shape_on_grid(x, ops, ws)
    force_map(g0, ops, ws)
    velocity_map(ws)
    length_creation_map(w, ops, ws)


@kernel
def tension_operator(ops, ws):
    """Bᵀ into ws.coupling: B = P1 ∘ G, G_il = t_i·t_l (t = x' on the grid).

    With T the tension's grid values, f_c = P1(t_c T) − x⁗_c − g0 δ_cz (the
    projected force: (T x')' has order 2n, so P_n of it is P1 applied to T x'),
    h = t·f and m_c = f_c + h t_c, the length creation is

        ε = Σ_c t_c P1 m_c − w(1 − |t|²)
          = Σ_c t_c P2 (t_c T) + Σ_c t_c P1 (t_c h) + (the T = 0 part)
          = B₂ T + B (B T) + b,   B₂ = P2 ∘ G,

    because P1 P1 = S1 (F S1) F = S1 D F = P2 and Σ_c t_c P (t_c v) = (P ∘ G) v.
    Only the product B (B S0) needs B itself: B S0 and B₂ S0 come from
    :func:`tension_columns`.
    """
    m = ops.m
    t = ws.tangent
    coupling = ws.coupling
    for l in range(m):
        row, p1 = coupling[l], ops.P1T[l]
        t0, t1, t2 = t[0, l], t[1, l], t[2, l]
        for i in range(m):
            row[i] = p1[i] * (t[0, i] * t0 + t[1, i] * t1 + t[2, i] * t2)


@kernel(inline=True)
def tension_columns(ops, ws):
    """(B S0)ᵀ into ws.partial and (B₂ S0)ᵀ into ws.length_rate[:K] (B, B₂:
    :func:`tension_operator`), in O(n M) operations instead of two (K, M) @ (M, M) products.

    Column j of S0 is cos js or sin js, the real and imaginary parts of φ_j = e^{ijs}.
    With t_c = Σ_k (α_ck e^{iks} + c.c.)/2 + const, α_ck = â_ck − i b̂_ck the tangent's
    cos and sin coefficients of mode k, t_c φ_j has order n + j and its modes above n
    come only from t_c's modes k > n − j:

        P_n[t_c φ_j] = t_c φ_j − ½ Σ_{k > n−j} α_ck e^{i(k+j)s}.

    Differentiating once (P1) or twice (P2), multiplying by t_c and summing over c, with
    q_k = Σ_c t_c α_ck and the running sums H_p = ½ Σ_{k > n−j} (ik)^p q_k e^{iks}:

        (B φ_j)  = e^{ijs} (A1 + ij A0),
        (B₂ φ_j) = e^{ijs} (A2 + 2ij A1 − j² A0),   A_p = t·t^{(p)} − H_p

    (t^{(p)} the p-th derivative of t = x'; t·t⁽⁰⁾ = |t|²).  Each column j adds one mode
    k = n − j + 1 to the sums.  ws.mode_sums holds Re, Im of A0, A1, A2 and of
    ψ = ½ q_k e^{iks}; the loops over the grid write at most two arrays each, so that
    they vectorise.  Needs :func:`shape_on_grid`'s fields.
    """
    m, k = ops.m, ops.S0.shape[1]
    n = ops.n
    t, t1, t2, modes = ws.tangent, ws.curvature, ws.x3, ws.shape_modes[0]
    sums = ws.mode_sums
    r0, i0, r1, i1, r2, i2, pr, pi = (sums[0], sums[1], sums[2], sums[3], sums[4], sums[5],
                                      sums[6], sums[7])
    y_t, e_t = ws.partial, ws.length_rate
    for i in range(m):
        r0[i] = t[0, i] * t[0, i] + t[1, i] * t[1, i] + t[2, i] * t[2, i]
        r1[i] = t[0, i] * t1[0, i] + t[1, i] * t1[1, i] + t[2, i] * t1[2, i]
        r2[i] = t[0, i] * t2[0, i] + t[1, i] * t2[1, i] + t[2, i] * t2[2, i]
    for i in range(m):
        i0[i] = 0.0
        i1[i] = 0.0
        i2[i] = 0.0
    copy_into(y_t[0], r1)
    copy_into(e_t[0], r2)
    for j in range(1, n + 1):
        mode = n + 1 - j
        wave = float(mode)
        ar0, ai0 = 0.5 * modes[0, mode], -0.5 * modes[0, n + mode]  # ½ α_ck
        ar1, ai1 = 0.5 * modes[1, mode], -0.5 * modes[1, n + mode]
        ar2, ai2 = 0.5 * modes[2, mode], -0.5 * modes[2, n + mode]
        cos_k, sin_k = ops.S0T[mode], ops.S0T[n + mode]
        for i in range(m):
            qr = t[0, i] * ar0 + t[1, i] * ar1 + t[2, i] * ar2
            qi = t[0, i] * ai0 + t[1, i] * ai1 + t[2, i] * ai2
            pr[i] = qr * cos_k[i] - qi * sin_k[i]
            pi[i] = qr * sin_k[i] + qi * cos_k[i]
        wave2 = wave * wave
        for i in range(m):
            r0[i] -= pr[i]
            i0[i] -= pi[i]
        for i in range(m):
            r1[i] += wave * pi[i]
            i1[i] -= wave * pr[i]
        for i in range(m):
            r2[i] += wave2 * pr[i]
            i2[i] += wave2 * pi[i]
        fj = float(j)
        fj2 = fj * fj
        cos_j, sin_j = ops.S0T[j], ops.S0T[n + j]
        y_cos, y_sin = y_t[j], y_t[n + j]
        for i in range(m):
            zr = r1[i] - fj * i0[i]
            zi = i1[i] + fj * r0[i]
            y_cos[i] = cos_j[i] * zr - sin_j[i] * zi
            y_sin[i] = sin_j[i] * zr + cos_j[i] * zi
        e_cos, e_sin = e_t[j], e_t[n + j]
        for i in range(m):
            zr = r2[i] - 2.0 * fj * i1[i] - fj2 * r0[i]
            zi = i2[i] + 2.0 * fj * r1[i] - fj2 * i0[i]
            e_cos[i] = cos_j[i] * zr - sin_j[i] * zi
            e_sin[i] = sin_j[i] * zr + cos_j[i] * zi


@kernel(inline=True)
def length_rate_operator(g0, w, ops, ws):
    """The affine map T -> ε into ws.length_rate: rows 0..K-1 the columns of
    A = (B₂ + B B) S0 (stored Aᵀ = S0ᵀ B₂ᵀ + (S0ᵀ Bᵀ) Bᵀ), row K the T = 0 part b.

    Needs :func:`shape_on_grid`'s fields; leaves Bᵀ in ws.coupling, S0ᵀ Bᵀ in ws.partial
    and the T = 0 force in ws.fields[0]; uses ws.fields[1:] as scratch.  One
    (K, M) @ (M, M) product: S0ᵀ B₂ᵀ and S0ᵀ Bᵀ come from :func:`tension_columns`.
    """
    m, k = ops.m, ops.S0.shape[1]
    tension_operator(ops, ws)
    tension_columns(ops, ws)
    add_product(ws.partial, ws.coupling, ws.length_rate[:k])
    t, force, mobile = ws.tangent, ws.fields[0], ws.fields[1]
    for i in range(m):
        for c in range(3):
            force[c, i] = -ws.x4[c, i] - (g0 if c == 2 else 0.0)
        h = t[0, i] * force[0, i] + t[1, i] * force[1, i] + t[2, i] * force[2, i]
        for c in range(3):
            mobile[c, i] = force[c, i] + h * t[c, i]
    dmobile = ws.fields[2]
    np.dot(mobile, ops.P1T, dmobile)
    b = ws.length_rate[k]
    for i in range(m):
        stretch = t[0, i] ** 2 + t[1, i] ** 2 + t[2, i] ** 2
        b[i] = (t[0, i] * dmobile[0, i] + t[1, i] * dmobile[1, i] + t[2, i] * dmobile[2, i]
                - w * (1.0 - stretch))


def loop_velocity(problem, y, dydt):
    """dydt = u.ravel(), the velocity coefficients u (3, K) of the shape x = y.reshape(3, K)
    of a loop ``problem`` (fields g0, w, ops, ws: a ``local_sbt.LoopProblem``); the
    tension is left in problem.ws.tension.

    u_c = F m_c, m_c = f_c + (t·f) t_c, f_c = P1(t_c T) − x⁗_c − g0 δ_cz, with T the
    least-squares tension of :func:`length_rate_operator`: the same map as
    :func:`loop_velocity_blocks`, with one (K, M) @ (M, M) product where that builds two (M, M)
    @ (M, 3K + 3) ones.

    Not decorated: it is compiled as the local model's ``rhs`` implementation
    (``local_sbt``), holding its code itself rather than calling a kernel that does, so
    a run compiles the velocity's code in one library fewer (docs/studies/performance.md,
    "Compilation").  From Python: ``models.evaluate``.
    """
    g0 = problem.g0
    w = problem.w
    ops = problem.ops
    ws = problem.ws
    k = y.shape[0] // 3
    x = y.reshape((3, k))
    u_out = dydt.reshape((3, k))
    m = ops.m
    shape_on_grid(x, ops, ws)
    length_rate_operator(g0, w, ops, ws)
    if least_squares_normal(ws.length_rate, ops.column_scale, ws.tension, ws.gram,
                            ws.residual, ws.correction) != 0:
        least_squares_affine(ws.length_rate, ws.tension, ws.tau)
    t = ws.tangent
    tension = ws.tension_grid
    np.dot(ops.S0, ws.tension, tension)
    weighted = ws.fields[2]
    for c in range(3):
        for i in range(m):
            weighted[c, i] = t[c, i] * tension[i]
    force = ws.grid_force
    np.dot(weighted, ops.P1T, force)
    for i in range(m):
        for c in range(3):
            force[c, i] += ws.fields[0, c, i]
        h = t[0, i] * force[0, i] + t[1, i] * force[1, i] + t[2, i] * force[2, i]
        for c in range(3):
            ws.velocity[c, i] = force[c, i] + h * t[c, i]
    np.dot(ws.velocity, ops.FT, u_out)


@kernel(inline=True)
def loop_velocity_blocks(x, g0, w, ops, ws, u_out):
    """:func:`loop_velocity` through the column blocks of :func:`compose_maps`: the
    previous dense path, kept as the Jacobian's first step and as the fast path's reference.

    The least-squares solve destroys ws.length_rate; the residual is not kept.
    """
    compose_maps(x, g0, w, ops, ws)
    velocity_from_blocks(ops, ws, u_out)


@kernel(inline=True)
def velocity_from_blocks(ops, ws, u_out):
    """From the column blocks (ws.length_rate: T -> ε; ws.mobile: T -> u on the grid): the
    least-squares tension T into ws.tension (ws.length_rate destroyed) and the velocity
    coefficients u = F (Σ_j mobile_j T_j + mobile_K) into u_out (3, K)."""
    least_squares_affine(ws.length_rate, ws.tension, ws.tau)
    k = ops.S0.shape[1]
    for i in range(ops.m):
        for c in range(3):
            acc = ws.mobile[i, c, k]
            for j in range(k):
                acc += ws.mobile[i, c, j] * ws.tension[j]
            ws.velocity[c, i] = acc
    np.dot(ws.velocity, ops.FT, u_out)


@kernel
def length_creation(x, tension, g0, w, ops, ws):
    """Grid values of ε for a given tension (the residual of the tension solve)."""
    compose_maps(x, g0, w, ops, ws)
    k = ops.S0.shape[1]
    eps = ws.length_rate[k].copy()
    for j in range(k):
        eps += ws.length_rate[j] * tension[j]
    return eps
