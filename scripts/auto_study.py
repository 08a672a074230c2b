"""Same-start study of ``n="auto"`` and of the determinacy estimate (docs/auto-and-determinacy.md).

    python scripts/auto_study.py [--cases G0:DEG[:SEED],...] [--json OUT.jsonl]

For each case the start is the tilted circle with its seeded perturbation at n = 6
(loopsim's default start).  From that one curve, at t = 0:

* ``auto``: ``simulate(n="auto")`` with every default (method auto, twin on);
* ``ref``: a fixed n = 32 radau5 run at rtol 1e-8, atol 1e-11 (the reference), and a
  fixed n = 24 run at rtol 1e-8 to show how well the reference itself is converged;
* ``pert``: ``n="auto"`` again from the start perturbed by 1e-6 (RMS, seed 1), no twin:
  how far a perturbation at the level of the tolerances moves the outcome.

Prints one line per case: the auto run's n_used, regime, determined flag and its
estimated tilt uncertainty, its actual distance from the reference (tilt, aspect
ratio), the reference's own n = 24 / 32 spread, the perturbed start's distance, and
the costs.  Run without a twin in the reference runs; no early stop (t = 10).
"""
import argparse
import json
import time
import warnings

from loopsim import api, shapes, spectral

CASES = ",".join([
    "20:60", "45:60", "60:30", "60:80", "80:45", "80:80", "100:30", "100:45", "100:60",
    "100:80", "120:30", "120:60", "150:30", "150:45", "150:60", "150:80", "180:30",
    "180:45", "180:60", "180:80", "200:30", "200:60", "250:30", "250:45", "250:80",
    "150:60:1", "150:60:2", "200:45:1",
])


def outcome(result):
    summary = result.summary()
    return dict(n_used=result.n_used, regime=result.regime, tilt=summary["theta_final_deg"],
                aspect=summary["aspect_ratio"], nfev=result.nfev, wall_s=result.wall_s,
                status=result.message)


def study(g0, theta0, seed):
    x0 = shapes.start_shape(theta0, 6, None, seed)[0]
    row = dict(g0=g0, theta0=theta0, seed=seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.perf_counter()
        auto = api.simulate(g0, initial=x0, perturbation=0.0, n="auto")
        row["auto_total_s"] = time.perf_counter() - start
        row["auto"] = outcome(auto)
        row["auto"].update(determined=auto.determined, **{
            k: auto.determinacy[k] for k in ("theta_uncertainty_deg", "aspect_uncertainty",
                                             "twin_nfev")})
        for n in (24, 32):
            ref = api.simulate(g0, initial=spectral.resize(x0, n), perturbation=0.0, n=n,
                               method="radau5", rtol=1e-8, atol=1e-11, twin=False)
            row[f"ref{n}"] = outcome(ref)
        pert = api.simulate(g0, initial=x0, perturbation=1e-6, seed=1, n="auto", twin=False)
        row["pert"] = outcome(pert)
    return row


def line(row):
    a, r, r24, p = row["auto"], row["ref32"], row["ref24"], row["pert"]
    return (f"{row['g0']:5g} {row['theta0']:4g} {row['seed']:2d} n_used {a['n_used']:2d} "
            f"{a['regime']:8s} det {str(a['determined']):5s} est {a['theta_uncertainty_deg']:8.2e}"
            f" | err {abs(a['tilt'] - r['tilt']):8.2e} ar {abs(a['aspect'] - r['aspect']):8.2e}"
            f" | ref24-32 {abs(r24['tilt'] - r['tilt']):8.2e} | pert {abs(p['tilt'] - a['tilt']):8.2e}"
            f" | auto {a['wall_s']:5.1f} s (+twin, total {row['auto_total_s']:5.1f} s)"
            f" ref32 {r['wall_s']:5.1f} s")


def markdown(rows):
    """The study as a Markdown table (docs/auto-and-determinacy.md)."""
    out = ["| g0 | θ0 | seed | n_used | regime | determined | estimate (deg) | error (deg) "
           "| error, aspect | n = 24 vs 32 (deg) | perturbed start (deg) | auto + twin (s) "
           "| reference (s) |", "|" + "---|" * 13]
    for row in rows:
        a, r, r24, p = row["auto"], row["ref32"], row["ref24"], row["pert"]
        out.append(
            f"| {row['g0']:g} | {row['theta0']:g} | {row['seed']} | {a['n_used']} | {a['regime']} "
            f"| {'yes' if a['determined'] else '**no**'} | {a['theta_uncertainty_deg']:.2g} "
            f"| {abs(a['tilt'] - r['tilt']):.2g} | {abs(a['aspect'] - r['aspect']):.2g} "
            f"| {abs(r24['tilt'] - r['tilt']):.2g} | {abs(p['tilt'] - a['tilt']):.2g} "
            f"| {row['auto_total_s']:.1f} | {r['wall_s']:.1f} |")
    return "\n".join(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=CASES)
    parser.add_argument("--json", help="also append each case as a JSON line to this file")
    parser.add_argument("--table", metavar="JSONL",
                        help="print the Markdown table of a saved study instead of running")
    args = parser.parse_args()
    if args.table:
        with open(args.table) as handle:
            print(markdown([json.loads(line) for line in handle]))
        return
    for spec in args.cases.split(","):
        parts = spec.split(":")
        row = study(float(parts[0]), float(parts[1]), int(parts[2]) if len(parts) > 2 else 0)
        print(line(row), flush=True)
        if args.json:
            with open(args.json, "a") as handle:
                handle.write(json.dumps(row) + "\n")


if __name__ == "__main__":
    main()
