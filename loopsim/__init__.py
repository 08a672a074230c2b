"""loopsim: flexible elastic loops sedimenting in a viscous (Stokes) fluid.

Layout (each layer imports only those above it):

* ``config``, ``validation``, ``spectral``, ``dispatch``: conventions, input
  checks, Fourier algebra, generic functions for jitted code;
* ``models``: equations of motion behind one interface (``local_sbt``: the loop);
* ``integrators``: one adaptive driver, methods as data (RKF45, Radau IIA);
* ``batch``: many cases in one parallel kernel;
* ``diagnostics``, ``shapes``, ``stability``: shape measures, initial shapes,
  linear stability of the circle;
* ``io``: table schemas, Parquet writing and reading;
* ``api`` (``simulate``), ``ensemble`` (sweeps), ``plots``, ``cli``.
"""
from . import _signals

_signals.install_early()  # the loopsim program: Ctrl-C while loading is one line, exit 130

from . import _jitcache  # noqa: E402
from ._version import __version__  # noqa: E402

_jitcache.configure()  # before any kernel is decorated: see loopsim/_jitcache.py

from .api import SUMMARY_FIELDS, SimulationResult, evaluate_maps, simulate  # noqa: E402
from .diagnostics import stability_parameter  # noqa: E402
from .io import coefficients, read_results, read_snapshots  # noqa: E402

__all__ = ["simulate", "SimulationResult", "evaluate_maps", "stability_parameter",
           "SUMMARY_FIELDS", "read_results", "read_snapshots", "coefficients", "__version__"]
