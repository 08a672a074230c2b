"""Whole trajectories through the API and the CLI."""
import json
import subprocess
import sys

import numpy as np
import pyarrow.parquet as pq
import pytest

import loopsim
from loopsim import api, diagnostics as D, storage, shapes
from loopsim.cli import main


@pytest.mark.parametrize("method", sorted(loopsim.integrators.METHODS))
def test_stiff_circle_translates_rigidly_for_ten_time_units(method):
    g0, theta_deg = 5.0, 50.0
    theta = np.radians(theta_deg)
    result = api.simulate(g0, theta_deg, n=6, perturbation=0.0, snapshots=3, method=method)
    assert result.success and result.t_final == 10.0
    u0 = -np.array([0.0, g0 * np.sin(2 * theta) / 6, g0 * (7 - np.cos(2 * theta)) / 6])
    expected = shapes.inclined_circle(6, theta)
    expected[:, 0] = u0 * 10.0
    np.testing.assert_allclose(result.x_final, expected, atol=1e-8)
    summary = result.summary()
    assert abs(summary["theta_final_deg"] - theta_deg) < 1e-6
    assert abs(summary["length_error"]) < 1e-10


def test_length_is_conserved_and_summary_is_complete():
    result = api.simulate(10.0, 30.0, n=6, snapshots=5)
    summary = result.summary()
    assert tuple(summary) == api.SUMMARY_FIELDS
    assert summary["status"] == "ok"
    assert max(abs(D.relative_length_error(x)) for x in result.x) < 1e-8
    assert abs(summary["q0"] - 10.0 * 0.5 / 3) < 1e-12
    assert summary["steps_accepted"] > 0 and summary["nfev"] >= 6 * summary["steps_accepted"]
    np.testing.assert_allclose(result.t, np.linspace(0, 10, 5))


def test_reproducible_from_inputs():
    a = api.simulate(60.0, 30.0, n=6, t_span=(0, 0.5), seed=7)
    b = api.simulate(60.0, 30.0, n=6, t_span=(0, 0.5), seed=7)
    np.testing.assert_array_equal(a.x, b.x)


def test_failure_is_a_status_not_an_exception():
    result = api.simulate(60.0, 30.0, n=6, t_span=(0, 1.0), max_steps=20)
    assert result.message == "step budget exhausted" and not result.success
    assert result.t_final < 1.0 and result.summary()["t_final"] == result.t_final


def test_length_error_stops_the_run_and_is_recorded():
    """A strongly unstable loop at n = 4 loses length transiently (truncation); a tight
    length_tol turns that into a status, and the worst error is recorded."""
    result = api.simulate(150.0, 60.0, n=4, t_span=(0, 0.5), length_tol=1e-4)
    assert result.message == "length error too large" and result.t_final < 0.5
    assert result.length_error_max > 1e-4
    free = api.simulate(150.0, 60.0, n=4, t_span=(0, 0.5))
    assert free.success and free.length_error_max > 1e-4


@pytest.mark.parametrize("kwargs, word", [
    (dict(n=0), "n"), (dict(n=-3), "n"), (dict(g0=float("nan")), "g0"), (dict(g0=-1.0), "g0"),
    (dict(theta0_deg=91.0), "theta0_deg"), (dict(theta0_deg=-0.5), "theta0_deg"),
    (dict(rtol=0.0), "rtol"), (dict(perturbation=float("inf")), "perturbation"),
    (dict(method="euler"), "method"), (dict(t_span=(0.0, -1.0)), "t_span"),
])
def test_api_rejects_bad_input(kwargs, word):
    args = dict(g0=10.0, theta0_deg=30.0, n=6)
    args.update(kwargs)
    with pytest.raises(ValueError, match=word):
        api.simulate(args.pop("g0"), args.pop("theta0_deg"), **args)


@pytest.mark.parametrize("argv, word", [
    (["run", "--g0", "10", "--theta0", "30", "--n", "-2"], "-2"),
    (["run", "--n", "6", "--g0", "nan", "--theta0", "30"], "nan"),
    (["run", "--n", "6", "--g0", "-4", "--theta0", "30"], "-4"),
    (["run", "--n", "6", "--g0", "10", "--theta0", "120"], "120"),
    (["run", "--n", "6", "--g0", "10", "--theta0", "30", "--bogus"], "--bogus"),
    (["run", "--n", "6", "--g0", "10"], "--theta0"),
    (["stability", "--paper", "--n-max", "0"], "0"),
])
def test_cli_bad_input_one_line_error(argv, word, capsys):
    with pytest.raises(SystemExit) as exc:
        sys.exit(main(argv))
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("loopsim: error:") and word in err
    assert "Traceback" not in err


def test_cli_run_json_and_parquet(tmp_path, capsys):
    out = tmp_path / "run.parquet"
    code = main(["run", "--n", "6", "--g0", "60", "--theta0", "30", "--t-end", "0.2", "--snapshots", "3",
                 "--json", "--out", str(out)])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert list(summary) == list(api.SUMMARY_FIELDS) + ["compile_s"]
    assert summary.pop("compile_s") >= 0.0  # kernel compilation, not in wall_s
    table = pq.read_table(out)
    assert table.num_rows == 3 and table.column("x").type.list_size == 3 * 13
    meta = storage.read_metadata(out)
    assert meta["summary"] == summary and meta["loopsim_version"] == loopsim.__version__
    assert [p.name for p in tmp_path.iterdir()] == ["run.parquet"]  # no temporary left


def test_cli_unwritable_output_is_a_clean_error(tmp_path, capsys):
    (tmp_path / "afile").write_text("not a directory")
    code = main(["run", "--n", "6", "--g0", "10", "--theta0", "30", "--t-end", "0.01",
                 "--out", str(tmp_path / "afile" / "run.parquet")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "afile" in err


def test_cli_output_directories_are_made(tmp_path):
    """As on a fresh clone, where runs/ does not exist: --out and --figure make their
    directories (checked before any work, made when written)."""
    assert main(["run", "--n", "6", "--g0", "10", "--theta0", "30", "--t-end", "0.01",
                 "--out", str(tmp_path / "new" / "deeper" / "run.parquet")]) == 0
    assert (tmp_path / "new" / "deeper" / "run.parquet").stat().st_size > 0


def test_cli_stability_and_module_entry_point():
    done = subprocess.run([sys.executable, "-m", "loopsim", "stability", "--paper", "--n-max", "12", "--json"],
                          capture_output=True, text=True, check=True)
    table = json.loads(done.stdout)["critical_q"]
    assert table["1"] is None and abs(table["12"] - 14.56105439107) < 1e-10


@pytest.mark.parametrize("g0, theta_deg", [(10.0, 30.0), (60.0, 30.0)])
def test_early_stop_at_steady_state_matches_full_run(g0, theta_deg):
    """A stable and an in-plane loop: stopping once steady changes the terminal shape
    diagnostics by less than 1e-5 compared with integrating to t = 10."""
    early = api.simulate(g0, theta_deg, n=6, steady_tol=1e-6)
    full = api.simulate(g0, theta_deg, n=6)
    assert early.success and early.stop_reason == "steady" and early.t_final < 9.0
    assert full.stop_reason == "t_end" and early.summary()["status"] == "ok"
    e, f = early.summary(), full.summary()
    for key in ("aspect_ratio", "theta_final_deg", "tension_max"):
        assert abs(e[key] - f[key]) < 1e-5 * max(1.0, abs(f[key])), key


def test_early_stop_waits_for_a_deforming_loop():
    """A tolerance far below the shape's rate of change never fires."""
    result = api.simulate(150.0, 60.0, n=6, t_span=(0, 1.0), steady_tol=1e-12)
    assert result.stop_reason == "t_end" and result.t_final == 1.0


def test_integrators_agree_on_an_in_plane_shape():
    """RKF45 and Radau IIA, independent schemes, reach the same deformed shape."""
    runs = [api.simulate(60.0, 30.0, n=6, t_span=(0, 3.0), rtol=1e-9, atol=1e-12, method=m)
            for m in ("rkf45", "radau5")]
    assert all(r.success for r in runs) and runs[0].summary()["aspect_ratio"] > 1.3
    np.testing.assert_allclose(runs[1].x_final, runs[0].x_final, atol=1e-7)


def test_trajectory_plot_is_centred_on_the_loop(tmp_path):
    """The drawn shape lies within a few radii of the centre of mass, wherever the loop has
    sedimented to (it falls ~ g0 t: here z ≈ -600; the old plot subtracted the mean from
    every coefficient and spanned thousands)."""
    import matplotlib
    matplotlib.use("Agg")
    import pyarrow.parquet as pq
    from loopsim import figures

    path = tmp_path / "run.parquet"
    assert main(["run", "--n", "6", "--g0", "60", "--theta0", "30", "--t-end", "10", "--snapshots", "5",
                 "--out", str(path)]) == 0
    frame = pq.read_table(path).to_pandas()
    assert np.asarray(frame["x"].iloc[-1])[2 * 13] < -100  # z's mean coefficient: it fell
    fig = figures.trajectory(frame, 6)
    lines = fig.axes[0].get_lines()
    assert len(lines) == 5
    extent = max(np.abs(line.get_xydata()).max() for line in lines)
    assert 0.5 < extent < 3.0  # unit radius, loop length 2π
    figures.save(fig, tmp_path / "run.png")
    assert (tmp_path / "run.png").stat().st_size > 0


@pytest.mark.parametrize("argv", [
    ["run", "--n", "6", "--g0", "60", "--theta0", "30", "--out", "{tmp}/afile/run.parquet"],
    ["run", "--n", "6", "--g0", "60", "--theta0", "30", "--out", "{tmp}"],
    ["run", "--n", "6", "--g0", "60", "--theta0", "30", "--out", ""],
    ["sweep", "--n", "6", "--g0", "60", "--theta0", "30", "--out", "{tmp}/s", "--figure", "{tmp}/afile/p.png"],
])
def test_output_paths_are_checked_before_any_work(argv, tmp_path, capsys, monkeypatch):
    """A bad --out or --figure is refused before any integration (one line, exit 2)."""
    from loopsim import sweeps

    def no_work(*args, **kwargs):
        raise AssertionError("integration started before the output path was checked")

    monkeypatch.setattr(api, "simulate", no_work)
    monkeypatch.setattr(sweeps, "run_sweep", no_work)
    (tmp_path / "afile").write_text("a file where a directory is needed")
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and err.startswith("loopsim: error:")
    assert not (tmp_path / "s").exists()  # nothing created for a refused sweep


def test_simulate_with_no_other_argument_returns_a_resolved_result():
    """The default is n="auto" (measured: about 15 s once compiled; n_used 24, 3D,
    determined): a 3D loop that n = 6 leaves unresolved comes back resolved."""
    result = loopsim.simulate(150, 45)
    assert result.success and result.resolved and result.determined
    assert result.n_used > 6 and result.regime == "3d"
    assert result.inputs["n"] == 6  # where the ladder started
