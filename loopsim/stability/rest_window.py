"""Where a loop can come to rest: the stable part of the steady branch, as a window of tilts.

A settled loop lies in a plane (docs/stability.md §5): it is either the translating
circle, stable for q < q_c = 8.9001 (the circle's in-plane threshold, where the branch
of steady in-plane shapes leaves it), or a steady shape of the branch's in-plane-stable
half, stable up to the first q where one of its sectors loses stability.  Along that
half (``branch.upper_half``, continued up to its fold) each loss is located by brentq
on the leading Re σ of its sector (``branch.rate_crossing``) and typed by the leading
eigenvalue there: a Hopf bifurcation when it is a complex pair (its frequency Im σ, in
1/t_u, is the period of the oscillation that grows), a steady bifurcation when it is
real; the fold is where q turns back along the branch (the largest q of a quadratic
through the three points around it, in arclength).

Both the branch and its spectra depend on q alone (the loop's plane at tilt θ feels
the in-plane gravity g0 sin θ = 3q), so at a given g0 the loop rests on the branch
only where

    q_c ≤ g0 sin θ / 3 ≤ q_loss      ⇔      arcsin(3 q_c / g0) ≤ θ ≤ arcsin(min(1, 3 q_loss / g0))

and as a tilted circle at θ < arcsin(3 q_c / g0) (any tilt if 3 q_c ≥ g0).  Tilts in
degrees, q and g0 dimensionless.  The local model only: in nonlocal slender-body theory
gravity normal to a non-circular loop's plane does not move its points alike, so a tilted
steady shape bends out of its plane and the tilt no longer enters through q alone
(docs/steady-branch.md).
"""
from __future__ import annotations

import dataclasses
import functools
import json
import math
import os

import numpy as np

from .. import _jitcache, storage, validation
from ..defaults import DEFAULT_W
from . import branch

__all__ = ["StabilityLoss", "RestWindow", "stability_losses", "rest_window", "tilt_window",
           "classify_rest", "window_for", "DEFAULT_WINDOW_N", "REST_CLASSES"]

#: Truncation order of the window: q_loss_out_of_plane within 4e-7 of n = 24
#: (docs/stability.md §5).
DEFAULT_WINDOW_N = 16
#: Continuation step limit (in the norm of (x, q)) along the branch up to its fold.
WINDOW_STEP_MAX = 0.4
#: A leading eigenvalue at a crossing is a complex pair (Hopf) when |Im σ| exceeds this.
HOPF_IM_TOL = 1e-6
#: Where a settled loop lies relative to the window (``classify_rest``).
REST_CLASSES = ("inside", "below", "outside")


@dataclasses.dataclass(frozen=True)
class StabilityLoss:
    """One loss of stability along the branch: ``q``; ``kind`` hopf | steady | fold;
    ``sector`` out-of-plane | in-plane (None for the fold); ``frequency`` |Im σ| of the
    leading eigenvalue at the crossing, 1/t_u (0 for a steady bifurcation, NaN for the
    fold)."""

    q: float
    kind: str
    sector: str | None
    frequency: float


@dataclasses.dataclass(frozen=True)
class RestWindow:
    """The stable stretch of the branch in q: from ``q_circle`` (the circle's in-plane
    threshold, where the branch starts) to ``q_loss`` (the first of ``losses``), at
    truncation ``n`` and penalty ``w``.  ``tilts`` turns it into tilts at a g0."""

    n: int
    w: float
    q_circle: float
    losses: tuple

    @property
    def q_loss(self):
        """q of the first loss of stability along the branch."""
        return self.losses[0].q

    def tilts(self, g0):
        """(θ_low, θ_high) in degrees at ``g0``: the branch's stable tilts (module
        docstring).  θ_low is NaN where no tilt reaches q_c (3 q_c ≥ g0: every rest is
        a circle); θ_high is 90 where even θ = 90° stays below the first loss."""
        return tilt_window(g0, self.q_circle, self.q_loss)

    #: Where a settled loop lies relative to the window (``classify``).
    CLASSES = REST_CLASSES

    def classify(self, theta_deg, g0):
        """``classify_rest(theta_deg, g0, self)``: inside, below or outside the window."""
        return classify_rest(theta_deg, g0, self)

    def as_dict(self, g0=()):
        """JSON-ready (NaN as None): n, w, q_circle, q_loss, losses, and per g0 its tilt
        window."""
        def clean(record):
            return {k: None if isinstance(v, float) and math.isnan(v) else v
                    for k, v in record.items()}

        out = dict(n=self.n, w=self.w, q_circle=self.q_circle, q_loss=self.q_loss,
                   losses=[clean(dataclasses.asdict(loss)) for loss in self.losses])
        out["windows"] = [clean(dict(zip(("g0", "theta_low_deg", "theta_high_deg"),
                                         (float(g), *self.tilts(g))))) for g in g0]
        return out


def tilt_window(g0, q_low, q_high):
    """(θ_low, θ_high) in degrees of q_low ≤ g0 sin θ / 3 ≤ q_high at ``g0``: θ_low NaN
    where 3 q_low ≥ g0, θ_high 90 where 3 q_high ≥ g0."""
    g0 = validation.check_real("g0", g0, 0.0, low_open=True)
    low = math.degrees(math.asin(3.0 * q_low / g0)) if 3.0 * q_low < g0 else math.nan
    high = math.degrees(math.asin(min(1.0, 3.0 * q_high / g0)))
    return low, high


def classify_rest(theta_deg, g0, window):
    """Where a loop settled at tilt ``theta_deg`` (degrees) lies at ``g0``: ``inside`` the
    window (on the stable branch), ``below`` it (q < q_c: a tilted circle; every tilt is
    below where 3 q_c ≥ g0) or ``outside`` (above it, where no steady shape is stable);
    None for a NaN tilt."""
    theta = float(theta_deg)
    if math.isnan(theta):
        return None
    low, high = window.tilts(g0)
    if math.isnan(low) or theta < low:
        return "below"
    return "inside" if theta <= high else "outside"


def _loss_at(shapes, qs, values, sector, tol):
    """The first sign change of ``values`` (leading Re σ of ``sector``) along the
    branch's shapes while q still grows (past the fold each q has two shapes, and a
    bisection in q is ill-posed), refined by brentq and typed by the eigenvalue there;
    None if none."""
    for i in range(1, len(values)):
        if qs[i] <= qs[i - 1]:
            break
        if values[i - 1] < 0.0 <= values[i]:
            q = branch.rate_crossing(shapes[i], qs[i - 1], qs[i], tol, sector=sector)
            shape = branch.solve_steady(shapes[i].x, q, shapes[i].w, symmetric=True)
            lead = branch.stability(shape)[f"leading_{sector}"]
            kind = "hopf" if abs(lead.imag) > HOPF_IM_TOL else "steady"
            return StabilityLoss(q=q, kind=kind, sector=sector.replace("_", "-"),
                                 frequency=abs(lead.imag) if kind == "hopf" else 0.0)
    return None


def _fold(shapes):
    """The fold: the largest q of the quadratic through the three points around the
    largest q along the branch, in cumulative arclength of (x, q)."""
    qs = np.array([s.q for s in shapes])
    i = int(np.argmax(qs))
    if i in (0, len(qs) - 1):
        return None
    pts = [np.concatenate([s.x.ravel(), [s.q]]) for s in shapes[i - 1:i + 2]]
    arc = np.concatenate([[0.0], np.cumsum([np.linalg.norm(b - a) for a, b in zip(pts, pts[1:])])])
    c2, c1, c0 = np.polyfit(arc, qs[i - 1:i + 2], 2)
    return StabilityLoss(q=float(c0 - c1 * c1 / (4.0 * c2)), kind="fold", sector=None,
                         frequency=math.nan)


#: The modules a window depends on beyond the kernels (whose source the cache directory
#: is already named after): a change in any of them computes the window anew.
WINDOW_SOURCES = ("stability/rest_window.py", "stability/branch.py", "stability/steady.py",
                  "stability/full_linear.py")


def cache_path(n, w, q_max, tol):
    """Where a computed window is kept: the kernels' cache directory
    (``loopsim._jitcache.cache_dir``), under a name holding a hash of
    ``WINDOW_SOURCES`` and the arguments."""
    sources = [os.path.join(_jitcache.PACKAGE_DIR, *name.split("/")) for name in WINDOW_SOURCES]
    return os.path.join(_jitcache.cache_dir(),
                        f"rest-window-{_jitcache.source_hash(sources)}-n{n}-w{w!r}-q{q_max!r}"
                        f"-tol{tol!r}.json")


def _from_record(record):
    return RestWindow(n=int(record["n"]), w=float(record["w"]),
                      q_circle=float(record["q_circle"]),
                      losses=tuple(StabilityLoss(q=float(loss["q"]), kind=loss["kind"],
                                                 sector=loss["sector"],
                                                 frequency=math.nan if loss["frequency"] is None
                                                 else float(loss["frequency"]))
                                   for loss in record["losses"]))


@functools.lru_cache(maxsize=8)
def stability_losses(n=DEFAULT_WINDOW_N, w=DEFAULT_W, q_max=80.0, tol=1e-10, cache=True):
    """The losses of stability along the branch's in-plane-stable half, in order of q:
    the first out-of-plane and in-plane crossings (Hopf or steady) and the fold, as a
    ``RestWindow``.  About 20 s of one core at n = 16; once computed it is kept
    beside the compiled kernels (``cache``; a change to the code it depends on computes it
    anew) and read back in milliseconds."""
    n = validation.check_count("n", n, 4, validation.MAX_BRANCH_N,
                               "the continuation's cost grows like n^3 per point")
    path = cache_path(n, float(w), float(q_max), float(tol)) if cache else None
    if path is not None and os.path.isfile(path):
        try:
            with open(path, encoding="utf-8") as handle:
                record = json.load(handle)
            if storage.CONTENT_KEY in record and storage.record_hash_damage(record) is None:
                return _from_record(record)
        except (OSError, ValueError, KeyError, TypeError, AttributeError):
            pass  # unreadable or damaged (its checksum): computed anew and written over
    window = _compute_losses(n, float(w), float(q_max), float(tol))
    if path is not None:
        try:
            storage.write_record_atomically(window.as_dict(), path)
        except OSError:
            pass  # a read-only cache: the window is still returned
    return window


def _compute_losses(n, w, q_max, tol):
    half = branch.upper_half(n, q_max, w, step_max=WINDOW_STEP_MAX, stop_after_fold=True)
    shapes = half.shapes
    qs = [s.q for s in shapes]
    spectra = [branch.stability(s) for s in shapes]
    losses = []
    for sector in ("out_of_plane", "in_plane"):
        rates = [spectrum[f"leading_{sector}"].real for spectrum in spectra]
        loss = _loss_at(shapes, qs, rates, sector, tol)
        if loss is not None:
            losses.append(loss)
    fold = _fold(shapes)
    if fold is not None:
        losses.append(fold)
    if not losses:
        raise ValueError(f"no loss of stability along the branch up to q = {q_max} at n = {n}")
    return RestWindow(n=n, w=w, q_circle=float(half.q_circle),
                      losses=tuple(sorted(losses, key=lambda loss: loss.q)))


def window_for(frame):
    """The window to count a results table's loops at rest against
    (``summarize(..., rest_window=...)``, the phase diagrams): ``stability_losses``
    for a local-model table, None for another model (its branch is not continued)."""
    models = set(frame["model"].dropna()) if "model" in frame else set()
    return stability_losses() if models <= {"local"} else None


def rest_window(g0, n=DEFAULT_WINDOW_N, w=DEFAULT_W):
    """The tilts (θ_low, θ_high), in degrees, at which a loop at ``g0`` can rest on the
    stable steady branch (module docstring), with the ``RestWindow`` they come from.

    Examples
    --------
    The window at the top of the paper's range (about a minute of one core):

    >>> low, high, window = rest_window(350.0)                      # doctest: +SKIP
    >>> round(low, 2), round(high, 2), window.losses[0].kind        # doctest: +SKIP
    (4.38, 18.78, 'hopf')
    """
    window = stability_losses(n, w)
    return (*window.tilts(g0), window)
