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
import shutil
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


CONVERGENCE = os.path.join(ROOT, "scripts", "convergence_study.py")


def _convergence(*args, cwd=ROOT):
    return subprocess.run([sys.executable, CONVERGENCE, *args], cwd=cwd, capture_output=True,
                          text=True, timeout=300)


def _one_line_error(done, words):
    err = done.stderr.strip().splitlines()
    assert done.returncode == 2, done.stdout[-2000:] + done.stderr[-2000:]
    assert len(err) == 1 and words in err[0] and "Traceback" not in done.stderr, done.stderr


def test_a_partial_convergence_run_never_shrinks_its_table(tmp_path):
    """Issue 54.2: --read-only --runs R with some of the sweeps finished in R rewrote the
    table at --out (the committed data/convergence_top.parquet: 31 rows) with fewer rows."""
    runs, out = tmp_path / "R", tmp_path / "convergence_top.parquet"
    shutil.copytree(os.path.join(ROOT, "data", "convergence_runs", "default_t60"),
                    runs / "default_t60")
    shutil.copy(os.path.join(ROOT, "data", "convergence_top.parquet"), out)
    before = out.read_bytes()
    done = _convergence("--read-only", "--runs", str(runs), "--out", str(out))
    _one_line_error(done, "of the 31 rows")
    assert out.read_bytes() == before
    elsewhere = tmp_path / "partial.parquet"  # the advice works
    assert _convergence("--read-only", "--runs", str(runs), "--out",
                        str(elsewhere)).returncode == 0
    assert len(pd.read_parquet(elsewhere)) == 1


@pytest.mark.parametrize("args, words", [
    (["--loopsim", "/nonexistent/loopsim"], "'/nonexistent/loopsim' is not an executable"),
    (["--read-only", "--out", "/proc/x.parquet"], "takes no files"),
    (["--read-only", "--out", "DIR"], "is a directory")])
def test_convergence_study_checks_its_places_before_any_work(tmp_path, args, words):
    """Issue 54.8: a missing --loopsim, an --out under /proc and an --out that is a
    directory ended in tracebacks, the last two after the whole table was computed."""
    runs = tmp_path / "R"
    shutil.copytree(os.path.join(ROOT, "data", "convergence_runs", "default_t60"),
                    runs / "default_t60")
    args = [str(tmp_path) if a == "DIR" else a for a in args]
    out = [] if "--out" in args else ["--out", str(tmp_path / "t.parquet")]
    done = _convergence("--runs", str(runs), *args, *out)
    _one_line_error(done, words)
    assert done.stdout == ""  # nothing run, nothing read
    assert sorted(os.listdir(runs)) == ["default_t60"] and not (tmp_path / "t.parquet").exists()
