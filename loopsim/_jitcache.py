"""Where compiled kernels are cached: one directory per version of the source.

Numba's on-disk cache checks only the timestamp of the file that defines a
function. A kernel that inlines code from another module (the batch kernel
calls the integrators, the integrators call the models) would silently keep
the old code after an edit elsewhere. So the cache lives in a directory named
after a hash of every ``.py`` file of the package, subpackages included: any
change to the source starts a fresh cache. This module must be imported before any ``@njit(cache=True)``
decorator runs (``loopsim/__init__.py`` does so first). A user-set
NUMBA_CACHE_DIR is respected as the parent directory.
"""
import hashlib
import os

import numba

PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))


def source_hash(paths=None):
    """SHA-256 (first 16 hex digits) over the relative names and bytes of the package's
    sources (every ``*.py`` below the package directory)."""
    if paths is None:
        paths = package_sources()
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


def cache_dir():
    parent = os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
        "loopsim")
    return os.path.join(parent, f"numba-{source_hash()}")


def configure():
    """Point Numba's cache at :func:`cache_dir` (before kernels are decorated)."""
    numba.config.CACHE_DIR = cache_dir()
