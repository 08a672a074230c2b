"""Tests for loopsim.stability.paper against independent references.

References: direct quadrature of L[sin ks] (operator applied analytically on a
grid of s), the paper's printed matrix and quoted critical values, sqrt(300)
for n = 3 (closed form of the 2x2 block det), and -(k² + k⁴) at q = 0.
"""

import math

import numpy as np
import pytest

from loopsim.stability.paper import (
    critical_q,
    critical_q_table,
    largest_growth_rate,
    paper_growth_rates,
    paper_operator,
)

Q_CRIT = 14.56105439107


def _projected_operator(q, n, n_grid=256):
    """M[j,k] = (1/π) ∫ L[sin ks] sin js ds, by the (exact) periodic trapezoid rule."""
    s = np.arange(n_grid) * (2 * np.pi / n_grid)
    m = np.empty((n, n))
    for k in range(1, n + 1):
        z = np.sin(k * s)
        z1 = k * np.cos(k * s)
        z2 = -k**2 * np.sin(k * s)
        z4 = k**4 * np.sin(k * s)
        lz = -z4 + z2 + q * (np.sin(s) * z1 + np.cos(s) * z2)
        for j in range(1, n + 1):
            m[j - 1, k - 1] = np.sum(lz * np.sin(j * s)) * (2 / n_grid)
    return m


@pytest.mark.parametrize("q", [0.0, 1.0, 3.7, 14.56, -5.0])
def test_matrix_matches_quadrature(q):
    n = 7
    ref = _projected_operator(q, n)
    np.testing.assert_allclose(paper_operator(q, n), ref, rtol=0, atol=1e-9)


def test_matrix_matches_printed_paper_matrix():
    q = 1.3
    printed = np.array([
        [-2, -3 * q, 0, 0],
        [0, -20, -6 * q, 0],
        [0, -q, -90, -10 * q],
        [0, 0, -3 * q, -272],
    ])
    np.testing.assert_allclose(paper_operator(q, 4), printed, rtol=0, atol=1e-12)
    # The text's formula (opposite sign on the q terms) is similar via diag((-1)^k).
    dflip = np.diag([(-1.0) ** k for k in range(1, 5)])
    text = dflip @ printed @ dflip
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(text).real),
                               np.sort(np.linalg.eigvals(printed).real), rtol=1e-12)


def test_growth_rate_matches_general_eigensolver():
    for n in (1, 2, 5, 12):
        for q in (0.0, 2.5, 14.0, 30.0):
            ref = np.max(np.linalg.eigvals(_projected_operator(q, n, 64)).real)
            assert largest_growth_rate(q, n) == pytest.approx(ref, rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("n", [10, 20, 60])
def test_critical_q_converged(n):
    qc = critical_q(n)
    assert abs(qc - Q_CRIT) / Q_CRIT < 5e-11  # 10 significant digits (quoted to 11)


@pytest.mark.parametrize("n, quoted, digits", [
    (3, 17.3205, 4), (4, 14.8106, 4), (6, 14.56146, 5), (8, 14.5610545, 7),
])
def test_critical_q_low_truncations(n, quoted, digits):
    assert round(critical_q(n), digits) == pytest.approx(quoted, abs=1e-12)


def test_critical_q_n3_closed_form():
    # n = 3: eigenvalue -2 decouples; the 2x2 block has det 1800 - 6q² = 0.
    assert critical_q(3) == pytest.approx(math.sqrt(300.0), rel=1e-14)


@pytest.mark.parametrize("n", [1, 2])
def test_no_crossing_for_small_n(n):
    assert math.isnan(critical_q(n))


def test_no_crossing_below_small_q_max():
    assert math.isnan(critical_q(20, q_max=10.0))


@pytest.mark.parametrize("n", [3, 4, 8, 20])
def test_sign_change_at_critical_q(n):
    qc = critical_q(n)
    assert largest_growth_rate(qc * (1 - 1e-6), n) < 0
    assert largest_growth_rate(qc * (1 + 1e-6), n) > 0
    assert abs(largest_growth_rate(qc, n)) < 1e-10


def test_q_zero_eigenvalues():
    n = 9
    k = np.arange(1, n + 1)
    expected = -(k**2 + k**4)
    eig = np.sort(np.linalg.eigvals(paper_operator(0.0, n)).real)
    assert np.array_equal(eig, np.sort(expected.astype(float)))
    assert largest_growth_rate(0.0, n) == -2.0


def test_growth_rates_vectorised():
    qs = np.array([[0.0, 10.0], [Q_CRIT - 0.1, 20.0]])
    g = paper_growth_rates(qs, 10)
    assert g.shape == qs.shape
    assert g[0, 0] == -2.0
    assert g[1, 0] < 0 < g[1, 1]
    assert g[0, 1] == largest_growth_rate(10.0, 10)


def test_table():
    table = critical_q_table(6)
    assert [n for n, _ in table] == list(range(1, 7))
    assert math.isnan(table[0][1]) and math.isnan(table[1][1])
    assert table[5][1] == critical_q(6)


@pytest.mark.parametrize("call", [
    lambda: paper_operator(1.0, 0),
    lambda: paper_operator(1.0, 2.0),
    lambda: paper_operator(1.0, True),
    lambda: paper_operator(float("nan"), 3),
    lambda: paper_operator(1 + 2j, 3),
    lambda: largest_growth_rate(float("inf"), 3),
    lambda: largest_growth_rate("1.0", 3),
    lambda: critical_q(-1),
    lambda: critical_q(5, q_max=0.0),
    lambda: critical_q(5, q_max=float("nan")),
    lambda: critical_q_table(0),
    lambda: paper_growth_rates([1.0, float("nan")], 4),
    lambda: paper_growth_rates([1.0], 0),
    lambda: paper_growth_rates(["a"], 4),
])
def test_bad_input_raises(call):
    with pytest.raises(ValueError):
        call()
