"""Tumbling samples: radau5's cost per window of a chaotic tumbling loop, with its Jacobian
at y (``RadauIIA.jacobian_point`` 0, before issue 44) and inside the step (the default),
and scipy's LSODA and BDF on loopsim's compiled F and J, all priced at the same compiled
unit costs, in one process.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_tumbling.py --out runs/tumbling.json
    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_tumbling.py --windows 0:0.5,1:1.5 \
        --repeats 3 --out runs/tumbling_wall.json    # counts and wall time only

The loop: (g0, θ0) = (350, 18°), seed 0, n = 32, the default perturbation: it tumbles, and
accurate runs of it part x10 every ~0.04 t_u (a finite-time Lyapunov exponent of ~60 per
t_u, issue 44).  Windows (``--windows START:END,...``; default [0, 0.1], [1, 1.1] and
[2, 2.1]) start at t = 0 from the seeded start (``shapes.start_shape``, as ``loopsim run
--g0 350 --theta0 18 --n 32`` builds it) or at later times from the states recorded in
``benchmarks/tumbling_start.json`` (at t = 0.5, 1, 1.5 and 2, from one radau5 run from
t = 0 at rtol 1e-8, by its dense output; ``--record-start`` runs it again and rewrites the
file; the loop tumbles at t = 0.5-1.5 and is calm at t = 2).  Windows longer than
``--accuracy-length`` are counted and timed only.

For each window, rtol (``--rtols``, atol = rtol / 1000) and Jacobian point (``--points``):
radau5's counts (steps, rejected, nfev, njev, nlu), its priced cost and its wall time (the
median of ``--repeats``, the points interleaved).  The priced cost is the counts times the
compiled unit costs measured at the start of the same run: F (``models.rhs``); J, the
Jacobian given F(y) (``models.jacobian``); the LU pair (one real and one
complex LAPACK getrf of the Newton matrices, ``integrators.radau.newton_matrices``, as
radau5 factorises both per nlu); one real LU for scipy's methods; each timed in a compiled
loop.  radau5's nfev counts the velocity its Jacobian evaluates inside, so its price is
(nfev - njev) F + njev J + nlu LU pair; scipy's is nfev F + njev J + nlu LU, what a
compiled method with its step and order choices would pay.

Accuracy: each run's end state against a reference from the same start (radau5 at
``--reference-rtol``, atol = reference-rtol / 1000), as the largest coefficient
difference (units L / 2π).  Windows must be short (default 0.1 t_u): over a window of
length T nearby runs part by ~e^(60 T) (400 for 0.1), so the error mixes each step's
local error with that growth, and over much longer windows it says nothing.  The
reference's own error is bounded by its distance from a second reference at 10x its rtol,
printed as the smallest difference the check can detect.

Equal error: radau5 with each Jacobian point also at ``--curve-rtols`` (its priced cost
against error), LSODA and BDF (``--scipy``) at ``--scipy-rtols``; each point is priced
against each radau5 curve at the same error (log-log interpolation).
"""
import argparse
import json
import os
import subprocess
import sys
import time

import numba
import numpy as np

import loopsim
from loopsim import defaults, integrators, linalg, models
from loopsim.integrators import driver
from loopsim.integrators import radau as radau_iia
from loopsim.models import local_sbt
from loopsim.shapes import loading

G0, THETA0, N, SEED = 350.0, 18.0, 32, 0
START_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "tumbling_start.json")
#: The recorded starts' run: t = 0 to the last of START_TIMES at START_RTOL (atol =
#: START_RTOL / 1000), its states at START_TIMES by its dense output.
START_TIMES, START_RTOL = (0.5, 1.0, 1.5, 2.0), 1e-8


def problem_of(n):
    """The loop's problem at order n (local slender-body theory, the default w)."""
    return local_sbt.LoopProblem(G0, defaults.DEFAULT_W, local_sbt.make_operators(n),
                                 local_sbt.make_workspace(n))


def radau(problem, y0, t0, t1, rtol, point, **fields):
    """radau5 with ``jacobian_point`` = point (and any other ``RadauIIA`` fields changed)
    from y0 at t0 to t1, atol = rtol / 1000: (wall s, status, end state, counts [steps,
    rejected, nfev, njev, nlu])."""
    method = integrators.RADAU5._replace(jacobian_point=point, **fields)
    options = integrators.step_options(rtol, rtol * 1e-3)
    start = time.perf_counter()
    status, _, y, counts, _ = driver.integrate(method, problem, y0.copy(), t0, t1, None,
                                               options, None)
    return time.perf_counter() - start, int(status), y, [int(c) for c in counts]


def scipy_run(problem, y0, t0, t1, rtol, method):
    """solve_ivp(method) on loopsim's compiled F and exact J: as :func:`radau`."""
    from scipy.integrate import solve_ivp

    aux = np.empty(y0.size // 3)

    def fun(_, y):
        dydt = np.empty_like(y)
        models.evaluate(problem, y, dydt, aux)
        return dydt

    def jac(_, y):
        out = np.empty((y.size, y.size))
        models.evaluate_jacobian(problem, y, out)
        return out

    start = time.perf_counter()
    sol = solve_ivp(fun, (t0, t1), y0.copy(), method=method.upper(), rtol=rtol,
                    atol=rtol * 1e-3, jac=jac)
    wall = time.perf_counter() - start
    return wall, int(sol.status), sol.y[:, -1].copy(), [int(sol.t.size - 1), 0, int(sol.nfev),
                                                        int(sol.njev), int(sol.nlu)]


@numba.njit(cache=True)
def _rhs_loop(problem, y, dydt, repeats):
    for _ in range(repeats):
        models.rhs(problem, y, dydt)


@numba.njit(cache=True)
def _jacobian_loop(problem, y, f, jac, work_y, work_f, repeats):
    for _ in range(repeats):
        models.jacobian(problem, y, f, jac, work_y, work_f)


@numba.njit(cache=True)
def _lu_pair_loop(jac, h, lu_real, piv_real, lu_complex, piv_complex, repeats):
    for _ in range(repeats):
        radau_iia.newton_matrices(jac, h, lu_real, piv_real, lu_complex, piv_complex)


@numba.njit(cache=True)
def _lu_loop(matrix, lu, piv, repeats):
    for _ in range(repeats):
        for i in range(matrix.shape[0]):
            for j in range(matrix.shape[1]):
                lu[i, j] = matrix[i, j]
        linalg.lu_factor(lu, piv)


def unit_costs(problem, y, repeats=200):
    """Seconds per F, per J given F(y) (``models.jacobian``: the velocity it evaluates
    inside included), per LU pair (radau5's ``newton_matrices``: a real and a complex
    LAPACK getrf) and per real LU (a copy and getrf), each in a compiled loop at y, the
    fastest of three timed loops."""
    n = y.size
    f, scratch, scratch_f = np.empty(n), np.empty(n), np.empty(n)
    jac, lu, lu_c = np.empty((n, n)), np.empty((n, n)), np.empty((n, n), dtype=complex)
    piv, piv_c = np.empty(n, dtype=linalg.PIVOT_DTYPE), np.empty(n, dtype=linalg.PIVOT_DTYPE)
    models.evaluate_jacobian(problem, y, jac)
    matrix = np.diag(np.full(n, radau_iia.MU_REAL / 1e-4)) - jac
    loops = dict(f=(_rhs_loop, (problem, y, f), repeats),
                 j=(_jacobian_loop, (problem, y, f, jac, scratch, scratch_f), repeats // 10),
                 lu_pair=(_lu_pair_loop, (jac, 1e-4, lu, piv, lu_c, piv_c), repeats // 4),
                 lu=(_lu_loop, (matrix, lu, piv), repeats // 4))
    costs = {}
    for name, (loop, arguments, k) in loops.items():
        loop(*arguments, 1)  # compile (cached)
        best = np.inf
        for _ in range(3):
            start = time.perf_counter()
            loop(*arguments, k)
            best = min(best, (time.perf_counter() - start) / k)
        costs[name] = best
    return costs


def priced(counts, units, method):
    """Seconds the counts cost at the compiled unit costs (module docstring)."""
    _, _, nfev, njev, nlu = counts
    if method == "radau5":
        return (nfev - njev) * units["f"] + njev * units["j"] + nlu * units["lu_pair"]
    return nfev * units["f"] + njev * units["j"] + nlu * units["lu"]


def record_start(problem, x0):
    """Run t = 0 to START_TIMES[-1] at START_RTOL and write its states at START_TIMES to
    START_FILE."""
    method = integrators.RADAU5
    options = integrators.step_options(START_RTOL, START_RTOL * 1e-3)
    times = np.array(START_TIMES)
    states = np.empty((times.size, x0.size))
    start = time.perf_counter()
    status, _, _, counts, _ = driver.integrate(method, problem, x0.copy(), 0.0, times[-1],
                                               times, options, states)
    wall = time.perf_counter() - start
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True, cwd=os.path.dirname(START_FILE)).stdout.strip()
    with open(START_FILE, "w") as handle:
        json.dump(dict(g0=G0, theta0=THETA0, n=N, seed=SEED, rtol=START_RTOL,
                       atol=START_RTOL * 1e-3, status=int(status),
                       counts=[int(c) for c in counts],
                       code=f"loopsim {loopsim.__version__} at commit {commit}: radau5, "
                            f"jacobian_point {method.jacobian_point:g}",
                       states={f"{t:g}": y.tolist() for t, y in zip(START_TIMES, states)}),
                  handle, indent=0)
    print(f"recorded the states at t = {', '.join(f'{t:g}' for t in START_TIMES)} "
          f"({int(counts[2])} RHS evaluations, {wall:.0f} s, status {int(status)}) in "
          f"{START_FILE}")


def start_state(t0, x0):
    """The window's start: the seeded start at t = 0, else the recorded state at t0."""
    if t0 == 0.0:
        return x0
    with open(START_FILE) as handle:
        states = json.load(handle)["states"]
    if f"{t0:g}" not in states:
        raise SystemExit(f"no recorded state at t = {t0:g} (only at {', '.join(states)})")
    return np.array(states[f"{t0:g}"])


def equal_error_cost(curve, error):
    """radau5's priced cost at ``error`` along its (error, cost) points; NaN outside."""
    points = sorted((e, c) for e, c in curve if e > 0)
    e = np.log([p[0] for p in points])
    c = np.log([p[1] for p in points])
    if not points or not (e[0] <= np.log(error) <= e[-1]):
        return float("nan")
    return float(np.exp(np.interp(np.log(error), e, c)))


def row_line(window, rtol, label, counts, cost, wall, error):
    return (f"| {window} | {rtol:g} | {label} | {counts[0]} | {counts[1]} | {counts[2]} | "
            f"{counts[3]} | {counts[4]} | {cost:.3f} | {wall:.2f} | {error:.1e} |")


def reference(args, problem, t0, t1, y0):
    """(reference end state, the difference it could detect), printed; (None, NaN) for a
    window that is counted only."""
    window = f"[{t0:g}, {t1:g}]"
    if t1 - t0 > args.accuracy_length * (1 + 1e-9):  # [1, 1.1] is 0.1 long
        print(f"\n## window {window}: counts and wall time only (runs part ~x"
              f"{np.exp(60 * (t1 - t0)):.0e} over it: its end states are not compared)\n")
        return None, float("nan")
    _, status, y_ref, counts = radau(problem, y0, t0, t1, args.reference_rtol, args.points[-1])
    _, _, y_check, _ = radau(problem, y0, t0, t1, 10 * args.reference_rtol, args.points[-1])
    floor = float(np.max(np.abs(y_check - y_ref)))
    print(f"\n## window {window}: reference rtol {args.reference_rtol:g} (status {status}, "
          f"nfev {counts[2]}); it differs from rtol {10 * args.reference_rtol:g} by {floor:.1e}: "
          f"end-state differences below ~{floor:.0e} are not resolved; runs part ~x"
          f"{np.exp(60 * (t1 - t0)):.0f} over the window (Lyapunov exponent ~60)\n")
    return y_ref, floor


def window_runs(args, problem, units, t0, t1, y0, rows):
    """Every run of one window; appends its rows and prints them."""
    window = f"[{t0:g}, {t1:g}]"
    y_ref, floor = reference(args, problem, t0, t1, y0)
    print("| window | rtol | method | steps | rejected | nfev | njev | nlu | priced s | wall s "
          "| end-state error |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")

    def add(method, point, rtol, wall, status, y, counts):
        row = dict(window=[t0, t1], method=method, jacobian_point=point, rtol=rtol,
                   status=status, counts=counts, wall_s=wall, priced_s=priced(counts, units,
                                                                               method),
                   error=float("nan") if y_ref is None else float(np.max(np.abs(y - y_ref))),
                   reference_floor=floor)
        rows.append(row)
        label = f"radau5, J at {point:g}" if method == "radau5" else method
        print(row_line(window, rtol, label, counts, row["priced_s"], wall, row["error"]),
              flush=True)
        return row

    for rtol in args.rtols:
        walls = {p: [] for p in args.points}
        found = {}
        for _ in range(args.repeats):
            for point in args.points:
                wall, status, y, counts = radau(problem, y0, t0, t1, rtol, point)
                walls[point].append(wall)
                found[point] = (status, y, counts)
        pair = [add("radau5", p, rtol, float(np.median(walls[p])), *found[p])
                for p in args.points]
        if len(pair) == 2:
            old, new = pair
            print(f"|  | {rtol:g} | ratio J at {args.points[1]:g} / at {args.points[0]:g} | "
                  + " | ".join(f"{b / max(a, 1):.2f}" for a, b in zip(old["counts"],
                                                                      new["counts"]))
                  + f" | {new['priced_s'] / old['priced_s']:.2f} | "
                    f"{new['wall_s'] / old['wall_s']:.2f} | |", flush=True)
    if y_ref is None:
        return
    for rtol in sorted(set(args.curve_rtols) - set(args.rtols), reverse=True):
        for point in args.points:
            add("radau5", point, rtol, *radau(problem, y0, t0, t1, rtol, point))
    for method in args.scipy:
        for rtol in args.scipy_rtols:
            add(method, None, rtol, *scipy_run(problem, y0, t0, t1, rtol, method))


def equal_error_summary(args, rows):
    """Each run's priced cost over radau5's with each Jacobian point at the same error
    (along that point's curve), geometric means by window and method."""
    print("\nequal-error priced cost over radau5's, by window (points with an error above "
          "3x the reference's floor, inside the curve's range):")
    for window in sorted({tuple(r["window"]) for r in rows if np.isfinite(r["error"])}):
        group = [r for r in rows if tuple(r["window"]) == window and r["status"] == 0
                 and r["error"] > 3 * r["reference_floor"]]
        for point in args.points:
            curve = [(r["error"], r["priced_s"]) for r in group
                     if r["method"] == "radau5" and r["jacobian_point"] == point]
            others = [(label, [r for r in group if (r["method"], r["jacobian_point"]) == key])
                      for label, key in [(f"radau5, J at {p:g}", ("radau5", p))
                                         for p in args.points if p != point]
                      + [(m, (m, None)) for m in args.scipy]]
            for label, runs in others:
                ratios = [r["priced_s"] / equal_error_cost(curve, r["error"]) for r in runs]
                ratios = [x for x in ratios if np.isfinite(x)]
                if ratios:
                    print(f"  [{window[0]:g}, {window[1]:g}] {label} over radau5 (J at "
                          f"{point:g}): {np.exp(np.mean(np.log(ratios))):.2f}x (geometric mean "
                          f"of {len(ratios)}: {', '.join(f'{x:.2f}' for x in ratios)})")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--windows", default="0:0.1,1:1.1,2:2.1",
                        help="START:END,... (t_u)")
    parser.add_argument("--accuracy-length", type=float, default=0.1,
                        help="compare end states (and run the curves and scipy) only over "
                             "windows this short")
    parser.add_argument("--rtols", default="1e-3,1e-6")
    parser.add_argument("--points", default=f"0,{integrators.RADAU5.jacobian_point:g}",
                        help="jacobian_point values, the last one the curve's")
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--reference-rtol", type=float, default=1e-11)
    parser.add_argument("--curve-rtols", default="1e-3,1e-4,1e-5,1e-6,1e-7,1e-8")
    parser.add_argument("--scipy", default="lsoda,bdf", help="scipy methods ('' for none)")
    parser.add_argument("--scipy-rtols", default="1e-4,1e-5,1e-6,1e-7,1e-8")
    parser.add_argument("--record-start", action="store_true",
                        help="recompute the recorded states first")
    parser.add_argument("--out", metavar="JSON")
    args = parser.parse_args()
    floats = lambda text: [float(v) for v in text.split(",") if v]  # noqa: E731
    args.rtols, args.points = floats(args.rtols), floats(args.points)
    args.curve_rtols, args.scipy_rtols = floats(args.curve_rtols), floats(args.scipy_rtols)
    args.scipy = [m for m in args.scipy.split(",") if m]
    x0 = loading.start_shape(THETA0, N, None, SEED)[0].ravel()
    problem = problem_of(N)
    small = problem_of(4)  # compile outside the timing
    radau(small, loading.start_shape(THETA0, 4, None, SEED)[0].ravel(), 0.0, 1e-3, 1e-3, 0.0)
    if args.record_start:
        record_start(problem, x0)
    units = unit_costs(problem, x0)
    print(f"# (g0, θ0, n) = ({G0:g}, {THETA0:g}°, {N}), seed {SEED}; compiled unit costs here: "
          f"F {units['f'] * 1e3:.3f} ms, J {units['j'] * 1e3:.2f} ms "
          f"({units['j'] / units['f']:.0f} F), LU pair {units['lu_pair'] * 1e3:.2f} ms, "
          f"real LU {units['lu'] * 1e3:.2f} ms; load average {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores")
    rows = []
    for window in args.windows.split(","):
        t0, t1 = (float(v) for v in window.split(":"))
        window_runs(args, problem, units, t0, t1, start_state(t0, x0), rows)
    equal_error_summary(args, rows)
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(dict(unit_costs=units, rows=rows), handle, indent=1)


if __name__ == "__main__":
    sys.exit(main())
