"""Cost per call of the implicit integrator's kernels, by truncation order n.

Usage: python benchmarks/bench_kernels.py [--orders 6,8,12,16,24,32,48,64] [--out FILE.json]

For each n, on one 3D shape (g0 = 150, θ0 = 45°, n = 12 run to t = 0.3,
zero-padded to n: a loop in mid-transient), best of three timed loops each:

* ``rhs``: the right-hand side, fast path (``local_sbt.loop_velocity``: the
  tension map as (B₂ + B B) S0, corrected semi-normal equations);
* ``rhs_blocks``: the previous dense path (``loop_velocity_blocks``: column
  blocks through two (M, M) projections, Householder QR), and the ratio;
* ``jacobian``: the exact Jacobian (``loop_jacobian``);
* ``newton_lu``: Radau's pair of factorisations (real and complex, 3K × 3K);
* ``max_du``: max |u_fast − u_blocks| / max |u_blocks| (the two paths agree to
  rounding).

Run it alone with OPENBLAS_NUM_THREADS=1: the ratios come from one run.
"""
import argparse
import json

import numba
import numpy as np

import loopsim
from loopsim import linalg, models, spectral
from loopsim.integrators import radau
from loopsim.models import local_sbt, rhs
from scaling import per_call  # best of three timed loops, µs per call


@numba.njit(cache=True)
def _rhs(problem, y, dydt, repeats):
    for _ in range(repeats):
        rhs(problem, y, dydt)


@numba.njit(cache=True)
def _rhs_blocks(x, g0, w, ops, ws, u, repeats):
    for _ in range(repeats):
        local_sbt.loop_velocity_blocks(x, g0, w, ops, ws, u)


@numba.njit(cache=True)
def _jacobian(x, g0, w, ops, ws, jac, repeats):
    for _ in range(repeats):
        local_sbt.loop_jacobian(x, g0, w, ops, ws, jac)


@numba.njit(cache=True)
def _newton_lu(jac, lu_real, piv_real, lu_complex, piv_complex, repeats):
    for _ in range(repeats):
        radau.newton_matrices(jac, 0.01, lu_real, piv_real, lu_complex, piv_complex)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--orders", default="6,8,12,16,24,32,48,64")
    parser.add_argument("--out")
    args = parser.parse_args()
    g0, w = 150.0, loopsim.config.DEFAULT_W
    start = loopsim.simulate(g0, 45.0, n=12, t_span=(0, 0.3), method="radau5").x_final
    rows = []
    print(f"{'n':>3} {'rhs_us':>9} {'blocks_us':>10} {'ratio':>6} {'jac_us':>9} "
          f"{'lu_us':>8} {'max_du':>8}")
    for n in (int(v) for v in args.orders.split(",")):
        x = spectral.resize(start, n)
        ops, ws = local_sbt.make_operators(n), local_sbt.make_workspace(n)
        d = 3 * (2 * n + 1)
        u, u_blocks, jac = np.empty_like(x), np.empty_like(x), np.empty((d, d))
        models.evaluate(local_sbt.LoopProblem(g0, w, ops, ws), x.reshape(-1), u.reshape(-1),
                        np.empty(x.shape[1]))
        local_sbt.loop_velocity_blocks(x, g0, w, ops, ws, u_blocks)
        local_sbt.loop_jacobian(x, g0, w, ops, ws, jac)
        max_du = float(np.abs(u - u_blocks).max() / np.abs(u_blocks).max())
        repeats = max(20, int(3e6 / n**3))
        row = dict(
            n=n,
            rhs_us=per_call(_rhs, (local_sbt.LoopProblem(g0, w, ops, ws), x.reshape(-1),
                                      u.reshape(-1)), repeats),
            rhs_blocks_us=per_call(_rhs_blocks, (x, g0, w, ops, ws, u), repeats),
            jacobian_us=per_call(_jacobian, (x, g0, w, ops, ws, jac), max(5, repeats // 8)),
            newton_lu_us=per_call(_newton_lu, (
                jac, np.empty((d, d)), np.empty(d, linalg.PIVOT_DTYPE),
                np.empty((d, d), np.complex128), np.empty(d, linalg.PIVOT_DTYPE)),
                max(5, repeats // 8)),
            max_du=max_du,
        )
        rows.append(row)
        print(f"{n:>3} {row['rhs_us']:>9.1f} {row['rhs_blocks_us']:>10.1f} "
              f"{row['rhs_blocks_us'] / row['rhs_us']:>6.2f} {row['jacobian_us']:>9.1f} "
              f"{row['newton_lu_us']:>8.1f} {row['max_du']:>8.1e}", flush=True)
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(rows, handle, indent=1)


if __name__ == "__main__":
    main()
