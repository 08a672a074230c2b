"""scripts/range_overview.py: one row per cell of the paper's grid, each from the committed
study that answers it best, checked against the sources it reads; its refusal to forget a
cell."""
import os
import shutil
import subprocess
import sys

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import loopsim
from loopsim import columns, outcome_statistics
from loopsim.intervals import wilson_interval
from loopsim.stability import rest_window

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "scripts", "range_overview.py")
DATA = os.path.join(ROOT, "data")
WINDOW_N = 8


#: The committed sources as they stood before the range sweeps below 36° and above it
#: ran (a data folder of links): the tests below then see every kind of cell (run to
#: rest, at t = 10, from an unfinished part, never run) whatever the study has reached.
FROZEN_REST_RUNS = ("rest_t18_326", "rest_t18_350", "rest_t24_350", "rest_t60_253",
                    "range_rest_t36")


@pytest.fixture(scope="module")
def frozen(tmp_path_factory):
    data = tmp_path_factory.mktemp("frozen") / "data"
    (data / "rest_runs").mkdir(parents=True)
    for name in ("paper_range_summary.parquet", "paper_range_top_summary.parquet",
                 "paper_range_runs"):
        (data / name).symlink_to(os.path.join(DATA, name))
    for name in FROZEN_REST_RUNS:
        (data / "rest_runs" / name).symlink_to(os.path.join(DATA, "rest_runs", name))
    return str(data)


def run(out, figure, data=DATA):
    return subprocess.run([sys.executable, SCRIPT, "--data", data, "--out", str(out),
                           "--figure", str(figure), "--window-n", str(WINDOW_N)],
                          capture_output=True, text=True, cwd=ROOT)


@pytest.fixture(scope="module")
def overview(tmp_path_factory, frozen):
    where = tmp_path_factory.mktemp("overview")
    out, figure = where / "overview.parquet", where / "overview.png"
    done = run(out, figure, frozen)
    assert done.returncode == 0, done.stderr
    return dict(table=pd.read_parquet(out), out=out, figure=figure, data=frozen)


def cell(table, g0, theta0):
    rows = table[np.isclose(table["g0"], g0) & np.isclose(table["theta0_deg"], theta0)]
    assert len(rows) == 1
    return rows.iloc[0]


def test_every_cell_once_with_declared_columns(overview):
    table = overview["table"]
    assert len(table) == 225 and not table.duplicated(["g0", "theta0_deg"]).any()
    assert list(table.columns) == list(columns.RANGE_OVERVIEW_COLUMNS)
    fields = pq.read_schema(overview["out"])
    assert all(fields.field(c).metadata[b"unit"] for c in table.columns)
    assert overview["figure"].stat().st_size > 0
    # the pooled survival of the cells run to rest, beside the figure unless given
    assert (overview["figure"].parent / "range_survival.png").stat().st_size > 0
    known = table[table["seeds"] > 0]
    assert set(known["t_max"]) <= {10.0, 40.0}
    assert ((known["p_not_rest_t10_low"] <= known["p_not_rest_t10"])
            & (known["p_not_rest_t10"] <= known["p_not_rest_t10_high"])).all()


def test_a_cell_at_the_papers_horizon_is_its_t10_table_row(overview):
    source = pd.read_parquet(os.path.join(DATA, "paper_range_summary.parquet"))
    mine = cell(overview["table"], 252.857142857, 6.0)   # q0 = 8.81: slow to decay
    theirs = source[np.isclose(source["g0"], 252.857142857) & (source["theta0_deg"] == 6.0)]
    theirs = theirs.iloc[0]
    assert mine["source"] == "data/paper_range_summary.parquet" and mine["t_max"] == 10.0
    assert mine["p_stable"] == theirs["p_stable"] and mine["seeds"] == theirs["seeds"]
    moving = int(theirs["seeds"] - theirs["steady"])
    assert mine["p_not_rest_t10"] == moving / theirs["seeds"]
    assert (mine["p_not_rest_t10_low"], mine["p_not_rest_t10_high"]) == pytest.approx(
        wilson_interval(moving, int(theirs["seeds"])))


def test_a_cell_run_to_rest_is_its_largest_sample(overview):
    """(350, 18°) is in the t = 10 table (8 seeds) and the run-to-rest study (16): the
    latter answers it, recomputed here from its runs."""
    rows = loopsim.read_results(os.path.join(DATA, "rest_runs", "rest_t18_350"))
    mine = cell(overview["table"], 350.0, 18.0)
    assert mine["source"] == "data/rest_runs/rest_t18_350" and mine["seeds"] == len(rows) == 16
    stats = outcome_statistics.summarize(
        rows, rest_window=rest_window.stability_losses(WINDOW_N)).iloc[0]
    assert mine["t_max"] == 40.0 and mine["p_3d"] == stats["p_3d"]
    assert mine["p_not_rest_t10"] == pytest.approx(1.0 - stats["p_rest_t10"])
    assert mine["at_rest"] == int(rows["stop_reason"].eq("steady").sum())
    assert mine["rest_inside"] + mine["rest_below"] + mine["rest_outside"] == mine["at_rest"]


def test_a_cell_never_run_is_empty_not_zero(overview):
    table = overview["table"]
    empty = table[table["seeds"] == 0]
    assert len(empty) == 44   # g0 = 252.9-350 at 42-90° but (252.9, 60°), before their sweeps
    assert (empty["source"] == "").all() and empty["p_3d"].isna().all()
    assert empty["p_not_rest_t10"].isna().all() and empty["at_rest"].isna().all()


def test_refuses_to_forget_a_known_cell(overview, tmp_path):
    table = overview["table"].copy()
    gone = table.index[table["seeds"] == 0][0]
    table.loc[gone, "seeds"] = 8       # a cell this run does not know
    out = tmp_path / "overview.parquet"
    pq.write_table(pa.Table.from_pandas(table, preserve_index=False).replace_schema_metadata(
        pq.read_schema(overview["out"]).metadata), out)   # an overview knowing one more cell
    done = run(out, tmp_path / "figure.png", overview["data"])
    assert done.returncode == 2 and "knows" in done.stderr and len(done.stderr.splitlines()) == 1
    assert pd.read_parquet(out)["seeds"].loc[gone] == 8 and not (tmp_path / "figure.png").exists()
    assert not (tmp_path / "range_survival.png").exists()


def test_refuses_to_write_over_another_kind_of_table(tmp_path):
    """The review's case: a copy of one of its own inputs at --out has the same cells, and
    was replaced."""
    out = tmp_path / "top.parquet"
    shutil.copy(os.path.join(DATA, "paper_range_top_summary.parquet"), out)
    before = out.read_bytes()
    done = run(out, tmp_path / "figure.png")
    assert done.returncode == 2 and "not a range overview" in done.stderr, done.stderr
    assert out.read_bytes() == before and not (tmp_path / "figure.png").exists()


def test_unfinished_parts_give_their_finished_rounds(overview):
    """A cell of the unfinished --seeds auto part at 24-30 deg is answered by its finished
    rounds only: (350, 30) by its two (8 seeds), (277.1, 30) by its first (4: its second
    round has 2 of 4 seeds)."""
    table = overview["table"]
    part = os.path.join(DATA, "paper_range_runs", "paper_range_top24")
    first = loopsim.read_results(os.path.join(part, "round-00"))
    for g0, seeds in ((350.0, 8), (277.142857143, 4)):
        row = cell(table, g0, 30.0)
        assert row["source"] == "data/paper_range_runs/paper_range_top24 (unfinished)"
        assert row["seeds"] == seeds and row["t_max"] == 10.0
    rows = first[np.isclose(first["g0"], 277.142857143) & (first["theta0_deg"] == 30.0)]
    moving = int((rows["stop_reason"] != "steady").sum())
    assert cell(table, 277.142857143, 30.0)["p_not_rest_t10"] == pytest.approx(moving / len(rows))


@pytest.mark.parametrize("bad", [["--data", "no-such-folder"], ["--window-n", "2"],
                                 ["--figure", "FILE/overview.png"]])
def test_bad_input_is_one_line_and_writes_nothing(tmp_path, bad):
    blocker = tmp_path / "FILE"
    blocker.write_text("")     # a file where a folder should be
    out, figure = tmp_path / "overview.parquet", tmp_path / "overview.png"
    argv = ["--data", DATA, "--out", str(out), "--figure", str(figure), "--window-n", "8"]
    for option, value in zip(bad[::2], bad[1::2]):
        argv[argv.index(option) + 1] = value.replace("FILE", str(blocker))
    done = subprocess.run([sys.executable, SCRIPT, *argv], capture_output=True, text=True,
                          cwd=str(tmp_path))
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith("range_overview: error:") and len(done.stderr.splitlines()) == 1
    assert sorted(os.listdir(tmp_path)) == ["FILE"]
