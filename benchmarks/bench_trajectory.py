"""Per trajectory at equal error: radau5 of this tree against the package at a git
revision (default 1a09d6c, the tree before the cheaper right-hand side and the step-control
changes) and against scipy's stiff solvers on loopsim's own compiled kernels, on hard 3D
cases, over rtol, in one process; optionally the work-precision figure.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_trajectory.py \
        --cases 150:45,100:60 --orders 16,24 --out runs/bench_trajectory.json \
        --figure docs/figures/work_precision.png

Each run starts from the same shape at t = 0 (the seeded circle of ``shapes.initial_shape``
at order n) and runs to ``--t-end``; its error is the terminal tilt's distance from this
tree's radau5 at ``--reference-rtol`` from that same start (atol = rtol / 1000 throughout).
Methods (``--methods``):

* ``radau5``: this tree; ``radau5-old``: the package at ``--baseline``;
* ``lsoda``, ``bdf``: ``scipy.integrate.solve_ivp`` with loopsim's compiled F
  (``models.evaluate``) and exact Jacobian (``models.evaluate_jacobian``), called from
  Python.  Besides their wall time, each gets a *compiled-cost estimate*: its counts
  (nfev, njev, nlu) times the compiled unit costs of F, J and one real LU measured here,
  what a compiled BDF with scipy's step and order choices would cost (issue: a
  variable-order method in loopsim pays only if it beats radau5 by >= 1.3x).

The equal-error speed-up of a method is its wall time over this tree's radau5 wall time
at the same error, interpolated log-log along radau5's work-precision curve.  Counts are
deterministic; wall times are the median of ``--repeats``, methods alternating.
"""
import argparse
import importlib
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import loopsim  # noqa: E402
from bench_kernels import import_baseline  # noqa: E402
from loopsim import diagnostics, models, shapes  # noqa: E402

RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
METHODS = ("radau5", "radau5-old", "lsoda", "bdf")
LABELS = {"radau5": "radau5 (loopsim)", "radau5-old": "radau5 (loopsim at {rev})",
          "lsoda": "LSODA (scipy, loopsim's F and J)", "bdf": "BDF (scipy, loopsim's F and J)"}


def run(problem, x0, t_end, rtol, package=loopsim):
    """radau5 from x0 to t_end at rtol (atol = rtol / 1000) with ``package``'s driver:
    (wall s, status, x, counts)."""
    driver = importlib.import_module(package.__name__ + ".integrators.driver")
    methods = importlib.import_module(package.__name__ + ".integrators")
    radau5, options = methods.RADAU5, methods.step_options(rtol, rtol * 1e-3)
    y_out = np.empty((1, x0.size))
    start = time.perf_counter()
    status, t, y, counts, _ = driver.integrate(radau5, problem, x0.ravel().copy(), 0.0, t_end,
                                               np.array([t_end]), options, y_out)
    return time.perf_counter() - start, int(status), y.reshape(x0.shape), counts


def problem_of(package, g0, n):
    sbt = sys.modules[package.__name__ + ".models.local_sbt"]
    return sbt.LoopProblem(g0, loopsim.defaults.DEFAULT_W, sbt.make_operators(n),
                           sbt.make_workspace(n))


def equal_error_time(errors, times, error):
    """This tree's wall time at ``error``, interpolated log-log along its (error, time)
    points sorted by error; NaN outside their range."""
    order = np.argsort(errors)
    e, t = np.log(np.asarray(errors)[order]), np.log(np.asarray(times)[order])
    if not (e[0] <= np.log(error) <= e[-1]):
        return float("nan")
    return float(np.exp(np.interp(np.log(error), e, t)))


def run_scipy(problem, x0, t_end, rtol, method):
    """solve_ivp(method) on loopsim's compiled F and J: (wall s, status, x, counts)."""
    from scipy.integrate import solve_ivp

    aux = np.empty(x0.shape[1])

    def fun(_, y):
        dydt = np.empty_like(y)
        models.evaluate(problem, y, dydt, aux)
        return dydt

    def jac(_, y):
        out = np.empty((y.size, y.size))
        models.evaluate_jacobian(problem, y, out)
        return out

    start = time.perf_counter()
    sol = solve_ivp(fun, (0.0, t_end), x0.ravel().copy(), method=method.upper(), rtol=rtol,
                    atol=rtol * 1e-3, jac=jac)
    wall = time.perf_counter() - start
    counts = [int(sol.t.size - 1), 0, int(sol.nfev), int(sol.njev), int(sol.nlu)]
    return wall, int(sol.status), sol.y[:, -1].reshape(x0.shape), counts


def unit_costs(problem, x0, repeats=200):
    """Compiled seconds per F, per exact J (its own F included) and per real LU of the
    Newton matrix (scipy.linalg.lu_factor, LAPACK as radau5 and BDF use it)."""
    from scipy.linalg import lu_factor

    y = x0.ravel().copy()
    dydt, aux, jac = np.empty_like(y), np.empty(x0.shape[1]), np.empty((y.size, y.size))
    models.evaluate(problem, y, dydt, aux)
    models.evaluate_jacobian(problem, y, jac)
    matrix = np.eye(y.size) - 1e-3 * jac

    def per_call(function, k):
        start = time.perf_counter()
        for _ in range(k):
            function()
        return (time.perf_counter() - start) / k

    return dict(f=per_call(lambda: models.evaluate(problem, y, dydt, aux), repeats),
                j=per_call(lambda: models.evaluate_jacobian(problem, y, jac), repeats // 10),
                lu=per_call(lambda: lu_factor(matrix), repeats // 4))


def draw(rows, path, baseline):
    """Terminal-tilt error against wall time, one panel per (case, n), one line per method;
    the scipy methods also at their compiled-cost estimate (dashed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = sorted({(r["g0"], r["theta0"], r["n"]) for r in rows})
    cases = sorted({k[:2] for k in keys})
    orders = sorted({k[2] for k in keys})
    from matplotlib.ticker import NullFormatter

    fig, axes = plt.subplots(len(cases), len(orders),
                             figsize=(max(3.4 * len(orders), 6.4), 2.9 * len(cases) + 0.6),
                             squeeze=False, sharey=True, constrained_layout=True)
    styles = {"radau5": ("C0", "o"), "radau5-old": ("C7", "s"), "lsoda": ("C1", "^"),
              "bdf": ("C2", "v")}
    for (g0, theta0, n) in keys:
        ax = axes[cases.index((g0, theta0)), orders.index(n)]
        for method, (colour, marker) in styles.items():
            group = sorted((r for r in rows if (r["g0"], r["theta0"], r["n"]) == (g0, theta0, n)
                            and r["method"] == method and r["status"] >= 0),
                           key=lambda r: r["rtol"])
            if not group:
                continue
            errors = [max(r["error"], 1e-12) for r in group]
            ax.loglog([r["wall_s"] for r in group], errors, marker=marker, color=colour, ms=3.5,
                      lw=1.2, label=LABELS[method].format(rev=baseline))
            if "compiled_s" in group[0]:
                ax.loglog([r["compiled_s"] for r in group], errors, marker=marker, color=colour,
                          ms=3, lw=1, ls="--", mfc="none",
                          label=f"{method.upper()}: its counts x compiled unit costs")
        ax.set_title(f"g0 = {g0:g}, θ0 = {theta0:g}°, n = {n}", fontsize=9)
        ax.grid(True, which="major", lw=0.4, alpha=0.5)
        ax.tick_params(labelsize=8)
        ax.xaxis.set_minor_formatter(NullFormatter())
    for ax in axes[-1]:
        ax.set_xlabel("wall time (s, one core)", fontsize=9)
    for ax in axes[:, 0]:
        ax.set_ylabel("terminal-tilt error (deg)", fontsize=9)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=2, fontsize=7.5, frameon=False)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="150:45,100:60", help="g0:theta0_deg,...")
    parser.add_argument("--orders", default="21,24")
    parser.add_argument("--methods", default="radau5,radau5-old",
                        help=f"comma-separated, of {', '.join(METHODS)}")
    parser.add_argument("--rtols", default=",".join(f"{r:g}" for r in RTOLS))
    parser.add_argument("--t-end", type=float, default=2.0)
    parser.add_argument("--reference-rtol", type=float, default=1e-11)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--baseline", metavar="REV", default="1a09d6c")
    parser.add_argument("--out", metavar="JSON")
    parser.add_argument("--figure", metavar="PNG")
    args = parser.parse_args()
    methods = [m.strip() for m in args.methods.split(",")]
    unknown = sorted(set(methods) - set(METHODS))
    if unknown or "radau5" not in methods:
        parser.error(f"--methods: unknown {unknown}" if unknown else "--methods needs radau5")
    rtols = [float(v) for v in args.rtols.split(",")]
    packages = {"radau5": loopsim}
    if "radau5-old" in methods:
        base = import_baseline(args.baseline)
        import loopsim_baseline.models.local_sbt  # noqa: F401 - registers its model
        packages["radau5-old"] = base

    def one(method, g0, n, x0, rtol):
        if method in packages:
            return run(problem_of(packages[method], g0, n), x0, args.t_end, rtol,
                       packages[method])
        return run_scipy(problem_of(loopsim, g0, n), x0, args.t_end, rtol, method)

    warm = shapes.initial_shape(4, np.radians(30.0), 1e-3, 0)
    for method in methods:  # compile outside the timing
        one(method, 60.0, 4, warm, 1e-3)
    rows = []
    print("| g0 | θ0 | n | rtol | method | steps | rejected | nfev | njev | nlu | s | "
          "error (deg) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for case in args.cases.split(","):
        g0, theta0 = (float(v) for v in case.split(":"))
        for n in (int(v) for v in args.orders.split(",")):
            x0 = shapes.initial_shape(n, np.radians(theta0), 1e-3, 0)
            _, status, x_ref, _ = run(problem_of(loopsim, g0, n), x0, args.t_end,
                                      args.reference_rtol)
            reference = diagnostics.tilt_deg(x_ref)
            units = unit_costs(problem_of(loopsim, g0, n), x0)
            print(f"# g0 {g0:g}, θ0 {theta0:g}, n {n}: reference tilt {reference:.6f}° "
                  f"(status {status}); compiled F {units['f'] * 1e6:.0f} µs, J "
                  f"{units['j'] * 1e6:.0f} µs, LU {units['lu'] * 1e6:.0f} µs", flush=True)
            for rtol in rtols:
                walls = {m: [] for m in methods}
                found = {}
                for _ in range(args.repeats):
                    for method in methods:
                        wall, status, x, counts = one(method, g0, n, x0, rtol)
                        walls[method].append(wall)
                        found[method] = (status, counts, abs(diagnostics.tilt_deg(x) - reference))
                for method in methods:
                    status, counts, error = found[method]
                    row = dict(g0=g0, theta0=theta0, n=n, rtol=rtol, method=method,
                               status=status, counts=[int(c) for c in counts], error=error,
                               wall_s=float(np.median(walls[method])),
                               reference_tilt=reference, unit_costs=units)
                    if method in ("lsoda", "bdf"):
                        row["compiled_s"] = (counts[2] * units["f"] + counts[3] * units["j"]
                                             + counts[4] * units["lu"])
                    rows.append(row)
                    print(f"| {g0:g} | {theta0:g} | {n} | {rtol:g} | {method} | {counts[0]} | "
                          f"{counts[1]} | {counts[2]} | {counts[3]} | {counts[4]} | "
                          f"{row['wall_s']:.2f} | {error:.2e} |", flush=True)
    print("\nequal-error speed-up of this tree's radau5 (other method's time / radau5's time "
          "at the other run's error; compiled estimate in brackets):")
    for method in methods[1:] if methods[0] == "radau5" else [m for m in methods if m != "radau5"]:
        ratios, compiled = [], []
        for key in sorted({(r["g0"], r["theta0"], r["n"]) for r in rows}):
            mine = [r for r in rows if (r["g0"], r["theta0"], r["n"]) == key
                    and r["method"] == "radau5"]
            errors = [max(r["error"], 1e-14) for r in mine]
            times = [r["wall_s"] for r in mine]
            for r in rows:
                if (r["g0"], r["theta0"], r["n"]) != key or r["method"] != method:
                    continue
                at = equal_error_time(errors, times, max(r["error"], 1e-14))
                r["radau5_speedup"] = r["wall_s"] / at
                r["radau5_speedup_compiled"] = r.get("compiled_s", np.nan) / at
                if np.isfinite(r["radau5_speedup"]):
                    ratios.append(r["radau5_speedup"])
                    if np.isfinite(r["radau5_speedup_compiled"]):
                        compiled.append(r["radau5_speedup_compiled"])
                print(f"  {method} {key} rtol {r['rtol']:g}: error {r['error']:.2e}, "
                      f"{r['radau5_speedup']:.2f}x ({r['radau5_speedup_compiled']:.2f}x)")
        if ratios:
            line = (f"{method}: geometric mean {np.exp(np.mean(np.log(ratios))):.2f}x over "
                    f"{len(ratios)} points (range {min(ratios):.2f}-{max(ratios):.2f})")
            if compiled:
                line += (f"; compiled estimate {np.exp(np.mean(np.log(compiled))):.2f}x "
                         f"(range {min(compiled):.2f}-{max(compiled):.2f})")
            print(line)
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(rows, handle, indent=1)
    if args.figure:
        draw(rows, args.figure, args.baseline)
        print(f"figure: {args.figure}")


if __name__ == "__main__":
    main()
