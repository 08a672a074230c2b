"""scripts/paper_range_study.py (issue 46): ``--quick`` keeps to a folder of its own and
never writes over the committed study; ``--read-only`` before any part has finished is
one line; the printout counts a cell whose ``steady`` is unknown apart."""
import hashlib
import os
import runpy
import shutil
import subprocess
import sys

import pandas as pd
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "scripts", "paper_range_study.py")
COMMITTED = [os.path.join(ROOT, "data", "paper_range_summary.parquet"),
             os.path.join(ROOT, "data", "paper_range_stops.parquet"),
             os.path.join(ROOT, "docs", "figures", "paper_range.png")]


def study():
    return runpy.run_path(SCRIPT)


def digests(paths):
    return [hashlib.sha256(open(p, "rb").read()).hexdigest() for p in paths]


def test_quick_writes_under_its_own_folder_by_default(monkeypatch):
    """Issue 46.3: --quick wrote data/paper_range_*.parquet and docs/figures/paper_range.png,
    the committed study, with exit 0 and no warning."""
    monkeypatch.chdir(ROOT)
    args = study()["parse_args"](["--quick"])
    quick = os.path.join("runs", "paper_range_quick")
    assert (args.runs, args.data, args.figure) == (
        quick, quick, os.path.join(quick, "paper_range.png"))
    full = study()["parse_args"]([])
    assert (full.runs, full.data, full.figure) == (
        "runs", "data", os.path.join("docs", "figures", "paper_range.png"))


def test_quick_refuses_to_write_over_the_committed_study(tmp_path, monkeypatch):
    """Run where a checkout's committed files lie (here copies of them, so that the test
    cannot damage the repository's own should the refusal ever fail): --quick pointed at
    them is one line, exit 2, before any sweep; the repository's own are refused too."""
    work = tmp_path / "checkout"
    copies = [str(work / os.path.relpath(p, ROOT)) for p in COMMITTED]
    for path, copy in zip(COMMITTED, copies):
        os.makedirs(os.path.dirname(copy), exist_ok=True)
        shutil.copy(path, copy)
    before = digests(copies)
    for given in (["--data", "data"], ["--figure", os.path.join("docs", "figures",
                                                                "paper_range.png")]):
        done = subprocess.run([sys.executable, SCRIPT, "--quick", "--runs", str(tmp_path / "r"),
                               *given], cwd=work, capture_output=True, text=True, timeout=600)
        assert done.returncode == 2, (given, done.stderr)
        err = done.stderr.strip().splitlines()
        assert len(err) == 1 and "committed study" in err[0] and "Traceback" not in done.stderr
        assert not (tmp_path / "r").exists()  # refused before any sweep
    assert digests(copies) == before
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError, match="committed study"):
        study()["parse_args"](["--quick", "--data", os.path.join(ROOT, "data")])


def test_read_only_with_no_finished_part_is_one_line(tmp_path):
    """Issue 46.9: it ended in a traceback (pandas' "No objects to concatenate")."""
    done = subprocess.run([sys.executable, SCRIPT, "--read-only", "--runs", str(tmp_path / "r"),
                           "--data", str(tmp_path / "d"), "--figure", str(tmp_path / "f.png")],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode != 0
    err = done.stderr.strip().splitlines()
    assert len(err) == 1 and "no part has finished" in err[0], done.stderr
    assert sorted(os.listdir(tmp_path)) == []  # nothing written


def test_the_printout_counts_unknown_steady_cells_apart():
    """Issue 46.4: a cell run with --no-early-stop has steady <NA> (unknown), never "all
    seeds moving"."""
    table = pd.DataFrame(dict(g0=[10.0, 60.0, 150.0], theta0_deg=30.0, seeds=[4, 4, 8],
                              steady=pd.array([4, 3, pd.NA], dtype="Int64")))
    lines = study()["steady_lines"](table)
    assert lines[0].endswith("1; runs not steady: 1 of 8"), lines
    assert lines[1] == "  (60.0, 30°): 1 of 4"
    assert lines[2].endswith("unknown (run with --no-early-stop: no run tested): 1")


def test_the_top_parts_are_the_cells_the_study_left_out():
    """--top's parts cover the paper's 225-cell grid together with the study's, each cell
    once: the 72 cells with g0 > 150 and θ0 >= 24° outside g0 = 155.7-228.6 at 24-72°."""
    names = study()
    cells = [(round(g, 6), round(t, 6)) for parts in (names["PARTS"], names["TOP_PARTS"])
             for _, g0, theta0 in parts for g in g0 for t in theta0]
    top = [(round(g, 6), round(t, 6)) for _, g0, theta0 in names["TOP_PARTS"]
           for g in g0 for t in theta0]
    assert len(cells) == len(set(cells)) == 225 and len(top) == 72
    assert all(g > 150 and t >= 24 and not (g < 230 and t <= 72) for g, t in top)


def test_top_keeps_its_sweeps_and_tables_apart(monkeypatch):
    """--top writes its sweeps under data/paper_range_runs (committed, so that it resumes
    elsewhere) and tables and figure of its own; --parts picks the parts to run (the tables
    still cover every finished part, so a partial run never shrinks them), an unknown one
    is a one-line error with exit status 2 before any sweep."""
    monkeypatch.chdir(ROOT)
    names = study()
    args = names["parse_args"](["--top", "--parts", "paper_range_top78"])
    assert (args.runs, args.data) == (os.path.join("data", "paper_range_runs"), "data")
    assert args.summary_file == "paper_range_top_summary.parquet"
    assert args.figure == os.path.join("docs", "figures", "paper_range_top.png")
    parts, to_run = names["selected_parts"](args)
    assert to_run == {"paper_range_top78"}  # runs one part; tabulates every finished one
    assert [p[0] for p in parts] == [p[0] for p in names["TOP_PARTS"]]
    done = subprocess.run([sys.executable, SCRIPT, "--top", "--parts", "paper_range_low"],
                          capture_output=True, text=True, timeout=300, cwd=ROOT)
    err = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(err) == 1 and "paper_range_low" in err[0], done.stderr


def _checkout_with_one_finished_part(tmp_path):
    """A checkout's committed tables and figure (copies: the test cannot damage the
    repository's own) and a --runs folder holding one finished part (the committed
    paper_range_top78 sweep under a main part's name, paper_range_mid30)."""
    work = tmp_path / "checkout"
    for path in COMMITTED:
        copy = work / os.path.relpath(path, ROOT)
        os.makedirs(copy.parent, exist_ok=True)
        shutil.copy(path, copy)
    runs = tmp_path / "R"
    shutil.copytree(os.path.join(ROOT, "data", "paper_range_runs", "paper_range_top78"),
                    runs / "paper_range_mid30")
    return work, runs, [str(work / os.path.relpath(p, ROOT)) for p in COMMITTED]


@pytest.mark.parametrize("given", [["--read-only"], ["--read-only", "--parts", "paper_range_mid30"],
                                   ["--read-only", "--data", "elsewhere"]])
def test_a_partial_run_never_shrinks_the_committed_tables(tmp_path, given):
    """Issue 54.2: --read-only --runs R (or --parts) with one finished part in R exited 0
    and rewrote data/paper_range_summary.parquet (153 cells down to the part's), the stops
    table and docs/figures/paper_range.png.  Now one line, exit 2, nothing written; with
    --data elsewhere the default --figure (the committed one, drawing 153 cells) is refused."""
    work, runs, copies = _checkout_with_one_finished_part(tmp_path)
    before = digests(copies)
    done = subprocess.run([sys.executable, SCRIPT, "--runs", str(runs), *given], cwd=work,
                          capture_output=True, text=True, timeout=300)
    err = done.stderr.strip().splitlines()
    assert done.returncode == 2, done.stdout + done.stderr
    assert len(err) == 1 and "of the 153 cells" in err[0] and "Traceback" not in done.stderr
    assert digests(copies) == before
    assert not (work / "elsewhere").exists()


def test_a_partial_run_tabulates_where_it_is_told(tmp_path):
    """The refusal's advice works: with --data and --figure elsewhere the finished part is
    tabulated (12 cells), and tabulating it again there is no shrink."""
    work, runs, copies = _checkout_with_one_finished_part(tmp_path)
    before = digests(copies)
    command = [sys.executable, SCRIPT, "--read-only", "--runs", str(runs), "--data",
               str(tmp_path / "d"), "--figure", str(tmp_path / "f.png")]
    for _ in range(2):
        done = subprocess.run(command, cwd=work, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
    assert len(pd.read_parquet(tmp_path / "d" / "paper_range_summary.parquet")) == 12
    assert (tmp_path / "f.png").is_file() and digests(copies) == before
