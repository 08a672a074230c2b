"""``--seeds auto`` end to end (loopsim.sweeps.seeds_auto): early stop on a deterministic cell, the
rows of a fixed ``--seeds K`` sweep, rounds that double, and a bit-for-bit resume."""
import dataclasses

import pandas as pd
import pytest

import loopsim
from loopsim import io, seeding, sweeps
from loopsim.io import STOPS_FILE, read_seeds_auto
from loopsim.sweeps.seeds_auto import run_seeds_auto

FAST = dict(t_end=0.3, method="rkf45", twin=False, chunk_size=2)
#: The columns that must agree bit for bit (wall_s and case_id are not inputs' functions).
SAME = ["g0", "theta0_deg", "n", "seed", "status", "regime", "theta_final_deg",
        "aspect_ratio", "nfev", "x_final"]


def cells(g0, theta0, n=4):
    return sweeps.grid_cases(g0, theta0, [n], 1)


def runner(calls):
    def run_round(config, directory):
        calls.append(len(config.cases))
        return sweeps.run_sweep(config, directory, threads=1, quiet=True)
    return run_round


def test_a_stable_cell_stops_after_the_first_round_with_a_fixed_sweeps_rows(tmp_path):
    config = sweeps.SweepConfig(cases=cells([10.0], [30.0]), **FAST)
    calls = []
    rows, stops = run_seeds_auto(config, str(tmp_path / "auto"), seeding.SeedTargets(),
                                 run_round=runner(calls))
    assert calls == [4]
    assert stops["stop_reason"].tolist() == [seeding.DETERMINISTIC]
    assert stops["seeds"].tolist() == [4] and stops["rounds"].tolist() == [1]
    fixed = sweeps.run_sweep(dataclasses.replace(config, cases=sweeps.grid_cases(
        [10.0], [30.0], [4], 4)), str(tmp_path / "fixed"), threads=1, quiet=True)
    pd.testing.assert_frame_equal(rows[SAME].reset_index(drop=True),
                                  fixed[SAME].reset_index(drop=True), check_exact=True)
    assert (tmp_path / "auto" / STOPS_FILE).is_file()


def test_rounds_double_to_the_cap_and_resume_bit_for_bit(tmp_path):
    # a tilt tolerance below the seeds' spread: never deterministic; cap 8 from 2
    targets = seeding.SeedTargets(min_seeds=2, max_seeds=8, tilt_tol_deg=1e-12,
                                  p_halfwidth=0.01)
    config = sweeps.SweepConfig(cases=cells([10.0, 60.0], [30.0]), **FAST)
    calls = []
    whole, stops = run_seeds_auto(config, str(tmp_path / "whole"), targets,
                                  run_round=runner(calls))
    assert calls == [4, 4, 8]  # 2 cells x 2, then x 2 more, then x 4 more
    assert stops["stop_reason"].tolist() == [seeding.CAP] * 2
    assert stops["seeds"].tolist() == [8, 8] and stops["rounds"].tolist() == [3, 3]
    assert whole["round"].tolist() == [0] * 4 + [1] * 4 + [2] * 8
    assert sorted(whole.loc[whole["g0"] == 10.0, "seed"]) == list(range(8))

    def interrupted(config, directory, _calls=[]):
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
    run_seeds_auto(config, out, seeding.SeedTargets(), run_round=runner([]))
    with pytest.raises(ValueError, match="tilt_halfwidth_deg"):
        run_seeds_auto(config, out, seeding.SeedTargets(tilt_halfwidth_deg=1.0),
                       run_round=runner([]))
    with pytest.raises(ValueError, match="t_end"):
        run_seeds_auto(dataclasses.replace(config, t_end=0.2), out, seeding.SeedTargets(),
                       run_round=runner([]))
    assert len(loopsim.read_results(out)) == 4


def test_the_python_sweep_runs_seeds_auto_and_refuses_targets_without_it(tmp_path):
    out = tmp_path / "auto"
    rows = loopsim.sweep([10.0], [30.0], out, n=4, seeds="auto", max_seeds=8, threads=1,
                         **FAST)
    assert len(rows) == 4 and rows["round"].tolist() == [0] * 4
    stops = io.read_stop_table(str(out))
    assert stops["stop_reason"].tolist() == [seeding.DETERMINISTIC]
    with pytest.raises(ValueError, match="seeds='auto'"):
        loopsim.sweep([10.0], [30.0], tmp_path / "fixed", n=4, max_seeds=8, **FAST)
    with pytest.raises(ValueError, match="seeds must be"):
        loopsim.sweep([10.0], [30.0], tmp_path / "bad", n=4, seeds="many", **FAST)


def test_every_target_is_an_option_of_the_command_line_and_of_sweep(tmp_path):
    """Each of config.SEED_TARGETS reaches seeding.SeedTargets from --OPTION and from
    sweep(OPTION=): a target given both ways is stored in the directory's record."""
    import json

    from loopsim.cli import main
    from loopsim.config import SEED_TARGETS

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
        stored = json.loads((out / io.SEEDS_FILE).read_text())["targets"]
        assert {SEED_TARGETS[k][0]: stored[SEED_TARGETS[k][0]] for k in given} == {
            SEED_TARGETS[k][0]: v for k, v in given.items()}, how


def test_seeds_auto_from_the_command_line(tmp_path, capsys):
    from loopsim.cli import main

    out = tmp_path / "auto"
    args = ["sweep", "--g0", "10", "--theta0", "30", "--n", "4", "--t-end", "0.3",
            "--no-twin", "--seeds", "auto", "--max-seeds", "8", "--threads", "1", "--quiet",
            "--out", str(out), "--figure", str(tmp_path / "summary.png")]
    assert main(args) == 0
    printed = capsys.readouterr().out
    assert "1 points, seeds until sharp: deterministic 1" in printed
    assert (tmp_path / "summary.png").stat().st_size > 0
    assert main(args) == 0  # resumed: nothing to do, the same table
    assert len(loopsim.read_results(str(out))) == 4
    for bad, message in ((["--min-seeds", "4"], "--min-seeds applies only with --seeds auto"),
                         (["--seeds", "many"], "--seeds must be a count"),
                         (["--seeds", "auto", "--shard", "0/2"], "--shard does not apply"),
                         (["--seeds", "auto", "--max-seeds", "2"], "--min-seeds and --max")):
        base = ["sweep", "--g0", "10", "--theta0", "30", "--out", str(tmp_path / "bad")]
        assert main(base + bad) == 2
        assert message in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()
