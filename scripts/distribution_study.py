"""Outcomes as distributions over a grid of points (docs/studies/seeds.md).

Usage: python scripts/distribution_study.py [--runs runs/distributions] [--threads T]
                                            [--g0 30,60,100] [--theta0 30,60]
                                            [--max-seeds 32]
                                            [--check tolerance|resolution]
                                            [--check-seeds 16] [--check-n 32]
                                            [--check-g0 SPEC] [--check-theta0 SPEC]

1. ``--seeds auto`` at ``--n auto`` (with twins) over the grid (``--g0`` and ``--theta0``
   as ``loopsim sweep`` takes them: ``10:150:8`` or ``30,60``): every point gets seeds
   until it is deterministic, sharp or at --max-seeds, or has failed (``RUNS/auto``);
2. the points that did not stop as deterministic (those at --check-g0 and --check-theta0
   only, when given) again, with --check-seeds fixed seeds and no twins (``RUNS/<check>``), either at
   10x stricter rtol and atol (``--check tolerance``) or at the fixed order --check-n
   from the same starts as ``--n auto`` (``--check resolution``, run on --threads
   processes), compared in distribution (``loopsim.compare``) and row by row with the
   first sweep's seeds 0 .. --check-seeds - 1;
3. writes the summary (``RUNS/summary.parquet``) and the comparison
   (``RUNS/compare-<check>.parquet``), prints them and the stop table as Markdown, and
   draws ``RUNS/summary.png`` (regime probabilities per point, tilt and aspect ratio over seeds).

Every step resumes: re-run the same command after an interruption.
"""
import argparse
import concurrent.futures
import math
import multiprocessing
import os
import time

import pandas as pd
import pyarrow as pa

import loopsim
from loopsim import columns, defaults, refinement, seeds_auto_rule, shapes, spectral, storage, sweeps
from loopsim.cli.common import directory_name, print_and_write, use_agg
from loopsim.figures import save_distribution_figure

#: What the second step varies, and the tolerances of ``--check tolerance``.
CHECKS = ("tolerance", "resolution")
STRICT = dict(rtol=1e-7, atol=1e-10)


def markdown(frame, columns, formats):
    head = "| " + " | ".join(columns) + " |\n|" + "---|" * len(columns) + "\n"
    rows = ["| " + " | ".join(formats.get(c, "{}").format(row[c]) for c in columns) + " |"
            for _, row in frame.iterrows()]
    return head + "\n".join(rows)


def check_cells(stops, g0, theta0):
    """The cells to check: not deterministic and not failed (no run succeeded: nothing to
    compare), and at one of ``g0`` and ``theta0`` when given (None: any)."""
    cells = stops[~stops["stop_reason"].isin([seeds_auto_rule.DETERMINISTIC, seeds_auto_rule.FAILED])]
    for column, values in (("g0", g0), ("theta0_deg", theta0)):
        if values is not None:
            cells = cells[cells[column].isin(values)]
    return [dict(g0=r.g0, theta0_deg=r.theta0_deg) for r in cells.itertuples()]


def same_start_run(g0, theta0_deg, seed, n):
    """One run at the fixed order ``n`` from the start ``--n auto`` uses (the circle with
    its seeded perturbation at the ladder's first order, zero-padded exactly to ``n``),
    with the sweep's defaults and early stop, no twin: its summary row."""
    start = shapes.initial_shape(refinement.AUTO_START, math.radians(theta0_deg),
                                 defaults.DEFAULT_PERTURBATION, seed)
    result = loopsim.simulate(g0, None, initial=spectral.resize(start, n), n=n, method="auto",
                              twin=False, steady_tol=defaults.DEFAULT_STEADY_TOL,
                              steady_interval=defaults.DEFAULT_STEADY_INTERVAL)
    # the cell's inputs as given (the measured tilt differs from them by the perturbation)
    return dict(result.summary(), g0=g0, theta0_deg=theta0_deg, seed=seed, n=n)


def resolution_check(cells, args, directory):
    """Seeds 0 .. --check-seeds - 1 of each cell at the fixed order --check-n from the
    same starts as ``--n auto``, on --threads processes; one Parquet file per cell in
    ``directory`` (written whole, so a rerun skips the cells done)."""
    os.makedirs(directory, exist_ok=True)
    frames, todo = [], []
    for cell in cells:
        path = os.path.join(directory, f"g{cell['g0']:g}_t{cell['theta0_deg']:g}.parquet")
        if os.path.exists(path):
            frames.append(storage.read_table_checked(path).to_pandas())  # damaged: named
        else:
            todo.append((cell, path))
    context = multiprocessing.get_context("spawn")  # no fork of a process that ran prange
    with concurrent.futures.ProcessPoolExecutor(args.threads or os.cpu_count(),
                                                mp_context=context) as pool:
        for cell, path in todo:
            rows = list(pool.map(same_start_run, *zip(*[
                (cell["g0"], cell["theta0_deg"], seed, args.check_n)
                for seed in range(args.check_seeds)])))
            frame = pd.DataFrame(rows)
            storage.write_table_atomically(pa.Table.from_pandas(frame, preserve_index=False), path)
            print(f"{args.check} check: g0 = {cell['g0']:g}, theta0 = {cell['theta0_deg']:g}: "
                  f"{frame['wall_s'].sum():.0f} s summed", flush=True)
            frames.append(frame)
    return pd.concat(frames, ignore_index=True)


def run_check(cells, args):
    """Each cell again with --check-seeds seeds and no twins, as --check says: at 10x
    stricter tolerances (a ``--n auto`` sweep) or at the fixed order --check-n."""
    directory = os.path.join(args.runs, args.check)
    if args.check == "resolution":
        return resolution_check(cells, args, directory)
    options = dict(STRICT, twin=False, threads=args.threads, quiet=False)
    return pd.concat([
        loopsim.sweep([c["g0"]], [c["theta0_deg"]],
                      os.path.join(directory, f"g{c['g0']:g}_t{c['theta0_deg']:g}"),
                      n="auto", seeds=args.check_seeds, **options)
        for c in cells], ignore_index=True)


def single_run_reading(rows, cells):
    """Per cell, what its seed-0 run (a one-run-per-cell sweep's row, the paper's
    reading) says against the cell's distribution: its regime and that regime's
    probability, and its terminal tilt's rank among the seeds (0: lowest, 1: highest)
    and whether it lies inside the median's 95 % interval."""
    out = []
    for cell in cells.itertuples():
        seeds = rows[(rows["g0"] == cell.g0) & (rows["theta0_deg"] == cell.theta0_deg)]
        first = seeds[seeds["seed"] == 0].iloc[0]
        tilt = first["theta_final_deg"]
        out.append(dict(g0=cell.g0, theta0_deg=cell.theta0_deg, seeds=len(seeds),
                        regime_0=first["regime"],
                        p_regime_0=float((seeds["regime"] == first["regime"]).mean()),
                        tilt_0=tilt, tilt_median=cell.tilt_median,
                        tilt_rank_0=float((seeds["theta_final_deg"] < tilt).mean()),
                        in_median_interval=bool(cell.tilt_median_low <= tilt
                                                <= cell.tilt_median_high)))
    return pd.DataFrame(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default=os.path.join("runs", "distributions"))
    parser.add_argument("--threads", type=int, default=None)
    parser.add_argument("--g0", default="30,60,100")
    parser.add_argument("--theta0", default="30,60")
    parser.add_argument("--max-seeds", type=int, default=32)
    parser.add_argument("--check", choices=CHECKS, default="tolerance")
    parser.add_argument("--check-seeds", type=int, default=16)
    parser.add_argument("--check-n", type=int, default=32)
    parser.add_argument("--check-g0", default=None)
    parser.add_argument("--check-theta0", default=None)
    args = parser.parse_args()
    g0 = sweeps.parse_values(args.g0, "--g0")
    theta0 = sweeps.parse_values(args.theta0, "--theta0")
    check_g0, check_theta0 = (
        None if text is None else sweeps.parse_values(text, name)
        for text, name in ((args.check_g0, "--check-g0"), (args.check_theta0, "--check-theta0")))

    started = time.perf_counter()
    auto_dir = os.path.join(args.runs, "auto")
    rows = loopsim.sweep(g0, theta0, auto_dir, n="auto", seeds="auto",
                         max_seeds=args.max_seeds, threads=args.threads, quiet=False)
    auto_s = time.perf_counter() - started
    stops = storage.read_stop_table(auto_dir)
    cells = loopsim.summarize(rows)

    started = time.perf_counter()
    comparison = None
    checked = check_cells(stops, check_g0, check_theta0)
    if checked:
        again = run_check(checked, args)
        # both checks repeat the same starts, seeds 0 .. K-1
        first = rows[rows["seed"] < args.check_seeds]
        comparison = loopsim.compare(first, again, by=["g0", "theta0_deg"])
        paired = first.merge(again, on=["g0", "theta0_deg", "seed"], suffixes=("", "_check"))
        shift = (paired["theta_final_deg"] - paired["theta_final_deg_check"]).abs()
        print(f"row by row ({len(paired)} pairs): |tilt - tilt_check| median "
              f"{shift.median():.3g} deg, largest {shift.max():.3g} deg; same regime in "
              f"{int((paired['regime'] == paired['regime_check']).sum())}")
    check_s = time.perf_counter() - started

    use_agg()
    save_distribution_figure(cells, rows, os.path.join(args.runs, "summary.png"))
    print(f"\nseeds auto: {len(rows)} runs, {auto_s:.0f} s, "
          f"{rows['wall_s'].sum():.0f} s summed case time; "
          f"{args.check} check of {len(checked)} points: {check_s:.0f} s")
    print_and_write(cells, os.path.join(args.runs, "summary.parquet"),
                    dict(cells.attrs["loopsim_summary"], summary_of=directory_name(auto_dir)),
                    ["g0", "theta0_deg", "seeds", "p_3d", "tilt_median"],
                    declarations=columns.SUMMARY_COLUMNS)
    print("\n" + markdown(stops, ["g0", "theta0_deg", "seeds", "rounds", "stop_reason",
                                  "p_halfwidth", "tilt_halfwidth_deg"],
                          {"p_halfwidth": "{:.3f}", "tilt_halfwidth_deg": "{:.2f}"}))
    print("\n" + markdown(cells, ["g0", "theta0_deg", "seeds", "determined", "p_stable",
                                  "p_in_plane", "p_3d", "tilt_median", "tilt_q25", "tilt_q75",
                                  "tilt_median_low", "tilt_median_high", "aspect_median"],
                          {c: "{:.3g}" for c in ["p_stable", "p_in_plane", "p_3d"]}
                          | {c: "{:.2f}" for c in ["tilt_median", "tilt_q25", "tilt_q75",
                                                   "tilt_median_low", "tilt_median_high"]}
                          | {"aspect_median": "{:.3f}"}))
    reading = single_run_reading(rows, cells)
    print("\nthe seed-0 run (one run per cell) against its cell's seeds:")
    print(reading.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    if comparison is not None:
        print_and_write(comparison, os.path.join(args.runs, f"compare-{args.check}.parquet"),
                        dict(compared=f"{args.check} check"), ["g0", "theta0_deg", "verdict"],
                        declarations=columns.COMPARE_COLUMNS)
        print("\n" + markdown(comparison, ["g0", "theta0_deg", "seeds_a", "seeds_b",
                                           "tilt_ks_p", "aspect_ks_p", "regime_p",
                                           "tilt_wasserstein", "verdict"],
                              {"tilt_ks_p": "{:.2f}", "aspect_ks_p": "{:.2f}",
                               "regime_p": "{:.2f}", "tilt_wasserstein": "{:.2f}"}))


if __name__ == "__main__":
    main()
