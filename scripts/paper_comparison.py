"""Numbers of docs/studies/paper-comparison.md, from the tables scripts/make_figures.py writes.

Usage: python scripts/paper_comparison.py [--runs runs] [--save-grids data]

Reads (through ``loopsim.read_results``) the n = 6 grid (runs/phase_n6, the README's
former main job), the same grid at n = 4 and n = 8, the 24 representative cases with --n auto
(runs/resolved_auto; runs/resolved_n24 at fixed n = 24 when run with --n24) and the
seed ensembles (n = 6, --n auto), and prints, per claim of the paper, the measured counts and
ranges.  Missing tables are skipped with a note.  ``--save-grids DIR`` also writes the case
tables of the grids at n = 4, 6 and 8 (``DIR/phase_n<n>_cases.parquet``, without the
coefficient column ``x_final``), every column described: the tables that
scripts/render_numbers.py renders the docs' n = 6 counts and Fig. 9's from.
"""
import argparse
import os

import numpy as np

import loopsim

Q_STAR = 8.9001  # the circle's in-plane threshold (docs/stability.md)


def load(runs, name):
    path = os.path.join(runs, name)
    try:
        return loopsim.read_results(path)
    except ValueError as exc:
        print(f"# {name}: skipped ({str(exc).splitlines()[0]})")
        return None


def regimes(frame):
    return ", ".join(f"{k} {v}" for k, v in sorted(frame["regime"].value_counts().items()))


def describe(name, f):
    used = ", ".join(f"{int(k)}: {v}" for k, v in sorted(f["n_used"].value_counts().items()))
    print(f"\n## {name}: {len(f)} cases, n = {sorted(int(v) for v in f['n'].unique())}, n_used {{{used}}}: "
          f"{regimes(f)}; resolved {int(f['resolved'].sum())}; "
          f"steady before t_end {int((f['stop_reason'] == 'steady').sum())}")
    print(f"methods {dict((str(k), int(v)) for k, v in f['method'].value_counts().items())}; tail_max largest {f['tail_max'].max():.2g}; "
          f"length_error_max largest {f['length_error_max'].max():.2g}; wall_s total "
          f"{f['wall_s'].sum():.0f}, largest {f['wall_s'].max():.0f}")
    stable, inplane, d3 = (f[f["regime"] == r] for r in ("stable", "in-plane", "3d"))
    if len(stable):
        print(f"settling angle, stable: max {stable['settling_angle_deg'].max():.4f} deg")
    for label, rows in (("in-plane", inplane), ("3d", d3)):
        if len(rows):
            print(f"settling angle, {label}: max {rows['settling_angle_deg'].max():.3f} deg")
    if len(stable) and len(f[f["regime"] != "stable"]):
        print(f"largest stable q0 {stable['q0'].max():.3f}; smallest non-stable q0 "
              f"{f[f['regime'] != 'stable']['q0'].min():.3f}")
    if len(inplane):
        print(f"in-plane q0: {len(inplane)} cases in [{inplane['q0'].min():.2f}, {inplane['q0'].max():.2f}]; "
              f"inside 10.5 < q0 < 18.5: {int(((inplane['q0'] > 10.5) & (inplane['q0'] < 18.5)).sum())}")
    if len(d3):
        smaller = int((d3["theta_final_deg"] < d3["theta0_deg"]).sum())
        flat = d3["theta_final_deg"] < 15
        round_ = d3["aspect_ratio"] < 1.05
        print(f"3d: smallest q0 {d3['q0'].min():.2f}; terminal tilt < initial in {smaller} of {len(d3)}; "
              f"tilt < 15 deg in {int(flat.sum())}; aspect ratio < 1.05 in {int(round_.sum())}; "
              f"both (near-horizontal circle) in {int((flat & round_).sum())}")
        print(f"3d: terminal tilt quartiles {np.round(d3['theta_final_deg'].quantile([.25, .5, .75]).to_numpy(), 1)}"
              f", aspect ratio quartiles {np.round(d3['aspect_ratio'].quantile([.25, .5, .75]).to_numpy(), 3)}"
              f", terminal q > 18.5 in {int((d3['q_final'] > 18.5).sum())}")
    band = f[(f["q0"] > 10.5) & (f["q0"] < 18.5)]
    if len(band):
        print(f"inside 10.5 < q0 < 18.5: {len(band)} cases, {regimes(band)}")
    if len(inplane):
        print("in-plane q0: " + ", ".join(f"{q:.2f}" for q in sorted(inplane["q0"])))
    if len(d3):
        print(f"3d: terminal q from {d3['q_final'].min():.2f} to {d3['q_final'].max():.1f}; "
              f"not resolved {int((~d3['resolved']).sum())} of {len(d3)}; length_error_max median "
              f"{d3['length_error_max'].median():.2g}, largest {d3['length_error_max'].max():.2g}; "
              f"still changing at t_end {int((d3['stop_reason'] == 't_end').sum())}")
    print(f"still changing at t_end: {int((f['stop_reason'] == 't_end').sum())} of {len(f)}")
    low = f[f["q_final"] < Q_STAR]
    if len(low):
        print(f"terminal q < {Q_STAR}: {len(low)} cases, aspect ratio <= 1.01 in "
              f"{int((low['aspect_ratio'] <= 1.01).sum())}, > 1.01 in "
              f"{int((low['aspect_ratio'] > 1.01).sum())} (of them steady: "
              f"{int(((low['aspect_ratio'] > 1.01) & (low['stop_reason'] == 'steady')).sum())})")


def pairs(low, high, label):
    """Cases of ``high`` (higher n) against the same (g0, θ0, seed) of ``low``."""
    keys = ["g0", "theta0_deg", "seed"]
    merged = high.merge(low, on=keys, suffixes=("", "_low"))
    if not len(merged):
        return
    print(f"\n## {label}")
    print("| g0 | θ0 | q0 | n_used (low / high) | regime (low / high) | tilt (low / high) | "
          "aspect ratio (low / high) | resolved (low / high) | tail_max (high) | wall s (high) |")
    for _, r in merged.iterrows():
        print(f"| {r['g0']:.1f} | {r['theta0_deg']:g} | {r['q0']:.1f} | {r['n_used_low']} / {r['n_used']} | "
              f"{r['regime_low']} / {r['regime']} | "
              f"{r['theta_final_deg_low']:.1f} / {r['theta_final_deg']:.1f} | "
              f"{r['aspect_ratio_low']:.3f} / {r['aspect_ratio']:.3f} | "
              f"{'yes' if r['resolved_low'] else 'no'} / {'yes' if r['resolved'] else 'no'} | "
              f"{r['tail_max']:.1e} | {r['wall_s']:.0f} |")


def save_cases(frame, path):
    """Write a sweep's case table to ``path`` (Parquet, without ``x_final``), each column's
    unit and description in its metadata, with the code version and the sweep's command."""
    import pyarrow as pa

    from loopsim import columns, storage

    import ast
    import subprocess

    config = frame.attrs.get("loopsim", {})
    kept = frame.drop(columns=[c for c in ("x_final",) if c in frame.columns]).reset_index(drop=True)
    words = config.get("command_line", [])
    words = ast.literal_eval(words) if isinstance(words, str) else list(words)
    # no machine's path: the executable and the output directory by name only
    words = ["loopsim"] + [os.path.basename(w) if os.path.isabs(w) else w for w in words[1:]]
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True, cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
    meta = {"loopsim_version": str(config.get("loopsim_version", "")),
            "code_commit": commit, "command_line": " ".join(words),
            "created_utc": str(config.get("created_utc_last", ""))}
    table = pa.Table.from_pandas(kept, preserve_index=False).replace_schema_metadata(meta)
    declarations = {name: columns.RESULT_COLUMNS[name] for name in kept.columns
                    if name in columns.RESULT_COLUMNS}
    declarations["round"] = ("count", "the --seeds auto round of the row (0 for a fixed-seed sweep)")
    storage.write_table_atomically(storage.described(table, declarations), path)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default="runs")
    parser.add_argument("--save-grids", metavar="DIR",
                        help="also write the case tables of the grids at n = 4, 6 and 8 to "
                             "DIR/phase_n<n>_cases.parquet")
    args = parser.parse_args()
    tables = {name: load(args.runs, name) for name in
              ("phase_n6", "phase_n4", "phase_n8", "resolved_auto", "resolved_n24", "seeds_n6",
               "seeds_auto")}
    for name, frame in tables.items():
        if frame is not None and len(frame):
            describe(name, frame)
    for name in ("phase_n4", "phase_n6", "phase_n8"):
        if args.save_grids and tables[name] is not None:
            save_cases(tables[name], os.path.join(args.save_grids, f"{name}_cases.parquet"))
    if tables["phase_n6"] is not None and tables["resolved_auto"] is not None:
        pairs(tables["phase_n6"], tables["resolved_auto"], "n = 6 grid against --n auto")
    if tables["resolved_auto"] is not None and tables["resolved_n24"] is not None:
        pairs(tables["resolved_auto"], tables["resolved_n24"], "--n auto against n = 24")


if __name__ == "__main__":
    main()
