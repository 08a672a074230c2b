"""Real truncated Fourier series on s ∈ [0, 2π): layout, transforms, algebra.

Storage.  A real periodic function of order n is stored as its 2n + 1 real
cos/sin coefficients::

    f(s) = c[0] + Σ_{k=1..n} ( c[k] cos ks + c[n+k] sin ks )

i.e. ``c = [a0, a1..an, b1..bn]``.  We store real cos/sin coefficients, not
complex exponentials, because every field of the model (position, velocity,
tension) is real: the state is real by construction, needs no projection
after each step, and the least-squares tension solve is a real problem with
2n + 1 unknowns (the paper projects complex coefficients back to real ones at
every step instead).

Derivative (per mode k):  (a cos ks + b sin ks)' = k b cos ks - k a sin ks.

Grids.  Products are evaluated exactly on the collocation grid
s_j = 2π j / M, j = 0..M-1.  A grid of M points represents a function of
order m exactly (and its mean-square exactly by the trapezoid rule) when
M ≥ 2m + 1; projecting an order-m product onto order n is alias-free when
M > m + n.
"""
import numpy as np


def n_coeffs(n):
    """Number of real coefficients of an order-n series: 2n + 1."""
    return 2 * n + 1


def order_of(n_coefficients):
    """Inverse of :func:`n_coeffs`."""
    n, rem = divmod(n_coefficients - 1, 2)
    if rem or n < 0:
        raise ValueError(f"{n_coefficients} is not an odd number of coefficients")
    return n


def wavenumbers(n):
    """Wavenumber of each stored coefficient: [0, 1..n, 1..n]."""
    k = np.arange(1, n + 1, dtype=float)
    return np.concatenate(([0.0], k, k))


def grid(m):
    """Equispaced collocation points s_j = 2π j / m."""
    return 2.0 * np.pi * np.arange(m) / m


def derivative_matrix(n, order=1):
    """Matrix D with D @ c = coefficients of d^order f / ds^order."""
    d = np.zeros((n_coeffs(n), n_coeffs(n)))
    for k in range(1, n + 1):
        # a_k' = k b_k,  b_k' = -k a_k
        d[k, n + k] = k
        d[n + k, k] = -k
    return np.linalg.matrix_power(d, order)


def basis(n, s):
    """(len(s), 2n+1) matrix of the basis [1, cos ks, sin ks] at the points s."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    k = np.arange(1, n + 1)
    return np.concatenate((np.ones((s.size, 1)), np.cos(np.outer(s, k)), np.sin(np.outer(s, k))),
                          axis=1)


def synthesis_matrix(n, m, order=0):
    """(m, 2n+1) matrix evaluating the order-th derivative of a series on the m-point grid."""
    return basis(n, grid(m)) @ derivative_matrix(n, order)


def analysis_matrix(n, m):
    """(2n+1, m) matrix of the discrete Fourier projection onto order n.

    Exact (returns the coefficients) for grid values of a series of order
    < m - n, since higher modes then alias outside [-n, n].
    """
    if m <= 2 * n:
        raise ValueError(f"a grid of {m} points cannot resolve order {n}")
    s = grid(m)
    k = np.arange(1, n + 1)
    return np.concatenate(
        (
            np.full((1, m), 1.0 / m),
            (2.0 / m) * np.cos(np.outer(k, s)),
            (2.0 / m) * np.sin(np.outer(k, s)),
        ),
        axis=0,
    )


def evaluate(c, s):
    """Values of the series with coefficients ``c`` (last axis) at the 1-D points ``s``."""
    c = np.asarray(c, dtype=float)
    n = order_of(c.shape[-1])
    k = np.arange(1, n + 1)
    s = np.atleast_1d(np.asarray(s, dtype=float))
    cos = np.cos(np.multiply.outer(s, k))
    sin = np.sin(np.multiply.outer(s, k))
    return c[..., :1] + c[..., 1 : n + 1] @ cos.T + c[..., n + 1 :] @ sin.T


def fit(values):
    """Coefficients of order (m - 1) // 2 interpolating values on the m-point grid."""
    values = np.asarray(values, dtype=float)
    m = values.shape[-1]
    n = (m - 1) // 2
    return values @ analysis_matrix(n, m).T


def resize(c, n):
    """Truncate (or zero-pad) coefficients ``c`` to order n."""
    c = np.asarray(c, dtype=float)
    n_old = order_of(c.shape[-1])
    out = np.zeros(c.shape[:-1] + (n_coeffs(n),))
    keep = min(n, n_old)
    out[..., 0] = c[..., 0]
    out[..., 1 : keep + 1] = c[..., 1 : keep + 1]
    out[..., n + 1 : n + 1 + keep] = c[..., n_old + 1 : n_old + 1 + keep]
    return out


def multiply(a, b):
    """Exact product of two series: order n_a + n_b, no truncation."""
    na, nb = order_of(np.shape(a)[-1]), order_of(np.shape(b)[-1])
    m = 2 * (na + nb) + 1
    va = np.asarray(a) @ synthesis_matrix(na, m).T
    vb = np.asarray(b) @ synthesis_matrix(nb, m).T
    return fit(va * vb)
