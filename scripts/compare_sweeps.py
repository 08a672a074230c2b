"""Compare two sweeps of the same cases: regimes, terminal tilt and shape, cost.

Usage: python scripts/compare_sweeps.py REFERENCE OTHER [--tilt-tol 1] [--common] [--json FILE]
                                         [--moved FILE.csv]

REFERENCE and OTHER are sweep directories (``loopsim sweep --out``) over the same
(g0, θ0, seed) cases, for example the resolved grid (``--n auto``) and the paper's
n = 6 main job.  Rows are matched on (g0, theta0_deg, seed); with ``--common`` only the
cases both hold are compared (a sweep still running: its finished cases are a sample
spread over the grid, see ``storage.case_order``).  Prints, as Markdown:

* each sweep's regime counts, resolved rows and the distribution of ``n_used``;
* the regime cross-table (rows: REFERENCE, columns: OTHER) and how many cases change
  regime;
* how many cases move by more than ``--tilt-tol`` degrees in terminal tilt, and the
  largest moves in tilt and aspect ratio;
* cost: the sum of ``wall_s`` (core-seconds) and of RHS evaluations, and per-case wall
  time quantiles by ``n_used``.

``--moved FILE.csv`` writes every case that moved (its key, its case_id in each
sweep, both tilts and aspect ratios, the differences), largest move first.  With
OTHER the same sweep re-run at rtol / 10, these are the rows whose terminal tilt
changed by more than --tilt-tol with rtol.  Cases whose tilt is missing (failed) in
either sweep are not listed.
"""
import argparse
import json

import pandas as pd

import loopsim

KEY = ["g0", "theta0_deg", "seed"]


def counts(series):
    return {str(k): int(v) for k, v in sorted(series.value_counts().items())}


def summary(name, frame):
    return dict(name=name, cases=len(frame), regimes=counts(frame["regime"]),
                resolved=int(frame["resolved"].sum()), n_used=counts(frame["n_used"]),
                methods=counts(frame["method"]), wall_core_s=float(frame["wall_s"].sum()),
                nfev=int(frame["nfev"].sum()))


def compare(reference, other, tilt_tol, common=False):
    both = reference.merge(other, on=KEY, suffixes=("_ref", "_other"), validate="one_to_one")
    if not common and (len(both) != len(reference) or len(both) != len(other)):
        raise SystemExit(f"the sweeps hold different cases ({len(reference)} and {len(other)} "
                         f"rows, {len(both)} in common)")
    tilt = (both["theta_final_deg_other"] - both["theta_final_deg_ref"]).abs()
    aspect = (both["aspect_ratio_other"] - both["aspect_ratio_ref"]).abs()
    changed = both["regime_ref"] != both["regime_other"]
    moved = both.assign(d_tilt=tilt, d_aspect=aspect).loc[tilt > tilt_tol, KEY + [
        "case_id_ref", "case_id_other", "regime_ref", "regime_other",
        "theta_final_deg_ref", "theta_final_deg_other",
        "aspect_ratio_ref", "aspect_ratio_other", "d_tilt", "d_aspect"]]
    cross = pd.crosstab(both["regime_ref"], both["regime_other"])
    by_regime = {r: dict(cases=int((both["regime_ref"] == r).sum()),
                         moved=int(((both["regime_ref"] == r) & (tilt > tilt_tol)).sum()))
                 for r in sorted(both["regime_ref"].unique())}
    return dict(cases=len(both), cross=cross, changed=int(changed.sum()), moved=int((tilt > tilt_tol).sum()),
                moved_by_regime=by_regime, tilt_max=float(tilt.max()),
                aspect_max=float(aspect.max()),
                changed_cases=both.loc[changed, KEY + ["regime_ref", "regime_other"]],
                moved_cases=moved.sort_values("d_tilt", ascending=False, kind="stable"))


def markdown(frame, index=True):
    """A DataFrame as a Markdown table (no tabulate dependency)."""
    frame = frame.reset_index() if index else frame
    lines = ["| " + " | ".join(str(c) for c in frame.columns) + " |",
             "|" + "--:|" * len(frame.columns)]
    lines += ["| " + " | ".join(str(v) for v in row) + " |" for row in frame.itertuples(False)]
    return "\n".join(lines)


def wall_by_order(frame):
    rows = []
    for n, group in frame.groupby("n_used"):
        q = group["wall_s"].quantile([0.5, 0.9, 1.0]).to_numpy()
        rows.append((int(n), len(group), *q, group["wall_s"].sum()))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("reference")
    parser.add_argument("other")
    parser.add_argument("--tilt-tol", type=float, default=1.0,
                        help="a case 'moves' when its terminal tilts differ by more (degrees)")
    parser.add_argument("--common", action="store_true",
                        help="compare only the cases both sweeps hold")
    parser.add_argument("--json", help="also write the numbers to this JSON file")
    parser.add_argument("--moved", metavar="CSV", help="write the cases that moved to this CSV file")
    args = parser.parse_args()
    reference, other = loopsim.read_results(args.reference), loopsim.read_results(args.other)
    sums = [summary(args.reference, reference), summary(args.other, other)]
    for s in sums:
        print(f"## {s['name']}: {s['cases']} cases; regimes {s['regimes']}; resolved "
              f"{s['resolved']}; n_used {s['n_used']}; methods {s['methods']}; "
              f"sum of wall_s {s['wall_core_s']:.0f} core-s; RHS evaluations {s['nfev']}")
    result = compare(reference, other, args.tilt_tol, args.common)
    print(f"\nRegimes of the {result['cases']} cases both hold (rows: {args.reference}, "
          f"columns: {args.other}):\n")
    print(markdown(result["cross"]))
    print(f"\n{result['changed']} cases change regime; {result['moved']} move by more than "
          f"{args.tilt_tol}° in terminal tilt (by regime of the reference: "
          f"{result['moved_by_regime']}); largest |Δ tilt| {result['tilt_max']:.3g}°, "
          f"largest |Δ aspect ratio| {result['aspect_max']:.3g}")
    if result["changed"]:
        print(markdown(result["changed_cases"], index=False))
    if args.moved:
        result["moved_cases"].to_csv(args.moved, index=False)
        print(f"the {result['moved']} cases that moved: {args.moved}")
    for name, frame in ((args.reference, reference), (args.other, other)):
        print(f"\nWall time per case in {name}, by n_used (s):\n")
        print("| n_used | cases | median | 90% | max | sum |\n|--:|--:|--:|--:|--:|--:|")
        for n, k, median, p90, top, total in wall_by_order(frame):
            print(f"| {n} | {k} | {median:.3g} | {p90:.3g} | {top:.3g} | {total:.0f} |")
    if args.json:
        with open(args.json, "w") as handle:
            json.dump(dict(sweeps=sums, cases=result["cases"], changed=result["changed"], moved=result["moved"],
                           moved_by_regime=result["moved_by_regime"],
                           tilt_max=result["tilt_max"], aspect_max=result["aspect_max"],
                           cross=result["cross"].to_dict()), handle, indent=1)


if __name__ == "__main__":
    main()
