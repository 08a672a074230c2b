"""Seeds until the answer is sharp: the stopping rule of ``--seeds auto`` (plain pandas).

A cell (one point of the sweep's inputs, the seed left out) starts with ``min_seeds``
seeds and doubles them, round after round, until one of these holds, checked in order:

* ``failed``: every seed failed (no run succeeded): the cell has no outcome, so no
  distribution to sharpen or check;
* ``deterministic``: every seed succeeded, in the same regime, and the terminal tilts and
  aspect ratios of all seeds lie within ``tilt_tol_deg`` and ``aspect_tol`` of each other
  (max − min): more seeds cannot change the answer (stable loops, settled in-plane loops);
* ``sharp``: every regime probability's 95 % Wilson interval has half-width at most
  ``p_halfwidth`` and the median tilt's 95 % bootstrap interval (``summary``) half-width
  at most ``tilt_halfwidth_deg``;
* ``cap``: the cell has ``max_seeds`` seeds.

After the sweep, ``--rerun-failed`` may replace failed runs: the cells it touched are
decided again from their rows, and one the rule would give more seeds stops as
``rescued`` (the finished sweep adds none).

A cell whose runs are *samples* (``runs_are_samples``: some run succeeded, and its
seeds end in different regimes, or some run's stricter twin ends elsewhere) needs no more
twins: each would only prove once more that one run is a sample.  Its later seeds run
without twins, and its distribution is checked instead against a subsample at the twins'
stricter tolerances (``check_seeds`` seeds, ``sweeps.seeds_auto``; verdict by
``outcome_statistics.compare``).

The rule reads only a cell's finished rows, which are reproducible bit for bit, so the
rounds it plans are too: a resumed ``--seeds auto`` sweep plans what the interrupted one
did.  Seeds are numbered 0, 1, 2, ... in every cell, so a cell that stops at K seeds holds
the rows a fixed ``--seeds K`` sweep would.
"""
import dataclasses
import math

import numpy as np

from .defaults import SEED_TARGETS
from .outcomes import REGIMES
from .outcome_statistics import bootstrap_interval, wilson_interval

#: Why a cell stopped adding seeds (``stop_reason``); ``CONTINUE`` while it has not.
FAILED, DETERMINISTIC, SHARP, CAP, CONTINUE = "failed", "deterministic", "sharp", "cap", ""
#: The stop reason of a cell of a finished sweep whose failed runs ``--rerun-failed``
#: replaced since, where the rule would now add seeds (``sweeps.seeds_auto``,
#: ``restate_stop_table``): its intervals are wider than the targets.
RESCUED = "rescued"


@dataclasses.dataclass(frozen=True)
class SeedTargets:
    """The targets of ``--seeds auto`` (defaults: docs/distributions.md, "Seeds until the
    answer is sharp")."""

    p_halfwidth: float = SEED_TARGETS["p_halfwidth"][1]
    tilt_halfwidth_deg: float = SEED_TARGETS["tilt_halfwidth"][1]
    min_seeds: int = SEED_TARGETS["min_seeds"][1]
    max_seeds: int = SEED_TARGETS["max_seeds"][1]
    tilt_tol_deg: float = 1.0
    aspect_tol: float = 0.1
    check_seeds: int = SEED_TARGETS["check_seeds"][1]

    def check(self):
        """A one-line ValueError naming the first bad target."""
        for name in ("p_halfwidth", "tilt_halfwidth_deg", "tilt_tol_deg", "aspect_tol"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"--{name.replace('_', '-')} must be a positive number, "
                                 f"got {value!r}")
        if not 0 < self.p_halfwidth <= 0.5:
            raise ValueError(f"--p-halfwidth must be in (0, 0.5], got {self.p_halfwidth!r}")
        if not 2 <= self.min_seeds <= self.max_seeds:
            raise ValueError(f"--min-seeds and --max-seeds must satisfy 2 <= min <= max, got "
                             f"{self.min_seeds!r} and {self.max_seeds!r}")
        if not 0 <= self.check_seeds <= self.max_seeds and self.check_seeds != \
                SEED_TARGETS["check_seeds"][1]:  # the default: as many as a cell has
            raise ValueError(f"--check-seeds must be in 0..--max-seeds ({self.max_seeds}), "
                             f"got {self.check_seeds!r}")
        return self


def widths(rows, seed=0):
    """(largest regime-probability Wilson half-width, median-tilt bootstrap half-width in
    degrees) of one cell's rows (NaN tilt width when no row has a finite tilt)."""
    trials = len(rows)
    p_width = 0.0
    for regime in REGIMES:
        low, high = wilson_interval(int((rows["regime"] == regime).sum()), trials)
        p_width = max(p_width, (high - low) / 2)
    low, high = bootstrap_interval(rows["theta_final_deg"].to_numpy(float), seed=seed)
    return p_width, (high - low) / 2


def is_deterministic(rows, targets):
    """Every seed succeeded in one regime, tilts and aspect ratios within tolerance."""
    regimes = rows["regime"].unique()
    if len(regimes) != 1 or regimes[0] == "failed":
        return False
    tilt = rows["theta_final_deg"].to_numpy(float)
    aspect = rows["aspect_ratio"].to_numpy(float)
    if not (np.isfinite(tilt).all() and np.isfinite(aspect).all()):
        return False
    return bool(np.ptp(tilt) <= targets.tilt_tol_deg and np.ptp(aspect) <= targets.aspect_tol)


def any_succeeded(rows):
    """Whether some run of a cell succeeded (a regime other than "failed")."""
    return bool(rows["regime"].ne("failed").any())


def runs_are_samples(rows):
    """Whether a cell's runs are samples of a distribution rather than determined
    trajectories: some run succeeded (``any_succeeded``; a cell with none has no
    distribution), and its seeds end in more than one regime, or a run's twin (at
    stricter tolerances) ends elsewhere (``determined`` False)."""
    return any_succeeded(rows) and bool(rows["regime"].nunique() > 1
                                        or rows["determined"].eq(False).any())


def decide(rows, targets):
    """(stop_reason, seeds wanted) for one cell whose finished rows are ``rows`` (seeds
    0 .. len(rows) − 1): ``CONTINUE`` with the next round's size (doubling, at most
    ``max_seeds``), or the reason it stops with its current size."""
    have = len(rows)
    if have < targets.min_seeds:
        return CONTINUE, targets.min_seeds
    if not any_succeeded(rows):
        return FAILED, have
    if is_deterministic(rows, targets):
        return DETERMINISTIC, have
    p_width, tilt_width = widths(rows)
    if p_width <= targets.p_halfwidth and tilt_width <= targets.tilt_halfwidth_deg:
        return SHARP, have
    if have >= targets.max_seeds:
        return CAP, have
    return CONTINUE, min(2 * have, targets.max_seeds)


def cell_record(key_names, key, rows, targets, rounds):
    """One row of the stop table: the cell's inputs, its seeds, why it stopped (or
    ``CONTINUE``) and the interval half-widths it reached."""
    reason, _ = decide(rows, targets)
    p_width, tilt_width = widths(rows)
    key = key if isinstance(key, tuple) else (key,)
    return dict(zip(key_names, key), seeds=len(rows), rounds=rounds, stop_reason=reason,
                p_halfwidth=p_width, tilt_halfwidth_deg=tilt_width)
