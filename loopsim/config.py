"""JIT options and numerical defaults, kept in one place.

Conventions used throughout loopsim (stated once, tested in ``tests/``):

* Lengths are scaled by L / 2π, so the loop has length 2π and arc length
  s ∈ [0, 2π).  Forces are scaled by 8π³EI / L³ (per unit length, per L³),
  time so that the dimensionless equations read (paper §3)::

      f = -x'''' + (T x')' - g0 e_z
      u = f + (x'·f) x'
      0 = x'·u' - w (1 - x'·x')

* Gravity points along -z.  Angles are radians inside the package and
  degrees at the user interface (CLI flags, result tables).
* The tension reported to users is the physical axial force
  N = T + |x''|², not the Lagrange multiplier T (see ``diagnostics``).
"""

# No fastmath: results must be bit-reproducible across thread counts.
JIT = dict(cache=True, nogil=True, error_model="numpy")

#: Default penalty rate of the length-creation term (see README "Choice of w").
DEFAULT_W = 10.0
DEFAULT_N = 6
DEFAULT_T_END = 10.0
DEFAULT_RTOL = 1e-6
DEFAULT_ATOL = 1e-9
DEFAULT_PERTURBATION = 1e-3
DEFAULT_SEED = 0
DEFAULT_MAX_STEPS = 2_000_000
#: Relative length error beyond which a run stops with status LENGTH_ERROR.
DEFAULT_LENGTH_TOL = 0.25
#: Early stop at the terminal state: every DEFAULT_STEADY_INTERVAL time units the
#: covariance eigenvalues and |n_z| of the plane normal are compared with their
#: values one interval earlier; two consecutive changes below DEFAULT_STEADY_TOL
#: make the state steady (see README "Terminal state").
DEFAULT_STEADY_INTERVAL = 0.5
DEFAULT_STEADY_TOL = 1e-6
#: A run is *resolved* at its truncation n when its worst transient relative length
#: error stays at or below RESOLVED_LENGTH_ERROR and its terminal spectral tail
#: (``diagnostics.spectral_tail``) at or below RESOLVED_TAIL.  Evidence
#: (scripts/resolution_study.py, n = 6 against n = 16 from the same start curve, 14
#: cases g0 = 30..350, θ0 = 30..85°; table in the README): the 2 cases whose terminal
#: tilt and aspect ratio agree (to 1e-4° and 3e-7) had length errors ≤ 1.5e-7 and tails
#: ≤ 1.1e-8; the 12 that differ (by 0.02 to 3.8 in aspect ratio, up to 62° in tilt) had
#: length errors ≥ 1.5e-4, or (g0 = 30, θ0 = 85°, in-plane) a tail of 1.2e-3.  The tail
#: alone is no guide: wrong 3D runs at n = 6 end as near-circles with tails of 1e-13.
RESOLVED_LENGTH_ERROR = 1e-5
RESOLVED_TAIL = 1e-3
