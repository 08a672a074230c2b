"""One command at a time in a sweep directory (``sweeps.lock``): taken before any case runs,
a second start is refused at once with one line naming the directory and the holder's pid;
shards of one sweep that share no chunk run side by side; a dead holder never wedges the
directory.  Issue 54.4: two different sweeps started at once into one new ``--out`` both
ran every case, and the directory held one's ``_sweep.json`` and the other's chunks."""
import json
import os
import signal
import subprocess
import sys

import pytest

import loopsim
from loopsim import storage
from loopsim.cli import main
from loopsim.sweeps import lock

GRID = ["sweep", "--g0", "10,40", "--theta0", "30", "--n", "6", "--t-end", "0.05",
        "--no-twin", "--threads", "1", "--chunk-size", "1", "--quiet"]


def _fingerprint(argv):
    """The configuration fingerprint of the sweep command ``argv``."""
    from loopsim.cli import build_parser, sweep

    config, _ = sweep.configuration(build_parser().parse_args(argv))
    return storage.config_fingerprint(json.loads(json.dumps(config.as_dict())))


def _one_line(capsys):
    err = capsys.readouterr().err
    assert err.startswith("loopsim: error:") and len(err.splitlines()) == 1, err
    return err


@pytest.mark.parametrize("other", [["--t-end", "0.06"], []], ids=["another sweep", "same sweep"])
def test_a_second_start_is_refused_while_the_directory_is_held(tmp_path, capsys, other):
    """The directory is held (here by this process, as a running sweep holds it): a start of
    another sweep, or of the same one again, is refused before it writes anything."""
    out = str(tmp_path / "s")
    os.mkdir(out)
    with lock.acquire(out, lock.holder(_fingerprint(GRID + ["--out", out])), ["first"]):
        assert main(GRID + other + ["--out", out]) == 2
        err = _one_line(capsys)
        assert repr(out) in err and f"pid {os.getpid()}" in err
        assert ("another sweep" if other else "this same sweep") in err
        assert not os.path.exists(os.path.join(out, storage.SWEEP_FILE))
        assert not storage.chunk_files(out)
    assert main(GRID + other + ["--out", out]) == 0  # released: it runs
    assert not [n for n in os.listdir(out) if n.startswith(lock.HOLDER_PREFIX)]


def test_shards_of_one_sweep_run_side_by_side_but_not_twice(tmp_path, capsys):
    out = str(tmp_path / "s")
    os.mkdir(out)
    argv = GRID + ["--out", out]
    with lock.acquire(out, lock.holder(_fingerprint(argv), shard=(0, 2)), ["shard 0"]):
        assert main(argv + ["--shard", "1/2"]) == 0  # no chunk in common
        capsys.readouterr()
        for clash in (["--shard", "0/2"], ["--shard", "2/4"], []):  # chunk 0 in common
            assert main(argv + clash) == 2, clash
            assert "this same sweep" in _one_line(capsys)
    assert main(argv) == 0
    assert len(loopsim.read_results(out)) == 2


def test_shards_overlap_exactly_when_they_share_a_chunk():
    for first, second in [((0, 2), (1, 2)), ((1, 4), (0, 2)), ((0, 3), (1, 6))]:
        assert not lock.shards_overlap(first, second)
        chunks = [k for k in range(60) if k % first[1] == first[0] and k % second[1] == second[0]]
        assert chunks == []
    for first, second in [((0, 2), (2, 4)), ((1, 3), (3, 4)), (None, (0, 5))]:
        assert lock.shards_overlap(first, second)


def test_a_rerun_of_failed_cases_waits_for_no_one(tmp_path, capsys):
    """A rerun rewrites result files: refused while a sweep holds the directory, and a
    sweep is refused while a rerun holds it."""
    out = str(tmp_path / "s")
    assert main(GRID + ["--out", out]) == 0
    with lock.acquire(out, lock.holder(_fingerprint(GRID + ["--out", out])), ["sweep"]):
        assert main(["sweep", "--rerun-failed", out, "--rtol", "1e-5", "--quiet"]) == 2
        assert "is in use by a sweep" in _one_line(capsys)
    with lock.acquire(out, lock.holder(None, exclusive=True), ["rerun"]):
        assert main(GRID + ["--out", out]) == 2
        assert "a rerun of its failed cases" in _one_line(capsys)


def test_a_seeds_auto_directory_is_held_too(tmp_path, capsys):
    out = str(tmp_path / "a")
    os.mkdir(out)
    auto = GRID + ["--seeds", "auto", "--min-seeds", "2", "--max-seeds", "2", "--out", out]
    with lock.acquire(out, lock.holder("another"), ["another --seeds auto sweep"]):
        assert main(auto) == 2
        assert "another sweep" in _one_line(capsys)
        assert not os.path.exists(os.path.join(out, storage.SEEDS_FILE))
    assert main(auto) == 0


def test_a_dead_holder_does_not_wedge_the_directory(tmp_path):
    """A holder killed outright (SIGKILL: no clean-up) leaves its file; the kernel released
    its flock, so the next start takes the directory and removes the stale file."""
    out = str(tmp_path / "s")
    os.mkdir(out)
    code = ("import sys, time\nfrom loopsim.sweeps import lock\n"
            f"lock.acquire({out!r}, lock.holder('x'), ['holder'])\n"
            "print('held', flush=True)\ntime.sleep(600)\n")
    process = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert process.stdout.readline().strip() == "held"
    os.kill(process.pid, signal.SIGKILL)
    process.wait()
    stale = [n for n in os.listdir(out) if n.startswith(lock.HOLDER_PREFIX)]
    assert len(stale) == 1 and f".{process.pid}." in stale[0]
    assert main(GRID + ["--out", out]) == 0
    assert not [n for n in os.listdir(out) if n.startswith(lock.HOLDER_PREFIX)]


def test_two_different_sweeps_started_at_once_into_a_new_directory(tmp_path):
    """Real processes, started together: exactly one runs, the other is refused at once
    with one line naming the holder; the directory is the winner's, whole."""
    out = str(tmp_path / "new")
    # 12 cases, 3-5 s of work: the winner still runs when the other has loaded (2-3 s)
    base = [sys.executable, "-m", "loopsim", "sweep", "--g0", "10,60,120,200", "--theta0",
            "30,60,80", "--n", "6", "--t-end", "10", "--no-twin", "--threads", "1",
            "--chunk-size", "1", "--quiet", "--out", out]
    processes = [subprocess.Popen(base + extra, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                  text=True) for extra in ([], ["--rtol", "1e-5"])]
    results = [p.communicate(timeout=300) + (p.returncode,) for p in processes]
    statuses = sorted(r[2] for r in results)
    assert statuses == [0, 2], results
    loser = next(r for r in results if r[2] == 2)
    assert loser[1].startswith(f"loopsim: error: {out!r} is in use by another sweep (pid ")
    winner = processes[[r[2] for r in results].index(0)]
    assert f"pid {winner.pid} " in loser[1]
    frame = loopsim.read_results(out)
    assert len(frame) == 12 and frame["rtol"].nunique() == 1
    stored = storage.read_sweep_file(out)
    assert stored["config"]["rtol"] == frame["rtol"].iloc[0]


def test_holder_file_names_are_skipped_by_dataset_readers(tmp_path):
    """A holder file in the directory (a sweep running) does not disturb
    ``pandas.read_parquet(DIR)``."""
    import pandas as pd

    out = str(tmp_path / "s")
    assert main(GRID + ["--out", out]) == 0
    with lock.acquire(out, lock.holder("x"), ["x"]):
        assert len(pd.read_parquet(out)) == 2
        assert len(loopsim.read_results(out)) == 2

