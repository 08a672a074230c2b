"""Generic functions for jitted code, resolved on the type of their first argument.

Models (``models.base``) and integrators (``integrators.base``) are namedtuple
types; code written against a generic function, ``rhs(problem, ...)`` or
``attempt(method, ...)``, is compiled once per type, with the implementation
registered for that type inlined (``numba.extending.overload``).  Calling a
generic from plain Python raises; call it from an njit function.
"""
from numba import types
from numba.extending import overload

from .jit import JIT

_IMPLEMENTATIONS = {}


def generic(stub):
    """Make ``stub`` a generic function: each call from jitted code resolves to the
    implementation registered for its first argument's namedtuple class."""
    table = _IMPLEMENTATIONS.setdefault(stub, {})

    def resolve(first, *rest):
        if isinstance(first, types.BaseNamedTuple):
            return table.get(first.instance_class)
        return None

    overload(stub, jit_options=JIT, strict=False)(resolve)
    return stub


def implements(stub, cls):
    """Decorator registering an njit-compilable implementation of the generic ``stub``
    for first arguments of namedtuple class ``cls``."""
    if stub not in _IMPLEMENTATIONS:
        raise ValueError(f"{getattr(stub, '__name__', stub)!r} is not a generic function")

    def register(implementation):
        _IMPLEMENTATIONS[stub][cls] = implementation
        return implementation

    return register

