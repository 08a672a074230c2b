"""The baseline a user might write instead: plain NumPy maps + scipy's stiff solve_ivp.

Usage: python benchmarks/baseline_scipy.py [--n 6] [--g0 60] [--theta0 30] [--t-end 10]

The same equations as loopsim (f = P_n[-x'''' + (T x')' - g0 e_z],
u = P_n[f + (x'·f) x'], T minimising ∫ε², ε = x'·u' - w(1 - x'·x')), written
the direct way: dense NumPy arrays on the 4n + 1 point grid, the tension
matrix built column by column, ``numpy.linalg.lstsq``, and
``scipy.integrate.solve_ivp`` with Radau or BDF (finite-difference Jacobian),
and, as a careful user would, Radau with the exact chain-rule Jacobian in
plain NumPy (``benchmarks/numpy_jacobian.py``).  Nothing else from
loopsim's numerics is used; the initial shape and the error measure come from
loopsim so both start from the same state.

Prints, in one run, wall time and terminal-shape error (max coefficient
difference from a loopsim rtol = 1e-12 reference at the same n) for the
baseline at several tolerances and for loopsim's integrators, and the ratios
at matched error.
"""
import argparse
import time

import numpy as np
from scipy.integrate import solve_ivp

import loopsim
from loopsim import shapes
from numpy_jacobian import rhs_jacobian


class NumpyLoop:
    """Right-hand side dx/dt = u(x) in plain NumPy (real cos/sin coefficients)."""

    def __init__(self, n, g0, w):
        self.n, self.g0, self.w = n, g0, w
        m = 4 * n + 1
        s = 2 * np.pi * np.arange(m) / m
        k = np.arange(1, n + 1)
        cos, sin = np.cos(np.outer(s, k)), np.sin(np.outer(s, k))
        self.S = np.hstack([np.ones((m, 1)), cos, sin])  # values
        self.dS = np.hstack([np.zeros((m, 1)), -sin * k, cos * k])  # first derivative
        self.ddS = np.hstack([np.zeros((m, 1)), -cos * k**2, -sin * k**2])
        self.d4S = np.hstack([np.zeros((m, 1)), cos * k**4, sin * k**4])
        self.F = np.linalg.pinv(self.S)  # projection onto order n (exact on this grid)
        self.K = 2 * n + 1

    def __call__(self, t, y):
        return self.velocity_and_tension(y.reshape(3, self.K))[0].ravel()

    def velocity_and_tension(self, x):
        """Velocity coefficients (3, K) and tension multiplier (K,) of shape x."""
        tangent, curvature = x @ self.dS.T, x @ self.ddS.T
        x4 = x @ self.d4S.T
        gravity = np.array([0.0, 0.0, self.g0])[:, None]

        def velocity_grid(T, dT, affine):
            f = dT * tangent + T * curvature - (x4 + gravity if affine else 0.0)
            f = (f @ self.F.T) @ self.S.T  # P_n
            v = f + np.sum(tangent * f, axis=0) * tangent
            return v

        def length_creation(v, affine):
            du = (v @ self.F.T) @ self.dS.T
            eps = np.sum(tangent * du, axis=0)
            if affine:
                eps -= self.w * (1.0 - np.sum(tangent * tangent, axis=0))
            return eps

        b_v = velocity_grid(0.0, 0.0, True)
        b = length_creation(b_v, True)
        columns = [length_creation(velocity_grid(self.S[:, j], self.dS[:, j], False), False)
                   for j in range(self.K)]
        tension = np.linalg.lstsq(np.array(columns).T, -b, rcond=None)[0]
        v = b_v + velocity_grid(self.S @ tension, self.dS @ tension, False)
        return v @ self.F.T, tension


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=6)
    parser.add_argument("--g0", type=float, default=60.0)
    parser.add_argument("--theta0", type=float, default=30.0)
    parser.add_argument("--t-end", type=float, default=10.0)
    parser.add_argument("--methods", default="rkf45,radau5", help="loopsim integrators to time")
    parser.add_argument("--baselines", default="radau,bdf,radau-exact",
                        help="scipy variants: radau, bdf (finite-difference Jacobian), radau-exact")
    parser.add_argument("--reference-method", default="radau5",
                        help="integrator of the rtol = 1e-12 reference")
    args = parser.parse_args()
    n = args.n
    run = dict(n=n, t_span=(0, args.t_end))
    loopsim.simulate(args.g0, args.theta0, n=n, t_span=(0, 0.01))  # JIT warm-up
    reference = loopsim.simulate(args.g0, args.theta0, rtol=1e-12, atol=1e-14,
                                 method=args.reference_method, **run).x_final
    x0 = shapes.initial_shape(n, np.radians(args.theta0), 1e-3, 0)
    rhs = NumpyLoop(n, args.g0, loopsim.defaults.DEFAULT_W)
    u_check = rhs(0.0, x0.ravel()).reshape(3, -1)
    u_loopsim, _ = loopsim.evaluate_maps(x0, args.g0)
    print(f"# n = {n}, g0 = {args.g0}, theta0 = {args.theta0}, t_end = {args.t_end}; "
          f"baseline RHS agrees with loopsim to {np.abs(u_check - u_loopsim).max():.1e}")
    print(f"{'solver':>22} {'rtol':>7} {'wall_s':>8} {'nfev':>9} {'error':>8}")
    results = []
    def exact_jacobian(t, y):  # the chain-rule Jacobian, plain NumPy (numpy_jacobian.py)
        return rhs_jacobian(y.reshape(3, -1), args.g0, rhs.w, rhs.velocity_and_tension)

    variants = {"radau": ("Radau", None), "bdf": ("BDF", None), "radau-exact": ("Radau", exact_jacobian)}
    for method, jac in (variants[v] for v in args.baselines.split(",")):
        name = method + (" + exact J" if jac is not None else "")
        for rtol in (1e-4, 1e-6, 1e-8):
            start = time.perf_counter()
            try:
                with np.errstate(all="ignore"):
                    sol = solve_ivp(rhs, (0, args.t_end), x0.ravel(), method=method, rtol=rtol,
                                    atol=rtol * 1e-3, jac=jac)
            except (np.linalg.LinAlgError, ValueError) as exc:  # the baseline blew up
                print(f"{'scipy ' + name:>22} {rtol:>7.0e} failed: {exc}", flush=True)
                continue
            wall = time.perf_counter() - start
            if not sol.success:
                print(f"{'scipy ' + name:>22} {rtol:>7.0e} failed: {sol.message}", flush=True)
                continue
            error = np.abs(sol.y[:, -1] - reference.ravel()).max()
            results.append((f"scipy {name}", rtol, wall, error))
            print(f"{'scipy ' + name:>22} {rtol:>7.0e} {wall:>8.2f} {sol.nfev:>9} {error:>8.1e}",
                  flush=True)
    for method in args.methods.split(","):
        for rtol in (1e-4, 1e-6, 1e-8):
            result = loopsim.simulate(args.g0, args.theta0, rtol=rtol, atol=rtol * 1e-3,
                                      method=method, **run)
            error = np.abs(result.x_final - reference).max()
            label = f"loopsim {method}"
            results.append((label, rtol, result.wall_s, error))
            print(f"{label:>22} {rtol:>7.0e} {result.wall_s:>8.3f} {result.nfev:>9} "
                  f"{error:>8.1e}", flush=True)
    for target in (1e-4, 1e-6):
        base = [r for r in results if r[0].startswith("scipy") and r[3] <= target]
        if not base:
            continue
        b = min(base, key=lambda r: r[2])
        for method in args.methods.split(","):
            mine = [r for r in results if r[0] == f"loopsim {method}" and r[3] <= target]
            if mine:
                m = min(mine, key=lambda r: r[2])
                print(f"# error <= {target:.0e}: fastest baseline {b[0]} {b[2]:.2f} s, "
                      f"loopsim {method} {m[2]:.3f} s: {b[2] / m[2]:.1f}x")


if __name__ == "__main__":
    main()
