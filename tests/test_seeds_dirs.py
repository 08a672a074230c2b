"""``--seeds auto`` directories that cannot mislead (issue 36): a refused command leaves
nothing behind, a directory of one kind refuses a sweep of another and rounds copied in
from elsewhere, ``--max-seeds`` is bounded before any work, the chunk size may change on
resume, and failed cases of a finished directory can be rerun."""
import dataclasses
import os
import shutil

import pytest

import loopsim
from loopsim import seeds_auto_rule, storage, sweeps
from loopsim.cli import main
from loopsim.sweeps.seeds_auto import run_seeds_auto

GRID = ["--g0", "10", "--theta0", "30", "--n", "4", "--t-end", "0.3", "--no-twin",
        "--threads", "1", "--quiet"]
AUTO = GRID + ["--seeds", "auto", "--min-seeds", "2", "--max-seeds", "4"]


def listing(path):
    """Every file and directory under ``path`` (relative), or None when it is absent."""
    if not os.path.exists(path):
        return None
    return sorted(os.path.relpath(os.path.join(root, name), path)
                  for root, dirs, files in os.walk(path) for name in dirs + files)


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished --seeds auto directory of one deterministic cell (2 seeds, 1 round)."""
    out = str(tmp_path_factory.mktemp("auto") / "a")
    assert main(["sweep", *AUTO, "--out", out]) == 0
    return out


@pytest.fixture
def auto(tmp_path, finished):
    out = str(tmp_path / "a")
    shutil.copytree(finished, out)
    return out


@pytest.mark.parametrize("bad, words", [
    (["--theta0", "95"], ["theta0", "95"]),
    (["--rtol", "0"], ["rtol", "0"]),
    (["--t-end", "0"], ["t_end", "0"]),
    (["--n", "129"], ["129"]),
    (["--perturbation", "0.6"], ["perturbation", "0.6"]),
    (["--model", "nonlocal"], ["slenderness"]),
    (["--model", "nonlocal", "--slenderness", "0.9"], ["slenderness", "0.9"]),
    (["--scheduler", "tcp://127.0.0.1:1"], ["127.0.0.1:1"]),
    (["--max-seeds", "1000000000"], ["--max-seeds", "1000000000"]),
])
def test_a_refused_seeds_auto_command_leaves_nothing(tmp_path, capsys, bad, words):
    """Issue 36.2 and 36.4: each refusal is one line and exit 2 (3 for an unreachable
    scheduler), before anything is written; the corrected command then runs."""
    out = tmp_path / "deeper" / "a"
    argv = ["sweep", *AUTO, *bad, "--out", str(out)]
    assert main(argv) in (2, 3)
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and all(w in err for w in words), err
    assert not (tmp_path / "deeper").exists()
    existing = tmp_path / "existing"
    existing.mkdir()
    assert main(["sweep", *AUTO, *bad, "--out", str(existing)]) in (2, 3)
    assert listing(str(existing)) == []


def test_max_seeds_bounded_by_the_largest_total_before_any_work(tmp_path):
    """Issue 36.4: points x --max-seeds above a sweep's most cases is refused at once."""
    config = sweeps.SweepConfig(cases=sweeps.grid_cases([10.0, 20.0], [30.0], [4], 1),
                                t_end=0.3, twin=False)
    with pytest.raises(ValueError, match="2 points x --max-seeds 600000 = 1200000 cases"):
        run_seeds_auto(config, str(tmp_path / "a"), seeds_auto_rule.SeedTargets(max_seeds=600_000),
                       run_round=lambda *_: pytest.fail("ran a round"))
    assert not (tmp_path / "a").exists()


def test_a_fixed_seed_sweep_is_refused_in_a_seeds_auto_directory(auto, capsys):
    """Issue 36.3: neither at its top nor in one of its rounds."""
    before = listing(auto)
    assert main(["sweep", *GRID, "--out", auto]) == 2
    assert "holds a --seeds auto sweep" in capsys.readouterr().err
    round_zero = storage.round_directory(auto, 0)
    assert main(["sweep", "--g0", "10,20", "--theta0", "30", "--n", "4", "--t-end", "0.2",
                 "--quiet", "--out", round_zero]) == 2
    assert "is round 0 of the --seeds auto sweep" in capsys.readouterr().err
    assert listing(auto) == before
    assert main(["sweep", *AUTO, "--out", auto]) == 0  # the right command: read back


def test_a_round_copied_in_from_another_sweep_is_refused_on_read(auto, tmp_path, capsys):
    """Issue 36.9: a round of a sweep with another perturbation put in place of round 0."""
    other = str(tmp_path / "other")
    assert main(["sweep", *AUTO, "--perturbation", "0.02", "--out", other]) == 0
    shutil.rmtree(storage.round_directory(auto, 0))
    shutil.copytree(storage.round_directory(other, 0), storage.round_directory(auto, 0))
    with pytest.raises(ValueError, match="is not a round of the --seeds auto sweep"):
        loopsim.read_results(auto)
    assert main(["summary", auto]) == 2
    assert "round-00" in capsys.readouterr().err
    # a directory recorded before round fingerprints (and checksums) were: its options
    # are compared
    record = storage.read_seeds_file(auto)
    del record["rounds"], record[storage.CONTENT_KEY]
    storage.write_json_atomically(record, os.path.join(auto, storage.SEEDS_FILE))
    with pytest.raises(ValueError, match="is not a round of the --seeds auto sweep"):
        loopsim.read_results(auto)


def test_a_resume_may_change_the_chunk_size(tmp_path):
    """Issue 36.8: as with fixed seeds, the chunk size is no part of the sweep."""
    config = sweeps.SweepConfig(cases=sweeps.grid_cases([10.0, 60.0], [30.0], [4], 1),
                                t_end=0.3, method="rkf45", twin=False, chunk_size=2)
    targets = seeds_auto_rule.SeedTargets(min_seeds=2, max_seeds=4, tilt_tol_deg=1e-12,
                                  p_halfwidth=0.01)
    calls = []

    def first_round_only(round_config, directory, weights=None):
        calls.append(directory)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return sweeps.run_sweep(round_config, directory, threads=1, quiet=True)

    out = str(tmp_path / "a")
    with pytest.raises(KeyboardInterrupt):
        run_seeds_auto(config, out, targets, run_round=first_round_only)
    rows, stops = run_seeds_auto(
        dataclasses.replace(config, chunk_size=3), out, targets,
        run_round=lambda c, d, w: sweeps.run_sweep(c, d, threads=1, quiet=True))
    assert len(rows) == 8 and list(stops["seeds"]) == [4, 4]
    with pytest.raises(ValueError, match="differs in: t_end"):
        run_seeds_auto(dataclasses.replace(config, t_end=0.2), out, targets,
                       run_round=lambda *_: pytest.fail("ran a round"))


def test_failed_cases_of_a_seeds_auto_directory_are_rerun(tmp_path, capsys):
    """Issue 36.7: the advice the sweep prints works.  rkf45 with a budget of 150 steps
    fails a stable loop to t = 3 (tests/test_sweepdir.py); radau5 needs about 60."""
    out = str(tmp_path / "a")
    config = sweeps.SweepConfig(cases=sweeps.grid_cases([10.0], [30.0], [4], 1), t_end=3.0,
                                max_steps=150, method="rkf45", twin=False)
    rows, stops = run_seeds_auto(config, out, seeds_auto_rule.SeedTargets(min_seeds=2, max_seeds=2),
                                 run_round=lambda c, d, w: sweeps.run_sweep(c, d, threads=1,
                                                                         quiet=True))
    assert list(rows["status"]) == ["step budget exhausted"] * 2
    assert main(["sweep", "--rerun-failed", out, "--method", "radau5", "--quiet",
                 "--threads", "1"]) == 0
    assert "reran 2 failed case(s)" in capsys.readouterr().out
    again = loopsim.read_results(out)
    assert list(again["status"]) == ["ok", "ok"] and list(again["seed"]) == [0, 1]
    assert list(again["method"]) == ["radau5"] * 2
    restated = storage.read_stop_table(out)  # issue 54.5: no longer "failed"
    assert list(stops["stop_reason"]) == ["failed"] and list(stops["runs"]) == ["none"]
    assert list(restated["stop_reason"]) == ["deterministic"]
    assert list(restated["runs"]) == ["trajectories"] and list(restated["seeds"]) == [2]
    assert restated.drop(columns=["stop_reason", "runs", "p_halfwidth",
                                  "tilt_halfwidth_deg"]).equals(
        stops.drop(columns=["stop_reason", "runs", "p_halfwidth", "tilt_halfwidth_deg"]))
    assert main(["sweep", "--rerun-failed", out, "--method", "radau5", "--quiet"]) == 0
    assert "reran 0 failed" in capsys.readouterr().out
    assert storage.read_stop_table(out).equals(restated)  # a second call changes nothing
    unfinished = str(tmp_path / "b")
    shutil.copytree(out, unfinished)
    os.remove(os.path.join(unfinished, storage.STOPS_FILE))
    assert main(["sweep", "--rerun-failed", unfinished, "--rtol", "1e-5"]) == 2
    assert "has not finished" in capsys.readouterr().err


def test_the_sweep_command_and_report_after_a_rescue_say_what_the_rows_say(tmp_path, capsys):
    """Issue 54.5: after --rerun-failed rescued the seeds of a cell stopped as failed,
    re-running the sweep's command still said "no successful seed ... no distribution,
    no check", and the report listed the cell as failed next to its p_stable 1.  (The
    step budget that fails rkf45 here is a Python option: the sweep's command is
    ``run_seeds_auto`` again; its closing lines print ``stop_counts`` of the table.)"""
    from loopsim import outcome_statistics

    out = str(tmp_path / "a")
    config = sweeps.SweepConfig(cases=sweeps.grid_cases([10.0], [30.0], [4], 1), t_end=3.0,
                                max_steps=150, method="rkf45", twin=False)
    targets = seeds_auto_rule.SeedTargets(min_seeds=2, max_seeds=2)

    def command():
        rows, stops = run_seeds_auto(config, out, targets, run_round=lambda c, d, w:
                                     sweeps.run_sweep(c, d, threads=1, quiet=True))
        return outcome_statistics.stop_counts(stops)["reasons"]

    assert command() == {"failed": 1}
    assert main(["sweep", "--rerun-failed", out, "--method", "radau5", "--quiet",
                 "--threads", "1"]) == 0
    capsys.readouterr()
    assert command() == {"deterministic": 1}  # the finished sweep, read back
    page = str(tmp_path / "a.html")
    assert main(["report", out, "--out", page]) == 0
    content = open(page, encoding="utf-8").read()
    assert "1: deterministic 1" in content and "failed 1" not in content
    assert loopsim.summarize(loopsim.read_results(out))["p_stable"].tolist() == [1.0]
