import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(__file__))  # for tests/naive.py and tests/oracles.py


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)
