"""Convergence study of automatic truncation (``--n auto``): each case's auto run against
a fixed run at n_used + 8 started from the same curve (the n = 6 start, zero-padded).

    python scripts/auto_study.py --tol 1e-4 [--tol 1e-3 ...] [--cases G0:DEG,...] [--json OUT]

Prints one line per (case, tolerance): n_used, terminal tilt and aspect ratio of both
runs and their differences, the transient length error and spectral tail, RHS counts
and wall times (radau5, rtol 1e-6, the sweep's early stop at a steady state).
"""
import argparse
import json
import time

import numpy as np

from loopsim import diagnostics, integrators, refinement, shapes
from loopsim.config import DEFAULT_N_MAX, DEFAULT_STEADY_INTERVAL, DEFAULT_STEADY_TOL

CASES = "30:30,60:30,60:85,100:60,150:45,150:80,250:30,350:60"


def run(g0, x0, ladder, tol, t_end):
    options = integrators.step_options(
        1e-6, 1e-9, max_steps=2_000_000, constraint_tol=0.1,
        steady_interval=DEFAULT_STEADY_INTERVAL, steady_tol=DEFAULT_STEADY_TOL)
    start = time.perf_counter()
    status, t, x, n_used, counts, worst, _ = refinement.integrate_case(
        integrators.METHODS["radau5"], g0, 10.0, x0, 0.0, t_end, np.empty(0), options, ladder,
        tol)
    return dict(status=integrators.STOP_REASONS[status], t_final=t, n_used=int(n_used),
                tilt=diagnostics.tilt_deg(x), aspect=diagnostics.aspect_ratio(x),
                length_error_max=float(worst[0]), tail_max=float(worst[1]),
                nfev=int(counts[2]), wall_s=time.perf_counter() - start)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tol", type=float, action="append", required=True)
    parser.add_argument("--cases", default=CASES)
    parser.add_argument("--t-end", type=float, default=10.0)
    parser.add_argument("--n-max", type=int, default=DEFAULT_N_MAX)
    parser.add_argument("--json")
    args = parser.parse_args()
    rows = []
    for item in args.cases.split(","):
        g0, theta = (float(v) for v in item.split(":"))
        x0 = shapes.start_shape(theta, 6, 1e-3, 0)[0]
        for tol in args.tol:
            auto = run(g0, x0, refinement.orders(6, args.n_max), tol, args.t_end)
            fixed = run(g0, x0, (auto["n_used"] + 8,), 1.0, args.t_end)
            row = dict(g0=g0, theta0=theta, tol=tol, auto=auto, fixed=fixed,
                       d_tilt=abs(auto["tilt"] - fixed["tilt"]),
                       d_aspect=abs(auto["aspect"] - fixed["aspect"]))
            rows.append(row)
            print(f"g0={g0:g} th={theta:g} tol={tol:g}: n_used={auto['n_used']} "
                  f"tilt {auto['tilt']:.3f}/{fixed['tilt']:.3f} (d {row['d_tilt']:.2e}) "
                  f"AR {auto['aspect']:.4f}/{fixed['aspect']:.4f} (d {row['d_aspect']:.1e}) "
                  f"len {auto['length_error_max']:.1e}/{fixed['length_error_max']:.1e} "
                  f"tail {auto['tail_max']:.1e} stop {auto['status']}/{fixed['status']} "
                  f"t {auto['t_final']:.2f}/{fixed['t_final']:.2f} nfev {auto['nfev']}/"
                  f"{fixed['nfev']} wall {auto['wall_s']:.1f}/{fixed['wall_s']:.1f}s", flush=True)
    if args.json:
        with open(args.json, "w") as handle:
            json.dump(rows, handle, indent=1)


if __name__ == "__main__":
    main()
