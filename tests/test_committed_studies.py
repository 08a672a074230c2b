"""The committed study tables are what their scripts compute from the committed sweeps:
retabulating ``data/convergence_runs`` and ``data/paper_range_runs`` (``--read-only``,
nothing run) reproduces ``data/convergence_top.parquet`` and
``data/paper_range_top_*.parquet`` exactly (the bootstrap is seeded)."""
import os
import shutil
import subprocess
import sys

import pandas as pd
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def script(name, *args):
    done = subprocess.run([sys.executable, os.path.join("scripts", name), *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]


def committed(name):
    return pd.read_parquet(os.path.join(ROOT, "data", name))


def test_convergence_table_is_the_committed_sweeps_retabulated(tmp_path):
    out = tmp_path / "convergence_top.parquet"
    script("convergence_study.py", "--runs", os.path.join("data", "convergence_runs"),
           "--read-only", "--out", str(out))
    table = pd.read_parquet(out)
    pd.testing.assert_frame_equal(table, committed("convergence_top.parquet"))
    assert len(table) >= 20 and set(table["seeds"]) == {16}


def test_paper_range_top_tables_are_the_committed_sweeps_retabulated(tmp_path):
    script("paper_range_study.py", "--top", "--read-only", "--data", str(tmp_path),
           "--figure", "")
    for name in ("paper_range_top_summary.parquet", "paper_range_top_stops.parquet"):
        pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / name), committed(name))


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
