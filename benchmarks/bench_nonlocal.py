"""Cost per call of the nonlocal operator's kernels against the local right-hand side.

Usage: python benchmarks/bench_nonlocal.py [--orders 8,12,16,24] [--points-per-order 8]

For each n, on a non-circular, non-planar loop parametrised by arc length, best of three
timed loops each (µs per call):

* ``local_rhs``: the local model's whole right-hand side (``models.rhs``: maps, tension
  solve, velocity) at order n;
* ``geometry``: ``nonlocal_maps.kernel_geometry`` on m = points-per-order × n grid points
  (the reference's default is max(64, 8n));
* ``apply``: one ``nonlocal_maps.apply_kernel`` (K on one force field); the nonlocal
  model's least-squares tension needs it on 2n + 2 fields (the tension basis and the
  tension-free force), estimated as ``apply × (2n + 2)``;
* ``dense``: (geometry + (2n + 2) apply) / local_rhs, an estimate of the nonlocal
  right-hand side's extra cost over the local one with a dense tension solve;
* ``iter5``: (local_rhs + geometry + 5 apply) / local_rhs, the estimate for a tension
  solved by the local solve plus corrections, five applications of K in all.
Both are estimates from the kernels' timings;

* ``nonlocal``: measured, the compiled nonlocal velocity and tension
  (``nonlocal_maps.nonlocal_loop_velocity``: the dense least-squares tension on the local
  model's 4n + 1 grid) over local_rhs (the target: 5× at n = 16).

Run it alone with OPENBLAS_NUM_THREADS=1.
"""
import argparse

import numba
import numpy as np

from loopsim import spectral
from loopsim.models import local_sbt, nonlocal_maps, nonlocal_operator, rhs
from scaling import per_call  # best of three timed loops, µs per call


@numba.njit(cache=True)
def _local_rhs(problem, y, dydt, repeats):
    for _ in range(repeats):
        rhs(problem, y, dydt)


@numba.njit(cache=True)
def _geometry(position, tangent, singular, weight, direction, repeats):
    for _ in range(repeats):
        nonlocal_maps.kernel_geometry(position, tangent, singular, weight, direction)


@numba.njit(cache=True)
def _nonlocal(x, g0, w, c, singular, ops, ws, position, weight, direction, u, repeats):
    for _ in range(repeats):
        nonlocal_maps.nonlocal_loop_velocity(x, g0, w, c, singular, ops, ws, position, weight,
                                             direction, u)


@numba.njit(cache=True)
def _apply(weight, direction, f, out, repeats):
    for _ in range(repeats):
        nonlocal_maps.apply_kernel(weight, direction, f, out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--orders", default="8,12,16,24")
    parser.add_argument("--points-per-order", type=int, default=8)
    args = parser.parse_args()
    raw = np.zeros((3, 7))
    raw[0, 1], raw[0, 3] = 1.05, 0.05
    raw[1, 4], raw[1, 6] = 0.95, 0.05
    raw[2, 6] = 0.1
    print(f"{'n':>3} {'m':>4} {'local_rhs':>10} {'geometry':>9} {'apply':>8} {'dense':>6} "
          f"{'iter5':>6} {'nonlocal':>9} {'ratio':>6}")
    for n in (int(v) for v in args.orders.split(",")):
        x = nonlocal_operator.arclength_parametrised(raw, n)
        m = max(64, args.points_per_order * n)
        problem = local_sbt.make_problem(n, 100.0, 10.0)
        y, dydt = x.reshape(-1).copy(), np.empty(x.size)
        position = np.ascontiguousarray(x @ spectral.synthesis_matrix(n, m).T)
        tangent = np.ascontiguousarray(x @ spectral.synthesis_matrix(n, m, 1).T)
        singular = nonlocal_operator.singular_weights(m)
        weight, direction = np.empty((m, m)), np.empty((3, m, m))
        force, out = np.random.default_rng(0).standard_normal((3, m)), np.empty((3, m))
        repeats = max(20, int(2e6 / m**2))
        local = per_call(_local_rhs, (problem, y, dydt), repeats)
        geometry = per_call(_geometry, (position, tangent, singular, weight, direction), repeats)
        apply = per_call(_apply, (weight, direction, force, out), repeats)
        dense = (geometry + (2 * n + 2) * apply) / local
        iterated = (local + geometry + 5 * apply) / local
        grid = 4 * n + 1
        nonlocal_args = (x, 100.0, 10.0, nonlocal_operator.slenderness_constant(1e-3),
                         nonlocal_operator.singular_weights(grid), problem.ops, problem.ws,
                         np.empty((3, grid)), np.empty((grid, grid)), np.empty((3, grid, grid)),
                         np.empty_like(x))
        full = per_call(_nonlocal, nonlocal_args, repeats)
        print(f"{n:3d} {m:4d} {local:10.1f} {geometry:9.1f} {apply:8.1f} {dense:6.1f} "
              f"{iterated:6.1f} {full:9.1f} {full / local:6.1f}")


if __name__ == "__main__":
    main()
