"""Outcomes as distributions (loopsim.outcome_statistics): the Wilson interval and the bootstrap
against closed forms and known cases, cells and their counts, the command."""
import json

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import loopsim
from loopsim import columns, outcome_statistics
from loopsim.cli import main


def test_wilson_interval_closed_forms():
    z = outcome_statistics.Z95
    assert outcome_statistics.wilson_interval(0, 10) == pytest.approx((0.0, z * z / (10 + z * z)))
    assert outcome_statistics.wilson_interval(10, 10) == pytest.approx((10 / (10 + z * z), 1.0))
    low, high = outcome_statistics.wilson_interval(5, 10)
    assert low + high == pytest.approx(1.0) and high - low == pytest.approx(
        2 * z * np.sqrt(0.25 / 10 + z * z / 400) / (1 + z * z / 10))
    # a textbook value: 8 of 20 gives (0.2188, 0.6134) to four places
    assert outcome_statistics.wilson_interval(8, 20) == pytest.approx((0.2188, 0.6134), abs=1e-4)
    assert all(np.isnan(outcome_statistics.wilson_interval(0, 0)))


def test_bootstrap_interval_is_seeded_and_covers_the_median():
    assert outcome_statistics.bootstrap_interval(np.full(9, 3.5)) == (3.5, 3.5)
    rng = np.random.default_rng(1)
    sample = rng.normal(10.0, 2.0, 200)
    first = outcome_statistics.bootstrap_interval(sample, seed=7)
    assert first == outcome_statistics.bootstrap_interval(sample, seed=7)  # reproducible
    assert first != outcome_statistics.bootstrap_interval(sample, seed=8)
    # the median's standard error is about 1.2533 sigma / sqrt(N) = 0.177: the 95 %
    # interval spans about 4 of them
    assert first[0] < np.median(sample) < first[1]
    assert 0.4 < first[1] - first[0] < 1.1
    covered = sum(lo < 10.0 < hi for lo, hi in (
        outcome_statistics.bootstrap_interval(rng.normal(10.0, 2.0, 50), seed=k, resamples=500)
        for k in range(100)))
    assert 85 <= covered <= 100


def naive_wilson(successes, trials, z=outcome_statistics.Z95):
    """The Wilson score interval written out (no continuity correction): the formula the
    module docstring gives, as loopsim computed it by hand before issue 55."""
    p = successes / trials
    centre = (p + z * z / (2 * trials)) / (1 + z * z / trials)
    half = z * np.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials)) / (1 + z * z / trials)
    return max(0.0, centre - half), min(1.0, centre + half)


def naive_bootstrap_draws(values, statistic, resamples, seed):
    """Resamples with replacement from default_rng(seed), the statistic of each."""
    rng = np.random.default_rng(seed)
    return statistic(values[rng.integers(0, values.size, size=(resamples, values.size))], axis=1)


def test_wilson_interval_is_the_score_interval_without_continuity_correction():
    """scipy's ``method="wilson"`` is the formula of the docstring to 1e-12 for every
    count up to 128 trials (measured: 3.3e-16 at most), and not the continuity-corrected
    ``wilsoncc``."""
    from scipy.stats import binomtest

    worst = max(max(abs(a - b) for a, b in zip(outcome_statistics.wilson_interval(k, n),
                                                naive_wilson(k, n)))
                for n in range(1, 129) for k in range(n + 1))
    assert worst < 1e-12
    corrected = binomtest(3, 16).proportion_ci(0.95, method="wilsoncc")
    assert abs(corrected.low - outcome_statistics.wilson_interval(3, 16)[0]) > 1e-3


def test_bootstrap_interval_is_the_percentile_of_the_seeded_resamples():
    """The percentile bootstrap through scipy resamples exactly as default_rng(seed) with
    ``integers`` does (the same draws, bit for bit) and reads their 2.5 and 97.5
    percentiles (to 1e-12 relative: the interpolation rounds differently); one value
    is its own interval."""
    rng = np.random.default_rng(3)
    for size in (2, 5, 16, 64):
        values = rng.normal(30.0, 20.0, size)
        draws = naive_bootstrap_draws(values, np.median, 2000, seed=size)
        low, high, drawn = outcome_statistics.percentile_bootstrap([values], np.median, 2000,
                                                                   seed=size)
        assert np.array_equal(drawn, draws)
        expected = np.percentile(draws, [2.5, 97.5])
        assert outcome_statistics.bootstrap_interval(values, seed=size) == pytest.approx(
            tuple(expected), rel=1e-12)
        assert (low, high) == outcome_statistics.bootstrap_interval(values, seed=size)
    assert outcome_statistics.bootstrap_interval([4.25]) == (4.25, 4.25)
    assert all(np.isnan(outcome_statistics.bootstrap_interval([np.nan])))


def test_wasserstein_interval_takes_a_one_value_sample():
    """A sample of one value is held fixed (scipy's bootstrap needs two): the interval is
    the other sample's resampled distances to it."""
    distance, low, high = outcome_statistics.wasserstein_interval([10.0], [9.0, 11.0, 12.0],
                                                                  resamples=200)
    assert distance == pytest.approx(4.0 / 3.0)
    assert 1.0 <= low <= distance <= high <= 2.0


def test_summarize_groups_seeds_into_cells():
    rows = []
    for g0 in (30.0, 150.0):
        for seed in range(8):
            regime = "stable" if g0 < 100 else ("3d" if seed % 4 else "in-plane")
            rows.append(dict(g0=g0, theta0_deg=60.0, n=6, seed=seed, rtol=1e-6, regime=regime,
                             resolved=True, determined=seed != 3,
                             theta_final_deg=60.0 if g0 < 100 else 20.0 + seed,
                             aspect_ratio=1.0 + seed / 100, nfev=100, twin_nfev=150,
                             wall_s=0.5,
                             stop_reason="t_end" if (g0 > 100 and seed == 5) else "steady"))
    table = outcome_statistics.summarize(pd.DataFrame(rows))
    assert list(table["g0"]) == [30.0, 150.0] and "n" not in table and "seed" not in table
    stable, hot = table.iloc[0], table.iloc[1]
    assert stable["seeds"] == 8 and stable["p_stable"] == 1.0 and stable["determined"] == 7
    assert stable["p_stable_low"] == pytest.approx(8 / (8 + outcome_statistics.Z95 ** 2))
    assert hot["p_3d"] == 0.75 and hot["p_in_plane"] == 0.25 and hot["p_failed"] == 0.0
    assert hot["tilt_median"] == 23.5 and hot["tilt_q25"] == 21.75
    assert hot["tilt_median_low"] <= 23.5 <= hot["tilt_median_high"]
    assert hot["nfev"] == 800 and hot["wall_s"] == 4.0
    assert stable["steady"] == 8 and hot["steady"] == 7  # seed 5 still moving at t_end
    frame = pd.DataFrame(rows)
    frame.attrs["loopsim"] = dict(sweep_config=dict(early_stop=False))  # --no-early-stop
    assert outcome_statistics.summarize(frame)["steady"].isna().all()  # unknown, not 0 (issue 46.4)
    frame.attrs["loopsim"] = dict(sweep_config=dict(early_stop=True))
    assert outcome_statistics.summarize(frame)["steady"].tolist() == [8, 7]
    with pytest.raises(ValueError, match="no column"):
        outcome_statistics.summarize(pd.DataFrame(rows), by=["colour"])


def test_summary_command_on_a_sweep_with_seeds(tmp_path, capsys):
    out = tmp_path / "s"
    assert main(["sweep", "--n", "6", "--g0", "10,40", "--theta0", "30", "--seeds", "3", "--t-end", "0.5",
                 "--no-twin", "--quiet", "--out", str(out)]) == 0
    capsys.readouterr()
    path = tmp_path / "cells" / "outcome_statistics.parquet"
    assert main(["summary", str(out), "--out", str(path)]) == 0
    printed = capsys.readouterr().out
    assert "p_stable" in printed and f"table: {path}" in printed
    table = pd.read_parquet(path)
    assert list(table["g0"]) == [10.0, 40.0] and list(table["seeds"]) == [3, 3]
    again = loopsim.summarize(loopsim.read_results(str(out)))
    assert again["determined"].isna().all()   # --no-twin: unknown, and empty in Parquet
    # (a count with unknowns, Int64 here, reads back from Parquet as float with NaN)
    pd.testing.assert_frame_equal(table, again.astype({"determined": "float64"}))
    schema = pq.read_schema(path)
    for field in schema:  # every column declared in loopsim.columns, with its unit
        assert field.metadata[b"unit"] == columns.SUMMARY_COLUMNS[field.name][0].encode()
    assert schema.metadata[b"summary_of"] == b"s"  # the directory's name, not its path


def _seeds_table(tilts, regimes=None, g0=150.0):
    return pd.DataFrame(dict(g0=g0, theta0_deg=60.0, seed=np.arange(len(tilts)),
                             theta_final_deg=tilts, aspect_ratio=2.0 + np.asarray(tilts) / 100,
                             regime=regimes if regimes is not None else ["3d"] * len(tilts)))


def test_compare_verdicts_on_one_distribution_and_on_shifted_ones():
    rng = np.random.default_rng(3)
    same_a, same_b = rng.normal(20, 5, 40), rng.normal(20, 5, 40)
    shifted = rng.normal(30, 5, 40)
    same = outcome_statistics.compare(_seeds_table(same_a), _seeds_table(same_b))
    assert same["verdict"].tolist() == [outcome_statistics.SAME]
    assert same["tilt_ks_p"].iloc[0] > 0.05 and same["seeds_a"].iloc[0] == 40
    low, high = same[["tilt_wasserstein_low", "tilt_wasserstein_high"]].iloc[0]
    assert low <= same["tilt_wasserstein"].iloc[0] <= high
    different = outcome_statistics.compare(_seeds_table(same_a), _seeds_table(shifted))
    assert different["verdict"].tolist() == [outcome_statistics.DIFFERENT]
    assert different["tilt_ks_p"].iloc[0] < 1e-4
    assert 7 < different["tilt_wasserstein"].iloc[0] < 13  # the shift is 10
    # regimes alone: the same tilts, but half the seeds in plane in one table
    regimes = outcome_statistics.compare(_seeds_table(same_a),
                              _seeds_table(same_a, ["3d", "in-plane"] * 20))
    assert regimes["regime_p"].iloc[0] < 1e-4
    assert regimes["verdict"].iloc[0] == outcome_statistics.DIFFERENT
    with pytest.raises(ValueError, match="share no cell"):
        outcome_statistics.compare(_seeds_table(same_a), _seeds_table(same_b, g0=10.0))


def test_compare_command_on_two_sweeps(tmp_path, capsys):
    """rtol 1e-6 against 1e-7 on stable cells: the same distributions."""
    for name, rtol in (("a", "1e-6"), ("b", "1e-7")):
        assert main(["sweep", "--n", "6", "--g0", "10,40", "--theta0", "30", "--seeds", "4", "--t-end",
                     "0.5", "--rtol", rtol, "--no-twin", "--quiet", "--out",
                     str(tmp_path / name)]) == 0
    capsys.readouterr()
    assert main(["compare", str(tmp_path / "a"), str(tmp_path / "b"), "--out",
                 str(tmp_path / "c.parquet")]) == 0
    printed = capsys.readouterr().out
    assert "2 cell(s) indistinguishable at this sample size" in printed
    assert len(pd.read_parquet(tmp_path / "c.parquet")) == 2
    schema = pq.read_schema(tmp_path / "c.parquet")
    assert {f.name: f.metadata[b"description"].decode() for f in schema} == {
        name: columns.COMPARE_COLUMNS[name][1] for name in schema.names}
    assert json.loads(schema.metadata[b"compared"]) == ["a", "b"]
    assert main(["compare", str(tmp_path / "a"), str(tmp_path / "b"), "--alpha", "0"]) == 2


def test_summary_figures_draw_every_cell():
    import matplotlib
    matplotlib.use("Agg")
    from loopsim import figures

    rows = []
    for g0 in (30.0, 150.0):
        for theta in (30.0, 60.0):
            for seed in range(4):
                regime = "stable" if g0 < 100 else ("3d" if seed else "in-plane")
                rows.append(dict(g0=g0, theta0_deg=theta, seed=seed, regime=regime,
                                 resolved=True, determined=not (g0 > 100 and seed == 2),
                                 q0=g0 * np.sin(np.radians(theta)) / 3,
                                 theta_final_deg=theta - (10 + seed if g0 > 100 else 0),
                                 aspect_ratio=1.5 + 0.1 * seed, nfev=1, twin_nfev=1,
                                 wall_s=0.1, q_final=g0 / 10 + seed,
                                 stop_reason="t_end" if (g0 > 100 and seed == 1) else "steady"))
    frame = pd.DataFrame(rows)
    cells = outcome_statistics.summarize(frame)
    fig = figures.probability_phase_diagram(cells, style="colour")
    marks = [c for c in fig.axes[0].collections
             if c.get_label() == "some seeds not steady at t_end"]
    assert len(marks) == 1 and len(marks[0].get_offsets()) == 2  # the two cells at g0 = 150
    no_early_stop = outcome_statistics.summarize(frame.assign(stop_reason="t_end"))
    fig = figures.probability_phase_diagram(no_early_stop, style="colour")
    assert not [c for c in fig.axes[0].collections
                if c.get_label() == "some seeds not steady at t_end"]  # no run was tested
    colours = fig.axes[0].collections[0]
    assert len(colours.get_offsets()) == 4
    np.testing.assert_allclose(colours.get_array(), cells["p_3d"])
    rings = [c for c in fig.axes[0].collections if c.get_label() == "some seeds not determined"]
    assert len(rings) == 1 and len(rings[0].get_offsets()) == 2
    assert sorted(t.get_text() for t in fig.axes[0].texts) == ["0.25", "0.25"]
    # as pies: one wedge per regime a cell reaches, clockwise from the top, filling it
    fig = figures.probability_phase_diagram(cells)
    wedges = [c for c in fig.axes[0].collections if not c.get_label().startswith("some seeds")
              and len(c.get_offsets()) == 1]
    assert len(wedges) == 1 + 1 + 2 + 2
    assert sorted(c.get_label() for c in fig.axes[0].collections
                  if not len(c.get_offsets())) == ["3D", "in-plane", "stable"]  # the legend
    verts, scale = figures.wedge_marker(0.0, np.pi / 2)
    assert scale == pytest.approx(1.0) and np.allclose(verts[1], [1, 0]) and np.allclose(
        verts[-2], [0, 1])
    _, scale = figures.wedge_marker(np.pi / 4 - 0.1, np.pi / 4 + 0.1)
    assert scale == pytest.approx(np.cos(np.pi / 4 - 0.1) ** 2)  # the marker's rescaling undone
    assert fig.axes[0].get_title() == "regime probabilities per cell over 4 seeds"
    with pytest.raises(ValueError, match="style must be"):
        figures.probability_phase_diagram(cells, style="bars")
    fig = figures.tilt_distribution(cells, frame)
    assert len(fig.axes[0].collections[0].get_offsets()) == len(frame)  # every seed, faint
    # Fig. 8 as distributions: one median per cell at its median terminal q, every seed
    # faint, over the steady branch drawn solid where stable, dashed where not
    assert list(cells["q_final_median"]) == [4.5, 4.5, 16.5, 16.5]
    np.testing.assert_allclose(cells["aspect_median"], 1.65)
    branch = pd.DataFrame(dict(q=[0.0, 5.0, 10.0], aspect_ratio=[1.0, 1.5, 2.0],
                               stable_in_plane=[True, True, False],
                               stable_out_of_plane=[True, True, True]))
    fig = figures.aspect_distribution(cells, frame, branch=branch)
    ax = fig.axes[0]
    assert len(ax.collections[0].get_offsets()) == len(frame)
    medians = [line for line in ax.lines if line.get_marker() == "o"]
    assert len(medians) == 1 and list(medians[0].get_xdata()) == list(cells["q_final_median"])
    assert {line.get_linestyle() for line in ax.lines if line.get_label().startswith(
        "steady shapes")} == {"-", "--"}
    fig = figures.distribution_summary(cells, frame, branch=branch)
    assert [a.get_title() for a in fig.axes[:3]][1:] == ["terminal tilt over seeds",
                                                        "terminal shape over seeds"]


def _model_rows(model, slenderness, tilts, g0=100.0):
    return [dict(g0=g0, theta0_deg=60.0, n=8, seed=seed, model=model, slenderness=slenderness,
                 rtol=1e-6, regime="3d", resolved=True, determined=True, theta_final_deg=tilt,
                 aspect_ratio=2.0, nfev=1, twin_nfev=0, wall_s=0.1)
            for seed, tilt in enumerate(tilts)]


def test_cells_are_kept_apart_by_model_and_slenderness():
    """Issue 36.1: rows of two slenderness values (and a local row) at one point are three
    cells, never one: the two slenderness values end at 65-79 and 15-22 degrees."""
    frame = pd.DataFrame(_model_rows("nonlocal", 1e-2, [64.9, 72.0, 79.1])
                         + _model_rows("nonlocal", 1e-3, [15.4, 18.0, 22.4])
                         + _model_rows("local", np.nan, [40.0]))
    table = outcome_statistics.summarize(frame)
    assert table.attrs["loopsim_summary"]["cells_by"] == ["g0", "theta0_deg", "model",
                                                          "slenderness"]
    assert len(table) == 3 and list(table["seeds"]) == [1, 3, 3]
    by_eps = table.set_index("slenderness")["tilt_median"]
    assert by_eps[1e-2] == 72.0 and by_eps[1e-3] == 18.0
    assert table.loc[table["model"] == "local", "tilt_median"].item() == 40.0
    # compare pairs cell with cell, the local row never merged into a nonlocal cell
    pairs = outcome_statistics.compare(
        frame, frame.assign(theta_final_deg=frame["theta_final_deg"] + 1))
    assert len(pairs) == 3 and list(pairs["seeds_a"]) == [1, 3, 3]
    # one table sweeping the slenderness, the other not: only the shared cell pairs
    other = pd.DataFrame(_model_rows("nonlocal", 1e-3, [15.0, 18.5, 22.0]))
    pairs = outcome_statistics.compare(frame, other)
    assert len(pairs) == 1 and pairs["slenderness"].item() == 1e-3


def test_a_cell_holding_one_seed_twice_is_refused():
    """Rows that differ in an input the table does not record (two initial shapes, seed 0
    each) are not one cell of two seeds."""
    frame = pd.DataFrame(_model_rows("local", np.nan, [10.0]) * 2)
    with pytest.raises(ValueError, match=r"holds seed 0 2 times"):
        outcome_statistics.summarize(frame)
    with pytest.raises(ValueError, match=r"holds seed 0 2 times"):
        outcome_statistics.compare(frame, frame)


def test_summary_figure_of_cells_sharing_a_point_is_refused_before_writing(tmp_path, capsys):
    """Two rtol at one point are two cells; one diagram cannot draw both: refused in one
    line before the table or the figure is written."""
    cases = tmp_path / "cases.csv"
    cases.write_text("g0,theta0_deg,n,seed,rtol\n10,30,4,0,1e-6\n10,30,4,0,1e-7\n")
    out = tmp_path / "s"
    assert main(["sweep", "--n", "6", "--cases", str(cases), "--t-end", "0.2", "--no-twin", "--quiet",
                 "--threads", "1", "--out", str(out)]) == 0
    capsys.readouterr()
    table, figure = tmp_path / "cells.parquet", tmp_path / "cells.png"
    assert main(["summary", str(out), "--out", str(table), "--figure", str(figure)]) == 2
    err = capsys.readouterr().err
    assert "2 cells at g0 = 10, theta0 = 30 (they differ in rtol)" in err, err
    assert not table.exists() and not figure.exists()
    assert main(["summary", str(out), "--out", str(table)]) == 0
    assert list(pd.read_parquet(table)["rtol"]) == [1e-7, 1e-6]


def test_steady_is_unknown_for_rows_never_tested_however_the_table_was_read(tmp_path, capsys):
    """Issue 54.7: summarize(pd.concat([early-stop rows, --no-early-stop rows])) counted
    the untested rows as not steady, and a --no-early-stop chunk read with
    pd.read_parquet gave steady 0 where the command line gives <NA>: each row now records
    whether it was tested (``early_stop``)."""
    grid = ["--theta0", "30", "--seeds", "2", "--n", "4", "--t-end", "0.3", "--no-twin",
            "--threads", "1", "--quiet"]
    tested, untested = str(tmp_path / "tested"), str(tmp_path / "untested")
    assert main(["sweep", "--g0", "10", *grid, "--out", tested]) == 0
    assert main(["sweep", "--g0", "40", *grid, "--no-early-stop", "--out", untested]) == 0
    capsys.readouterr()
    a, b = loopsim.read_results(tested), loopsim.read_results(untested)
    both = outcome_statistics.summarize(pd.concat([a, b], ignore_index=True))
    assert both["g0"].tolist() == [10.0, 40.0]
    assert both["steady"].iloc[0] == int(a["stop_reason"].eq("steady").sum())
    assert pd.isna(both["steady"].iloc[1])  # never tested: unknown, not 0
    plain = outcome_statistics.summarize(pd.read_parquet(untested))
    assert plain.attrs["loopsim_summary"] and pd.isna(plain["steady"].iloc[0])
    assert main(["summary", untested]) == 0
    assert pd.isna(outcome_statistics.summarize(b)["steady"].iloc[0])
    assert a["early_stop"].tolist() == [True, True] and b["early_stop"].tolist() == [False] * 2


def test_determined_is_unknown_where_no_row_ran_a_twin(tmp_path, capsys):
    """Audit L6: a --no-twin sweep's cells read "determined 0" (every seed undetermined,
    ringed red in the phase diagram) although no twin ran; unknown is <NA>, and a cell
    whose rows did run twins still counts them."""
    grid = ["--theta0", "30", "--seeds", "2", "--n", "4", "--t-end", "0.3", "--threads", "1",
            "--quiet"]
    alone, twinned = str(tmp_path / "alone"), str(tmp_path / "twinned")
    assert main(["sweep", "--g0", "10", *grid, "--no-twin", "--out", alone]) == 0
    assert main(["sweep", "--g0", "40", *grid, "--out", twinned]) == 0
    capsys.readouterr()
    a, b = loopsim.read_results(alone), loopsim.read_results(twinned)
    both = outcome_statistics.summarize(pd.concat([a, b], ignore_index=True))
    assert pd.isna(both["determined"].iloc[0]) and str(both["determined"].dtype) == "Int64"
    assert both["determined"].iloc[1] == int(b["determined"].eq(True).sum()) == 2
    assert outcome_statistics.summarize(b)["determined"].dtype == np.int64  # all known
    counts = outcome_statistics.outcome_counts(a)
    assert counts["twinned"] == 0 and outcome_statistics.undetermined_text(counts).startswith(
        "not checked (unknown)")
    mixed = outcome_statistics.outcome_counts(pd.concat([a, b], ignore_index=True))
    assert outcome_statistics.undetermined_text(mixed).endswith(
        "of the 2 of 4 cases with a twin")
    import matplotlib

    matplotlib.use("Agg")
    from loopsim import figures

    labels = figures.probability_phase_diagram(both).axes[0].get_legend_handles_labels()[1]
    assert "some seeds not determined" not in labels    # (both cells: none known undetermined)
    undetermined = both.assign(determined=pd.array([pd.NA, 1], dtype="Int64"))
    labels = figures.probability_phase_diagram(undetermined).axes[0].get_legend_handles_labels()[1]
    assert "some seeds not determined" in labels
    # the review's case: a --seeds auto cell, twins in its first round only, all agreeing
    mixed = outcome_statistics.summarize(pd.concat([b, b.assign(seed=b["seed"] + 2,
                                                                determined=None)]))
    assert (mixed["seeds"].iloc[0], mixed["twinned"].iloc[0], mixed["determined"].iloc[0]) == (4, 2, 2)
    labels = figures.probability_phase_diagram(mixed).axes[0].get_legend_handles_labels()[1]
    assert "some seeds not determined" not in labels


def test_complete_cells_keeps_the_cells_whose_every_case_finished():
    """The committed partial sweep data/rest_runs/range_rest_t84 against its case list
    counted by hand: a cell is complete when its rows are as many as its cases."""
    import os

    path = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                        "data", "rest_runs", "range_rest_t84")
    frame = loopsim.read_results(path)
    with open(os.path.join(path, "_sweep.json"), encoding="utf-8") as handle:
        cases = json.load(handle)["config"]["cases"]
    wanted = {}
    for case in cases:
        key = (round(case["g0"], 6), round(case["theta0_deg"], 6))
        wanted[key] = wanted.get(key, 0) + 1
    have = frame.groupby(["g0", "theta0_deg"]).size()
    expected = {(round(g, 6), round(t, 6)) for (g, t), k in have.items()
                if k == wanted[(round(g, 6), round(t, 6))]}
    cells = outcome_statistics.complete_cells(frame)
    assert set(cells) == expected
    assert all(len(rows) == wanted[key] for key, rows in cells.items())
    bare = frame.copy()
    bare.attrs = {}
    with pytest.raises(ValueError, match="no sweep case list"):
        outcome_statistics.complete_cells(bare)
