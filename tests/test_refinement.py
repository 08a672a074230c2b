"""Automatic truncation (``n="auto"``, loopsim.refinement): the monitor, exact
zero-padding on a change of n, a one-order ladder equal to the fixed-n driver, and the
tail control's convergence to a fixed high-n run."""
import numpy as np
import pytest

import loopsim
from loopsim import diagnostics, integrators, models, refinement, shapes, spectral
from loopsim.integrators.control import REFINE

RADAU = integrators.METHODS["radau5"]


def _options(**extra):
    return integrators.step_options(1e-6, 1e-9, max_steps=200_000, constraint_tol=0.1, **extra)


def test_ladder_orders():
    assert refinement.orders(6, 32) == (6, 8, 12, 16, 20, 24, 32)
    assert refinement.orders(6, 6) == (6,)
    assert refinement.orders(10, 14) == (10, 12, 14)
    with pytest.raises(ValueError, match="n_max"):
        refinement.orders(8, 6)


def test_spectral_tail_kernel_matches_the_diagnostic(rng):
    for n in (2, 3, 6, 11):
        x = rng.standard_normal((3, 2 * n + 1)) / (1 + np.arange(2 * n + 1))
        assert models.local_sbt.spectral_tail(x) == pytest.approx(
            diagnostics.spectral_tail(x, n), rel=1e-14)
        assert models.local_sbt.top_mode_share(x) == pytest.approx(
            diagnostics.top_mode_share(x, n), rel=1e-14)


def test_zero_padding_is_exact(rng):
    x = rng.standard_normal((3, 13))
    padded = spectral.resize(x, 16)
    s = np.linspace(0, 2 * np.pi, 57)
    np.testing.assert_array_equal(spectral.resize(padded, 6), x)
    np.testing.assert_allclose(spectral.evaluate(padded, s), spectral.evaluate(x, s),
                               rtol=0, atol=1e-14)


def test_driver_stops_with_refine_when_the_tail_passes_the_tolerance():
    """The n = 6 start zero-padded to n = 8 has no tail; the 3D transient (q = 43) fills
    the top modes, and the driver stops once their share passes the tolerance."""
    x0 = spectral.resize(shapes.start_shape(60.0, 6, 1e-3, 0)[0], 8)
    assert models.local_sbt.spectral_tail(x0) == 0.0
    tol = 1e-3
    problem = models.local_sbt.make_problem(8, 150.0, 10.0)
    no_output = np.empty(0)
    status, t, y, counts, worst = integrators.integrate(
        RADAU, problem, x0.ravel(), 0.0, 10.0, no_output, _options(resolution_tol=tol),
        np.empty((0, x0.size)))
    assert status == REFINE and 0.0 < t < 10.0
    assert models.local_sbt.spectral_tail(y.reshape(3, -1)) > tol
    assert worst[1] > tol
    # without a tolerance the same run goes on past that time
    status_free, t_free, *_ = integrators.integrate(
        RADAU, problem, x0.ravel(), 0.0, t, no_output, _options(), np.empty((0, x0.size)))
    assert status_free == integrators.OK and t_free == t


def test_spectral_tail_is_relative_to_the_deformation():
    """The tail is the top modes' share of the deformation (modes k >= 2), floored at
    DEFORMATION_FLOOR of the loop's size: the same top modes weigh more on a less
    deformed loop, and an exact circle has none."""
    from loopsim.defaults import DEFORMATION_FLOOR

    circle = shapes.inclined_circle(6, 0.3)  # E_1 = 1
    assert diagnostics.spectral_tail(circle, 6) == 0.0

    def expected(a, b):  # mode 2 of amplitude a, mode 6 of amplitude b: E_k = a^2 / 2 ...
        e2, e6 = a * a / 2, b * b / 2
        return np.sqrt(e6 / (e2 + e6 + DEFORMATION_FLOOR**2 * (1.0 + e2 + e6)))

    shape = circle.copy()
    for a in (1e-1, 1e-2, 0.0):
        shape[2, 2], shape[2, 6] = a, 1e-5
        assert diagnostics.spectral_tail(shape, 6) == pytest.approx(expected(a, 1e-5), rel=1e-12)
        assert models.local_sbt.spectral_tail(shape) == pytest.approx(expected(a, 1e-5),
                                                                        rel=1e-12)
    # 1e-4 and 1e-3 of deformations 1e-1 and 1e-2 (a 1e-5 top mode); without one, b / floor
    assert expected(1e-1, 1e-5) == pytest.approx(1e-4, rel=1e-3)
    assert expected(1e-2, 1e-5) == pytest.approx(1e-3, rel=2e-2)
    assert expected(0.0, 1e-5) == pytest.approx(1e-5 / DEFORMATION_FLOOR / np.sqrt(2), rel=1e-3)


def test_recorded_tail_counts_growth_not_the_relaxing_seeded_modes():
    """A stable loop's seeded top modes decay from the start (a share 0.24 of the
    deformation at n = 6): the recorded tail_max counts the tail only once the top modes
    grow, so the stable loop's stays tiny while an in-plane loop's (q = 10: the top
    modes grow with the deformation, to a share of 0.05 at n = 6) is recorded."""
    x0 = shapes.start_shape(30.0, 6, 1e-3, 0)[0]
    assert models.local_sbt.spectral_tail(x0) > 0.2
    stable = refinement.integrate_case(RADAU, 30.0, 10.0, x0, 0.0, 3.0, np.empty(0),
                                       _options(), (6,), 1.0)
    assert stable[0] == integrators.OK and stable[5][1] < 1e-8
    in_plane = refinement.integrate_case(RADAU, 60.0, 10.0, x0, 0.0, 3.0, np.empty(0),
                                         _options(), (6,), 1.0)
    assert in_plane[5][1] > 1e-4


def test_one_order_ladder_is_the_fixed_driver_bit_for_bit():
    x0 = shapes.start_shape(45.0, 6, 1e-3, 3)[0]
    t_eval = np.linspace(0.0, 1.0, 5)
    y_out = np.full((5, x0.size), np.nan)
    fixed = integrators.integrate(RADAU, models.local_sbt.make_problem(6, 80.0, 10.0),
                                  x0.ravel(), 0.0, 1.0, t_eval, _options(), y_out)
    status, t, x, n_used, counts, worst, x_out = refinement.integrate_case(
        RADAU, 80.0, 10.0, x0, 0.0, 1.0, t_eval, _options(), (6,), 1e-12)
    assert status == fixed[0] and t == fixed[1] and n_used == 6
    np.testing.assert_array_equal(x.ravel(), fixed[2])
    np.testing.assert_array_equal(counts, fixed[3])
    np.testing.assert_array_equal(worst, fixed[4][:2])
    np.testing.assert_array_equal(x_out.reshape(5, -1), y_out)


def test_auto_run_is_the_fixed_run_at_n_used_from_the_same_start():
    """Each change of n restarts from the start, zero-padded: the auto result (final
    state, outputs, tail) is the fixed-order run at n_used from that start, bit for
    bit, and its cost counts every level's work."""
    x0 = shapes.start_shape(60.0, 6, 1e-3, 0)[0]
    t_eval = np.array([0.0, 0.3, 1.0])
    status, t_final, x, n_used, counts, worst, x_out = refinement.integrate_case(
        RADAU, 150.0, 10.0, x0, 0.0, 1.0, t_eval, _options(), (6, 8, 12, 16), 1e-4)
    assert n_used > 8 and t_final == 1.0 and status == integrators.OK
    padded = spectral.resize(x0, n_used)
    y_out = np.full((3, padded.size), np.nan)
    with refinement.one_blas_thread():  # as every integration runs (BLAS rounding)
        fixed = integrators.integrate(
            RADAU, models.local_sbt.make_problem(n_used, 150.0, 10.0), padded.ravel(), 0.0,
            1.0, t_eval, _options(), y_out)
    np.testing.assert_array_equal(x.ravel(), fixed[2])
    np.testing.assert_array_equal(x_out.reshape(3, -1), y_out)
    np.testing.assert_array_equal(worst, fixed[4][:2])
    assert np.all(counts >= fixed[3]) and counts[2] > fixed[3][2]  # lower levels' work


def test_tail_control_converges_to_the_fixed_high_order_run():
    """In-plane loop (g0 = 60, θ0 = 30°, q = 10): as the tolerance shrinks, the auto run
    climbs and its terminal aspect ratio approaches the fixed n = 20 run from the same
    curve (measured: n_used 8, 12, 16 at tolerances 0.1, 1e-3, 1e-5; errors 6.5e-4,
    2.1e-7, 3.4e-10)."""
    x0 = shapes.start_shape(30.0, 6, 1e-3, 0)[0]
    t_end = 4.0
    reference = refinement.integrate_case(RADAU, 60.0, 10.0, x0, 0.0, t_end, np.empty(0),
                                          _options(), (20,), 1.0)
    aspect_ref = diagnostics.aspect_ratio(reference[2])
    errors, orders = [], []
    for tol in (0.1, 1e-3, 1e-5):
        _, t, x, n_used, *_ = refinement.integrate_case(
            RADAU, 60.0, 10.0, x0, 0.0, t_end, np.empty(0), _options(), (6, 8, 12, 16, 20), tol)
        assert t == t_end
        errors.append(abs(diagnostics.aspect_ratio(x) - aspect_ref))
        orders.append(n_used)
    assert orders == [8, 12, 16]
    assert errors[2] < 1e-8 and errors[1] < 1e-5 < 1e-4 < errors[0]
    assert errors[2] < errors[1] / 100 and errors[1] < errors[0] / 100


def test_models_without_truncation_never_refine():
    problem = models.riccati.RiccatiProblem(np.array([-1.0, -2.0]))
    options = integrators.step_options(1e-8, 1e-10, resolution_tol=0.0)
    status, *_ = integrators.integrate(RADAU, problem, np.array([1.0, 0.5]), 0.0, 1.0,
                                       np.empty(0), options, np.empty((0, 2)))
    assert status == integrators.OK


def test_simulate_auto_records_the_order_reached_and_the_method():
    result = loopsim.simulate(150.0, 60.0, n="auto", n_max=12, method="auto",
                              t_span=(0.0, 0.3), snapshots=3)
    assert result.method == "radau5" and result.inputs["n"] == 6
    assert result.n_used in (8, 12) and result.x.shape == (3, 3, 2 * result.n_used + 1)
    assert result.tail_max > 0
    summary = result.summary()
    assert summary["n_used"] == result.n_used and summary["method"] == "radau5"
    with pytest.raises(ValueError, match="n"):
        loopsim.simulate(150.0, 60.0, n="automatic")
    with pytest.raises(ValueError, match="n_max must be at most 128"):
        loopsim.simulate(150.0, 60.0, n="auto", n_max=200)
    with pytest.raises(ValueError, match="tail_tol"):
        loopsim.simulate(150.0, 60.0, n=6, tail_tol=0.0)  # checked even for a fixed n
    with pytest.raises(ValueError, match="n_start applies only"):
        loopsim.simulate(150.0, 60.0, n=8, n_start=6)


def test_auto_method_by_expected_regime():
    assert refinement.auto_method(20.0, 6, False) == "rkf45"  # 3D expected at n = 6
    assert refinement.auto_method(5.0, 6, False) == "radau5"  # stable
    assert refinement.auto_method(20.0, 16, False) == "radau5"  # stiff at high n
    assert refinement.auto_method(20.0, 6, True) == "radau5"  # climbs


def blas_threads():
    from threadpoolctl import threadpool_info

    return {i["filepath"]: i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"}


def test_blas_limit_belongs_to_its_first_holder():
    """The limit is process-wide: a sweep's worker thread entering it while the sweep
    holds it changes nothing, and the sweep's exit restores the caller's setting even
    while a worker abandoned after an interrupt is still inside."""
    import threading

    from threadpoolctl import threadpool_limits

    entered, leave = threading.Event(), threading.Event()

    def worker():
        with refinement.one_blas_thread():
            entered.set()
            leave.wait(10)

    with threadpool_limits(limits=2, user_api="blas"):
        with refinement.one_blas_thread():
            thread = threading.Thread(target=worker)
            thread.start()
            assert entered.wait(10)
            assert set(blas_threads().values()) == {1}
        assert set(blas_threads().values()) == {2}  # restored; the worker is still inside
        leave.set()
        thread.join()
        assert set(blas_threads().values()) == {2}
        with refinement.one_blas_thread():  # free again for the next holder
            assert set(blas_threads().values()) == {1}
        assert set(blas_threads().values()) == {2}


def test_integrations_run_with_one_blas_thread(monkeypatch):
    """Both entry points hold BLAS to one thread while the kernels run (the cases are
    parallel already; loopsim._blas), and restore the user's setting afterwards."""
    from threadpoolctl import threadpool_limits

    seen = []

    def recording(real):
        def wrapped(*args, **kwargs):
            seen.append(blas_threads())
            return real(*args, **kwargs)
        return wrapped

    monkeypatch.setattr(refinement.integrators, "integrate",
                        recording(refinement.integrators.integrate))
    monkeypatch.setattr(refinement.batch, "integrate_batch",
                        recording(refinement.batch.integrate_batch))
    x0 = shapes.start_shape(30.0, 4, 1e-3, 0)[0]
    with threadpool_limits(limits=2, user_api="blas"):
        before = blas_threads()
        refinement.integrate_case(RADAU, 30.0, 10.0, x0, 0.0, 0.1, np.empty(0), _options(),
                                  (4,), 1.0)
        refinement.integrate_cases(RADAU, [(30.0, 10.0)], [x0], 0.1, _options(), (4,), 1.0)
        after = blas_threads()
    assert before and len(seen) == 2
    assert all(set(s.values()) == {1} for s in seen)
    assert after == before and set(before.values()) == {2}
