"""The exact chain-rule Jacobian of the loop's RHS in plain NumPy (for baseline_scipy.py).

What a careful user would hand scipy's Radau: dense NumPy arrays, einsum, no
compilation.  The tension T at x comes from the caller (the baseline's own
NumPy RHS); the operator matrices are loopsim's (constant arrays).
"""
import numpy as np

from loopsim.models import local_sbt


def rhs_jacobian(x, g0, w, tension_of):
    """Exact Jacobian dF/dx (3K, 3K) of the spectral RHS at shape x (3, K).

    Acts on x.ravel() (component-major).  Linearises, for each coordinate
    direction δx, with t = x', κ = x'':
      δf = P[T' δt + T δκ - δx''''] + P[δT' t + δT κ]
      δm = δf + (δt·f + t·δf) t + (t·f) δt,      u = F m
      δε = δt·(P1 m) + t·(P1 δm) + 2w t·δt
    and the least-squares tension dT = -(AᵀA)⁻¹[Aᵀ δε|_T + dAᵀ r].
    """
    x = np.ascontiguousarray(x, dtype=float)
    n = (x.shape[1] - 1) // 2
    K = 2 * n + 1
    ops = local_sbt.make_operators(n)
    S0, S1, S2, S4, P, P1, F = ops.S0, ops.S1, ops.S2, ops.S4, ops.P, ops.P1, ops.F
    M = ops.m
    _, T = tension_of(x)

    t, kap, x4 = x @ S1.T, x @ S2.T, x @ S4.T                     # (3, M)
    Tg, Tp = S0 @ T, S1 @ T
    ez = np.array([0.0, 0.0, 1.0])[:, None]
    f = (Tp * t + Tg * kap - x4 - g0 * ez) @ P.T
    tf = np.sum(t * f, 0)
    m = f + tf * t
    dm_base = m @ P1.T
    r = np.sum(t * dm_base, 0) - w * (1.0 - np.sum(t * t, 0))      # residual of the solve

    # linear part A (M, K) of ε(T) = A T + b, column j for T = φ_j
    fj = np.einsum("mi,ci,ij->mcj", P, t, S1) + np.einsum("mi,ci,ij->mcj", P, kap, S0)
    tfj = np.einsum("cm,mcj->mj", t, fj)
    mj = fj + tfj[:, None, :] * t.T[:, :, None]
    dmj = np.einsum("mi,icj->mcj", P1, mj)
    A = np.einsum("cm,mcj->mj", t, dmj)

    # directions: unit vectors e_(c,k); δt[d] etc. (D, 3, M)
    D = 3 * K
    dt = np.zeros((3, K, 3, M))
    dk = np.zeros((3, K, 3, M))
    d4 = np.zeros((3, K, 3, M))
    for c in range(3):
        dt[c, :, c, :] = S1.T
        dk[c, :, c, :] = S2.T
        d4[c, :, c, :] = S4.T
    dt, dk, d4 = (a.reshape(D, 3, M) for a in (dt, dk, d4))

    df = (Tp * dt + Tg * dk - d4) @ P.T
    dm = (df + (np.einsum("dcm,cm->dm", dt, f) + np.einsum("cm,dcm->dm", t, df))[:, None, :] * t
          + tf * dt)
    deps = (np.einsum("dcm,cm->dm", dt, dm_base) + np.einsum("cm,dcm->dm", t, dm @ P1.T)
            + 2.0 * w * np.einsum("cm,dcm->dm", t, dt))

    # dAᵀ r without forming dA: Σ_i r_i δε_ij with δε_ij = δt·(P1 m_j) + t·(P1 δm_j)
    rho = (r * t) @ P1                                               # P1ᵀ(r t), (3, M)
    rt = np.sum(rho * t, 0)
    sig = (rho + rt * t) @ P                                         # Pᵀ(ρ + (ρ·t) t)
    dAr = (np.einsum("dcm,cm->dm", dt, sig) @ S1 + np.einsum("dcm,cm->dm", dk, sig) @ S0
           + np.einsum("dcm,mcj->dj", rt * dt, fj) + np.einsum("dm,mj->dj", np.einsum("cm,dcm->dm", rho, dt), tfj)
           + np.einsum("dcm,mcj->dj", r * dt, dmj))

    q_, r_ = np.linalg.qr(A)
    dT = -np.linalg.solve(r_, q_.T @ deps.T)                         # (K, D)
    dT -= np.linalg.solve(r_, np.linalg.solve(r_.T, dAr.T))
    du = (dm + np.einsum("mcj,jd->dcm", mj, dT)) @ F.T               # (D, 3, K)
    return du.reshape(D, D).T

