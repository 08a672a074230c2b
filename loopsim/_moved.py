"""Old import paths of renamed modules, kept working for one release with a
``DeprecationWarning`` (CHANGELOG.md, "Unreleased").

No file is left at an old path: an import of one is answered by :class:`MovedFinder`
(on ``sys.meta_path`` from ``import loopsim`` on) with the new module itself, so
``loopsim.summary.summarize is loopsim.outcome_statistics.summarize``.  A package's
submodules follow it (``loopsim.io.tables`` is ``loopsim.storage.tables``).
``loopsim.config``, split three ways, is a module that looks each name up in the three
(its ``__all__``, the names it had, makes ``from loopsim.config import *`` give them).
Plain Python: importing this module loads neither NumPy nor Numba.
"""
import importlib
import importlib.abc
import importlib.machinery
import sys
import warnings

#: Old dotted name: the new module(s) holding what it held.
MOVED = {
    "loopsim.summary": ("loopsim.outcome_statistics",),
    "loopsim.seeding": ("loopsim.seeds_auto_rule",),
    "loopsim.sweeps.stopping": ("loopsim.sweeps.signals",),
    "loopsim.io": ("loopsim.storage",),
    "loopsim.outputs": ("loopsim.render_defaults",),
    "loopsim.shapes.circle": ("loopsim.shapes.tilted_circle",),
    "loopsim.stability.circle": ("loopsim.stability.full_linear",),
    "loopsim.models.nonlocal_circle": ("loopsim.models.nonlocal_closed_form",),
    "loopsim.config": ("loopsim.defaults", "loopsim.jit", "loopsim.exit_codes"),
}

#: The public names of the split modules as they were (what ``from loopsim.config import *``
#: gave): a split module has no dictionary of its own to take them from.
OLD_PUBLIC_NAMES = {
    "loopsim.config": (
        "JIT", "ENVIRONMENT_ERRNOS", "DEFAULT_W", "DEFAULT_N", "DEFAULT_T_END", "DEFAULT_RTOL",
        "DEFAULT_ATOL", "DEFAULT_PERTURBATION", "DEFAULT_SEED", "DEFAULT_MAX_STEPS",
        "DEFAULT_CHUNK_SIZE", "DEFAULT_AUTO_CHUNK_SIZE", "DEFAULT_LENGTH_TOL",
        "DEFAULT_STEADY_INTERVAL", "DEFAULT_STEADY_TOL", "RESOLVED_LENGTH_ERROR",
        "RESOLVED_TAIL", "DEFORMATION_FLOOR", "AUTO_ORDERS", "DEFAULT_N_MAX", "MODEL_CHOICES",
        "MAX_SLENDERNESS", "DEFAULT_TAIL_TOL", "INITIAL_CONTENT_TOL", "SEED_TARGETS"),
}


def new_names(name):
    """The new module(s) of an old dotted module name, or None if it did not move."""
    for old, new in MOVED.items():
        if name == old:
            return new
        if name.startswith(old + ".") and len(new) == 1:
            return (new[0] + name[len(old):],)
    return None


def warn_moved(old, new):
    """The one DeprecationWarning of an old name (a module path or a function)."""
    warnings.warn(f"{old} is deprecated and will be removed in the next release: use {new}",
                  DeprecationWarning, stacklevel=3)


class MovedFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds the old module names and loads each as its new module (see the module's
    docstring)."""

    def find_spec(self, fullname, path=None, target=None):
        if new_names(fullname) is None:
            return None
        return importlib.machinery.ModuleSpec(fullname, self)

    def create_module(self, spec):
        return None  # the default module; exec_module replaces it

    def exec_module(self, module):
        name = module.__name__
        targets = new_names(name)
        warn_moved(name, " / ".join(targets))
        if len(targets) == 1:
            # the import system returns what sys.modules holds after exec_module
            sys.modules[name] = importlib.import_module(targets[0])
            return

        def look_up(attribute):  # a split module: the first new module holding the name
            for target in targets:
                found = importlib.import_module(target)
                if hasattr(found, attribute):
                    return getattr(found, attribute)
            raise AttributeError(f"module {name!r} has no attribute {attribute!r}")

        module.__getattr__ = look_up
        module.__all__ = list(OLD_PUBLIC_NAMES[name])  # ``import *`` looks each one up


def install():
    """Put :class:`MovedFinder` first on ``sys.meta_path`` (once)."""
    if not any(isinstance(finder, MovedFinder) for finder in sys.meta_path):
        sys.meta_path.insert(0, MovedFinder())
