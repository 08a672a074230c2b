"""The nonlocal model where users reach it: ``simulate(model=, slenderness=)``, ``loopsim
run``/``sweep`` ``--model nonlocal --slenderness``, cases files, ``--n auto``; recorded
in every row.  Closed forms: Johnson & Wu's (1979) rigid-ring speeds (the elastic ring
released as a horizontal or vertical circle stays one and translates as the rigid ring)."""
import json

import numpy as np
import pyarrow as pa
import pytest

import loopsim
from loopsim import integrators, models, shapes, storage, sweeps
from loopsim.cli import main
from loopsim.models import nonlocal_closed_form as closed
from loopsim.models import nonlocal_sbt

NONLOCAL = dict(model="nonlocal", slenderness=1e-3)


@pytest.mark.parametrize("eps", [1e-2, 1e-3, 1e-4])
def test_released_rings_fall_at_johnson_wu_speeds(eps, capsys):
    """``loopsim run --model nonlocal``: a horizontal ring falls broadside, a vertical one
    edgewise, at Johnson & Wu's speeds g0 U_b and g0 U_e (to 1e-10), without drifting
    sideways; the summary records the model and ε."""
    broadside, edgewise = closed.johnson_wu_ring(eps)
    for theta0, speed in (("0", broadside), ("90", edgewise)):
        assert main(["run", "--g0", "1", "--theta0", theta0, "--n", "6", "--t-end", "1",
                     "--perturbation", "0", "--no-twin", "--json", "--model", "nonlocal",
                     "--slenderness", f"{eps:g}"]) == 0
        summary = json.loads(capsys.readouterr().out)
        assert (summary["model"], summary["slenderness"]) == ("nonlocal", eps)
        assert abs(-summary["u_z"] - speed) < 1e-10 * speed
        assert abs(summary["u_x"]) + abs(summary["u_y"]) < 1e-12
        assert abs(summary["aspect_ratio"] - 1.0) < 1e-12


def test_simulate_runs_the_nonlocal_problem_and_twins_it():
    """``simulate(model="nonlocal")`` is the driver on ``nonlocal_sbt.make_problem`` bit for
    bit; its twin runs the same model (a determined, resolved tilted loop)."""
    result = loopsim.simulate(20.0, 30.0, n=6, t_span=(0.0, 0.3), **NONLOCAL)
    x0 = shapes.start_shape(30.0, 6, None, 0, None, None)[0]
    status, t, y, _, _ = integrators.integrate(
        integrators.RKF45, nonlocal_sbt.make_problem(6, 20.0, 10.0, 1e-3), x0.ravel().copy(),
        0.0, 0.3, None, integrators.step_options(1e-6, 1e-9), None)
    np.testing.assert_array_equal(result.x_final.ravel(), y)
    assert result.determined and result.resolved
    assert abs(result.twin["theta_final_deg"] - result.end_state["theta_final_deg"]) < 1e-6
    local = loopsim.simulate(20.0, 30.0, n=6, t_span=(0.0, 0.3), twin=False)
    assert np.abs(local.x_final - result.x_final).max() > 1e-3  # another model moved it


def test_sweep_rows_record_the_model_and_equal_single_runs(tmp_path):
    """A nonlocal sweep's rows carry model and slenderness (described in the schema), equal
    ``simulate`` bit for bit, on one thread and on two."""
    cases = sweeps.grid_cases([10.0, 40.0], [30.0, 60.0], [6], seeds=1)
    config = sweeps.SweepConfig(cases=cases, t_end=0.3, twin=False, **NONLOCAL)
    one = sweeps.run_sweep(config, str(tmp_path / "one"), threads=1, quiet=True)
    two = sweeps.run_sweep(config, str(tmp_path / "two"), threads=2, quiet=True)
    assert set(one["model"]) == {"nonlocal"} and set(one["slenderness"]) == {1e-3}
    assert storage.RESULT_SCHEMA.field("slenderness").metadata[b"unit"] == b"1"
    for a, b in zip(one["x_final"], two["x_final"]):
        np.testing.assert_array_equal(a, b)
    single = loopsim.simulate(40.0, 60.0, n=6, t_span=(0.0, 0.3), steady_tol=1e-6, twin=False,
                              **NONLOCAL)
    row = one[(one["g0"] == 40.0) & (one["theta0_deg"] == 60.0)].iloc[0]
    np.testing.assert_array_equal(single.x_final.ravel(), row["x_final"])
    assert loopsim.read_results(str(tmp_path / "one")).attrs["loopsim"]["sweep_config"][
        "model"] == "nonlocal"


def test_cases_file_mixes_models_per_row(tmp_path):
    """Columns model and slenderness set each row's model; a local row equals a plain
    local sweep's row bit for bit, and the sweep's --slenderness is the nonlocal rows'
    default."""
    path = tmp_path / "cases.csv"
    path.write_text("g0,theta0_deg,n,model,slenderness\n40,60,6,nonlocal,1e-2\n"
                    "40,60,6,local,\n40,60,6,nonlocal,\n")
    out = tmp_path / "mixed"
    assert main(["sweep", "--n", "6", "--cases", str(path), "--t-end", "0.3", "--no-twin", "--quiet",
                 "--slenderness", "1e-3", "--out", str(out)]) == 0
    frame = loopsim.read_results(str(out))
    assert list(frame["model"]) == ["nonlocal", "local", "nonlocal"]
    assert frame["slenderness"].iloc[0] == 1e-2 and frame["slenderness"].iloc[2] == 1e-3
    assert np.isnan(frame["slenderness"].iloc[1])
    local = sweeps.run_sweep(sweeps.SweepConfig(
        cases=sweeps.grid_cases([40.0], [60.0], [6], 1), t_end=0.3, twin=False),
        str(tmp_path / "local"), threads=1, quiet=True)
    np.testing.assert_array_equal(frame["x_final"].iloc[1], local["x_final"].iloc[0])
    assert np.abs(frame["x_final"].iloc[0] - frame["x_final"].iloc[2]).max() > 1e-6


def test_n_auto_stops_at_the_models_highest_order():
    """ε = 1e-2: the operator loses positivity at mode 11, so the ladder ends at 10."""
    model = models.choose("nonlocal", 1e-2)
    assert models.highest_order(model) == 10
    assert loopsim.api.ladder_top(model, 32) == 10 and loopsim.api.ladder_top(model, 8) == 8
    result = loopsim.simulate(150.0, 60.0, n="auto", t_span=(0.0, 0.05), twin=False,
                              model="nonlocal", slenderness=1e-2)
    assert result.n_used <= 10 and result.success


@pytest.mark.parametrize("argv, words", [
    (["--model", "nonlocal"], ["needs slenderness"]),
    (["--slenderness", "1e-3"], ["only to the nonlocal model", "0.001"]),
    (["--model", "nonlocal", "--slenderness", "0.2"], ["slenderness", "0.2"]),
    (["--model", "nonlocal", "--slenderness", "nan"], ["--slenderness", "nan"]),
    (["--model", "nonlocal", "--slenderness", "1e-2", "--n", "12"],
     ["n = 12", "mode 11", "n <= 10"]),
    (["--model", "stokes"], ["--model", "stokes"]),
])
def test_bad_model_options_are_one_line_errors(argv, words, capsys, tmp_path):
    """run and sweep refuse them with exit 2, one line naming the value, nothing written."""
    for command in (["run", "--n", "6"], ["sweep", "--n", "6", "--out", str(tmp_path / "s")]):
        try:
            status = main(command + ["--g0", "20", "--theta0", "30"] + argv)
        except SystemExit as exc:  # argparse's own errors (a bad number, a bad choice)
            status = exc.code
        assert status == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and all(w in err for w in words), err
        assert not (tmp_path / "s").exists()


def test_result_files_written_before_the_model_columns_read_as_local():
    """A row of a file without the columns model and slenderness is a local-model row."""
    table = storage.RESULT_SCHEMA.empty_table().drop_columns(["model", "slenderness"])
    row = {name: [None] for name in table.schema.names}
    table = pa.table(row, schema=table.schema)
    read = storage.sweepdir.result_table(table)
    assert read.schema.equals(storage.RESULT_SCHEMA)
    assert read.column("model").to_pylist() == ["local"]
    assert read.column("slenderness").to_pylist() == [None]



def test_unresolved_rows_at_the_models_highest_order_get_no_larger_n_advice():
    """The sweep's advice for unresolved rows: a larger n, except for rows already at their
    model's highest order (ε = 1e-2: n = 10), for which no larger n exists."""
    import pandas as pd

    from loopsim.cli.sweep import refinement_advice

    config = sweeps.SweepConfig(cases=sweeps.grid_cases([10.0], [30.0], [6], 1), n_auto=True)
    rows = lambda *cases: pd.DataFrame(cases, columns=["model", "slenderness", "n_used"])
    capped = refinement_advice(config, rows(("nonlocal", 1e-2, 10), ("nonlocal", 1e-2, 10)))
    assert "highest order" in capped and "--n-max" not in capped
    mixed = refinement_advice(config, rows(("nonlocal", 1e-2, 10), ("local", np.nan, 32),
                                            ("nonlocal", 1e-3, 32)))
    assert "--n-max than 32" in mixed and "1 of them are at their model's highest" in mixed
    plain = refinement_advice(config, rows(("local", np.nan, 32)))
    assert "--n-max than 32" in plain and "highest" not in plain
