"""Models: the equations of motion behind one interface (``models.base``).

* ``local_sbt``: the sedimenting loop in local slender-body theory (the paper's model);
* ``nonlocal_sbt``: the same loop in nonlocal slender-body theory (docs/nonlocal.md);
* ``riccati``: a closed-form test problem for the integrators.

A new model is one module implementing the
interface, imported here so its implementations are registered.  A user chooses the
loop's model by name (:class:`Model`: ``--model``, ``simulate(model=)``).
"""
import collections
import functools

import numpy as np

from .. import validation
from ..defaults import MAX_SLENDERNESS, MODEL_CHOICES
from ..jit import entry
from . import local_sbt, nonlocal_closed_form, nonlocal_sbt, riccati  # noqa: F401 - registers them
from .base import (
    auxiliary, for_case, implements, jacobian, monitored_errors, rhs, steady_invariants,
)

__all__ = ["Model", "LOCAL", "choose", "highest_order", "check_order", "make_problem",
           "case_constants", "case_parameters", "rhs", "jacobian", "monitored_errors",
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


#: The loop's model as a user chooses it: ``name`` one of ``defaults.MODEL_CHOICES``,
#: ``slenderness`` ε = a/L for "nonlocal" (None for "local").
Model = collections.namedtuple("Model", "name slenderness")
#: The default: the paper's local slender-body theory.
LOCAL = Model("local", None)


def choose(name="local", slenderness=None):
    """The :class:`Model` of a user's choice, checked: one-line ValueErrors naming the value
    (the nonlocal model needs a slenderness in (0, ``defaults.MAX_SLENDERNESS``]; the local
    one takes none)."""
    name = validation.check_choice("model", name, MODEL_CHOICES)
    if name == "local":
        if slenderness is not None:
            raise ValueError(f"slenderness applies only to the nonlocal model, got "
                             f"slenderness={slenderness!r} with model 'local'")
        return LOCAL
    if slenderness is None:
        raise ValueError("the nonlocal model needs slenderness = a/L (filament radius over "
                         "loop length), e.g. 1e-3")
    return Model(name, validation.check_real("slenderness", slenderness, 0.0,
                                             MAX_SLENDERNESS, low_open=True))


@functools.lru_cache(maxsize=64)
def highest_order(model):
    """The highest truncation order ``model`` can run at (None: no limit below
    ``validation.MAX_N``): for the nonlocal model, one below the first mode its operator is not positive at on the circle
    (``nonlocal_closed_form.first_nonpositive_mode``: ε = 1e-2 gives n ≤ 10, 1e-3 n ≤ 108)."""
    if model.name == "local":
        return None
    first = nonlocal_closed_form.first_nonpositive_mode(model.slenderness, validation.MAX_N + 1)
    return None if first is None else first - 1


def check_order(model, n, name="n"):
    """n, or a one-line ValueError when ``model`` cannot run at truncation n."""
    top = highest_order(model)
    if top is not None and n > top:
        raise ValueError(
            f"{name} = {n} is too high for the nonlocal model at slenderness "
            f"{model.slenderness:g}: its operator is not positive from mode {top + 1} on "
            f"(slender-body theory fails at wavelengths below ~9 filament radii); use "
            f"{name} <= {top} or a smaller slenderness")
    return n


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
