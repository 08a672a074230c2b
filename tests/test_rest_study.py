"""scripts/rest_study.py: its table from finished sweeps (here the convergence study's
t = 10 sweeps standing in for run-to-rest ones), its declared columns, and its refusal to
shrink a committed table."""
import os
import shutil
import subprocess
import sys

import pandas as pd
import pyarrow.parquet as pq
import pytest

from loopsim import columns

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "scripts", "rest_study.py")


def run_study(tmp_path, out):
    return subprocess.run([sys.executable, SCRIPT, "--read-only", "--runs", str(tmp_path / "runs"),
                           "--out", str(out), "--figures", str(tmp_path), "--window-n", "8"],
                          capture_output=True, text=True, cwd=ROOT)


@pytest.fixture
def runs(tmp_path):
    # the rtol 1e-3 sample of (350, 18 deg) stands in for a run to rest: the script
    # compares it with its t = 10 baseline, data/convergence_runs/jmid_t18 (the defaults)
    shutil.copytree(os.path.join(ROOT, "data", "convergence_runs", "jmid_rtol1e-3_t18"),
                    tmp_path / "runs" / "rest_t18_350")
    return tmp_path


def test_table_from_finished_sweeps(runs):
    out = runs / "rest.parquet"
    done = run_study(runs, out)
    assert done.returncode == 0, done.stderr
    table = pd.read_parquet(out)
    assert list(table.columns) == [c for c in columns.REST_STUDY_COLUMNS if c in table]
    fields = pq.read_schema(out)
    assert all(fields.field(c).metadata for c in table.columns)     # declared, with units
    row = table.iloc[0]
    frame = pd.read_parquet(runs / "runs" / "rest_t18_350")
    base = pd.read_parquet(os.path.join(ROOT, "data", "convergence_runs", "jmid_t18"))
    rested = frame[frame["stop_reason"] == "steady"]
    assert row["seeds"] == len(frame) == 16
    assert row["at_rest"] == len(rested) and row["moving_at_t_max"] == 16 - len(rested)
    assert row["rest_inside"] + row["rest_below"] + row["rest_outside"] == len(rested)
    # the regime shares and tilts are over the loops at rest; the differences are those
    # at rest minus the t = 10 sample's (every row of it)
    assert row["p_3d"] == pytest.approx((rested["regime"] == "3d").mean())
    assert row["tilt_median"] == pytest.approx(rested["theta_final_deg"].median())
    assert row["delta_p_3d"] == pytest.approx((rested["regime"] == "3d").mean()
                                              - (base["regime"] == "3d").mean())
    assert row["base_p_steady"] == pytest.approx((base["stop_reason"] == "steady").mean())
    assert row["delta_p_3d_low"] <= row["delta_p_3d"] <= row["delta_p_3d_high"]
    assert (runs / "rest_survival.png").stat().st_size > 0


def test_refuses_to_shrink_a_table(runs):
    out = runs / "rest.parquet"
    bigger = pd.DataFrame(dict(g0=[350.0, 325.7], theta0_deg=[18.0, 18.0]))
    bigger.to_parquet(out)
    done = run_study(runs, out)
    assert done.returncode == 2 and "holds 2 cells, this run only 1" in done.stderr
    assert len(pd.read_parquet(out)) == 2


def test_the_keys_a_write_would_drop(tmp_path):
    """The check every study script makes before it writes (storage.keys_a_write_would_drop)."""
    from loopsim import storage

    path = tmp_path / "t.parquet"
    cells = ("g0", "theta0_deg")
    assert storage.keys_a_write_would_drop(str(path), set(), cells) == (set(), set())
    pd.DataFrame(dict(g0=[350.0, 325.7142857142857], theta0_deg=[18.0, 18.0])).to_parquet(path)
    one = storage.study_keys(dict(g0=[350.0], theta0_deg=[18]), cells)
    held, dropped = storage.keys_a_write_would_drop(str(path), one, cells)
    assert len(held) == 2 and dropped == {(325.714285714, 18.0)}
    path.write_bytes(b"not parquet")
    with pytest.raises(ValueError, match="cannot be read"):
        storage.keys_a_write_would_drop(str(path), one, cells)


@pytest.mark.parametrize("bad", [["--window-n", "2"], ["--range-out", "FILE/range.parquet"],
                                 ["--figures", "FILE/figures"]])
def test_bad_input_is_one_line_and_writes_nothing(runs, bad):
    """Checked before any work: the study's table was written before a bad --range-out
    failed with a traceback."""
    blocker = runs / "FILE"
    blocker.write_text("")     # a file where a folder should be
    argv = {"--window-n": "8", "--range-out": str(runs / "range.parquet"),
            "--figures": str(runs / "figures")}
    argv[bad[0]] = bad[1].replace("FILE", str(blocker))
    done = subprocess.run([sys.executable, SCRIPT, "--read-only", "--runs", str(runs / "runs"),
                           "--out", str(runs / "rest.parquet"),
                           *[word for pair in argv.items() for word in pair]],
                          capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith("rest_study: error:") and len(done.stderr.splitlines()) == 1
    assert sorted(os.listdir(runs)) == ["FILE", "runs"]


def test_a_range_table_that_would_shrink_is_refused_before_anything_is_written(runs):
    """The review's case: the study's table and figures were written, then --range-out
    was refused."""
    shutil.copytree(os.path.join(ROOT, "data", "rest_runs", "range_rest_t36"),
                    runs / "runs" / "range_rest_t36")
    fuller = runs / "range.parquet"
    shutil.copy(os.path.join(ROOT, "data", "paper_range_rest_summary.parquet"), fuller)
    before = fuller.read_bytes()
    done = subprocess.run([sys.executable, SCRIPT, "--read-only", "--runs", str(runs / "runs"),
                           "--out", str(runs / "rest.parquet"), "--figures", str(runs / "figs"),
                           "--range-out", str(fuller), "--window-n", "8"],
                          capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 2 and "give another --range-out" in done.stderr, done.stderr
    assert sorted(os.listdir(runs)) == ["range.parquet", "runs"]
    assert fuller.read_bytes() == before
    same = subprocess.run([sys.executable, SCRIPT, "--read-only", "--runs", str(runs / "runs"),
                           "--out", str(fuller), "--range-out", str(fuller)],
                          capture_output=True, text=True, cwd=ROOT)
    assert same.returncode == 2 and "are one file" in same.stderr
