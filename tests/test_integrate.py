"""The adaptive driver and the registered schemes on closed-form problems."""
import numpy as np
import pytest

from loopsim import integrators as I
from loopsim.integrators import explicit
from loopsim.integrators import radau as R
from loopsim.linalg import PIVOT_DTYPE
from loopsim.models import riccati

METHODS = sorted(I.METHODS.items())


RATES = np.array([1.0, -0.5, 0.3, 2.0])
Y0 = np.array([0.5, 1.0, -1.0, 0.1])


def run(method, t_end, t_out, rtol=1e-8, atol=1e-10, h_init=-1.0, h_min=0.0, h_max=np.inf,
        max_steps=100_000, rates=RATES, y0=Y0):
    y_out = np.full((len(t_out), len(y0)), np.nan)
    options = I.step_options(rtol, atol, h_init if h_init > 0 else None, h_min, h_max, max_steps)
    result = I.integrate(method, riccati.RiccatiProblem(rates), y0, 0.0, t_end,
                         np.asarray(t_out, float), options, y_out)
    return result, y_out


def test_fehlberg_tableau_is_consistent():
    np.testing.assert_allclose(explicit.RKF45_A.sum(axis=1), explicit.RKF45_C, atol=1e-15)
    assert abs(explicit.RKF45_B5.sum() - 1) < 1e-15 and abs(explicit.RKF45_B4.sum() - 1) < 1e-15
    # order conditions up to 4 for both weight sets (b·c^{q-1} = 1/q), 5 for B5
    for weights, order in ((explicit.RKF45_B5, 5), (explicit.RKF45_B4, 4)):
        for q in range(1, order + 1):
            assert abs(weights @ explicit.RKF45_C ** (q - 1) - 1 / q) < 1e-14
        assert abs(weights @ (explicit.RKF45_A @ explicit.RKF45_C) - 1 / 6) < 1e-14


@pytest.mark.parametrize("name, method", METHODS)
def test_a_run_without_output_times_takes_the_same_steps(name, method):
    """t_out = y_out = None compiles the driver without its output code: the end state
    and every count are those of the run asked for output inside the steps."""
    (status, t, y, counts, worst), y_out = run(method, 0.9, np.linspace(0.0, 0.9, 7))
    options = I.step_options(1e-8, 1e-10, None, 0.0, np.inf, 100_000)
    bare = I.integrate(method, riccati.RiccatiProblem(RATES), Y0, 0.0, 0.9, None, options, None)
    assert (bare[0], bare[1]) == (status, t)
    np.testing.assert_array_equal(bare[2], y)
    np.testing.assert_array_equal(bare[3], counts)
    np.testing.assert_array_equal(bare[4], worst)
    np.testing.assert_array_equal(y_out[-1], y)


@pytest.mark.parametrize("name, method", METHODS)
def test_adaptive_run_meets_tolerance_at_output_times(name, method):
    t_out = np.linspace(0.0, 0.9, 7)
    (status, t, y, counts, _), y_out = run(method, 0.9, t_out)
    n_acc, n_rhs = counts[0], counts[2]
    assert status == I.OK and t == 0.9
    exact = riccati.exact_solution(RATES[None], Y0[None], t_out[:, None])
    np.testing.assert_allclose(y_out, exact, rtol=1e-6, atol=1e-8)
    np.testing.assert_array_equal(y_out[-1], y)
    assert n_rhs >= 6 * n_acc


EXPLICIT = [(name, m) for name, m in METHODS if isinstance(m, I.Tableau)]


@pytest.mark.parametrize("name, method", EXPLICIT)
def test_fixed_step_order(name, method):
    """Global error of fixed steps (every step accepted) falls like h^5."""
    errors = []
    steps = [0.08, 0.04, 0.02]  # errors from 1e-10 down to 1e-13, above round-off
    y0 = np.array([0.2, 1.0, -1.0, 0.1])
    for h in steps:
        (status, t, y, counts, _), _ = run(method, 0.8, [], rtol=1e10, atol=1e10, h_init=h, h_max=h,
                                           y0=y0)
        assert status == I.OK and counts[0] == round(0.8 / h)
        errors.append(np.abs(y - riccati.exact_solution(RATES, y0, 0.8)).max())
    slopes = np.diff(np.log(errors)) / np.diff(np.log(steps))
    assert np.all(slopes > 4.7), slopes


@pytest.mark.parametrize("name, method", METHODS)
def test_error_falls_with_tolerance(name, method):
    errors = []
    for rtol in (1e-4, 1e-6, 1e-8, 1e-10):
        (status, t, y, *_), _ = run(method, 0.9, [], rtol=rtol, atol=rtol * 1e-2)
        errors.append(np.abs(y - riccati.exact_solution(RATES, Y0, 0.9)).max())
    assert errors[-1] < 1e-8 and all(b < a for a, b in zip(errors, errors[1:]))


@pytest.mark.parametrize("name, method", METHODS)
def test_status_codes(name, method):
    (status, t, *_), _ = run(method, 0.9, [], max_steps=5)
    assert status == I.STEP_BUDGET and t < 0.9
    (status, t, *_), _ = run(method, 0.9, [], h_min=0.5)
    assert status == I.STEP_UNDERFLOW
    # y' = y² from y = 1 blows up at t = 1: steps shrink until they underflow
    (status, t, y, *_), _ = run(method, 2.0, [], rates=np.array([1.0]), y0=np.array([1.0]))
    # (an implicit step may land a hair beyond the blow-up time)
    assert status in (I.STEP_UNDERFLOW, I.NON_FINITE) and 0.99 < t <= 1.0 + 1e-9
    (status, t, *_), _ = run(method, 1.0, [], y0=np.array([np.nan, 1.0, 1.0, 1.0]))
    assert status == I.NON_FINITE and t == 0.0


@pytest.mark.parametrize("name, method", METHODS)
def test_steady_state_stop(name, method):
    """y' = a y² with a < 0 decays like 1/(|a| t): its change per interval falls below
    the tolerance at a predictable time, and not before."""
    rates, y0 = np.array([-1.0]), np.array([1.0])
    options = I.step_options(1e-10, 1e-12, steady_interval=0.5, steady_tol=1e-3)
    status, t, y, *_ = I.integrate(method, riccati.RiccatiProblem(rates), y0, 0.0, 100.0,
                                   np.empty(0), options, np.empty((0, 1)))
    assert status == I.STEADY
    # y(t) = 1/(1+t): change over 0.5 is ≈ 0.5/(1+t)², below 1e-3 once t ≳ 21.4;
    # two quiet intervals in a row are needed, checked every ≥ 0.5
    assert 21.0 < t < 24.0


def test_radau_tableau_and_transformation():
    np.testing.assert_allclose(R.A.sum(axis=1), R.C, atol=1e-14)
    for q in range(1, 6):  # order 5: b·c^(q-1) = 1/q with b = last row of A
        assert abs(R.A[2] @ R.C ** (q - 1) - 1 / q) < 1e-14
    block = R.TI @ np.linalg.inv(R.A) @ R.T
    alpha, beta = R.MU_COMPLEX.real, -R.MU_COMPLEX.imag
    np.testing.assert_allclose(block, [[R.MU_REAL, 0, 0], [0, alpha, beta], [0, -beta, alpha]],
                               atol=1e-12)
    # the embedded weights equal scipy's closed form [-13 - 7√6, -13 + 7√6, -1] / 3
    s6 = np.sqrt(6)
    np.testing.assert_allclose(R.E, np.array([-13 - 7 * s6, -13 + 7 * s6, -1]) / 3, rtol=1e-12)


def test_radau_fixed_step_order():
    """Radau IIA steps of fixed h, Newton solved tightly: global error falls like h^5."""
    problem = riccati.RiccatiProblem(RATES)
    y0 = np.array([0.5, 1.0, -1.0, 0.4])  # errors 1e-6 .. 1e-9, above round-off
    errors, steps = [], [0.4, 0.2, 0.1]
    n = y0.size
    for h in steps:
        y = y0.copy()
        f, work_y, work_f = np.empty(n), np.empty(n), np.empty(n)
        jac = np.empty((n, n))
        lu_r, lu_c = np.empty((n, n)), np.empty((n, n), complex)
        piv_r, piv_c = np.empty(n, PIVOT_DTYPE), np.empty(n, PIVOT_DTYPE)
        z, w, fz = np.zeros((3, n)), np.empty((3, n)), np.empty((3, n))
        real_rhs, complex_rhs = np.empty(n), np.empty(n, complex)
        for _ in range(round(0.8 / h)):
            f[:] = RATES * y * y
            jac[:] = np.diag(2.0 * RATES * y)  # the exact Jacobian of F = RATES y²
            R.newton_matrices(jac, h, lu_r, piv_r, lu_c, piv_c)
            z[:] = 0.0
            for _ in range(20):  # restart from the last iterate until tightly converged
                converged, *_ = R.solve_collocation(problem, y, h, z, np.full(n, 1e-14), 1e-2, 0.0, R.NEWTON_MAXITER,
                                                      lu_r, piv_r, lu_c, piv_c, w, fz, work_y,
                                                      real_rhs, complex_rhs)
                if converged:
                    break
            assert converged
            y = y + z[2]
        errors.append(np.abs(y - riccati.exact_solution(RATES, y0, 0.8)).max())
    slopes = np.diff(np.log(errors)) / np.diff(np.log(steps))
    assert np.all(slopes > 4.5), (errors, slopes)


def test_terminal_precision_script_compares_policies_and_restores_the_method_table(tmp_path, monkeypatch):
    """scripts/terminal_precision.py swaps the Radau policy in integrators.METHODS for each
    run: its rows carry the policy asked for, errors against the reference run, and the
    table holds the default method again afterwards (also on the way out of an error)."""
    import os
    import runpy
    import sys

    import pandas as pd

    out = tmp_path / "tp.parquet"
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    monkeypatch.setattr(sys, "argv", [
        "terminal_precision.py", "--cases", "60:30:4", "--rtols", "1e-4,1e-6", "--ref-rtol", "1e-8",
        "--t-end", "0.2", "--newton-maxiter", "6,3", "--out", str(out)])
    script = runpy.run_path(os.path.join(root, "scripts", "terminal_precision.py"))
    script["main"]()
    assert I.METHODS["radau5"] is R.RADAU5
    rows = pd.read_parquet(out)
    assert rows["reference"].sum() == 1
    runs = rows[~rows["reference"]]
    assert sorted(runs["newton_maxiter"]) == [3, 3, 6, 6]
    tight = runs[runs["rtol"] == 1e-6]
    loose = runs[runs["rtol"] == 1e-4]
    assert (tight["d_aspect"].max() < loose["d_aspect"].max()) and tight["d_aspect"].max() < 1e-5
    monkeypatch.setattr(sys, "argv", ["terminal_precision.py", "--cases", "60:30:4", "--rtols", "-1"])
    with pytest.raises(ValueError, match="rtol"):
        script["main"]()
    assert I.METHODS["radau5"] is R.RADAU5
