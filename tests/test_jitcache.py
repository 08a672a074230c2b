"""The compiled-kernel cache is keyed by the source of every module a kernel can reach."""
import numba

from loopsim import batch
from loopsim import _jitcache  # noqa: the cache guard is tested as a unit


def test_cache_directory_follows_the_source(tmp_path):
    a, b = tmp_path / "a.py", tmp_path / "b.py"
    a.write_text("x = 1\n")
    b.write_text("y = 2\n")
    before = _jitcache.source_hash([str(a), str(b)])
    b.write_text("y = 3\n")  # an edit in a module other than the kernel's own
    assert _jitcache.source_hash([str(a), str(b)]) != before
    assert numba.config.CACHE_DIR == _jitcache.cache_dir()
    assert numba.config.CACHE_DIR.endswith("numba-" + _jitcache.source_hash())
    # subpackages count: an integrator or model edit must start a fresh cache, and so
    # must an edit to a module a kernel module imports (local_sbt imports spectral)
    sources = [p.replace("\\", "/") for p in _jitcache.kernel_sources()]
    for module in ("integrators/driver.py", "integrators/radau.py", "models/local_sbt.py",
                   "linalg.py", "batch.py", "spectral.py", "defaults.py", "jit.py"):
        assert any(p.endswith("loopsim/" + module) for p in sources), module
    # orchestration that no kernel imports does not invalidate the compiled kernels
    for module in ("cli/__init__.py", "cli/sweep.py", "ensemble.py", "sweeps/runner.py",
                   "figures/phase.py"):
        assert not any(p.endswith("loopsim/" + module) for p in sources), module


def test_kernel_sources_are_closed_under_imports():
    """Every package module imported by a module in the hashed set is in the set."""
    known = {_jitcache.module_name(p): p for p in _jitcache.package_sources()}
    hashed = {_jitcache.module_name(p) for p in _jitcache.kernel_sources()}
    for name in hashed:
        assert _jitcache.imported_modules(name, known[name], known) <= hashed, name
    assert batch.parallel_cases._cache._cache_path.startswith(numba.config.CACHE_DIR)
