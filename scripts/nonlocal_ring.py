"""The rigid ring in nonlocal slender-body theory against Johnson & Wu (1979).

Prints, at ε = a/L = 1e-2, 1e-3, 1e-4 (a/R = 2π ε), the rigid ring's velocity under a
uniform force density (per unit density, loopsim units: the local model gives 1
broadside and 4/3 edgewise), from loopsim.models.nonlocal_operator:

* broadside: the mean of u for a uniform density along the axis (u is uniform: its
  spread is printed too);
* edgewise: the rigid-body mobility (the force density that keeps the ring rigid is
  solved for; a uniform density alone does not move it rigidly);
* the largest |Ω| and relative error over rings tilted at random;

next to Johnson & Wu's closed forms, the two-term edgewise form 6π²μRU/(ℓ + 1/3), and
the first mode k at which (Λ + K)/c stops being positive.  Output is a Markdown table
(docs/nonlocal.md).  Runs in a few seconds.

    python scripts/nonlocal_ring.py
"""
import math

import numpy as np

from loopsim.models import nonlocal_closed_form as closed
from loopsim.models import nonlocal_operator as nl

EPSILONS = (1e-2, 1e-3, 1e-4)


def circle():
    x = np.zeros((3, 3))
    x[0, 1] = 1.0  # cos s
    x[1, 2] = 1.0  # sin s
    return x


def random_rotation(rng):
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def main():
    rng = np.random.default_rng(1979)
    rows = []
    for eps in EPSILONS:
        c = nl.slenderness_constant(eps)
        ell = math.log(4.0 / (math.pi * eps))  # log(8R/a)
        jw_broad, jw_edge = closed.johnson_wu_ring(eps)
        u = nl.nonlocal_velocity(circle(), np.array([[0.0], [0.0], [1.0]]), eps)
        broad, spread = float(np.mean(u[2])), float(np.ptp(u, axis=1).max())
        edge, spin = nl.rigid_velocity(circle(), [2 * np.pi, 0.0, 0.0], eps=eps)
        tilt_error = tilt_spin = 0.0
        for _ in range(10):
            rotation = random_rotation(rng)
            g = rng.standard_normal(3)
            axis = rotation[:, 2]
            expected = jw_broad * (g @ axis) * axis + jw_edge * (g - (g @ axis) * axis)
            velocity, omega = nl.rigid_velocity(rotation @ circle(), 2 * np.pi * g, eps=eps)
            scale = np.linalg.norm(expected)
            tilt_error = max(tilt_error, np.linalg.norm(velocity - expected) / scale)
            tilt_spin = max(tilt_spin, np.linalg.norm(omega) / scale)
        rows.append(dict(
            eps=eps, aR=2 * np.pi * eps, c=c, ell=ell, broad=broad, jw_broad=jw_broad,
            err_broad=broad / jw_broad - 1, spread=spread, edge=edge[0], jw_edge=jw_edge,
            err_edge=edge[0] / jw_edge - 1, spin=max(np.abs(spin).max(), tilt_spin),
            two_term=8.0 * (ell + 1.0 / 3.0) / (3.0 * c), tilt=tilt_error,
            kmax=closed.first_nonpositive_mode(eps)))

    print("| ε = a/L | a/R | c = −2 log ε | log(8R/a) | broadside U | J&W | rel. error "
          "| edgewise U | J&W | rel. error | two-term form: rel. diff. |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['eps']:.0e} | {r['aR']:.4f} | {r['c']:.4f} | {r['ell']:.4f} "
              f"| {r['broad']:.12f} | {r['jw_broad']:.12f} | {r['err_broad']:.1e} "
              f"| {r['edge']:.12f} | {r['jw_edge']:.12f} | {r['err_edge']:.1e} "
              f"| {r['two_term'] / r['jw_edge'] - 1:+.2e} |")
    print()
    print("| ε | spread of u, broadside | max abs Ω / abs U | max rel. error, 10 tilted rings "
          "| c (U_b − 1) | c (U_e − 4/3) | first non-positive mode k |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['eps']:.0e} | {r['spread']:.1e} | {r['spin']:.1e} | {r['tilt']:.1e} "
              f"| {r['c'] * (r['broad'] - 1):.6f} | {r['c'] * (r['edge'] - 4 / 3):.6f} "
              f"| {r['kmax']} |")


if __name__ == "__main__":
    main()
