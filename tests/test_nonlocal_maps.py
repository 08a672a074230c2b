"""The compiled kernels of the nonlocal operator (``models.nonlocal_maps``) against its
plain-NumPy reference (``models.nonlocal_operator``), which is tested against closed forms
and adaptive quadrature in tests/test_nonlocal_operator.py."""
import numpy as np
import pytest

from loopsim import spectral
from loopsim.models import local_sbt, nonlocal_maps, nonlocal_operator as nl


def perturbed_loop(n):
    """A non-circular, non-planar loop parametrised by arc length (length 2π), order n."""
    raw = np.zeros((3, 7))
    raw[0, 1], raw[0, 3] = 1.05, 0.05
    raw[1, 4], raw[1, 6] = 0.95, 0.05
    raw[2, 6] = 0.1
    return nl.arclength_parametrised(raw, n)


def compiled_geometry(x, m):
    n = spectral.order_of(x.shape[1])
    position = np.ascontiguousarray(x @ spectral.synthesis_matrix(n, m).T)
    tangent = np.ascontiguousarray(x @ spectral.synthesis_matrix(n, m, 1).T)
    weight, direction = np.empty((m, m)), np.empty((3, m, m))
    nonlocal_maps.kernel_geometry(position, tangent, nl.singular_weights(m), weight, direction)
    return tangent, weight, direction


@pytest.mark.parametrize("n, m", [(12, 97), (16, 128), (20, 160)])
def test_kernel_geometry_matches_the_reference(n, m):
    x = perturbed_loop(n)
    tangent, weight, direction = compiled_geometry(x, m)
    ref_tangent, ref_weight, ref_direction = nl.kernel_geometry(x, m)
    np.testing.assert_allclose(tangent, ref_tangent, rtol=0, atol=1e-14)
    np.testing.assert_allclose(weight, ref_weight, rtol=1e-13,
                               atol=1e-13 * np.abs(ref_weight).max())
    np.testing.assert_allclose(direction, ref_direction, rtol=0, atol=1e-13)


@pytest.mark.parametrize("n, m", [(12, 97), (16, 128)])
def test_apply_kernel_matches_the_reference_operator(n, m, rng):
    x = perturbed_loop(n)
    force = rng.standard_normal((3, m))
    _, weight, direction = compiled_geometry(x, m)
    out = np.empty((3, m))
    nonlocal_maps.apply_kernel(weight, direction, force, out)
    reference = nl.K_operator(x, force, m, f_on_grid=True)
    assert np.abs(out - reference).max() < 1e-12 * np.abs(reference).max()


def test_apply_kernel_is_linear_and_sees_a_shift_along_the_grid(rng):
    """K[a f + b g] = a K[f] + b K[g]; a loop whose start moves by j grid points gives the
    same values, rolled by j (the closed-loop form has no preferred s = 0)."""
    n, m, j = 12, 100, 23
    x = perturbed_loop(n)
    f, g = rng.standard_normal((2, 3, m))
    _, weight, direction = compiled_geometry(x, m)
    kf, kg, kfg = (np.empty((3, m)) for _ in range(3))
    nonlocal_maps.apply_kernel(weight, direction, f, kf)
    nonlocal_maps.apply_kernel(weight, direction, g, kg)
    nonlocal_maps.apply_kernel(weight, direction, 2.0 * f - 0.5 * g, kfg)
    assert np.abs(kfg - (2.0 * kf - 0.5 * kg)).max() < 1e-12 * np.abs(kfg).max()
    k = np.arange(1, n + 1)
    s0 = 2 * np.pi * j / m
    moved = x.copy()
    moved[:, 1:n + 1] = x[:, 1:n + 1] * np.cos(k * s0) + x[:, n + 1:] * np.sin(k * s0)
    moved[:, n + 1:] = x[:, n + 1:] * np.cos(k * s0) - x[:, 1:n + 1] * np.sin(k * s0)
    _, weight_moved, direction_moved = compiled_geometry(moved, m)
    out = np.empty((3, m))
    nonlocal_maps.apply_kernel(weight_moved, direction_moved, np.roll(f, -j, axis=1), out)
    assert np.abs(out - np.roll(kf, -j, axis=1)).max() < 1e-11 * np.abs(kf).max()


@pytest.mark.parametrize("n, eps", [(12, 1e-3), (16, 1e-4)])
def test_nonlocal_loop_velocity_matches_its_numpy_twin(n, eps):
    """The compiled nonlocal velocity and tension on the local model's 4n + 1 grid against
    the dense NumPy reference (nonlocal_matrix on the same grid, numpy.linalg.lstsq)."""
    x = perturbed_loop(n)
    g0, w = 60.0, 10.0
    m = 4 * n + 1
    ops, ws = local_sbt.make_operators(n), local_sbt.make_workspace(n)
    u = np.empty_like(x)
    nonlocal_maps.nonlocal_loop_velocity(
        x, g0, w, nl.slenderness_constant(eps), nl.singular_weights(m), ops, ws,
        np.empty((3, m)), np.empty((m, m)), np.empty((3, m, m)), u)
    tension, reference = nl.loop_tension_and_velocity(
        x, g0, w, nl.nonlocal_matrix(x, eps, quadrature_points=m))
    assert np.abs(u - reference).max() < 1e-10 * np.abs(reference).max()
    assert np.abs(ws.tension - tension).max() < 1e-10 * np.abs(tension).max()


@pytest.mark.parametrize("n, eps", [(6, 1e-2), (6, 1e-3), (8, 1e-4)])
def test_nonlocal_jacobian_matches_differences_of_the_numpy_twin(n, eps):
    """nonlocal_maps.nonlocal_jacobian against Richardson-extrapolated central differences
    (h = 1e-4, 5e-5) of the dense NumPy reference (nonlocal_matrix and lstsq on the same
    4n + 1 grid; no compiled code).  Tolerance 1e-7 of max|J|: the differences' error was
    measured at 3e-11, 3e-10 and 1.2e-8 for these cases; leaving out the rule's change
    with the shape (δK[f], its W and e held fixed) is a 0.2 error."""
    x = perturbed_loop(n)
    g0, w, m = 60.0, 10.0, 4 * n + 1
    ops, ws = local_sbt.make_operators(n), local_sbt.make_workspace(n)
    jac = np.empty((x.size, x.size))
    nonlocal_maps.nonlocal_jacobian(
        x, g0, w, nl.slenderness_constant(eps), nl.singular_weights(m), ops, ws,
        np.empty((3, m)), np.empty((m, m)), np.empty((3, m, m)), jac)

    def velocity(y):
        return nl.nonlocal_loop_velocity(y.reshape(x.shape), g0, w, eps, quadrature_points=m,
                                         arclength_tol=None)[1].ravel()

    def central(h):
        steps = np.eye(x.size) * h
        return np.array([velocity(x.ravel() + e) - velocity(x.ravel() - e)
                         for e in steps]).T / (2 * h)

    reference = (4 * central(5e-5) - central(1e-4)) / 3
    scale = np.abs(reference).max()
    assert np.abs(jac - reference).max() < 1e-7 * scale
    k = x.shape[1]  # u depends on x through differences and derivatives only
    assert np.abs(jac[:, ::k]).max() < 1e-12 * scale
