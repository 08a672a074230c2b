"""--seeds auto on hard cells with twins throughout (--check-seeds 0) against the default,
which drops the twins of a cell once its runs are samples and checks its distribution
against a stricter subsample instead: RHS evaluations (deterministic) and case time, with
the answers of both (regime probabilities and median tilt per cell).

    python benchmarks/bench_seeds_auto.py --g0 130,150 --theta0 60,90 --max-seeds 8 \
        --out runs/bench_seeds_auto.json
"""
import argparse
import json
import os
import time

import loopsim
from loopsim import storage


def cost(frame):
    """(RHS evaluations of runs and twins, case seconds with twins) of a table's rows."""
    nfev = frame["nfev"].astype(float).clip(lower=1.0)
    seconds = frame["wall_s"] * (1.0 + frame["twin_nfev"] / nfev)
    return int(frame["nfev"].sum() + frame["twin_nfev"].sum()), float(seconds.sum())


def run(label, out, g0, theta0, max_seeds, check_seeds, threads):
    start = time.perf_counter()
    rows = loopsim.sweep(g0, theta0, out, n="auto", seeds="auto", max_seeds=max_seeds,
                         check_seeds=check_seeds, threads=threads)
    wall = time.perf_counter() - start
    evaluations, seconds = cost(rows)
    check = os.path.join(out, storage.CHECK_DIR)
    if os.path.isdir(check):
        extra = cost(loopsim.read_results(check))
        evaluations, seconds = evaluations + extra[0], seconds + extra[1]
    cells = loopsim.summarize(rows)
    stops = storage.read_stop_table(out)
    return dict(label=label, rows=len(rows), nfev=evaluations, case_s=seconds, wall_s=wall,
                cells=cells[["g0", "theta0_deg", "seeds", "determined", "p_3d", "p_in_plane",
                             "tilt_median"]].to_dict("records"),
                stops=stops.drop(columns=[c for c in stops if c.endswith("_p")]).to_dict(
                    "records"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--g0", default="130,150")
    parser.add_argument("--theta0", default="60,90")
    parser.add_argument("--max-seeds", type=int, default=8)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--dir", default="runs/bench_seeds_auto")
    parser.add_argument("--out", help="also write the results as JSON")
    args = parser.parse_args()
    g0 = [float(v) for v in args.g0.split(",")]
    theta0 = [float(v) for v in args.theta0.split(",")]
    results = [run(label, os.path.join(args.dir, label), g0, theta0, args.max_seeds, check,
                   args.threads)
               for label, check in (("twins throughout", 0), ("samples checked", 8))]
    base = results[0]
    print("| policy | rows | RHS evaluations | ratio | case time (s) | ratio | wall (s) |")
    print("|---|---|---|---|---|---|---|")
    for r in results:
        print(f"| {r['label']} | {r['rows']} | {r['nfev']} | {r['nfev'] / base['nfev']:.2f} "
              f"| {r['case_s']:.0f} | {r['case_s'] / base['case_s']:.2f} | {r['wall_s']:.0f} |")
    for r in results:
        print(r["label"])
        for cell, stop in zip(r["cells"], r["stops"]):
            print("  ", {k: (round(v, 3) if isinstance(v, float) else v)
                         for k, v in {**cell, **stop}.items()})
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(results, handle, indent=1, default=str)


if __name__ == "__main__":
    main()
