"""radau5's step control punishes no tolerance: counted on short hard runs.

Counts (nfev, accepted and rejected steps) are deterministic, so these are exact
checks.  The runs are the early, flipping part of 3D loops (t ≤ 2), where the
error estimate allows steps at loose rtol at which the simplified Newton iteration
no longer converges, and a start whose centroid sits at zero, where a tiny atol asks
the Newton test for accuracy below rounding (benchmarks/bench_step_control.py
prints the whole picture over rtol 1e-3 ... 1e-12).
"""
import warnings

import pytest

import loopsim
from loopsim import api
from loopsim.integrators import control
from loopsim.integrators import radau as R


def counts(g0, theta0, n, t_end, rtol, atol=None):
    kwargs = {} if atol is None else dict(atol=atol)
    with warnings.catch_warnings():  # short runs are "not resolved": not the subject here
        warnings.simplefilter("ignore", api.LoopsimWarning)
        result = loopsim.simulate(g0, theta0, n=n, t_span=(0.0, t_end), rtol=rtol,
                                  method="radau5", twin=False, **kwargs)
    assert result.success
    return result.nfev, result.steps_accepted, result.steps_rejected


@pytest.mark.parametrize("case", [(150, 45, 16, 2.0), (100, 60, 16, 2.0)])
def test_a_looser_rtol_costs_no_more_and_rejects_few_steps(case):
    """rtol 1e-3, 1e-4, 1e-5 (default atol): nfev falls as rtol loosens, and rejected
    steps stay within a quarter of the accepted ones.  Before the Newton limit, at
    (150, 45°, 16): nfev 9 314, 8 341, 9 340 with 298 rejected of 557 accepted at 1e-3,
    almost all Newton failures."""
    runs = [counts(*case, rtol) for rtol in (1e-3, 1e-4, 1e-5)]
    nfev = [r[0] for r in runs]
    assert nfev[0] <= nfev[1] <= nfev[2], runs
    for _, accepted, rejected in runs:
        assert rejected <= 0.25 * accepted, runs


def test_a_tiny_atol_does_not_stall_the_newton_iteration():
    """atol 1e-17 (pure relative control on the start's zero centroid): cost grows
    smoothly as rtol tightens, with few rejections.  The previous step control, with no
    rounding floor on the error weights, took 250 050 RHS evaluations and 15 638 rejected
    steps at rtol 1e-10, against 29 498 (886 rejected) at 1e-9 and 38 461 at 1e-11."""
    runs = [counts(150, 45, 16, 0.05, rtol, atol=1e-17) for rtol in (1e-9, 1e-10, 1e-11)]
    nfev = [r[0] for r in runs]
    assert nfev[0] <= nfev[1] <= nfev[2] <= 3 * nfev[0], runs
    for _, accepted, rejected in runs:
        assert rejected <= 0.05 * accepted, runs


def test_step_proposal_takes_the_smaller_limit_and_no_growth_after_a_rejection():
    """The error limit, the Newton limit (target/rate)^(1/order), no growth right after a
    rejection, and the hold of h (and the LU factors) below HOLD_FACTOR."""
    method = R.RADAU5
    assert R.newton_limit(-1.0, method.rate_target, method.rate_order) == control.MAX_FACTOR
    limit = R.newton_limit(0.8, method.rate_target, method.rate_order)
    assert limit == pytest.approx((method.rate_target / 0.8) ** (1 / method.rate_order))
    # error limit 3: a fast Newton (rate 1e-3) lets it through, a slow one (0.8) cuts it
    assert R.step_proposal(method, 3.0, 1.0, 1e-3, False, True) == pytest.approx(3.0)
    assert R.step_proposal(method, 3.0, 1.0, 0.8, False, True) == pytest.approx(limit)
    assert R.step_proposal(method, 3.0, 1.0, 1e-3, True, True) == method.rejected_growth
    assert R.step_proposal(method, 1.1, 1.0, 1e-3, False, False) == 1.0  # hold h
    assert R.step_proposal(method, 50.0, 1.0, -1.0, False, True) == control.MAX_FACTOR


def test_tight_tolerances_cost_at_most_3x_a_decade():
    """rtol 1e-8 ... 1e-11 with atol = rtol/1000 over t <= 10 at (150, 45°, 21), where the
    loop nears its steady state and the Newton corrections sink into rounding: each decade
    costs at most 3x the one before, and a looser rtol never costs more.  Before (0.3.0):
    nfev 21 176, 148 712, 1 699 786 and 2 200 884 (7.0x, 11.4x): the noise's contraction
    "rate" capped the step, and Newton failures in the noise halved it."""
    nfev = [counts(150, 45, 21, 10.0, rtol, atol=rtol * 1e-3)[0]
            for rtol in (1e-8, 1e-9, 1e-10, 1e-11)]
    for looser, tighter in zip(nfev, nfev[1:]):
        assert looser <= tighter <= 3 * looser, nfev


def test_tight_rtols_with_the_default_atol_cost_about_the_same():
    """With the default atol (1e-9) the weights of the small coefficients stay at atol, so
    rtol 1e-8 ... 1e-11 cost about the same: each decade at most 3x, the tightest at most
    1.5x the loosest.  (Measured: 10 406, 11 613, 12 353, 11 793 RHS evaluations: rtol
    1e-11 costs 4 % less than 1e-10, its Newton tolerance being 10 eps / rtol.)"""
    nfev = [counts(150, 45, 21, 10.0, rtol, atol=1e-9)[0]
            for rtol in (1e-8, 1e-9, 1e-10, 1e-11)]
    for looser, tighter in zip(nfev, nfev[1:]):
        assert tighter <= 3 * looser, nfev
    assert nfev[-1] <= 1.5 * nfev[0], nfev


def test_the_newton_limit_ignores_rates_measured_in_the_noise():
    """solve_collocation reports as ``limit_rate`` only rates whose previous correction
    was above NOISE_MARGIN times the stated rounding noise.  On the Riccati test model
    (loopsim.models.riccati), restarted from converged stages (corrections below the
    Newton tolerance 1e-3): with no noise stated the rate it measures counts; with a
    noise of 1e-3 (corrections within 10x of it) it is measured and does not count."""
    import numpy as np
    from loopsim.models import riccati
    from loopsim.linalg import PIVOT_DTYPE

    rates = np.array([-1.0, -10.0, 1.0, 0.5])
    problem = riccati.RiccatiProblem(rates)
    y = np.array([0.5, 1.0, -1.0, 0.4])
    n, h, tol = y.size, 0.05, 1e-3
    f = rates * y * y
    jac = np.diag(2 * rates * y)
    lu_r, lu_c = np.empty((n, n)), np.empty((n, n), complex)
    piv_r, piv_c = np.empty(n, PIVOT_DTYPE), np.empty(n, PIVOT_DTYPE)
    R.newton_matrices(jac, h, lu_r, piv_r, lu_c, piv_c)
    z, w, fz = np.zeros((3, n)), np.empty((3, n)), np.empty((3, n))
    work = (w, fz, np.empty(n), np.empty(n), np.empty(n, complex))
    scale = np.full(n, 1e-6)
    converged, *_ = R.solve_collocation(problem, y, h, z, scale, tol, 0.0, 50, lu_r, piv_r,
                                        lu_c, piv_c, *work)
    assert converged
    start = z.copy()
    converged, iterations, rate, limit_rate = R.solve_collocation(
        problem, y, h, z, scale, tol, 0.0, 50, lu_r, piv_r, lu_c, piv_c, *work)
    assert converged and rate >= 0 and limit_rate == rate
    z[:] = start
    converged, iterations, rate, limit_rate = R.solve_collocation(
        problem, y, h, z, scale, tol, 1e-3, 50, lu_r, piv_r, lu_c, piv_c, *work)
    assert converged and rate >= 0 and limit_rate == -1.0


#: Compiled unit costs in RHS evaluations at n = 32 on an idle machine (docs/studies/performance.md:
#: F 0.11 ms, J 3.7 ms, the LU pair 1.5 ms), to weigh counts into one cost.
J_IN_F, LU_PAIR_IN_F = 34, 14


def priced_counts(g0, theta0, n, t_end, rtol, point):
    """radau5 with ``jacobian_point`` = point from the seeded start: (cost in RHS
    evaluations, nfev, njev, nlu)."""
    import numpy as np
    from loopsim import defaults, integrators, shapes
    from loopsim.models import local_sbt

    problem = local_sbt.make_problem(n, g0, defaults.DEFAULT_W)
    x0 = shapes.initial_shape(n, np.radians(theta0), defaults.DEFAULT_PERTURBATION, 0)
    method = integrators.RADAU5._replace(jacobian_point=point)
    status, _, _, counts, _ = integrators.integrate(
        method, problem, x0.reshape(-1).copy(), 0.0, t_end, None,
        integrators.step_options(rtol, rtol * 1e-3), None)
    assert status == control.OK
    nfev, njev, nlu = (int(c) for c in counts[2:])
    return nfev + J_IN_F * njev + LU_PAIR_IN_F * nlu, nfev, njev, nlu


@pytest.mark.parametrize("case", [(150, 45, 12, 0.5), (350, 18, 16, 0.1)])
def test_the_jacobian_inside_the_step_costs_no_more_than_at_y(case):
    """The Jacobian at RADAU5.jacobian_point of the step (on the last step's collocation
    polynomial) against at y (jacobian_point 0, Hairer's and scipy's): no more Jacobians,
    LU factorisations or priced cost at rtol 1e-3 and 1e-6, on a well-posed flipping loop
    and on the start of a tumbling one (at (350, 18°, 32) priced 0.61-0.85x,
    benchmarks/bench_tumbling.py).
    Measured (cost in F): 9 742 -> 7 823 at rtol 1e-3 and 24 700 -> 21 378 at 1e-6 on the
    first, 2 577 -> 1 971 and 5 441 -> 4 336 on the second."""
    assert R.RADAU5.jacobian_point > 0.0
    for rtol in (1e-3, 1e-6):
        old = priced_counts(*case, rtol, 0.0)
        new = priced_counts(*case, rtol, R.RADAU5.jacobian_point)
        assert new[0] <= old[0] and new[2] <= old[2] and new[3] <= old[3], (rtol, old, new)


def test_the_jacobian_state_is_the_last_steps_polynomial_extrapolated():
    """jacobian_state(y, q, r) = y + Σ_k q_k ((1 + r)^(k+1) - 1), against NumPy's
    polynomial evaluation; y itself at r = 0."""
    import numpy as np

    rng = np.random.default_rng(1)
    y, q = rng.normal(size=5), rng.normal(size=(3, 5))
    out = np.empty(5)
    for ratio in (0.0, 0.3, 0.578 * 2.5):
        R.jacobian_state(y, q, ratio, out)
        x = 1.0 + ratio
        expected = y + np.polynomial.polynomial.polyval(x, np.vstack([np.zeros(5), q]))
        expected -= np.polynomial.polynomial.polyval(1.0, np.vstack([np.zeros(5), q]))
        np.testing.assert_allclose(out, expected, rtol=1e-13, atol=1e-13)
