"""Terminal outcome against rtol: how accurate is a 3D case's terminal tilt, and what does it cost?

Usage: python scripts/terminal_precision.py [--cases 100:60:24,150:45:24,150:80:20]
           [--rtols 1e-5,1e-6,1e-7,1e-8,1e-9] [--ref-rtol 1e-10] [--t-end 10]
           [--newton-maxiter 6,10] [--out FILE.parquet]

Each case g0:θ0:n runs radau5 from one seeded start (perturbation 1e-3, seed 0)
at every rtol (atol = rtol · 1e-3) and once at --ref-rtol; the table gives the
wall time, the work counts and the terminal tilt and aspect ratio's distance
to the reference run.  The tilt is converged in rtol when these distances
shrink steadily down the ladder; a case whose distances jump is sensitive to
its integration error (a near-separatrix transient), and one run of it at
the default rtol says little.  ``--newton-maxiter`` compares Newton iteration
caps of the Radau method (the policy ``integrators.radau.RadauIIA.newton_maxiter``).
"""
import argparse

import pandas as pd

import loopsim
from loopsim import integrators


def run(g0, theta0, n, rtol, t_end, method):
    integrators.METHODS["radau5"] = method
    result = loopsim.simulate(g0, theta0, n=n, t_span=(0, t_end), rtol=rtol, atol=rtol * 1e-3,
                              method="radau5")
    summary = result.summary()
    return dict(g0=g0, theta0=theta0, n=n, rtol=rtol, newton_maxiter=method.newton_maxiter,
                wall_s=result.wall_s, nfev=result.nfev, njev=result.njev,
                accepted=result.steps_accepted, rejected=result.steps_rejected,
                status=summary["status"], tilt=summary["theta_final_deg"],
                aspect=summary["aspect_ratio"])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="100:60:24,150:45:24,150:80:20")
    parser.add_argument("--rtols", default="1e-5,1e-6,1e-7,1e-8,1e-9")
    parser.add_argument("--ref-rtol", type=float, default=1e-10)
    parser.add_argument("--t-end", type=float, default=10.0)
    parser.add_argument("--newton-maxiter", default=str(integrators.RADAU5.newton_maxiter))
    parser.add_argument("--out", help="write the rows as Parquet")
    args = parser.parse_args()
    default = integrators.RADAU5
    policies = [default._replace(newton_maxiter=int(v)) for v in args.newton_maxiter.split(",")]
    loopsim.simulate(60, 30, n=4, t_span=(0, 0.01), method="radau5")  # compile outside timing
    rows = []
    print(f"{'g0':>5} {'th0':>4} {'n':>3} {'rtol':>6} {'maxit':>5} {'wall_s':>7} {'nfev':>6} "
          f"{'acc':>5} {'rej':>4} {'tilt':>10} {'d_tilt':>8} {'d_aspect':>8}")
    try:
        for spec in args.cases.split(","):
            g0, theta0, n = (float(v) for v in spec.split(":"))
            ref = run(g0, theta0, int(n), args.ref_rtol, args.t_end, default)
            ref["reference"] = True
            rows.append(ref)
            for rtol in (float(v) for v in args.rtols.split(",")):
                for policy in policies:
                    row = run(g0, theta0, int(n), rtol, args.t_end, policy)
                    row["reference"] = False
                    row["d_tilt"] = abs(row["tilt"] - ref["tilt"])
                    row["d_aspect"] = abs(row["aspect"] - ref["aspect"])
                    rows.append(row)
                    print(f"{g0:>5g} {theta0:>4g} {int(n):>3} {rtol:>6.0e} {policy.newton_maxiter:>5} "
                          f"{row['wall_s']:>7.2f} {row['nfev']:>6} {row['accepted']:>5} "
                          f"{row['rejected']:>4} {row['tilt']:>10.5f} {row['d_tilt']:>8.1e} "
                          f"{row['d_aspect']:>8.1e}", flush=True)
            print(f"{'':>15} reference rtol {args.ref_rtol:g}: tilt {ref['tilt']:.6f}, aspect "
                  f"{ref['aspect']:.6f}, {ref['wall_s']:.1f} s", flush=True)
    finally:
        integrators.METHODS["radau5"] = default
    if args.out:
        pd.DataFrame(rows).to_parquet(args.out)


if __name__ == "__main__":
    main()
