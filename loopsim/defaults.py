"""Numerical and run defaults, kept in one place (the JIT options are ``jit.JIT``; the
OSError numbers the command line exits 3 on, ``exit_codes.ENVIRONMENT_ERRNOS``).

Conventions used throughout loopsim (stated once, tested in ``tests/``):

* Lengths are scaled by ℓ = L / 2π, so the loop has length 2π and arc length
  s ∈ [0, 2π).  Force densities are scaled by EI/ℓ³ = 8π³EI / L³, forces (the
  multiplier T, the axial force N) by EI/ℓ² = EI (2π/L)², and time by
  t_u = ζ⊥ ℓ⁴ / EI (ζ⊥ = 8πμ/c, c = −2 ln(a/L): the perpendicular drag coefficient per
  unit length), so that the dimensionless equations read (paper §3; docs/model.md,
  "Units")::

      f = -x'''' + (T x')' - g0 e_z
      u = f + (x'·f) x'
      0 = x'·u' - w (1 - x'·x')

* Gravity points along -z.  Angles are radians inside the package and
  degrees at the user interface (CLI flags, result tables).
* The tension reported to users is the physical axial force
  N = T + |x''|², not the Lagrange multiplier T (see ``diagnostics``).
"""

#: Default penalty rate of the length-creation term (docs/model.md, "Choice of the length
#: penalty w").
DEFAULT_W = 10.0
DEFAULT_N = 6
DEFAULT_T_END = 10.0
DEFAULT_RTOL = 1e-6
DEFAULT_ATOL = 1e-9
DEFAULT_PERTURBATION = 1e-3

#: The ensemble every probability over seeds is taken over (``shapes.tilted_circle``'s
#: recipe), in one line (named in
#: ``--help``, in summary tables' metadata and in docs/studies/convergence-top.md).
PERTURBATION_ENSEMBLE = (
    "seed k perturbs modes 2 to the starting order n (6 with --n auto, zero-padded as n "
    "climbs) with amplitudes N(0,1)/m^2 from numpy.random.default_rng(k), scaled to RMS "
    "size --perturbation (default 1e-3), the length kept 2 pi (a given shape: the same "
    "draws in its own frame)")
DEFAULT_SEED = 0
DEFAULT_MAX_STEPS = 2_000_000
#: Cases per chunk file of a sweep by default, and with ``n="auto"``, whose 3D cases take
#: minutes: a SIGKILL loses the chunks not yet written (up to threads + 1 of them).
DEFAULT_CHUNK_SIZE = 32
DEFAULT_AUTO_CHUNK_SIZE = 4
#: Relative length error beyond which a run stops with status LENGTH_ERROR.
DEFAULT_LENGTH_TOL = 0.25
#: Early stop at the terminal state: every DEFAULT_STEADY_INTERVAL time units the
#: covariance eigenvalues and |n_z| of the plane normal are compared with their
#: values one interval earlier; two consecutive changes below DEFAULT_STEADY_TOL
#: make the state steady (docs/sweeps.md, "Terminal state and early stop").
DEFAULT_STEADY_INTERVAL = 0.5
DEFAULT_STEADY_TOL = 1e-6
#: A run is *resolved* at its truncation n when its worst transient relative length
#: error stays at or below RESOLVED_LENGTH_ERROR and its spectral tail (the top two modes'
#: share of the deformation, ``diagnostics.spectral_tail``), once the top modes have
#: started to grow, at or below RESOLVED_TAIL (the decay of a seeded start's own top modes
#: does not count: ``integrators.control.monitor``).  ``n="auto"`` restarts a case at the
#: next order whenever the tail passes DEFAULT_TAIL_TOL, the same value.  Evidence
#: (scripts/auto_study.py, docs/auto-and-determinacy.md): against fixed n = 32 runs from
#: the same start, the determined auto rows of 25 cases end within 0.0068 deg in tilt and
#: 1.9e-4 in aspect ratio.  The earlier tail, relative to the loop's size, let 3D tilts
#: end up to 18 deg off (docs/studies/earlier-n-auto.md).
RESOLVED_LENGTH_ERROR = 1e-5
RESOLVED_TAIL = 1e-5
#: The spectral tail is measured against the loop's deformation (modes k >= 2), floored at
#: DEFORMATION_FLOOR times its size (the default perturbation's size): a smaller deformation
#: counts as that large, so top modes below DEFORMATION_FLOOR * RESOLVED_TAIL = 1e-8 of the
#: loop's size (ten times the default atol: integration noise) never call for refinement,
#: and a loop relaxing back to its circle does not climb the ladder on noise.  (At 1e-4,
#: noise at the atol level tripped the tolerance on stable loops.)
DEFORMATION_FLOOR = 1e-3
#: Automatic truncation (``n="auto"``, ``loopsim.refinement``): the orders a case may
#: climb, the default top order, and the spectral-tail tolerance that sends a case up.
AUTO_ORDERS = (6, 8, 12, 16, 20, 24, 32, 40, 48, 64)
DEFAULT_N_MAX = 32
#: The loop's models (``--model``, ``simulate(model=)``; ``loopsim.models``): the paper's
#: local slender-body theory (the default) and nonlocal slender-body theory, which needs
#: the slenderness ε = a/L (``--slenderness``) and a truncation below the first mode its
#: operator is not positive at (``models.nonlocal_circle.first_nonpositive_mode``).
MODEL_CHOICES = ("local", "nonlocal")
#: Largest slenderness a/L the nonlocal model accepts: at 0.1 the operator is not positive
#: from mode 1 on (docs/nonlocal.md, "High modes"); slender-body theory needs ε ≪ 1.
MAX_SLENDERNESS = 0.05
DEFAULT_TAIL_TOL = RESOLVED_TAIL
#: A point file started with ``n="auto"`` (``--initial POINTS --n auto``) starts at the
#: lowest order whose truncation of the fitted curve leaves out at most this RMS amplitude
#: relative to the loop's (``shapes.content_order``): 1000 times below the default atol
#: (1e-9, in L/2π, on a loop of size about 1), so the start is the file's shape to within
#: the integration's own error; a curve whose fit is at round-off (about 2e-15) by a lower
#: order starts there.
INITIAL_CONTENT_TOL = 1e-12
#: ``--seeds auto``'s targets, by option name (``--p-halfwidth``, ``sweep(p_halfwidth=)``):
#: (``seeds_auto_rule.SeedTargets`` field, default).  The defaults are defended in
#: docs/distributions.md, "Seeds until the answer is sharp".
SEED_TARGETS = {
    "p_halfwidth": ("p_halfwidth", 0.15),
    "tilt_halfwidth": ("tilt_halfwidth_deg", 2.5),
    "min_seeds": ("min_seeds", 4),
    "max_seeds": ("max_seeds", 64),
    "check_seeds": ("check_seeds", 8),
}
