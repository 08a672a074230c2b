"""The two ways loopsim compiles a function (Numba nopython mode, cached on disk).

``@entry``: a function Python calls in production (``integrate``, ``evaluate``, the batch
kernel's helpers): a plain ``numba.njit`` dispatcher with its Python entry wrapper.

``@kernel``: a function compiled code calls.  It is compiled *without* the Python
(``cpython``) and C (``cfunc``) entry wrappers Numba would build by default: for a
kernel taking a problem namedtuple (some 40 arrays) the wrappers are about a fifth of
its LLVM IR (``loop_velocity``: 2 180 of 9 317 lines); docs/studies/performance.md,
"Compilation", measures what leaving them out saves.
Jitted callers see the plain dispatcher (``_numba_type_``); a call from Python (tests,
interactive use) goes through a small uncached trampoline compiled on first use, so
calling a kernel from Python works, only its first call compiles more than an entry's.
"""
import functools

import numba

from . import _jitcache

# Numba's cache points at loopsim's (``_jitcache.configure``) before the first decorator:
# every kernel module imports this one first, so the cache is set up exactly when the
# first kernel is defined, and the command line, which defines none, loads neither Numba
# nor NumPy (``--help`` is fast).
_jitcache.configure()

#: The options of every compiled function.  No fastmath: results must be bit-reproducible
#: across thread counts.
JIT = dict(cache=True, nogil=True, error_model="numpy")

#: Options of every entry (:data:`JIT`: cached, no fastmath).
ENTRY_JIT = JIT
#: Options of every kernel: an entry's without the Python and C entry wrappers.
KERNEL_JIT = dict(JIT, no_cpython_wrapper=True, no_cfunc_wrapper=True)
#: Kernels this process has called from Python (each compiled a trampoline, uncached):
#: production code calls entries only (tests/test_jit.py checks a run, a sweep and the
#: stability analyses leave this empty).
TRAMPOLINES = []


def entry(function):
    """Compile ``function`` as an entry point: callable from Python and from jitted code."""
    return numba.njit(**ENTRY_JIT)(function)


class Kernel:
    """A wrapper-less dispatcher (``dispatcher``) that jitted code calls directly and
    Python through a trampoline; other attributes (``py_func``, ``signatures``,
    ``inspect_llvm``...) are the dispatcher's."""

    def __init__(self, function, inline=False):
        options = dict(KERNEL_JIT, inline="always") if inline else KERNEL_JIT
        self.dispatcher = numba.njit(**options)(function)
        self.inline = inline
        self._from_python = None
        functools.update_wrapper(self, function)

    @property
    def _numba_type_(self):
        return self.dispatcher._numba_type_

    def __call__(self, *args):
        if self._from_python is None:
            TRAMPOLINES.append(f"{self.__module__}.{self.__qualname__}")
            target = self.dispatcher
            if self.inline:  # a trampoline cannot take an inline kernel's code: call a copy
                target = numba.njit(**dict(KERNEL_JIT, cache=False))(self.py_func)
            self._from_python = numba.njit(nogil=True, error_model="numpy")(
                lambda *arguments: target(*arguments))
        return self._from_python(*args)

    def __getattr__(self, name):
        if name == "dispatcher":  # not yet set: during unpickling or __init__
            raise AttributeError(name)
        return getattr(self.dispatcher, name)

    def __reduce__(self):
        return _kernel_by_name, (self.__module__, self.__qualname__)

    def __repr__(self):
        return f"<loopsim kernel {self.__module__}.{self.__qualname__}>"


def _kernel_by_name(module, qualname):
    import importlib

    found = importlib.import_module(module)
    for part in qualname.split("."):
        found = getattr(found, part)
    return found


def kernel(function=None, *, inline=False):
    """Compile ``function`` as a kernel: called from jitted code (from Python only in tests
    and interactive use, through a trampoline).

    ``@kernel(inline=True)``: jitted callers take the function's code into their own
    (Numba's ``inline="always"``, before typing) instead of calling it, so it has no
    library of its own.  For a large kernel with one or two callers: every library that
    calls another links in and compiles again all the code below it, so a kernel between
    two big ones costs a compilation of everything under it (docs/studies/performance.md,
    "Compilation").  The arithmetic is the same operations either way (no fastmath), so
    results do not change."""
    if function is None:
        return lambda function: Kernel(function, inline=inline)
    return Kernel(function, inline=inline)
