"""Deprecated alias of :mod:`loopsim.sweeps`, kept for one more release for users and
scripts that import ``loopsim.ensemble`` (the sweeps' module until they became a package);
importing it warns (``DeprecationWarning``).

Nothing is defined here: every public name of ``loopsim.sweeps`` (its ``__all__``) is
re-exported unchanged, so ``ensemble.run_sweep is sweeps.run_sweep``.  New code imports
``loopsim.sweeps``; patch a helper (in a test) in the ``loopsim.sweeps`` module that
uses it, not here.
"""
from ._moved import warn_moved

warn_moved("loopsim.ensemble", "loopsim.sweeps")

from .sweeps import *  # noqa: E402,F401,F403 - this module's one job is the re-export
from .sweeps import __all__  # noqa: E402,F401
