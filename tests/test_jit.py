"""Kernels (``loopsim.jit.kernel``) carry no Python entry wrapper: production code must
reach them through entries only, or each process would compile uncached trampolines."""
import json
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


DRIVER_SPECIALISATIONS = """
import collections, json, sys, warnings
import loopsim
from loopsim import integrators
warnings.simplefilter("ignore")
loopsim.simulate(60.0, 30.0, n=6, t_span=(0.0, 0.05), method="rkf45")
loopsim.simulate(60.0, 30.0, n=6, t_span=(0.0, 0.05), method="radau5", snapshots=3)
loopsim.simulate(150.0, 60.0, t_span=(0.0, 0.05))
loopsim.sweep([20.0], [30.0], sys.argv[1], n=6, t_end=0.05, quiet=True, threads=1)
pairs = collections.Counter((str(s[0]), str(s[1])[:20]) for s in integrators.integrate.signatures)
print(json.dumps([sorted(pairs.values()), [str(s[5]) for s in integrators.integrate.signatures]]))
"""


def test_a_run_its_twin_and_a_sweep_compile_one_driver_per_method(tmp_path):
    """Every run samples its late motion through dense output, so its twin, a sweep and
    a run asking for snapshots all call the driver with output arrays (empty for the
    twin): one specialisation of ``integrate`` per method and model, not two (b1d79af's
    twin passed None and compiled the driver, all the model's code with it, a second
    time: issue 55)."""
    result = subprocess.run([sys.executable, "-c", DRIVER_SPECIALISATIONS,
                             str(tmp_path / "sweep")],
                            capture_output=True, text=True, timeout=900)
    assert result.returncode == 0, result.stderr[-2000:]
    counts, t_out_types = json.loads(result.stdout.strip().splitlines()[-1])
    assert counts == [1, 1], (counts, t_out_types)
    assert "none" not in " ".join(t_out_types)


def test_a_kernel_called_from_python_runs_and_is_recorded():
    source = np.arange(4.0)
    target = np.zeros(4)
    copy_into(target, source)
    np.testing.assert_array_equal(target, source)
    assert "loopsim.linalg.copy_into" in jit.TRAMPOLINES
    assert copy_into.py_func.__name__ == "copy_into"
