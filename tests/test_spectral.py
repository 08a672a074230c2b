"""Fourier layout and algebra against direct evaluation and numpy.fft."""
import numpy as np
import pytest

import naive
from loopsim import spectral


@pytest.mark.parametrize("n", [1, 4, 9])
def test_synthesis_matches_closed_form_derivatives(n, rng):
    c = rng.standard_normal(2 * n + 1)
    m = 4 * n + 1
    s = spectral.grid(m)
    k = np.arange(1, n + 1)
    a, b = c[1 : n + 1], c[n + 1 :]
    # d/ds (a cos ks + b sin ks) = -a k sin ks + b k cos ks
    d1 = (np.cos(np.outer(s, k)) * k) @ b - (np.sin(np.outer(s, k)) * k) @ a
    d4 = (np.cos(np.outer(s, k)) * k**4) @ a + (np.sin(np.outer(s, k)) * k**4) @ b
    np.testing.assert_allclose(spectral.synthesis_matrix(n, m, 1) @ c, d1, atol=1e-12)
    np.testing.assert_allclose(spectral.synthesis_matrix(n, m, 4) @ c, d4, atol=1e-9)
    np.testing.assert_allclose(spectral.evaluate(c, s), naive.to_grid(c, 0, m), atol=1e-12)


@pytest.mark.parametrize("n", [1, 5])
def test_analysis_inverts_synthesis_and_projects(n, rng):
    m = 4 * n + 1
    c = rng.standard_normal(2 * n + 1)
    np.testing.assert_allclose(spectral.analysis_matrix(n, m) @ spectral.synthesis_matrix(n, m) @ c, c,
                               atol=1e-13)
    high = rng.standard_normal(2 * (3 * n) + 1)  # order 3n < m - n: projection exact
    np.testing.assert_allclose(spectral.analysis_matrix(n, m) @ naive.to_grid(high, 0, m),
                               spectral.resize(high, n), atol=1e-12)


def test_product_is_exact_convolution(rng):
    a, b = rng.standard_normal(2 * 3 + 1), rng.standard_normal(2 * 5 + 1)
    expected = naive.complex_to_real(np.convolve(naive.real_to_complex(a), naive.real_to_complex(b)))
    product = spectral.multiply(a, b)
    assert product.shape == (2 * 8 + 1,)
    np.testing.assert_allclose(product, expected, atol=1e-13)
    np.testing.assert_allclose(spectral.resize(product, 3), expected[[0, 1, 2, 3, 9, 10, 11]], atol=1e-13)


def test_resize_pads_and_layout_helpers():
    c = np.arange(5.0)  # n = 2: [a0, a1, a2, b1, b2]
    np.testing.assert_array_equal(spectral.resize(c, 3), [0, 1, 2, 0, 3, 4, 0])
    np.testing.assert_array_equal(spectral.wavenumbers(2), [0, 1, 2, 1, 2])
    assert spectral.order_of(13) == 6
    with pytest.raises(ValueError):
        spectral.order_of(12)
    with pytest.raises(ValueError):
        spectral.analysis_matrix(4, 8)
