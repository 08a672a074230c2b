"""Differences between two samples of a cell: intervals against published values, the
detectable difference against simulation, the verdict's false-alarm rate."""
import numpy as np
import pandas as pd
import pytest
from scipy.stats import binom

from loopsim import distribution_differences as dd


@pytest.mark.parametrize("counts, expected", [
    # Newcombe (1998), Statistics in Medicine 17, 873, Table II, method 10: 56/70 − 48/80
    # and 9/10 − 3/10.
    ((48, 80, 56, 70), (0.0524, 0.3339)),
    ((3, 10, 9, 10), (0.1705, 0.8090)),
])
def test_newcombe_interval_matches_the_published_examples(counts, expected):
    low, high = dd.newcombe_interval(*counts)
    assert (round(low, 4), round(high, 4)) == expected


def test_newcombe_interval_is_antisymmetric_and_brackets_the_difference():
    low, high = dd.newcombe_interval(5, 16, 11, 16)
    back_low, back_high = dd.newcombe_interval(11, 16, 5, 16)
    assert (low, high) == pytest.approx((-back_high, -back_low), abs=1e-14)
    assert low < 6 / 16 < high


def _exclusion_rate(p_a, p_b, n_a, n_b):
    """Exact probability that the Newcombe interval excludes 0 (plain double loop)."""
    total = 0.0
    for i in range(n_a + 1):
        for j in range(n_b + 1):
            low, high = dd.newcombe_interval(i, n_a, j, n_b)
            if low > 0 or high < 0:
                total += binom.pmf(i, n_a, p_a) * binom.pmf(j, n_b, p_b)
    return total


@pytest.mark.parametrize("p_a, n", [(1.0, 16), (0.5, 16), (0.875, 8)])
def test_detectable_difference_is_the_smallest_with_the_stated_power(p_a, n):
    delta = dd.detectable_probability_difference(p_a, n, n)
    rates = [_exclusion_rate(p_a, p_a + s * delta, n, n) for s in (1, -1)
             if 0 <= p_a + s * delta <= 1]
    assert max(rates) >= dd.POWER
    smaller = delta - 0.01
    rates = [_exclusion_rate(p_a, p_a + s * smaller, n, n) for s in (1, -1)
             if 0 <= p_a + s * smaller <= 1]
    assert max(rates) < dd.POWER
    # and by simulation, independently of the binomial sums
    rng = np.random.default_rng(3)
    p_b = p_a - delta if p_a - delta >= 0 else p_a + delta
    hits_a, hits_b = rng.binomial(n, p_a, 4000), rng.binomial(n, p_b, 4000)
    excluded = [dd.newcombe_interval(i, n, j, n) for i, j in zip(hits_a, hits_b)]
    assert np.mean([low > 0 or high < 0 for low, high in excluded]) >= dd.POWER - 0.03


def test_more_seeds_detect_smaller_differences():
    assert (dd.detectable_probability_difference(1.0, 64, 64)
            < dd.detectable_probability_difference(1.0, 16, 16)
            < dd.detectable_probability_difference(1.0, 8, 8))


def test_quantile_difference_finds_a_known_shift_and_its_detectable_size():
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=400), rng.normal(size=400) + 0.5
    diff, low, high, detectable = dd.quantile_difference(a, b, 0.5)
    assert low < 0.5 < high and low > 0
    # the median's standard error is sqrt(pi/2)/sqrt(N) per sample: the detectable
    # difference is (1.96 + 0.84) sqrt(2) of it
    expected = 2.8016 * np.sqrt(2) * np.sqrt(np.pi / 2) / np.sqrt(400)
    assert detectable == pytest.approx(expected, rel=0.2)


def _cell(rng, size, p_3d, tilt_shift=0.0):
    return pd.DataFrame(dict(is_3d=rng.random(size) < p_3d,
                             steady=rng.random(size) < 0.5,
                             theta_final_deg=rng.normal(20 + tilt_shift, 5, size)))


def test_the_verdict_rarely_calls_one_distribution_different():
    rng = np.random.default_rng(7)
    verdicts = [dd.compare_samples(_cell(rng, 16, 0.6), _cell(rng, 16, 0.6),
                                   ["is_3d", "steady"], seed=k)["verdict"]
                for k in range(60)]
    assert verdicts.count(dd.DIFFERENT) <= 6  # about 5 % expected (Bonferroni, 5 statistics)


def test_the_verdict_sees_a_large_difference():
    rng = np.random.default_rng(8)
    out = dd.compare_samples(_cell(rng, 32, 0.1), _cell(rng, 32, 0.95, tilt_shift=10.0),
                             ["is_3d", "steady"])
    assert out["verdict"] == dd.DIFFERENT
    assert out["delta_p_3d_low"] > 0 and out["delta_tilt_q50_low"] > 0


def test_certain_means_a_wilson_lower_end_of_at_least_0_8():
    assert dd.certain(16, 16) and not dd.certain(8, 8) and not dd.certain(15, 16)


def test_quantile_difference_draws_are_the_seeded_resamples_of_a_then_b():
    """The bootstrap through scipy draws a's resamples, then b's, from default_rng(seed)
    (the draws loopsim made by hand before issue 55, bit for bit), so that
    data/convergence_top.parquet's differences are reproduced exactly."""
    rng = np.random.default_rng(5)
    a, b = rng.normal(20.0, 5.0, 16), rng.normal(24.0, 5.0, 12)
    draws_rng = np.random.default_rng(9)
    draws_a = np.quantile(a[draws_rng.integers(0, a.size, (2000, a.size))], 0.25, axis=1)
    draws_b = np.quantile(b[draws_rng.integers(0, b.size, (2000, b.size))], 0.25, axis=1)
    delta, draws = dd.bootstrap_quantile_differences(a, b, 0.25, 2000, seed=9)
    assert np.array_equal(draws, draws_b - draws_a)
    assert delta == np.quantile(b, 0.25) - np.quantile(a, 0.25)
    one = dd.bootstrap_quantile_differences([3.0], b, 0.5, 500, seed=1)[1]
    assert one.shape == (500,) and np.all(np.isfinite(one))
