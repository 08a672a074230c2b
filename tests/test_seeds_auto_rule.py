"""The stopping rule of ``--seeds auto`` (loopsim.seeds_auto_rule) on synthetic cells."""
import numpy as np
import pandas as pd
import pytest

from loopsim import seeds_auto_rule
from loopsim.seeds_auto_rule import CAP, CONTINUE, DETERMINISTIC, FAILED, SHARP, SeedTargets


def cell(regimes, tilts, aspects=None):
    tilts = np.asarray(tilts, float)
    aspects = np.ones_like(tilts) if aspects is None else np.asarray(aspects, float)
    return pd.DataFrame(dict(regime=list(regimes), theta_final_deg=tilts, aspect_ratio=aspects))


def test_too_few_seeds_asks_for_the_minimum():
    assert seeds_auto_rule.decide(cell(["stable"] * 2, [8.2, 8.2]), SeedTargets()) == (CONTINUE, 4)


def test_a_deterministic_cell_stops_at_the_minimum():
    rows = cell(["stable"] * 4, 8.2 + np.array([0, 1e-4, -2e-4, 3e-4]))
    assert seeds_auto_rule.decide(rows, SeedTargets()) == (DETERMINISTIC, 4)


@pytest.mark.parametrize("change", ["tilt", "aspect", "regime", "failed"])
def test_one_seed_apart_is_not_deterministic(change):
    targets = SeedTargets()
    regimes, tilts, aspects = ["in-plane"] * 4, np.full(4, 30.0), np.full(4, 2.0)
    if change == "tilt":
        tilts[2] += 2 * targets.tilt_tol_deg
    elif change == "aspect":
        aspects[1] += 2 * targets.aspect_tol
    elif change == "regime":
        regimes[3] = "3d"
    else:
        regimes[0], tilts[0], aspects[0] = "failed", np.nan, np.nan
    reason, wanted = seeds_auto_rule.decide(cell(regimes, tilts, aspects), targets)
    assert (reason, wanted) == (CONTINUE, 8)


def test_a_cell_whose_every_seed_failed_stops_as_failed_and_is_no_sample():
    """Issue 46.2: no successful run, no distribution: the cell stops after its first round
    (it went on to the cap), and its runs are not samples even though no failed run is
    "determined" (they were, so its later seeds dropped their twins and it was checked)."""
    rows = cell(["failed"] * 4, np.full(4, np.nan), np.full(4, np.nan)).assign(
        determined=False)
    assert seeds_auto_rule.decide(rows, SeedTargets()) == (FAILED, 4)
    assert seeds_auto_rule.decide(rows.iloc[:2], SeedTargets()) == (CONTINUE, 4)  # first round first
    assert not seeds_auto_rule.runs_are_samples(rows)
    one_ok = rows.assign(regime=["failed"] * 3 + ["3d"])
    assert seeds_auto_rule.decide(one_ok, SeedTargets())[0] == CONTINUE
    assert seeds_auto_rule.runs_are_samples(one_ok)


def test_a_spread_cell_doubles_until_sharp():
    rng = np.random.default_rng(1)
    targets = SeedTargets()
    sizes = []
    size = 4
    tilts = rng.normal(20.0, 3.0, 256)
    while True:
        reason, wanted = seeds_auto_rule.decide(cell(["3d"] * size, tilts[:size]), targets)
        sizes.append(size)
        if reason != CONTINUE:
            break
        size = wanted
    assert sizes == [4, 8, 16, 32, 64][:len(sizes)] and len(sizes) >= 3
    assert reason == SHARP
    p_width, tilt_width = seeds_auto_rule.widths(cell(["3d"] * size, tilts[:size]))
    assert p_width <= targets.p_halfwidth and tilt_width <= targets.tilt_halfwidth_deg
    # one round earlier it was not sharp
    p_width, tilt_width = seeds_auto_rule.widths(cell(["3d"] * (size // 2), tilts[:size // 2]))
    assert p_width > targets.p_halfwidth or tilt_width > targets.tilt_halfwidth_deg


def test_a_mixed_cell_stops_at_the_cap():
    targets = SeedTargets(max_seeds=16)
    rows = cell(["3d", "in-plane"] * 8, np.linspace(5, 60, 16))
    assert seeds_auto_rule.decide(rows, targets) == (CAP, 16)
    assert seeds_auto_rule.decide(rows.iloc[:8], targets) == (CONTINUE, 16)


def test_the_wilson_width_of_a_certain_cell_matches_its_closed_form():
    # p = 1 of N: half-width z²/(2N) / (1 + z²/N) (the interval is [1 - 2 half, 1])
    z = 1.959963984540054
    for trials in (4, 9, 16):
        p_width, _ = seeds_auto_rule.widths(cell(["stable"] * trials, np.full(trials, 8.2)))
        assert p_width == pytest.approx(z * z / (2 * trials) / (1 + z * z / trials), rel=1e-12)


@pytest.mark.parametrize("bad", [dict(p_halfwidth=0), dict(p_halfwidth=0.7),
                                 dict(tilt_halfwidth_deg=float("nan")),
                                 dict(min_seeds=1), dict(min_seeds=8, max_seeds=4)])
def test_bad_targets_are_refused(bad):
    with pytest.raises(ValueError):
        SeedTargets(**bad).check()
