"""radau5's policy constants on the tumbling loop: the counts and priced cost of windows of
(350, 18°, n = 32), seed 0, with ``RadauIIA`` fields changed, against the defaults.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_radau_policy.py \
        --policies "jacobian_rate=0.03;jacobian_rate=0.1;rate_target=0.35;rate_order=2"

The windows, their starts and the pricing are ``bench_tumbling.py``'s (the seeded start at
t = 0, the recorded states at later times; (nfev − njev) F + njev J + nlu LU pair at unit
costs measured at the start of this run).  Each policy is one or more ``FIELD=VALUE``
pairs joined by ``/`` (fields of ``loopsim.integrators.RADAU5``); policies are separated
by ``;``.  A tumbling loop's step is set by the Newton iteration (performance.md,
"Tumbling loops"), so these are the constants that could move it: when the Jacobian is
refreshed (``jacobian_rate``, ``jacobian_iterations``) and how far the step may grow
against the contraction rate (``rate_target``, ``rate_order``).
"""
import argparse
import os
import sys

from loopsim import integrators
from loopsim.shapes import loading

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_tumbling as bt  # noqa: E402  (windows, starts and pricing: one definition)


def parse_policies(text):
    """[(label, {field: value})], the defaults first."""
    policies = [("defaults", {})]
    for spec in (p for p in text.split(";") if p):
        fields = dict(pair.split("=") for pair in spec.split("/"))
        policies.append((spec, {k: int(v) if v.isdigit() else float(v)  # ints stay ints
                                for k, v in fields.items()}))
    return policies


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policies", required=True, help="FIELD=VALUE[/...];...")
    parser.add_argument("--windows", default="0:0.5,1:1.3", help="START:END,... (t_u)")
    parser.add_argument("--rtols", default="1e-3,1e-6")
    args = parser.parse_args()
    policies = parse_policies(args.policies)
    x0 = loading.start_shape(bt.THETA0, bt.N, None, bt.SEED)[0].ravel()
    problem = bt.problem_of(bt.N)
    small = bt.problem_of(4)  # compile outside the timing
    bt.radau(small, loading.start_shape(bt.THETA0, 4, None, bt.SEED)[0].ravel(), 0.0, 1e-3,
             1e-3, 0.0)
    units = bt.unit_costs(problem, x0)
    print(f"# unit costs: F {units['f'] * 1e3:.3f} ms, J {units['j'] * 1e3:.2f} ms, "
          f"LU pair {units['lu_pair'] * 1e3:.2f} ms; load {os.getloadavg()[0]:.1f}")
    print("| window | rtol | policy | steps | rejected | nfev | njev | nlu | priced | wall |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for window in args.windows.split(","):
        t0, t1 = (float(v) for v in window.split(":"))
        y0 = bt.start_state(t0, x0)
        for rtol in (float(v) for v in args.rtols.split(",")):
            base = None
            for label, fields in policies:
                wall, status, _, counts = bt.radau(problem, y0, t0, t1, rtol,
                                                   integrators.RADAU5.jacobian_point, **fields)
                if status not in integrators.SUCCESS:
                    sys.exit(f"bench_radau_policy: {label} failed on [{t0:g}, {t1:g}]")
                cost = bt.priced(counts, units, "radau5")
                base = base or cost
                print(f"| [{t0:g}, {t1:g}] | {rtol:g} | {label} | "
                      + " | ".join(str(c) for c in counts)
                      + f" | {cost:.2f} s ({cost / base:.2f}x) | {wall:.1f} s |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
