"""Outcomes as distributions: one row per cell of a sweep, from its seeds.

A *cell* is one point of the sweep's inputs with the seed left out: every input column
that takes more than one value in the table (``g0``, ``theta0_deg`` and whatever else
was swept: ``n``, ``rtol``, ``perturbation`` ...).  Per cell:

* ``seeds``, ``resolved``, ``determined``: how many rows, and how many of them are
  resolved and determined (``loopsim.outcomes``);
* ``p_<regime>`` for each regime, with its 95 % Wilson score interval
  ``p_<regime>_low``, ``p_<regime>_high``:

      (p̂ + z²/2N ± z sqrt(p̂(1 − p̂)/N + z²/4N²)) / (1 + z²/N),  z = Φ⁻¹(0.975)

* the median and quartiles of the terminal tilt and aspect ratio, each median with a
  95 % percentile-bootstrap interval (``BOOTSTRAP_RESAMPLES`` resamples from a
  generator seeded with ``seed``, so the table is reproducible bit for bit);
* the cost: ``nfev`` and ``twin_nfev`` summed, ``wall_s`` summed.

Plain NumPy and pandas: no integration happens here.
"""
import numpy as np
import pandas as pd

from .outcomes import REGIMES

#: z of a two-sided 95 % interval, Φ⁻¹(0.975).
Z95 = 1.959963984540054
BOOTSTRAP_RESAMPLES = 2000
#: The inputs that may define a cell (the seed never does).
CELL_INPUTS = ("g0", "theta0_deg", "n", "t_end", "rtol", "atol", "w", "perturbation",
               "method")


def wilson_interval(successes, trials, z=Z95):
    """(low, high) of the Wilson score interval of a proportion successes / trials."""
    if trials <= 0:
        return float("nan"), float("nan")
    p = successes / trials
    centre = (p + z * z / (2 * trials)) / (1 + z * z / trials)
    half = z * np.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials)) / (1 + z * z / trials)
    return float(max(0.0, centre - half)), float(min(1.0, centre + half))


def bootstrap_interval(values, statistic=np.median, resamples=BOOTSTRAP_RESAMPLES, seed=0,
                       level=0.95):
    """(low, high) percentile-bootstrap interval of ``statistic`` of the finite
    ``values``: ``resamples`` resamples with replacement from ``default_rng(seed)``."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return float("nan"), float("nan")
    rng = np.random.default_rng(seed)
    draws = values[rng.integers(0, values.size, size=(resamples, values.size))]
    estimates = statistic(draws, axis=1)
    tail = 100 * (1 - level) / 2
    low, high = np.percentile(estimates, [tail, 100 - tail])
    return float(low), float(high)


def cell_columns(frame):
    """The inputs that define the cells of ``frame``: g0 and theta0_deg, and every other
    input of :data:`CELL_INPUTS` that varies."""
    return [c for c in CELL_INPUTS if c in frame and (c in ("g0", "theta0_deg")
                                                      or frame[c].nunique(dropna=False) > 1)]


def _cell_row(rows, seed):
    trials = len(rows)
    out = dict(seeds=trials, resolved=int(rows["resolved"].sum()),
               determined=int(rows["determined"].eq(True).sum()))
    for regime in REGIMES:
        name = regime.replace("-", "_")
        hits = int((rows["regime"] == regime).sum())
        out[f"p_{name}"] = hits / trials
        out[f"p_{name}_low"], out[f"p_{name}_high"] = wilson_interval(hits, trials)
    for column, short in (("theta_final_deg", "tilt"), ("aspect_ratio", "aspect")):
        values = rows[column].to_numpy(float)
        finite = values[np.isfinite(values)]
        quartiles = np.percentile(finite, [25, 50, 75]) if finite.size else [np.nan] * 3
        out[f"{short}_q25"], out[f"{short}_median"], out[f"{short}_q75"] = map(float, quartiles)
        out[f"{short}_median_low"], out[f"{short}_median_high"] = bootstrap_interval(
            finite, seed=seed)
    for column in ("nfev", "twin_nfev", "wall_s"):
        out[column] = rows[column].sum() if column in rows else 0
    return out


def summarize(frame, by=None, seed=0):
    """One row per cell of a results table (``read_results``): see the module docstring.
    ``by``: the cell columns (default :func:`cell_columns`); ``seed``: the bootstrap's."""
    by = list(cell_columns(frame) if by is None else by)
    missing = [c for c in by if c not in frame]
    if missing:
        raise ValueError(f"no column(s) {missing} to group the cells by")
    if not len(frame):
        raise ValueError("no rows to summarise")
    rows = [dict(zip(by, key if isinstance(key, tuple) else (key,)), **_cell_row(group, seed))
            for key, group in frame.groupby(by, sort=True, dropna=False)]
    table = pd.DataFrame(rows)
    table.attrs["loopsim_summary"] = dict(cells_by=by, bootstrap_seed=seed,
                                          bootstrap_resamples=BOOTSTRAP_RESAMPLES,
                                          interval="95 % (Wilson; percentile bootstrap)")
    return table
