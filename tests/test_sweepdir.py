"""Sweep directories as Parquet datasets; shards, chunk-size changes, Dask, signals, exit
codes and reruns of failed cases (issue 13)."""
import io as stdio
import json
import os
import signal
import subprocess
import sys
import threading
import time

import pandas as pd
import pyarrow.dataset as ds
import pyarrow.parquet as pq
import pytest

import loopsim
from loopsim import storage, sweeps
from loopsim.cli import main

DETERMINISTIC = [c for c in storage.RESULT_SCHEMA.names if c != "wall_s"]


def config(**kwargs):
    cases = sweeps.grid_cases([10.0, 60.0, 150.0], [30.0, 60.0], [4], seeds=1)
    args = dict(cases=cases, t_end=0.3, chunk_size=2)
    args.update(kwargs)
    return sweeps.SweepConfig(**args)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The 6-case sweep run whole on this machine's threads, with snapshots of case 4."""
    out = str(tmp_path_factory.mktemp("reference") / "s")
    frame = sweeps.run_sweep(config(snapshots_for=[4], snapshot_count=3), out, threads=2,
                             quiet=True)
    return out, frame


def same_rows(a, b):
    pd.testing.assert_frame_equal(a[DETERMINISTIC].reset_index(drop=True),
                                  b[DETERMINISTIC].reset_index(drop=True), check_exact=True)


def test_dataset_readers_return_exactly_the_rows(reference):
    out, frame = reference
    assert sorted(os.listdir(out)) == ["_snapshots", "_sweep.json"] + sorted(
        storage.CHUNK_PATTERN.format(s, e) for s, e in [(0, 2), (2, 4), (4, 6)])
    by_id = lambda f: f.sort_values("case_id").reset_index(drop=True)  # noqa: E731
    same_rows(by_id(pd.read_parquet(out)), frame)
    same_rows(by_id(ds.dataset(out).to_table().to_pandas()), frame)
    same_rows(by_id(pq.read_table(out).to_pandas()), frame)
    duckdb = pytest.importorskip("duckdb")
    rows = duckdb.sql(f"SELECT * FROM read_parquet('{out}/*.parquet') ORDER BY case_id").df()
    assert list(rows.columns) == list(frame.columns) and list(rows["case_id"]) == list(range(6))
    pd.testing.assert_series_equal(rows["theta_final_deg"], frame["theta_final_deg"])
    assert len(loopsim.read_snapshots(out)) == 3  # snapshots still read, from _snapshots/


def test_configuration_stored_once_fingerprint_in_each_file(reference):
    out, frame = reference
    with open(os.path.join(out, "_sweep.json")) as handle:
        stored = json.load(handle)
    assert stored["config"]["t_end"] == 0.3 and len(stored["config"]["cases"]) == 6
    for (start, stop), path in storage.chunk_files(out).items():
        meta = storage.read_metadata(path)
        assert "sweep_config" not in meta and "command_line" not in meta
        assert meta["sweep_fingerprint"] == stored["fingerprint"] == storage.config_fingerprint(
            stored["config"])
        assert meta["positions"] == [start, stop]
    assert frame.attrs["loopsim"]["sweep_config"]["t_end"] == 0.3
    assert storage.config_fingerprint(dict(stored["config"], chunk_size=7)) == stored["fingerprint"]
    assert storage.config_fingerprint(dict(stored["config"], t_end=0.4)) != stored["fingerprint"]


def test_the_tables_metadata_describes_the_whole_table(reference):
    """attrs hold what every file shares, the number of files and the range of creation
    times, never one file's positions, content hash or creation time."""
    out, frame = reference
    meta = frame.attrs["loopsim"]
    files = [storage.read_metadata(path) for path in storage.chunk_files(out).values()]
    assert meta["files"] == len(files) == 3
    assert not {"positions", storage.CONTENT_KEY, "created_utc"} & set(meta)
    created = sorted(m["created_utc"] for m in files)
    assert (meta["created_utc_first"], meta["created_utc_last"]) == (created[0], created[-1])
    assert meta["sweep_fingerprint"] == files[0]["sweep_fingerprint"]
    assert meta["loopsim_version"] == loopsim.__version__
    # a value the files disagree on is listed, not taken from the first file
    mixed = storage.table_metadata([dict(files[0], loopsim_version="0.1"), files[1]])
    assert mixed["loopsim_version"] == sorted(["0.1", files[1]["loopsim_version"]])


def test_files_follow_the_umask(tmp_path):
    previous = os.umask(0o002)
    try:
        sweeps.run_sweep(config(cases=config().cases[:2]), str(tmp_path / "s"), quiet=True)
    finally:
        os.umask(previous)
    for path in (tmp_path / "s").iterdir():
        if path.is_file():
            assert path.stat().st_mode & 0o777 == 0o664, path


def test_old_layout_is_refused_in_one_line(tmp_path, capsys):
    out = tmp_path / "old"
    out.mkdir()
    (out / "sweep.json").write_text("{}")
    (out / "chunk-00000.parquet").write_bytes(b"PAR1")
    with pytest.raises(ValueError, match=r"layout-1 .*loopsim 0\.2\.0 and earlier releases.*new --out"):
        loopsim.read_results(str(out))
    assert main(["sweep", "--n", "6", "--g0", "10", "--theta0", "30", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "new --out" in err


def test_shards_together_equal_the_whole_sweep(tmp_path, reference):
    out = str(tmp_path / "s")
    for i in range(3):
        sweeps.run_sweep(config(snapshots_for=[4], snapshot_count=3), out, threads=1,
                         quiet=True, shard=(i, 3))
    same_rows(loopsim.read_results(out), reference[1])
    pd.testing.assert_frame_equal(loopsim.read_snapshots(out), loopsim.read_snapshots(reference[0]))


def test_changed_chunk_size_resumes_without_loss_or_duplicates(tmp_path, reference):
    out = str(tmp_path / "s")
    traced = dict(snapshots_for=[4], snapshot_count=3)  # as the reference
    sweeps.run_sweep(config(chunk_size=2, **traced), out, quiet=True, shard=(0, 2))  # chunks 0, 2
    assert sorted(storage.chunk_files(out)) == [(0, 2), (4, 6)]
    frame = sweeps.run_sweep(config(chunk_size=3, **traced), out, quiet=True)  # [0, 3), [3, 6)
    assert sorted(storage.chunk_files(out)) == [(0, 2), (2, 3), (3, 4), (4, 6)]
    same_rows(frame, reference[1])


def test_pieces_never_repeat_a_position():
    cfg = config(cases=config().cases * 4, chunk_size=5)  # 24 cases
    covered = {(0, 3): None, (3, 7): None, (12, 13): None}
    pieces = sweeps.pending_pieces(cfg, covered)
    positions = [p for piece in pieces for p in piece] + [0, 1, 2, 3, 4, 5, 6, 12]
    assert sorted(positions) == list(range(24))
    assert sorted(sweeps.case_order(24)) == list(range(24))


def test_dask_local_cluster_equals_prange(tmp_path, reference):
    pytest.importorskip("distributed")
    out = str(tmp_path / "s")
    frame = sweeps.run_sweep(config(snapshots_for=[4], snapshot_count=3), out, threads=1,
                             quiet=True, local_cluster=True, workers=2)
    same_rows(frame, reference[1])
    pd.testing.assert_frame_equal(loopsim.read_snapshots(out), loopsim.read_snapshots(reference[0]))


def test_progress_goes_to_a_log_file_with_a_cost_weighted_eta(monkeypatch):
    clock = iter([0.0, 10.0, 20.0, 20.0, 25.0, 25.0, 25.0])
    monkeypatch.setattr(time, "perf_counter", lambda: next(clock))
    stream = stdio.StringIO()  # not a TTY: whole lines, every `interval` seconds
    weights = {0: 1.0, 1: 1.0, 2: 8.0}
    progress = sweeps.Progress(weights, [], stream=stream, interval=15.0)
    progress.update([0], 0)  # t = 10: before the interval, no line
    progress.update([1], 1)  # t = 20: a line; the last case weighs 8 of 10: ETA 20 s x 8 / 2
    progress.close()
    lines = stream.getvalue().splitlines()
    assert len(lines) == 2 and "\r" not in stream.getvalue()
    assert lines[0].startswith("cases 2/3") and "failures 1" in lines[0]
    assert "elapsed 0h00m20s ETA 0h01m20s" in lines[0], lines[0]
    stable, loop_3d = dict(g0=10.0, theta0_deg=30.0, n=4), dict(g0=150.0, theta0_deg=60.0, n=4)
    assert sweeps.case_weight(loop_3d) == 3 * sweeps.case_weight(stable)
    q0 = 150.0 * 3**0.5 / 2 / 3  # --n auto: (q0 / 11)^4 times a stable case
    assert sweeps.case_weight(loop_3d, n_auto=True) == pytest.approx(
        (q0 / 11.0) ** 4 * sweeps.case_weight(stable, n_auto=True), rel=1e-12)
    early = stdio.StringIO()  # one cheap case of a costly run: no ETA extrapolated from it
    clock = iter([0.0, 10.0, 10.0, 10.0, 20.0, 20.0, 20.0, 20.0])
    progress = sweeps.Progress({0: 1.0, 1: 1000.0}, [], stream=early, interval=0.0)
    progress.update([0], 0)
    assert "ETA ? " in early.getvalue(), early.getvalue()
    progress.update([1], 0)
    assert "ETA 0h00m00s" in early.getvalue().splitlines()[-1]
    quiet = stdio.StringIO()
    progress = sweeps.Progress(weights, [], quiet=True, stream=quiet, interval=0.0)
    progress.update([0], 0)
    progress.close()
    assert quiet.getvalue() == ""


def _sweep_command(out, *extra):
    return [sys.executable, "-m", "loopsim", "sweep", "--g0", "10,300", "--theta0", "30,80",
            "--n", "8", "--t-end", "40", "--threads", "1", "--chunk-size",
            "4", "--out", str(out), *extra]


@pytest.mark.parametrize("signum, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_signal_stops_promptly_keeps_finished_cases(tmp_path, signum, status):
    """Case order at 4 cases: positions 0..3 are cases 0, 3, 2, 1 (g0 = 10 first: cheap);
    one case per kernel call (--threads 1).  The signal lands while a 3D case (g0 = 300,
    t = 40, n = 8: much longer than the bound below) runs: the sweep stops at once, writes
    the finished case, says how to resume, exits 128 + signum."""
    out = tmp_path / "s"
    process = subprocess.Popen(_sweep_command(out, "--progress-every", "0.001"),
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = process.stderr.readline()  # a log-file progress line once case 0 is done
    assert first.startswith("cases 1/4"), first + process.communicate()[1]
    time.sleep(1.0)  # inside the 3D case (g0 = 300)
    sent = time.monotonic()
    process.send_signal(signum)
    stdout, rest = process.communicate(timeout=60)
    waited = time.monotonic() - sent
    stderr = first + rest
    assert process.returncode == status, stderr
    assert waited < 5.0, f"stopped {waited:.1f} s after the signal"
    assert "Traceback" not in stderr
    assert "re-run the same command to resume" in stderr.splitlines()[-1]
    frame = loopsim.read_results(str(out))
    assert 0 in set(frame["case_id"]) and len(frame) < 4
    assert not list(out.glob(".tmp-*"))


def test_exit_status_and_rerun_of_failed_cases(tmp_path, capsys):
    """A step budget of 150 fails rkf45 on a stable loop to t = 3 but not radau5 (about
    60 steps), nor a flat unperturbed circle (steady after about 90): the failed case is
    rerun alone, first with another rtol (still failing: exit status 1), then with
    radau5; every attempt's rows are kept in _reruns/, the dataset holds each case once,
    and a further call finds nothing to rerun."""
    out = tmp_path / "s"
    cases = sweeps.grid_cases([10.0, 60.0], [30.0], [4], seeds=1)
    cases[0].update(theta0_deg=0.0, perturbation=0.0)  # a flat circle: steady at t = 1
    first = sweeps.run_sweep(sweeps.SweepConfig(cases=cases, t_end=3.0, max_steps=150,
                                                chunk_size=1), str(out), quiet=True)
    assert list(first["status"]) == ["ok", "step budget exhausted"]
    assert main(["sweep", "--rerun-failed", str(out), "--t-end", "4"]) == 2  # not a rerun option
    assert main(["sweep", "--rerun-failed", str(out), "--rtol", "1e-5", "--quiet"]) == 1
    assert "--rerun-failed" in capsys.readouterr().err
    assert main(["sweep", "--rerun-failed", str(out), "--method", "radau5", "--quiet"]) == 0
    second = loopsim.read_results(str(out))
    assert list(second["status"]) == ["ok", "ok"]
    assert second.loc[1, "rtol"] == 1e-6 and second.loc[0, "rtol"] == 1e-6
    same_rows(second.iloc[:1], first.iloc[:1])
    assert [r["case_ids"] for r in second.attrs["loopsim"]["reruns"]] == [[1], [1]]
    for attempt, rtol in ((1, 1e-6), (2, 1e-5)):  # rows each attempt replaced
        kept = pd.concat(pd.read_parquet(p) for p in (out / "_reruns" / str(attempt)
                                                       / "replaced").iterdir())
        assert list(kept["case_id"]) == [1] and list(kept["rtol"]) == [rtol]
        assert list(kept["status"]) == ["step budget exhausted"]
    assert len(pd.read_parquet(out)) == 2
    assert main(["sweep", "--rerun-failed", str(out), "--rtol", "1e-6", "--quiet"]) == 0
    assert "reran 0 failed" in capsys.readouterr().out


def test_resume_after_sigint_equals_uninterrupted_run(tmp_path):
    """SIGINT mid-chunk: the finished cases of the running chunk are written as a shorter
    piece; the resume computes the rest, nothing twice."""
    args = ["sweep", "--g0", "20,80,160", "--theta0", "20,50,80", "--n", "4", "--t-end", "1.5",
            "--chunk-size", "9", "--threads", "1", "--progress-every", "0.001"]
    reference = tmp_path / "reference"
    assert main(args + ["--quiet", "--out", str(reference)]) == 0
    out = tmp_path / "s"
    process = subprocess.Popen([sys.executable, "-m", "loopsim"] + args + ["--out", str(out)],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    for _ in range(2):
        line = process.stderr.readline()
    assert line.startswith("cases 2/9"), line
    process.send_signal(signal.SIGINT)
    rest = process.communicate(timeout=60)[1]
    assert process.returncode == 130, rest
    (piece,) = storage.chunk_files(str(out))  # one chunk of 9, cut short
    assert piece[0] == 0 and 2 <= piece[1] < 9
    assert main(args + ["--quiet", "--out", str(out)]) == 0
    assert sorted(storage.chunk_files(str(out))) == [piece, (piece[1], 9)]
    same_rows(loopsim.read_results(str(out)), loopsim.read_results(str(reference)))


def _hold_position(monkeypatch, held, auto_release=True):
    """run_chunk, except that the task holding position ``held`` waits until every other
    task has finished (or 60 s; without ``auto_release``, until the caller sets the
    event).  Returns (finish order of positions, release event)."""
    real, finished, release = sweeps.run_chunk, [], threading.Event()

    def run_chunk(config, chunk, threads):
        if held in chunk:
            release.wait(60)
        output = real(config, chunk, threads)
        finished.extend(chunk)
        if auto_release and len(finished) == len(config.cases) - 1 and held not in finished:
            release.set()
        return output

    monkeypatch.setattr(sweeps.local, "run_chunk", run_chunk)
    return finished, release


def test_free_workers_go_past_a_slow_case(tmp_path, reference, monkeypatch):
    """The local backend is a work queue: while one worker is held on position 0, the
    other computes all five remaining positions (with units of --threads positions and a
    barrier per unit, it would wait for position 0 first).  The table is unchanged.  The
    held worker waits in Python; the kernels let two workers compute at once because
    they release the GIL (nogil), checked on the kernel the workers call (one-thread
    batches call ``integrate`` case by case)."""
    from loopsim import integrators

    assert integrators.integrate.targetoptions.get("nogil") is True
    finished, release = _hold_position(monkeypatch, held=0)
    start = time.monotonic()
    frame = sweeps.run_sweep(config(snapshots_for=[4], snapshot_count=3), str(tmp_path / "q"),
                             threads=2, quiet=True)
    assert release.is_set() and time.monotonic() - start < 60
    # position 0 last, the other five past it (in the costliest-first order of their pieces)
    assert finished[-1] == 0 and sorted(finished[:-1]) == [1, 2, 3, 4, 5], finished
    same_rows(frame, reference[1])


def _interrupt_after(monkeypatch, cases):
    """SIGINT to this process, from the sweep's own thread, once ``cases`` cases are done."""
    real = sweeps.Progress.update

    def update(self, case_ids, failures, seconds=None):
        real(self, case_ids, failures, seconds)
        if self.done == cases:
            os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(sweeps.Progress, "update", update)


def _resume_computes(monkeypatch, out, expected):
    """Resume the sweep in ``out`` and check that it computes exactly ``expected``
    positions; returns the table."""
    monkeypatch.undo()
    computed, real = [], sweeps.run_chunk
    monkeypatch.setattr(sweeps.local, "run_chunk",
                        lambda c, chunk, t: computed.extend(chunk) or real(c, chunk, t))
    frame = sweeps.run_sweep(config(snapshots_for=[4], snapshot_count=3), out, threads=2,
                             quiet=True)
    assert sorted(computed) == sorted(expected)
    return frame


def test_stop_writes_finished_cases_past_a_running_one(tmp_path, reference, monkeypatch):
    """SIGINT once positions 1..5 are done while position 0 still runs: piece [0, 2) is
    written as [1, 2), the others whole; the resume computes position 0 only."""
    _, release = _hold_position(monkeypatch, held=0, auto_release=False)
    _interrupt_after(monkeypatch, 5)
    out = str(tmp_path / "q")
    with pytest.raises(sweeps.SweepInterrupted):
        sweeps.run_sweep(config(snapshots_for=[4], snapshot_count=3), out, threads=2,
                         quiet=True)
    release.set()  # the held worker goes on unseen, as a kernel would after a signal
    assert sorted(storage.chunk_files(out)) == [(1, 2), (2, 4), (4, 6)]
    frame = _resume_computes(monkeypatch, out, [0])
    assert sorted(storage.chunk_files(out)) == [(0, 1), (1, 2), (2, 4), (4, 6)]
    same_rows(frame, reference[1])
    assert len(loopsim.read_snapshots(out)) == 3


def test_worker_error_is_raised_after_finished_cases_are_written(tmp_path, reference,
                                                                monkeypatch):
    """An exception in a worker (not a failed case: those are rows) stops the sweep and
    is raised; the cases finished by then are written and the resume computes the rest,
    each once."""
    real = sweeps.run_chunk

    def run_chunk(config, chunk, threads):
        if 3 in chunk:
            raise RuntimeError("worker broke at position 3")
        return real(config, chunk, threads)

    monkeypatch.setattr(sweeps.local, "run_chunk", run_chunk)
    out = str(tmp_path / "e")
    with pytest.raises(RuntimeError, match="position 3"):
        sweeps.run_sweep(config(snapshots_for=[4], snapshot_count=3), out, threads=2,
                         quiet=True)
    written = [p for low, high in storage.chunk_files(out) for p in range(low, high)]
    assert 3 not in written and len(set(written)) == len(written)
    frame = _resume_computes(monkeypatch, out, sorted(set(range(6)) - set(written)))
    same_rows(frame, reference[1])


@pytest.mark.parametrize("argv, word", [
    (["--shard", "2/2"], "--shard"),
    (["--shard", "x"], "--shard"),
    (["--workers", "2"], "--workers needs --dask"),
    (["--dask", "--scheduler", "tcp://h:1"], "not both"),
    (["--progress-every", "0"], "--progress-every"),
])
def test_sweep_backend_options_checked_before_work(tmp_path, capsys, argv, word):
    out = tmp_path / "s"
    assert main(["sweep", "--n", "6", "--g0", "10", "--theta0", "30", "--out", str(out), *argv]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and word in err, err
    assert not (out / "_sweep.json").exists()


def test_dask_is_imported_only_when_used():
    code = ("import sys, loopsim.cli, loopsim.sweeps, loopsim.ensemble; "
            "print(any(m.split('.')[0] in ('dask', 'distributed') for m in sys.modules))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True)
    assert result.stdout.strip() == "False"


def test_compare_sweeps_lists_the_cases_that_moved(reference, tmp_path, monkeypatch, capsys):
    """scripts/compare_sweeps.py: cases whose terminal tilt moved by more than --tilt-tol
    are counted and written to --moved, largest move first; the others are not."""
    import runpy

    out, frame = reference
    script = runpy.run_path(os.path.join(os.path.dirname(os.path.dirname(__file__)),
                                         "scripts", "compare_sweeps.py"))
    other = frame.copy()
    other.loc[1, "theta_final_deg"] += 0.5
    other.loc[4, "theta_final_deg"] -= 2.0
    other.loc[4, "regime"] = "stable" if frame.loc[4, "regime"] != "stable" else "3d"
    result = script["compare"](frame, other, tilt_tol=0.1)
    assert result["moved"] == 2 and result["changed"] == 1
    moved = result["moved_cases"]
    assert list(moved["theta0_deg"]) == [frame.loc[4, "theta0_deg"], frame.loc[1, "theta0_deg"]]
    assert list(moved["g0"]) == [frame.loc[4, "g0"], frame.loc[1, "g0"]]
    assert moved["d_tilt"].tolist() == pytest.approx([2.0, 0.5])
    # end to end: a sweep compared with itself moves nothing, and the CSV holds no row
    csv = tmp_path / "moved.csv"
    monkeypatch.setattr(sys, "argv", ["compare_sweeps.py", out, out, "--tilt-tol", "0",
                                      "--moved", str(csv)])
    script["main"]()
    assert "0 cases change regime; 0 move" in capsys.readouterr().out
    assert len(pd.read_csv(csv)) == 0
    # ... and against the moved copy the CSV holds the two cases, largest move first
    monkeypatch.setattr(loopsim, "read_results", lambda path: frame if path == out else other)
    monkeypatch.setattr(sys, "argv", ["compare_sweeps.py", out, "other", "--tilt-tol", "0.1",
                                      "--moved", str(csv)])
    script["main"]()
    assert "1 cases change regime; 2 move" in capsys.readouterr().out
    written = pd.read_csv(csv)
    assert list(written["case_id_ref"]) == [frame.loc[4, "case_id"], frame.loc[1, "case_id"]]
    assert written["d_tilt"].tolist() == pytest.approx([2.0, 0.5])
