"""The three maps and the tension solve against closed forms and a NumPy twin."""
import numpy as np
import pytest

import naive
from loopsim import api, models, shapes
from loopsim.linalg import least_squares_affine, least_squares_normal
from loopsim.models import local_sbt as physics


def _velocity(x, g0, w, ops, ws, u):
    """u = F(x) (3, K) through the compiled entry (``models.evaluate``)."""
    models.evaluate(physics.LoopProblem(g0, w, ops, ws), x.reshape(-1), u.reshape(-1),
                    np.empty(x.shape[1]))


def translating_circle(g0, theta):
    """Physics notes: T = -1 + q cos s, u0 = -[0, g0 sin2θ/6, g0 (7 - cos2θ)/6]."""
    q = g0 * np.sin(theta) / 3
    u0 = -np.array([0.0, g0 * np.sin(2 * theta) / 6, g0 * (7 - np.cos(2 * theta)) / 6])
    return q, u0


@pytest.mark.parametrize("n", [2, 6, 12])
@pytest.mark.parametrize("g0, theta_deg", [(0.0, 30.0), (10.0, 17.0), (150.0, 60.0), (400.0, 90.0), (80.0, 0.0)])
def test_translating_circle_closed_form(n, g0, theta_deg):
    theta = np.radians(theta_deg)
    q, u0 = translating_circle(g0, theta)
    u, multiplier = api.evaluate_maps(shapes.inclined_circle(n, theta), g0)
    expected_u = np.zeros_like(u)
    expected_u[:, 0] = u0
    expected_t = np.zeros(2 * n + 1)
    expected_t[0], expected_t[1] = -1.0, q
    scale = 1.0 + g0
    np.testing.assert_allclose(u, expected_u, atol=1e-13 * scale)
    np.testing.assert_allclose(multiplier, expected_t, atol=1e-13 * scale)


@pytest.mark.parametrize("n", [2, 5, 10, 16])
def test_velocity_and_tension_match_numpy_reference(n, rng):
    for _ in range(3):
        x = naive.random_shape(rng, n)
        g0, w = rng.uniform(0, 300), rng.uniform(0, 100)
        tension, u = naive.tension_and_velocity(x, g0, w)
        u_fast, tension_fast = api.evaluate_maps(x, g0, w)
        # measured: 2.6e-13 (tension) and 5.2e-14 (velocity), relative to 1 + max
        np.testing.assert_allclose(tension_fast, tension, atol=3e-12 * (1 + np.abs(tension).max()))
        np.testing.assert_allclose(u_fast, u, atol=1e-12 * (1 + np.abs(u).max()))


@pytest.mark.parametrize("n", [3, 8])
def test_each_map_matches_numpy_reference(n, rng):
    """Maps (1)-(3) column by column, for a given (not solved) tension."""
    x = naive.random_shape(rng, n)
    g0, w = 55.0, 7.0
    tension = rng.standard_normal(2 * n + 1)
    f_ref, u_ref, eps_ref = naive.maps(x, tension, g0, w)
    ops = physics.make_operators(n)
    ws = physics.make_workspace(n)
    physics.shape_on_grid(x, ops, ws)
    physics.force_map(g0, ops, ws)
    weights = np.append(tension, 1.0)  # columns: tension basis, then the affine part
    f_grid = (ws.force @ weights).T  # blocks are (M, 3, J)
    np.testing.assert_allclose(f_grid @ ops.F.T, f_ref, atol=1e-10 * np.abs(f_ref).max())
    physics.velocity_map(ws)
    np.testing.assert_allclose((ws.mobile @ weights).T @ ops.F.T, u_ref, atol=1e-10 * np.abs(u_ref).max())
    eps = physics.length_creation(x, tension, g0, w, ops, ws)
    # ε has order 2n: compare the interpolant of our M-point values with the fine-grid values
    eps_fine = naive.to_grid(naive.project(eps, 2 * n), 0, naive.FINE)
    np.testing.assert_allclose(eps_fine, eps_ref, atol=1e-9 * np.abs(eps_ref).max())


def test_least_squares_matches_numpy(rng):
    """linalg.least_squares_affine (LAPACK QR, column-major block) against numpy's lstsq."""
    a = rng.standard_normal((41, 11))
    b = rng.standard_normal(41)
    out = np.empty(10)
    block = np.ascontiguousarray(np.column_stack([a[:, :10], b]).T)  # row j = column j
    least_squares_affine(block, out, np.empty(10))
    np.testing.assert_allclose(out, np.linalg.lstsq(a[:, :10], -b, rcond=None)[0], atol=1e-12)


@pytest.mark.parametrize("n", [3, 8, 20])
def test_tension_operator_equals_the_column_blocks(n, rng):
    """The fast path's ε(T) = (B₂ + B B) S0 T + b (local_sbt.length_rate_operator) against
    the column blocks of compose_maps, column by column, on strongly deformed shapes."""
    for _ in range(2):
        x = naive.random_shape(rng, n)
        g0, w = rng.uniform(0, 300), rng.uniform(0, 100)
        ops = physics.make_operators(n)
        ws = physics.make_workspace(n)
        physics.compose_maps(x, g0, w, ops, ws)
        blocks = ws.length_rate.copy()
        physics.shape_on_grid(x, ops, ws)
        physics.length_rate_operator(g0, w, ops, ws)
        np.testing.assert_allclose(ws.length_rate, blocks, rtol=0, atol=1e-11 * np.abs(blocks).max())


@pytest.mark.parametrize("n", [4, 16])
def test_fast_velocity_equals_the_block_path(n, rng):
    x = naive.random_shape(rng, n)
    ops = physics.make_operators(n)
    ws = physics.make_workspace(n)
    u_fast, u_blocks = np.empty_like(x), np.empty_like(x)
    _velocity(x, 120.0, 10.0, ops, ws, u_fast)
    tension_fast = ws.tension.copy()
    physics.loop_velocity_blocks(x, 120.0, 10.0, ops, ws, u_blocks)
    np.testing.assert_allclose(u_fast, u_blocks, rtol=0, atol=1e-11 * np.abs(u_blocks).max())
    np.testing.assert_allclose(tension_fast, ws.tension, rtol=0,
                               atol=1e-11 * np.abs(ws.tension).max())


@pytest.mark.parametrize("n", [6, 32, 64])
def test_normal_equations_agree_with_qr_on_the_tension_map(n, rng):
    """The normal equations are safe only while cond(A D) stays small: A the map T -> ε
    of a strongly deformed, stretched loop, D = ops.column_scale.  Unscaled, cond(A) grows
    like n²; scaled it stays below 10⁴ (on run shapes up to n = 128: ≤ 23), and the
    tension agrees with LAPACK's QR to 1e-10."""
    x = shapes.initial_shape(n, np.radians(50.0), 0.0, 0)
    x[:, 2] += 0.3 * rng.standard_normal(3)  # a strong second mode
    x[:, n + 3] += 0.1 * rng.standard_normal(3)
    ops = physics.make_operators(n)
    ws = physics.make_workspace(n)
    physics.shape_on_grid(x, ops, ws)
    physics.length_rate_operator(150.0, 10.0, ops, ws)
    a = ws.length_rate[:-1].T
    assert np.linalg.cond(a) > n * n / 2
    assert np.linalg.cond(a * ops.column_scale) < 1e4
    k = 2 * n + 1
    normal, qr = np.empty(k), np.empty(k)
    assert least_squares_normal(ws.length_rate, ops.column_scale, normal, np.empty((k, k)),
                                np.empty(ops.m), np.empty(k)) == 0
    least_squares_affine(ws.length_rate, qr, np.empty(k))
    np.testing.assert_allclose(normal, qr, rtol=0, atol=1e-10 * np.abs(qr).max())


def test_normal_equations_match_numpy_and_refuse_indefinite(rng):
    """linalg.least_squares_normal against lstsq; a rank-deficient A returns info > 0."""
    a = rng.standard_normal((41, 10)) * (1 + np.arange(10) ** 2)
    b = rng.standard_normal(41)
    block = np.ascontiguousarray(np.column_stack([a, b]).T)
    out = np.empty(10)
    scale = 1.0 / (1.0 + np.arange(10) ** 2)
    assert least_squares_normal(block, scale, out, np.empty((10, 10)), np.empty(41),
                                np.empty(10)) == 0
    np.testing.assert_allclose(out, np.linalg.lstsq(a, -b, rcond=None)[0], rtol=1e-11)
    block[3] = 0.0  # a zero column
    assert least_squares_normal(block, scale, out, np.empty((10, 10)), np.empty(41),
                                np.empty(10)) > 0


def _rotate_z(x, phi):
    c, s = np.cos(phi), np.sin(phi)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ x


def _shift_arclength(c, sigma):
    """Coefficients of f(s + σ): each (a_k, b_k) pair rotates by kσ."""
    n = (c.shape[-1] - 1) // 2
    k = np.arange(1, n + 1)
    a, b = c[..., 1 : n + 1], c[..., n + 1 :]
    out = c.copy()
    out[..., 1 : n + 1] = a * np.cos(k * sigma) + b * np.sin(k * sigma)
    out[..., n + 1 :] = b * np.cos(k * sigma) - a * np.sin(k * sigma)
    return out


def test_equivariance_rotation_about_vertical_and_arclength_shift(rng):
    n = 6
    x = naive.random_shape(rng, n)
    u, tension = api.evaluate_maps(x, 90.0, 10.0)
    phi, sigma = 0.83, 1.9
    u_rot, t_rot = api.evaluate_maps(_rotate_z(x, phi), 90.0, 10.0)
    np.testing.assert_allclose(u_rot, _rotate_z(u, phi), atol=1e-11)
    np.testing.assert_allclose(t_rot, tension, atol=1e-11)
    u_sh, t_sh = api.evaluate_maps(_shift_arclength(x, sigma), 90.0, 10.0)
    np.testing.assert_allclose(u_sh, _shift_arclength(u, sigma), atol=1e-11)
    np.testing.assert_allclose(t_sh, _shift_arclength(tension, sigma), atol=1e-11)


def test_outputs_real_and_finite(rng):
    x = naive.random_shape(rng, 7)
    u, tension = api.evaluate_maps(x, 123.0)
    assert u.dtype == np.float64 and tension.dtype == np.float64
    assert np.all(np.isfinite(u)) and np.all(np.isfinite(tension))
    # the complex twin of the same fields has no imaginary part beyond round-off
    for field in (u, tension):
        z = naive.real_to_complex(field)
        n = (z.shape[-1] - 1) // 2
        np.testing.assert_allclose(z[..., :n], np.conj(z[..., n + 1 :][..., ::-1]))


@pytest.mark.parametrize("n", [3, 6, 12])
def test_exact_jacobian_against_finite_differences_and_numpy_twin(n, rng):
    """physics.loop_jacobian (njit) against central differences of loop_velocity (the
    NumPy-twin comparison is in test_twins.py)."""

    x = naive.random_shape(rng, n, amplitude=0.1)
    problem = physics.make_problem(n, 70.0, 10.0)
    jac = np.empty((x.size, x.size))
    physics.loop_jacobian(x, 70.0, 10.0, problem.ops, problem.ws, jac)
    scale = np.abs(jac).max()
    h = 1e-6
    up, um = np.empty_like(x), np.empty_like(x)
    fd = np.empty_like(jac)
    for col in range(x.size):
        step = np.zeros(x.size)
        step[col] = h
        _velocity(x + step.reshape(x.shape), 70.0, 10.0, problem.ops, problem.ws, up)
        _velocity(x - step.reshape(x.shape), 70.0, 10.0, problem.ops, problem.ws, um)
        fd[:, col] = ((up - um) / (2 * h)).ravel()
    assert np.abs(jac - fd).max() < 1e-6 * scale  # central differences: O(h²) + round-off
