"""What a row says about its outcome (loopsim.outcomes): ``n="auto"`` against fixed
high-order runs from the same start, the determinacy estimate against independent
twins, and the same fields in simulate(), run --json and sweep rows."""
import json
import math
import warnings

import numpy as np
import pytest

import loopsim
from loopsim import api, outcomes, shapes, spectral
from loopsim.cli import main


def reference(g0, x0, n=24):
    """A fixed order-n radau5 run at rtol 1e-8 from x0 zero-padded: the same start at t = 0."""
    return loopsim.simulate(g0, initial=spectral.resize(x0, n), perturbation=0.0, n=n,
                            method="radau5", rtol=1e-8, atol=1e-11, twin=False)


@pytest.mark.parametrize("g0, theta0, regime", [
    (20.0, 60.0, "stable"), (60.0, 30.0, "in-plane"), (60.0, 80.0, "3d")])
def test_auto_lands_on_the_same_start_fixed_high_order_run(g0, theta0, regime):
    """Defaults only: the auto run is determined and within 0.05 deg / 1e-3 of a fixed
    n = 24 run from the same start (measured: within 1e-5 deg), and its uncertainty
    estimate is the size of its actual error (measured 9.5e-6 against 9.4e-6 deg at
    (60, 80)), never far below it."""
    x0 = shapes.start_shape(theta0, 6, None, 0)[0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # resolved and determined: no warning
        auto = loopsim.simulate(g0, initial=x0, perturbation=0.0, n="auto")
    ref = reference(g0, x0)
    assert auto.method == "radau5" and auto.regime == ref.regime == regime
    assert auto.resolved and auto.determined
    error = abs(auto.end_state["theta_final_deg"] - ref.end_state["theta_final_deg"])
    assert error < 1e-4 and abs(auto.end_state["aspect_ratio"] - ref.end_state["aspect_ratio"]) < 1e-5
    estimate = auto.determinacy["theta_uncertainty_deg"]
    assert estimate < outcomes.Thresholds().determined_tilt_deg
    assert error < 10 * estimate + 1e-8


def test_an_ill_conditioned_case_is_not_determined_and_says_so():
    """g0 = 150, θ0 = 60° at n = 6 (rkf45): the twin at 10x stricter tolerances ends
    degrees away, and so does an independent run at 100x stricter tolerances: the row
    is not determined, simulate() warns, and the estimate is of the size of the real
    spread (measured 10.5 deg against 3.7 deg)."""
    with pytest.warns(api.LoopsimWarning, match="not determined"):
        result = loopsim.simulate(150.0, 60.0, n=6)
    assert result.regime == "3d" and result.determined is False
    estimate = result.determinacy["theta_uncertainty_deg"]
    strict = loopsim.simulate(150.0, 60.0, n=6, rtol=1e-8, atol=1e-11, twin=False)
    spread = abs(result.end_state["theta_final_deg"] - strict.end_state["theta_final_deg"])
    assert estimate > 0.1 and spread > 0.1
    assert spread / 10 < estimate < spread * 10
    assert "determined=False" in repr(result) and "n_used=6" in repr(result)


def test_determinacy_rule():
    run = dict(regime="3d", theta_final_deg=30.0, aspect_ratio=2.0)
    near = dict(regime="3d", theta_final_deg=30.005, aspect_ratio=2.0001)
    fields = outcomes.determinacy(run, near, 123)
    assert fields["determined"] and fields["twin_nfev"] == 123
    assert fields["theta_uncertainty_deg"] == pytest.approx(0.005)
    assert not outcomes.determinacy(run, dict(near, theta_final_deg=30.02), 1)["determined"]
    assert not outcomes.determinacy(run, dict(near, aspect_ratio=2.001), 1)["determined"]
    assert not outcomes.determinacy(run, dict(near, regime="in-plane"), 1)["determined"]
    failed = outcomes.end_state(30.0, 1.0, np.full((3, 5), np.nan), False)
    assert failed["regime"] == "failed" and math.isnan(failed["theta_final_deg"])
    assert not outcomes.determinacy(run, failed, 1)["determined"]
    nothing = outcomes.determinacy(failed, run, 7)  # a failed run: no outcome to determine
    assert nothing["determined"] is False and nothing["twin_nfev"] == 7
    assert np.isnan(nothing["theta_uncertainty_deg"])
    result = loopsim.simulate(60.0, 30.0, n=6, t_span=(0, 1.0), max_steps=20)
    assert not result.success and result.determined is False  # and no twin was run:
    assert result.summary()["twin_nfev"] == 0
    assert outcomes.twin_tolerances(1e-6, 1e-9, 1e-5) == pytest.approx((1e-7, 1e-10, 1e-6), rel=1e-15)


def test_the_same_outcome_fields_in_run_json_simulate_and_sweep_rows(tmp_path, capsys):
    """regime, resolved, determined, the uncertainties and n_used: in run --json, in
    simulate()'s summary and repr, and as sweep columns, with equal values for one case."""
    argv = ["--g0", "30", "--theta0", "45", "--n", "auto", "--t-end", "2"]
    assert main(["run"] + argv + ["--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    result = loopsim.simulate(30.0, 45.0, n="auto", t_span=(0.0, 2.0))
    summary = result.summary()
    assert main(["sweep"] + argv + ["--quiet", "--no-early-stop", "--out",
                                    str(tmp_path / "s")]) == 0
    row = loopsim.read_results(str(tmp_path / "s")).iloc[0]
    for key in loopsim.storage.OUTCOME_FIELDS + ("n_used", "method", "theta_final_deg"):
        assert printed[key] == summary[key] == row[key], key
    assert summary["regime"] == "stable" and summary["resolved"] and summary["determined"]
    assert summary["twin_nfev"] > 0 and summary["method"] == "radau5"
    assert f"n_used={result.n_used}" in repr(result) and "regime='stable'" in repr(result)


def test_without_a_twin_determined_is_empty(tmp_path):
    result = loopsim.simulate(30.0, 45.0, n=6, t_span=(0.0, 0.5), twin=False)
    assert result.determined is None and result.summary()["twin_nfev"] == 0
    assert main(["sweep", "--n", "6", "--g0", "30", "--theta0", "45", "--t-end", "0.5", "--no-twin",
                 "--quiet", "--out", str(tmp_path / "s")]) == 0
    frame = loopsim.read_results(str(tmp_path / "s"))
    assert frame["determined"].isna().all() and frame["theta_uncertainty_deg"].isna().all()


def test_every_written_column_has_a_unit_and_a_description(tmp_path):
    """Sweep chunks and run files: each Parquet field carries 'unit' and 'description'
    metadata from the one declaration (loopsim.columns); read_results puts them in
    attrs; coefficients() gives x_final as (3, 2 n_used + 1)."""
    import pyarrow.parquet as pq

    from loopsim import columns

    out = tmp_path / "s"
    assert main(["sweep", "--n", "6", "--g0", "30", "--theta0", "45", "--t-end", "0.5", "--quiet",
                 "--snapshots-for", "0", "--snapshots", "3", "--out", str(out)]) == 0
    run = tmp_path / "run.parquet"
    assert main(["run", "--n", "6", "--g0", "30", "--theta0", "45", "--t-end", "0.5", "--out",
                 str(run)]) == 0
    files = list(out.glob("chunk-*.parquet")) + list((out / "_snapshots").glob("*.parquet"))
    assert len(files) == 2
    for path in files + [run]:
        for field in pq.read_schema(path):
            meta = field.metadata or {}
            assert meta.get(b"unit") and meta.get(b"description"), (path.name, field.name)
    assert set(pq.read_schema(files[0]).names) == set(columns.RESULT_COLUMNS)
    frame = loopsim.read_results(str(out))
    documented = frame.attrs["loopsim"]["columns"]
    assert set(documented) == set(frame.columns)
    assert documented["theta_final_deg"]["unit"] == "deg"
    x = loopsim.coefficients(frame.iloc[0])
    assert x.shape == (3, 2 * int(frame["n_used"].iloc[0]) + 1)
    np.testing.assert_array_equal(x.ravel(), frame["x_final"].iloc[0])


def test_python_sweep_writes_the_directory_the_command_line_writes(tmp_path):
    """loopsim.sweep(...) mirrors `loopsim sweep`: the same rows, bit for bit, and either
    resumes the other's directory; bad options are one-line errors."""
    frame = loopsim.sweep([10.0, 40.0], 30.0, tmp_path / "py", n=6, t_end=0.5, twin=False)
    assert main(["sweep", "--n", "6", "--g0", "10,40", "--theta0", "30", "--t-end", "0.5", "--no-twin",
                 "--quiet", "--out", str(tmp_path / "cli")]) == 0
    cli = loopsim.read_results(str(tmp_path / "cli"))
    keep = [c for c in frame.columns if c != "wall_s"]
    assert len(frame) == 2 and list(frame["case_id"]) == [0, 1]
    assert frame[keep].equals(cli[keep])
    again = loopsim.sweep([10.0, 40.0], 30.0, tmp_path / "cli", n=6, t_end=0.5, twin=False)
    assert again[keep].equals(cli[keep])  # resumed: nothing to do, the same table
    with pytest.raises(TypeError, match="colour"):  # an unknown keyword, as in any call
        loopsim.sweep(10.0, 30.0, tmp_path / "bad", colour="red")
    with pytest.raises(TypeError, match="cases"):
        loopsim.sweep(10.0, 30.0, tmp_path / "bad", cases=[])
    with pytest.raises(ValueError, match="n must be"):
        loopsim.sweep(10.0, 30.0, tmp_path / "bad", n="automatic")


def test_the_docs_column_table_is_the_declaration():
    """docs/sweeps.md's column table is `python -m loopsim.columns`, not a stale copy."""
    import os

    from loopsim import columns

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    with open(os.path.join(root, "docs", "sweeps.md"), encoding="utf-8") as handle:
        assert columns.markdown() in handle.read()
