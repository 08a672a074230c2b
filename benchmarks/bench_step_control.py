"""Step control of radau5 across tolerances: work counts and terminal-tilt error by rtol.

Usage: python benchmarks/bench_step_control.py [--cases 150:45:16,100:60:16,150:45:21,100:60:24]
           [--rtols 1e-3,...,1e-12] [--t-end 2] [--atol-ratio 1e-3 | --atol A]
           [--ref-rtol 1e-13] [--refs OLD.json] [--jacobian-point P] [--out FILE.json]

For each case (g0:θ0:n) it runs ``loopsim.simulate(method="radau5", twin=False)`` from the
seeded start (perturbation 1e-3, seed 0) over t ≤ t_end at every rtol, atol = rtol ×
atol-ratio (or the fixed --atol), and prints nfev, accepted and rejected steps, njev,
nlu, the wall time and the terminal tilt's error against a reference run of the same
start (radau5 at --ref-rtol, atol = ref-rtol × atol-ratio).  Step control must not
punish a tolerance: a looser rtol should never cost more RHS evaluations, rejected steps
should stay a small share of the accepted ones, and the error should fall with rtol.
The last columns give the rejected share and flag a looser rtol that cost more than the
next tighter one.

``--refs OLD.json`` takes the reference tilts from an earlier run's file instead of
computing them, so that two versions of the code are measured against the same
reference (nfev and the step counts are deterministic; wall times are not).
``--jacobian-point P`` runs radau5 with that Jacobian policy (``RadauIIA.jacobian_point``;
0: at y, as before issue 44) instead of the default, references included.
"""
import argparse
import json
import time
import warnings

import loopsim
from loopsim import api, diagnostics, integrators

CASES = "150:45:16,100:60:16,150:45:21,100:60:24"
RTOLS = "1e-3,1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10,1e-11,1e-12"


def run(g0, theta0, n, t_end, rtol, atol):
    """One radau5 run from the seeded start: (result, tilt at t_end in degrees, wall s)."""
    start = time.perf_counter()
    with warnings.catch_warnings():  # "not resolved" at t_end is not this benchmark's subject
        warnings.simplefilter("ignore", api.LoopsimWarning)
        result = loopsim.simulate(g0, theta0, n=n, t_span=(0.0, t_end), rtol=rtol, atol=atol,
                                  method="radau5", twin=False)
    return result, diagnostics.tilt_deg(result.x_final), time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=CASES, help="g0:theta0:n,...")
    parser.add_argument("--rtols", default=RTOLS)
    parser.add_argument("--t-end", type=float, default=2.0)
    parser.add_argument("--atol-ratio", type=float, default=1e-3, help="atol = rtol * this")
    parser.add_argument("--atol", type=float, help="a fixed atol instead of --atol-ratio")
    parser.add_argument("--ref-rtol", type=float, default=1e-13)
    parser.add_argument("--refs", help="take the reference tilts from this earlier --out file")
    parser.add_argument("--jacobian-point", type=float,
                        help="radau5's RadauIIA.jacobian_point (default: the method's)")
    parser.add_argument("--out", help="write the rows and references as JSON")
    args = parser.parse_args()
    if args.jacobian_point is not None:  # simulate(method="radau5") looks the method up here
        integrators.METHODS["radau5"] = integrators.RADAU5._replace(
            jacobian_point=args.jacobian_point)
    cases = [(float(g0), float(theta0), int(n)) for g0, theta0, n in
             (c.split(":") for c in args.cases.split(","))]
    rtols = [float(v) for v in args.rtols.split(",")]
    atol_of = (lambda rtol: args.atol) if args.atol is not None else \
        (lambda rtol: rtol * args.atol_ratio)
    references = {}
    if args.refs:
        with open(args.refs) as handle:
            references = {tuple(r["case"]): r["tilt"] for r in json.load(handle)["references"]}
    loopsim.simulate(60, 30, n=4, t_span=(0, 0.01), method="radau5", twin=False)  # compile
    rows, refs = [], []
    for g0, theta0, n in cases:
        key = (g0, theta0, n)
        if key not in references:
            result, tilt, _ = run(g0, theta0, n, args.t_end, args.ref_rtol,
                                  args.ref_rtol * args.atol_ratio)
            references[key] = tilt
        refs.append(dict(case=list(key), tilt=references[key]))
        print(f"\n(g0, θ0, n) = ({g0:g}, {theta0:g}°, {n}), t ≤ {args.t_end:g}, reference tilt "
              f"{references[key]:.10f}°")
        print(f"{'rtol':>7} {'atol':>7} {'nfev':>8} {'acc':>7} {'rej':>6} {'njev':>6} {'nlu':>6} "
              f"{'wall_s':>7} {'tilt_err':>9}  {'rej/acc':>7}")
        previous = None
        for rtol in rtols:
            result, tilt, wall = run(g0, theta0, n, args.t_end, rtol, atol_of(rtol))
            row = dict(g0=g0, theta0=theta0, n=n, t_end=args.t_end, rtol=rtol,
                       atol=atol_of(rtol), status=result.stop_reason, nfev=result.nfev,
                       accepted=result.steps_accepted, rejected=result.steps_rejected,
                       njev=result.njev, nlu=result.nlu, wall_s=wall, tilt=tilt,
                       tilt_error=abs(tilt - references[key]))
            rows.append(row)
            costlier = False  # of this rtol and the previous, the looser cost more
            if previous is not None:
                looser, tighter = (previous, row) if previous["rtol"] > rtol else (row, previous)
                costlier = looser["nfev"] > tighter["nfev"]
            print(f"{rtol:>7.0e} {row['atol']:>7.0e} {row['nfev']:>8} {row['accepted']:>7} "
                  f"{row['rejected']:>6} {row['njev']:>6} {row['nlu']:>6} {wall:>7.2f} "
                  f"{row['tilt_error']:>9.1e}  {row['rejected'] / max(1, row['accepted']):>7.2f}"
                  f"{'  looser rtol cost more' if costlier else ''}", flush=True)
            previous = row
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(dict(t_end=args.t_end, atol_ratio=args.atol_ratio, atol=args.atol,
                           ref_rtol=args.ref_rtol,
                           jacobian_point=integrators.METHODS["radau5"].jacobian_point, references=refs, rows=rows), handle, indent=1)


if __name__ == "__main__":
    main()
