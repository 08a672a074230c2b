"""Regenerate the figure suite of docs/figures/ (the paper's figures and their corrections).

Usage: python scripts/make_figures.py [--runs runs] [--out docs/figures] [--threads T]
                                      [--dry-run]

Runs what the figures need into --runs (gitignored; each step is skipped when its
output exists, and an interrupted sweep resumes), then draws everything with
``loopsim figures`` (loopsim/figures.py).  The steps, with their cost measured on
a shared 2-core machine in this project (other jobs running):

1. the main job, 225 loops at n = 6 (README): a few minutes;
2. the same grid at n = 4 (rkf45) and n = 8 (radau5): the paper's Fig. 9;
3. 24 representative cases at n = 16 (radau5, rtol 1e-7): the resolved reference
   drawn over Figs. 7 and 8 and its own gallery (θ0 = 30°);
4. g0 = 150, θ0 = 60°: 16 seeds at n = 6 and 12 at n = 16 (seed distributions),
   one trajectory at n = 6 and n = 16 with snapshots (Fig. 6), and an in-plane loop
   (g0 = 60, θ0 = 30°, n = 16) for the tension colouring (Fig. 1);
5. 4 cases at n = 24: the convergence check of docs/paper-comparison.md (not drawn).

Nothing here is random beyond the seeded initial perturbations (seed 0 unless
stated), so a rerun reproduces the tables.
"""
import argparse
import os
import shlex
import subprocess
import sys

import numpy as np
import pandas as pd

GRID = ["--g0", "10:350:15", "--theta0", "6:90:15"]
RESOLVED = ["--method", "radau5", "--rtol", "1e-7", "--atol", "1e-10"]


def resolved_cases(path):
    """The 24 representative cases (the main grid's g0 values): θ0 = 30° across g0,
    five at θ0 = 60° and four at 84°."""
    g = np.linspace(10, 350, 15)
    rows = [(g0, 30.0) for g0 in g]
    rows += [(g[i], 60.0) for i in (1, 2, 4, 6, 10)]
    rows += [(g[i], 84.0) for i in (1, 4, 8, 14)]
    pd.DataFrame(rows, columns=["g0", "theta0_deg"]).assign(n=16, seed=0).to_csv(path, index=False)


def n24_cases(path):
    g = np.linspace(10, 350, 15)
    rows = [(g[4], 30.0), (g[6], 60.0), (g[10], 30.0), (g[14], 84.0)]
    pd.DataFrame(rows, columns=["g0", "theta0_deg"]).assign(n=24, seed=0).to_csv(path, index=False)


def steps(runs, threads):
    """(output path, command) in order; a command is a list of loopsim arguments."""
    t = ["--threads", str(threads), "--quiet"]
    fig = os.path.join(runs, "fig")
    return [
        (os.path.join(runs, "phase"), ["sweep", *GRID, "--out", os.path.join(runs, "phase"), *t]),
        (os.path.join(runs, "phase_n4"),
         ["sweep", *GRID, "--n", "4", "--out", os.path.join(runs, "phase_n4"), *t]),
        (os.path.join(runs, "phase_n8"),
         ["sweep", *GRID, "--n", "8", "--method", "radau5", "--out", os.path.join(runs, "phase_n8"), *t]),
        (os.path.join(runs, "resolved_n16"),
         ["sweep", "--cases", os.path.join(fig, "resolved_cases.csv"), *RESOLVED,
          "--out", os.path.join(runs, "resolved_n16"), *t]),
        (os.path.join(runs, "seeds_n6"),
         ["sweep", "--g0", "150", "--theta0", "60", "--n", "6", "--seeds", "16",
          "--out", os.path.join(runs, "seeds_n6"), *t]),
        (os.path.join(runs, "seeds_n16"),
         ["sweep", "--g0", "150", "--theta0", "60", "--n", "16", "--seeds", "12", *RESOLVED,
          "--out", os.path.join(runs, "seeds_n16"), *t]),
        (os.path.join(fig, "g150_t60_n6.parquet"),
         ["run", "--g0", "150", "--theta0", "60", "--n", "6", "--t-end", "10", "--snapshots", "41",
          "--out", os.path.join(fig, "g150_t60_n6.parquet")]),
        (os.path.join(fig, "g150_t60_n16.parquet"),
         ["run", "--g0", "150", "--theta0", "60", "--n", "16", "--method", "radau5", "--t-end", "2",
          "--snapshots", "41", "--out", os.path.join(fig, "g150_t60_n16.parquet")]),
        (os.path.join(fig, "g60_t30_n16.parquet"),
         ["run", "--g0", "60", "--theta0", "30", "--n", "16", "--method", "radau5", "--t-end", "10",
          "--snapshots", "21", "--out", os.path.join(fig, "g60_t30_n16.parquet")]),
        (os.path.join(runs, "resolved_n24"),
         ["sweep", "--cases", os.path.join(fig, "n24_cases.csv"), *RESOLVED,
          "--out", os.path.join(runs, "resolved_n24"), *t]),
    ]


def figure_commands(runs, out):
    """Two ``loopsim figures`` calls: everything but the tension colouring (3D runs for
    Fig. 6), then the tension colouring of the in-plane loop only."""
    fig = os.path.join(runs, "fig")
    sweeps = [os.path.join(runs, d) for d in ("phase", "phase_n4", "phase_n8", "resolved_n16",
                                              "seeds_n6", "seeds_n16")]
    evolution = [os.path.join(fig, f) for f in ("g150_t60_n6.parquet", "g150_t60_n16.parquet")]
    return [
        ["figures", *sweeps, *evolution, "--out", out, "--only",
         "stability,gallery,phase,q_tilt,aspect,phase_n,seeds,evolution"],
        ["figures", sweeps[0], os.path.join(fig, "g60_t30_n16.parquet"), "--out", out,
         "--only", "tension"],
    ]


def loopsim(args, dry_run):
    command = [sys.executable, "-m", "loopsim", *args]
    print("$ " + " ".join(shlex.quote(a) for a in command), flush=True)
    if dry_run:
        return
    code = subprocess.run(command).returncode
    if code == 1 and args[0] == "sweep":  # some case failed: it is a row with its status
        print("# some cases failed (see their 'status'); going on", flush=True)
    elif code != 0:
        sys.exit(f"make_figures: '{' '.join(args[:2])} ...' exited with status {code}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default="runs", help="where the runs go (gitignored)")
    parser.add_argument("--out", default=os.path.join("docs", "figures"))
    parser.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--dry-run", action="store_true", help="print the commands only")
    args = parser.parse_args()
    fig = os.path.join(args.runs, "fig")
    os.makedirs(fig, exist_ok=True)
    resolved_cases(os.path.join(fig, "resolved_cases.csv"))
    n24_cases(os.path.join(fig, "n24_cases.csv"))
    for output, command in steps(args.runs, args.threads):
        # a sweep resumes by itself; a finished run file is kept
        if command[0] == "run" and os.path.exists(output):
            print(f"# {output} exists, kept")
            continue
        loopsim(command, args.dry_run)
    for command in figure_commands(args.runs, args.out):
        loopsim(command, args.dry_run)


if __name__ == "__main__":
    main()
