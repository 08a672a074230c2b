"""Progress of a sweep on stderr (a live line, or lines in a log file), with an ETA
weighted by each case's estimated cost and, once cases have been timed, its upper end
from their measured costs (:func:`eta_upper`)."""
import math
import sys
import time

import numpy as np

from .. import _jitcache, diagnostics


#: ``--n auto`` sweeps: a 3D case's wall time grows like q0**AUTO_COST_EXPONENT.  Fitted
#: (log-log least squares) to the 24 3D cases among the first 32 of the resolved main-job
#: grid (radau5, rtol 1e-6, t = 10): exponent 3.95, and 0.058 s × (q0 / 11)^3.95 meets the
#: cheap cases' median, 0.066 s, at q0 = 11 (docs/studies/earlier-n-auto.md).
AUTO_COST_EXPONENT = 4.0
#: The ETA is shown ("?" before) once the finished cases carry this share of the run's
#: estimated cost: extrapolated from one cheap case it was 10x off (32 min for the
#: README's 3-minute main job).
ETA_MIN_SHARE = 0.01
#: The ETA's upper end is the ETA_QUANTILE quantile of the remaining time over
#: ETA_RESAMPLES bootstrap resamples of the finished cases' measured cost per unit weight
#: (:func:`eta_upper`), shown once ETA_MIN_TIMED cases have been timed.  Heavy tails are
#: the reason: at (350, 12°) one seed took 205 s and the cell's other seven 0.5-0.8 s
#: (docs/distributions.md), so a mean-rate ETA reads seconds while minutes remain.
ETA_QUANTILE = 0.9
ETA_RESAMPLES = 200
ETA_MIN_TIMED = 5
#: At most this many remaining cases enter a resample (a random subset, its sum scaled
#: to all of them): milliseconds per estimate (measured with the list of remaining weights
#: built: 0.3 ms with 100 cases left, 5 ms with 2 000, 35 ms with a million, on a busy
#: core), made at most every ETA_UPPER_EVERY seconds of the run and aged in between.
ETA_MAX_DRAWN = 2000
ETA_UPPER_EVERY = 5.0


def case_weight(case, n_auto=False):
    """Estimated relative cost of a case, for the ETA.  Fixed n: n², times 3 when q0 > 11
    (3D loops: 2.7× the RHS evaluations of stable ones in docs/studies/performance.md; one
    RHS costs about n^1.7).  ``n_auto``: n² × (q0 / 11)^4 when q0 > 11 (the resolved 3D
    transient climbs to n = 24–32, and its cost spans 1 s to minutes with q0)."""
    theta = case.get("theta0_deg", math.nan)
    q0 = diagnostics.stability_parameter(case["g0"], theta) if math.isfinite(theta) else 0.0
    if q0 <= 11.0:
        return float(case["n"] ** 2)
    return case["n"] ** 2 * ((q0 / 11.0) ** AUTO_COST_EXPONENT if n_auto else 3.0)


def case_seconds(table):
    """Seconds of work of each finished case of a result table (pyarrow): its ``wall_s``
    scaled by (nfev + twin_nfev) / nfev, the twin's share (its time is not recorded
    apart); NaN where a case has no time; None for a table without ``wall_s`` (a Dask
    worker that wrote its rows itself returns only their ids and statuses)."""
    if "wall_s" not in table.column_names:
        return None
    wall = np.asarray(table.column("wall_s").to_pylist(), dtype=float)
    if "twin_nfev" not in table.column_names:
        return wall
    nfev = np.asarray(table.column("nfev").to_pylist(), dtype=float)
    twin = np.nan_to_num(np.asarray(table.column("twin_nfev").to_pylist(), dtype=float))
    return wall * (1.0 + twin / np.clip(np.nan_to_num(nfev, nan=1.0), 1.0, None))


def eta_upper(done_weights, done_seconds, left_weights, working, quantile=ETA_QUANTILE,
              resamples=ETA_RESAMPLES, seed=0):
    """Upper end of the remaining wall time, in seconds, from the finished cases' measured
    costs: a bootstrap of their cost per unit weight r_i = s_i / w_i.

    For each resample every remaining case j (weight w_j) draws r*_j from the r_i, and the
    remaining time is max(working Σ_j w_j r*_j / Σ_i s_i, max_j w_j r*_j): the remaining
    cost at the pace the finished ones took (``working`` seconds for Σ_i s_i seconds of
    cases, whatever the threads), or its costliest case alone, which no thread shortens.
    Returns the ``quantile`` of it over ``resamples`` resamples (seeded: reproducible);
    0 with no case left.  More than ETA_MAX_DRAWN remaining cases: a random subset of them,
    its sum scaled to all (the costliest-case term then comes from the subset alone).
    """
    w = np.asarray(done_weights, dtype=float)
    s = np.asarray(done_seconds, dtype=float)
    left = np.asarray(left_weights, dtype=float)
    if not left.size:
        return 0.0
    rng = np.random.default_rng(seed)
    scale = 1.0
    if left.size > ETA_MAX_DRAWN:
        scale = left.size / ETA_MAX_DRAWN
        left = rng.choice(left, ETA_MAX_DRAWN, replace=False)
    ratios = s / w
    draws = left * ratios[rng.integers(0, ratios.size, size=(resamples, left.size))]
    pace = working / s.sum()
    remaining = np.maximum(pace * scale * draws.sum(axis=1), draws.max(axis=1))
    return float(np.quantile(remaining, quantile))


def _duration(seconds):
    if not math.isfinite(seconds):
        return "?"
    seconds = int(round(seconds))
    return f"{seconds // 3600}h{seconds // 60 % 60:02d}m{seconds % 60:02d}s"


class Progress:
    """Progress on stderr: a live line in a terminal; in a log file (not a TTY) one line
    every ``interval`` seconds, and a last one at the end.  Done/total, rate, ETA weighted
    by :func:`case_weight` (both from the time worked: kernel compilation left out; the
    ETA "?" until ``ETA_MIN_SHARE`` of the cost is done) with, once ETA_MIN_TIMED cases
    came with their seconds (``update(seconds=)``), its upper end (:func:`eta_upper`),
    failures.  ``quiet``: nothing."""

    def __init__(self, weights, done_ids, quiet=False, stream=None, interval=30.0):
        self.stream = sys.stderr if stream is None else stream
        self.weights = weights  # {case_id: weight} of the cases this run is responsible for
        self.total, self.done, self.failures = len(weights), len(done_ids), 0
        self.weight_left = sum(weights.values()) - sum(weights[i] for i in done_ids)
        self.weight_run, self.cases_run = 0.0, 0
        self.start = self.last = time.perf_counter()
        self.compiled = _jitcache.compile_seconds()  # compilation is not work: not in the ETA
        self.quiet, self.interval = quiet, interval
        self.live = not quiet and self.stream.isatty()
        self.printed = None  # the last line written to a log (not repeated by close)
        self.left = set(weights) - set(done_ids)
        self.timed_weights, self.timed_seconds = [], []
        self.upper, self.upper_at = math.nan, -math.inf  # the last upper end, and when

    def update(self, case_ids, failures, seconds=None):
        """``case_ids`` finished (``failures`` of them failed), taking ``seconds`` each
        (:func:`case_seconds`; None: not timed)."""
        self.left.difference_update(case_ids)
        if seconds is not None:
            for i, t in zip(case_ids, seconds):
                if self.weights.get(i, 0.0) > 0.0 and t > 0.0:  # NaN: not timed
                    self.timed_weights.append(self.weights[i])
                    self.timed_seconds.append(float(t))
        self.done += len(case_ids)
        self.cases_run += len(case_ids)
        self.failures += failures
        weight = sum(self.weights.get(i, 0.0) for i in case_ids)
        self.weight_run += weight
        self.weight_left -= weight
        now = time.perf_counter()
        if self.live:
            self.stream.write("\r" + self._line())
            self.stream.flush()
        elif not self.quiet and now - self.last >= self.interval:
            self.printed = self._line()
            self.stream.write(self.printed + "\n")
            self.stream.flush()
            self.last = now

    def _line(self):
        elapsed = time.perf_counter() - self.start
        working = max(elapsed - (_jitcache.compile_seconds() - self.compiled), 1e-9)
        rate = self.cases_run / working
        share = self.weight_run / max(self.weight_run + self.weight_left, 1e-300)
        eta = (working * max(self.weight_left, 0.0) / self.weight_run
               if self.weight_run > 0.0 and share >= ETA_MIN_SHARE else math.nan)
        upper = ""
        if math.isfinite(eta) and self.left and len(self.timed_seconds) >= ETA_MIN_TIMED:
            if elapsed - self.upper_at >= ETA_UPPER_EVERY or not math.isfinite(self.upper):
                self.upper = eta_upper(self.timed_weights, self.timed_seconds,
                                       [self.weights[i] for i in self.left], working)
                self.upper_at = elapsed
            aged = self.upper - (elapsed - self.upper_at)  # the time since came off it
            upper = f" ({ETA_QUANTILE:.0%}: <{_duration(max(aged, eta))})"
        return (f"cases {self.done}/{self.total} ({100 * self.done / max(self.total, 1):3.0f}%) "
                f"{rate:6.2f} case/s elapsed {_duration(elapsed)} ETA {_duration(eta)}{upper} "
                f"failures {self.failures}")

    def close(self):
        if self.quiet:
            return
        line = self._line()
        if self.live or line != self.printed:
            self.stream.write(("\r" if self.live else "") + line + "\n")
            self.stream.flush()


def failures(table):
    return sum(1 for s in table.column("status").to_pylist() if s != "ok")
