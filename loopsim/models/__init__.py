"""Models: the equations of motion behind one interface (``models.base``).

* ``local_sbt``: the sedimenting loop in local slender-body theory (the paper's model);
* ``nonlocal_sbt``: the same loop in nonlocal slender-body theory (not yet on the
  command line nor in the batch kernel);
* ``riccati``: a closed-form test problem for the integrators.

A new model is one module implementing the
interface, imported here so its implementations are registered.
"""

import numpy as np

from ..jit import entry
from . import local_sbt, nonlocal_sbt, riccati  # noqa: F401 - importing registers them
from .base import (
    auxiliary, for_case, implements, jacobian, monitored_errors, rhs, steady_invariants,
)

__all__ = ["rhs", "jacobian", "monitored_errors",
           "steady_invariants",
           "auxiliary",
           "for_case", "implements", "evaluate", "evaluate_jacobian", "local_sbt", "nonlocal_sbt",
           "riccati"]


@entry
def evaluate(problem, y, dydt, aux):
    """dydt = F(y) and the model's auxiliary field at y (the tension multiplier of a loop)."""
    rhs(problem, y, dydt)
    auxiliary(problem, aux)


@entry
def evaluate_jacobian(problem, y, jac):
    """jac = ∂F/∂y at y (the model's :func:`jacobian`, after the F(y) it is given)."""
    f = np.empty_like(y)
    rhs(problem, y, f)
    jacobian(problem, y, f, jac, np.empty_like(y), np.empty_like(y))
