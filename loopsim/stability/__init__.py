"""Linear stability of the translating circle and of the steady in-plane shapes.

* ``paper``: the paper's §4 operator, and the same operator with the sign of
  ∂² corrected (its q_c = 14.561 is wrong; corrected: 10.6493);
* ``circle``: the full linearisation of loopsim's own equations about the
  circle (the njit Jacobian), its sectors, spectrum and critical q (in-plane
  8.9001, out-of-plane 10.6493);
* ``onset``: when loops released near the circle become visibly in-plane or 3D;
* ``branch``: the steady in-plane shapes that bifurcate off the circle at q_c,
  continued in q, and their in-plane and out-of-plane stability;
* ``roots``: the scan-and-refine root finder they share.
"""
from . import branch, full_linear, onset, paper  # noqa: F401
