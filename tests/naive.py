"""Plain-NumPy twins of the njit maps, written independently of loopsim.

Complex exponentials and numpy.fft on a fine grid (no loopsim matrices), and
numpy.linalg.lstsq for the tension: the reference the kernels are tested
against.
"""
import numpy as np

FINE = 256  # grid points; resolves every product up to order 4n for n <= 16


def real_to_complex(c):
    """[a0, a1..an, b1..bn] -> complex coefficients for k = -n..n (last axis)."""
    c = np.asarray(c, dtype=float)
    n = (c.shape[-1] - 1) // 2
    a, b = c[..., 1 : n + 1], c[..., n + 1 :]
    out = np.zeros(c.shape[:-1] + (2 * n + 1,), dtype=complex)
    out[..., n] = c[..., 0]
    out[..., n + 1 :] = (a - 1j * b) / 2
    out[..., :n] = ((a + 1j * b) / 2)[..., ::-1]
    return out


def complex_to_real(z):
    n = (z.shape[-1] - 1) // 2
    pos, neg = z[..., n + 1 :], z[..., :n][..., ::-1]
    return np.concatenate([z[..., n : n + 1].real, (pos + neg).real, (1j * (pos - neg)).real], axis=-1)


def to_grid(c, derivative=0, m=FINE):
    """Grid values on s_j = 2πj/m of the derivative of the real series c."""
    z = real_to_complex(c)
    n = (z.shape[-1] - 1) // 2
    k = np.arange(-n, n + 1)
    z = z * (1j * k) ** derivative
    spectrum = np.zeros(z.shape[:-1] + (m,), dtype=complex)
    np.add.at(spectrum, (..., k % m), z)  # aliased modes add up
    values = np.fft.ifft(spectrum, axis=-1) * m
    assert np.abs(values.imag).max() < 1e-9 * (1 + np.abs(values.real).max())
    return values.real


def project(values, n):
    """Real coefficients of order n of grid values (discrete L² projection)."""
    m = values.shape[-1]
    spectrum = np.fft.fft(values, axis=-1) / m
    k = np.arange(-n, n + 1)
    return complex_to_real(spectrum[..., k % m])


def maps(x, tension, g0, w):
    """(f, u, ε on the fine grid) for shape x (3, 2n+1) and multiplier coefficients T."""
    n = (x.shape[-1] - 1) // 2
    t, kap, x4 = to_grid(x, 1), to_grid(x, 2), to_grid(x, 4)
    T, dT = to_grid(tension), to_grid(tension, 1)
    gravity = np.array([0.0, 0.0, g0])[:, None]
    f = project(-x4 + dT * t + T * kap - gravity, n)
    fg = to_grid(f)
    u = project(fg + np.sum(t * fg, axis=0) * t, n)
    eps = np.sum(t * to_grid(u, 1), axis=0) - w * (1.0 - np.sum(t * t, axis=0))
    return f, u, eps


def tension_and_velocity(x, g0, w):
    """T minimising ∫ε² ds (lstsq over the fine grid) and the resulting u."""
    k = x.shape[-1]
    zero = np.zeros(k)
    _, _, b = maps(x, zero, g0, w)
    columns = []
    for j in range(k):
        e = np.zeros(k)
        e[j] = 1.0
        columns.append(maps(x, e, g0, w)[2] - b)
    tension = np.linalg.lstsq(np.array(columns).T, -b, rcond=None)[0]
    return tension, maps(x, tension, g0, w)[1]


def random_shape(rng, n, amplitude=0.2, theta=0.7):
    """A smooth random closed curve: a tilted circle plus 1/k³-decaying modes."""
    x = np.zeros((3, 2 * n + 1))
    x[0, n + 1] = 1.0
    x[1, 1] = np.cos(theta)
    x[2, 1] = np.sin(theta)
    k = np.concatenate(([1.0], np.arange(1, n + 1), np.arange(1, n + 1)))
    x += amplitude * rng.standard_normal(x.shape) / k**3
    return x


def jacobian(x, g0, w, h=5e-5):
    """∂u/∂x (3K × 3K, acting on x.ravel()) of :func:`tension_and_velocity` by
    Richardson-extrapolated central differences: (4 D(h/2) − D(h)) / 3, error O(h⁴).

    The step for a coefficient of wavenumber k is h max(1, max|x|) / k (x' changes
    by the same amount for every k).  The truncation error still grows quickly
    with n (terms like (k h)⁴ times high powers of x'), the rounding error is
    ~1e-16 |u| / step: h = 5e-5 balances them for n = 3..8, where the result
    agrees with the exact Jacobian to ≲ 1.4e-10 max|J| (tests/test_twins.py).
    """
    x = np.asarray(x, dtype=float)
    n = (x.shape[-1] - 1) // 2
    flat = x.ravel()
    wavenumber = np.tile(np.concatenate(([1.0], np.arange(1, n + 1), np.arange(1, n + 1))), 3)
    steps = h * max(1.0, np.abs(flat).max()) / wavenumber

    def u_of(y):
        return tension_and_velocity(y.reshape(x.shape), g0, w)[1].ravel()

    def central(delta, j):
        e = np.zeros_like(flat)
        e[j] = delta
        return (u_of(flat + e) - u_of(flat - e)) / (2 * delta)

    jac = np.empty((flat.size, flat.size))
    for j in range(flat.size):
        jac[:, j] = (4 * central(steps[j] / 2, j) - central(steps[j], j)) / 3
    return jac


def lu_solve(a, b):
    """x with a x = b (numpy.linalg.solve, i.e. LAPACK gesv)."""
    return np.linalg.solve(a, b)


def relative_length_error(x, m=FINE):
    """(L − 2π) / 2π with L = ∫|x'| ds as the mean of |x'| on an m-point FFT grid."""
    speed = np.sqrt(np.sum(to_grid(x, 1, m) ** 2, axis=0))
    return speed.mean() - 1.0


def shape_invariants(x, m=FINE):
    """[covariance eigenvalues ascending, |n_z|] from m sampled points of the curve.

    C = mean over the grid of (x(s) − x̄)(x(s) − x̄)ᵀ (exact for m > 2n: the
    integrand has order 2n); n is the eigenvector of the smallest eigenvalue.
    """
    points = to_grid(x, 0, m)
    centred = points - points.mean(axis=1, keepdims=True)
    cov = centred @ centred.T / m
    values, vectors = np.linalg.eigh(cov)
    return np.append(values, abs(vectors[2, 0]))
