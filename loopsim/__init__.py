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
* ``api`` (``simulate``), ``sweeps`` (``loopsim.ensemble``: its earlier name), ``plots``,
  ``cli``.
"""
from . import _signals

_signals.install_early()  # the loopsim program: Ctrl-C while loading is one line, exit 130

from ._version import __version__  # noqa: E402

#: The public names and the modules that define them, loaded on first use (PEP 562), so
#: that ``import loopsim.cli`` (``loopsim --help``) loads neither NumPy nor Numba.
_EXPORTS = {
    "simulate": "api", "SimulationResult": "api", "evaluate_maps": "api",
    "SUMMARY_FIELDS": "api", "stability_parameter": "diagnostics",
    "coefficients": "io", "read_results": "io", "read_snapshots": "io", "sweep": "sweeps",
    "summarize": "summary", "compare": "summary",
    "animate": "figures.animation", "report": "sweep_report",
}
__all__ = list(_EXPORTS) + ["__version__"]


def __getattr__(name):
    if name in _EXPORTS:
        import importlib

        value = getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
