"""Regenerate every figure of docs/figures/ (the paper's, their corrections, the docs').

Usage: python scripts/make_figures.py [--runs runs] [--out docs/figures] [--threads T]
                                      [--max-wall SECONDS] [--only NAME[,NAME...]] [--list]
                                      [--quick] [--n24] [--dry-run]

Runs what the figures need into --runs (gitignored; a finished run file is kept, a sweep
resumes, so a second call only draws), then draws each PNG of docs/figures/ (and the
GIF animations and the example HTML report, through ``loopsim animate`` and ``loopsim
report``) with
loopsim.figures (the functions behind ``loopsim figures``, ``sweep
--figure`` and ``summary --figure``, the last one through the command itself).
``--only`` draws the named figures (stems of the PNG files, see ``--list``) and runs only
the steps they need.  ``--quick`` exercises every step and every drawing end to end on
tiny inputs (3 x 3 grids, t = 0.5, --n-max 8, 3 seeds, Fig. 3 and the steady branch at
n = 6), in about a minute with a warm Numba cache: a test, never figures to commit.

The steps (the runs), with the figures that need them:

* ``phase_n6``: the 225-loop n = 6 grid (``--g0 10:350:15 --theta0 6:90:15``, rkf45),
  the paper's resolution: fig4_gallery, fig5_phase, fig7_q_tilt, fig8_aspect, phase_n6;
* ``phase_n4``, ``phase_n8``: the same grid at n = 4 (rkf45) and n = 8 (radau5):
  fig9_phase_n;
* ``resolved_auto``: 24 representative cases (θ0 = 30° across the grid's g0, five at
  60°, four at 84°) with ``--n auto --n-max 32 --method auto --rtol 1e-7 --atol 1e-10``,
  run cheapest first (increasing q0), one case per chunk file, so that a --max-wall cap
  keeps every finished case and drops the highest-q0 ones: the reference drawn over
  Figs. 7 and 8 and fig4_gallery_resolved_auto;
* ``seeds_n6``, ``seeds_auto``: g0 = 150, θ0 = 60°, 16 seeds at n = 6 and 12 with the
  settings of ``resolved_auto``: seed_distributions;
* ``g150_t60_n6``, ``g150_t60_n16``, ``g150_t60_auto``: that start at n = 6 (t = 10),
  n = 16 (radau5, t = 2) and with the settings of ``resolved_auto`` (t = 10), 41
  snapshots each: fig6_evolution (one row each, one time scale);
* ``g60_t30_n16``: the in-plane loop g0 = 60, θ0 = 30°, n = 16 (radau5):
  fig1_tension_g60_t30_n16;
* ``main_job``: the README's main job, its exact command (72 loops at ``--n auto``,
  with twins) into ``runs/phase``: phase_main, fig7_q_tilt_main, fig8_aspect_main (Figs.
  7 and 8 of a resolved grid);
* ``seeds_auto_study``: docs/studies/seeds.md's study, ``--seeds auto`` (at most 32) at
  ``--n auto`` with twins over g0 = 30, 60, 100 x θ0 = 30, 60°: seeds_auto_study
  (``loopsim summary --figure``; ``scripts/distribution_study.py`` runs the same sweep
  and its stricter-tolerance check);
* ``seeds_auto_grid``: docs/studies/seeds.md's grid study, the main job's 72 points at
  ``--seeds auto`` (at most 16) with twins: seeds_auto_grid (``loopsim summary
  --figure``; ``scripts/distribution_study.py`` runs the same sweep and its resolution
  check);
* ``seed_cells``: docs/studies/seeds.md's four cells (g0 = 100, 150 x θ0 = 45, 60°),
  16 seeds each at ``--n auto`` with twins: seed_cells (``loopsim summary --figure``);
* ``nonlocal_eps1e-2``, ``nonlocal_eps1e-3``: the main job's grid at ``--n auto`` under
  nonlocal SBT (``--model nonlocal --slenderness``; at 1e-2 the ladder ends at n = 10):
  phase_nonlocal_eps1e-2, phase_nonlocal_eps1e-3, and with ``main_job``
  nonlocal_outcomes (docs/nonlocal.md);
* ``movie_stable``, ``movie_in_plane``, ``movie_3d``: g0 = 10, θ0 = 30° (t = 6);
  g0 = 60, θ0 = 30° (t = 6); g0 = 150, θ0 = 60° (t = 3), each at ``--n auto`` with 121
  snapshots: anim_stable, anim_in_plane, anim_3d (``loopsim animate``, GIF); ``main_job``
  also gives report_main_job.html (``loopsim report``);
* ``resolved_n24`` (only with --n24): 4 cases at fixed n = 24 (radau5, rtol 1e-7), a
  check not drawn.

The figure suite's own runs (all but ``main_job`` and ``seed_cells``) skip the twin
(``--no-twin``): these figures draw no determinacy, and the twin would cost 1.5-2.5x.
work_precision (docs/studies/performance.md) runs ``benchmarks/bench_trajectory.py`` itself
(``WORK_PRECISION``: about 15 minutes on one core); paper_range (docs/studies/paper-range.md)
runs ``scripts/paper_range_study.py``, which also writes its tables into data/;
paper_range_top redraws the top of that range from the sweeps committed under
data/paper_range_runs (``paper_range_study.py --top --read-only``: the parts themselves
take hours each and run apart, see docs/studies/paper-range.md); rest_survival and
rest_tilts redraw the run-to-rest study from data/rest_runs (``rest_study.py
--read-only``, docs/studies/rest.md); paper_range_overview and range_survival draw the
whole range from the committed tables and sweeps (``range_overview.py``).  Fig. 3 and
nonlocal_thresholds (the circle's critical q against ε) need no run.  Nothing
here is random beyond the seeded initial perturbations
(seed 0 unless stated), so a rerun reproduces the tables.

What was run for the committed figures, and when: docs/figures.md ("Regenerating the
figures").
"""
import argparse
import os
import shlex
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd

from loopsim.storage import case_order

#: The paper's grid (225 loops) and its --quick stand-in (9 loops).
GRID = ["--g0", "10:350:15", "--theta0", "6:90:15"]
QUICK_GRID = ["--g0", "10:150:3", "--theta0", "10:90:3"]
#: The README's main job (README.md, first code block), its grid and its --quick stand-in.
MAIN_JOB = ["--g0", "10:150:8", "--theta0", "10:90:9", "--n", "auto"]
QUICK_MAIN_JOB = ["--g0", "10:150:3", "--theta0", "10:90:3", "--n", "auto"]
#: Resolved runs: automatic truncation (start at n = 6, climb the ladder 6, 8, 12, ... 32
#: whenever the spectral tail passes the default --tail-tol 1e-5), integrator chosen per case.
RESOLVED = ["--n", "auto", "--n-max", "32", "--method", "auto", "--rtol", "1e-7", "--atol", "1e-10"]
#: A fixed-n check at n = 24 (radau5), not drawn: only with --n24.
FIXED_N24 = ["--method", "radau5", "--rtol", "1e-7", "--atol", "1e-10"]
#: The slendernesses of the nonlocal phase diagrams (the main job's grid, docs/nonlocal.md).
NONLOCAL_SLENDERNESS = ("1e-2", "1e-3")
#: Figures of loopsim figures at this resolution; the phase diagrams as sweep --figure draws them.
DPI, PHASE_DPI = 110, 200
#: Figures drawn at a lower resolution to stay under 300 kB (fig6_evolution: three rows).
FIGURE_DPI = {"fig6_evolution": 80}
#: The animations of docs/getting-started.md, one per regime: (run step, g0, θ0, t_end),
#: each at ``--n auto`` with 121 snapshots, drawn by ``loopsim animate`` (60 frames).
MOVIES = (("movie_stable", "10", "30", "6"), ("movie_in_plane", "60", "30", "6"),
          ("movie_3d", "150", "60", "3"))
#: docs/studies/performance.md's work-precision figure: ``benchmarks/bench_trajectory.py`` (terminal
#: tilt at t = 2 against a same-start radau5 rtol 1e-11 run; radau5 now and at the
#: benchmark's baseline revision, scipy's LSODA and BDF on loopsim's compiled kernels), and
#: its --quick stand-in (one case at n = 8, t = 0.1, two tolerances, no baseline).
WORK_PRECISION = ["--cases", "150:45,100:60", "--orders", "16,24",
                  "--methods", "radau5,radau5-old,lsoda,bdf", "--repeats", "2"]
QUICK_WORK_PRECISION = ["--cases", "100:60", "--orders", "8", "--methods", "radau5,lsoda,bdf",
                        "--rtols", "1e-3,1e-5", "--repeats", "1", "--t-end", "0.1",
                        "--reference-rtol", "1e-9"]


def resolved_cases(path, quick=False):
    """The 24 representative cases (the main grid's g0 values): θ0 = 30° across g0,
    five at θ0 = 60° and four at 84° (--quick: three at 30°, one at 60°).  Written so that
    the sweep runs them in order of increasing q0 (cost grows steeply with q0): the
    sweep's k-th chunk of one case is case ``case_order(24)[k]``, so a --max-wall cap drops
    the highest-q0 cases first."""
    g = np.linspace(10, 350, 15)
    if quick:
        rows = [(10.0, 30.0), (60.0, 30.0), (100.0, 30.0), (60.0, 60.0)]
    else:
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


def steps(runs, threads, quick=False, n24=False):
    """{name: (output path, loopsim arguments, capped)} in running order; ``capped``: the
    --n auto sweeps, which --max-wall may stop (they keep every finished case, and a
    re-run resumes)."""
    t = ["--threads", str(threads), "--quiet"]
    fig = os.path.join(runs, "fig")
    one = ["--chunk-size", "1"]
    lean = ["--no-twin"]  # the figure suite's own runs: no determinacy drawn
    grid, main_job = (QUICK_GRID, QUICK_MAIN_JOB) if quick else (GRID, MAIN_JOB)
    resolved = RESOLVED
    short, short_run = [], ["--t-end", "10"]
    seeds_n6, seeds_auto, seeds_cells, snapshots = "16", "12", "16", "41"
    if quick:
        resolved = [*RESOLVED[:2], "--n-max", "8", *RESOLVED[4:]]
        short = short_run = ["--t-end", "0.5"]
        seeds_n6 = seeds_auto = seeds_cells = "3"
        snapshots = "5"
    auto_quick = ["--n-max", "8"] if quick else []

    def sweep(name, *args, capped=False):
        path = os.path.join(runs, name)
        return name, (path, ["sweep", *args, *short, "--out", path, *t], capped)

    def run(name, *args):
        path = os.path.join(fig, f"{name}.parquet")
        return name, (path, ["run", *args, "--snapshots", snapshots, *lean, "--out", path], False)

    out = dict([
        run("g150_t60_n6", "--g0", "150", "--theta0", "60", "--n", "6", *short_run),
        run("g150_t60_n16", "--g0", "150", "--theta0", "60", "--n", "16", "--method", "radau5",
            "--t-end", "0.5" if quick else "2"),
        run("g150_t60_auto", "--g0", "150", "--theta0", "60", *resolved, *short_run),
        run("g60_t30_n16", "--g0", "60", "--theta0", "30", "--n", "16", "--method", "radau5",
            *short_run),
        sweep("seeds_n6", "--g0", "150", "--theta0", "60", "--n", "6", "--seeds", seeds_n6, *lean),
        sweep("seeds_auto", "--g0", "150", "--theta0", "60", "--seeds", seeds_auto, *resolved,
              *lean, *one, capped=True),
        sweep("phase_n6", *grid, "--n", "6", *lean),
        sweep("phase_n4", *grid, "--n", "4", *lean),
        sweep("phase_n8", *grid, "--n", "8", "--method", "radau5", *lean),
        sweep("resolved_auto", "--cases", os.path.join(fig, "resolved_cases.csv"), *resolved,
              *lean, *one, capped=True),
        sweep("phase", *main_job, *auto_quick, capped=True),
        sweep("seed_cells", "--g0", "100,150", "--theta0", "45,60", "--seeds", seeds_cells,
              "--n", "auto", *auto_quick, capped=True),
        sweep("seeds_auto_study", "--g0", "30,60,100", "--theta0", "30,60", "--seeds", "auto",
              "--max-seeds", "4" if quick else "32", "--n", "auto", *auto_quick, capped=True),
        sweep("seeds_auto_grid", *main_job, "--seeds", "auto", "--max-seeds",
              "4" if quick else "16", *auto_quick, capped=True),
        *(sweep(f"nonlocal_eps{eps}", *main_job, *auto_quick, "--model", "nonlocal",
                "--slenderness", eps, *lean, capped=True) for eps in NONLOCAL_SLENDERNESS),
    ])
    # the animations' runs: many snapshots, each ending once its shape has settled
    movie_snapshots = "5" if quick else "121"
    for name, g0, theta0, t_end in MOVIES:
        path = os.path.join(fig, f"{name}.parquet")
        out[name] = (path, ["run", "--g0", g0, "--theta0", theta0, "--n", "auto",
                            "--t-end", "0.5" if quick else t_end, "--snapshots", movie_snapshots,
                            *lean, "--out", path], False)
    out["main_job"] = out.pop("phase")  # the README's --out runs/phase, under a clearer name
    if n24:
        out.update([sweep("resolved_n24", "--cases", os.path.join(fig, "n24_cases.csv"),
                          *FIXED_N24, *one, *lean, capped=True)])
    return out


def targets(quick=False):
    """{figure stem: (steps it needs, how it is drawn)}: every PNG of docs/figures/.  How:
    ("figures", main step, other steps, loopsim figures' name, its output stem), ("phase",
    step) for a plain phase diagram, ("summary", step) for ``loopsim summary --figure``,
    ("stability",), ("nonlocal_stability",), ("models", step, step, ...) for
    ``figures.model_outcomes`` (one column per step's model), ("animate", step) for
    ``loopsim animate`` (a GIF) or ("report", step) for ``loopsim report`` (an HTML page)."""
    runs3 = ["g150_t60_n6", "g150_t60_n16", "g150_t60_auto"]
    nonlocal_steps = [f"nonlocal_eps{eps}" for eps in NONLOCAL_SLENDERNESS]
    return {
        "fig1_tension_g60_t30_n16": (["g60_t30_n16"],
                                     ("figures", "seeds_n6", ["g60_t30_n16"], "tension",
                                      "fig1_tension_g60_t30_n16")),
        "fig3_stability": ([], ("stability",)),
        "fig4_gallery": (["phase_n6"], ("figures", "phase_n6", [], "gallery", "fig4_gallery")),
        "fig4_gallery_resolved_auto": (["resolved_auto"],
                                       ("figures", "phase_n6", ["resolved_auto"], "gallery",
                                        "fig4_gallery_resolved_auto")),
        "fig5_phase": (["phase_n6"], ("figures", "phase_n6", [], "phase", "fig5_phase")),
        "fig6_evolution": (runs3, ("figures", "seeds_n6", runs3, "evolution", "fig6_evolution")),
        "fig7_q_tilt": (["phase_n6", "resolved_auto"],
                        ("figures", "phase_n6", ["resolved_auto"], "q_tilt", "fig7_q_tilt")),
        "fig7_q_tilt_main": (["main_job"], ("figures", "main_job", [], "q_tilt", "fig7_q_tilt")),
        "fig8_aspect": (["phase_n6", "resolved_auto"],
                        ("figures", "phase_n6", ["resolved_auto"], "aspect", "fig8_aspect")),
        "fig8_aspect_main": (["main_job"], ("figures", "main_job", [], "aspect", "fig8_aspect")),
        "fig9_phase_n": (["phase_n4", "phase_n8"],
                         ("figures", "phase_n6", ["phase_n4", "phase_n8"], "phase_n",
                          "fig9_phase_n")),
        "phase_main": (["main_job"], ("phase", "main_job")),
        "phase_n6": (["phase_n6"], ("phase", "phase_n6")),
        **{f"phase_nonlocal_eps{eps}": ([f"nonlocal_eps{eps}"], ("phase", f"nonlocal_eps{eps}"))
           for eps in NONLOCAL_SLENDERNESS},
        "nonlocal_thresholds": ([], ("nonlocal_stability",)),
        "nonlocal_outcomes": (["main_job", *nonlocal_steps],
                              ("models", "main_job", *nonlocal_steps)),
        "seed_cells": (["seed_cells"], ("summary", "seed_cells")),
        "seeds_auto_study": (["seeds_auto_study"], ("summary", "seeds_auto_study")),
        "seeds_auto_grid": (["seeds_auto_grid"], ("summary", "seeds_auto_grid")),
        **{f"anim_{step[len('movie_'):]}": ([step], ("animate", step)) for step, *_ in MOVIES},
        "report_main_job": (["main_job"], ("report", "main_job")),
        "work_precision": ([], ("benchmark",)),
        "paper_range": ([], ("study",)),
        "paper_range_top": ([], ("study_top",)),
        "rest_survival": ([], ("rest_study",)),
        "rest_tilts": ([], ("rest_study",)),
        "paper_range_overview": ([], ("range_overview",)),
        "range_survival": ([], ("range_overview",)),
        "seed_distributions": (["seeds_n6", "seeds_auto"],
                               ("figures", "seeds_n6", ["seeds_n6", "seeds_auto"], "seeds",
                                "seed_distributions")),
    }


def needed_steps(names, table):
    """The steps the figures ``names`` need: their own, and the main sweep ``loopsim
    figures`` reads for them."""
    need = set()
    for name in names:
        own, how = table[name]
        need.update(own)
        if how[0] == "figures":
            need.add(how[1])
        elif how[0] in ("phase", "summary", "animate", "report"):
            need.add(how[1])
    return need


def loopsim(args, dry_run, max_wall=None):
    """Run ``loopsim ARGS``: in this process (``loopsim.cli.main``), or, with ``max_wall``,
    as ``python -m loopsim ARGS`` that gets SIGTERM after ``max_wall`` seconds (a sweep
    keeps its finished cases and exits 143; the figures use those).  Returns the wall
    time."""
    command = [sys.executable, "-m", "loopsim", *args]
    print("$ " + " ".join(shlex.quote(a) for a in (command if max_wall else ["loopsim", *args]))
          + (f"    # capped at {max_wall:g} s" if max_wall else ""), flush=True)
    if dry_run:
        return 0.0
    start = time.monotonic()
    if max_wall is None:
        from loopsim import cli

        argv, sys.argv = sys.argv, ["loopsim", *args]  # what a sweep records as its command
        try:
            code = cli.main(list(args))
        except SystemExit as exc:  # argparse
            code = exc.code if isinstance(exc.code, int) else 2
        finally:
            sys.argv = argv
    else:
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
    return wall


def draw(name, how, paths, out, work, quick):
    """Draw figure ``name`` into ``out``/``name``.png; ``paths``: {step: its output}."""
    import matplotlib

    matplotlib.use("Agg")
    from loopsim import figures, read_results

    kind = how[0]
    target = os.path.join(out, name + {"animate": ".gif", "report": ".html"}.get(kind, ".png"))
    if kind == "animate":
        loopsim(["animate", paths[how[1]], "--out", target], dry_run=False)
    elif kind == "report":
        loopsim(["report", paths[how[1]], "--out", target], dry_run=False)
    elif kind == "benchmark":
        command = [sys.executable, os.path.join(os.path.dirname(__file__), os.pardir,
                                                "benchmarks", "bench_trajectory.py"),
                   *(QUICK_WORK_PRECISION if quick else WORK_PRECISION),
                   "--out", os.path.join(work, f"{name}.json"), "--figure", target]
        print("$ " + " ".join(shlex.quote(a) for a in command), flush=True)
        os.makedirs(work, exist_ok=True)
        os.makedirs(out, exist_ok=True)
        subprocess.run(command, check=True, env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    elif kind in ("study", "study_top"):
        script = os.path.join(os.path.dirname(__file__), "paper_range_study.py")
        data = os.path.join(work, "data") if quick else "data"
        if kind == "study":
            runs = os.path.dirname(os.path.dirname(work))  # --runs (work is RUNS/fig/draw)
            command = [sys.executable, script, "--runs", runs, "--figure", target,
                       "--data", data, *(["--quick"] if quick else [])]
        else:  # the committed parts, redrawn
            command = [sys.executable, script, "--top", "--read-only", "--figure", target,
                       "--data", data]
        print("$ " + " ".join(shlex.quote(a) for a in command), flush=True)
        os.makedirs(out, exist_ok=True)
        subprocess.run(command, check=True)
    elif kind == "rest_study":  # the run-to-rest study's two figures, from its committed runs
        script = os.path.join(os.path.dirname(__file__), "rest_study.py")
        table = os.path.join(work, "rest_study.parquet") if quick else \
            os.path.join("data", "rest_study.parquet")
        command = [sys.executable, script, "--read-only", "--out", table, "--figures", out,
                   *(["--window-n", "8", "--range-out",
                      os.path.join(work, "paper_range_rest_summary.parquet")] if quick else [])]
        print("$ " + " ".join(shlex.quote(a) for a in command), flush=True)
        os.makedirs(work, exist_ok=True)
        os.makedirs(out, exist_ok=True)
        subprocess.run(command, check=True)
    elif kind == "range_overview":  # the whole range from the committed tables: no run
        script = os.path.join(os.path.dirname(__file__), "range_overview.py")
        table = os.path.join(work, "paper_range_overview.parquet") if quick else \
            os.path.join("data", "paper_range_overview.parquet")
        command = [sys.executable, script, "--out", table,
                   "--figure", os.path.join(out, "paper_range_overview.png"),
                   *(["--window-n", "8"] if quick else [])]
        print("$ " + " ".join(shlex.quote(a) for a in command), flush=True)
        os.makedirs(work, exist_ok=True)
        os.makedirs(out, exist_ok=True)
        subprocess.run(command, check=True)
    elif kind == "stability":
        n = 6 if quick else 16
        fig = figures.stability(*figures.stability_data(n=n, n_values=range(3, n + 1)))
        figures.save(fig, target, dpi=DPI)
    elif kind == "nonlocal_stability":
        eps = (1e-2, 1e-4) if quick else (1e-2, 3e-3, 1e-3, 1e-4, 1e-6, 1e-9, 1e-12)
        figures.save(figures.nonlocal_thresholds(eps, n=6 if quick else 8), target, dpi=DPI)
    elif kind == "models":
        frames = [read_results(paths[step]) for step in how[1:]]
        figures.save(figures.model_outcomes(frames), target, dpi=DPI)
    elif kind == "phase":
        frame = read_results(paths[how[1]])
        figures.save(figures.phase_diagram(frame, rest_window=figures.rest_window_for(frame)),
                     target, dpi=PHASE_DPI)
    elif kind == "summary":
        loopsim(["summary", paths[how[1]], "--figure", target], dry_run=False)
    else:
        _, main, others, figure, stem = how
        staging = os.path.join(work, name)
        shutil.rmtree(staging, ignore_errors=True)
        written = figures.write_figures(paths[main], [paths[o] for o in others], staging,
                                        only=[figure], stability_n=6 if quick else 16,
                                        branch_n=6 if quick else 12,
                                        dpi=FIGURE_DPI.get(name, DPI), log=lambda _: None)
        if stem not in written:
            raise SystemExit(f"make_figures: {name}: loopsim figures drew {sorted(written)}, "
                             f"not {stem}")
        os.makedirs(out, exist_ok=True)
        shutil.copyfile(written[stem], target)
    print(f"{name}: {target}", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default="runs", help="where the runs go (gitignored)")
    parser.add_argument("--out", default=os.path.join("docs", "figures"))
    parser.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--max-wall", type=float, default=None, metavar="SECONDS",
                        help="stop each --n auto sweep after this many seconds and draw from "
                             "the cases it finished (default: no cap)")
    parser.add_argument("--only", metavar="NAME[,NAME...]",
                        help="draw these figures (PNG stems; see --list) and run what they need")
    parser.add_argument("--list", action="store_true",
                        help="print each figure with the steps it needs, and stop")
    parser.add_argument("--quick", action="store_true",
                        help="tiny inputs (3 x 3 grids, t = 0.5, n-max 8, 3 seeds): exercises "
                             "every step and drawing in about a minute; not figures to commit")
    parser.add_argument("--n24", action="store_true",
                        help="also run the fixed n = 24 check (4 cases, not drawn)")
    parser.add_argument("--dry-run", action="store_true", help="print the commands only")
    args = parser.parse_args()
    if args.max_wall is not None and args.max_wall <= 0:
        parser.error("--max-wall must be positive")
    table = targets(args.quick)
    names = (sorted(table) if args.only is None
             else [v.strip() for v in args.only.split(",") if v.strip()])
    unknown = sorted(set(names) - set(table))
    if unknown:
        parser.error(f"unknown figure(s) {', '.join(unknown)}; "
                     f"choose from {', '.join(sorted(table))}")
    if args.quick and os.path.abspath(args.out) == os.path.abspath(os.path.join("docs", "figures")):
        parser.error("--quick figures are not docs figures: give another --out")
    all_steps = steps(args.runs, args.threads, args.quick, args.n24)
    if args.list:
        for name in sorted(table):
            print(f"{name}: {', '.join(sorted(needed_steps([name], table))) or '(no run)'}")
        return
    fig = os.path.join(args.runs, "fig")
    if not args.dry_run:  # --dry-run prints the commands and writes nothing
        os.makedirs(fig, exist_ok=True)
        resolved_cases(os.path.join(fig, "resolved_cases.csv"), args.quick)
        n24_cases(os.path.join(fig, "n24_cases.csv"))
    need = needed_steps(names, table) | ({"resolved_n24"} if args.n24 else set())
    start = time.monotonic()
    for step, (output, command, capped) in all_steps.items():
        if step not in need:
            continue
        if command[0] == "run" and os.path.exists(output):  # a sweep resumes by itself
            print(f"# {output} exists, kept")
            continue
        loopsim(command, args.dry_run, args.max_wall if capped else None)
    if args.dry_run:
        return
    paths = {step: output for step, (output, _, _) in all_steps.items()}
    work = os.path.join(fig, "draw")
    for name in names:
        draw(name, table[name][1], paths, args.out, work, args.quick)
    print(f"# {len(names)} figures in {args.out}, {time.monotonic() - start:.0f} s in all",
          flush=True)


if __name__ == "__main__":
    main()
