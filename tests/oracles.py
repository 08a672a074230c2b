"""Reference computations the tests compare loopsim with that are not plain-NumPy twins
(those are in tests/naive.py): here, derivatives by finite differences of loopsim's own
compiled right-hand side, a check of an exact Jacobian that needs no second derivation."""
import numpy as np

from loopsim import models

#: Relative step of :func:`difference_jacobian`: the cube root of the machine epsilon.
CENTRAL_STEP = float(np.finfo(float).eps ** (1.0 / 3.0))


def difference_jacobian(problem, y, step=CENTRAL_STEP):
    """∂F/∂y by central differences: column j is [F(y + h e_j) − F(y − h e_j)] / 2h with
    h = step max(1, |y_j|) (truncation error O(h²), rounding O(ε/h): about 1e-10 relative
    at the default step)."""
    y = np.array(y, dtype=float)
    size = y.size
    jac = np.empty((size, size))
    plus, minus, aux = np.empty(size), np.empty(size), np.empty(size // 3)
    for j in range(size):
        h = step * max(1.0, abs(y[j]))
        saved = y[j]
        y[j] = saved + h
        models.evaluate(problem, y, plus, aux)
        y[j] = saved - h
        models.evaluate(problem, y, minus, aux)
        y[j] = saved
        jac[:, j] = (plus - minus) / (2.0 * h)
    return jac
