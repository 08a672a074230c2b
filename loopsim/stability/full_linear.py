"""Full linear stability of the translating circle, from loopsim's own equations.

The state is the coefficient vector x (3, K), K = 2n + 1, and dx/dt = F(x) is
the spectral right-hand side of ``physics.loop_velocity`` (tension solve
included):

    f = P_n[-x'''' + (T x')' - g0 e_z],   u = P_n[f + (x'·f) x'],
    T = argmin_T ||ε||²,   ε = x'·(P_n u)' - w (1 - x'·x')   (4n+1-point grid).

The inclined circle x0 = [sin s, cos θ0 cos s, sin θ0 cos s] translates with
u0 = -[0, g0 sin 2θ0/6, g0 (7 - cos 2θ0)/6] and T0 = -1 + q cos s,
q = g0 sin θ0 / 3.  F is translation invariant, so in the co-moving frame a
perturbation δ, x = x0 + u0 t + δ, obeys dδ/dt = J δ with J = dF/dx(x0).

Jacobian.  :func:`rhs_jacobian` is the exact linearisation of the *discrete*
maps (``models.local_sbt.loop_jacobian``: chain rule through the three maps
and the least-squares tension solve, dT = -(AᵀA)⁻¹[Aᵀ(dA T + db) + dAᵀ r] for
ε = A T + b, r = ε(T)), exact to round-off at any shape; tested against an
independent NumPy twin and finite differences in ``tests/``.

Coordinates.  y = [P, R, Z]: the components of δ along a = e_x, b = [0, cos θ0,
sin θ0] (the circle's plane, x0 = sin s a + cos s b) and e_n = [0, -sin θ0,
cos θ0] (:func:`sector_frame`).  Neutral modes (:func:`neutral_modes`): the
translations (P, R, Z = 1), the arc-length shift x0' = cos s a - sin s b
(= rotation about e_n), and the rotations about a and b, Z = cos s and
Z = -sin s.  J maps this 6-dimensional space N into the translations (a
rotation is another translating circle), so the physical spectrum is that of
the map induced on the quotient R^{3K}/N, J̄ = Qᵀ J Q with Q an orthonormal
basis of N^⊥ (exact because JN ⊂ N).

Sectors.  J never maps in-plane perturbations out of the plane (J_oi = 0 to
round-off, every θ0), while out-of-plane ones drive in-plane motion through
the normal gravity component g0 cos θ0 (J_io ≠ 0 unless θ0 = 90°).  J is
therefore block-triangular and its spectrum is exactly the union of the
in-plane and out-of-plane blocks; both blocks depend on (g0, θ0) only through
q.  The in-plane block further splits (again triangularly) into

* inextensible perturbations, ker E with E δ = x0'·δ' (invariant under J):
  the physical in-plane sector, 2(n - 2) modes, independent of w;
* stretch modes (the quotient by ker E): 2n + 1 modes decaying at exactly
  -2w (the length penalty: a numerical artefact), and 2 modes whose length
  change is at wavenumber n + 1, beyond the reach of the order-n tension
  (truncation artefacts, strongly damped).  Neither is physical.

The out-of-plane sector (2(n - 1) modes, ζ = Z of wavenumber 2..n) coincides
with the corrected operator (``stability.paper``, ``corrected=True``)

    L = -∂⁴ - ∂² + q (sin s ∂ + cos s ∂²),

the paper's operator with the sign of ∂² reversed: the paper's T0 = 1 + q cos s
should be -1 + q cos s (see docs/stability.md).

Free ring (q = 0): out-of-plane σ_k = -k²(k² - 1), in-plane
σ_k = -2k²(k² - 1)²/(2k² + 1) (k ≥ 2, each twice).
"""
from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from .. import models, spectral, validation
from ..defaults import DEFAULT_W
from ..models import local_sbt
from ..shapes import inclined_circle
from . import paper
from .roots import first_crossing

__all__ = [
    "SECTORS", "circle_velocity", "rhs_jacobian", "sector_frame",
    "neutral_modes", "neutral_mode_residuals", "CircleLinearisation", "linearise_circle",
    "FullSpectrum", "full_spectrum", "free_ring_rates", "sector_growth_rates", "sigma",
    "critical_q", "critical_q_table", "paper_comparison", "unstable_mode", "l2_weights",
]

#: Physical sectors (labels of :class:`FullSpectrum`; also "stretch" and "neutral").
SECTORS = ("in-plane", "out-of-plane")


# ---------------------------------------------------------------- helpers
def _check_n(n, low=3):
    return validation.check_integer("n", n, low)


def _check_theta_for_q(theta0_deg):
    return validation.check_tilt("theta0 (for a given q)", theta0_deg, allow_zero=False)


def check_sector(sector):
    """One of SECTORS."""
    if sector not in SECTORS:
        raise ValueError(f"sector must be one of {SECTORS}, got {sector!r}")
    return sector


def circle_velocity(g0, theta0):
    """u0 = -[0, g0 sin 2θ0 / 6, g0 (7 - cos 2θ0) / 6] (θ0 in radians)."""
    return -np.array([0.0, g0 * math.sin(2 * theta0) / 6.0, g0 * (7.0 - math.cos(2 * theta0)) / 6.0])


def l2_weights(n):
    """Weights of the coefficient layout for ⟨f, g⟩ = (1/2π)∫ f g ds: [1, ½ ...]."""
    w = np.full(2 * n + 1, 0.5)
    w[0] = 1.0
    return w


# ---------------------------------------------------------------- Jacobian
def rhs_jacobian(x, g0, w=DEFAULT_W, model=models.LOCAL):
    """Jacobian dF/dx (3K, 3K) of the spectral RHS at shape x (3, K), acting on x.ravel()
    (component-major): the model's exact Jacobian (``local_sbt.loop_jacobian``,
    ``nonlocal_maps.nonlocal_jacobian``)."""
    x = np.ascontiguousarray(x, dtype=float)
    n = (x.shape[1] - 1) // 2
    problem = models.make_problem(model, models.check_order(model, n), g0, w)
    jac = np.empty((x.size, x.size))
    models.evaluate_jacobian(problem, x.reshape(-1), jac)
    return jac


# ---------------------------------------------------------------- frame and neutral modes
def sector_frame(n, theta0):
    """Orthogonal R (3K, 3K) with x.ravel() = R y, y = [P, R, Z] along (a, b, e_n)."""
    K = 2 * n + 1
    axes = np.array([[1.0, 0.0, 0.0],
                     [0.0, math.cos(theta0), math.sin(theta0)],
                     [0.0, -math.sin(theta0), math.cos(theta0)]])   # rows a, b, e_n
    return np.kron(axes.T, np.eye(K))


NEUTRAL_NAMES = ("translation a", "translation b", "translation e_n",
                 "arc-length shift x0' (rotation about e_n)",
                 "rotation about a (Z = cos s)", "rotation about b (Z = -sin s)")


def _neutral_y(n):
    """The six neutral generators in y = [P, R, Z] coordinates, (3K, 6)."""
    K = 2 * n + 1
    N = np.zeros((3 * K, 6))
    N[0, 0] = N[K, 1] = N[2 * K, 2] = 1.0
    N[1, 3], N[K + n + 1, 3] = 1.0, -1.0          # x0' = cos s a - sin s b
    N[2 * K + 1, 4] = 1.0                          # a × x0 = cos s e_n
    N[2 * K + n + 1, 5] = -1.0                     # b × x0 = -sin s e_n
    return N


def neutral_modes(n, theta0_deg):
    """(3K, 6) neutral generators in x coordinates (columns named by NEUTRAL_NAMES)."""
    n = _check_n(n, 1)
    return sector_frame(n, math.radians(theta0_deg)) @ _neutral_y(n)


@functools.lru_cache(maxsize=32)
def _bases(n):
    """Orthonormal bases in y coordinates: physical in-plane Qp, stretch Qs, out-of-plane Qo.

    E δ = x0'·δ' = cos s P' - sin s R' on the 4n+1 grid (exact, order n+1);
    ker E ⊃ the in-plane neutral modes.  Qp spans ker E ⊖ N_in, Qs the row
    space of E, Qo the Z coordinates without Z0, Z_a1, Z_b1.
    """
    K = 2 * n + 1
    ops = local_sbt.make_operators(n)
    s = 2.0 * np.pi * np.arange(ops.m) / ops.m
    E = np.hstack([np.cos(s)[:, None] * ops.S1, -np.sin(s)[:, None] * ops.S1])
    _, sv, vt = np.linalg.svd(E)
    rank = int(np.sum(sv > 1e-9 * sv[0]))
    ker = vt[rank:].T
    n_in = _neutral_y(n)[:2 * K, :4]
    n_in = n_in[:, [0, 1, 3]] / np.linalg.norm(n_in[:, [0, 1, 3]], axis=0)
    z = ker - n_in @ (n_in.T @ ker)
    uz, sz, _ = np.linalg.svd(z, full_matrices=False)
    qp = uz[:, sz > 1e-8]
    qs = vt[:rank].T
    keep = [i for i in range(K) if i not in (0, 1, n + 1)]
    qo = np.eye(K)[:, keep]
    return qp, qs, qo


# ---------------------------------------------------------------- linearisation
@dataclasses.dataclass
class CircleLinearisation:
    """J at the translating circle and its sector blocks (co-moving quotient).

    ``blocks``: "in-plane" (Qpᵀ J_ii Qp), "stretch" (Qsᵀ J_ii Qs),
    "out-of-plane" (Qoᵀ J_oo Qo).  ``quotient``: J̄ on the 3K - 6 coordinates
    [Qp | Qs | Qo], block upper-triangular in that order; ``basis`` (3K, 3K-6)
    maps them to x coordinates.  ``diagnostics``: max-norm sizes (relative to
    max|J|) of the in→out coupling, the out→in coupling, the leak of ker E and
    of the neutral space N out of themselves.
    """

    n: int
    g0: float
    theta0_deg: float
    w: float
    q: float
    jacobian: np.ndarray
    blocks: dict
    quotient: np.ndarray
    basis: np.ndarray
    sizes: dict
    diagnostics: dict


def linearise_circle(n, g0, theta0_deg, w=DEFAULT_W, model=models.LOCAL):
    """Linearise the RHS of ``model`` about the circle tilted by theta0_deg; see
    :class:`CircleLinearisation`."""
    n = _check_n(n)
    th = math.radians(theta0_deg)
    K = 2 * n + 1
    J = rhs_jacobian(inclined_circle(n, th), g0, w, model)
    R = sector_frame(n, th)
    Jy = R.T @ J @ R
    qp, qs, qo = _bases(n)
    Jii, Joo = Jy[:2 * K, :2 * K], Jy[2 * K:, 2 * K:]
    Jio, Joi = Jy[:2 * K, 2 * K:], Jy[2 * K:, :2 * K]
    Q = np.zeros((3 * K, qp.shape[1] + qs.shape[1] + qo.shape[1]))
    Q[:2 * K, :qp.shape[1]] = qp
    Q[:2 * K, qp.shape[1]:qp.shape[1] + qs.shape[1]] = qs
    Q[2 * K:, qp.shape[1] + qs.shape[1]:] = qo
    Jbar = Q.T @ Jy @ Q
    scale = np.abs(J).max()
    Ny = _neutral_y(n) / np.linalg.norm(_neutral_y(n), axis=0)
    jn = Jy @ Ny
    diagnostics = {
        "jacobian_max": float(scale),
        "in_to_out_coupling": float(np.abs(Joi).max() / scale),
        "out_to_in_coupling": float(np.abs(Jio).max() / scale),
        "ker_E_leak": float(np.abs(qs.T @ Jii @ qp).max() / scale),
        "neutral_leak": float(np.abs(Q.T @ jn).max() / scale),
    }
    return CircleLinearisation(
        n=n, g0=float(g0), theta0_deg=float(theta0_deg), w=float(w),
        q=g0 * math.sin(th) / 3.0, jacobian=J,
        blocks={"in-plane": qp.T @ Jii @ qp, "stretch": qs.T @ Jii @ qs, "out-of-plane": qo.T @ Joo @ qo},
        quotient=Jbar, basis=R @ Q,
        sizes={"in-plane": qp.shape[1], "stretch": qs.shape[1], "out-of-plane": qo.shape[1]},
        diagnostics=diagnostics,
    )


def neutral_mode_residuals(n, g0, theta0_deg, w=DEFAULT_W, model=models.LOCAL):
    """For each neutral generator v (unit max-norm): J v, split into its constant part
    (a translation velocity, expected: 0, 0, 0, 0, du0/dθ0, [g0 cos θ0 / 3, 0, 0]) and
    the rest, whose max-norm is the residual.  Returns a list of dicts.
    """
    n = _check_n(n)
    th = math.radians(theta0_deg)
    K = 2 * n + 1
    J = rhs_jacobian(inclined_circle(n, th), g0, w, model)
    V = neutral_modes(n, theta0_deg)
    out = []
    for name, v in zip(NEUTRAL_NAMES, V.T):
        jv = (J @ v).reshape(3, K)
        const = jv[:, 0].copy()
        rest = jv.copy()
        rest[:, 0] = 0.0
        out.append({"mode": name, "velocity": const, "residual": float(np.abs(rest).max()),
                    "residual_rel": float(np.abs(rest).max() / np.abs(J).max())})
    return out


# ---------------------------------------------------------------- spectrum
@dataclasses.dataclass
class FullSpectrum:
    """Eigenvalues σ of J (co-moving frame), sorted by decreasing Re σ, with labels.

    ``sector[i]`` ∈ {"in-plane", "out-of-plane", "stretch", "neutral"};
    ``modes[i]`` (3, K) complex coefficients of the eigenvector of the quotient
    map: the shape change, orthogonal to the six rigid motions N, unit L² norm;
    J v - σ v lies in N (a true eigenvector of J adds a rigid-motion part that
    grows like 1/σ near a threshold, so it is not used); ``out_of_plane_fraction[i]``
    = ∫|δ·e_n|² / ∫|δ|².  "stretch" modes are penalty/truncation artefacts
    (σ = -2w, and two unresolved ones); "neutral" are the six zeros, whose
    ``modes`` are the generators (J v = 0 for the translations and the shift,
    J v = a constant velocity for the two rotations: a Jordan pair).
    """

    g0: float
    theta0_deg: float
    n: int
    w: float
    q: float
    eigenvalues: np.ndarray
    sector: np.ndarray
    modes: np.ndarray
    out_of_plane_fraction: np.ndarray

    def growth_rate(self, sector):
        """Largest Re σ in the sector."""
        return float(np.max(self.eigenvalues[self.sector == sector].real))


def _lift(jbar, offset, size, lam, y):
    """Eigenvector of block-upper-triangular jbar from an eigenvector y of a diagonal block."""
    v = np.zeros(jbar.shape[0], dtype=complex)
    v[offset:offset + size] = y
    if offset:
        a = jbar[:offset, :offset] - lam * np.eye(offset)
        rhs = -jbar[:offset, offset:offset + size] @ y
        v[:offset] = np.linalg.lstsq(a, rhs, rcond=None)[0]
    return v


def full_spectrum(g0, theta0_deg, n, w=DEFAULT_W, model=models.LOCAL):
    """All 3K eigenvalues of J at the circle (g0, θ0), labelled by sector; see :class:`FullSpectrum`."""
    lin = linearise_circle(n, g0, theta0_deg, w, model)
    K = 2 * lin.n + 1
    wts = np.tile(l2_weights(lin.n), 3)
    frame = sector_frame(lin.n, math.radians(theta0_deg))
    vals, labels, vecs, frac = [], [], [], []
    offset = 0
    for name in ("in-plane", "stretch", "out-of-plane"):
        size = lin.sizes[name]
        lam, ys = np.linalg.eig(lin.blocks[name])
        for j in range(size):
            v = lin.basis @ _lift(lin.quotient, offset, size, lam[j], ys[:, j])
            v /= np.sqrt(np.sum(wts * np.abs(v) ** 2))
            vy = frame.T @ v
            vals.append(lam[j])
            labels.append(name)
            vecs.append(v.reshape(3, K))
            frac.append(float(np.sum(wts[2 * K:] * np.abs(vy[2 * K:]) ** 2)))
        offset += size
    for v in neutral_modes(lin.n, theta0_deg).T:
        vals.append(0.0)
        labels.append("neutral")
        vecs.append((v / np.sqrt(np.sum(wts * v ** 2))).reshape(3, K).astype(complex))
        frac.append(float(np.sum(wts[2 * K:] * (frame.T @ v)[2 * K:] ** 2) / np.sum(wts * v ** 2)))
    vals = np.array(vals, dtype=complex)
    order = np.lexsort((-vals.imag, -vals.real))
    return FullSpectrum(
        g0=float(g0), theta0_deg=float(theta0_deg), n=lin.n, w=float(w), q=lin.q,
        eigenvalues=vals[order], sector=np.array(labels)[order],
        modes=np.array(vecs)[order], out_of_plane_fraction=np.array(frac)[order],
    )


def free_ring_rates(n, sector):
    """Closed-form q = 0 rates of the free ring, k = 2..: each wavenumber twice.

    Out-of-plane (k = 2..n): σ = -k²(k² - 1), from ∂t ζ = -ζ'''' - ζ''.
    In-plane (k = 2..n-1): σ = -2k²(k² - 1)²/(2k² + 1), for δ = α e_r + β e_t
    with α = -β' (inextensible), normal mobility 1, tangential 2, and the
    tension perturbation fixed by δu_r + δu_t' = 0.
    """
    n = _check_n(n)
    if check_sector(sector) == "out-of-plane":
        k = np.arange(2, n + 1, dtype=float)
        rates = -k**2 * (k**2 - 1.0)
    else:
        k = np.arange(2, n, dtype=float)
        rates = -2.0 * k**2 * (k**2 - 1.0) ** 2 / (2.0 * k**2 + 1.0)
    return np.sort(np.repeat(rates, 2))[::-1]


@functools.lru_cache(maxsize=64)
def _pencil(n, theta0_deg, w, model=models.LOCAL):
    """Sector blocks B(q) = B0 + q B1 (J is affine in g0 at the circle, in either model: the
    tension, and so F, is affine in g0 at any fixed shape)."""
    th = math.radians(theta0_deg)
    lin0 = linearise_circle(n, 0.0, theta0_deg, w, model)
    lin1 = linearise_circle(n, 3.0 / math.sin(th), theta0_deg, w, model)
    return {s: (lin0.blocks[s], lin1.blocks[s] - lin0.blocks[s]) for s in SECTORS + ("stretch",)}


def sigma(n, theta0_deg, w, sector, q, model=models.LOCAL):
    """Largest Re σ of a sector's block at q (from the affine pencil, :func:`sector_growth_rates`)."""
    b0, b1 = _pencil(n, theta0_deg, w, model)[sector]
    return float(np.max(np.linalg.eigvals(b0 + q * b1).real))


def sector_growth_rates(q_values, n, theta0_deg=90.0, w=DEFAULT_W, model=models.LOCAL):
    """Largest Re σ of each sector ("in-plane", "out-of-plane", "stretch") for each q.

    Uses J(q) = J(0) + q (J(q=1) - J(0)), exact because the circle's T0, f0 and
    the linearised tension are affine in g0 (checked in the tests).
    """
    n = _check_n(n)
    th = _check_theta_for_q(theta0_deg)
    qs = np.asarray(q_values, dtype=float)
    return {s: np.array([sigma(n, th, float(w), s, float(q), model)
                         for q in qs.ravel()]).reshape(qs.shape)
            for s in SECTORS + ("stretch",)}


def critical_q(n, sector, theta0_deg=90.0, w=DEFAULT_W, q_max=60.0, q_step=0.5,
               model=models.LOCAL):
    """Smallest q > 0 where the sector's largest Re σ crosses 0 (scan, then brentq to 1e-13).

    NaN if there is no crossing on [0, q_max].  ``model``: ``models.Model`` (the nonlocal
    model's sectors decouple exactly only at θ0 = 90°, docs/nonlocal.md).
    """
    n = _check_n(n)
    check_sector(sector)
    th = _check_theta_for_q(theta0_deg)
    return first_crossing(lambda q: sigma(n, th, float(w), sector, q, model), q_max, q_step,
                          1e-13)


def critical_q_table(n_values, theta0_deg=90.0, w=DEFAULT_W):
    """Rows (n, q_crit in-plane, q_crit out-of-plane, paper's q_crit, corrected-operator q_crit)."""
    return [(int(n), critical_q(n, "in-plane", theta0_deg, w), critical_q(n, "out-of-plane", theta0_deg, w),
             paper.critical_q(int(n)), paper.critical_q(int(n), corrected=True)) for n in n_values]


# ---------------------------------------------------------------- comparison with the paper
def paper_comparison(q_values, n, theta0_deg=90.0, w=DEFAULT_W, model=models.LOCAL):
    """Rows dict(q, paper, corrected, out_of_plane, in_plane): largest growth rates of the
    paper's operator and the corrected one (``stability.paper``), and the full Jacobian's
    sectors (of ``model``)."""
    rates = sector_growth_rates(q_values, n, theta0_deg, w, model)
    rows = []
    for i, q in enumerate(np.asarray(q_values, dtype=float).ravel()):
        rows.append(dict(q=float(q), paper=paper.largest_growth_rate(float(q), n),
                         corrected=paper.largest_growth_rate(float(q), n, corrected=True),
                         out_of_plane=float(rates["out-of-plane"].ravel()[i]),
                         in_plane=float(rates["in-plane"].ravel()[i])))
    return rows


# ---------------------------------------------------------------- unstable modes
def unstable_mode(q, n, sector, theta0_deg=90.0, w=DEFAULT_W, points=256):
    """Shape of the leading eigenspace of a sector at q.

    The leading eigenvalue is double (the wavenumber chains k > 0 and k < 0
    couple only through the quotiented k = 0, ±1 modes), so the description is
    made basis-free over an L²-orthonormal basis δ_i of the eigenspace (shape
    part, orthogonal to rigid motions).  Local-frame fields: ζ = δ·e_n,
    α = δ·e_r, β = δ·e_t.  ``envelope`` = sqrt(Σ_i ζ_i²) (out-of-plane) or
    sqrt(Σ_i α_i² + β_i²) (in-plane); ``spectrum[k]`` the fraction of that
    field's Σ_i ∫ in wavenumber k; ``normal_fraction`` = ∫ζ²/∫|δ|² (below 1
    for out-of-plane modes when θ0 < 90°: they drag in-plane motion along);
    ``radial_fraction`` = ∫α²/∫(α²+β²).  s = 0 is the top (aft) of the falling
    loop, N = +q; s = π the bottom (fore), N = -q.
    """
    n = _check_n(n)
    check_sector(sector)
    th = math.radians(_check_theta_for_q(theta0_deg))
    g0 = 3.0 * q / math.sin(th)
    spec = full_spectrum(g0, theta0_deg, n, w)
    sel = np.flatnonzero(spec.sector == sector)
    lead = spec.eigenvalues[sel[0]]
    group = sel[np.abs(spec.eigenvalues[sel] - lead) <= 1e-7 * max(1.0, abs(lead))]
    vecs = np.concatenate([np.stack([v.real, v.imag]) if np.any(v.imag) else v.real[None]
                           for v in spec.modes[group]]).reshape(-1, 3 * (2 * n + 1))
    # L²-orthonormal basis of the eigenspace
    wts = np.sqrt(np.tile(l2_weights(n), 3))
    qv, rv = np.linalg.qr((vecs * wts).T)
    qv = qv[:, np.abs(np.diag(rv)) > 1e-10 * np.abs(rv).max()]
    basis = (qv.T / wts).reshape(-1, 3, 2 * n + 1)
    s = 2.0 * np.pi * np.arange(points) / points
    frame = np.array([[1.0, 0.0, 0.0], [0.0, math.cos(th), math.sin(th)],
                      [0.0, -math.sin(th), math.cos(th)]])
    e_r = np.outer(frame[0], np.sin(s)) + np.outer(frame[1], np.cos(s))
    e_t = np.outer(frame[0], np.cos(s)) - np.outer(frame[1], np.sin(s))
    vals = np.stack([b @ spectral.basis(n, s).T for b in basis])         # (B, 3, points)
    zeta = np.einsum("c,bcs->bs", frame[2], vals)
    alpha = np.einsum("cs,bcs->bs", e_r, vals)
    beta = np.einsum("cs,bcs->bs", e_t, vals)
    if sector == "out-of-plane":
        envelope = np.sqrt(np.sum(zeta**2, 0))
        fields = [zeta]
    else:
        envelope = np.sqrt(np.sum(alpha**2 + beta**2, 0))
        fields = [alpha, beta]
    power = sum(np.sum(np.abs(np.fft.rfft(fld, axis=-1)) ** 2, 0) for fld in fields)
    power[1:] *= 2.0
    return dict(
        q=float(q), sector=sector, growth_rate=complex(lead), multiplicity=len(basis),
        s=s, envelope=envelope, s_max=float(s[np.argmax(envelope)]),
        spectrum=power[: n + 2] / power.sum(),
        radial_fraction=(float(np.sum(alpha**2) / np.sum(alpha**2 + beta**2))
                     if np.sum(alpha**2 + beta**2) > 1e-20 * np.sum(vals**2) else float("nan")),
        normal_fraction=float(np.sum(zeta**2) / np.sum(vals**2)),
    )
