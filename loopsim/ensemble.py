"""Backwards-compatible alias of :mod:`loopsim.sweeps`, kept for users and scripts that
import ``loopsim.ensemble`` (the sweeps' module until they became a package).

Nothing is defined here: every public name of ``loopsim.sweeps`` (its ``__all__``) is
re-exported unchanged, so ``ensemble.run_sweep is sweeps.run_sweep``.  New code imports
``loopsim.sweeps``; patch a helper (in a test) in the ``loopsim.sweeps`` module that
uses it, not here.
"""
from .sweeps import *  # noqa: F401,F403 - this module's one job is the re-export
from .sweeps import __all__  # noqa: F401
