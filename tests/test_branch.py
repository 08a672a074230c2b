"""Steady in-plane shapes (``stability.branch``): the bifurcation off the circle, Newton,
the continuation, the stability of the steady shapes, a run started on one, the CLI.

References are independent of the branch code: the circle's in-plane threshold from
the eigenvalues of its full linearisation (``stability.full_linear``), the right-hand side
itself (``loop_velocity`` through ``api.evaluate_maps``), the time integrator
(``loopsim.simulate``) and invariance under tilting.
"""
import functools
import json
import math

import numpy as np
import pytest

import loopsim
from loopsim import cli, diagnostics, spectral
from loopsim.stability import branch, full_linear

N = 6
Q_MAX = 12.0


@functools.lru_cache(maxsize=None)
def _halves(n=N, q_max=Q_MAX):
    """(upper, lower) halves of the branch: leaving towards q > q_c and q < q_c."""
    halves = [branch.continue_branch(n, q_max, side=s, q_min=8.0, max_points=80) for s in (1, -1)]
    return tuple(sorted(halves, key=lambda b: b.shapes[1].q, reverse=True))


def _nearest(shapes, q):
    return min(shapes, key=lambda s: abs(s.q - q))


def test_branch_starts_at_the_circles_in_plane_threshold():
    upper, lower = _halves()
    q_c = full_linear.critical_q(N, "in-plane")          # eigenvalue crossing of the circle's J
    assert abs(upper.q_bifurcation - q_c) < 1e-6
    assert abs(upper.q_bifurcation - 8.9011866906) < 1e-6   # docs/stability.md, n = 6
    # both halves leave the circle there: aspect ratio → 1 as q → q_c, q increases on one
    for half in (upper, lower):
        assert half.shapes[0].aspect_ratio == pytest.approx(1.0, abs=1e-14)
        assert abs(half.shapes[1].q - q_c) < 1e-2 and half.shapes[1].aspect_ratio < 1.01
    assert upper.shapes[2].q > q_c > lower.shapes[2].q


def test_newton_residual_against_the_right_hand_side():
    """Every branch point is a relative equilibrium: F(x) - V is uniform to round-off,
    checked with the public right-hand side, not with the Newton system."""
    upper, lower = _halves()
    for shape in upper.shapes[1::5] + lower.shapes[1::5]:
        u, _ = loopsim.evaluate_maps(shape.x, 3.0 * shape.q)
        shape_change = u.copy()
        shape_change[:, 0] = 0.0
        assert np.abs(shape_change).max() < 1e-11 * np.abs(u).max()
        assert shape.residual < 1e-12
        assert np.abs(u[1]).max() < 1e-14 * np.abs(u).max()   # stays in its plane
        assert shape.slide == 0.0 and abs(shape.velocity[0]) < 1e-12   # falls straight down
        assert shape.velocity[2] < 0.0


def test_full_newton_from_a_shifted_noisy_shape_finds_the_same_shape():
    """All phase conditions (no symmetry assumed): shift the parametrisation, add noise,
    move it; Newton returns to a steady shape with the same invariants."""
    upper, _ = _halves()
    shape = _nearest(upper.shapes, 10.0)
    n = shape.n
    shift = np.eye(2 * n + 1)
    for k in range(1, n + 1):            # s → s + 0.3: rotate each (a_k, b_k) pair
        c, s = math.cos(0.3 * k), math.sin(0.3 * k)
        shift[k, k], shift[k, n + k], shift[n + k, k], shift[n + k, n + k] = c, s, -s, c
    guess = shape.x @ shift.T + 1e-3 * np.random.default_rng(1).standard_normal(shape.x.shape)
    guess[:, 0] += 5.0
    found = branch.solve_steady(guess, shape.q)
    assert found.residual < 1e-12 and abs(found.slide) < 1e-10
    np.testing.assert_allclose(diagnostics.principal_axes(found.x)[0],
                               diagnostics.principal_axes(shape.x)[0], atol=1e-11)


def test_steady_shapes_do_not_depend_on_the_penalty():
    upper, _ = _halves()
    shape = _nearest(upper.shapes, 11.0)
    for w in (1.0, 100.0, 1000.0):
        r = branch.steady_residual(shape.x, shape.velocity, 0.0, shape.q, w)
        assert np.abs(r).max() < 1e-11 * np.abs(shape.velocity).max()


def test_tilted_steady_shape_is_steady_with_the_same_q():
    """The θ0 = 90° frame loses nothing: tilted to 30° with g0 = 3q / sin 30°, the shape
    still translates rigidly (its velocity gains only the uniform normal part)."""
    upper, _ = _halves()
    shape = _nearest(upper.shapes, 10.0)
    th = math.radians(30.0)
    x = branch.tilt_shape(shape.x, th)
    u, _ = loopsim.evaluate_maps(x, 3.0 * shape.q / math.sin(th))
    change = u.copy()
    change[:, 0] = 0.0
    assert np.abs(change).max() < 1e-10 * np.abs(u).max()
    assert diagnostics.tilt_deg(x) == pytest.approx(30.0, abs=1e-9)


def test_stability_at_the_circle_matches_the_circle_linearisation():
    """First point of the branch = the circle at q_c: in-plane rate 0, out-of-plane rate and
    all sector sizes as in ``stability.full_linear`` (2(n-2), 2n+3, 2(n-1))."""
    upper, _ = _halves()
    spec = branch.stability(upper.shapes[0], w_spectrum=10.0)
    q_c = upper.shapes[0].q
    ref = full_linear.sector_growth_rates([q_c], N)
    assert abs(spec["leading_in_plane"].real) < 1e-8
    assert spec["leading_out_of_plane"].real == pytest.approx(ref["out-of-plane"][0], abs=1e-9)
    assert spec["sizes"] == (2 * (N - 2), 2 * N + 3, 2 * (N - 1))
    assert spec["neutral_leak"] < 1e-12


def test_exchange_of_stability_and_neutral_modes_along_the_branch():
    """Transcritical: the half towards q > q_c is stable in its plane, the other unstable;
    the neutral modes stay exact (no extra zero rate: isolated shapes at fixed q)."""
    upper, lower = _halves()
    for shape in upper.shapes[3::6]:
        spec = branch.stability(shape)
        assert spec["leading_in_plane"].real < -1e-3
        assert spec["neutral_leak"] < 1e-11
        assert spec["sizes"] == (2 * (N - 2), 2 * N + 3, 2 * (N - 1))
    near = [s for s in lower.shapes[2:] if s.aspect_ratio < 1.2]
    assert near and all(branch.stability(s)["leading_in_plane"].real > 1e-3 for s in near)


def _run_from(shape, theta0_deg, t_end, perturbation=0.0):
    th = math.radians(theta0_deg)
    x0 = branch.tilt_shape(shape.x, th)
    result = loopsim.simulate(3.0 * shape.q / math.sin(th), initial=x0,
                              n=(x0.shape[1] - 1) // 2, t_span=(0.0, t_end),
                              method="radau5", rtol=1e-10, atol=1e-12, perturbation=perturbation,
                              seed=3)
    assert result.success
    return x0, result.x_final


def test_a_run_started_on_a_stable_steady_shape_stays_on_it():
    upper, _ = _halves()
    shape = _nearest(upper.shapes, 10.0)
    x0, x1 = _run_from(shape, 40.0, 3.0)
    np.testing.assert_allclose(diagnostics.principal_axes(x1)[0],
                               diagnostics.principal_axes(x0)[0], atol=1e-9)
    assert diagnostics.tilt_deg(x1) == pytest.approx(40.0, abs=1e-8)
    x1c, x0c = x1.copy(), x0.copy()
    x1c[:, 0] = x0c[:, 0] = 0.0
    np.testing.assert_allclose(x1c, x0c, atol=1e-8)     # the same parametrisation: c = 0


def test_a_run_started_on_the_unstable_half_leaves_it():
    """The control of the test above: the same kind of run from the half through q < q_c
    (in-plane rate > 0, a saddle between the circle and larger shapes) does leave it."""
    upper, lower = _halves()
    shape = max((s for s in lower.shapes if s.q < lower.shapes[0].q and s.aspect_ratio < 1.2),
                key=lambda s: s.aspect_ratio)
    x0, x1 = _run_from(shape, 90.0, 15.0, perturbation=1e-6)
    change = abs(diagnostics.aspect_ratio(x1) - diagnostics.aspect_ratio(x0))
    assert change > 1e-2


def test_q_loss_out_of_plane_brackets_a_sign_change():
    """The refined crossing of ``q_loss_out_of_plane`` is where the out-of-plane rate of
    steady shapes solved just below and above it changes sign (n = 6, window near it)."""
    upper = branch.upper_half(N, 30.0, step_max=1.0)
    rows = [dict(q=s.q, stable_in_plane=True,
                 leading_out_of_plane_real=branch.stability(s)["leading_out_of_plane"].real)
            for s in upper.shapes]
    q_loss = branch.q_loss_out_of_plane(rows, upper.shapes)
    assert q_loss is not None and 20.0 < q_loss < 30.0
    guess = _nearest(upper.shapes, q_loss)
    below = branch.solve_steady(guess.x, q_loss - 1e-4, symmetric=True)
    above = branch.solve_steady(guess.x, q_loss + 1e-4, symmetric=True)
    assert branch.stability(below)["leading_out_of_plane"].real < 0.0
    assert branch.stability(above)["leading_out_of_plane"].real > 0.0


def test_q_loss_out_of_plane_converges_in_n():
    """Continued from the circle at n = 8 (coarse steps: the crossing is refined by brentq),
    then followed to n = 10, 12, 14 from the resized shape: the differences shrink
    geometrically (measured: 0.674, 0.0485, 0.0015; n = 16 adds 3e-5)."""
    half = branch.upper_half(8, 38.0, step_max=1.0)
    rows = [dict(q=s.q, stable_in_plane=True,
                 leading_out_of_plane_real=branch.stability(s)["leading_out_of_plane"].real)
            for s in half.shapes]
    values = [branch.q_loss_out_of_plane(rows, half.shapes)]
    near = _nearest(half.shapes, values[0])
    for n in (10, 12, 14):
        values.append(branch.out_of_plane_loss_near(near, n, values[-1] - 1.0, values[-1] + 1.0))
    steps = np.abs(np.diff(values))
    assert np.all(steps[1:] < steps[:-1] / 5), values
    assert 30.0 < values[-1] < 45.0 and steps[-1] < 1e-2


def test_steady_branch_frame():
    frame = branch.steady_branch(5, 9.6)
    assert list(frame.columns) == list(branch.ROW_FIELDS)
    assert abs(frame.attrs["q_bifurcation"] - full_linear.critical_q(5, "in-plane")) < 1e-6
    circle_row = frame[frame.side == 0].iloc[0]
    assert circle_row.aspect_ratio == pytest.approx(1.0) and circle_row.q == frame.attrs["q_circle"]
    assert frame[frame.side == 1].stable_in_plane.all()
    assert not frame[(frame.side == -1) & (frame.aspect_ratio < 1.2)].stable_in_plane.any()


def test_cli_json(capsys):
    assert cli.main(["branch", "--n", "5", "--q-max", "10", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert {"q_bifurcation", "q_loss_out_of_plane", "branch"} <= set(out)
    assert abs(out["q_bifurcation"] - full_linear.critical_q(5, "in-plane")) < 1e-6
    assert out["q_loss_out_of_plane"] is None          # none below q = 10
    rows = out["branch"]
    for key in ("q", "aspect_ratio", "stable_in_plane", "stable_out_of_plane",
                "leading_in_plane_real", "leading_out_of_plane_real"):
        assert all(key in row for row in rows)
    upper = [r for r in rows if r["side"] == 1]
    assert upper and max(r["q"] for r in upper) >= 10.0
    assert all(r["stable_in_plane"] and r["stable_out_of_plane"] for r in upper)
    assert [r["side"] for r in rows] == sorted(r["side"] for r in rows)


@pytest.mark.parametrize("argv", [["--n", "3"], ["--q-max", "8"], ["--q-max", "nan"]])
def test_cli_bad_input_is_a_one_line_error(argv, capsys):
    try:
        code = cli.main(["branch", *argv])
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("loopsim: error:") and err.count("\n") == 1


def test_to_plane_recovers_a_tilted_steady_shape():
    upper, _ = _halves()
    shape = _nearest(upper.shapes, 10.0)
    x = branch.tilt_shape(shape.x, math.radians(25.0))
    x[:, 0] += [1.0, -2.0, 3.0]
    planar, theta, off = branch.to_plane(x)
    assert math.degrees(theta) == pytest.approx(25.0, abs=1e-10) and off < 1e-14
    np.testing.assert_allclose(diagnostics.principal_axes(planar)[0],
                               diagnostics.principal_axes(shape.x)[0], atol=1e-13)
    assert spectral.order_of(planar.shape[1]) == N
