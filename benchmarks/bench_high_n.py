"""Wall time, work counts and terminal outcome of radau5 on the 3D cases of issue 11.

Usage: python benchmarks/bench_high_n.py [--cases 100:60,150:45,150:80] [--orders 16,24]
                                      [--t-end 10] [--rtol 1e-6] [--out FILE.json]

For each case (g0:θ0) and order n it runs ``loopsim.simulate(method="radau5")``
from the same seeded start (perturbation 1e-3, seed 0) and prints the wall
time, nfev, njev, nlu, accepted/rejected steps and the terminal tilt and
aspect ratio.  With ``--out`` the rows are written as JSON, so two versions
of the code can be compared case by case (``--compare OLD.json``: the
terminal differences to those rows, the speed ratio).
"""
import argparse
import json

import loopsim


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="100:60,150:45,150:80")
    parser.add_argument("--orders", default="16,24")
    parser.add_argument("--t-end", type=float, default=10.0)
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--out")
    parser.add_argument("--compare")
    args = parser.parse_args()
    cases = [tuple(float(v) for v in c.split(":")) for c in args.cases.split(",")]
    orders = [int(n) for n in args.orders.split(",")]
    old = {}
    if args.compare:
        with open(args.compare) as handle:
            old = {(r["g0"], r["theta0"], r["n"]): r for r in json.load(handle)}
    loopsim.simulate(60, 30, n=4, t_span=(0, 0.01), method="radau5")  # compile outside timing
    rows = []
    print(f"{'g0':>5} {'th0':>4} {'n':>3} {'wall_s':>8} {'nfev':>7} {'njev':>5} {'nlu':>5} "
          f"{'acc':>6} {'rej':>5} {'tilt':>9} {'aspect':>8}" + ("  speedup  d_tilt  d_aspect"
                                                            if old else ""))
    for g0, theta0 in cases:
        for n in orders:
            r = loopsim.simulate(g0, theta0, n=n, t_span=(0, args.t_end), rtol=args.rtol,
                                 atol=args.rtol * 1e-3, method="radau5")
            s = r.summary()
            row = dict(g0=g0, theta0=theta0, n=n, wall_s=r.wall_s, nfev=r.nfev, njev=r.njev,
                       nlu=r.nlu, accepted=r.steps_accepted, rejected=r.steps_rejected,
                       status=s["status"], tilt=s["theta_final_deg"], aspect=s["aspect_ratio"])
            rows.append(row)
            line = (f"{g0:>5g} {theta0:>4g} {n:>3} {r.wall_s:>8.2f} {r.nfev:>7} {r.njev:>5} "
                    f"{r.nlu:>5} {r.steps_accepted:>6} {r.steps_rejected:>5} {row['tilt']:>9.4f} "
                    f"{row['aspect']:>8.4f}")
            before = old.get((g0, theta0, n))
            if before:
                line += (f"  {before['wall_s'] / r.wall_s:7.2f} {abs(before['tilt'] - row['tilt']):7.1e}"
                         f" {abs(before['aspect'] - row['aspect']):8.1e}")
            print(line, flush=True)
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(rows, handle, indent=1)


if __name__ == "__main__":
    main()
