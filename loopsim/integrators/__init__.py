"""Time integration: one driver, methods as data.

* ``control``: statuses, options, error norm, step-size factor, output times, monitors;
* ``base``: the three generic functions a method implements (start, attempt, advance);
* ``explicit``: embedded Runge–Kutta methods as Butcher tableaux (RKF45);
* ``radau``: Radau IIA of order 5 with simplified Newton;
* ``linalg``: LU factorisation for the implicit methods;
* ``driver``: :func:`integrate`, the adaptive loop around any method.

``METHODS`` maps the user-facing names to method objects; every test
parametrised over it covers a new method.  To add one: a namedtuple type
with an ``error_order`` field, implementations of ``start``, ``attempt`` and
``advance`` for it, and a name here.
"""
from .control import (  # noqa: F401 - the public vocabulary of the package
    LENGTH_ERROR, NON_FINITE, OK, STATUS_NAMES, STEADY, STEP_BUDGET, STEP_UNDERFLOW,
    STOP_REASONS, SUCCESS, StepOptions, step_options,
)
from .driver import COUNTS, integrate
from .explicit import RKF45, Tableau
from .radau import RADAU5, RadauIIA

#: Integrators by name: the value is the method object passed to :func:`integrate`.
METHODS = {"rkf45": RKF45, "radau5": RADAU5}

__all__ = ["integrate", "COUNTS", "METHODS", "Tableau", "RadauIIA", "RKF45", "RADAU5", "step_options",
           "StepOptions", "STATUS_NAMES", "STOP_REASONS", "SUCCESS"]
