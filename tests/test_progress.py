"""The ETA's upper end (``sweeps.progress.eta_upper``): a bootstrap of the finished cases'
measured cost per unit weight, checked against cases whose quantile is known exactly."""
import io as stdio
import time

import numpy as np
import pyarrow as pa
import pytest

from loopsim.sweeps import progress


def test_equal_paces_give_the_mean_rate_eta():
    # every finished case took 2 s per unit weight, 10 s of wall for 20 s of cases (two
    # threads): the remaining 30 units are 60 s of cases, 30 s of wall, in every resample
    # (no one case of them, 10 s at most, outlasts that)
    upper = progress.eta_upper([1.0, 2.0, 3.0, 4.0], [2.0, 4.0, 6.0, 8.0], [5.0] * 6,
                               working=10.0)
    assert upper == pytest.approx(30.0, rel=1e-12)


def test_a_heavy_tail_lifts_the_upper_end_to_the_tail():
    # 6 of 8 finished cases took 1 s, 2 took 250 s (weights equal): a remaining case draws
    # 250 s with probability 1/4 > 1 - 0.9, so the 90% quantile is the tail's 250 s
    # (it runs alone: the straggler term), where the mean-rate ETA, working x (weight
    # left) / (weight done) = 253 s x 1/8, says 31.6 s
    seconds = [1.0] * 6 + [250.0] * 2
    upper = progress.eta_upper([1.0] * 8, seconds, [1.0], working=sum(seconds) / 2)
    assert upper == pytest.approx(250.0, rel=1e-12)


def test_the_costliest_remaining_case_bounds_it_from_below():
    # a fast pace (8 threads' worth) cannot shorten one remaining case of 100 units at 1 s
    upper = progress.eta_upper([1.0] * 5, [1.0] * 5, [100.0, 1.0], working=5.0 / 8)
    assert upper == pytest.approx(100.0, rel=1e-12)
    assert progress.eta_upper([1.0] * 5, [1.0] * 5, [], working=1.0) == 0.0


def test_many_remaining_cases_are_subsampled_to_the_same_sum():
    n = progress.ETA_MAX_DRAWN * 5
    upper = progress.eta_upper([1.0] * 6, [3.0] * 6, [1.0] * n, working=18.0)
    assert upper == pytest.approx(3.0 * n, rel=1e-12)


def test_untimed_cases_do_not_enter_the_bootstrap():
    line = progress.Progress({i: 1.0 for i in range(8)}, [], quiet=True)
    line.update([0, 1, 2], 0, [1.0, float("nan"), 0.0])  # NaN: failed before running
    line.update([3], 0, None)  # a table without times
    line.update([99], 0, [5.0])  # not one of this run's cases
    assert line.timed_seconds == [1.0] and line.timed_weights == [1.0]
    assert line.left == {4, 5, 6, 7}


def test_case_seconds_count_the_twin_by_its_evaluations():
    table = pa.table(dict(wall_s=[2.0, 4.0, 1.0], nfev=[100, 200, 50],
                          twin_nfev=[150, None, 0]))
    np.testing.assert_allclose(progress.case_seconds(table), [5.0, 4.0, 1.0])
    np.testing.assert_allclose(progress.case_seconds(table.drop(["twin_nfev"])),
                               [2.0, 4.0, 1.0])
    # a Dask worker that wrote its own rows sends back ids and statuses only
    assert progress.case_seconds(pa.table(dict(case_id=[0], status=["ok"]))) is None


def test_the_line_shows_the_upper_end_once_cases_are_timed(monkeypatch):
    clock = iter(float(t) for t in range(100))
    monkeypatch.setattr(time, "perf_counter", lambda: next(clock))
    stream = stdio.StringIO()
    line = progress.Progress({i: 1.0 for i in range(10)}, [], stream=stream, interval=0.0)
    for i in range(4):
        line.update([i], 0, [1.0])
    assert "<" not in stream.getvalue()  # 4 timed cases: no upper end yet
    line.update([4], 0, [250.0])
    last = stream.getvalue().splitlines()[-1]
    assert "ETA" in last and "(90%: <" in last, last
    eta, upper = last.split("ETA ")[1].split(" (90%: <")
    seconds = [sum(int(p) * m for p, m in zip(
        text.replace("h", " ").replace("m", " ").replace("s", " ").split()[:3],
        (3600, 60, 1))) for text in (eta, upper)]
    assert seconds[1] > seconds[0]


def _upper_seconds(line):
    text = line.split("(90%: <")[1].split(")")[0]
    h, rest = text.split("h")
    m, s = rest.rstrip("s").split("m")
    return 3600 * int(h) + 60 * int(m) + int(s)


def test_the_upper_end_is_aged_between_estimates(monkeypatch):
    clock = [0.0]
    monkeypatch.setattr(time, "perf_counter", lambda: clock[0])
    stream = stdio.StringIO()
    line = progress.Progress({i: 1.0 for i in range(20)}, [], stream=stream, interval=0.0)
    for i, seconds in enumerate([1.0, 1.0, 1.0, 1.0, 100.0]):
        clock[0] = 10.0 * (i + 1)
        line.update([i], 0, [seconds])  # t = 10 ... 50: the estimate made at t = 50
    first = _upper_seconds(stream.getvalue().splitlines()[-1])
    clock[0] = 52.0
    line.update([5], 0, [1.0])  # within ETA_UPPER_EVERY: the estimate, 2 s older
    second = _upper_seconds(stream.getvalue().splitlines()[-1])
    assert first > 100 and second == first - 2
