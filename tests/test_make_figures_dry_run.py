"""``scripts/make_figures.py --dry-run`` prints the commands it would run and writes
nothing (it once wrote the cases files of the resolved reference into RUNS/fig)."""
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def test_dry_run_prints_the_commands_and_writes_nothing(tmp_path):
    runs = tmp_path / "runs"
    done = subprocess.run(
        [sys.executable, os.path.join(ROOT, "scripts", "make_figures.py"), "--dry-run",
         "--runs", str(runs), "--only", "fig7_q_tilt"],
        cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "resolved_cases.csv" in done.stdout  # the command that would read it is printed
    assert not runs.exists() and os.listdir(tmp_path) == []
