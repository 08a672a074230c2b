"""When do loops released near the circle become visibly in-plane or 3D: onset predictions.

From the circle's growth rates (``stability.full_linear``) and the linear gains of
the sweep's observables (aspect ratio, tilt); see :func:`regime_onsets`.
"""
import math

import numpy as np
from scipy.linalg import eig

from .. import diagnostics, models, validation
from ..defaults import DEFAULT_W
from ..shapes import inclined_circle, initial_shape
from .full_linear import (
    SECTORS, check_sector, critical_q, full_spectrum, l2_weights,
    linearise_circle, neutral_modes, sigma,
)
from .roots import first_crossing

__all__ = ["onset_q", "seeded_mode_amplitudes", "regime_onsets"]

#: Scan range and step of the onset search in q.
ONSET_Q_MAX = 59.75
ONSET_SCAN_STEP = 0.25


def onset_q(eps, t_end, detect, n, sector, theta0_deg=90.0, w=DEFAULT_W, q_max=60.0,
            model=models.LOCAL):
    """q at which a mode of initial size eps reaches size detect at t_end:
    eps·exp(σ(q) t_end) = detect, i.e. σ(q) = ln(detect/eps)/t_end.  NaN if never on [0, q_max].
    """
    if not (eps > 0 and detect > 0 and t_end > 0):
        raise ValueError("eps, detect and t_end must be positive")
    n = validation.check_integer("n", n, 3)
    check_sector(sector)
    th = validation.check_tilt("theta0 (for a given q)", theta0_deg, allow_zero=False)
    target = math.log(detect / eps) / t_end
    fun = lambda q: sigma(n, th, float(w), sector, q, model) - target  # noqa: E731
    return first_crossing(fun, q_max, 0.5, 1e-12)


def _observable_gains(q, n, theta0_deg, w):
    """Linear gains of the sweep's observables per unit rms amplitude of the leading modes.

    c_aspect: max over the in-plane eigenspace of |d(aspect ratio)/dA| at the circle.
    c_tilt: max over the out-of-plane eigenspace (amplitude = rms of ζ) of the rate of
    rigid rotation about the horizontal axis a (dθ/dt per unit amplitude), read off
    J v - σ v ∈ N: the k = 2 normal mode drives the k = 1 tilt (the -3q coupling).
    """
    th = math.radians(theta0_deg)
    g0 = 3.0 * q / math.sin(th)
    spec = full_spectrum(g0, theta0_deg, n, w)
    lin = linearise_circle(n, g0, theta0_deg, w)
    x0 = inclined_circle(n, th)
    nx = neutral_modes(n, theta0_deg)
    wts = l2_weights(n)
    gains = {}
    for sector in SECTORS:
        sel = np.flatnonzero(spec.sector == sector)[:2]
        lam = spec.eigenvalues[sel[0]].real
        best = 0.0
        for phi in np.linspace(0.0, np.pi, 37):
            v = math.cos(phi) * spec.modes[sel[0]].real + math.sin(phi) * spec.modes[sel[-1]].real
            if sector == "in-plane":
                v = v / math.sqrt(np.sum(wts * v**2))
                h = 1e-7
                best = max(best, abs(diagnostics.aspect_ratio(x0 + h * v) - 1.0) / h)
            else:
                zeta = (-math.sin(th)) * v[1] + math.cos(th) * v[2]
                v = v / math.sqrt(np.sum(wts * zeta**2))
                r = lin.jacobian @ v.ravel() - lam * v.ravel()
                best = max(best, abs(np.linalg.lstsq(nx, r, rcond=None)[0][4]))
        gains[sector] = best
    return gains["in-plane"], gains["out-of-plane"]


def seeded_mode_amplitudes(eps, seed, n, theta0_deg, w=DEFAULT_W):
    """Rms amplitudes that ``initial_shape(n, θ0, eps, seed)`` puts into the leading
    in-plane eigenspace (its |δ|) and the leading out-of-plane one (its ζ), each taken at
    the sector's critical q, via the spectral projector V (WᴴV)⁻¹ Wᴴ of the quotient J̄
    (right and left eigenvectors of the double eigenvalue).
    """
    n = validation.check_integer("n", n, 3)
    th = math.radians(validation.check_tilt("theta0 (for a given q)", theta0_deg, allow_zero=False))
    x0 = inclined_circle(n, th)
    d = (initial_shape(n, th, eps, seed) - x0).ravel()
    wts = np.tile(l2_weights(n), 3)
    amps = {}
    for sector in SECTORS:
        qc = critical_q(n, sector, theta0_deg, w)
        lin = linearise_circle(n, 3.0 * qc / math.sin(th), theta0_deg, w)
        vals, left, right = eig(lin.quotient, left=True, right=True)
        lead = np.max(np.linalg.eigvals(lin.blocks[sector]).real)
        pick = np.argsort(np.abs(vals - lead))[:2]
        V, W = right[:, pick], left[:, pick]
        coords = lin.basis.T @ d                               # d in quotient coordinates
        proj = lin.basis @ (V @ np.linalg.solve(W.conj().T @ V, W.conj().T @ coords))
        proj = proj.real.reshape(3, -1)
        if sector == "out-of-plane":
            proj = (-math.sin(th) * proj[1] + math.cos(th) * proj[2])[None]
        amps[sector] = float(math.sqrt(np.sum(wts[:proj.shape[1]] * proj**2)))
    return amps["in-plane"], amps["out-of-plane"]


def regime_onsets(eps=1e-3, t_end=10.0, n=6, theta0_deg=90.0, w=DEFAULT_W,
                  aspect_tol=0.01, tilt_tol_deg=1.0, saturation=0.5, seed=None):
    """Predicted q where loops released with perturbation size eps are first labelled
    in-plane and 3D at t_end (the sweep's thresholds), from the circle's growth rates.

    Each leading mode starts with rms amplitude eps (ζ's rms for the out-of-plane one).
    In-plane: the aspect ratio changes by c_aspect·A (A = eps·e^{σ_in t}); visible when
    c_aspect·eps·e^{σ_in t_end} = aspect_tol.
    3D: the out-of-plane mode turns the loop about its horizontal axis at rate c_tilt·A,
    so Δθ(t) = c_tilt·eps·(e^{σ_out t} - 1)/σ_out; growth about the circle stops once the
    in-plane mode saturates (aspect change ``saturation``, reached at
    t_sat = ln(saturation/(c_aspect eps))/σ_in), so Δθ is taken at min(t_end, t_sat).
    With ``seed`` given, the amplitudes are those the seeded initial perturbation of size
    eps puts into the two leading eigenspaces (:func:`seeded_mode_amplitudes`) instead
    of eps.  Gains from :func:`_observable_gains` at each sector's critical q.  The 3D onset of
    the circle is a lower bound: beyond it the saturated in-plane shape has its own
    instability (docs/stability.md).  Returns a dict.
    """
    n = validation.check_integer("n", n, 3)
    th = validation.check_tilt("theta0 (for a given q)", theta0_deg, allow_zero=False)
    if not (eps > 0 and t_end > 0 and aspect_tol > 0 and tilt_tol_deg > 0 and saturation > aspect_tol):
        raise ValueError("eps, t_end and the tolerances must be positive, saturation > aspect_tol")
    qc_in, qc_out = critical_q(n, "in-plane", th, w), critical_q(n, "out-of-plane", th, w)
    c_aspect, _ = _observable_gains(qc_in, n, th, w)
    _, c_tilt = _observable_gains(qc_out, n, th, w)
    tilt_tol = math.radians(tilt_tol_deg)
    a_in, a_out = (eps, eps) if seed is None else seeded_mode_amplitudes(eps, seed, n, th, w)

    def f_in(q):
        return math.log(c_aspect * a_in / aspect_tol) + sigma(n, th, float(w), "in-plane", q) * t_end

    def f_out(q):
        s_in = sigma(n, th, float(w), "in-plane", q)
        t = t_end if s_in <= 0 else min(t_end, math.log(saturation / (c_aspect * a_in)) / s_in)
        s_out = sigma(n, th, float(w), "out-of-plane", q)
        growth = math.expm1(s_out * t) / s_out if s_out != 0.0 else t
        return c_tilt * a_out * growth - tilt_tol

    out = {}
    for key, fun in (("q_in_plane", f_in), ("q_3d", f_out)):
        out[key] = first_crossing(fun, ONSET_Q_MAX, ONSET_SCAN_STEP, 1e-10)
    out.update(c_aspect=float(c_aspect), c_tilt=float(c_tilt), amplitude_in_plane=a_in,
               amplitude_out_of_plane=a_out, q_crit_in_plane=qc_in,
               q_crit_out_of_plane=qc_out)
    return out


