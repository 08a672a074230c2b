"""Figures (loopsim/figures/, ``loopsim figures``, scripts/plot_trajectory.py, scripts/make_figures.py).

Figure functions are drawn from small synthetic tables (tilted ellipses with known
tilt and aspect ratio), so these tests need no integration; the command line and
the trajectory script run on a tiny real sweep and run (n = 4, short times).
"""
import os
import runpy
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

from loopsim import diagnostics, figures, spectral  # noqa: E402
from loopsim.cli import main  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
N = 4
THRESHOLDS = dict(paper=14.561, in_plane=8.9001, out_of_plane=10.6493)


def ellipse(theta_deg, stretch=1.0, n=N, centre=(0.0, 0.0, 0.0)):
    """Coefficients (3, 2n+1) of the ellipse [sin s, stretch cos s (cos θ, sin θ)] + centre:
    tilt θ, aspect ratio (variances) stretch²."""
    t = np.radians(theta_deg)
    x = np.zeros((3, spectral.n_coeffs(n)))
    x[:, 0] = centre
    x[0, n + 1] = 1.0  # b1 of x: sin s
    x[1, 1], x[2, 1] = stretch * np.cos(t), stretch * np.sin(t)  # a1 of y, z
    return x


def table(rows=12):
    """A synthetic sweep table with the columns the figures read."""
    g0 = np.repeat([20.0, 60.0, 150.0], 4)[:rows]
    theta0 = np.tile([10.0, 30.0, 60.0, 85.0], 3)[:rows]
    regimes = np.array(["stable", "in-plane", "3d", "failed"])[np.arange(rows) % 4]
    records = []
    for i, (g, t, regime) in enumerate(zip(g0, theta0, regimes)):
        stretch = 1.0 if regime == "stable" else 1.3
        theta_final = t if regime != "3d" else t / 2
        x = ellipse(theta_final, stretch)
        records.append(dict(
            case_id=i, g0=g, theta0_deg=t, n=N, seed=0, q0=g * np.sin(np.radians(t)) / 3,
            t_end=10.0, theta_final_deg=diagnostics.tilt_deg(x),
            q_final=g * np.sin(np.radians(theta_final)) / 3,
            aspect_ratio=diagnostics.aspect_ratio(x), regime=regime, resolved=bool(i % 3),
            determined=True, x_final=x.ravel().tolist()))
    return pd.DataFrame(records)


def trajectory(times=(0.0, 0.5, 1.0, 1.5, 2.0), g0=60.0, theta0=30.0):
    """A synthetic trajectory table: a tilted circle that flattens and falls; multiplier of
    the translating circle T = -1 + q cos s."""
    q = g0 * np.sin(np.radians(theta0)) / 3
    rows = []
    for t in times:
        x = ellipse(theta0, 1.0 + 0.1 * min(t, 1.0), centre=(0.0, 0.0, -65.0 * t))
        multiplier = np.zeros(spectral.n_coeffs(N))
        multiplier[0], multiplier[1] = -1.0, q
        rows.append(dict(t=t, theta_deg=diagnostics.tilt_deg(x),
                         aspect_ratio=diagnostics.aspect_ratio(x), x=x.ravel().tolist(),
                         multiplier=multiplier.tolist()))
    return pd.DataFrame(rows)


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def test_import_leaves_the_backend_alone():
    code = ("import matplotlib; before = matplotlib.get_backend(); "
            "import loopsim.figures, loopsim.cli; "
            "assert matplotlib.get_backend() == before == 'svg', matplotlib.get_backend()")
    env = dict(os.environ, MPLBACKEND="svg")
    subprocess.run([sys.executable, "-c", code], check=True, env=env, cwd=ROOT)


def test_ellipse_fixture_has_the_intended_tilt_and_aspect_ratio():
    x = ellipse(30.0, 1.3)
    assert diagnostics.tilt_deg(x) == pytest.approx(30.0, abs=1e-9)
    assert diagnostics.aspect_ratio(x) == pytest.approx(1.69, rel=1e-12)


def test_centred_curve_removes_only_the_mean():
    x = ellipse(30.0, centre=(5.0, -7.0, -3000.0))
    points = figures.centred_curve(x)
    assert np.abs(points.mean(axis=1)).max() < 1e-2
    assert np.abs(points).max() == pytest.approx(1.0, abs=1e-12)


def test_gallery_draws_side_and_plane_views_in_regime_colours():
    frame = table()
    fig = figures.gallery(frame, theta0_deg=30.0)
    # a colour key of the regimes drawn; titles name θ0 (initial) and the terminal tilt
    key = [t.get_text() for t in fig.legends[0].get_texts()]
    drawn_regimes = frame[frame["theta0_deg"] == 30.0]["regime"]
    for regime in drawn_regimes:
        assert figures.REGIME_STYLE[regime]["label"] in key
    assert "θ0 = 30° (initial tilt)" in fig._suptitle.get_text()
    assert "terminal θ" in fig.axes[0].get_title()
    cases = frame[frame["theta0_deg"] == 30.0]
    assert len(fig.axes) == 2 * len(cases)
    expected = [figures.REGIME_STYLE[r]["color"] for r in cases.sort_values("g0")["regime"]]
    side = fig.axes[: len(cases)]
    drawn = [matplotlib.colors.to_hex(ax.get_lines()[-1].get_color()) for ax in side]
    assert drawn == [matplotlib.colors.to_hex(c) for c in expected]
    # the side view of a loop at 30 degrees is a segment at 30 degrees
    y, z = side[0].get_lines()[-1].get_data()
    assert np.degrees(np.arctan2(np.ptp(z), np.ptp(y))) == pytest.approx(30.0, abs=0.5)


def auto_table():
    """Rows as --n auto writes them: n the ladder's start (N), terminal coefficients at n_used."""
    frame = table(8)
    used = np.where(np.arange(len(frame)) % 2, N + 2, N)
    frame["n_used"] = used
    frame["x_final"] = [ellipse(t, 1.3, n=int(k)).ravel().tolist()
                        for t, k in zip(frame["theta_final_deg"], used)]
    return frame


def test_figures_of_n_auto_rows_read_the_coefficients_at_n_used():
    frame = auto_table()
    assert figures.order_column(frame) == "n_used"
    assert figures.orders_text(frame) == f"n auto (n_used = {N}, {N + 2})"
    assert figures.orders_text(table()) == f"n = {N}"
    fig = figures.gallery(frame, theta0_deg=30.0)  # coefficients at n_used, not at n
    assert "n auto (n_used = " in fig._suptitle.get_text()
    fig = figures.aspect_ratio(table(), reference=frame)
    assert any("n auto" in text.get_text() for text in fig.axes[0].get_legend().get_texts())
    # titles name the orders reached (Figs. 7, 8 of an --n auto sweep said "n = 4")
    assert f"n auto (n_used = {N}, {N + 2})" in figures.q_and_tilt(frame)._suptitle.get_text()
    assert "n auto (n_used = " in figures.aspect_ratio(frame).axes[0].get_title()


def test_phase_diagram_of_n_auto_rows_names_n_used_and_draws_its_linearisation():
    """An --n auto table is titled by the orders reached, not by the ladder's start, and its
    full-linearisation curves are those of the largest n_used."""
    from loopsim.stability import full_linear

    title = figures.phase_diagram(auto_table()).axes[0].get_title()
    assert f"n auto (n_used = {N}, {N + 2})" in title
    assert f"n = {N}," in figures.phase_diagram(table()).axes[0].get_title()
    labels = [t.get_text() for t in figures.phase_diagram(auto_table()).axes[0].get_legend().get_texts()]
    q_in_plane = full_linear.critical_q(N + 2, "in-plane")
    assert any(f"q = {q_in_plane:.3f}" in text for text in labels)


def test_nonlocal_tables_draw_their_models_thresholds_side_by_side():
    """A nonlocal table's phase diagram and outcome columns draw the nonlocal model's
    thresholds (θ0 = 90°) and name ε; one outcome column per table; mixing models in one
    table is refused."""
    from loopsim import models
    from loopsim.stability import full_linear

    local = table()
    nonlocal_table = table().assign(model="nonlocal", slenderness=1e-3)
    model = models.choose("nonlocal", 1e-3)
    q_in = full_linear.critical_q(N, "in-plane", model=model)
    fig = figures.phase_diagram(nonlocal_table)
    assert "ε = 0.001" in fig.axes[0].get_title()
    assert any(f"q = {q_in:.3f}" in t.get_text() for t in fig.axes[0].get_legend().get_texts())
    fig = figures.model_outcomes([local, nonlocal_table])
    assert len(fig.axes) == 4
    lines = lambda ax: sorted(round(line.get_xdata()[0], 6) for line in ax.get_lines())
    assert lines(fig.axes[2]) == sorted(round(full_linear.critical_q(N, s), 6)
                                        for s in ("in-plane", "out-of-plane"))
    assert round(q_in, 6) in lines(fig.axes[3])
    assert "nonlocal SBT, ε = 0.001" in fig.axes[1].get_title()
    with pytest.raises(ValueError, match="mixes models"):
        figures.phase_diagram(pd.concat([local.assign(model="local", slenderness=np.nan),
                                       nonlocal_table]))


def test_phase_diagram_paper_band_adds_the_two_empirical_curves():
    frame = table()
    plain = figures.phase_diagram(frame)
    banded = figures.phase_diagram(frame, paper_band=True)
    assert len(banded.axes[0].get_lines()) == len(plain.axes[0].get_lines()) + 2
    theta, g0 = banded.axes[0].get_lines()[-1].get_data()
    assert np.allclose(g0 * np.sin(np.radians(theta)) / 3, figures.PAPER_BAND[1])


def test_phase_diagram_draws_failed_cases_resolved_or_not():
    frame = table().assign(resolved=False)
    failed = [c for c in figures.phase_diagram(frame).axes[0].collections if c.get_label() == "failed"]
    assert len(failed) == 1 and len(failed[0].get_offsets()) == (frame["regime"] == "failed").sum()


def test_phase_diagrams_one_panel_per_sweep():
    fig = figures.phase_diagrams([table(), table(8)])
    assert len(fig.axes) == 2


def test_phase_diagrams_share_one_legend_with_every_panels_markers():
    """A marker drawn in one panel only (hollow: not resolved) has its legend entry."""
    only_left = table().assign(resolved=False)
    only_right = table().assign(resolved=True)
    fig = figures.phase_diagrams([only_left, only_right])
    left, right = fig.axes
    assert left.get_legend() is None
    labels = [t.get_text() for t in right.get_legend().get_texts()]
    assert "stable, not resolved at n" in labels and "stable" in labels
    assert len(labels) == len(set(labels))
    assert labels.index("stable") < labels.index("stable, not resolved at n") < labels.index("in-plane")


def test_q_and_tilt_scatter_and_thresholds():
    frame = table()
    fig = figures.q_and_tilt(frame, thresholds=THRESHOLDS, reference=table(4))
    left, right = fig.axes
    levels = sorted(line.get_ydata()[0] for line in left.get_lines()[1:])
    assert levels == pytest.approx(sorted([14.561, 8.9001, 10.6493, 10.5, 18.5]))
    points = np.concatenate([c.get_offsets() for c in right.collections])
    assert len(points) == len(frame) + 4


def test_aspect_ratio_with_branch_solid_stable_dashed_unstable():
    frame = table()
    q = np.linspace(8.9, 25.0, 30)
    branch = pd.DataFrame(dict(q=q, aspect_ratio=1 + 0.1 * (q - 8.9), stable_in_plane=True,
                               stable_out_of_plane=q < 18.0))
    fig = figures.aspect_ratio(frame, branch, q_max=20.0)
    styles = {line.get_label(): line.get_linestyle() for line in fig.axes[0].get_lines()}
    assert styles["steady shapes, stable"] == "-"
    assert styles["steady shapes, unstable"] == "--"
    solid = next(line for line in fig.axes[0].get_lines() if line.get_label() == "steady shapes, stable")
    assert np.nanmax(solid.get_xdata()[np.isfinite(solid.get_ydata())]) < 18.6
    assert fig.axes[0].get_xlim() == (0.0, 20.0)
    assert any("not shown" in t.get_text() for t in fig.axes[0].texts)
    assert len(figures.aspect_ratio(frame).axes[0].get_lines()) == 1  # no branch: y = 1 only


def test_evolution_three_views_coloured_by_time_until_settled():
    trace = trajectory(times=np.linspace(0.0, 4.0, 9))
    assert figures.settling_index(trace) == 2  # the shape stops changing at t = 1
    fig = figures.evolution(trace, snapshots=9)
    ax3d, side, top = fig.axes[:3]
    assert ax3d.name == "3d" and len(fig.axes) == 4  # + colour bar
    assert len(side.get_lines()) == 3  # snapshots t = 0, 0.5, 1
    for line in side.get_lines():
        assert np.abs(line.get_xydata()).max() < 2.0  # centred, though it fell 65 per unit t
    fig = figures.evolution(trace, snapshots=5, t_max=None)
    assert len(fig.axes[1].get_lines()) == 5


def test_tension_on_the_translating_circle_is_q_cos_s():
    """N = T + |x''|² = q cos s on the circle with T = -1 + q cos s (physics notes)."""
    trace = trajectory()
    q = 60.0 * np.sin(np.radians(30.0)) / 3
    fig = figures.tension_figure(trace.iloc[:1], rows=(0,))
    lines = fig.axes[0].collections[0]
    values = lines.get_array()
    # each segment is coloured by the mean of N at its two ends, on the profile grid
    s = np.append(diagnostics.tension_profile(np.asarray(trace["x"].iloc[0]).reshape(3, -1),
                                              np.asarray(trace["multiplier"].iloc[0]))[0],
                  2 * np.pi)
    np.testing.assert_allclose(values, q * 0.5 * (np.cos(s[:-1]) + np.cos(s[1:])),
                               rtol=0, atol=1e-10 * q)
    assert len(fig.axes) == 2  # 3D axes and colour bar


def test_stability_figure_from_tables():
    q = np.linspace(0, 20, 11)
    growth = pd.DataFrame(dict(q=q, paper=q - 14.5, corrected=q - 10.6, in_plane=q - 8.9,
                               out_of_plane=q - 10.6))
    critical = pd.DataFrame(dict(n=[3, 4, 5], in_plane=[np.nan, 9.8, 8.94],
                                 out_of_plane=[12.0, 10.7, 10.65], paper=[17.3, 14.8, 14.6],
                                 corrected=[12.0, 10.7, 10.65]))
    fig = figures.stability(growth, critical)
    left, right = fig.axes
    assert len(left.get_lines()) == 4  # three curves and sigma = 0
    assert len(right.get_lines()) == 3
    assert len(right.get_lines()[1].get_xdata()) == 2  # NaN (no crossing) left out


def test_seed_distributions_one_histogram_per_table():
    frame = table(4)
    fig = figures.seed_distributions([frame, frame], ["a", "b"])
    left, right = fig.axes
    assert len(left.patches) == 2 and len(right.patches) == 2
    # one legend, below the panels (not over the bars); the title names g0 and θ0
    assert left.get_legend() is None and right.get_legend() is None and len(fig.legends) == 1
    title = fig._suptitle.get_text()
    assert "g0 = 20" in title and "θ0 = 10°, 30°, 60°, 85°" in title


def test_aspect_ratio_axes_say_what_the_ratio_is():
    label = figures.aspect_ratio(table()).axes[0].get_ylabel()
    assert "variance" in label and "major / minor principal axis" in label
    assert "variance" in figures.seed_distributions([table(4)]).axes[1].get_xlabel()


def test_evolution_rows_share_one_time_range_and_one_colour_bar():
    """Several runs: one row each, coloured on one time scale (0 to the latest time any row
    draws), one colour bar; rows titled by their runs."""
    short = trajectory(times=np.linspace(0.0, 2.0, 5))  # settles at t = 1
    long = trajectory(times=np.linspace(0.0, 4.0, 9)).assign(
        theta_deg=lambda f: 30.0 - f["t"])  # still tilting at t = 4
    fig = figures.evolution_rows([short, long], ["short", "long"])
    assert len(fig.axes) == 2 * 3 + 1  # three views per row, one colour bar
    colour_bars = [ax for ax in fig.axes if ax.get_ylabel() == "time t"]
    assert len(colour_bars) == 1
    assert colour_bars[0].get_ylim() == pytest.approx((0.0, 4.0))
    assert [sub._suptitle.get_text() for sub in fig.subfigs[0].subfigs] == [
        "short: t = 0 to 1", "long: t = 0 to 4"]
    cmap, norm = figures.time_colours((0.0, 4.0))
    side = [ax for ax in fig.axes if ax.get_title() == "side view (along x)"]
    last_short = side[0].get_lines()[-1].get_color()
    assert matplotlib.colors.to_hex(last_short) == matplotlib.colors.to_hex(cmap(norm(1.0)))


# ---- real files: a tiny sweep, a tiny run -------------------------------------------
@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    from loopsim import sweeps

    base = tmp_path_factory.mktemp("tiny")
    cases = sweeps.grid_cases([10.0, 60.0], [30.0, 60.0], [N], seeds=1)
    sweeps.run_sweep(sweeps.SweepConfig(cases=cases, t_end=0.3), str(base / "sweep"), quiet=True)
    run = base / "run.parquet"
    assert main(["run", "--g0", "60", "--theta0", "30", "--n", str(N), "--t-end", "1",
                 "--snapshots", "5", "--out", str(run)]) == 0
    return base


def test_cli_figures_on_a_tiny_sweep_and_run(tiny, capsys):
    out = tiny / "figures"
    assert main(["figures", str(tiny / "sweep"), str(tiny / "run.parquet"), "--out", str(out),
                 "--only", "gallery,phase,q_tilt,aspect,evolution,tension", "--no-branch"]) == 0
    names = sorted(os.listdir(out))
    assert names == sorted(["fig4_gallery.png", "fig5_phase.png", "fig7_q_tilt.png",
                            "fig8_aspect.png", "fig6_evolution_run.png", "fig1_tension_run.png"])
    for name in names:
        assert 5_000 < (out / name).stat().st_size < 300_000
    assert "6 figures" in capsys.readouterr().out


@pytest.mark.parametrize("args, word", [
    (["{tmp}/missing", "--out", "{tmp}/o"], "no sweep directory"),
    (["{sweep}", "{tmp}/garbage.parquet", "--out", "{tmp}/o"], "cannot read"),
    (["{sweep}", "{tmp}/nothing.parquet", "--out", "{tmp}/o"], "no such file"),
    (["{sweep}", "--out", "{tmp}/o", "--only", "fig99"], "unknown figure"),
])
def test_cli_figures_bad_input_is_one_line_exit_2(tiny, tmp_path, capsys, args, word):
    (tmp_path / "garbage.parquet").write_bytes(b"not parquet at all")
    args = [a.format(tmp=tmp_path, sweep=tiny / "sweep") for a in args]
    assert main(["figures", *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("loopsim: error:") and word in err and err.count("\n") == 1


def test_plot_trajectory_script_draws_the_loop_near_its_centroid(tiny, tmp_path, monkeypatch):
    """scripts/plot_trajectory.py centres each snapshot on its centre of mass: the loop
    fell ~65 per unit time, yet every drawn point lies within 3 radii of the centroid."""
    drawn = {}
    monkeypatch.setattr(figures, "save", lambda fig, path, dpi=200: drawn.setdefault("fig", fig))
    script = runpy.run_path(os.path.join(ROOT, "scripts", "plot_trajectory.py"))
    script["main"](str(tiny / "run.parquet"), str(tmp_path / "t.png"))
    lines = drawn["fig"].axes[0].get_lines()
    assert len(lines) == 5
    extent = max(np.abs(line.get_xydata()).max() for line in lines)
    assert 0.5 < extent < 3.0


def test_plot_trajectory_script_draws_an_n_auto_run_at_the_order_it_ended_at(tmp_path,
                                                                             monkeypatch):
    """README's first plot: ``loopsim run`` at the default ``--n auto`` starts at n = 6 and
    stores its snapshots at n_used (16 here, climbed before t = 0.2); the script reads
    that order from the file instead of reshaping with the starting n (audit N1: it
    raised "cannot reshape array of size 99 into shape (3,13)")."""
    run = tmp_path / "auto.parquet"
    assert main(["run", "--g0", "60", "--theta0", "30", "--t-end", "0.2", "--snapshots", "5",
                 "--out", str(run)]) == 0
    _, summary = figures.read_run(str(run))
    assert summary["n"] == 6 and summary["n_used"] > summary["n"]
    drawn = {}
    monkeypatch.setattr(figures, "save", lambda fig, path, dpi=200: drawn.setdefault("fig", fig))
    script = runpy.run_path(os.path.join(ROOT, "scripts", "plot_trajectory.py"))
    script["main"](str(run), str(tmp_path / "auto.png"))
    fig = drawn["fig"]
    assert len(fig.axes[0].get_lines()) == 5
    assert f"n_used = {summary['n_used']}" in fig.axes[0].get_title()


def test_trajectory_figure_reads_the_order_from_the_snapshots_and_checks_a_given_one():
    """figures.trajectory needs no order (it reads it from the stored coefficients); one
    given that the coefficients do not have raises ValueError naming it."""
    frame = pd.DataFrame({"t": [0.0, 1.0], "theta_deg": [30.0, 31.0], "aspect_ratio": [1.0, 1.1],
                          "x": [ellipse(30.0, n=8).ravel(), ellipse(31.0, 1.05, n=8).ravel()]})
    assert len(figures.trajectory(frame).axes[0].get_lines()) == 2
    assert len(figures.trajectory(frame, 8).axes[0].get_lines()) == 2
    with pytest.raises(ValueError, match="n = 6"):
        figures.trajectory(frame, 6)
    plt.close("all")


def test_undetermined_rows_are_ringed_in_the_phase_diagram_and_figs_7_8():
    """Rows whose twin ended elsewhere (determined False) get one red ring each and one
    legend entry; a table without undetermined rows gets none."""
    frame = table()
    assert "determined" in frame and frame["determined"].notna().all()
    labels = lambda fig: [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert not any("not determined" in text for text in labels(figures.phase_diagram(frame)))
    frame = frame.assign(determined=[False] + [True] * (len(frame) - 1))
    fig = figures.phase_diagram(frame)
    assert sum("not determined" in text for text in labels(fig)) == 1
    rings = [c for c in fig.axes[0].collections if c.get_label().startswith("not determined")]
    assert len(rings) == 1 and len(rings[0].get_offsets()) == 1
    assert tuple(rings[0].get_offsets()[0]) == (frame["theta0_deg"].iloc[0], frame["g0"].iloc[0])
    fig = figures.q_and_tilt(frame)
    assert any(c.get_label().startswith("not determined") for c in fig.axes[0].collections)


# ---- scripts/make_figures.py ---------------------------------------------------------
def test_make_figures_quick_draws_every_committed_figure(tmp_path):
    """``scripts/make_figures.py --quick`` runs every step on tiny inputs and draws every
    PNG, GIF and HTML page of docs/figures/: the one command covers the committed figures."""
    committed = sorted(name for name in os.listdir(os.path.join(ROOT, "docs", "figures"))
                       if name.endswith((".png", ".gif", ".html")))
    out = tmp_path / "figures"
    done = subprocess.run(
        [sys.executable, os.path.join("scripts", "make_figures.py"), "--quick", "--threads", "1",
         "--runs", str(tmp_path / "runs"), "--out", str(out)],
        cwd=ROOT, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert sorted(os.listdir(out)) == committed
    for name in committed:
        assert (out / name).stat().st_size > 5_000, name
    assert f"{len(committed)} figures in {out}" in done.stdout


def test_make_figures_quick_refuses_the_docs_folder():
    done = subprocess.run(
        [sys.executable, os.path.join("scripts", "make_figures.py"), "--quick", "--dry-run"],
        cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and "not docs figures" in done.stderr
