"""loopsim: flexible elastic loops sedimenting in a viscous (Stokes) fluid.

Layout: ``spectral`` (Fourier algebra), ``physics`` (the three maps and the
tension solve, njit), ``problems`` and ``integrate`` (time stepping, njit),
``initial`` and ``diagnostics`` (shapes), ``linear_stability`` (paper's
operator), ``api`` (Python entry points), ``io`` (Parquet), ``cli``.
"""
__version__ = "0.1.0"

from . import _jitcache

_jitcache.configure()  # before any kernel is decorated: see loopsim/_jitcache.py

from .api import SUMMARY_FIELDS, SimulationResult, evaluate_maps, simulate, stability_parameter
from .ensemble import read_results, read_snapshots

__all__ = ["simulate", "SimulationResult", "evaluate_maps", "stability_parameter",
           "SUMMARY_FIELDS", "read_results", "read_snapshots", "__version__"]
