"""Cost per call of the implicit integrator's kernels, by truncation order n.

Usage: python benchmarks/bench_kernels.py [--orders 6,8,12,16,24,32,48,64] [--out FILE.json]
                                        [--baseline REV] [--parts] [--rhs-only]

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

``--rhs-only`` times the right-hand side alone (no blocks, Jacobian or LU).

``--baseline REV`` also times the right-hand side of the package as of git revision
REV (``git archive`` of ``loopsim/`` into a temporary directory, imported as a second
package, ``loopsim_baseline``) in the same process on the same inputs: ``--rounds``
rounds, each one timed loop of the current and one of the baseline right-hand side
in turn; it prints the medians, their ratio, the ratio of the fastest rounds (``min``:
the least disturbed by other work on the machine) and max |u − u_base| / max |u_base|.  The
baseline compiles its kernels into its own cache the first time (a minute or two).

``--parts`` splits the fast right-hand side into its kernels, each timed in its
own loop on the same shape (fastest of ``--rounds`` rounds, the loops in turn): the
shape on the grid, Bᵀ
(``tension_operator``), S0ᵀBᵀ and S0ᵀB₂ᵀ (``tension_columns``), the one
(K, M) @ (M, M) product, the rest of the affine map T -> ε (its T = 0 part), the
Gram matrix, LAPACK's Cholesky with the refinement step, and the velocity after the
solve (the remainder).

Run it alone with OPENBLAS_NUM_THREADS=1: the ratios come from one run.
"""
import argparse
import importlib
import json
import os
import subprocess
import sys
import tempfile
import time

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


@numba.njit(cache=True)
def _part(x, g0, w, ops, ws, which, repeats):
    """One part of the fast right-hand side, ``repeats`` times (ws filled by a call first)."""
    k = x.shape[1]
    for _ in range(repeats):
        if which == 0:
            local_sbt.shape_on_grid(x, ops, ws)
        elif which == 1:
            local_sbt.tension_operator(ops, ws)
        elif which == 2:
            local_sbt.tension_columns(ops, ws)
        elif which == 3:
            linalg.add_product(ws.partial, ws.coupling, ws.length_rate[:k])
        elif which == 4:
            local_sbt.length_rate_operator(g0, w, ops, ws)
        elif which == 5:
            linalg.gram_upper(ws.length_rate[:k], ws.gram)
        else:
            linalg.least_squares_normal(ws.length_rate, ops.column_scale, ws.tension, ws.gram,
                                        ws.residual, ws.correction)


#: The columns of --parts (:func:`parts`).
PARTS = ("shape", "B", "columns", "BY", "affine", "gram", "cholesky", "velocity")


def parts(problem, y, dydt, repeats, rounds):
    """µs per call of the right-hand side and of each of its parts (PARTS): the fastest of
    ``rounds`` rounds, all loops timed in turn in each."""
    x = y.reshape((3, -1))
    args = (x, problem.g0, problem.w, problem.ops, problem.ws)
    loops = [(_rhs, (problem, y, dydt))] + [(_part, args + (which,)) for which in range(7)]
    total, shape, operator, columns, product, length_rate, gram, solve = (
        min(times) for times in interleaved(loops, repeats, rounds))
    return dict(rhs=total, shape=shape, B=operator, columns=columns, BY=product,
                affine=length_rate - operator - columns - product, gram=gram,
                cholesky=solve - gram, velocity=total - shape - length_rate - solve)


def import_baseline(revision):
    """The package at git ``revision``, imported as ``loopsim_baseline`` from a temporary
    directory (kept until the process ends)."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(loopsim.__file__)))
    folder = tempfile.mkdtemp(prefix="loopsim_baseline_")
    archive = subprocess.run(["git", "-C", root, "archive", revision, "loopsim"],
                             check=True, capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", folder], input=archive, check=True)
    os.rename(os.path.join(folder, "loopsim"), os.path.join(folder, "loopsim_baseline"))
    sys.path.insert(0, folder)
    return importlib.import_module("loopsim_baseline")


def loop_of(function):
    """A compiled loop calling ``function(problem, y, dydt)`` ``repeats`` times, not cached
    (for the baseline, whose types share the current package's names)."""
    @numba.njit
    def loop(problem, y, dydt, repeats):
        for _ in range(repeats):
            function(problem, y, dydt)
    return loop


def interleaved(loops, repeats, rounds):
    """µs per call of each (fn, args) in ``loops``, one list per loop: ``rounds`` rounds,
    each timing every loop in turn."""
    for fn, args in loops:
        fn(*args, 1)
    times = [[] for _ in loops]
    for _ in range(rounds):
        for timing, (fn, args) in zip(times, loops):
            start = time.perf_counter()
            fn(*args, repeats)
            timing.append(1e6 * (time.perf_counter() - start) / repeats)
    return times


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--orders", default="6,8,12,16,24,32,48,64")
    parser.add_argument("--out")
    parser.add_argument("--baseline", metavar="REV")
    parser.add_argument("--rounds", type=int, default=21)
    parser.add_argument("--parts", action="store_true")
    parser.add_argument("--rhs-only", action="store_true")
    args = parser.parse_args()
    g0, w = 150.0, loopsim.defaults.DEFAULT_W
    start = loopsim.simulate(g0, 45.0, n=12, t_span=(0, 0.3), method="radau5").x_final
    base = None
    if args.baseline:
        base = import_baseline(args.baseline)
        from loopsim_baseline import models as base_models
        from loopsim_baseline.models import local_sbt as base_sbt

        base_rhs = loop_of(base_models.rhs)
    rows = []
    header = f"{'n':>3} {'rhs_us':>9}"
    if not args.rhs_only:
        header += f" {'blocks_us':>10} {'ratio':>6} {'jac_us':>9} {'lu_us':>8} {'max_du':>8}"
    if base is not None:
        header += (f" {'med_us':>8} {'base_us':>8} {'new/base':>8} {'min':>8}"
                   f" {'max_du_base':>11}")
    if args.parts:
        header += "".join(f" {name:>8}" for name in PARTS)
    print(header)
    for n in (int(v) for v in args.orders.split(",")):
        x = spectral.resize(start, n)
        ops, ws = local_sbt.make_operators(n), local_sbt.make_workspace(n)
        problem = local_sbt.LoopProblem(g0, w, ops, ws)
        d = 3 * (2 * n + 1)
        u, u_blocks, jac = np.empty_like(x), np.empty_like(x), np.empty((d, d))
        models.evaluate(problem, x.reshape(-1), u.reshape(-1), np.empty(x.shape[1]))
        repeats = max(20, int(3e6 / n**3))
        row = dict(n=n, rhs_us=per_call(_rhs, (problem, x.reshape(-1), u.reshape(-1)), repeats))
        line = f"{n:>3} {row['rhs_us']:>9.1f}"
        if not args.rhs_only:
            local_sbt.loop_velocity_blocks(x, g0, w, ops, ws, u_blocks)
            local_sbt.loop_jacobian(x, g0, w, ops, ws, jac)
            row.update(
                rhs_blocks_us=per_call(_rhs_blocks, (x, g0, w, ops, ws, u_blocks), repeats),
                jacobian_us=per_call(_jacobian, (x, g0, w, ops, ws, jac), max(5, repeats // 8)),
                newton_lu_us=per_call(_newton_lu, (
                    jac, np.empty((d, d)), np.empty(d, linalg.PIVOT_DTYPE),
                    np.empty((d, d), np.complex128), np.empty(d, linalg.PIVOT_DTYPE)),
                    max(5, repeats // 8)),
                max_du=float(np.abs(u - u_blocks).max() / np.abs(u_blocks).max()),
            )
            line += (f" {row['rhs_blocks_us']:>10.1f} {row['rhs_blocks_us'] / row['rhs_us']:>6.2f}"
                     f" {row['jacobian_us']:>9.1f} {row['newton_lu_us']:>8.1f}"
                     f" {row['max_du']:>8.1e}")
        if base is not None:
            base_problem = base_sbt.LoopProblem(g0, w, base_sbt.make_operators(n),
                                                base_sbt.make_workspace(n))
            u_base = np.empty_like(x)
            base_models.evaluate(base_problem, x.reshape(-1), u_base.reshape(-1),
                                 np.empty(x.shape[1]))
            new_times, base_times = interleaved(
                [(_rhs, (problem, x.reshape(-1), u.reshape(-1))),
                 (base_rhs, (base_problem, x.reshape(-1), u_base.reshape(-1)))],
                max(5, repeats // 4), args.rounds)
            new_us, base_us = float(np.median(new_times)), float(np.median(base_times))
            models.evaluate(problem, x.reshape(-1), u.reshape(-1), np.empty(x.shape[1]))
            base_models.evaluate(base_problem, x.reshape(-1), u_base.reshape(-1),
                                 np.empty(x.shape[1]))
            row.update(rhs_median_us=new_us, base_median_us=base_us,
                       min_ratio=min(new_times) / min(base_times),
                       max_du_base=float(np.abs(u - u_base).max() / np.abs(u_base).max()))
            line += (f" {new_us:>8.1f} {base_us:>8.1f} {new_us / base_us:>8.2f}"
                     f" {row['min_ratio']:>8.2f} {row['max_du_base']:>11.1e}")
        if args.parts:
            row["parts_us"] = parts(problem, x.reshape(-1), u.reshape(-1), max(5, repeats // 4),
                                    args.rounds)
            line += "".join(f" {row['parts_us'][name]:>8.1f}" for name in PARTS)
        rows.append(row)
        print(line, flush=True)
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(rows, handle, indent=1)


if __name__ == "__main__":
    main()
