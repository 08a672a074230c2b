"""Where compiled kernels are cached: one directory per version of the kernels' source.

Numba's on-disk cache checks only the timestamp of the file that defines a
function. A kernel that inlines code from another module (the batch kernel
calls the integrators, the integrators call the models) would silently keep
the old code after an edit elsewhere. So the cache lives in a directory named
after a hash of every module a kernel can reach: the modules that define
kernels (a Numba decorator or ``numba.extending``), and, read with
``ast``, everything they import from the package, transitively (a kernel can
only see globals of modules its own module imports).  Any change there starts
a fresh cache; an edit to the command line or the figures does not.  :func:`configure`
must run before any ``@njit(cache=True)`` decorator: ``loopsim.jit``, which every kernel
module imports first, runs it. A user-set NUMBA_CACHE_DIR is
respected as the parent directory.
"""
import ast
import hashlib
import os
import re

import numba
import numba.core.event

PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
PACKAGE = os.path.basename(PACKAGE_DIR)
#: Code (not prose) that marks a module as defining compiled code: a Numba decorator,
#: loopsim's (``jit.kernel``, ``jit.entry``, ``dispatch.implements``) or the extension API.
KERNEL_CODE = re.compile(
    r"^\s*(@numba\.|@njit|@overload|@kernel|@entry|@implements|from numba\.extending import)",
    re.M)


def source_hash(paths=None):
    """SHA-256 (first 16 hex digits) over the relative names and bytes of the kernels'
    sources (:func:`kernel_sources`)."""
    if paths is None:
        paths = kernel_sources()
    digest = hashlib.sha256()
    for path in paths:
        digest.update(os.path.relpath(path, PACKAGE_DIR).replace(os.sep, "/").encode())
        with open(path, "rb") as handle:
            digest.update(handle.read())
    return digest.hexdigest()[:16]


def package_sources():
    """Every ``.py`` file below the package directory, sorted."""
    found = []
    for root, dirs, files in os.walk(PACKAGE_DIR):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        found.extend(os.path.join(root, name) for name in files if name.endswith(".py"))
    return sorted(found)


def module_name(path):
    parts = os.path.relpath(path, os.path.dirname(PACKAGE_DIR))[:-3].split(os.sep)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_modules(name, path, known):
    """Package modules imported anywhere in ``path`` (module ``name``): P for
    ``from P import x`` (where x is defined) and P.x when that is a module; a.b for
    ``import a.b``.  Parent packages run on import but lend the importer no names, so
    they are not counted."""
    with open(path, "rb") as handle:
        tree = ast.parse(handle.read(), path)
    here = name.split(".") if path.endswith("__init__.py") else name.split(".")[:-1]
    targets = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets.extend(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = here[: len(here) - node.level + 1] if node.level else []
            base = ".".join(base + ([node.module] if node.module else []))
            targets.extend(f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else base
                           for alias in node.names)
    return set(targets) & set(known)


def kernel_sources():
    """The modules that define kernels and every package module they import,
    transitively: the sources compiled code can depend on (sorted paths)."""
    known = {module_name(p): p for p in package_sources()}
    pending = []
    for name, path in known.items():
        with open(path, encoding="utf-8") as handle:
            text = handle.read()
        if KERNEL_CODE.search(text):
            pending.append(name)
    reached = set()
    while pending:
        name = pending.pop()
        if name in reached:
            continue
        reached.add(name)
        pending.extend(imported_modules(name, known[name], known) - reached)
    return sorted(known[name] for name in reached)


def cache_dir():
    parent = os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
        "loopsim")
    return os.path.join(parent, f"numba-{source_hash()}")


def configure():
    """Point Numba's cache at :func:`cache_dir` (before kernels are decorated) and start
    the compile clock; once per process (importing ``loopsim.jit`` calls it)."""
    if COMPILE_CLOCK.registered:
        return
    numba.config.CACHE_DIR = cache_dir()
    numba.core.event.register("numba:compile", COMPILE_CLOCK)
    COMPILE_CLOCK.registered = True


# ---- compilation made visible and kept apart from the work ----------------------------
class CompileClock(numba.core.event.Listener):
    """Numba's compile events (cache misses only: a kernel loaded from the cache sends
    none): the first one prints :data:`NOTICE` on stderr once per process; ``seconds``
    adds up the time spent in outermost compilations, so callers can report their work
    without it (``seconds`` before and after, subtracted)."""

    NOTICE = ("loopsim: compiling numerical kernels for first use (cached for later runs; "
              "most of a minute on 2 idle cores, longer on busy ones) ...")

    def __init__(self):
        self.seconds = 0.0
        self.announced = False
        self.registered = False
        self._depth = 0
        self._started = 0.0

    def on_start(self, event):
        import sys
        import time

        if self._depth == 0:
            if not self.announced and not os.environ.get("LOOPSIM_QUIET_COMPILE"):
                print(self.NOTICE, file=sys.stderr, flush=True)
            self.announced = True
            self._started = time.perf_counter()
        self._depth += 1

    def on_end(self, event):
        import time

        self._depth -= 1
        if self._depth == 0:
            self.seconds += time.perf_counter() - self._started


#: The process's compile clock (registered by :func:`configure`).
COMPILE_CLOCK = CompileClock()


def compile_seconds():
    """Seconds this process has spent compiling kernels so far (cache misses)."""
    return COMPILE_CLOCK.seconds
