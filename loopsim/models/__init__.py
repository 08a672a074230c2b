"""Models: the equations of motion behind one interface (``models.base``).

* ``local_sbt``: the sedimenting loop in local slender-body theory (the paper's model);
* ``nonlocal_sbt``: the same loop in nonlocal slender-body theory (docs/nonlocal.md);
* ``riccati``: a closed-form test problem for the integrators.

A new model is one module implementing the
interface, imported here so its implementations are registered.  A user chooses the
loop's model by name (:class:`Model`: ``--model``, ``simulate(model=)``).
"""
import collections

import numpy as np

from ..jit import entry
from . import local_sbt, nonlocal_sbt, riccati  # noqa: F401 - importing registers them
from .base import (
    auxiliary, for_case, implements, jacobian, monitored_errors, rhs, steady_invariants,
)

__all__ = ["Model", "LOCAL", "rhs", "jacobian", "monitored_errors",
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


#: The loop's model as a user chooses it: ``name`` one of ``config.MODEL_CHOICES``,
#: ``slenderness`` ε = a/L for "nonlocal" (None for "local").
Model = collections.namedtuple("Model", "name slenderness")
#: The default: the paper's local slender-body theory.
LOCAL = Model("local", None)
_MODULES = {"local": local_sbt, "nonlocal": nonlocal_sbt}


def make_problem(model, n, g0, w):
    """The problem of one loop of ``model`` (a :class:`Model`) at truncation n."""
    if model.name == "local":
        return local_sbt.make_problem(n, g0, w)
    return nonlocal_sbt.make_problem(n, g0, w, model.slenderness)


def case_constants(model, n):
    """What the cases of ``model`` at truncation n share (the batch kernel's constants)."""
    if model.name == "local":
        return local_sbt.make_operators(n)
    return nonlocal_sbt.shared_constants(n)


def case_parameters(model, g0, w):
    """One case's parameters, in the order of the model's ``PARAMETERS``."""
    if model.name == "local":
        return (float(g0), float(w))
    return (float(g0), float(w), nonlocal_sbt.slenderness_constant(model.slenderness))
