"""The translating circle under nonlocal slender-body theory: still a steady solution,
its Jacobian, and its linear stability against ε (``stability.full_linear`` with
``model=``; docs/nonlocal.md, "The translating circle")."""
import json
import math

import numpy as np
import pytest

import oracles

from loopsim import api, models, shapes
from loopsim.cli import main
from loopsim.models import nonlocal_closed_form as closed
from loopsim.stability import full_linear

LOCAL_IN_PLANE, LOCAL_OUT_OF_PLANE = 8.900090534313328, 10.649315608483457


@pytest.mark.parametrize("eps", [1e-2, 1e-3, 1e-4])
@pytest.mark.parametrize("theta0", [15.0, 45.0, 80.0])
def test_the_tilted_circle_translates_rigidly_at_johnson_wu_mobilities(eps, theta0):
    """The circle at any tilt is a steady solution in the nonlocal model too: its velocity
    is the uniform u = −g0 [M_b cos θ0 e_n + M_e sin θ0 b] (Johnson & Wu's mobilities, b
    the in-plane direction of steepest descent), no rotation, no shape change (1e-11)."""
    g0, th = 7.0, math.radians(theta0)
    broadside, edgewise = closed.johnson_wu_ring(eps)
    u, _ = api.evaluate_maps(shapes.inclined_circle(6, th), g0, model="nonlocal",
                             slenderness=eps)
    normal = np.array([0.0, -math.sin(th), math.cos(th)])
    steepest = np.array([0.0, math.cos(th), math.sin(th)])
    expected = -g0 * (broadside * math.cos(th) * normal + edgewise * math.sin(th) * steepest)
    assert np.abs(u[:, 0] - expected).max() < 1e-11 * g0
    assert np.abs(u[:, 1:]).max() < 1e-11 * g0  # every non-constant mode of u is zero


def test_difference_jacobian_matches_the_exact_local_one(rng):
    """oracles.difference_jacobian (central differences) against the exact local Jacobian
    at a deformed, tilted loop: 1e-7 relative to its largest entry."""
    x = shapes.inclined_circle(6, 0.7) + 0.05 * rng.standard_normal((3, 13))
    exact = full_linear.rhs_jacobian(x, 40.0)
    problem = models.make_problem(models.LOCAL, 6, 40.0, 10.0)
    approx = oracles.difference_jacobian(problem, x.ravel())
    assert np.abs(approx - exact).max() < 1e-7 * np.abs(exact).max()


@pytest.mark.parametrize("eps", [1e-2, 1e-3])
def test_exact_nonlocal_jacobian_matches_central_differences_of_the_compiled_rhs(eps, rng):
    """The nonlocal model's exact Jacobian (radau5's and the stability's) against central
    differences of its own compiled right-hand side at a deformed, tilted loop off arc-length
    parametrisation: 1e-7 of the largest entry, as for the local model (the
    twin-independent check is tests/test_nonlocal_maps.py)."""
    model = models.choose("nonlocal", eps)
    x = shapes.inclined_circle(6, 0.7) + 0.05 * rng.standard_normal((3, 13))
    problem = models.make_problem(model, 6, 40.0, 10.0)
    exact = full_linear.rhs_jacobian(x, 40.0, model=model)
    central = oracles.difference_jacobian(problem, x.ravel())
    assert np.abs(exact - central).max() < 1e-7 * np.abs(central).max()


@pytest.mark.parametrize("eps, in_plane, out_of_plane", [
    (1e-2, 14.787116, 14.092226), (1e-3, 11.392069, 12.295640), (1e-4, 10.471107, 11.725268)])
def test_nonlocal_thresholds_converge_in_n_and_the_sectors_decouple(eps, in_plane,
                                                                    out_of_plane):
    """At θ0 = 90° the plane is a mirror symmetry: in- and out-of-plane perturbations
    decouple exactly (1e-12).  The thresholds at n = 8 and 10 agree to 1e-6 (the values
    are docs/nonlocal.md's table, to its six decimals)."""
    model = models.choose("nonlocal", eps)
    lin = full_linear.linearise_circle(10, 30.0, 90.0, model=model)
    assert lin.diagnostics["in_to_out_coupling"] < 1e-12
    assert lin.diagnostics["out_to_in_coupling"] < 1e-12
    assert lin.diagnostics["neutral_leak"] < 1e-10
    for sector, expected in (("in-plane", in_plane), ("out-of-plane", out_of_plane)):
        q8, q10 = (full_linear.critical_q(n, sector, model=model) for n in (8, 10))
        assert abs(q8 - q10) < 1e-6 and abs(q10 - expected) < 1e-6


def test_thresholds_tend_to_the_local_ones_like_one_over_c():
    """ε → 0: c (q_nonlocal − q_local) is a straight line in 1/c (c = −2 log ε), so the
    thresholds reach the local model's 8.9001 and 10.6493 at the rate 1/c; the two
    slopes of three points agree to 10 %."""
    eps = (1e-9, 1e-12, 1e-15)
    c = np.array([-2.0 * math.log(e) for e in eps])
    for sector, local in (("in-plane", LOCAL_IN_PLANE), ("out-of-plane", LOCAL_OUT_OF_PLANE)):
        q = np.array([full_linear.critical_q(8, sector, model=models.choose("nonlocal", e))
                      for e in eps])
        scaled = c * (q - local)
        assert np.all(q > local) and np.all(np.diff(q) < 0)
        slopes = np.diff(scaled) / np.diff(1.0 / c)
        assert abs(slopes[0] - slopes[1]) < 0.1 * abs(slopes[1])
        assert 10.0 < scaled[-1] - slopes[1] / c[-1] < 30.0  # the 1/c coefficient


def test_stability_command_with_the_nonlocal_model(capsys):
    """``loopsim stability --model nonlocal`` prints the API's thresholds and records the
    model; a tilt other than 90° and --paper with a model are refused in one line."""
    assert main(["stability", "--n", "8", "--model", "nonlocal", "--slenderness", "1e-3",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    model = models.choose("nonlocal", 1e-3)
    assert (out["model"], out["slenderness"]) == ("nonlocal", 1e-3)
    assert out["q_crit_in_plane"] == full_linear.critical_q(8, "in-plane", model=model)
    for argv in (["--theta0", "30"], ["--paper"]):
        assert main(["stability", "--model", "nonlocal", "--slenderness", "1e-3"] + argv) == 2
        assert len(capsys.readouterr().err.strip().splitlines()) == 1
