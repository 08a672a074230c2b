"""The nonlocal slender-body operator (loopsim.models.nonlocal_operator) against closed forms.

* the constants: ∫(1/(2|sin σ/2|) - 1/|σ|) = 2 log(4/π) and the product-integration
  weights, against scipy.integrate.quad;
* the circle's mode-by-mode action of K (digamma closed forms), itself checked against
  quad of the kernel, and the operator against it for k = 0..6 (and at the high-mode
  sign change);
* the matrix against the function, invariance under s -> s + s0, the local limit;
* the rigid ring against Johnson & Wu (1979) at ε = 1e-2, 1e-3, 1e-4 (broadside,
  edgewise, tilted), and the local model's rigid circle against the paper's u0;
* spectral convergence in the number of quadrature points and in the truncation n.

Tolerances: the Johnson & Wu formulas are exact solutions of the same SBT integral
equation on the circle (modes k ≤ 1, 2x2 algebra), so the operator must reproduce them
to rounding (1e-11), far inside SBT's own O(ε² log ε) error against Stokes flow.
"""
import math
import warnings

import numpy as np
import pytest
from scipy import integrate

import naive
from loopsim import spectral
from loopsim.models import nonlocal_closed_form as closed
from loopsim.models import nonlocal_operator as nl
from loopsim.shapes import inclined_circle

EPSILONS = (1e-2, 1e-3, 1e-4)


# ---- shapes and helpers ----------------------------------------------------------------

def circle(n=1):
    """x = (cos s, sin s, 0) at order n."""
    x = np.zeros((3, spectral.n_coeffs(n)))
    x[0, 1] = 1.0
    x[1, n + 1] = 1.0
    return x


def random_rotation(rng):
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def shifted(c, s0):
    """Coefficients of c(s + s0)."""
    c = np.array(c, dtype=float)
    n = spectral.order_of(c.shape[-1])
    k = np.arange(1, n + 1)
    a, b = c[..., 1:n + 1].copy(), c[..., n + 1:].copy()
    c[..., 1:n + 1] = a * np.cos(k * s0) + b * np.sin(k * s0)
    c[..., n + 1:] = b * np.cos(k * s0) - a * np.sin(k * s0)
    return c


def perturbed_loop(n):
    """The circle with an in-plane radial mode 2 and an out-of-plane mode 3, both of
    amplitude 0.1 (r = 1 + 0.1 cos 2α, z = 0.1 sin 3α), parametrised by arc length and
    scaled to length 2π, truncated at order n."""
    raw = np.zeros((3, 7))
    raw[0, 1], raw[0, 3] = 1.05, 0.05  # (1 + 0.1 cos 2α) cos α
    raw[1, 4], raw[1, 6] = 0.95, 0.05  # (1 + 0.1 cos 2α) sin α
    raw[2, 6] = 0.1
    return nl.arclength_parametrised(raw, n)


def elastic_force(x, g0=2.0):
    """f = -x'''' + (T x')' - g0 e_z with T = 1 + 0.5 cos s, order n (alias-free)."""
    n = spectral.order_of(x.shape[1])
    d = spectral.derivative_matrix(n)
    m = 4 * n + 1
    tension = 1.0 + 0.5 * np.cos(spectral.grid(m))
    tangent = (x @ d.T) @ spectral.synthesis_matrix(n, m).T
    flux = spectral.resize(spectral.fit(tension * tangent), n)
    f = -(x @ np.linalg.matrix_power(d, 4).T) + flux @ d.T
    f[2, 0] -= g0
    return f


def frame(s):
    """(t, n, b) of the unit circle on the points s: tangent, outward radial, e_z."""
    zero, one = np.zeros_like(s), np.ones_like(s)
    return (np.array([-np.sin(s), np.cos(s), zero]), np.array([np.cos(s), np.sin(s), zero]),
            np.array([zero, zero, one]))


def quad(fun, a, b):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", integrate.IntegrationWarning)
        return integrate.quad(fun, a, b, epsabs=1e-14, epsrel=1e-14, limit=400)[0]


# ---- constants and weights -----------------------------------------------------------------

def test_chord_versus_arc_constant():
    """∫_{-π}^{π} [1/(2|sin(σ/2)|) - 1/|σ|] dσ = 2 log(4/π): the periodic subtraction's
    local constant (docs/nonlocal.md)."""
    value = 2.0 * quad(lambda s: 1.0 / (2.0 * math.sin(s / 2.0)) - 1.0 / s, 0.0, math.pi)
    assert abs(value - 2.0 * nl.LOG_4_OVER_PI) < 1e-12


def test_slenderness_constant():
    assert nl.slenderness_constant(1e-3) == pytest.approx(6.0 * math.log(10.0), rel=1e-15)
    for bad in (0.0, 1.0, -1e-3, 2.0):
        with pytest.raises(ValueError):
            nl.slenderness_constant(bad)


@pytest.mark.parametrize("m", [31, 32])
def test_singular_weights_integrate_trigonometric_polynomials_exactly(m):
    q = nl.singular_weights(m)
    s = spectral.grid(m)
    k = np.arange(1, m // 2 + 1)  # degrees < m/2, and the Nyquist cos(mσ/2) for even m
    h = closed.odd_harmonic_digamma(k)
    assert np.allclose(nl.odd_harmonic(k), h, rtol=0, atol=1e-13)
    assert abs(q.sum()) < 1e-12
    for kk, hk in zip(k, h):
        assert abs(q @ (np.cos(kk * s) - 1.0) + 4.0 * hk) < 1e-12
        assert abs(q @ np.sin(kk * s)) < 1e-12


def test_singular_weights_converge_spectrally_on_an_analytic_function():
    """A(σ) = exp(cos(σ + 0.3)), neither even nor a polynomial: quad splits at σ = 0."""
    def a(s):
        return np.exp(np.cos(s + 0.3))

    def integrand(s):
        return (a(s) - a(0.0)) / (2.0 * abs(math.sin(s / 2.0)))

    exact = quad(integrand, -math.pi, 0.0) + quad(integrand, 0.0, math.pi)
    errors = {m: abs(nl.singular_weights(m) @ a(spectral.grid(m)) - exact) for m in (8, 16, 32)}
    assert errors[8] > 1e-7  # not exact: the test can see the convergence
    assert errors[16] < 1e-3 * errors[8]
    assert errors[32] < 1e-13


# ---- the circle's modes ----------------------------------------------------------------------

def kernel_integral_on_circle(k, component):
    """Column ``component`` of the mode matrix C(k), by quad of the kernel at s = 0:
    K[e^{iks} v](0) projected on (t, n, b)(0), v the frame vector ``component``."""
    t0, n0, b0 = (v[:, 0] for v in frame(np.zeros(1)))
    x0 = np.array([1.0, 0.0, 0.0])
    local = (np.eye(3) + np.outer(t0, t0)) @ (t0, n0, b0)[component]

    def integrand(s, part, row):
        r = x0 - np.array([math.cos(s), math.sin(s), 0.0])
        d = np.linalg.norm(r)
        v = np.array([w[:, 0] for w in frame(np.array([s]))])[component]
        phase = (math.cos(k * s), math.sin(k * s))[part]
        value = ((v + r * (r @ v) / d**2) / d) * phase - local * (part == 0) / abs(s)
        return value @ (t0, n0, b0)[row]

    column = np.zeros(3, dtype=complex)
    for row in range(3):
        for part in (0, 1):
            f = lambda s: integrand(s, part, row)  # noqa: E731
            value = quad(f, -math.pi, 0.0) + quad(f, 0.0, math.pi)
            column[row] += value * (1.0 if part == 0 else 1j)
    return column


@pytest.mark.parametrize("k", range(7))
def test_circle_closed_forms_match_quadrature_of_the_kernel(k):
    c = closed.circle_K_mode_matrix(k)
    assert np.allclose(c, c.conj().T, atol=1e-15)  # K is symmetric
    for component in range(3):
        assert np.allclose(kernel_integral_on_circle(k, component), c[:, component],
                           rtol=0, atol=1e-10), (k, component)


def circle_mode_velocity(matrix, k, alpha, component, s):
    """Re[e^{iks} α (C e_component) · (t, n, b)] on the points s."""
    phase = alpha * np.exp(1j * k * s)
    return sum(np.real(matrix[row, component] * phase) * vec for row, vec in enumerate(frame(s)))


@pytest.mark.parametrize("k", range(7))
def test_operator_on_circle_modes_matches_closed_forms(k, rng):
    """K and (1/c)(Λ + K) on cos ks and sin ks times t, n, b, on the circle and on the
    same circle rotated and moved (the closed forms live in the circle's own frame)."""
    m = 32
    s = spectral.grid(m)
    rotation = random_rotation(rng)
    moved = rotation @ circle()
    moved[:, 0] += rng.standard_normal(3)
    eps = 1e-3
    kmat, umat = closed.circle_K_mode_matrix(k), closed.circle_velocity_mode_matrix(k, eps)
    for alpha in (1.0, -1j):  # cos ks, sin ks
        for component, vec in enumerate(frame(s)):
            f = np.real(alpha * np.exp(1j * k * s)) * vec
            expected = circle_mode_velocity(kmat, k, alpha, component, s)
            assert np.abs(nl.K_operator(circle(), f, f_on_grid=True) - expected).max() < 1e-12
            got = nl.K_operator(moved, rotation @ f, f_on_grid=True)
            assert np.abs(got - rotation @ expected).max() < 1e-12
            expected = circle_mode_velocity(umat, k, alpha, component, s)
            got = nl.nonlocal_velocity(circle(), f, eps, f_on_grid=True)
            assert np.abs(got - expected).max() < 1e-13


def test_high_modes_lose_positivity_where_the_closed_form_says():
    """ε = 1e-2: the (t, n) block of (1/c)(Λ + K) is positive up to k = 10, not at 11."""
    eps, m = 1e-2, 64
    s = spectral.grid(m)
    t, n, _ = frame(s)
    for k, positive in ((10, True), (11, False)):
        block = np.zeros((2, 2), dtype=complex)  # numerical, from the operator
        for column, vec in enumerate((t, n)):
            for alpha in (1.0, -1j):
                u = nl.nonlocal_velocity(circle(), np.real(alpha * np.exp(1j * k * s)) * vec,
                                         eps, f_on_grid=True)
                for row, w in enumerate((t, n)):  # the e^{iks} amplitude of u·w
                    amp = 2.0 * np.mean(np.sum(u * w, axis=0) * np.exp(-1j * k * s))
                    block[row, column] += amp / 2.0 if alpha == 1.0 else 1j * amp / 2.0
        exact = closed.circle_velocity_mode_matrix(k, eps)[:2, :2]
        assert np.allclose(block, exact, atol=1e-12)
        assert (np.linalg.eigvalsh(exact).min() > 0) == positive



@pytest.mark.parametrize("eps", [1e-1, 3e-2, 1e-2, 1e-3])
def test_first_nonpositive_mode_is_the_first_of_a_linear_scan(eps):
    """The bisection's answer equals a scan k = 1, 2, ... of the closed-form spectrum."""
    k = 1
    while np.linalg.eigvalsh(closed.circle_velocity_mode_matrix(k, eps)).min() > 0:
        k += 1
    assert closed.first_nonpositive_mode(eps) == k
    assert k == {1e-1: 1, 3e-2: 4, 1e-2: 11, 1e-3: 109}[eps]  # docs/nonlocal.md's table


# ---- matrix, shift, local limit --------------------------------------------------------------

def test_matrix_matches_function(rng):
    x = perturbed_loop(16)
    f = rng.standard_normal((3, 21)) / (1.0 + spectral.wavenumbers(10)) ** 2
    m, eps = 96, 1e-3
    a = nl.nonlocal_matrix(x, eps, n=10, quadrature_points=m)
    assert a.shape == (63, 63)
    u = nl.nonlocal_velocity(x, f, eps, quadrature_points=m, order=10)
    assert np.abs(a @ f.reshape(-1) - u.reshape(-1)).max() < 1e-12
    fg = f @ spectral.synthesis_matrix(10, m).T
    k_grid = nl.K_grid_matrix(x, m) @ fg.reshape(-1)
    assert np.abs(k_grid - nl.K_operator(x, fg, f_on_grid=True).reshape(-1)).max() < 1e-12
    local = nl.local_matrix(x, n=10, quadrature_points=m) @ f.reshape(-1)
    assert np.abs(local - nl.local_velocity(x, f, m, order=10).reshape(-1)).max() < 1e-13


def test_velocity_is_independent_of_where_s_starts(rng):
    x = perturbed_loop(12)
    f = rng.standard_normal((3, 13)) / (1.0 + spectral.wavenumbers(6)) ** 2
    m, eps = 128, 1e-3
    u = nl.nonlocal_velocity(x, f, eps, quadrature_points=m)
    j = 37  # a shift by grid points: the same sums, permuted
    grid_shift = nl.nonlocal_velocity(shifted(x, 2 * np.pi * j / m), shifted(f, 2 * np.pi * j / m),
                                      eps, quadrature_points=m)
    assert np.abs(grid_shift - np.roll(u, -j, axis=1)).max() < 1e-12
    s0 = 0.7071  # off the grid: equal up to the (spectral) quadrature error
    coefficients = nl.nonlocal_velocity(x, f, eps, quadrature_points=m, order=10)
    moved = nl.nonlocal_velocity(shifted(x, s0), shifted(f, s0), eps, quadrature_points=m, order=10)
    assert np.abs(moved - shifted(coefficients, s0)).max() < 1e-11


def test_local_limit_and_the_one_over_c_correction(rng):
    """local_velocity is loopsim's local map (tests/naive.py); c (u - u_local) =
    (I - 3x'x') f + K f whatever ε, so u -> u_local like 1/c."""
    x = naive.random_shape(rng, 6, amplitude=0.05)
    x = nl.arclength_parametrised(x, 6)
    f, u_local, _ = naive.maps(x, 0.3 * rng.standard_normal(13), 3.0, 10.0)
    assert np.abs(nl.local_velocity(x, f, order=6) - u_local).max() < 1e-12
    m = 96
    t = x @ spectral.synthesis_matrix(6, m, 1).T
    fg = f @ spectral.synthesis_matrix(6, m).T
    correction = fg - 3.0 * t * np.sum(t * fg, axis=0) + nl.K_operator(x, f, m, arclength_tol=1e-2)
    for eps in (1e-3, 1e-12):
        c = nl.slenderness_constant(eps)
        u = nl.nonlocal_velocity(x, f, eps, m, arclength_tol=1e-2)
        gap = c * (u - nl.local_velocity(x, f, m))
        assert np.abs(gap - correction).max() < 1e-11 * c


def test_arclength_is_required_and_provided():
    raw = np.zeros((3, 7))
    raw[0, 1], raw[1, 4], raw[2, 2] = 1.0, 1.0, 0.1  # z = 0.1 cos 2α: not arc length
    with pytest.raises(ValueError, match="arc length"):
        nl.nonlocal_velocity(raw, np.ones((3, 1)), 1e-3)
    x = nl.arclength_parametrised(raw, 40)
    assert nl.arclength_error(x) < 1e-9
    assert 2 * np.pi * np.mean(np.linalg.norm(
        x @ spectral.synthesis_matrix(40, 401, 1).T, axis=0)) == pytest.approx(2 * np.pi, rel=1e-12)


# ---- the rigid ring ---------------------------------------------------------------------------

def test_johnson_wu_in_loopsim_units():
    """johnson_wu_ring converts the dimensional drags (μ = 1, R = 1, a = 2π ε R)."""
    for eps in EPSILONS:
        a, big_r, mu = 2 * np.pi * eps, 1.0, 1.0
        ell = math.log(8 * big_r / a)
        drag_broad = 8 * np.pi**2 * mu * big_r / (ell + 0.5)  # F / U
        drag_edge = 2 * np.pi**2 * mu * big_r * (3 * ell - 8.5) / ((ell - 0.5) * (ell - 2) - 2)
        c = nl.slenderness_constant(eps)
        # density g = F/(2πR), loopsim velocity = 8πμ U / (c g)
        expected = [8 * np.pi * mu * 2 * np.pi * big_r / (c * d) for d in (drag_broad, drag_edge)]
        assert np.allclose(closed.johnson_wu_ring(eps), expected, rtol=1e-14)


@pytest.mark.parametrize("eps", EPSILONS)
def test_ring_broadside_uniform_force_translates_it_as_johnson_wu(eps, rng):
    """A uniform force along the axis gives a uniform velocity (no rigidity needed), for
    the ring tilted any way and parametrised from any point."""
    broadside, _ = closed.johnson_wu_ring(eps)
    for _ in range(3):
        rotation = random_rotation(rng)
        x = shifted(rotation @ circle(), rng.uniform(0, 2 * np.pi))
        axis = rotation[:, 2]
        u = nl.nonlocal_velocity(x, -2.0 * axis[:, None], eps, quadrature_points=32)
        assert np.abs(u - (-2.0 * broadside * axis)[:, None]).max() < 1e-12


@pytest.mark.parametrize("eps", EPSILONS)
def test_rigid_ring_translates_without_rotating_as_johnson_wu(eps, rng):
    """Uniform force density g on the rigid ring, any tilt and any direction of g:
    Ω = 0 and U = M_b (g·b) b + M_e (g - (g·b) b) with Johnson & Wu's mobilities."""
    broadside, edgewise = closed.johnson_wu_ring(eps)
    for trial in range(4):
        rotation = np.eye(3) if trial == 0 else random_rotation(rng)
        x = shifted(rotation @ circle(), rng.uniform(0, 2 * np.pi))
        x[:, 0] += rng.standard_normal(3)
        axis = rotation[:, 2]
        g = rotation[:, 0] if trial == 0 else rng.standard_normal(3)  # trial 0: edgewise
        along = (g @ axis) * axis
        velocity, spin = nl.rigid_velocity(x, 2 * np.pi * g, eps=eps)
        expected = broadside * along + edgewise * (g - along)
        assert np.abs(velocity - expected).max() < 1e-12 * np.linalg.norm(expected)
        assert np.abs(spin).max() < 1e-12 * np.linalg.norm(expected)
        # the force density that holds it rigid gives a pure translation, of mean g
        f = nl.rigid_force(x, velocity, eps=eps)
        force, torque = nl.force_and_torque(x, f)
        assert np.allclose(force, 2 * np.pi * g, atol=1e-12) and np.abs(torque).max() < 1e-12
        u = nl.nonlocal_velocity(x, f, eps)
        assert np.abs(u - velocity[:, None]).max() < 1e-12


@pytest.mark.parametrize("eps", EPSILONS)
def test_uniform_edgewise_force_alone_does_not_move_the_ring_rigidly(eps):
    """Without the internal forces of a rigid ring, a uniform in-plane density e_x gives
    u = (1/c)[(2ℓ+3) cos s n - (4ℓ-4) sin s t] (ℓ = log 8R/a): not a translation."""
    c, ell = nl.slenderness_constant(eps), math.log(4 / (math.pi * eps))
    s = spectral.grid(32)
    t, n, _ = frame(s)
    u = nl.nonlocal_velocity(circle(), np.array([[1.0], [0.0], [0.0]]), eps, quadrature_points=32)
    expected = ((2 * ell + 3) * np.cos(s) * n - (4 * ell - 4) * np.sin(s) * t) / c
    assert np.abs(u - expected).max() < 1e-12
    assert np.ptp(u[0]) > 0.1 * np.mean(u[0])  # far from uniform


@pytest.mark.parametrize("theta0", [0.0, 0.3, 0.9, np.pi / 2])
def test_local_rigid_circle_is_the_papers_u0_and_nonlocal_corrects_it_by_one_over_c(theta0):
    """Local model: U = -[0, g0 sin 2θ0 / 6, g0 (7 - cos 2θ0) / 6] (physics-notes.md).
    Nonlocal: the same with mobilities 1 -> M_b and 4/3 -> M_e, and c (M - M_local)
    tends to 1 + 2 log(4/π) (broadside) and (8/3)(log(4/π) + 1/3) (edgewise)."""
    g0 = 5.0
    x = inclined_circle(1, theta0)
    u0 = -np.array([0.0, g0 * np.sin(2 * theta0) / 6, g0 * (7 - np.cos(2 * theta0)) / 6])
    velocity, spin = nl.rigid_velocity(x, [0.0, 0.0, -2 * np.pi * g0])
    assert np.abs(velocity - u0).max() < 1e-13 and np.abs(spin).max() < 1e-13
    normal = np.array([0.0, -np.sin(theta0), np.cos(theta0)])
    gravity = np.array([0.0, 0.0, -g0])
    along = (gravity @ normal) * normal
    for eps in EPSILONS:
        broadside, edgewise = closed.johnson_wu_ring(eps)
        velocity, _ = nl.rigid_velocity(x, 2 * np.pi * gravity, eps=eps)
        assert np.abs(velocity - (broadside * along + edgewise * (gravity - along))).max() < 1e-12
    c = nl.slenderness_constant(1e-12)
    broadside, edgewise = closed.johnson_wu_ring(1e-12)
    assert c * (broadside - 1.0) == pytest.approx(1.0 + 2.0 * nl.LOG_4_OVER_PI, rel=1e-12)
    assert c * (edgewise - 4.0 / 3.0) == pytest.approx(
        8.0 / 3.0 * (nl.LOG_4_OVER_PI + 1.0 / 3.0), rel=0.02)  # the next term is O(1/c)


# ---- spectral convergence ---------------------------------------------------------------------

def test_spectral_convergence_in_quadrature_points():
    x = perturbed_loop(12)
    f = elastic_force(x)
    eps = 1e-3
    ref = nl.nonlocal_velocity(x, f, eps, quadrature_points=384, order=8, arclength_tol=1e-2)
    error = {m: np.abs(nl.nonlocal_velocity(x, f, eps, quadrature_points=m, order=8,
                                            arclength_tol=1e-2) - ref).max()
             for m in (32, 64, 128)}
    scale = np.abs(ref).max()
    assert error[32] > 1e-6 * scale  # the coarse grid is visibly unresolved
    assert error[64] < 1e-3 * error[32]
    assert error[128] < 1e-4 * error[64] or error[128] < 1e-12 * scale  # or at rounding


def test_spectral_convergence_in_truncation_order():
    """Shape and force truncated at n = 8, 16, 32 against n = 64 (M = 256)."""
    eps, m = 1e-3, 256
    ref_x = perturbed_loop(64)
    ref = nl.nonlocal_velocity(ref_x, elastic_force(ref_x), eps, m, order=8)
    error = {}
    for n in (8, 16, 32):
        x = perturbed_loop(n)
        u = nl.nonlocal_velocity(x, elastic_force(x), eps, m, order=8, arclength_tol=1e-2)
        error[n] = np.abs(u - ref).max()
    assert error[16] < 1e-2 * error[8]
    assert error[32] < 1e-4 * error[16]


def test_operator_matches_adaptive_quadrature_off_the_circle(rng):
    """K[f] at one point of the non-circular loop, by scipy quad of the paper's
    integrand (periodic form, 1/|σ| subtraction), independent of the weights."""
    x = perturbed_loop(64)  # | |x'| - 1 | < 1e-12: else quad sees its log divergence
    assert nl.arclength_error(x) < 1e-12
    f = rng.standard_normal((3, 9)) / (1.0 + spectral.wavenumbers(4)) ** 2
    m, j = 160, 50
    s0 = spectral.grid(m)[j]
    position = spectral.evaluate(x, [s0])[:, 0]
    tangent = (x @ spectral.derivative_matrix(64).T)
    t0 = spectral.evaluate(tangent, [s0])[:, 0]
    local = (np.eye(3) + np.outer(t0, t0)) @ spectral.evaluate(f, [s0])[:, 0]

    def integrand(sigma, a):
        r = position - spectral.evaluate(x, [s0 + sigma])[:, 0]
        d = np.linalg.norm(r)
        fs = spectral.evaluate(f, [s0 + sigma])[:, 0]
        return ((fs + r * (r @ fs) / d**2) / d - local / abs(sigma))[a]

    expected = [quad(lambda s: integrand(s, a), -math.pi, 0.0)
                + quad(lambda s: integrand(s, a), 0.0, math.pi) for a in range(3)]
    got = nl.K_operator(x, f, m)[:, j]
    assert np.abs(got - expected).max() < 1e-10  # measured 9e-12, |K| ≈ 7


# ---- the elastic loop: tension and velocity ---------------------------------------------------

def test_loop_velocity_with_the_local_mobility_is_loopsims_local_model(rng):
    """loop_tension_and_velocity with local_matrix against the compiled local model
    (models.evaluate: its own grid, its own least-squares solver)."""
    from loopsim import models
    from loopsim.models import local_sbt

    n, g0, w = 6, 80.0, 10.0
    x = naive.random_shape(rng, n)
    tension, u = nl.loop_tension_and_velocity(x, g0, w, nl.local_matrix(x, quadrature_points=64))
    problem = local_sbt.make_problem(n, g0, w)
    u_compiled, tension_compiled = np.empty_like(x), np.empty(x.shape[1])
    models.evaluate(problem, x.reshape(-1).copy(), u_compiled.reshape(-1), tension_compiled)
    assert np.abs(u - u_compiled).max() < 1e-9 * np.abs(u_compiled).max()
    assert np.abs(tension - tension_compiled).max() < 1e-9 * np.abs(tension_compiled).max()


@pytest.mark.parametrize("eps", EPSILONS)
def test_horizontal_ring_sediments_as_johnson_wu_broadside(eps):
    """A horizontal ring under gravity: the tension (−1, cancelling bending) keeps it
    circular and it translates at Johnson & Wu's broadside velocity, −g0 U_b e_z."""
    g0 = 3.0
    x = circle(4)
    tension, u = nl.nonlocal_loop_velocity(x, g0, 10.0, eps, quadrature_points=64)
    broadside, _ = closed.johnson_wu_ring(eps)
    expected = np.zeros_like(u)
    expected[2, 0] = -g0 * broadside
    assert np.abs(u - expected).max() < 1e-11
    assert np.abs(tension - np.eye(1, tension.size)[0] * -1.0).max() < 1e-10


def test_loop_velocity_tends_to_the_local_one_as_one_over_c(rng):
    """u(c) = u_local + u1 / c + O(1/c²): c (u - u_local) converges, its change halving as
    c doubles (ε = 1e-8 ... 1e-64: c = 36.8, 73.7, 147, 295; at c = 18.4 the ratio is
    still 2.5)."""
    x = perturbed_loop(12)
    g0, w, m = 40.0, 10.0, 128
    _, u_local = nl.loop_tension_and_velocity(x, g0, w, nl.local_matrix(x, quadrature_points=m))
    scaled = []
    for eps in (1e-8, 1e-16, 1e-32, 1e-64):
        _, u = nl.nonlocal_loop_velocity(x, g0, w, eps, quadrature_points=m)
        scaled.append(nl.slenderness_constant(eps) * (u - u_local))
    changes = [np.abs(b - a).max() for a, b in zip(scaled, scaled[1:])]
    assert np.abs(scaled[-1]).max() > 10 * changes[-1]  # a correction of order 1/c, not 0
    for previous, current in zip(changes, changes[1:]):
        assert 1.9 < previous / current < 2.3, changes


def test_loop_velocity_converges_spectrally_in_quadrature_points():
    """u of the elastic loop (n = 16, ε = 1e-3) against m = 16n + 1 points: 2n + 2 points
    are off by ~1e-5, 3n + 1 by ~1e-7, the local model's 4n + 1 grid by ~1e-10."""
    n = 16
    x = perturbed_loop(n)
    reference = nl.nonlocal_loop_velocity(x, 60.0, 10.0, 1e-3, quadrature_points=16 * n + 1)[1]
    errors = [np.abs(nl.nonlocal_loop_velocity(x, 60.0, 10.0, 1e-3, quadrature_points=m)[1]
                     - reference).max() / np.abs(reference).max()
              for m in (2 * n + 2, 3 * n + 1, 4 * n + 1)]
    assert errors[0] < 1e-3 and errors[2] < 1e-9
    assert errors[1] < 1e-2 * errors[0] and errors[2] < 1e-2 * errors[1]  # geometric in m


@pytest.mark.parametrize("eps", EPSILONS)
def test_settling_angle_of_the_tilted_rigid_ring(eps):
    """The closed form against the rigid ring's computed velocity under gravity at tilts
    around θ*: its angle to the vertical is largest at θ* and equals φ_max there; the
    local model's is the paper's tan⁻¹(1/(4√3)) at cos 2θ0 = 1/7."""
    phi_max, theta_star = closed.settling_angle(eps)

    def angle(theta_deg):
        theta = np.radians(theta_deg)
        x = inclined_circle(1, theta)
        velocity, _ = nl.rigid_velocity(x, 2 * np.pi * np.array([0.0, 0.0, -1.0]), eps=eps)
        return np.degrees(np.arctan2(np.hypot(velocity[0], velocity[1]), -velocity[2]))

    assert abs(angle(theta_star) - phi_max) < 1e-9
    assert angle(theta_star - 2.0) < phi_max and angle(theta_star + 2.0) < phi_max
    local_phi, local_theta = closed.settling_angle()
    assert abs(local_phi - np.degrees(np.arctan(1 / (4 * np.sqrt(3))))) < 1e-12
    assert abs(np.cos(2 * np.radians(local_theta)) - 1 / 7) < 1e-12
    assert phi_max < local_phi  # nonlocal hydrodynamics settles the ring less steeply
