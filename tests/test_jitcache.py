"""The compiled-kernel cache is keyed by the whole package source."""
import numba

import loopsim
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
    # subpackages count: an integrator or model edit must start a fresh cache
    sources = _jitcache.package_sources()
    assert any(p.endswith("integrators/driver.py") for p in sources)
    assert any(p.endswith("models/local_sbt.py") for p in sources)
    assert loopsim.batch.parallel_cases._cache._cache_path.startswith(numba.config.CACHE_DIR)
