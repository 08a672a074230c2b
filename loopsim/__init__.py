"""loopsim: flexible elastic loops sedimenting in a viscous (Stokes) fluid.

A closed inextensible elastic filament (Euler-Bernoulli bending, local or nonlocal
slender-body theory) falling under gravity, after Waszkiewicz, Szymczak & Lisicki,
J. Fluid Mech. 919, A14 (2021): its centreline is a Fourier series of order n, time-stepped
by RKF45 (the paper's scheme) or Radau IIA, and every run says whether its order resolves
it and whether its terminal state is determined.  Units: docs/model.md, "Units".

Main entry points:

* :func:`simulate`: one loop, to a resolved terminal state by default (``n="auto"``;
  the paper's scheme is ``n=6, method="rkf45"``); returns a :class:`SimulationResult`;
* :func:`sweep`: a grid of loops into a resumable Parquet directory (``loopsim sweep``);
  :func:`read_results`, :func:`read_snapshots` and :func:`coefficients` read it back;
* :func:`summarize` and :func:`compare`: outcomes over seeds as distributions;
* :func:`evaluate_maps`, :func:`stability_parameter`: the model's maps and q;
* :class:`LoopsimWarning`: a result that is not resolved or not determined;
* the ``loopsim`` command (``loopsim --help``, docs/cli.md).

Internals, each layer importing only those before it (tests/test_layout.py checks that
every module is named here and that no import goes to a later layer; docs/extending.md's
module table is made from this list): ``_version``, ``_signals``, ``_moved``,
``_jitcache``, ``_blas``, ``defaults``, ``exit_codes``, ``render_defaults``, ``columns``,
``spectral``; ``jit``, ``validation``, ``diagnostics``, ``intervals``; ``dispatch``, ``linalg``,
``outcomes``, ``survival``, ``storage``; ``models``, ``outcome_statistics``, ``shapes``, ``late_motion``; ``integrators``,
``seeds_auto_rule``, ``distribution_differences``, ``stability``; ``batch``, ``figures``, ``result``; ``refinement``,
``sweep_report``; ``api``; ``sweeps``; ``cli``, ``ensemble``; ``__main__``.
"""
from . import _moved, _signals

_signals.install_early()  # the loopsim program: Ctrl-C while loading is one line, exit 130
_moved.install()  # the old paths of renamed modules, for one release (CHANGELOG.md)

from ._version import __version__  # noqa: E402

#: The public names and the modules that define them, loaded on first use (PEP 562), so
#: that ``import loopsim.cli`` (``loopsim --help``) loads neither NumPy nor Numba.
_EXPORTS = {
    "simulate": "api", "SimulationResult": "api", "evaluate_maps": "api",
    "SUMMARY_FIELDS": "api", "LoopsimWarning": "api", "stability_parameter": "diagnostics",
    "coefficients": "storage", "read_results": "storage", "read_snapshots": "storage",
    "sweep": "sweeps",
    "summarize": "outcome_statistics", "compare": "outcome_statistics",
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
