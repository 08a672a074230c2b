"""The nonlocal loop model (``models.nonlocal_sbt``) in the adaptive driver: closed forms
and agreement between integrators (its velocity kernel is tested against its NumPy twin
in tests/test_nonlocal_maps.py)."""
import numpy as np
import pytest

from loopsim import integrators, shapes
from loopsim.models import nonlocal_closed_form as closed
from loopsim.models import nonlocal_operator as nl
from loopsim.models import nonlocal_sbt


def run(method, problem, x0, t_end, rtol=1e-10, atol=1e-12):
    options = integrators.step_options(rtol, atol)
    status, t, y, counts, _ = integrators.integrate(
        method, problem, x0.reshape(-1).copy(), 0.0, t_end, None, options, None)
    assert status == integrators.OK and t == t_end
    return y.reshape(x0.shape), counts


@pytest.mark.parametrize("eps", [1e-2, 1e-3])
def test_horizontal_ring_sediments_at_johnson_wu_broadside_speed(eps):
    """A horizontal ring stays a circle and falls at −g0 U_b (Johnson & Wu 1979) all the
    way: z(t) = −g0 U_b t, every other coefficient unchanged."""
    n, g0, t_end = 4, 3.0, 0.5
    x0 = np.zeros((3, 2 * n + 1))
    x0[0, 1] = 1.0
    x0[1, n + 1] = 1.0
    x, _ = run(integrators.RKF45, nonlocal_sbt.make_problem(n, g0, 10.0, eps), x0, t_end)
    expected = x0.copy()
    expected[2, 0] = -g0 * closed.johnson_wu_ring(eps)[0] * t_end
    assert np.abs(x - expected).max() < 1e-9


def test_radau_with_the_exact_jacobian_follows_rkf45():
    """A tilted, perturbed loop: radau5 (exact Jacobian) and rkf45 end at the
    same shape to their tolerances."""
    n, g0, eps, t_end = 6, 30.0, 1e-3, 0.2
    x0 = shapes.initial_shape(n, np.radians(30.0), 1e-2, 0)
    problem = nonlocal_sbt.make_problem(n, g0, 10.0, eps)
    explicit, _ = run(integrators.RKF45, problem, x0, t_end, rtol=1e-10)
    implicit, counts = run(integrators.RADAU5, problem, x0, t_end, rtol=1e-8)
    assert counts[3] > 0  # the Jacobian was used
    assert np.abs(implicit - explicit).max() < 1e-6 * np.abs(explicit).max()
    assert np.abs(implicit - x0).max() > 1e-3  # and the loop moved
