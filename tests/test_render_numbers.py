"""The measured numbers the pages quote are the committed tables' (scripts/render_numbers.py):
every marked span of README.md and docs/ equals what its function computes from data/, a
page that disagrees or names no such number fails, and the numbers are where the pages
need them (the n = 6 grid's counts, the settings at the top of the range)."""
import importlib.util
import os
import re

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def render_numbers():
    spec = importlib.util.spec_from_file_location(
        "render_numbers", os.path.join(ROOT, "scripts", "render_numbers.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


RENDER = render_numbers()


def page(name):
    with open(os.path.join(ROOT, name), encoding="utf-8") as handle:
        return handle.read()


def test_every_marked_number_is_its_tables():
    values = RENDER.numbers()
    problems = {name: RENDER.rendered(page(name), values)[1] for name in RENDER.pages()}
    problems = {name: found for name, found in problems.items() if found}
    assert not problems, f"{problems}: run python scripts/render_numbers.py"


def test_the_check_exits_1_on_a_stale_page_and_names_the_span():
    values = {"n6.3d": "172"}
    text = "3D <!-- num:n6.3d -->171<!-- /num --> and <!-- num:nothing -->1<!-- /num -->"
    new, problems = RENDER.rendered(text, values)
    assert new == "3D <!-- num:n6.3d -->172<!-- /num --> and <!-- num:nothing -->1<!-- /num -->"
    assert problems == ["n6.3d: the page says '171', the table '172'", "nothing: no such number"]


def test_the_n6_counts_are_the_committed_tables():
    """Independently of the script: the regime counts of data/phase_n6_cases.parquet, as the
    settings guide states them."""
    import pandas as pd

    frame = pd.read_parquet(os.path.join(ROOT, "data", "phase_n6_cases.parquet"))
    counts = frame["regime"].value_counts()
    text = page(os.path.join("docs", "choosing-n-method-rtol.md"))
    for key, regime in (("n6.3d", "3d"), ("n6.in-plane", "in-plane"), ("n6.stable", "stable")):
        shown = re.search(rf"<!-- num:{re.escape(key)} -->(\d+)<!-- /num -->", text).group(1)
        assert int(shown) == counts[regime], key
    assert len(frame) == 225 and set(frame["n"]) == {6} and set(frame["method"]) == {"rkf45"}
    assert "move with rounding" in text


def test_the_pages_mark_what_they_quote_from_the_tables():
    """The numbers that drifted from their tables are marked, so the check covers them."""
    keys = {name: set(re.findall(r"<!-- num:([\w.\-]+) -->", page(name))) for name in RENDER.pages()}
    assert {"n6.3d", "n6.in-plane", "n6.unresolved"} <= keys[os.path.join("docs", "choosing-n-method-rtol.md")]
    assert {"top.sample-median", "top.n-used"} <= keys[os.path.join("docs", "choosing-n-method-rtol.md")]
    assert {"n6.3d-tilt-quartiles", "n6.steady", "n6.3d-circles"} <= keys[
        os.path.join("docs", "studies", "paper-comparison.md")]
    assert {"grid.cost-stable", "top.sample-median"} <= keys["README.md"]


def test_the_pooled_counts_are_the_overviews():
    """Independently of the pooled group: its loops and loops at rest are the sums over
    the cells the range overview (data/paper_range_overview.parquet) has run to rest, and
    its cells split the overview's known cells with those at t = 10."""
    import pandas as pd

    values = RENDER.numbers()
    overview = pd.read_parquet(os.path.join(ROOT, "data", "paper_range_overview.parquet"))
    rest = overview[overview["t_max"] > 10]
    observed = (rest["seeds"] - (rest["p_failed"] * rest["seeds"]).round()).sum()
    assert values["range.pooled-loops"] == RENDER.count(observed)
    assert values["range.pooled-at-rest"] == RENDER.count(rest["at_rest"].sum())
    assert values["range.pooled-cells"] == values["range.rest-cells"] == RENDER.count(len(rest))
    assert int(values["range.known"]) == (int(values["range.rest-cells"])
                                          + int(values["range.horizon-cells"]))
    left = values["range.pooled-left"]
    moving = int(observed - rest["at_rest"].sum())
    assert (left == "none") if moving == 0 else left.count("seed") == moving


def test_no_loop_run_to_rest_tumbles_at_its_end():
    """README.md and docs/studies/rest.md say none tumbles for good: a loop still moving
    at t = 40 is quiet (approaching its rest too slowly for the steady test), never
    unsteady."""
    rows = RENDER._rest_samples()
    assert set(rows.loc[rows["stop_reason"].eq("t_end"), "terminal_state"]) <= {"quiet"}


def test_the_regime_shares_the_study_page_says_stand_do():
    """docs/studies/rest.md says the regime probabilities at t = 10 stand: the pooled
    differences at rest minus at t = 10, and each cell's, have 0 inside their intervals."""
    values = RENDER.numbers()
    for regime in ("3d", "in-plane"):
        shown = values[f"range.t10-vs-rest-{regime}"]
        low, high = (float(v) for v in re.search(r"\[([-+\d.]+), ([-+\d.]+)\]", shown).groups())
        assert low <= 0.0 <= high, shown
    for row in values["range.t10-vs-rest-table"].strip().splitlines()[2:]:
        low, high = (float(v) for v in re.search(r"\| [-+\d.]+ \[([-+\d.]+), ([-+\d.]+)\] \|",
                                                 row).groups())
        assert low <= 0.0 <= high, row


def test_the_range_progress_is_the_range_summarys():
    import pandas as pd

    summary = pd.read_parquet(os.path.join(ROOT, "data", "paper_range_rest_summary.parquet"))
    done = RENDER.numbers()["range.rest-rows-done"]
    assert done == ", ".join(f"{t:.0f}°" for t in sorted(summary["theta0_deg"].unique()))


def test_a_key_defined_twice_is_refused(monkeypatch):
    monkeypatch.setattr(RENDER, "GROUPS", (lambda: {"a": "1"}, lambda: {"a": "2"}))
    RENDER.numbers.cache_clear()
    try:
        with pytest.raises(AssertionError, match="redefines"):
            RENDER.numbers()
    finally:
        RENDER.numbers.cache_clear()


def test_the_horizon_comparison_pools_only_cells_with_equal_seeds(tmp_path, monkeypatch):
    """Three cells at t = 10 and to rest: the one with 4 seeds at t = 10 is in the per-cell
    table but not in the pooled counts; a cell only at t = 10 is in neither; the pooled
    interval is Newcombe's of the summed counts; g0 pairs up whatever its last bits."""
    from loopsim import distribution_differences as dd
    import pandas as pd

    ten = pd.DataFrame({"g0": [300.0, 300.0, 350.0, 325.7142857142857],
                        "theta0_deg": [6.0, 12.0, 6.0, 12.0], "seeds": [4, 8, 8, 8],
                        "p_in_plane": [1.0, 0.25, 0.5, 0.5], "p_3d": [0.0, 0.75, 0.5, 0.5],
                        "tilt_median": [30.0, 40.0, 50.0, 60.0]})
    rest = pd.DataFrame({"g0": [300.0, 300.0, 325.71428571428567],
                         "theta0_deg": [6.0, 12.0, 12.0], "seeds": [8, 8, 8],
                         "p_in_plane": [0.5, 0.0, 0.375], "p_3d": [0.5, 1.0, 0.625],
                         "tilt_median": [10.0, 20.0, 30.0]})
    ten.to_parquet(tmp_path / "paper_range_summary.parquet")
    rest.to_parquet(tmp_path / "paper_range_rest_summary.parquet")
    monkeypatch.setattr(RENDER, "DATA", str(tmp_path))
    out = RENDER._range_horizon_regimes()
    assert out["range.t10-vs-rest-cells"] == "3"
    low, high = dd.newcombe_interval(10, 16, 13, 16)
    assert out["range.t10-vs-rest-3d"] == f"10 → 13 of 16: +0.19 [{low:+.2f}, {high:+.2f}]"
    assert out["range.t10-vs-rest-in-plane"].startswith("6 → 3 of 16: -0.19 [")
    assert out["range.t10-vs-rest-3d-detectable"] == (
        f"{dd.detectable_probability_difference(10 / 16, 16, 16):.2f}")
    table = out["range.t10-vs-rest-table"]
    assert "| (300.0, 6°) | 4 / 8 |" in table and "(350.0, 6°)" not in table
    assert "| 0.75 / 1.00 | +0.25 [" in table and "| 40.0 / 20.0 |" in table
