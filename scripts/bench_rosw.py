"""Would a Rosenbrock-W method beat radau5 in the 3D regime?  (issue 11's last lever, a prototype)

Usage: python scripts/bench_rosw.py G0:THETA0:N RTOL[,RTOL...] JAC_EVERY[,JAC_EVERY...]
e.g.   python scripts/bench_rosw.py 100:60:24 1e-6 1,5,20

ROS34PW2 (Rang & Angermann, BIT 45 (2005): 4 stages, order 3, embedded order 2,
L-stable, a W-method: stays order 3 with an approximate Jacobian) on the loop from
the seeded tilted circle, driven from Python with loopsim's compiled RHS
(``loop_velocity``) and exact Jacobian (``loop_jacobian``):

    (I − hγJ) k_i = h f(y + Σ_j a_ij k_j) + h J Σ_j γ_ij k_j,   y_new = y + Σ b_i k_i,

error Σ (b_i − b̂_i) k_i in the RMS norm of atol + rtol |y| (atol = rtol · 1e-3),
h ← h · clip(0.9 err^(-1/3), 0.2, 5), h held for factors in [1, 1.2) so the LU is
kept.  The Jacobian is refreshed every JAC_EVERY accepted steps (1: a plain
Rosenbrock method) and after a rejected step with a stale one.  Prints the counts
(steps, RHS, Jacobians, LUs) and the terminal tilt and aspect ratio, to set
against radau5's (scripts/terminal_precision.py) through the per-call costs of
scripts/bench_kernels.py.  Wall times include Python overhead and scipy's LU:
not comparable with the compiled integrators.
"""
import sys
import time

import numpy as np
import scipy.linalg as sl

import loopsim
from loopsim import diagnostics
from loopsim.models import local_sbt as L

g = 4.3586652150845900e-01
A = np.array([[0, 0, 0, 0], [8.7173304301691801e-01, 0, 0, 0],
              [8.4457060015369423e-01, -1.1299064236484185e-01, 0, 0], [0, 0, 1, 0]])
G = np.array([[0, 0, 0, 0], [-8.7173304301691801e-01, 0, 0, 0],
              [-9.0338057013044082e-01, 5.4180672388095326e-02, 0, 0],
              [2.4212380706095346e-01, -1.2232505839045147e+00, 5.4526025533510214e-01, 0]])
B = np.array([2.4212380706095346e-01, -1.2232505839045147e+00, 1.5452602553351020e+00, 4.3586652150845900e-01])
BS = np.array([3.7810903145819369e-01, -9.6042292212423178e-02, 0.5, 2.1793326075422950e-01])

def run(g0, theta0, n, rtol, t_end=10.0, jac_every=1, atol=None):
    atol = rtol * 1e-3 if atol is None else atol
    r0 = loopsim.simulate(g0, theta0, n=n, t_span=(0, 1e-9), method="radau5")
    x0 = r0.x[0]
    prob = L.make_problem(n, g0, r0.inputs["w"])
    k3 = x0.size
    def f(y):
        out = np.empty((3, k3 // 3)); L.loop_velocity(y.reshape(3, -1), prob.g0, prob.w, prob.ops, prob.ws, out); return out.ravel()
    def jac(y):
        J = np.empty((k3, k3)); L.loop_jacobian(y.reshape(3, -1), prob.g0, prob.w, prob.ops, prob.ws, J); return J
    y = x0.ravel().copy(); t = 0.0; h = 1e-4
    nf = nj = nlu = acc = rej = 0
    J = jac(y); nj += 1; since = 0; lu = None; h_lu = None
    while t < t_end:
        h = min(h, t_end - t)
        if lu is None or h != h_lu:
            lu = sl.lu_factor(np.eye(k3) - h * g * J); nlu += 1; h_lu = h
        ks = []
        for i in range(4):
            u = y + sum(A[i, j] * ks[j] for j in range(i)) if i else y
            rhs = h * f(u); nf += 1
            if i:
                rhs += h * (J @ sum(G[i, j] * ks[j] for j in range(i)))
            ks.append(sl.lu_solve(lu, rhs))
        y_new = y + sum(B[i] * ks[i] for i in range(4))
        e = sum((B[i] - BS[i]) * ks[i] for i in range(4))
        sc = atol + rtol * np.maximum(abs(y), abs(y_new))
        err = np.sqrt(np.mean((e / sc) ** 2))
        fac = min(5.0, max(0.2, 0.9 * err ** (-1 / 3))) if err > 0 else 5.0
        if err <= 1.0:
            y = y_new; t += h; acc += 1; since += 1
            if since >= jac_every:
                J = jac(y); nj += 1; since = 0; lu = None
            if 1.0 <= fac < 1.2:
                fac = 1.0
        else:
            rej += 1
            if since > 0:  # stale Jacobian: refresh before retrying
                J = jac(y); nj += 1; since = 0; lu = None
        h *= fac
        if not np.all(np.isfinite(y)) or acc + rej > 400000:
            break
    x = y.reshape(3, -1)
    return dict(t=t, acc=acc, rej=rej, nfev=nf, njev=nj, nlu=nlu, tilt=diagnostics.tilt_deg(x), aspect=diagnostics.aspect_ratio(x))

if __name__ == "__main__":
    g0, th, n = (float(v) for v in sys.argv[1].split(":"))
    for rtol in (float(v) for v in sys.argv[2].split(",")):
        for every in (int(v) for v in sys.argv[3].split(",")):
            t0 = time.perf_counter(); r = run(g0, th, int(n), rtol, jac_every=every); w = time.perf_counter() - t0
            print(f"{g0:g}:{th:g}:{n:g} rtol {rtol:g} jac_every {every} wall {w:.1f}s", r, flush=True)
