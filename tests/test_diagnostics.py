"""Shape diagnostics against closed forms."""
import numpy as np
import pytest
from scipy import special

from loopsim import api, diagnostics as D, shapes


@pytest.mark.parametrize("theta_deg", [0.0, 12.5, 45.0, 90.0])
def test_circle_tilt_and_aspect(theta_deg):
    x = shapes.inclined_circle(5, np.radians(theta_deg))
    assert abs(D.tilt_deg(x) - theta_deg) < 1e-6
    assert abs(D.aspect_ratio(x) - 1.0) < 1e-12
    np.testing.assert_allclose(x[:, 0], 0.0)  # the centre of mass: the mean coefficient
    assert abs(D.relative_length_error(x)) < 1e-14


def test_ellipse_aspect_ratio_and_length():
    a, b = 1.3, 0.7
    x = np.zeros((3, 7))  # n = 3; ellipse (a cos s, b sin s, 0) in the horizontal plane
    x[0, 1], x[1, 4] = a, b
    assert abs(D.aspect_ratio(x) - (a / b) ** 2) < 1e-12  # ratio of variances a²/2 : b²/2
    assert abs(D.axis_ratio(x) - a / b) < 1e-12
    assert D.tilt_deg(x) < 1e-6
    exact = 4 * a * special.ellipe(1 - (b / a) ** 2)
    assert abs(D.relative_length_error(x) - (exact / (2 * np.pi) - 1)) < 1e-12


def test_settling_angle_of_the_rigid_circle_peaks_at_cos2theta_one_seventh():
    """tan γ = sin 2θ / (7 - cos 2θ), maximal atan(1/(4√3)) ≈ 8.21° at cos 2θ = 1/7."""
    thetas = np.radians(np.linspace(1, 89, 177))
    angles = []
    for theta in thetas:
        u, _ = api.evaluate_maps(shapes.inclined_circle(3, theta), 100.0)
        angles.append(D.settling_angle_deg(u[:, 0]))
        expected = np.degrees(np.arctan(np.sin(2 * theta) / (7 - np.cos(2 * theta))))
        assert abs(angles[-1] - expected) < 1e-10
    theta_star = 0.5 * np.arccos(1 / 7)
    u, _ = api.evaluate_maps(shapes.inclined_circle(3, theta_star), 100.0)
    assert abs(D.settling_angle_deg(u[:, 0]) - np.degrees(np.arctan(1 / (4 * np.sqrt(3))))) < 1e-10
    assert max(angles) <= D.settling_angle_deg(u[:, 0]) + 1e-12


@pytest.mark.parametrize("g0, theta_deg", [(0.0, 40.0), (30.0, 40.0), (200.0, 75.0)])
def test_tension_on_translating_circle_is_q_cos_s(g0, theta_deg):
    x = shapes.inclined_circle(6, np.radians(theta_deg))
    _, multiplier = api.evaluate_maps(x, g0)
    s, force = D.tension_profile(x, multiplier)
    q = api.stability_parameter(g0, theta_deg)
    np.testing.assert_allclose(force, q * np.cos(s), atol=1e-11 * (1 + q))
    t_max, t_min, s_max = D.tension_extremes(x, multiplier)
    assert abs(t_max - q) < 1e-10 * (1 + q) and abs(t_min + q) < 1e-10 * (1 + q)
    if q > 0:
        assert s_max == 0.0  # largest on the aft (upper) side, s = 0


def test_perturbation_definition():
    n, theta = 8, np.radians(35)
    d = shapes.perturbation_field(n, theta, seed=3)
    assert abs(D.rms_amplitude(d) - 1.0) < 1e-14
    # the displacement creates no length to first order: ΔL = O(ε²)
    x0 = shapes.inclined_circle(n, theta)
    dl = [D.curve_length(x0 + eps * d) - 2 * np.pi for eps in (1e-2, 1e-3)]
    assert abs(dl[1] / dl[0] - 1e-2) < 1e-4
    # a mode's draw does not depend on n
    d_small = shapes.perturbation_field(5, theta, seed=3)
    ratio = d[:, 2] / d_small[:, 2]
    np.testing.assert_allclose(ratio, ratio[np.argmax(np.abs(d[:, 2]))], rtol=1e-12)
    x = shapes.initial_shape(n, theta, 1e-2, seed=3)
    assert abs(D.relative_length_error(x)) < 1e-14
    np.testing.assert_array_equal(x, shapes.initial_shape(n, theta, 1e-2, seed=3))
    assert not np.array_equal(x, shapes.initial_shape(n, theta, 1e-2, seed=4))
