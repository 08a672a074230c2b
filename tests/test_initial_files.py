"""Initial shapes from files (issue 6): point files, continuation from results, bad input."""
import json
import os

import numpy as np
import pandas as pd
import pytest
from scipy import integrate, special

import loopsim
from loopsim import api, shapes, spectral, storage, sweeps
from loopsim.cli import main

EXAMPLE = os.path.join(os.path.dirname(__file__), os.pardir, "data", "wobbly_ellipse.csv")


def write_points(path, points, columns=("x", "y", "z")):
    frame = pd.DataFrame(np.asarray(points), columns=list(columns))
    if str(path).endswith(".parquet"):
        frame.to_parquet(path)
    else:
        frame.to_csv(path, index=False, float_format="%.17g")
    return str(path)


def uneven(m, rng, warp=0.3, jitter=0.35):
    """m increasing parameters in [0, 2π), the first 0: a smooth warp plus random jitter."""
    u = 2 * np.pi * np.arange(m) / m
    t = u + warp * np.sin(u) + jitter * (2 * np.pi / m) * rng.uniform(-1, 1, m)
    t[0] = 0.0
    assert np.all(np.diff(t) > 0)
    return t


# ---- point files ------------------------------------------------------------------
@pytest.mark.parametrize("suffix", ["csv", "parquet"])
def test_circle_points_reproduce_the_builtin_circle(tmp_path, rng, suffix):
    theta, radius, centre = np.radians(30.0), 2.5, np.array([1.0, -2.0, 3.0])
    s = uneven(200, rng)
    points = centre + radius * np.stack(
        [np.sin(s), np.cos(theta) * np.cos(s), np.sin(theta) * np.cos(s)], axis=1)
    x, info = shapes.load_initial(write_points(tmp_path / f"circle.{suffix}", points), 6)
    reference = shapes.inclined_circle(6, theta)
    error = np.max(np.abs(x[:, 1:] - reference[:, 1:]))
    assert error < 1e-10, error  # measured 1.1e-15
    assert np.max(np.abs(x[:, 0] - centre / radius)) < 1e-10  # x_model = scale * x_file
    assert info["scale"] == pytest.approx(1 / radius, rel=1e-13)
    assert info["length"] == pytest.approx(2 * np.pi * radius, rel=1e-13)
    assert info["tilt_deg"] == pytest.approx(30.0, abs=1e-10)
    assert info["aspect_ratio"] == pytest.approx(1.0, abs=1e-12)
    assert info["spectral_tail"] < 1e-10 and info["warnings"] == []


def test_circle_file_runs_like_the_builtin_circle(tmp_path, rng):
    s = uneven(120, rng)
    points = 0.7 * np.stack([np.sin(s), np.cos(0.5) * np.cos(s), np.sin(0.5) * np.cos(s)], axis=1)
    path = write_points(tmp_path / "c.csv", points)
    from_file = api.simulate(60, None, initial=path, n=6, t_span=(0, 0.2))
    builtin = api.simulate(60, np.degrees(0.5), n=6, perturbation=0.0, t_span=(0, 0.2))
    assert from_file.inputs["perturbation"] == 0.0  # no perturbation unless asked
    assert from_file.inputs["theta0_deg"] == pytest.approx(np.degrees(0.5), abs=1e-10)
    assert np.max(np.abs(from_file.x_final - builtin.x_final)) < 1e-9


def test_ellipse_arc_length_parametrisation_against_quadrature(tmp_path, rng):
    a, b, tilt = 1.5, 1.0, 0.4
    phi = uneven(200, rng, warp=0.2, jitter=0.3)  # uneven in φ, and φ is not arc length
    points = np.stack([a * np.cos(phi), b * np.cos(tilt) * np.sin(phi),
                       b * np.sin(tilt) * np.sin(phi)], axis=1)
    n = 32
    x, info = shapes.load_initial(write_points(tmp_path / "ellipse.csv", points), n)
    length = 4 * a * special.ellipe(1 - (b / a) ** 2)
    assert info["length"] == pytest.approx(length, rel=1e-13)
    # independent: arc length of each point by adaptive quadrature of |dX/dφ|
    speed = lambda p: np.hypot(a * np.sin(p), b * np.cos(p))  # noqa: E731
    arc = np.array([integrate.quad(speed, 0, p, epsabs=1e-13, epsrel=1e-13)[0] for p in phi])
    fitted = spectral.evaluate(x, 2 * np.pi * arc / length).T / info["scale"]
    assert np.max(np.abs(fitted - points)) < 1e-8  # measured 3e-10 (the order-32 truncation)
    dx = x @ spectral.synthesis_matrix(n, 8 * n + 1, 1).T
    assert np.max(np.abs(np.linalg.norm(dx, axis=0) - 1)) < 1e-7  # |x'| = 1: measured 8e-9
    assert info["truncation"] < 1e-8 and info["warnings"] == []


def test_example_file_diagnostics_and_tail_warning(capsys):
    x, info = shapes.load_initial(EXAMPLE, 8)
    assert info["points"] == 120 and info["n"] == 8 and info["warnings"] == []
    assert 29 < info["tilt_deg"] < 31 and 1.4 < info["aspect_ratio"] < 1.6
    assert info["length"] * info["scale"] == pytest.approx(2 * np.pi, rel=1e-3)
    assert x.shape == (3, 17)
    _, coarse = shapes.load_initial(EXAMPLE, 4)
    assert coarse["spectral_tail"] > shapes.TAIL_WARNING and "increase n" in coarse["warnings"][0]
    code = main(["run", "--initial", EXAMPLE, "--g0", "60", "--n", "4", "--t-end", "0.05",
                 "--json"])
    captured = capsys.readouterr()
    assert code == 0 and captured.err.startswith("loopsim: warning: initial shape not resolved")
    out = json.loads(captured.out)
    assert out["initial"]["scale"] == coarse["scale"] and out["theta0_deg"] == coarse["tilt_deg"]
    assert out["perturbation"] == 0.0


def test_perturbation_in_the_shapes_own_frame_matches_the_builtin():
    theta = np.radians(35.0)
    mine = shapes.perturb(shapes.inclined_circle(7, theta), 1e-3, seed=4)
    assert np.max(np.abs(mine - shapes.initial_shape(7, theta, 1e-3, seed=4))) < 1e-14


# ---- continuation from results -----------------------------------------------------
TIGHT = dict(rtol=1e-10, atol=1e-13)


def test_continuation_equals_one_longer_run(tmp_path, capsys):
    first = api.simulate(60, 30, n=6, t_span=(0, 1.0), **TIGHT)
    path = str(tmp_path / "first.parquet")
    storage.write_trajectory(first, path)
    x, info = shapes.load_initial(path)
    assert np.array_equal(x, first.x_final)  # exact: stored coefficients, no resampling
    assert info["kind"] == "run" and info["g0"] == 60 and info["t_final"] == 1.0
    more = api.simulate(60, None, initial=path, n=6, t_span=(0, 0.5), **TIGHT)
    whole = api.simulate(60, 30, n=6, t_span=(0, 1.5), **TIGHT)
    difference = np.max(np.abs(more.x_final - whole.x_final))
    assert difference < 1e-8, difference  # measured ~1e-11
    # the CLI: g0 from the file
    assert main(["run", "--n", "6", "--initial", path, "--t-end", "0.5", "--json", "--rtol", "1e-10",
                 "--atol", "1e-13"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["g0"] == 60 and out["n"] == 6 and out["initial"]["kind"] == "run"
    assert out["aspect_ratio"] == pytest.approx(whole.summary()["aspect_ratio"], abs=1e-8)
    # resizing: exact padding up, truncation down
    up, _ = shapes.load_initial(path, 9)
    assert np.array_equal(spectral.resize(up, 6), first.x_final)
    assert np.array_equal(shapes.load_initial(path, 4)[0], spectral.resize(first.x_final, 4))


def test_sweep_results_and_cases_with_initial_column(tmp_path, capsys):
    out = str(tmp_path / "sweep")
    assert main(["sweep", "--g0", "20,80", "--theta0", "40", "--n", "4", "--t-end", "0.3",
                 "--out", out, "--quiet"]) == 0
    capsys.readouterr()
    frame = loopsim.read_results(out)
    x, info = shapes.load_initial(out, case_id=1)
    assert np.array_equal(x.ravel(), np.asarray(frame["x_final"][1]))
    assert info["kind"] == "sweep" and info["g0"] == 80 and info["n"] == 4
    with pytest.raises(ValueError, match="choose one"):
        shapes.load_initial(out)
    code = main(["run", "--n", "6", "--initial", out, "--case-id", "1", "--t-end", "0.1", "--json"])
    assert code == 0 and json.loads(capsys.readouterr().out)["g0"] == 80
    # a cases file with a per-row initial column (paths relative to the cases file)
    cases = tmp_path / "cases.csv"
    cases.write_text(f"g0,theta0_deg,n,initial,initial_case_id\n"
                     f"30,20,4,,\n"
                     f"50,,4,sweep,1\n"
                     f"70,,8,{os.path.abspath(EXAMPLE)},\n")
    out2 = str(tmp_path / "sweep2")
    assert main(["sweep", "--n", "6", "--cases", str(cases), "--t-end", "0.05", "--out", out2, "--quiet",
                 "--snapshots-for", "1"]) == 0
    rows = loopsim.read_results(out2)
    _, example = shapes.load_initial(EXAMPLE, 8)
    assert list(rows["perturbation"]) == [1e-3, 0.0, 0.0]
    assert rows["theta0_deg"][1] == pytest.approx(info["tilt_deg"])
    assert rows["theta0_deg"][2] == example["tilt_deg"]
    assert rows["aspect_ratio_initial"][2] == pytest.approx(example["aspect_ratio"], rel=1e-12)
    snaps = loopsim.read_snapshots(out2)
    assert np.array_equal(np.asarray(snaps["x"][0]), x.ravel())  # traced case starts from it
    config = rows.attrs["loopsim"]["sweep_config"]
    assert config["cases"][2]["initial_scale"] == example["scale"]


def test_api_initial_arguments():
    circle = shapes.inclined_circle(5, 0.3)
    result = api.simulate(10, None, initial=circle, n=5, t_span=(0, 0.01))
    assert result.inputs["n"] == 5 and result.initial_info["kind"] == "coefficients"
    with pytest.raises(ValueError, match="theta0_deg must be None"):
        api.simulate(10, 30, initial=circle)
    with pytest.raises(ValueError, match="theta0_deg is required"):
        api.simulate(10)
    with pytest.raises(ValueError, match="shape"):
        api.simulate(10, None, initial=np.zeros((3, 4)))
    with pytest.raises(ValueError, match="degenerate"):
        api.simulate(10, None, initial=np.zeros((3, 5)))


# ---- bad input: one line, exit 2 ---------------------------------------------------
def _circle(m, phase=0.1):
    s = phase + 2 * np.pi * np.arange(m) / m
    return np.stack([np.cos(s), np.sin(s), 0 * s], axis=1)


def _bad_files(tmp_path):
    figure_eight = (lambda s: np.stack([np.sin(s), np.sin(s) * np.cos(s), 0 * s], axis=1))(
        0.05 + 2 * np.pi * np.arange(60) / 60)
    duplicated = np.insert(_circle(40), 7, _circle(40)[7], axis=0)
    nan = _circle(40)
    nan[5, 1] = np.nan
    closed = np.vstack([_circle(40), _circle(40)[:1]])
    line = np.outer(np.arange(20.0), [1.0, 2.0, -1.0])
    garbage = tmp_path / "garbage.parquet"
    garbage.write_bytes(b"PAR1 this is not parquet")
    text = tmp_path / "text.csv"
    text.write_text("x,y,z\n1,2,3\n4,five,6\n7,8,9\n")
    return {
        "few": (write_points(tmp_path / "few.csv", _circle(10)), "needs at least 13"),
        "repeated": (write_points(tmp_path / "rep.csv", duplicated), "coincide"),
        "closed": (write_points(tmp_path / "closed.csv", closed), "last point repeats"),
        "nan": (write_points(tmp_path / "nan.csv", nan), "non-finite"),
        "text": (str(text), "non-numeric"),
        "collinear": (write_points(tmp_path / "line.csv", line), "collinear"),
        "eight": (write_points(tmp_path / "eight.csv", figure_eight), "self-intersecting"),
        "columns": (write_points(tmp_path / "abc.csv", _circle(40), "abc"), "lacks column"),
        "missing": (str(tmp_path / "nothing.csv"), "no such file"),
        "garbage": (str(garbage), "cannot read"),
    }


@pytest.mark.parametrize("which", ["few", "repeated", "closed", "nan", "text", "collinear",
                                   "eight", "columns", "missing", "garbage"])
def test_bad_point_files(which, tmp_path, capsys):
    path, word = _bad_files(tmp_path)[which]
    with pytest.raises(ValueError, match=word):
        shapes.load_initial(path, 6)
    assert main(["run", "--n", "6", "--initial", path, "--g0", "10", "--t-end", "0.01"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("loopsim: error:") and word in err


def test_bad_case_ids_and_flag_combinations(tmp_path, capsys):
    run = api.simulate(10, 30, n=4, t_span=(0, 0.01))
    path = str(tmp_path / "run.parquet")
    storage.write_trajectory(run, path)
    points = write_points(tmp_path / "p.csv", _circle(40))
    sweep = str(tmp_path / "sweep")
    sweeps.run_sweep(sweeps.SweepConfig(
        cases=sweeps.grid_cases([10, 20], [30], [4], 1), t_end=0.01), sweep, quiet=True)
    for argv, word in [
        (["--initial", path, "--case-id", "3"], "case id 3 is not in the results"),
        (["--initial", sweep, "--case-id", "7"], "case id 7 is not in the results"),
        (["--initial", points, "--g0", "1", "--case-id", "0"], "applies only to results"),
        (["--initial", points, "--g0", "1", "--theta0", "30"], "not both"),
        (["--initial", points], "--g0 is required"),
        (["--g0", "1", "--theta0", "30", "--case-id", "0"], "--case-id needs --initial"),
    ]:
        assert main(["run", "--n", "6", *argv, "--t-end", "0.01"]) == 2, argv
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and err.startswith("loopsim: error:") and word in err


def test_n_auto_starts_a_point_file_at_the_order_its_content_needs(tmp_path, capsys):
    """``--initial POINTS --n auto``: a perturbed tilted circle sampled at 256 equally
    spaced parameter values (not arc length: refitted by arc length, its content above
    order 6 is about 5e-5 of its RMS amplitude) starts at the lowest order whose
    truncation leaves out at most defaults.INITIAL_CONTENT_TOL, not at order 6, and every
    order of the ladder starts from that same shape (exactly zero-padded)."""
    from loopsim import defaults

    x = shapes.initial_shape(6, np.radians(45.0), 1e-3, 3)
    s = np.linspace(0.0, 2.0 * np.pi, 256, endpoint=False)
    path = write_points(tmp_path / "tilted.csv", spectral.evaluate(x, s).T)
    assert shapes.load_initial(path, 6)[1]["truncation"] > 1e-6  # content above order 6
    order = shapes.auto_start_order(path)
    start, info = shapes.load_initial(path, order)
    assert order > 6 and info["truncation"] <= defaults.INITIAL_CONTENT_TOL
    assert shapes.load_initial(path, order - 1)[1]["truncation"] > defaults.INITIAL_CONTENT_TOL
    assert shapes.auto_start_order(path, high=8) == 8  # never above the ladder's top
    result = api.simulate(60.0, None, initial=path, t_span=(0.0, 0.05), twin=False)
    assert result.inputs["n"] == order == result.initial_info["n"]
    assert result.n_used >= order
    np.testing.assert_array_equal(result.x[0], spectral.resize(start, result.n_used))
    assert main(["run", "--initial", path, "--g0", "60", "--t-end", "0.05", "--no-twin",
                 "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["n"] == order and printed["initial"]["n"] == order
    # a fixed n is what it says: the file fitted at that order
    assert api.simulate(60.0, None, initial=path, n=6, t_span=(0.0, 0.01),
                        twin=False).inputs["n"] == 6


def test_a_cases_file_point_row_with_n_auto_starts_at_its_content_order(tmp_path, capsys):
    """The sweep's counterpart of ``run --initial POINTS --n auto``: a cases-file row
    that starts from a point file and gives no n starts at the order its content needs;
    a row that gives n keeps it."""
    x = shapes.initial_shape(6, np.radians(45.0), 1e-3, 3)
    s = np.linspace(0.0, 2.0 * np.pi, 256, endpoint=False)
    write_points(tmp_path / "tilted.csv", spectral.evaluate(x, s).T)
    order = shapes.auto_start_order(str(tmp_path / "tilted.csv"))
    cases = tmp_path / "cases.csv"
    cases.write_text("g0,initial\n60,tilted.csv\n")
    out = str(tmp_path / "s")
    assert main(["sweep", "--cases", str(cases), "--n", "auto", "--t-end", "0.01", "--no-twin",
                 "--quiet", "--out", out]) == 0
    assert order > 6 and loopsim.read_results(out)["n"].tolist() == [order]
    fixed = sweeps.read_cases_file(str(cases), n=8)  # no --n auto: the given order
    assert fixed[0]["n"] == 8


@pytest.mark.parametrize("size", [1e-300, 1e-200, 1e154, 1e300])
def test_point_files_at_extreme_scales_fit_as_at_unit_scale(tmp_path, rng, size):
    """The model is scale-free (the loop is rescaled to length 2π): a file's curve at
    1e300 or 1e-300 gives the shape the same curve at size 1 gives, and the length and
    scale in the file's units.  Issue 54.10: near 1e154 and 1e300 scipy's "value of p too
    large", near 1e-300 "points 0 and 1 coincide"."""
    s = uneven(150, rng)
    points = np.stack([np.sin(s) + 0.2 * np.sin(2 * s), 0.8 * np.cos(s),
                       0.3 * np.cos(s) + 0.1 * np.sin(3 * s)], axis=1) + [0.5, -0.25, 1.0]
    unit, unit_info = shapes.load_initial(write_points(tmp_path / "unit.csv", points), 8)
    x, info = shapes.load_initial(write_points(tmp_path / "scaled.csv", points * size), 8)
    assert np.max(np.abs(x - unit)) < 1e-9  # measured 0.7e-15 to 2.1e-15
    assert info["length"] == pytest.approx(unit_info["length"] * size, rel=1e-9)
    assert info["scale"] == pytest.approx(unit_info["scale"] / size, rel=1e-9)
    assert info["tilt_deg"] == pytest.approx(unit_info["tilt_deg"], abs=1e-9)


@pytest.mark.parametrize("size, reason", [(1e-310, "below"), (1e308, "beyond what a double")])
def test_point_files_beyond_a_doubles_range_say_so(tmp_path, rng, size, reason):
    """Coordinates all subnormal (too few digits), or a curve whose length in the file's
    units overflows: "scale out of range", one line, naming the file."""
    s = uneven(40, rng)
    points = np.stack([np.sin(s), np.cos(s), 0.2 * np.cos(s)], axis=1) * size
    path = write_points(tmp_path / "p.csv", points)
    with pytest.raises(ValueError, match="scale out of range") as caught:
        shapes.load_initial(path, 6)
    assert reason in str(caught.value) and "\n" not in str(caught.value)
