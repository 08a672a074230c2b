"""Sweeps: classification, schema, failures, thread reproducibility, resume after SIGKILL."""
import json
import os
import signal
import subprocess
import sys
import time

import numba
import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import loopsim
from loopsim import storage, sweeps
from loopsim.cli import main
from loopsim.defaults import DEFAULT_AUTO_CHUNK_SIZE

DETERMINISTIC = [c for c in storage.RESULT_SCHEMA.names if c != "wall_s"]


def small_config(**kwargs):
    cases = sweeps.grid_cases([10.0, 60.0, 150.0], [30.0, 60.0], [4], seeds=1)
    args = dict(cases=cases, t_end=0.5, chunk_size=2)
    args.update(kwargs)
    return sweeps.SweepConfig(**args)


@pytest.mark.parametrize("theta0, theta1, ar0, ar1, ok, expected", [
    (30, 30.2, 1.0, 1.001, True, "stable"),
    (30, 30.2, 1.0, 1.3, True, "in-plane"),
    (30, 12.0, 1.0, 1.0, True, "3d"),
    (60, 58.5, 1.0, 2.0, True, "3d"),
    (30, 30.0, 1.0, 1.0, False, "failed"),
])
def test_classification(theta0, theta1, ar0, ar1, ok, expected):
    assert sweeps.classify(theta0, theta1, ar0, ar1, ok) == expected


def test_classification_thresholds_are_parameters():
    loose = sweeps.Thresholds(tilt_change_deg=5.0, shape_change=0.5)
    assert sweeps.classify(30, 27, 1.0, 1.3, True, loose) == "stable"


def test_resolved_flag_follows_both_thresholds():
    """A case is resolved only with a small transient length error AND a small spectral
    tail along the run (the failure modes of scripts/auto_study.py and of
    scripts/distribution_study.py --check resolution)."""
    t = sweeps.Thresholds()
    assert t.resolved(2e-7, 1e-8)
    assert not t.resolved(1.5e-4, 1e-8)  # 3D at n = 6: length error, tiny tail
    assert not t.resolved(2e-7, 1.2e-3)  # in-plane at n = 6: tail, no length error
    assert not t.resolved(1.7e-7, 3.2e-5)  # 3D at n = 16 (150, 45°): 5° off in tilt
    assert sweeps.Thresholds(resolved_length_error=1e-3).resolved(1.5e-4, 1e-8)


def test_sweep_marks_under_resolved_cases(tmp_path, capsys):
    """n = 6: a stable loop is resolved; g0 = 150, θ0 = 60° (3D) is not (its length
    error exceeds 1e-2 by t = 3), and the sweep's summary line says so."""
    out = tmp_path / "res"
    assert main(["sweep", "--n", "6", "--g0", "30,150", "--theta0", "30,60", "--t-end", "3", "--quiet",
                 "--out", str(out)]) == 0
    frame = loopsim.read_results(str(out))
    by_case = frame.set_index(["g0", "theta0_deg"])
    assert by_case.loc[(30.0, 30.0), "resolved"]
    assert not by_case.loc[(150.0, 60.0), "resolved"]
    assert by_case.loc[(150.0, 60.0), "length_error_max"] > 1e-2
    assert frame["resolved"].dtype == bool
    stdout = capsys.readouterr().out
    unresolved = int((~frame["resolved"]).sum())
    assert f"{unresolved} of 4 cases NOT resolved" in stdout
    assert "rerun them with a larger --n or --n auto" in stdout


def test_auto_sweep_names_n_max_for_unresolved_cases(tmp_path, capsys):
    """--n auto: a case still unresolved at --n-max (g0 = 150, θ0 = 60° at n = 8) is
    counted, and the hint names --n-max, not --n."""
    out = tmp_path / "auto"
    assert main(["sweep", "--g0", "150", "--theta0", "60", "--n", "auto", "--n-max", "8",
                 "--method", "radau5", "--t-end", "1", "--quiet", "--out", str(out)]) == 0
    (row,) = loopsim.read_results(str(out)).itertuples()
    assert row.n_used == 8 and not row.resolved
    chunk_size = loopsim.read_results(str(out)).attrs["loopsim"]["sweep_config"]["chunk_size"]
    assert chunk_size == DEFAULT_AUTO_CHUNK_SIZE  # --n auto: small chunks, little lost to SIGKILL
    assert "1 of 1 cases NOT resolved" in (stdout := capsys.readouterr().out)
    assert "a larger --n-max than 8" in stdout


def test_ensemble_is_the_sweeps_package_under_its_earlier_name():
    """``loopsim.ensemble`` (sweeps' module until they became the package
    ``loopsim.sweeps``) re-exports every public name of the package, unchanged, and warns
    that it is deprecated."""
    import importlib
    import sys

    sys.modules.pop("loopsim.ensemble", None)
    with pytest.warns(DeprecationWarning, match="loopsim.ensemble"):
        ensemble = importlib.import_module("loopsim.ensemble")

    assert sorted(ensemble.__all__) == sorted(sweeps.__all__)
    for name in sweeps.__all__:
        assert getattr(ensemble, name) is getattr(sweeps, name), name
    assert loopsim.sweep is sweeps.sweep


def test_parse_values():
    assert sweeps.parse_values("0:10:3", "--g0") == [0.0, 5.0, 10.0]
    assert sweeps.parse_values("6,8", "--n", integer=True) == [6, 8]
    for bad in ("1:2", "a,b", "1:2:0", "", "nan"):
        with pytest.raises(ValueError, match="--g0"):
            sweeps.parse_values(bad, "--g0")


def test_sweep_schema_round_trip_and_thread_reproducibility(tmp_path):
    config = small_config()
    one = sweeps.run_sweep(config, str(tmp_path / "one"), threads=1, quiet=True)
    two = sweeps.run_sweep(config, str(tmp_path / "two"), threads=2, quiet=True)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    assert list(one["case_id"]) == list(range(6))
    pd.testing.assert_frame_equal(one[DETERMINISTIC], two[DETERMINISTIC], check_exact=True)
    for path in (tmp_path / "one").glob("chunk-*.parquet"):
        assert pq.read_schema(path).remove_metadata() == storage.RESULT_SCHEMA
    meta = one.attrs["loopsim"]
    assert meta["sweep_config"]["t_end"] == 0.5 and meta["thresholds"]["tilt_change_deg"] == 1.0
    assert meta["loopsim_version"] == loopsim.__version__
    row = one.iloc[3]
    x = np.asarray(row["x_final"]).reshape(3, 2 * row["n"] + 1)
    assert abs(loopsim.diagnostics.aspect_ratio(x) - row["aspect_ratio"]) < 1e-12
    assert set(one["regime"]) <= set(sweeps.REGIMES)
    assert set(one["stop_reason"]) == {"t_end"}  # t_end = 0.5: too short to call steady
    # results equal a single API run of the same case
    single = loopsim.simulate(row["g0"], row["theta0_deg"], n=4, t_span=(0, 0.5), seed=0)
    np.testing.assert_array_equal(single.x_final.ravel(), x.ravel())


def test_batch_kernel_gives_the_same_bits_on_any_number_of_lanes():
    """The parallel batch kernel (``prange`` over lanes: Dask tasks, the Python API) and
    the serial one (one lane: each worker of the local work queue) agree bit for bit."""
    from loopsim import batch, integrators, models, shapes

    n, cases = 4, [(10.0, 30.0), (150.0, 60.0), (60.0, 85.0)]
    x0 = np.array([shapes.start_shape(theta, n, 1e-3, 0)[0].ravel() for _, theta in cases])
    options = integrators.step_options(1e-6, 1e-9, max_steps=200_000, constraint_tol=0.25)
    runs = [batch.integrate_batch(integrators.METHODS["rkf45"], models.local_sbt.make_operators(n),
                                  [(g0, 10.0) for g0, _ in cases], x0, 0.3, options,
                                  cost=[1.0, 3.0, 2.0], lanes=lanes)
            for lanes in (1, 2, 3)]
    assert np.all(runs[0][2] == 0) and np.all(np.isfinite(runs[0][0]))  # status ok
    for other in runs[1:]:
        for one, many in zip(runs[0], other):
            np.testing.assert_array_equal(one, many)


def test_failures_are_rows_and_the_sweep_goes_on(tmp_path):
    config = small_config(max_steps=50)  # stable cases need fewer; 3D ones run out
    frame = sweeps.run_sweep(config, str(tmp_path / "f"), threads=2, quiet=True)
    assert len(frame) == 6
    failed = frame[frame["status"] != "ok"]
    assert len(failed) > 0 and set(failed["status"]) == {"step budget exhausted"}
    assert set(failed["regime"]) == {"failed"}
    assert np.all(np.isfinite(frame["aspect_ratio"]))


def test_changed_configuration_is_refused(tmp_path):
    out = str(tmp_path / "s")
    sweeps.run_sweep(small_config(), out, quiet=True)
    with pytest.raises(ValueError, match="different sweep.*t_end"):
        sweeps.run_sweep(small_config(t_end=0.6), out, quiet=True)


@pytest.mark.parametrize("argv, word", [
    (["sweep", "--n", "6", "--g0", "1:2", "--theta0", "30", "--out", "X"], "--g0"),
    (["sweep", "--n", "6", "--g0", "10", "--theta0", "95", "--out", "X"], "theta0_deg"),
    (["sweep", "--n", "6", "--cases", "/nonexistent/cases.csv", "--out", "X"], "cases.csv"),
    (["sweep", "--n", "6", "--g0", "10", "--out", "X"], "--theta0"),
])
def test_sweep_bad_input(argv, word, tmp_path, capsys):
    argv = [str(tmp_path / a) if a == "X" else a for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and word in err and "Traceback" not in err


def test_cases_file(tmp_path):
    cases = tmp_path / "cases.csv"
    cases.write_text("g0,theta0_deg,seed\n20,45,3\n90,10,1\n")
    out = tmp_path / "c"
    assert main(["sweep", "--cases", str(cases), "--n", "4", "--t-end", "0.2", "--out", str(out),
                 "--quiet"]) == 0
    frame = loopsim.read_results(str(out))
    assert list(frame["g0"]) == [20.0, 90.0] and list(frame["seed"]) == [3, 1]


def test_resume_after_sigkill_equals_uninterrupted_run(tmp_path):
    args = ["sweep", "--g0", "20,80,160", "--theta0", "20,50,80", "--n", "4", "--t-end", "1.5",
            "--chunk-size", "1", "--threads", "1", "--quiet"]
    reference = tmp_path / "reference"
    assert main(args + ["--out", str(reference)]) == 0
    killed = tmp_path / "killed"
    command = [sys.executable, "-m", "loopsim"] + args + ["--out", str(killed)]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 120
    while len(list(killed.glob("chunk-*.parquet"))) < 3 and time.time() < deadline:
        time.sleep(0.05)
    os.kill(process.pid, signal.SIGKILL)
    process.wait()
    partial = len(list(killed.glob("chunk-*.parquet")))
    assert 3 <= partial < 9, "the kill should land mid-sweep"
    assert main(args + ["--out", str(killed)]) == 0
    resumed = loopsim.read_results(str(killed))
    expected = loopsim.read_results(str(reference))
    assert list(resumed["case_id"]) == list(range(9))  # none missing, none duplicated
    pd.testing.assert_frame_equal(resumed[DETERMINISTIC], expected[DETERMINISTIC], check_exact=True)
    assert not list(killed.glob(".tmp-*"))  # a chunk cut short by the kill is cleaned up


def test_snapshots_for_selected_cases(tmp_path):
    out = str(tmp_path / "snap")
    frame = sweeps.run_sweep(small_config(snapshots_for=[1, 4], snapshot_count=6), out,
                             quiet=True)
    snaps = loopsim.read_snapshots(out)
    assert sorted(snaps["case_id"].unique()) == [1, 4]
    for case_id, rows in snaps.groupby("case_id"):
        np.testing.assert_allclose(rows["t"], np.linspace(0, 0.5, 6))
        final = frame.set_index("case_id").loc[case_id]
        # the row and the trajectory come from the same run
        assert rows["aspect_ratio"].iloc[-1] == final["aspect_ratio"]
        assert list(rows["x"].iloc[-1]) == list(final["x_final"])
        assert len(rows["x"].iloc[-1]) == 3 * (2 * final["n"] + 1)
    assert loopsim.read_snapshots(str(tmp_path / "nothing")).empty


def test_snapshots_do_not_change_the_results(tmp_path):
    """Output times come from dense output, never from landing steps on them: a 3D case
    (g0 = 150, θ0 = 60°, t = 3) and a stable one give bit-identical rows with and
    without snapshots, work counters included (dense output's RHS evaluations are not
    counted in nfev; only the wall time differs)."""
    cases = sweeps.grid_cases([30.0, 150.0], [60.0], [6], seeds=1)
    plain = sweeps.run_sweep(sweeps.SweepConfig(cases=cases, t_end=3.0), str(tmp_path / "a"),
                             quiet=True)
    traced = sweeps.run_sweep(sweeps.SweepConfig(cases=cases, t_end=3.0, snapshots_for=[0, 1],
                                                 snapshot_count=31),
                              str(tmp_path / "b"), quiet=True)
    pd.testing.assert_frame_equal(plain[DETERMINISTIC], traced[DETERMINISTIC], check_exact=True)
    assert plain.loc[1, "regime"] == "3d"
    snaps = loopsim.read_snapshots(str(tmp_path / "b"))
    assert len(snaps) == 2 * 31


def test_auto_sweep_records_orders_and_methods_and_is_reproducible(tmp_path):
    """--n auto --method auto: rows carry n (the start), n_used, tail_max and method; the
    table is bit-identical on 1 and 2 threads and with snapshots (dense output, and the
    traced case climbs the same ladder)."""
    cases = sweeps.grid_cases([30.0, 150.0], [60.0], [6], seeds=1)
    config = dict(cases=cases, t_end=0.4, method="auto", n_auto=True, n_max=12)
    one = sweeps.run_sweep(sweeps.SweepConfig(**config), str(tmp_path / "a"), threads=1,
                           quiet=True)
    two = sweeps.run_sweep(sweeps.SweepConfig(**config), str(tmp_path / "b"), threads=2,
                           quiet=True)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    traced = sweeps.run_sweep(sweeps.SweepConfig(**config, snapshots_for=[1],
                                                 snapshot_count=5),
                              str(tmp_path / "c"), quiet=True)
    columns = DETERMINISTIC + ["n_used", "tail_max", "method"]
    pd.testing.assert_frame_equal(one[columns], two[columns], check_exact=True)
    pd.testing.assert_frame_equal(one[columns], traced[columns], check_exact=True)
    assert list(one["n"]) == [6, 6] and list(one["method"]) == ["radau5", "radau5"]
    assert one.loc[1, "n_used"] > 6  # the 3D case climbs
    for _, row in one.iterrows():
        assert len(row["x_final"]) == 3 * (2 * row["n_used"] + 1)
    snaps = loopsim.read_snapshots(str(tmp_path / "c"))
    assert {len(x) for x in snaps["x"]} == {3 * (2 * one.loc[1, "n_used"] + 1)}


def test_snapshots_for_unknown_case_is_refused(tmp_path, capsys):
    code = main(["sweep", "--n", "6", "--g0", "10", "--theta0", "30", "--snapshots-for", "5",
                 "--out", str(tmp_path / "s")])
    err = capsys.readouterr().err
    assert code == 2 and "case 5" in err


# ---- a sweep directory holds one sweep, whole ---------------------------------------

def _fast_sweep_argv(out, g0="10,60"):
    return ["sweep", "--g0", g0, "--theta0", "30", "--n", "4", "--t-end", "0.2",
            "--chunk-size", "1", "--quiet", "--out", str(out)]


def test_refused_sweep_leaves_live_temporaries_alone(tmp_path, capsys):
    """A second sweep refused for another configuration must not delete the temporary
    files of a sweep still writing (it used to remove every .tmp-*); a dead process's
    temporary is cleaned by the next run of the same sweep."""
    import socket
    out = tmp_path / "s"
    assert main(_fast_sweep_argv(out)) == 0
    host = socket.gethostname()
    live = out / f".tmp-{host}-{os.getpid()}-abc.parquet"  # this process: alive
    live.write_bytes(b"partial")
    child = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True, check=True)
    dead = out / f".tmp-{host}-{int(child.stdout)}-abc.parquet"
    dead.write_bytes(b"partial")
    assert main(_fast_sweep_argv(out, g0="20,70")) == 2  # refused: another sweep
    assert live.exists() and dead.exists()
    assert main(_fast_sweep_argv(out)) == 0  # the same sweep again: resumes, cleans
    assert live.exists() and not dead.exists()


def test_foreign_and_duplicate_chunks_are_refused(tmp_path, capsys):
    """Rows of another sweep never pass for this one's, and a case is never read twice."""
    out = tmp_path / "s"
    assert main(_fast_sweep_argv(out)) == 0
    frame = loopsim.read_results(str(out))
    assert list(frame["case_id"]) == [0, 1]
    first, second = sorted(out.glob("chunk-*.parquet"))
    # a lost sidecar, then a different sweep into the same directory: refused
    (out / "_sweep.json").unlink()
    with pytest.raises(ValueError, match="no _sweep.json"):
        loopsim.read_results(str(out))
    assert main(_fast_sweep_argv(out, g0="20,70")) == 2
    assert "belongs to a different sweep" in capsys.readouterr().err
    assert not (out / "_sweep.json").exists()
    assert main(_fast_sweep_argv(out)) == 0  # the same sweep restores it, computes nothing
    # a stray copy is ignored with a warning (no duplicate rows)
    copy = out / (second.stem + " (copy).parquet")
    copy.write_bytes(second.read_bytes())
    with pytest.warns(UserWarning, match="stray copy"):
        frame = loopsim.read_results(str(out))
    assert list(frame["case_id"]) == [0, 1]
    # a copy under another valid name: its rows are not the cases its name says
    copy.rename(out / "chunk-0000000-0000002.parquet")
    with pytest.raises(ValueError, match="other cases than its name says"):
        loopsim.read_results(str(out))
    assert main(_fast_sweep_argv(out)) == 2
    assert "other cases than its name says" in capsys.readouterr().err
    assert first.exists() and second.exists()  # nothing removed on the strength of a name


@pytest.mark.parametrize("content, words", [
    ("g0,theta0_deg,n\n60,30,6.5\n", ["row 0", "column n", "integer", "6.5"]),
    ("g0,theta0_deg\n60,30\nten,30\n", ["row 1", "column g0", "'ten'"]),
])
def test_cases_file_cells_are_checked(tmp_path, capsys, content, words):
    """n = 6.5 is refused (it used to run n = 6), and a bad cell names row and column."""
    path = tmp_path / "cases.csv"
    path.write_text(content)
    assert main(["sweep", "--n", "6", "--cases", str(path), "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and all(word in err for word in words), err
    assert not (tmp_path / "s").exists()


def test_too_many_threads_refused_before_the_directory_is_made(tmp_path, capsys):
    out = tmp_path / "s"
    assert main(["sweep", "--n", "6", "--g0", "60", "--theta0", "30", "--threads", "1000",
                 "--out", str(out)]) == 2
    assert "--threads" in capsys.readouterr().err and not out.exists()


def test_cases_file_sets_method_rtol_and_t_end_per_row(tmp_path, capsys):
    """Cells of the optional columns method, rtol and t_end override the sweep's options
    for their row only; the row records them, and it equals a single run with them."""
    path = tmp_path / "cases.csv"
    path.write_text("g0,theta0_deg,n,method,rtol,t_end\n60,30,4,radau5,1e-8,0.3\n"
                    "150,60,4,,,\n")
    out = tmp_path / "per_row"
    assert main(["sweep", "--n", "6", "--cases", str(path), "--t-end", "0.5", "--quiet",
                 "--out", str(out)]) == 0
    frame = loopsim.read_results(str(out))
    first, second = frame.iloc[0], frame.iloc[1]
    assert (first["method"], first["rtol"], first["t_end"]) == ("radau5", 1e-8, 0.3)
    assert (second["method"], second["rtol"], second["t_end"]) == ("rkf45", 1e-6, 0.5)
    assert first["t_final"] == 0.3 and second["t_final"] == 0.5
    single = loopsim.simulate(60.0, 30.0, n=4, method="radau5", rtol=1e-8, t_span=(0, 0.3),
                              steady_tol=1e-6)
    np.testing.assert_array_equal(single.x_final.ravel(), first["x_final"])
    path.write_text("g0,theta0_deg,method\n60,30,euler\n")
    assert main(["sweep", "--n", "6", "--cases", str(path), "--out", str(tmp_path / "bad")]) == 2
    err = capsys.readouterr().err
    assert "row 0, column method" in err and "euler" in err


def test_local_backend_starts_the_costliest_pieces_first(tmp_path, monkeypatch):
    """Longest processing time first: with expected costs given, one worker takes the
    pieces in descending total weight (positions in order within a piece); the table is
    the one a sweep in position order writes."""
    from loopsim.sweeps import local

    config = sweeps.SweepConfig(cases=sweeps.grid_cases([10.0, 20.0, 30.0, 40.0], [30.0], [4],
                                                        seeds=1), t_end=0.1, chunk_size=1)
    started = []
    real = local.run_chunk

    def recording(config, part, threads):
        started.append(sweeps.chunk_case_ids(config, part))
        return real(config, part, threads)

    monkeypatch.setattr(local, "run_chunk", recording)
    weights = {0: 1.0, 1: 5.0, 2: 3.0, 3: 8.0}
    frame = sweeps.run_sweep(config, str(tmp_path / "w"), threads=1, quiet=True,
                             weights=weights)
    assert [ids[0] for ids in started] == [3, 1, 2, 0]
    plain = sweeps.run_sweep(config, str(tmp_path / "p"), threads=1, quiet=True,
                             weights={i: 1.0 for i in range(4)})
    columns = [c for c in frame.columns if c != "wall_s"]
    pd.testing.assert_frame_equal(frame[columns], plain[columns], check_exact=True)
