import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(__file__))  # for tests/naive.py and tests/oracles.py


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)


@pytest.hookimpl(tryfirst=True)
def pytest_sessionfinish():
    """Let pytest's clean-up of earlier sessions' temporary roots (``shutil.rmtree``,
    recursive on Python 3.11: one frame per level) remove a tree 2 000 levels deep that an
    interrupted ``test_long_paths`` run left behind; with the default limit of 1 000 the
    whole session failed after every test had passed.  Raised only here, at the end, so the
    tests that make deep paths still fail if the code recurses."""
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))
