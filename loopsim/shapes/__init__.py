"""Initial shapes.

* ``circle``: the inclined unit circle, the seeded perturbation, perturbing any shape;
* ``curvefit``: polygon checks and the arc-length Fourier fit of a closed curve;
* ``loading``: point files and earlier results, and :func:`start_shape`, the one
  resolver of a run's start used by ``simulate``, sweeps and the CLI.
"""
from .tilted_circle import (
    default_perturbation, inclined_circle, initial_shape, perturb, perturbation_field,
)
from .curvefit import check_points, fit_points
from .loading import (
    TAIL_WARNING, auto_start_order, check_coefficients, content_order, from_coefficients,
    initial_case, load_initial, points_shape, read_points, resolve_initial, shape_info,
    start_shape,
)

__all__ = ["default_perturbation", "inclined_circle", "initial_shape", "perturb",
           "perturbation_field", "check_points", "fit_points", "TAIL_WARNING",
           "auto_start_order", "check_coefficients", "content_order",
           "from_coefficients", "initial_case", "load_initial", "points_shape",
           "read_points", "resolve_initial", "shape_info", "start_shape"]
