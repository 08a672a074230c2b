"""Regenerate the figure suite of docs/figures/ (the paper's figures and their corrections).

Usage: python scripts/make_figures.py [--runs runs] [--out docs/figures] [--threads T]
                                      [--max-wall SECONDS] [--n24] [--dry-run]

Runs what the figures need into --runs (gitignored; each step is skipped when its
output exists, and an interrupted sweep resumes), then draws everything with
``loopsim figures`` (loopsim/figures.py).  The steps:

1. the main job, 225 loops at n = 6 (rkf45, the README's);
2. the same grid at n = 4 (rkf45) and n = 8 (radau5): the paper's Fig. 9;
3. 24 representative cases (θ0 = 30° across the grid's g0, five at 60°, four at 84°)
   with automatic truncation: ``--n auto --n-max 32 --method auto --rtol 1e-7
   --atol 1e-10`` (each starts at n = 6 from the main job's curve and climbs the
   ladder 6, 8, 12, ... 32 whenever its spectral tail passes the default --tail-tol
   1e-5; rows carry n_used, tail_max, resolved).  The resolved reference, drawn over
   Figs. 7 and 8 and as its own gallery (θ0 = 30°).  Run cheapest first (increasing
   q0), one case per chunk file, so a --max-wall cap keeps every finished case and
   drops the highest-q0 ones;
4. g0 = 150, θ0 = 60°: 16 seeds at n = 6 and 12 seeds with the settings of step 3
   (seed distributions); one trajectory at n = 6 and at fixed n = 16 (radau5, t = 2,
   kept from the earlier suite) with snapshots
   (Fig. 6), the same start with the settings of step 3 (t = 10: the fixed n = 16 run
   fails the `resolved` test, its spectral tail reaching 5.8e-5; this one ends at
   n_used 20, resolved), and an in-plane loop (g0 = 60, θ0 = 30°, n = 16) for the tension
   colouring (Fig. 1);
5. only with --n24: 4 cases at fixed n = 24 (radau5, rtol 1e-7), a check not drawn
   (--n auto's own tail criterion now says which rows are resolved; see README,
   "Automatic truncation", for its check against n_used + 8).

What was run for the committed figures (December 2026; a shared 2-core machine, one
thread, ``nice -n 10``, another engineer's benchmark on the other core):
``python scripts/make_figures.py --runs runs --out docs/figures --threads 1
--max-wall 1500``, after steps 1-2 had been run with the same commands (the script
then found them complete in 3-5 s each; a first start of step 3 in the grid's order,
stopped after 10 min with 7 cases, was set aside and the cases reordered).  Wall times:
step 1 379 s; n = 4 135 s (1 of 225 cases failed: length error); n = 8 617 s;
step 3 stopped at the 1500 s cap with 20 of the 24 cases done (n_used 12: 5,
16: 5, 20: 3, 24: 4, 32: 3; 18 resolved, the other two at n_max = 32 with tail_max
1.6e-5 and 1.7e-5); the four not run are the highest q0 (58.3, 67.7, 73.0, 116.0).
Cost grows steeply with q0 (column wall_s): q0 <= 30.9 at most 3.3 s per case,
q0 = 34-45 2.6-40 s, q0 = 46.2, 50.2, 54.3 (n_used 32) 304, 361 and 507 s.  rtol 1e-7
was kept; 1e-6 was not tried.
Step 4: seeds at n = 6 16 s; the 12 --n auto seeds 139 s (all resolved; n_used 20: 7,
24: 5); the runs 5 s (n = 6), n = 16 8 s, the in-plane n = 16 run 7 s; the pipeline
took 1716 s in all.  The --n auto trajectory was added afterwards and run alone with
its step's command (12 s; n_used 20, tail_max 4.4e-6), then the two ``loopsim figures``
commands below were re-run (17 s and 6 s).

Nothing here is random beyond the seeded initial perturbations (seed 0 unless
stated), so a rerun reproduces the tables.
"""
import argparse
import os
import shlex
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd

from loopsim.io import case_order

GRID = ["--g0", "10:350:15", "--theta0", "6:90:15"]
#: Resolved runs: automatic truncation (start at n = 6, climb the ladder 6, 8, 12, ... 32
#: whenever the spectral tail passes the default --tail-tol 1e-5), integrator chosen per case.
RESOLVED = ["--n", "auto", "--n-max", "32", "--method", "auto", "--rtol", "1e-7", "--atol", "1e-10"]
#: A fixed-n check at n = 24 (radau5), not drawn: only with --n24.
FIXED_N24 = ["--method", "radau5", "--rtol", "1e-7", "--atol", "1e-10"]


def resolved_cases(path):
    """The 24 representative cases (the main grid's g0 values): θ0 = 30° across g0,
    five at θ0 = 60° and four at 84°.  Written so that the sweep runs them in order of
    increasing q0 (cost grows steeply with q0): the sweep's k-th chunk of one case is
    case ``case_order(24)[k]``, so a --max-wall cap drops the highest-q0 cases first."""
    g = np.linspace(10, 350, 15)
    rows = [(g0, 30.0) for g0 in g]
    rows += [(g[i], 60.0) for i in (1, 2, 4, 6, 10)]
    rows += [(g[i], 84.0) for i in (1, 4, 8, 14)]
    rows.sort(key=lambda r: r[0] * np.sin(np.radians(r[1])))
    table = [None] * len(rows)
    for k, case_id in enumerate(case_order(len(rows))):
        table[case_id] = rows[k]
    # n: the start of the --n auto ladder (the n = 6 main job's initial curve, zero-padded)
    pd.DataFrame(table, columns=["g0", "theta0_deg"]).assign(n=6, seed=0).to_csv(path, index=False)


def n24_cases(path):
    g = np.linspace(10, 350, 15)
    rows = [(g[4], 30.0), (g[6], 60.0), (g[10], 30.0), (g[14], 84.0)]
    pd.DataFrame(rows, columns=["g0", "theta0_deg"]).assign(n=24, seed=0).to_csv(path, index=False)


def steps(runs, threads, n24=False):
    """(output path, command, capped) in order; a command is a list of loopsim arguments;
    ``capped``: the resolved sweeps, which --max-wall may stop (they run one case per chunk
    file, so every finished case is kept and a re-run resumes)."""
    t = ["--threads", str(threads), "--quiet"]
    fig = os.path.join(runs, "fig")
    one = ["--chunk-size", "1"]
    out = [
        (os.path.join(runs, "phase"), ["sweep", *GRID, "--out", os.path.join(runs, "phase"), *t], False),
        (os.path.join(runs, "phase_n4"),
         ["sweep", *GRID, "--n", "4", "--out", os.path.join(runs, "phase_n4"), *t], False),
        (os.path.join(runs, "phase_n8"),
         ["sweep", *GRID, "--n", "8", "--method", "radau5", "--out", os.path.join(runs, "phase_n8"),
          *t], False),
        (os.path.join(runs, "resolved_auto"),
         ["sweep", "--cases", os.path.join(fig, "resolved_cases.csv"), *RESOLVED, *one,
          "--out", os.path.join(runs, "resolved_auto"), *t], True),
        (os.path.join(runs, "seeds_n6"),
         ["sweep", "--g0", "150", "--theta0", "60", "--n", "6", "--seeds", "16",
          "--out", os.path.join(runs, "seeds_n6"), *t], False),
        (os.path.join(runs, "seeds_auto"),
         ["sweep", "--g0", "150", "--theta0", "60", "--seeds", "12", *RESOLVED, *one,
          "--out", os.path.join(runs, "seeds_auto"), *t], True),
        (os.path.join(fig, "g150_t60_n6.parquet"),
         ["run", "--g0", "150", "--theta0", "60", "--n", "6", "--t-end", "10", "--snapshots", "41",
          "--out", os.path.join(fig, "g150_t60_n6.parquet")], False),
        (os.path.join(fig, "g150_t60_n16.parquet"),
         ["run", "--g0", "150", "--theta0", "60", "--n", "16", "--method", "radau5", "--t-end", "2",
          "--snapshots", "41", "--out", os.path.join(fig, "g150_t60_n16.parquet")], False),
        (os.path.join(fig, "g150_t60_auto.parquet"),
         ["run", "--g0", "150", "--theta0", "60", *RESOLVED, "--t-end", "10", "--snapshots", "41",
          "--out", os.path.join(fig, "g150_t60_auto.parquet")], False),
        (os.path.join(fig, "g60_t30_n16.parquet"),
         ["run", "--g0", "60", "--theta0", "30", "--n", "16", "--method", "radau5", "--t-end", "10",
          "--snapshots", "21", "--out", os.path.join(fig, "g60_t30_n16.parquet")], False),
    ]
    if n24:
        out.append((os.path.join(runs, "resolved_n24"),
                    ["sweep", "--cases", os.path.join(fig, "n24_cases.csv"), *FIXED_N24, *one,
                     "--out", os.path.join(runs, "resolved_n24"), *t], True))
    return out


def figure_commands(runs, out):
    """Two ``loopsim figures`` calls: everything but the tension colouring (3D runs for
    Fig. 6), then the tension colouring of the in-plane loop only."""
    fig = os.path.join(runs, "fig")
    sweeps = [os.path.join(runs, d) for d in ("phase", "phase_n4", "phase_n8", "resolved_auto",
                                              "seeds_n6", "seeds_auto")]
    evolution = [os.path.join(fig, f) for f in ("g150_t60_n6.parquet", "g150_t60_n16.parquet",
                                                "g150_t60_auto.parquet")]
    return [
        ["figures", *sweeps, *evolution, "--out", out, "--only",
         "stability,gallery,phase,q_tilt,aspect,phase_n,seeds,evolution"],
        ["figures", sweeps[0], os.path.join(fig, "g60_t30_n16.parquet"), "--out", out,
         "--only", "tension"],
    ]


def loopsim(args, dry_run, max_wall=None):
    """Run ``python -m loopsim ARGS``; ``max_wall``: seconds after which a sweep gets
    SIGTERM (it keeps its finished cases and exits 143; the figures use those)."""
    command = [sys.executable, "-m", "loopsim", *args]
    print("$ " + " ".join(shlex.quote(a) for a in command)
          + (f"    # capped at {max_wall:g} s" if max_wall else ""), flush=True)
    if dry_run:
        return
    start = time.monotonic()
    process = subprocess.Popen(command)
    try:
        code = process.wait(timeout=max_wall)
    except subprocess.TimeoutExpired:
        process.send_signal(signal.SIGTERM)
        code = process.wait()
    wall = time.monotonic() - start
    print(f"# wall {wall:.0f} s, exit status {code}", flush=True)
    if code == 1 and args[0] == "sweep":  # some case failed: it is a row with its status
        print("# some cases failed (see their 'status'); going on", flush=True)
    elif code == 143 and max_wall and args[0] == "sweep":
        print(f"# stopped at the {max_wall:g} s cap: finished cases kept (re-run to resume)",
              flush=True)
    elif code != 0:
        sys.exit(f"make_figures: '{' '.join(args[:2])} ...' exited with status {code}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default="runs", help="where the runs go (gitignored)")
    parser.add_argument("--out", default=os.path.join("docs", "figures"))
    parser.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--max-wall", type=float, default=None, metavar="SECONDS",
                        help="stop each resolved sweep (--n auto, and --n24) after this many "
                             "seconds and draw from the cases it finished (default: no cap)")
    parser.add_argument("--n24", action="store_true",
                        help="also run the fixed n = 24 check (4 cases, not drawn)")
    parser.add_argument("--dry-run", action="store_true", help="print the commands only")
    args = parser.parse_args()
    if args.max_wall is not None and args.max_wall <= 0:
        parser.error("--max-wall must be positive")
    fig = os.path.join(args.runs, "fig")
    os.makedirs(fig, exist_ok=True)
    resolved_cases(os.path.join(fig, "resolved_cases.csv"))
    n24_cases(os.path.join(fig, "n24_cases.csv"))
    for output, command, capped in steps(args.runs, args.threads, args.n24):
        # a sweep resumes by itself; a finished run file is kept
        if command[0] == "run" and os.path.exists(output):
            print(f"# {output} exists, kept")
            continue
        loopsim(command, args.dry_run, args.max_wall if capped else None)
    for command in figure_commands(args.runs, args.out):
        loopsim(command, args.dry_run)


if __name__ == "__main__":
    main()
