"""The committed study tables are what their scripts compute from the committed sweeps:
retabulating ``data/convergence_runs`` and ``data/paper_range_runs`` (``--read-only``,
nothing run) reproduces ``data/convergence_top.parquet`` and
``data/paper_range_top_*.parquet`` (the bootstrap is seeded).

The intervals come from ``scipy.stats`` since issue 55 (the tables were written by the
hand-written formulas before it).  Counts, text and the Wilson and Newcombe intervals
are reproduced bit for bit; a median's bootstrap interval is drawn from the very same
resamples, and only the interpolation between two sorted draws rounds differently
(scipy's quantile at 0.025 against NumPy's percentile at 2.5: 4.3e-14 deg at most,
measured): the floats are compared to 1e-12 relative.  The tables whose sweeps are not
committed (the 153 paper-range cells, the 72-point seeds-auto grid) are checked where
their counts allow: every Wilson interval from the counts beside it."""
import os
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from loopsim.outcome_statistics import wilson_interval

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def script(name, *args):
    done = subprocess.run([sys.executable, os.path.join("scripts", name), *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]


def committed(name):
    return pd.read_parquet(os.path.join(ROOT, "data", name))


def assert_reproduced(table, expected):
    """Equal columns and non-float values; floats to 1e-12 relative (module docstring)."""
    pd.testing.assert_frame_equal(table, expected, check_exact=False, rtol=1e-12, atol=1e-12)


def test_convergence_table_is_the_committed_sweeps_retabulated(tmp_path):
    out = tmp_path / "convergence_top.parquet"
    script("convergence_study.py", "--runs", os.path.join("data", "convergence_runs"),
           "--read-only", "--out", str(out))
    table = pd.read_parquet(out)
    assert_reproduced(table, committed("convergence_top.parquet"))
    assert len(table) >= 20 and set(table["seeds"]) == {16}


def test_paper_range_top_tables_are_the_committed_sweeps_retabulated(tmp_path):
    script("paper_range_study.py", "--top", "--read-only", "--data", str(tmp_path),
           "--figure", "")
    for name in ("paper_range_top_summary.parquet", "paper_range_top_stops.parquet"):
        assert_reproduced(pd.read_parquet(tmp_path / name), committed(name))


@pytest.mark.parametrize("name", ["paper_range_summary.parquet", "seeds_auto_grid_summary.parquet",
                                  "paper_range_top_summary.parquet"])
def test_committed_wilson_intervals_are_scipys_from_the_counts(name):
    """Every regime (and unsteady) probability's interval of a committed summary is
    ``scipy.stats.binomtest(k, seeds).proportion_ci(method="wilson")`` of its own count
    k = p × seeds, to 1e-12 (measured: 612 + 288 + 60 intervals, 2 of them off by one
    rounding, 1.1e-16)."""
    table = committed(name)
    probabilities = [c for c in table if c.startswith("p_") and f"{c}_low" in table]
    assert len(probabilities) >= 4
    for column in probabilities:
        hits = np.round(table[column] * table["seeds"]).astype(int)
        assert np.allclose(hits / table["seeds"], table[column], rtol=0, atol=1e-12)
        expected = np.array([wilson_interval(k, n) for k, n in zip(hits, table["seeds"])])
        assert np.allclose(expected[:, 0], table[f"{column}_low"], rtol=0, atol=1e-12)
        assert np.allclose(expected[:, 1], table[f"{column}_high"], rtol=0, atol=1e-12)
