"""Would a matrix-free Krylov tension solve beat the dense one?  (issue 11's O(n² log n) lever)

Usage: python scripts/bench_krylov.py [--orders 16,24,32] [--reps 400]

On a real 3D shape (g0 = 150, θ0 = 45°, radau5 to t = 0.3 at each n) it measures
(1) the iterations CG on the normal equations (CGNR), preconditioned by the column
scaling 1/(1 + 2k²) the dense solve uses, needs to reach the dense least-squares
tension to 1e-12 (and 1e-9), from zero and from a warm start 1e-3 away (the
previous stage's tension), and (2) the time of one matrix-free pair A·v + Aᵀ·r
(grid products with the dense P1 and P2, the operator of
``models.local_sbt.tension_operator`` never formed) against forming A densely
(``length_rate_operator``), both in Numba on one core.  A Krylov RHS costs about
(iterations) × (pair); it pays only when that is below the dense formation.
FFT products would make the pair O(M log M) instead of O(M²); the iteration count
is what they cannot change.
"""
import argparse
import time

import numba
import numpy as np
import loopsim
from loopsim.models import local_sbt as L

@numba.njit(cache=True)
def apply_b(P, t, u, out, tmp, prod):
    """out = Σ_c t_c ⊙ P (t_c ⊙ u)  (B u with B = P ∘ G, G_il = t_i·t_l); no allocation."""
    m = u.shape[0]
    for c in range(3):
        for i in range(m):
            tmp[i, c] = t[c, i] * u[i]
    np.dot(P, tmp, prod)
    for i in range(m):
        out[i] = t[0, i] * prod[i, 0] + t[1, i] * prod[i, 1] + t[2, i] * prod[i, 2]


@numba.njit(cache=True)
def apply_a(S0, P1, P2, t, v, out, u, w, z, tmp, prod):
    """A v = (B₂ + B B) S0 v, matrix-free."""
    np.dot(S0, v, u)
    apply_b(P1, t, u, w, tmp, prod)
    apply_b(P1, t, w, out, tmp, prod)
    apply_b(P2, t, u, z, tmp, prod)
    out += z


@numba.njit(cache=True)
def apply_at(S0T, P1T, P2T, t, r, out, u, w, z, tmp, prod):
    """Aᵀ r = S0ᵀ (B₂ᵀ + Bᵀ Bᵀ) r, matrix-free."""
    apply_b(P1T, t, r, u, tmp, prod)
    apply_b(P1T, t, u, w, tmp, prod)
    apply_b(P2T, t, r, z, tmp, prod)
    w += z
    np.dot(S0T, w, out)


@numba.njit(cache=True)
def pair_many(S0, S0T, P1, P1T, P2, P2T, t, v, r, reps):
    """reps × (A v, Aᵀ r), scratch allocated once."""
    m, k = S0.shape
    out_m, out_k = np.empty(m), np.empty(k)
    u, w, z = np.empty(m), np.empty(m), np.empty(m)
    tmp, prod = np.empty((m, 3)), np.empty((m, 3))
    for _ in range(reps):
        apply_a(S0, P1, P2, t, v, out_m, u, w, z, tmp, prod)
        apply_at(S0T, P1T, P2T, t, r, out_k, u, w, z, tmp, prod)
    return out_m[0] + out_k[0]


@numba.njit(cache=True)
def dense_many(g0, w, ops, ws, reps):
    for _ in range(reps):
        L.length_rate_operator(g0, w, ops, ws)
    return ws.length_rate[0, 0]

def cgnr(A, b, d, x0, tol, ref, maxit=500):
    # minimise |A x + b| with x = d*y, CG on (DAᵀAD) y = -DAᵀb
    y = x0 / d
    r = -(d * (A.T @ (A @ (d * y) + b)))
    p = r.copy(); rs = r @ r
    for it in range(1, maxit + 1):
        q = d * (A.T @ (A @ (d * p)))
        alpha = rs / (p @ q)
        y += alpha * p; r -= alpha * q
        rs_new = r @ r
        if np.linalg.norm(d * y - ref) <= tol * np.linalg.norm(ref):
            return it
        p = r + rs_new / rs * p; rs = rs_new
    return -1

def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--orders", default="16,24,32")
    parser.add_argument("--reps", type=int, default=400)
    args_cli = parser.parse_args()
    for n in (int(v) for v in args_cli.orders.split(",")):
        res = loopsim.simulate(150, 45, n=n, t_span=(0, 0.3), method="radau5")
        x = res.x_final
        ops = L.make_operators(n); ws = L.make_workspace(n)
        g0, w = 150.0, res.inputs["w"]
        L.shape_on_grid(x, ops, ws)
        L.length_rate_operator(g0, w, ops, ws)
        k = ops.S0.shape[1]
        A = ws.length_rate[:k].T.copy(); b = ws.length_rate[k].copy()
        ref = np.linalg.lstsq(A, -b, rcond=None)[0]
        d = ops.column_scale
        its0 = cgnr(A, b, d, np.zeros(k), 1e-12, ref)
        warm = ref * (1 + 1e-3 * np.random.default_rng(0).standard_normal(k))
        itsw = cgnr(A, b, d, warm, 1e-12, ref)
        its6 = cgnr(A, b, d, warm, 1e-9, ref)
        cond = np.linalg.cond(A * d)
        t = ws.tangent.copy()
        P2 = ops.S2 @ ops.F
        args = (ops.S0, ops.S0T, ops.P1, ops.P1T, np.ascontiguousarray(P2), ops.P2T, t, ref.copy(), b.copy())
        pair_many(*args, 2); dense_many(g0, w, ops, ws, 2)
        reps = args_cli.reps
        t0 = time.perf_counter(); pair_many(*args, reps); tp = (time.perf_counter() - t0) / reps
        t0 = time.perf_counter(); dense_many(g0, w, ops, ws, reps); td = (time.perf_counter() - t0) / reps
        # check the matrix-free apply against the dense A
        m = ops.m
        out = np.empty(m)
        apply_a(ops.S0, ops.P1, np.ascontiguousarray(P2), t, ref, out, np.empty(m), np.empty(m),
                np.empty(m), np.empty((m, 3)), np.empty((m, 3)))
        err = np.abs(out - A @ ref).max() / np.abs(A @ ref).max()
        print(f"n {n}: cond(A D) {cond:.2e}; CGNR iterations to 1e-12: from zero {its0}, warm (1e-3) {itsw}; to 1e-9 warm {its6}; "
              f"matrix-free A v + Aᵀ r {tp*1e6:.1f} us, dense A formation {td*1e6:.1f} us (ratio {td/tp:.1f}); apply check {err:.1e}", flush=True)


if __name__ == "__main__":
    main()
