"""Tests for loopsim.stability.full_linear: the Jacobian of loopsim's own RHS about the
translating circle, its neutral modes, sectors, thresholds and the comparison
with the paper's operator.

Independent references: central differences of ``physics.loop_velocity``; the
rigid-circle velocity u0(θ0) (rotations must map to its derivatives); the
closed-form free-ring rates -k²(k²-1) (out of plane) and
-2k²(k²-1)²/(2k²+1) (in plane, derived in docs/stability.md); the corrected
operator -∂⁴ - ∂² + q(sin s ∂ + cos s ∂²) in closed form (n = 3: q_c = 12).
"""
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from loopsim import api, shapes
from loopsim.stability import full_linear as fs
from loopsim.stability import onset, paper
from loopsim.cli import main

Q_IN = 8.9000904456      # in-plane critical q (converged, see docs/stability.md)
Q_OUT = 10.6493156061    # out-of-plane critical q


def _central_fd(x, g0, w, h):
    """(u(x + h e) - u(x - h e)) / 2h for every coordinate e of x.ravel()."""
    jac = np.empty((x.size, x.size))
    for i in range(x.size):
        e = np.zeros(x.size)
        e[i] = h
        up, _ = api.evaluate_maps(x + e.reshape(x.shape), g0, w)
        um, _ = api.evaluate_maps(x - e.reshape(x.shape), g0, w)
        jac[:, i] = ((up - um) / (2.0 * h)).ravel()
    return jac


def _richardson_fd(x, g0, w, h=2e-5):
    return (4.0 * _central_fd(x, g0, w, h / 2) - _central_fd(x, g0, w, h)) / 3.0


@pytest.mark.parametrize("shape", ["circle", "perturbed"])
def test_jacobian_matches_finite_differences(shape):
    n, g0, w, th = 5, 40.0, 10.0, math.radians(35.0)
    x = (shapes.inclined_circle(n, th) if shape == "circle"
         else shapes.initial_shape(n, th, 0.05, 3))   # a shape with a nonzero tension residual
    jac = fs.rhs_jacobian(x, g0, w)
    scale = np.abs(jac).max()
    assert np.abs(jac - _central_fd(x, g0, w, 1e-6)).max() < 1e-7 * scale
    assert np.abs(jac - _richardson_fd(x, g0, w)).max() < 1e-10 * scale


def test_neutral_modes_are_neutral_to_round_off():
    n, g0, theta = 10, 50.0, 35.0
    th = math.radians(theta)
    res = {r["mode"]: r for r in fs.neutral_mode_residuals(n, g0, theta)}
    expected = dict(zip(fs.NEUTRAL_NAMES, [
        np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3),
        # rotating about a = e_x tilts the circle: J v = du0/dθ0
        -np.array([0.0, g0 * math.cos(2 * th) / 3.0, g0 * math.sin(2 * th) / 3.0]),
        # rotation about the vertical is a symmetry: J(e_z × x0) = e_z × u0, e_z = sinθ b + cosθ e_n
        np.array([g0 * math.cos(th) / 3.0, 0.0, 0.0]),
    ]))
    for name, r in res.items():
        assert r["residual"] < 1e-10, name                 # J v is a constant (a translation)
        np.testing.assert_allclose(r["velocity"], expected[name], rtol=0, atol=1e-10)
    for name in fs.NEUTRAL_NAMES[:3]:
        assert res[name]["residual"] == 0.0 and not np.any(res[name]["velocity"])
    lin = fs.linearise_circle(n, g0, theta)
    assert lin.diagnostics["neutral_leak"] < 1e-14          # N is J-invariant
    spec = fs.full_spectrum(g0, theta, 6)
    assert np.sum(spec.sector == "neutral") == 6


def test_sectors_are_block_triangular():
    """In-plane never drives out-of-plane; out-of-plane drives in-plane iff θ0 < 90°."""
    tilted = fs.linearise_circle(8, 45.0, 35.0)
    upright = fs.linearise_circle(8, 45.0 * math.sin(math.radians(35.0)), 90.0)
    for lin in (tilted, upright):
        assert lin.diagnostics["in_to_out_coupling"] < 1e-14
        assert lin.diagnostics["ker_E_leak"] < 1e-13        # inextensible modes stay inextensible
        assert lin.sizes == {"in-plane": 2 * (8 - 2), "stretch": 2 * 8 + 3, "out-of-plane": 2 * (8 - 1)}
    assert tilted.diagnostics["out_to_in_coupling"] > 1e-3
    assert upright.diagnostics["out_to_in_coupling"] < 1e-15
    # same q: identical sector spectra
    for s in ("in-plane", "out-of-plane"):
        a = np.sort_complex(np.linalg.eigvals(tilted.blocks[s]))
        b = np.sort_complex(np.linalg.eigvals(upright.blocks[s]))
        np.testing.assert_allclose(a, b, rtol=1e-10)


@pytest.mark.parametrize("g0, theta", [(0.0, 40.0), (25.0, 0.0)])
def test_q0_spectrum_is_the_free_ring(g0, theta):
    """q = 0 (no gravity, or gravity normal to the plane): closed-form ring rates."""
    n, w = 9, 10.0
    spec = fs.full_spectrum(g0, theta, n, w)
    k_out = np.arange(2, n + 1.0)
    k_in = np.arange(2, n + 0.0)
    ref = {"out-of-plane": -k_out**2 * (k_out**2 - 1),
           "in-plane": -2 * k_in**2 * (k_in**2 - 1) ** 2 / (2 * k_in**2 + 1)}
    for sector, rates in ref.items():
        got = np.sort(spec.eigenvalues[spec.sector == sector].real)[::-1]
        np.testing.assert_allclose(got, np.sort(np.repeat(rates, 2))[::-1], rtol=1e-11)
        np.testing.assert_allclose(got, fs.free_ring_rates(n, sector), rtol=1e-11)
        assert np.abs(spec.eigenvalues[spec.sector == sector].imag).max() < 1e-9
    stretch = np.sort(spec.eigenvalues[spec.sector == "stretch"].real)[::-1]
    np.testing.assert_allclose(stretch[:2 * n + 1], -2 * w, rtol=1e-10)   # length penalty
    assert np.all(stretch[2 * n + 1:] < -1000)                          # unresolved stretch


def test_stretch_modes_are_penalty_artefacts():
    """Changing w moves only the stretch modes (to -2w); physical sectors are unchanged."""
    n, q = 8, 7.0
    a = fs.sector_growth_rates([q], n, 60.0, w=10.0)
    b = fs.sector_growth_rates([q], n, 60.0, w=40.0)
    for s in fs.SECTORS:
        assert a[s][0] == pytest.approx(b[s][0], rel=1e-10)
    assert a["stretch"][0] == pytest.approx(-20.0, rel=1e-10)
    assert b["stretch"][0] == pytest.approx(-80.0, rel=1e-10)
    assert fs.critical_q(n, "in-plane", w=40.0) == pytest.approx(fs.critical_q(n, "in-plane"), rel=1e-10)


def test_jacobian_is_affine_in_g0():
    lin = fs.linearise_circle(9, 3 * 7.3 / math.sin(math.radians(40.0)), 40.0)
    lin0 = fs.linearise_circle(9, 0.0, 40.0)
    lin1 = fs.linearise_circle(9, 3.0 / math.sin(math.radians(40.0)), 40.0)
    for s in fs.SECTORS:
        b0, b1 = lin0.blocks[s], lin1.blocks[s] - lin0.blocks[s]
        assert np.abs(lin.blocks[s] - (b0 + 7.3 * b1)).max() < 1e-11 * np.abs(b0).max()


def test_out_of_plane_sector_is_the_corrected_operator():
    n, q = 9, 6.3
    lin = fs.linearise_circle(n, 3 * q / math.sin(math.radians(50.0)), 50.0)
    got = np.sort(np.linalg.eigvals(lin.blocks["out-of-plane"]).real)
    ref = np.sort(np.repeat(np.linalg.eigvals(paper.paper_operator(q, n, corrected=True)).real, 2))
    np.testing.assert_allclose(got, ref, rtol=1e-11)
    # corrected operator = paper's operator minus 2∂² (the paper's T0 is off by +2); the paper's
    # k = 1 mode (a rigid rotation) decays at -2 instead of being neutral
    k = np.arange(2, n + 1.0)
    printed = paper.paper_operator(q, n)
    np.testing.assert_allclose(printed[1:, 1:] - paper.paper_operator(q, n, corrected=True),
                               np.diag(-2 * k**2), atol=1e-12)
    assert printed[0, 0] == -2.0 and printed[1, 0] == 0.0


def test_corrected_operator_closed_form_n3():
    # k = 2, 3 block: det [[-12, -6q], [-q, -72]] = 0  ->  q = 12
    assert paper.critical_q(3, corrected=True) == pytest.approx(12.0, rel=1e-13)
    assert fs.critical_q(3, "out-of-plane") == pytest.approx(12.0, rel=1e-10)


@pytest.mark.parametrize("sector, ref", [("in-plane", Q_IN), ("out-of-plane", Q_OUT)])
def test_critical_q_converged_in_n(sector, ref):
    q10, q14 = fs.critical_q(10, sector), fs.critical_q(14, sector)
    assert abs(q10 - q14) < 1e-9 * ref                   # 9 digits between n = 10 and 14
    assert abs(q14 - ref) < 1e-9 * ref


def test_critical_q_independent_of_theta():
    for s in fs.SECTORS:
        ref = fs.critical_q(8, s, 90.0)
        for theta in (12.0, 47.0):
            assert fs.critical_q(8, s, theta) == pytest.approx(ref, rel=1e-10)
    rates = [fs.sector_growth_rates([9.5], 8, th) for th in (10.0, 45.0, 90.0)]
    for s in fs.SECTORS:
        assert max(r[s][0] for r in rates) - min(r[s][0] for r in rates) < 1e-9


def test_full_spectrum_labels_and_eigenvectors():
    n, g0, theta = 6, 40.0, 30.0
    spec = fs.full_spectrum(g0, theta, n)
    counts = {s: int(np.sum(spec.sector == s)) for s in ("in-plane", "out-of-plane", "stretch", "neutral")}
    assert counts == {"in-plane": 2 * (n - 2), "out-of-plane": 2 * (n - 1), "stretch": 2 * n + 3, "neutral": 6}
    assert np.all(np.diff(spec.eigenvalues.real) <= 1e-12)
    lin = fs.linearise_circle(n, g0, theta)
    nx = fs.neutral_modes(n, theta)
    nx /= np.linalg.norm(nx, axis=0)
    for lam, v, sec, frac in zip(spec.eigenvalues, spec.modes, spec.sector, spec.out_of_plane_fraction):
        if sec == "neutral":
            continue
        r = lin.jacobian @ v.ravel() - lam * v.ravel()
        r -= nx @ (nx.T @ r)                               # J v - σ v must be a rigid motion
        assert np.abs(r).max() < 1e-9 * np.abs(lin.jacobian).max()
        assert (frac < 1e-20) if sec != "out-of-plane" else (0.0 < frac <= 1.0)
    assert spec.growth_rate("in-plane") == pytest.approx(
        fs.sector_growth_rates([spec.q], n, theta)["in-plane"][0], rel=1e-10)


def test_unstable_modes_are_k2_on_the_fore_side():
    for sector, q in (("in-plane", 9.5), ("out-of-plane", 11.0)):
        mode = fs.unstable_mode(q, 10, sector)
        assert mode["growth_rate"].real > 0 and mode["multiplicity"] == 2
        assert mode["spectrum"][2] > 0.9                    # wavenumber 2 dominates
        assert abs(mode["s_max"] - math.pi) < 0.05          # largest at s = π (fore, compressed)
    assert fs.unstable_mode(9.5, 10, "in-plane")["radial_fraction"] == pytest.approx(0.8, abs=0.02)


def test_onset_q():
    eps, t_end, detect = 1e-3, 10.0, 1e-2
    for s in fs.SECTORS:
        q_on = onset.onset_q(eps, t_end, detect, 8, s)
        assert q_on > fs.critical_q(8, s)
        assert fs.sector_growth_rates([q_on], 8)[s][0] == pytest.approx(math.log(detect / eps) / t_end,
                                                                         abs=1e-9)


def test_cli_full_json(capsys):
    assert main(["stability", "--n", "10", "--theta0", "30", "--json",
                 "--q-scan", "0,12", "--g0", "40", "--top", "4"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["q_crit_in_plane"] == pytest.approx(Q_IN, rel=1e-9)
    assert out["q_crit_out_of_plane"] == pytest.approx(Q_OUT, rel=1e-9)
    assert out["q_crit_paper"] == pytest.approx(14.56105439107, rel=1e-10)
    assert [row["q"] for row in out["q_scan"]] == [0.0, 12.0]
    assert out["q_scan"][0]["paper"] == pytest.approx(-2.0) and out["q_scan"][0]["in_plane"] == pytest.approx(-8.0)
    assert out["spectrum"]["sector"] == ["in-plane", "in-plane", "out-of-plane", "out-of-plane"]


def test_cli_paper_table_with_its_caveat():
    done = subprocess.run([sys.executable, "-m", "loopsim", "stability", "--paper", "--n-max", "4",
                           "--json"], capture_output=True, text=True, check=True)
    assert json.loads(done.stdout) == {"operator": "paper", "note": paper.SIGN_NOTE, "critical_q": {
        str(n): (None if math.isnan(q) else q) for n, q in paper.critical_q_table(4)}}


def test_cli_default_is_the_full_linearisation(capsys):
    assert main(["stability", "--n", "10"]) == 0
    out = capsys.readouterr().out
    assert "q_crit_in_plane" in out and "8.9000" in out and "10.6493" in out
    assert "wrong sign" in out  # the paper's value is printed with its caveat


@pytest.mark.parametrize("argv", [["--paper", "--n", "10"], ["--paper", "--g0", "3"],
                                  ["--n-max", "4"], ["--full"]])
def test_cli_refuses_flag_mixtures(argv, capsys):
    try:
        code = main(["stability", *argv])
    except SystemExit as exc:  # argparse: an unknown option
        code = exc.code
    assert code == 2
    assert "error" in capsys.readouterr().err


def test_cli_full_rejects_bad_input(capsys):
    assert main(["stability", "--n", "2"]) == 2
    assert main(["stability", "--theta0", "0"]) == 2


@pytest.mark.slow
def test_critical_q_converged_high_n():
    for n in (20, 24):
        assert fs.critical_q(n, "in-plane") == pytest.approx(Q_IN, rel=1e-9)
        assert fs.critical_q(n, "out-of-plane") == pytest.approx(Q_OUT, rel=1e-9)


def test_regime_onsets_bracket_the_sweep():
    """n = 6, eps = 1e-3, seed 0, t_end = 10, θ0 = 90°: the main-job sweep (README) labels
    q = 8.81 stable, 9.11 in-plane and q = 11.43 (θ0 = 90°) 3D."""
    r = onset.regime_onsets(eps=1e-3, t_end=10.0, n=6, theta0_deg=90.0, seed=0)
    assert r["q_crit_in_plane"] < r["q_in_plane"] < 9.11
    assert r["q_crit_out_of_plane"] < r["q_3d"] < 11.43
    assert 0 < r["amplitude_out_of_plane"] < 1e-3 and 0 < r["amplitude_in_plane"] < 1e-3


def test_in_plane_threshold_from_the_numpy_twin():
    """The number 8.9000904456 itself, from a second discretisation: the plain-NumPy twin
    of the maps (tests/naive.py: FFTs on a 256-point grid, lstsq tension) differentiated
    by Richardson central differences, about the vertical circle (θ0 = 90°, q = g0 / 3),
    in-plane block (x and z components).  The leading non-neutral eigenvalue is tracked
    at three q around the threshold and its quadratic interpolant's root is q_c."""
    import naive

    n = 8
    x = shapes.inclined_circle(n, math.pi / 2)
    k = 2 * n + 1
    in_plane = np.r_[0:k, 2 * k:3 * k]

    def leading(q):
        jac = naive.jacobian(x, 3.0 * q, 10.0)[np.ix_(in_plane, in_plane)]
        values = np.linalg.eigvals(jac)
        values = values[np.abs(values) > 1e-5]  # the neutral modes: translations, shift
        return values[np.argmax(values.real)].real

    qs = np.array([8.8, 8.85, 8.95])
    rates = np.array([leading(q) for q in qs])
    assert rates[0] < rates[1] < 0 < rates[2]
    roots = np.roots(np.polyfit(qs, rates, 2))
    q_c = roots[np.argmin(np.abs(roots - 8.9))].real
    assert abs(q_c - Q_IN) < 1e-5, q_c
