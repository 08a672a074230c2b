"""Model and integrator kernels against the independent NumPy twins of tests/naive.py.

Each kernel is compared with a twin that computes the same quantity by other
means (finite differences of the FFT maps, LAPACK, sampled points on a fine
FFT grid), at a tolerance set a few times above the error measured for the
twin itself, so that a wrong term or factor in the kernel fails the test.
"""
import numpy as np
import pytest

import naive
from loopsim.linalg import PIVOT_DTYPE, factor, lu_solve
from loopsim.models import local_sbt


def _factor_and_solve(a, b):
    """lu_factor on a copy of a, then lu_solve on a copy of b: (x, lu, piv)."""
    lu = np.array(a, copy=True)
    piv = np.empty(a.shape[0], dtype=PIVOT_DTYPE)
    assert factor(lu, piv) == 0
    x = np.array(b, copy=True)
    lu_solve(lu, piv, x)
    return x, lu, piv


def _permutation(piv):
    """Row order of P m for LAPACK's 1-based swaps piv (row k swapped with piv[k] - 1)."""
    order = np.arange(piv.size)
    for k, p in enumerate(piv - 1):
        order[[k, p]] = order[[p, k]]
    return order


# ---- the exact Jacobian of the velocity map ---------------------------------------

@pytest.mark.parametrize("n", [3, 6, 8])
def test_loop_jacobian_matches_finite_difference_twin(n, rng):
    """local_sbt.loop_jacobian against Richardson-extrapolated central differences of
    naive.tension_and_velocity (FFT maps, lstsq tension; no loopsim code).

    Tolerance 5e-10 max|J|: the twin's error (truncation ~(k h)⁴ plus round-off
    ~1e-16 |u| / h at h = 5e-5 / k) was measured at ≤ 1.4e-10 max|J| for
    n = 3, 6, 8 over three seeds (≈ 1e-10 at n = 3, ≈ 1e-11 at n = 6, 8);
    a dropped chain-rule term is an O(1) error.
    """
    g0, w = 70.0, 10.0
    x = naive.random_shape(rng, n, amplitude=0.1)
    problem = local_sbt.make_problem(n, g0, w)
    jac = np.full((x.size, x.size), np.nan)
    local_sbt.loop_jacobian(x, g0, w, problem.ops, problem.ws, jac)
    reference = naive.jacobian(x, g0, w)
    scale = np.abs(reference).max()
    np.testing.assert_allclose(jac, reference, rtol=0, atol=5e-10 * scale)
    # u depends on x through its derivatives only: the a0 (translation) columns vanish
    k = x.shape[1]
    np.testing.assert_allclose(jac[:, ::k], 0.0, rtol=0, atol=1e-14 * scale)


# ---- dense LU with partial pivoting -----------------------------------------------

def _lu_tolerance(a, x):
    """Forward-error bound for comparing two backward-stable solvers: the solutions
    differ by ≲ cond(a) · ε · |x|; measured ≤ 2.9e-16 cond(a) |x| over 300 Gaussian
    matrices of sizes 1, 7, 51 (real and complex), so 1e-15 cond(a) |x|."""
    return 1e-15 * np.linalg.cond(a) * np.abs(x).max()


@pytest.mark.parametrize("size", [1, 7, 51])
@pytest.mark.parametrize("dtype", [np.float64, np.complex128])
def test_lu_solve_matches_lapack_on_random_matrices(size, dtype, rng):
    """lu_factor / lu_solve against numpy.linalg.solve (LAPACK gesv) on Gaussian
    matrices (cond ≤ 1e4 checked; 51 = 3K at n = 8), and P aᵀ = L U from the pivots
    (LAPACK's factors of the column-major reading of a, see ``linalg``).

    Solutions: :func:`_lu_tolerance`.  Factors: backward error ≲ size · ε · growth
    · max|a|, measured ≤ 7.8e-17 size max|a|, tolerance 4e-16 size max|a|.
    """
    def draw(shape):
        if dtype is np.float64:
            return rng.standard_normal(shape)
        return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)

    a = draw((size, size))
    assert np.linalg.cond(a) < 1e4
    b = draw(size)
    x, lu, piv = _factor_and_solve(a, b)
    assert x.dtype == dtype
    expected = naive.lu_solve(a, b)
    np.testing.assert_allclose(x, expected, rtol=0, atol=_lu_tolerance(a, expected))
    # the factors themselves (column-major: the transpose of the row-major buffer):
    # unit lower L, upper U, P aᵀ = L U
    lower = np.tril(lu.T, -1) + np.eye(size)
    upper = np.triu(lu.T)
    np.testing.assert_allclose(lower @ upper, a.T[_permutation(piv)], rtol=0,
                               atol=4e-16 * size * np.abs(a).max())
    # partial pivoting bounds the multipliers: |l| ≤ 1 for real; LAPACK picks complex
    # pivots by |Re| + |Im| (izamax), which bounds |l| by √2
    bound = 1.0 if dtype is np.float64 else np.sqrt(2.0)
    assert np.abs(np.tril(lu.T, -1)).max(initial=0.0) <= bound
    # the factorisation is reusable: a second right-hand side with the same lu, piv
    b2 = draw(size)
    x2 = np.array(b2, copy=True)
    lu_solve(lu, piv, x2)
    expected2 = naive.lu_solve(a, b2)
    np.testing.assert_allclose(x2, expected2, rtol=0, atol=_lu_tolerance(a, expected2))


@pytest.mark.parametrize("dtype", [np.float64, np.complex128])
def test_lu_solve_pivots_zero_and_tiny_leading_entries(dtype, rng):
    """Matrices that Gaussian elimination without row swaps cannot solve: a zero
    leading entry (division by zero) and a 1e-20 one (the classic growth example:
    without a swap x₀ comes out 0 instead of ≈ 1).  Tolerance :func:`_lu_tolerance`."""
    zero_lead = rng.standard_normal((6, 6)).astype(dtype)
    if dtype is np.complex128:
        zero_lead += 1j * rng.standard_normal((6, 6))
    zero_lead[0, 0] = 0.0
    tiny_lead = np.array([[1e-20, 1.0], [1.0, 1.0]], dtype=dtype)
    for a, expected in ((zero_lead, None), (tiny_lead, np.array([1.0, 1.0]))):
        b = np.arange(1, a.shape[0] + 1).astype(dtype)
        x, _, piv = _factor_and_solve(a, b)
        assert piv[0] != 1  # the first step swapped rows (1-based pivots)
        if expected is None:
            expected = naive.lu_solve(a, b)
        np.testing.assert_allclose(x, expected, rtol=0, atol=_lu_tolerance(a, expected))


# ---- the monitored invariant and the steady-state invariants ----------------------

@pytest.mark.parametrize("n", [2, 5, 8])
def test_relative_length_error_is_the_trapezoid_rule_on_the_model_grid(n, rng):
    """relative_length_error against the twin sampled on the same M = 4n + 1 grid:
    the same quadrature by other means (FFT synthesis), so only round-off
    separates them: ≲ M ε ≈ 4e-15 for n = 8, measured ≤ 2.3e-16; tolerance 1e-14."""
    problem = local_sbt.make_problem(n, 70.0, 10.0)
    for _ in range(3):
        x = naive.random_shape(rng, n, amplitude=0.2)
        got = local_sbt.relative_length_error(x, problem.ops, problem.ws)
        expected = naive.relative_length_error(x, local_sbt.grid_size(n))
        assert abs(got - expected) < 1e-14, (got, expected)


@pytest.mark.parametrize("n", [10, 12, 16])
def test_relative_length_error_matches_fine_grid_twin(n, rng):
    """The M-point rule against the mean of |x'| on the 256-point FFT grid.

    |x'| is not a trigonometric polynomial, so the M-point rule is only
    spectrally accurate.  For random shapes of amplitude 0.1 (speed varying by
    ~±20 %) the difference, measured over 100 shapes per order, is ≤ 1.1e-11 for
    n = 10, 3e-12 for n = 12, 4e-13 for n = 16 (but 1.3e-10 at n = 8 and 2e-6
    at n = 3: low orders are covered by the same-grid test above).  Tolerance 5e-11.
    """
    problem = local_sbt.make_problem(n, 70.0, 10.0)
    for _ in range(5):
        x = naive.random_shape(rng, n, amplitude=0.1)
        got = local_sbt.relative_length_error(x, problem.ops, problem.ws)
        expected = naive.relative_length_error(x)
        speed = np.linalg.norm(naive.to_grid(x, 1), axis=0)
        assert np.ptp(speed) > 0.05  # far from unit speed: |x'| is not a polynomial
        assert abs(got - expected) < 5e-11, (got, expected)


@pytest.mark.parametrize("n", [2, 6, 16])
@pytest.mark.parametrize("amplitude", [0.05, 0.3])
def test_shape_invariants_match_sampled_covariance_twin(n, amplitude, rng):
    """shape_invariants (covariance from the coefficients, Parseval) against the
    covariance of 256 sampled points, its eigenvalues and |n_z|.

    Tolerance 1e-14 (absolute; entries are O(1)): round-off is ~ε |C| / gap;
    measured ≤ 3e-15 over 170 random shapes (n = 2..16, amplitude 0.05..0.3).
    """
    for _ in range(5):
        x = naive.random_shape(rng, n, amplitude=amplitude, theta=rng.uniform(0, np.pi))
        got = local_sbt.shape_invariants(x)
        expected = naive.shape_invariants(x)
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-14)
