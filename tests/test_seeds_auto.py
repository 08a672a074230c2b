"""``--seeds auto`` end to end (loopsim.sweeps.seeds_auto): early stop on a deterministic cell, the
rows of a fixed ``--seeds K`` sweep, rounds that double, and a bit-for-bit resume."""
import dataclasses

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import loopsim
from loopsim import columns, outcome_statistics, seeds_auto_rule, storage, sweeps
from loopsim.storage import STOPS_FILE, read_seeds_auto
from loopsim.sweeps.seeds_auto import run_seeds_auto

FAST = dict(t_end=0.3, method="rkf45", twin=False, chunk_size=2)
#: The columns that must agree bit for bit (wall_s and case_id are not inputs' functions).
SAME = ["g0", "theta0_deg", "n", "seed", "status", "regime", "theta_final_deg",
        "aspect_ratio", "nfev", "x_final"]


def cells(g0, theta0, n=4):
    return sweeps.grid_cases(g0, theta0, [n], 1)


def runner(calls):
    def run_round(config, directory, weights=None):
        calls.append(len(config.cases))
        return sweeps.run_sweep(config, directory, threads=1, quiet=True)
    return run_round


def test_a_stable_cell_stops_after_the_first_round_with_a_fixed_sweeps_rows(tmp_path):
    config = sweeps.SweepConfig(cases=cells([10.0], [30.0]), **FAST)
    calls = []
    rows, stops = run_seeds_auto(config, str(tmp_path / "auto"), seeds_auto_rule.SeedTargets(),
                                 run_round=runner(calls))
    assert calls == [4]
    assert stops["stop_reason"].tolist() == [seeds_auto_rule.DETERMINISTIC]
    assert stops["seeds"].tolist() == [4] and stops["rounds"].tolist() == [1]
    fixed = sweeps.run_sweep(dataclasses.replace(config, cases=sweeps.grid_cases(
        [10.0], [30.0], [4], 4)), str(tmp_path / "fixed"), threads=1, quiet=True)
    pd.testing.assert_frame_equal(rows[SAME].reset_index(drop=True),
                                  fixed[SAME].reset_index(drop=True), check_exact=True)
    assert (tmp_path / "auto" / STOPS_FILE).is_file()


def test_rounds_double_to_the_cap_and_resume_bit_for_bit(tmp_path):
    # a tilt tolerance below the seeds' spread: never deterministic; cap 8 from 2
    targets = seeds_auto_rule.SeedTargets(min_seeds=2, max_seeds=8, tilt_tol_deg=1e-12,
                                  p_halfwidth=0.01)
    config = sweeps.SweepConfig(cases=cells([10.0, 60.0], [30.0]), **FAST)
    calls = []
    whole, stops = run_seeds_auto(config, str(tmp_path / "whole"), targets,
                                  run_round=runner(calls))
    assert calls == [4, 4, 8]  # 2 cells x 2, then x 2 more, then x 4 more
    assert stops["stop_reason"].tolist() == [seeds_auto_rule.CAP] * 2
    assert stops["seeds"].tolist() == [8, 8] and stops["rounds"].tolist() == [3, 3]
    assert whole["round"].tolist() == [0] * 4 + [1] * 4 + [2] * 8
    assert sorted(whole.loc[whole["g0"] == 10.0, "seed"]) == list(range(8))

    def interrupted(config, directory, weights=None, _calls=[]):
        _calls.append(1)
        if len(_calls) == 2:
            raise KeyboardInterrupt
        return sweeps.run_sweep(config, directory, threads=1, quiet=True)

    out = str(tmp_path / "resumed")
    with pytest.raises(KeyboardInterrupt):
        run_seeds_auto(config, out, targets, run_round=interrupted)
    resumed, resumed_stops = run_seeds_auto(config, out, targets, run_round=runner([]))
    columns = SAME + ["round", "case_id"]
    pd.testing.assert_frame_equal(resumed[columns], whole[columns], check_exact=True)
    pd.testing.assert_frame_equal(resumed_stops, stops, check_exact=True)
    pd.testing.assert_frame_equal(read_seeds_auto(out)[columns], whole[columns],
                                  check_exact=True)


def test_other_targets_in_the_same_directory_are_refused(tmp_path):
    config = sweeps.SweepConfig(cases=cells([10.0], [30.0]), **FAST)
    out = str(tmp_path / "auto")
    run_seeds_auto(config, out, seeds_auto_rule.SeedTargets(), run_round=runner([]))
    with pytest.raises(ValueError, match="tilt_halfwidth_deg"):
        run_seeds_auto(config, out, seeds_auto_rule.SeedTargets(tilt_halfwidth_deg=1.0),
                       run_round=runner([]))
    with pytest.raises(ValueError, match="t_end"):
        run_seeds_auto(dataclasses.replace(config, t_end=0.2), out, seeds_auto_rule.SeedTargets(),
                       run_round=runner([]))
    assert len(loopsim.read_results(out)) == 4


def test_the_python_sweep_runs_seeds_auto_and_refuses_targets_without_it(tmp_path):
    out = tmp_path / "auto"
    rows = loopsim.sweep([10.0], [30.0], out, n=4, seeds="auto", max_seeds=8, threads=1,
                         **FAST)
    assert len(rows) == 4 and rows["round"].tolist() == [0] * 4
    stops = storage.read_stop_table(str(out))
    assert stops["stop_reason"].tolist() == [seeds_auto_rule.DETERMINISTIC]
    schema = pq.read_schema(out / storage.STOPS_FILE)
    assert schema.field("n").type == pa.int64() and stops["n"].tolist() == [4]
    assert all(f.metadata[b"unit"] == columns.STOP_COLUMNS[f.name][0].encode() for f in schema)
    with pytest.raises(ValueError, match="seeds='auto'"):
        loopsim.sweep([10.0], [30.0], tmp_path / "fixed", n=4, max_seeds=8, **FAST)
    with pytest.raises(ValueError, match="seeds must be"):
        loopsim.sweep([10.0], [30.0], tmp_path / "bad", n=4, seeds="many", **FAST)


def test_every_target_is_an_option_of_the_command_line_and_of_sweep(tmp_path):
    """Each of config.SEED_TARGETS reaches seeds_auto_rule.SeedTargets from --OPTION and from
    sweep(OPTION=): a target given both ways is stored in the directory's record."""
    import json

    from loopsim.cli import main
    from loopsim.defaults import SEED_TARGETS

    given = dict(p_halfwidth=0.3, tilt_halfwidth=7.5, min_seeds=2, max_seeds=2)
    for how in ("cli", "python"):
        out = tmp_path / how
        if how == "cli":
            flags = [x for k, v in given.items() for x in ("--" + k.replace("_", "-"), str(v))]
            assert main(["sweep", "--g0", "10", "--theta0", "30", "--n", "4", "--t-end", "0.3",
                         "--no-twin", "--seeds", "auto", "--threads", "1", "--quiet",
                         "--out", str(out), *flags]) == 0
        else:
            loopsim.sweep([10.0], [30.0], out, n=4, seeds="auto", threads=1, **given, **FAST)
        stored = json.loads((out / storage.SEEDS_FILE).read_text())["targets"]
        assert {SEED_TARGETS[k][0]: stored[SEED_TARGETS[k][0]] for k in given} == {
            SEED_TARGETS[k][0]: v for k, v in given.items()}, how


def test_seeds_auto_from_the_command_line(tmp_path, capsys):
    from loopsim.cli import main

    out = tmp_path / "auto"
    args = ["sweep", "--g0", "10", "--theta0", "30", "--n", "4", "--t-end", "0.3",
            "--no-twin", "--seeds", "auto", "--max-seeds", "8", "--threads", "1", "--quiet",
            "--out", str(out), "--figure", str(tmp_path / "outcome_statistics.png")]
    assert main(args) == 0
    printed = capsys.readouterr().out
    assert "1 points, seeds until sharp: deterministic 1" in printed
    assert (tmp_path / "outcome_statistics.png").stat().st_size > 0
    assert main(args) == 0  # resumed: nothing to do, the same table
    assert len(loopsim.read_results(str(out))) == 4
    for bad, message in ((["--min-seeds", "4"], "--min-seeds applies only with --seeds auto"),
                         (["--seeds", "many"], "--seeds must be a count"),
                         (["--seeds", "auto", "--shard", "0/2"], "--shard does not apply"),
                         (["--seeds", "auto", "--max-seeds", "2"], "--min-seeds and --max")):
        base = ["sweep", "--n", "6", "--g0", "10", "--theta0", "30", "--out", str(tmp_path / "bad")]
        assert main(base + bad) == 2
        assert message in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()


def _rows(regimes, determined, round_=0):
    tilts = [10.0 + 7 * k for k in range(len(regimes))]
    return pd.DataFrame(dict(g0=150.0, theta0_deg=60.0, n=6, perturbation=0.01,
                             seed=range(len(regimes)), regime=regimes, determined=determined,
                             theta_final_deg=tilts, aspect_ratio=2.0, nfev=100,
                             twin_nfev=[0 if d is None else 300 for d in determined],
                             twin_regime=[None if d is None else r
                                          for d, r in zip(determined, regimes)],
                             twin_theta_final_deg=[np.nan if d is None else t + (not d)
                                                   for d, t in zip(determined, tilts)],
                             twin_aspect_ratio=[np.nan if d is None else 2.0
                                                for d in determined],
                             wall_s=1.0, round=round_))


def test_runs_are_samples_when_seeds_disagree_or_a_twin_does():
    assert not seeds_auto_rule.runs_are_samples(_rows(["3d"] * 4, [True] * 4))
    assert seeds_auto_rule.runs_are_samples(_rows(["3d", "in-plane", "3d", "3d"], [True] * 4))
    assert seeds_auto_rule.runs_are_samples(_rows(["3d"] * 4, [True, False, True, True]))
    assert not seeds_auto_rule.runs_are_samples(_rows(["3d"] * 4, [None] * 4))  # no twins: no sign


def test_sampled_cells_drop_their_twins_and_are_checked_in_distribution():
    """A cell whose runs are samples plans its next seeds without twins; its stricter sample
    is its twins' outcomes, topped up to check_seeds with runs of the seeds that had none;
    a cell of determined trajectories keeps its twins; the expected costs come from the
    cells' rows (twins counted where they run)."""
    from loopsim.sweeps import seeds_auto

    targets = seeds_auto_rule.SeedTargets(check_seeds=3)
    cell = dict(g0=150.0, theta0_deg=60.0, n=6, perturbation=0.01, seed=0)
    first = _rows(["3d", "3d", "in-plane", "3d"], [True, False, True, True])
    cases = seeds_auto.plan_round([cell], first, targets)
    assert [c["seed"] for c in cases] == [4, 5, 6, 7] and all(c["twin"] is False for c in cases)
    assert seeds_auto.plan_round([cell], first, targets, twins=False) == [
        dict(cell, seed=s) for s in range(4, 8)]  # --no-twin: nothing to drop
    assert seeds_auto.plan_round([cell], first, dataclasses.replace(targets, check_seeds=0)) \
        == [dict(cell, seed=s) for s in range(4, 8)]  # no check: twins throughout
    costs = seeds_auto.expected_costs(cases, first)
    assert costs == {i: 1.0 for i in range(4)}
    assert seeds_auto.expected_costs([cell], first) == {0: 4.0}  # with its twin: 1 + 300/100
    assert seeds_auto.expected_costs([cell], None) is None
    later = _rows(["3d"] * 4, [None] * 4).assign(seed=range(4, 8), round=1)
    rows = pd.concat([first, later], ignore_index=True)
    assert seeds_auto.plan_check([cell], rows, targets) == []  # 4 twins make up 3
    targets = dataclasses.replace(targets, check_seeds=7)
    check = seeds_auto.plan_check([cell], rows, targets)
    assert [c["seed"] for c in check] == [4, 5, 6]  # 4 twins + 3 untwinned seeds
    config = sweeps.SweepConfig(cases=[cell], rtol=1e-6, atol=1e-9, tail_tol=1e-5)
    strict = seeds_auto.check_config(config, check)
    assert (strict.rtol, strict.atol, strict.tail_tol, strict.twin) == pytest.approx(
        (1e-7, 1e-10, 1e-6, False))
    steady = dict(cell, g0=10.0)
    determined = _rows(["stable"] * 4, [True] * 4).assign(g0=10.0)
    assert seeds_auto.plan_check([steady], determined, targets) == []
    checks = rows.iloc[4:7].assign(theta_final_deg=[40.0, 47, 54])
    stricter = seeds_auto.stricter_sample([cell, steady], pd.concat([rows, determined]),
                                          targets, checks)
    assert list(stricter["seed"]) == [0, 1, 2, 3, 4, 5, 6]
    assert list(stricter["theta_final_deg"]) == [10.0, 18, 24, 31, 40, 47, 54]  # twins' own
    assert list(stricter["regime"][:4]) == ["3d", "3d", "in-plane", "3d"]
    table = seeds_auto.stop_table([cell, steady], pd.concat([rows, determined]), targets,
                                  checks=checks)
    sampled, settled = table.iloc[0], table.iloc[1]
    assert (sampled["runs"], sampled["twins"], sampled["check_seeds"]) == ("samples", 4, 7)
    assert sampled["check_verdict"] in (outcome_statistics.SAME, outcome_statistics.DIFFERENT)
    assert 0 <= sampled["check_tilt_ks_p"] <= 1 and sampled["check_tilt_wasserstein"] > 0
    assert (settled["runs"], settled["twins"], settled["check_seeds"]) == ("trajectories", 4, 0)
    assert settled["check_verdict"] == "" and np.isnan(settled["check_tilt_ks_p"])


def test_a_cell_whose_every_seed_fails_stops_as_failed_without_a_check(tmp_path):
    """Issue 46.2: a step budget of 3 fails every run (and every twin) at once.  The cell
    used to be taken for samples (no failed run is "determined"): 4 more seeds without
    twins and 4 check runs, and the verdict "indistinguishable" for failures against
    failures.  It stops after its first round, twins kept, with no check and no verdict."""
    config = sweeps.SweepConfig(cases=cells([60.0], [30.0]), t_end=0.2, method="rkf45",
                                twin=True, chunk_size=2, max_steps=3)
    targets = seeds_auto_rule.SeedTargets(max_seeds=8)
    calls = []
    out = tmp_path / "auto"
    rows, stops = run_seeds_auto(config, str(out), targets, run_round=runner(calls))
    assert calls == [4] and set(rows["regime"]) == {"failed"}
    assert rows["twin_nfev"].gt(0).all()  # every seed kept its twin
    stop = stops.iloc[0]
    assert (stop["stop_reason"], stop["seeds"], stop["runs"]) == (seeds_auto_rule.FAILED, 4, "none")
    assert (stop["check_seeds"], stop["check_verdict"]) == (0, "")
    assert not (out / storage.CHECK_DIR).exists()


def test_check_seeds_0_says_the_later_seeds_ran_with_twins(tmp_path, capsys, monkeypatch):
    """Issue 46.8: with --check-seeds 0 a sampled cell keeps its twins; the closing line
    said its later seeds ran without.  Twins that never agree (as in the test below) make
    the cell's runs samples, and a tilt tolerance below the seeds' spread runs it to the
    cap."""
    from loopsim.cli import main
    from loopsim.outcomes import Thresholds

    real = sweeps.run_seeds_auto

    def sampled(config, out, targets, **kwargs):
        strict = Thresholds(determined_tilt_deg=1e-15, determined_aspect=1e-15)
        return real(dataclasses.replace(config, thresholds=strict), out,
                    dataclasses.replace(targets, tilt_tol_deg=1e-12), **kwargs)

    monkeypatch.setattr(sweeps, "run_seeds_auto", sampled)
    out = tmp_path / "auto"
    assert main(["sweep", "--g0", "60", "--theta0", "30", "--n", "4", "--method", "rkf45",
                 "--t-end", "0.3", "--seeds", "auto", "--min-seeds", "2", "--max-seeds", "4",
                 "--p-halfwidth", "0.01", "--check-seeds", "0", "--threads", "1", "--quiet",
                 "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    rows = loopsim.read_results(str(out))
    assert len(rows) == 4 and rows["twin_nfev"].gt(0).all()  # the later seeds had twins
    assert storage.read_stop_table(str(out))["runs"].tolist() == ["samples"]
    line = next(line for line in printed.splitlines() if "runs are samples" in line)
    assert "ran with twins" in line and "without twins" not in line, line
    assert "not checked (--check-seeds 0)" in line, line


def test_a_sampled_cell_end_to_end(tmp_path):
    """Twins that can never agree (determined_tilt_deg 1e-15) make every run a sample:
    round 0 runs twins, round 1 none, and the check runs the untwinned seeds at 10x
    stricter tolerances into out/check, each exactly its seed's twin would be (the same
    RHS count as a twin of that seed in a sweep with twins throughout); the stop table
    says so."""
    from loopsim.outcomes import Thresholds

    config = sweeps.SweepConfig(cases=cells([60.0], [30.0]), t_end=0.3, method="rkf45",
                                twin=True, chunk_size=2,
                                thresholds=Thresholds(determined_tilt_deg=1e-15,
                                                      determined_aspect=1e-15))
    targets = seeds_auto_rule.SeedTargets(min_seeds=2, max_seeds=4, tilt_tol_deg=1e-12,
                                  p_halfwidth=0.01, check_seeds=4)
    out = tmp_path / "auto"
    rows, stops = run_seeds_auto(config, str(out), targets, run_round=runner([]))
    assert rows["twin_nfev"].gt(0).tolist() == [True, True, False, False]
    assert rows["determined"].tolist()[:2] == [False, False]
    check = loopsim.read_results(str(out / storage.CHECK_DIR))
    assert list(check["seed"]) == [2, 3] and set(check["rtol"]) == {config.rtol / 10}
    throughout = sweeps.run_sweep(dataclasses.replace(config, cases=sweeps.grid_cases(
        [60.0], [30.0], [4], 4)), str(tmp_path / "twins"), threads=1, quiet=True)
    assert list(check["nfev"]) == list(throughout["twin_nfev"][2:])
    assert list(check["theta_final_deg"]) == list(throughout["twin_theta_final_deg"][2:])
    stop = stops.iloc[0]
    assert (stop["runs"], stop["twins"], stop["check_seeds"]) == ("samples", 2, 4)
    assert stop["check_verdict"] == outcome_statistics.SAME  # 10x stricter: the same tilts to 1e-5
    pd.testing.assert_frame_equal(storage.read_stop_table(str(out)), stops)
