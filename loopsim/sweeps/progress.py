"""Progress of a sweep on stderr (a live line, or lines in a log file), with an ETA
weighted by each case's estimated cost."""
import math
import sys
import time

from .. import _jitcache, diagnostics


#: ``--n auto`` sweeps: a 3D case's wall time grows like q0**AUTO_COST_EXPONENT.  Fitted
#: (log-log least squares) to the 24 3D cases among the first 32 of the resolved main-job
#: grid (radau5, rtol 1e-6, t = 10): exponent 3.95, and 0.058 s × (q0 / 11)^3.95 meets the
#: cheap cases' median, 0.066 s, at q0 = 11 (docs/earlier-n-auto.md).
AUTO_COST_EXPONENT = 4.0
#: The ETA is shown ("?" before) once the finished cases carry this share of the run's
#: estimated cost: extrapolated from one cheap case it was 10x off (32 min for the
#: README's 3-minute main job).
ETA_MIN_SHARE = 0.01


def case_weight(case, n_auto=False):
    """Estimated relative cost of a case, for the ETA.  Fixed n: n², times 3 when q0 > 11
    (3D loops: 2.7× the RHS evaluations of stable ones in docs/performance.md; one
    RHS costs about n^1.7).  ``n_auto``: n² × (q0 / 11)^4 when q0 > 11 (the resolved 3D
    transient climbs to n = 24–32, and its cost spans 1 s to minutes with q0)."""
    theta = case.get("theta0_deg", math.nan)
    q0 = diagnostics.stability_parameter(case["g0"], theta) if math.isfinite(theta) else 0.0
    if q0 <= 11.0:
        return float(case["n"] ** 2)
    return case["n"] ** 2 * ((q0 / 11.0) ** AUTO_COST_EXPONENT if n_auto else 3.0)


def _duration(seconds):
    if not math.isfinite(seconds):
        return "?"
    seconds = int(round(seconds))
    return f"{seconds // 3600}h{seconds // 60 % 60:02d}m{seconds % 60:02d}s"


class Progress:
    """Progress on stderr: a live line in a terminal; in a log file (not a TTY) one line
    every ``interval`` seconds, and a last one at the end.  Done/total, rate, ETA weighted
    by :func:`case_weight` (both from the time worked: kernel compilation left out; the
    ETA "?" until ``ETA_MIN_SHARE`` of the cost is done), failures.  ``quiet``: nothing."""

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

    def update(self, case_ids, failures):
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
        return (f"cases {self.done}/{self.total} ({100 * self.done / max(self.total, 1):3.0f}%) "
                f"{rate:6.2f} case/s elapsed {_duration(elapsed)} ETA {_duration(eta)} "
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
