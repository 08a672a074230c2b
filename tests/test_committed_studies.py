"""The committed study tables are what their scripts compute from the committed sweeps:
retabulating ``data/convergence_runs`` and ``data/paper_range_runs`` (``--read-only``,
nothing run) reproduces ``data/convergence_top.parquet`` and
``data/paper_range_top_*.parquet`` exactly (the bootstrap is seeded)."""
import os
import subprocess
import sys

import pandas as pd

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
