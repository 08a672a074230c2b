"""Confidence intervals through ``scipy.stats``: the Wilson score interval of a
proportion and the percentile bootstrap, shared by the summaries
(``outcome_statistics``), the comparisons (``distribution_differences``) and the
settling statistics (``survival``).

The Wilson interval (no continuity correction) of k successes in N trials::

    (p̂ + z²/2N ± z sqrt(p̂(1 − p̂)/N + z²/4N²)) / (1 + z²/N),  z = Φ⁻¹(0.975)

Plain NumPy and SciPy: no integration happens here.
"""
import functools

import numpy as np
from scipy import stats

#: Resamples of every percentile bootstrap (seeded: tables are reproducible bit for bit).
BOOTSTRAP_RESAMPLES = 2000


@functools.lru_cache(maxsize=4096)
def wilson_interval(successes, trials, level=0.95):
    """The Wilson score interval of a proportion (module docstring), without continuity
    correction, by ``scipy.stats.binomtest(successes, trials).proportion_ci``.

    Parameters
    ----------
    successes, trials : int
        The count and the number of trials (0 <= successes <= trials).
    level : float, default 0.95
        Confidence level of the two-sided interval.

    Returns
    -------
    (float, float)
        (low, high); (nan, nan) with no trials.
    """
    if trials <= 0:
        return float("nan"), float("nan")
    interval = stats.binomtest(int(successes), int(trials)).proportion_ci(
        confidence_level=level, method="wilson")
    return float(interval.low), float(interval.high)


def percentile_bootstrap(samples, statistic, resamples=BOOTSTRAP_RESAMPLES, seed=0,
                         level=0.95, vectorized=True):
    """The percentile bootstrap of ``statistic(*samples)`` by ``scipy.stats.bootstrap``.

    Each sample is resampled on its own (unpaired), in order, from
    ``numpy.random.default_rng(seed)``.  A sample of one value is held fixed: every
    resample of it is that value (SciPy refuses samples of fewer than two values, and
    NumPy draws nothing for them either).

    Parameters
    ----------
    samples : sequence of 1-D arrays
        The samples, each of at least one value.
    statistic : callable
        ``statistic(*samples, axis=-1)`` with ``vectorized``, else ``statistic(*samples)``
        of 1-D samples.
    resamples : int
        Bootstrap resamples.
    seed : int
        Seed of the generator.
    level : float
        Confidence level of the two-sided percentile interval.
    vectorized : bool
        Whether ``statistic`` takes ``axis``.

    Returns
    -------
    (float, float, numpy.ndarray)
        (low, high, the bootstrap draws of the statistic).
    """
    samples = [np.asarray(sample, dtype=float) for sample in samples]
    varying = [i for i, sample in enumerate(samples) if sample.size > 1]

    def with_fixed(*drawn, **axis):
        full = list(samples)
        for i, sample in zip(varying, drawn):
            full[i] = sample
        return statistic(*full, **axis)

    if not varying:
        value = float(statistic(*samples, **({"axis": -1} if vectorized else {})))
        return value, value, np.full(resamples, value)
    result = stats.bootstrap([samples[i] for i in varying], with_fixed, n_resamples=resamples,
                             vectorized=vectorized, paired=False, confidence_level=level,
                             method="percentile", rng=np.random.default_rng(seed))
    interval = result.confidence_interval
    return float(interval.low), float(interval.high), result.bootstrap_distribution


def bootstrap_interval(values, statistic=np.median, resamples=BOOTSTRAP_RESAMPLES, seed=0,
                       level=0.95):
    """(low, high) percentile-bootstrap interval of ``statistic`` (a NumPy reduction taking
    ``axis``) of the finite ``values``: :func:`percentile_bootstrap` with ``resamples``
    resamples from ``default_rng(seed)``; (nan, nan) without finite values."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return float("nan"), float("nan")
    low, high, _ = percentile_bootstrap([values], statistic, resamples, seed, level)
    return low, high
