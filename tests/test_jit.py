"""Kernels (``loopsim.jit.kernel``) carry no Python entry wrapper: production code must
reach them through entries only, or each process would compile uncached trampolines."""
import subprocess
import sys

import numpy as np

from loopsim import jit
from loopsim.linalg import copy_into

PRODUCTION_CALLS = """
import sys
from loopsim import api, jit
from loopsim.stability import branch, circle
from loopsim.sweeps.orchestrate import sweep
api.simulate(60.0, 30.0, n=6, t_span=(0.0, 0.05), method="rkf45")
api.simulate(60.0, 30.0, n=6, t_span=(0.0, 0.05), method="radau5")
api.simulate(150.0, 60.0, n="auto", t_span=(0.0, 0.05))
sweep([20.0], [30.0], sys.argv[1], n=6, t_end=0.05, quiet=True, threads=1)
circle.critical_q(4, "in-plane", q_step=2.0)
shapes = branch.continue_branch(4, 4.0, max_points=3)
print(repr(jit.TRAMPOLINES))
"""


def test_production_paths_call_no_kernel_from_python(tmp_path):
    result = subprocess.run([sys.executable, "-c", PRODUCTION_CALLS, str(tmp_path / "sweep")],
                            capture_output=True, text=True, timeout=900)
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.strip().splitlines()[-1] == "[]"


def test_a_kernel_called_from_python_runs_and_is_recorded():
    source = np.arange(4.0)
    target = np.zeros(4)
    copy_into(target, source)
    np.testing.assert_array_equal(target, source)
    assert "loopsim.linalg.copy_into" in jit.TRAMPOLINES
    assert copy_into.py_func.__name__ == "copy_into"
