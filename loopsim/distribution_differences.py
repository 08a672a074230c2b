"""How far two samples of one cell's outcomes differ, with intervals, and the smallest
difference the comparison could have detected.

Two samples of a cell (its seeds at two settings: the defaults and a stricter rtol, a
higher n, another perturbation size) are compared statistic by statistic:

* a probability (a regime's, or of reaching a steady state before t_end): the difference
  p_b − p_a with Newcombe's hybrid score interval (his method 10, built from the two
  Wilson intervals ``(l_a, u_a)``, ``(l_b, u_b)``)::

      Δ = p̂_b − p̂_a,
      low  = Δ − sqrt((p̂_b − l_b)² + (u_a − p̂_a)²),
      high = Δ + sqrt((u_b − p̂_b)² + (p̂_a − l_a)²);

* a tilt (or aspect-ratio) quantile: the difference Q_b − Q_a with a percentile-bootstrap
  interval (``scipy.stats.bootstrap``), each sample resampled on its own from a seeded
  generator.

A statistic *differs* when its interval excludes 0.  The intervals are 95 % each; over
the k statistics of one comparison the verdict uses Bonferroni's 1 − 0.05/k intervals, so
that a cell whose two samples come from one distribution is called different with
probability at most about 5 %.

What a comparison could have detected (``*_detectable``): for a probability, the
smallest true difference (on a grid of 0.01, either sign) at which the 95 % Newcombe
interval would exclude 0 with probability ≥ :data:`POWER`, computed exactly over the two
binomial distributions at the observed p̂_a; for a quantile, (z₀.₉₇₅ + z_POWER) times
the bootstrap standard deviation of the difference.  A difference smaller than that is
not excluded by a verdict of "same".

Plain NumPy and SciPy: nothing here integrates.
"""
import numpy as np
from scipy.stats import binom, norm

from .intervals import percentile_bootstrap, wilson_interval

#: Probability of detecting a difference of the stated size (the power of ``*_detectable``).
POWER = 0.8
#: Quantiles of the terminal tilt compared.
TILT_QUANTILES = (0.25, 0.5, 0.75)
#: Bootstrap resamples of a quantile difference.
RESAMPLES = 2000
#: A cell is *certain* of a regime when the 95 % Wilson interval of its probability has
#: its lower end at or above this: 16 of 16 seeds in one regime give 0.806, 8 of 8 only
#: 0.676, 4 of 4 0.510.
CERTAIN_LOWER = 0.8
#: The verdicts.
SAME, DIFFERENT = "same within the intervals", "different"


def newcombe_interval(hits_a, trials_a, hits_b, trials_b, level=0.95):
    """(low, high) of Newcombe's hybrid score interval of p_b − p_a (module docstring),
    from the two Wilson intervals at confidence ``level``."""
    p_a, p_b = hits_a / trials_a, hits_b / trials_b
    low_a, high_a = wilson_interval(hits_a, trials_a, level)
    low_b, high_b = wilson_interval(hits_b, trials_b, level)
    delta = p_b - p_a
    return (float(delta - np.hypot(p_b - low_b, high_a - p_a)),
            float(delta + np.hypot(high_b - p_b, p_a - low_a)))


def _excludes_zero_table(trials_a, trials_b, level):
    """Boolean (trials_a + 1, trials_b + 1): whether the Newcombe interval at counts
    (i, j) excludes 0."""
    table = np.zeros((trials_a + 1, trials_b + 1), dtype=bool)
    for i in range(trials_a + 1):
        for j in range(trials_b + 1):
            low, high = newcombe_interval(i, trials_a, j, trials_b, level)
            table[i, j] = low > 0.0 or high < 0.0
    return table


def detectable_probability_difference(p_a, trials_a, trials_b, power=POWER, level=0.95):
    """Smallest |Δ| on a 0.01 grid such that, with true probabilities p_a and p_a + Δ
    (either sign, inside [0, 1]), the Newcombe interval excludes 0 with probability
    ≥ ``power`` (exact binomial sums; the interval at confidence ``level``); NaN when no
    Δ reaches it."""
    excludes = _excludes_zero_table(trials_a, trials_b, level)
    weights_a = binom.pmf(np.arange(trials_a + 1), trials_a, p_a)
    for delta in np.arange(0.01, 1.0 + 1e-9, 0.01):
        for p_b in (p_a + delta, p_a - delta):
            if 0.0 <= p_b <= 1.0:
                weights_b = binom.pmf(np.arange(trials_b + 1), trials_b, p_b)
                if weights_a @ excludes @ weights_b >= power:
                    return float(round(delta, 2))
    return float("nan")


def bootstrap_quantile_differences(a, b, quantile, resamples=RESAMPLES, seed=0):
    """(Δ, draws) for Q_b − Q_a, the ``quantile`` of the finite values of a and b: the
    sample difference and ``resamples`` bootstrap draws of it
    (:func:`loopsim.outcome_statistics.percentile_bootstrap`: a then b resampled from
    ``default_rng(seed)``); (None, None) if either sample is empty."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    a, b = a[np.isfinite(a)], b[np.isfinite(b)]
    if not (a.size and b.size):
        return None, None

    def difference(x, y, axis=-1):
        return np.quantile(y, quantile, axis=axis) - np.quantile(x, quantile, axis=axis)

    _, _, draws = percentile_bootstrap([a, b], difference, resamples, seed)
    return float(np.quantile(b, quantile) - np.quantile(a, quantile)), draws


def percentile_interval(draws, level):
    """The central ``level`` percentile interval of bootstrap draws, as (low, high)."""
    tail = 100 * (1 - level) / 2
    low, high = np.percentile(draws, [tail, 100 - tail])
    return float(low), float(high)


def detectable_from_draws(draws):
    """The difference a bootstrap with these draws detects with POWER: (z_0.975 + z_POWER)
    × their standard deviation."""
    return float((norm.ppf(0.975) + norm.ppf(POWER)) * draws.std())


def quantile_difference(a, b, quantile, resamples=RESAMPLES, seed=0, level=0.95):
    """(Δ, low, high, detectable) of Q_b − Q_a for the ``quantile`` of the finite values of
    a and b: percentile-bootstrap interval at ``level``; detectable = (z + z_POWER) × the
    bootstrap standard deviation."""
    delta, draws = bootstrap_quantile_differences(a, b, quantile, resamples, seed)
    if draws is None:
        return (float("nan"),) * 4
    return (delta, *percentile_interval(draws, level), detectable_from_draws(draws))


def compare_samples(a, b, probabilities, quantiles=TILT_QUANTILES, seed=0):
    """Differences b − a of one cell's two samples, statistic by statistic.

    Parameters
    ----------
    a, b : pandas.DataFrame
        The cell's rows at two settings, with ``theta_final_deg`` and the boolean columns
        named in ``probabilities``.
    probabilities : list of str
        Boolean columns whose means are compared (e.g. ``is_3d``, ``steady``); a row with
        a missing value is left out of that statistic.
    quantiles : tuple of float
        Tilt quantiles compared.
    seed : int
        Seed of the bootstraps (statistic i uses seed + i).

    Returns
    -------
    dict
        ``delta_<stat>``, ``delta_<stat>_low``, ``delta_<stat>_high``,
        ``delta_<stat>_detectable`` per statistic (``p_<column>``, a leading ``is_``
        dropped, and ``tilt_q<percent>``), and ``verdict``: :data:`DIFFERENT` when a
        Bonferroni interval (module docstring) excludes 0.
    """
    statistics = len(probabilities) + len(quantiles)
    level_family = 1 - 0.05 / statistics
    out, differs = {}, False
    for column in probabilities:
        x, y = a[column].dropna().astype(bool), b[column].dropna().astype(bool)
        name = "delta_p_" + column.removeprefix("is_")
        if not (len(x) and len(y)):
            out.update({name: np.nan, **{f"{name}_{k}": np.nan
                                         for k in ("low", "high", "detectable")}})
            continue
        hits_a, hits_b = int(x.sum()), int(y.sum())
        out[name] = hits_b / len(y) - hits_a / len(x)
        out[f"{name}_low"], out[f"{name}_high"] = newcombe_interval(hits_a, len(x), hits_b,
                                                                    len(y))
        out[f"{name}_detectable"] = detectable_probability_difference(hits_a / len(x), len(x),
                                                                      len(y))
        low, high = newcombe_interval(hits_a, len(x), hits_b, len(y), level_family)
        differs |= low > 0.0 or high < 0.0
    for i, quantile in enumerate(quantiles):
        name = f"delta_tilt_q{round(100 * quantile)}"
        delta, draws = bootstrap_quantile_differences(
            a["theta_final_deg"], b["theta_final_deg"], quantile, seed=seed + i)
        if draws is None:
            out.update({name: np.nan, **{f"{name}_{k}": np.nan
                                         for k in ("low", "high", "detectable")}})
            continue
        out[name] = delta
        out[f"{name}_low"], out[f"{name}_high"] = percentile_interval(draws, 0.95)
        out[f"{name}_detectable"] = detectable_from_draws(draws)
        low, high = percentile_interval(draws, level_family)  # the same draws
        differs |= bool(low > 0.0 or high < 0.0)
    out["verdict"] = DIFFERENT if differs else SAME
    return out


def certain(hits, trials):
    """Whether a cell is certain of an outcome seen ``hits`` times in ``trials``: the 95 %
    Wilson interval's lower end is at least :data:`CERTAIN_LOWER`."""
    return trials > 0 and wilson_interval(hits, trials)[0] >= CERTAIN_LOWER
