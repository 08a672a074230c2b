"""Work-precision: error against wall time over rtol and n, for each integrator.

Usage: python benchmarks/work_precision.py [--out runs/work_precision] [--quick]

Two cases:
* in-plane: g0 = 60, θ0 = 30°, t = 10 (a steady elongated terminal shape);
* 3D: g0 = 150, θ0 = 60°, over the short window t ≤ 0.5 only: in the 3D
  regime tiny differences grow by orders of magnitude within a fraction of a
  time unit, so terminal states converge in rtol slowly, and for some cases
  not at all (scripts/terminal_precision.py measures that at t = 10).

Two errors, kept apart:
* time discretisation: the same n against an rtol = 1e-12 Radau run (max
  coefficient difference, same initial shape, so no symmetry to remove);
* truncation: against the highest n run at rtol = 1e-12 (caveat: the seeded
  perturbation is normalised over modes 2..n, so these runs start from
  slightly different curves, and terminal shapes depend on the start; see
  tests/test_convergence.py for a clean convergence study), compared modulo
  the exact symmetries (rotation about the vertical, shift of arc length)
  through invariants: the amplitudes |mode k| = (Σ_c a_ck² + b_ck²)^½ for
  k = 1..4, the aspect ratio and the tilt.

Writes OUT.parquet (one row per run) and OUT.png (error against wall time).
RKF45 runs that would take minutes each (in-plane at n ≥ 16) are skipped
unless --all is given.
"""
import argparse
import os

import numpy as np
import pandas as pd

import loopsim
from loopsim import diagnostics, integrators

CASES = {
    "in-plane": dict(g0=60.0, theta0=30.0, t_end=10.0, orders=[4, 6, 8, 12, 16], n_ref=20),
    "3d-window": dict(g0=150.0, theta0=60.0, t_end=0.5, orders=[4, 6, 8, 12, 16], n_ref=20),
}
RTOLS = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10]


def mode_amplitudes(x, modes=4):
    n = (x.shape[1] - 1) // 2
    return np.array([np.sqrt(np.sum(x[:, k] ** 2 + x[:, n + k] ** 2)) for k in range(1, modes + 1)])


def invariants(x):
    return np.concatenate([mode_amplitudes(x), [diagnostics.aspect_ratio(x), diagnostics.tilt_deg(x)]])


def run(case, n, rtol, method):
    return loopsim.simulate(case["g0"], case["theta0"], n=n, t_span=(0, case["t_end"]), rtol=rtol,
                            atol=rtol * 1e-3, method=method)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="runs/work_precision")
    parser.add_argument("--quick", action="store_true", help="fewer orders and tolerances")
    parser.add_argument("--methods", default=",".join(sorted(integrators.METHODS)))
    parser.add_argument("--all", action="store_true", help="include RKF45 in-plane runs at n >= 16")
    parser.add_argument("--plot-only", action="store_true", help="redraw OUT.png from OUT.parquet")
    args = parser.parse_args()
    if args.plot_only:
        plot(pd.read_parquet(args.out + ".parquet"), args.out + ".png")
        return
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    rtols = RTOLS[::3] if args.quick else RTOLS
    loopsim.simulate(60, 30, n=4, t_span=(0, 0.01))  # JIT warm-up
    rows = []
    for method in args.methods.split(","):
        for label, case in CASES.items():
            orders = case["orders"][:3] if args.quick else case["orders"]
            if method == "rkf45" and label == "in-plane" and not args.all:
                orders = [n for n in orders if n < 16]
            # the converged reference comes from the stiff solver when it exists (cheap at high n)
            reference_method = "radau5" if "radau5" in integrators.METHODS else method
            converged = run(case, case["n_ref"], 1e-12, reference_method).x_final
            for n in orders:
                reference = run(case, n, 1e-12, reference_method).x_final
                truncation = np.abs(invariants(reference) - invariants(converged))
                for rtol in rtols:
                    result = run(case, n, rtol, method)
                    x = result.x_final
                    rows.append(dict(
                        method=method, case=label, n=n, rtol=rtol, status=result.status,
                        wall_s=result.wall_s, nfev=result.nfev,
                        steps=result.steps_accepted, mean_step=result.t_final / result.steps_accepted,
                        time_error=float(np.abs(x - reference).max()),
                        time_error_aspect=abs(diagnostics.aspect_ratio(x) - diagnostics.aspect_ratio(reference)),
                        truncation_error_modes=float(truncation[:4].max()),
                        truncation_error_aspect=float(truncation[4]),
                        truncation_error_tilt_deg=float(truncation[5]),
                    ))
                    print(f"{method} {label:9s} n={n:2d} rtol={rtol:.0e} wall={result.wall_s:8.3f}s "
                          f"time_err={rows[-1]['time_error']:.1e} trunc_err={truncation[:4].max():.1e}",
                          flush=True)
    table = pd.DataFrame(rows)
    table.to_parquet(args.out + ".parquet")
    plot(table, args.out + ".png")
    print(f"wrote {args.out}.parquet and {args.out}.png")


def plot(table, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = list(CASES)
    orders = sorted(table["n"].unique())
    colours = dict(zip(orders, plt.cm.viridis(np.linspace(0, 0.9, len(orders)))))
    styles = {"rkf45": dict(ls="--", marker="s"), "radau5": dict(ls="-", marker="o")}
    fig, axes = plt.subplots(1, len(cases), figsize=(10, 4.2), constrained_layout=True)
    for ax, label in zip(axes, cases):
        rows = table[table["case"] == label]
        for (method, n), group in rows.groupby(["method", "n"]):
            ax.loglog(group["wall_s"], np.maximum(group["time_error"], 1e-17), ms=3,
                      color=colours[n], label=f"{method}, n = {n}",
                      **styles.get(method, dict(ls="-.", marker="^")))
        ax.set(xlabel="wall time per trajectory (s)", ylabel="terminal shape error (time discr.)",
               title=f"{label}: solid radau5, dashed rkf45")
        ax.legend(fontsize=6, frameon=False, ncol=2)
    fig.savefig(path, dpi=150)


if __name__ == "__main__":
    main()
