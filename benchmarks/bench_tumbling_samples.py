"""Tumbling samples, whole: the cost of every sample of the committed convergence sweeps at
a tumbling cell, priced by its counts at compiled unit costs measured in this run.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_tumbling_samples.py \
        --sweeps default_t18,jmid_t18,jmid_rtol1e-3_t18 --g0 350

Each sweep (``data/convergence_runs/NAME``, ``scripts/convergence_study.py``) holds 16
seeds of one cell at one setting, each run from t = 0 to t_end = 10 without a twin.  A
sample's priced cost is (nfev − njev) F + njev J + nlu LU pair (radau5's counts; the
unit costs as ``bench_tumbling.unit_costs``, at the sample's own n), so that sweeps run
on different days, under different loads, compare by their work.  The sweeps' recorded
wall times are shown beside it (summed case time: a busy machine inflates it).

For each sweep: the samples, how many tumble (``terminal_state`` unsteady), the summed
priced cost and wall time, the median priced cost of a tumbling sample, and each as a
ratio to the first sweep named (the "before").
"""
import argparse
import os
import sys

import numpy as np
import pandas as pd

import loopsim
from loopsim.shapes import loading

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_tumbling  # noqa: E402  (the unit costs and the pricing, one definition)

RUNS = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "data",
                    "convergence_runs")


def sample_costs(frame, units_by_n):
    """Priced seconds of each sample (row) at the unit costs of its n."""
    return np.array([bench_tumbling.priced(
        (0, 0, row.nfev, row.njev, row.nlu), units_by_n[row.n_used], "radau5")
        for row in frame.itertuples()])


def unit_costs_by_order(orders, given=None):
    """{n: unit costs (s)}: measured at each n, or ``given`` ("F,J,LU_PAIR" in ms) at all."""
    fixed = None
    if given:
        fixed = dict(zip(("f", "j", "lu_pair"), (float(v) * 1e-3 for v in given.split(","))))
    units_by_n = {}
    for n in orders:
        if fixed:
            units_by_n[n] = fixed
        else:
            x0 = loading.start_shape(bench_tumbling.THETA0, n, None, bench_tumbling.SEED)[0]
            units_by_n[n] = bench_tumbling.unit_costs(bench_tumbling.problem_of(n), x0.ravel())
        u = units_by_n[n]
        print(f"# unit costs at n = {n} ({'given' if given else 'measured'}): F "
              f"{u['f'] * 1e3:.3f} ms, J {u['j'] * 1e3:.2f} ms, "
              f"LU pair {u['lu_pair'] * 1e3:.2f} ms")
    return units_by_n


def sweep_summary(name, frame, costs):
    """One line's numbers for a sweep: samples, tumbling, priced and wall sums, medians."""
    tumbling = frame["terminal_state"].eq("unsteady").to_numpy()
    return dict(sweep=name, samples=len(frame), tumbling=int(tumbling.sum()),
                rtol=f'{frame["rtol"].iloc[0]:g}', priced_s=float(costs.sum()),
                wall_s=float(frame["wall_s"].sum()),
                tumbling_priced_median_s=float(np.median(costs[tumbling])) if tumbling.any()
                else np.nan,
                p_steady=float(frame["stop_reason"].eq("steady").mean()),
                tilt_median_deg=float(frame["theta_final_deg"].median()))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sweeps", default="default_t18,jmid_t18,jmid_rtol1e-3_t18",
                        help="sweep names under --runs, the first one the baseline")
    parser.add_argument("--runs", default=RUNS)
    parser.add_argument("--g0", type=float, default=bench_tumbling.G0,
                        help="the cell's g0 (θ0 = 18°)")
    parser.add_argument("--unit-costs", metavar="F,J,LU_PAIR",
                        help="price at these unit costs (ms, every n) instead of measuring "
                             "them: e.g. an idle machine's, from bench_tumbling.py")
    args = parser.parse_args()
    frames = {}
    for name in args.sweeps.split(","):
        frame = loopsim.read_results(os.path.join(args.runs, name))
        frames[name] = frame[frame["g0"] == args.g0]
        if frames[name].empty:
            sys.exit(f"bench_tumbling_samples: no sample at g0 = {args.g0:g} in {name}")
    units_by_n = unit_costs_by_order(
        sorted({int(n) for f in frames.values() for n in f["n_used"]}), args.unit_costs)
    rows = [sweep_summary(name, frame, sample_costs(frame, units_by_n))
            for name, frame in frames.items()]
    table = pd.DataFrame(rows).set_index("sweep")
    base = table.iloc[0]
    for column in ("priced_s", "wall_s", "tumbling_priced_median_s"):
        table[column.removesuffix("_s") + "_ratio"] = table[column] / base[column]
    print(f"# (g0, θ0) = ({args.g0:g}, 18°); load average {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores")
    with pd.option_context("display.width", 200, "display.max_columns", 20):
        print(table.round(3).to_string())


if __name__ == "__main__":
    sys.exit(main())
