"""``loopsim report`` (one HTML page of a sweep) and ``loopsim animate`` (a GIF of a run),
issue 39: the page parses, its images decode and its numbers are the summary's; the
animation has one frame per stored snapshot; bad input leaves no file."""
import base64
import html.parser
import io as stdio
import os
import re

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import loopsim  # noqa: E402
from loopsim import outcome_statistics, sweeps  # noqa: E402
from loopsim.cli import main  # noqa: E402

PIL = pytest.importorskip("PIL")
from PIL import Image, ImageSequence  # noqa: E402

SNAPSHOTS = 12
#: The committed tables and sweeps.
DATA = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data")


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    """Four cases (g0 10, 60 x θ0 30, 60; n = 4; t = 3; no early stop) under a step
    budget of 500: rkf45 takes about 300 steps on the first three and exhausts it on
    g0 = 60, θ0 = 60 (about 1400); every case traced with 12 snapshots."""
    out = str(tmp_path_factory.mktemp("report") / "s")
    cases = sweeps.grid_cases([10.0, 60.0], [30.0, 60.0], [4], seeds=1)
    frame = sweeps.run_sweep(sweeps.SweepConfig(
        cases=cases, t_end=3.0, max_steps=500, chunk_size=2, snapshots_for=[0, 1, 2, 3],
        early_stop=False,
        snapshot_count=SNAPSHOTS), out, threads=1, quiet=True)
    return out, frame


class Page(html.parser.HTMLParser):
    """The tables (by id: rows of cell texts), images (src) and text of an HTML page."""

    def __init__(self):
        super().__init__()
        self.tables, self.images, self.text, self.open = {}, [], [], []
        self._table = self._row = None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag not in ("img", "meta", "br"):
            self.open.append(tag)
        if tag == "table":
            self._table = self.tables.setdefault(attrs.get("id", f"t{len(self.tables)}"), [])
        elif tag == "tr" and self._table is not None:
            self._row = []
            self._table.append(self._row)
        elif tag in ("td", "th") and self._row is not None:
            self._row.append("")
        elif tag == "img":
            self.images.append(attrs["src"])

    def handle_endtag(self, tag):
        assert self.open and self.open[-1] == tag, (tag, self.open[-3:])
        self.open.pop()
        if tag == "table":
            self._table = None

    def handle_data(self, data):
        self.text.append(data)
        if self._row is not None and self.open and self.open[-1] in ("td", "th"):
            self._row[-1] += data


def parse(path):
    page = Page()
    with open(path, encoding="utf-8") as handle:
        content = handle.read()
    page.feed(content)
    page.close()
    assert page.open == [], page.open  # every element closed
    return page, content


def png_ok(src):
    assert src.startswith("data:image/png;base64,")
    data = base64.b64decode(src.split(",", 1)[1], validate=True)
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    image = matplotlib.image.imread(stdio.BytesIO(data), format="png")
    assert image.ndim == 3 and image.shape[0] > 100 and image.shape[1] > 100
    return image


def test_report_parses_its_images_decode_and_its_numbers_are_the_summarys(sweep, tmp_path):
    out, frame = sweep
    target = tmp_path / "report.html"
    assert main(["report", out, "--out", str(target), "--costliest", "3"]) == 0
    page, content = parse(target)
    assert "<script" not in content and "http://" not in content and "https://" not in content
    assert len(page.images) == 1
    png_ok(page.images[0])
    # the per-cell table is outcome_statistics.summarize's, to the 4 digits shown
    cells = outcome_statistics.summarize(frame)
    rows = page.tables["cells"]
    header, body = rows[0], rows[1:]
    assert len(body) == len(cells) == 4
    for column in ("g0", "theta0_deg", "seeds", "resolved", "determined", "p_3d", "tilt_median",
                   "wall_s"):
        shown = [float(r[header.index(column)]) if r[header.index(column)] else np.nan
                 for r in body]
        assert np.allclose(shown, cells[column].to_numpy(float), rtol=5e-4, equal_nan=True), column
    # counts, counted here from the rows
    counts = dict((r[0], r[1]) for r in page.tables["counts"])
    assert counts["cases"] == "4"
    failed = int((frame["status"] != "ok").sum())
    assert 1 <= failed <= 3 and counts["failed"] == str(failed)
    for regime, number in frame["regime"].value_counts().items():
        assert f"{regime} {number}" in counts["by regime"]
    assert counts["resolved"] == str(int(frame["resolved"].sum()))
    # the failed cases and the rerun command
    assert len(page.tables["failed"]) == 1 + failed
    assert f"loopsim sweep --rerun-failed {out} --method radau5" in content
    # cost: the three costliest rows, and the sum of wall_s
    costliest = page.tables["costliest"]
    shown = [float(r[costliest[0].index("wall_s")]) for r in costliest[1:]]
    assert np.allclose(shown, np.sort(frame["wall_s"].to_numpy())[::-1][:3], rtol=5e-4)
    total = re.search(r"([0-9.e+-]+) s of integration", content).group(1)
    assert float(total) == pytest.approx(frame["wall_s"].sum(), rel=5e-4)
    # provenance: version, creation time, machine
    provenance = dict((r[0], r[1]) for r in page.tables["provenance"])
    assert provenance["loopsim version"] == loopsim.__version__
    assert provenance["created (UTC)"].startswith("20")
    assert "CPUs" in provenance["machine"]


def test_steady_is_unknown_for_a_sweep_without_early_stop(sweep, tmp_path, capsys):
    """Issue 46.4: the fixture's sweep ran with --no-early-stop, so no run was tested for a
    steady state: ``steady`` is unknown (empty), not 0, in summarize, ``loopsim summary``
    (printed and written) and the report."""
    out, frame = sweep
    assert frame.attrs["loopsim"]["sweep_config"]["early_stop"] is False
    cells = outcome_statistics.summarize(frame)
    assert cells["steady"].isna().all() and cells["seeds"].notna().all()
    table = tmp_path / "cells.parquet"
    assert main(["summary", out, "--out", str(table)]) == 0
    printed = capsys.readouterr().out.splitlines()
    steady = printed[0].split().index("steady")
    assert all(line.split()[steady] == "<NA>" for line in printed[1:5]), printed
    import pandas as pd

    assert pd.read_parquet(table)["steady"].isna().all()
    target = tmp_path / "report.html"
    assert main(["report", out, "--out", str(target)]) == 0
    rows = parse(target)[0].tables["cells"]
    column = rows[0].index("steady")
    assert [r[column] for r in rows[1:]] == [""] * 4


def test_report_of_a_seeds_auto_directory_shows_the_distributions(tmp_path):
    from loopsim import seeds_auto_rule
    from loopsim.sweeps.seeds_auto import run_seeds_auto

    config = sweeps.SweepConfig(cases=sweeps.grid_cases([10.0], [30.0], [4], 1), t_end=0.3,
                                method="rkf45", twin=False, chunk_size=2)
    out = str(tmp_path / "auto")
    rows, stops = run_seeds_auto(config, out, seeds_auto_rule.SeedTargets(),
                                 run_round=lambda c, d, weights=None: sweeps.run_sweep(
                                     c, d, threads=1, quiet=True))
    target = tmp_path / "auto.html"
    loopsim.report(out, str(target))
    page, content = parse(target)
    assert len(page.images) == 1
    assert png_ok(page.images[0]).shape[1] > 2 * png_ok(page.images[0]).shape[0]  # panels
    counts = dict((r[0], r[1]) for r in page.tables["counts"])
    assert counts["cases"] == str(len(rows))
    assert f"{stops['stop_reason'].iloc[0]} 1" in counts["points, why their seeds stopped"]
    assert page.tables["cells"][1][page.tables["cells"][0].index("seeds")] == str(len(rows))


def test_report_refuses_bad_input_and_leaves_nothing(sweep, tmp_path, capsys):
    out, _ = sweep
    target = tmp_path / "r.html"
    assert main(["report", str(tmp_path / "missing"), "--out", str(target)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("loopsim: error:") and "missing" in err and err.count("\n") == 1
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main(["report", out, "--out", str(blocker / "r.html")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("loopsim: error:") and err.count("\n") == 1
    assert sorted(os.listdir(tmp_path)) == ["file"]


def frames_of(path):
    with Image.open(path) as image:
        assert image.format == "GIF"
        return image.size, sum(1 for _ in ImageSequence.Iterator(image))


def test_animate_a_sweep_case_one_frame_per_snapshot(sweep, tmp_path):
    out, frame = sweep
    case = int(frame[frame["status"] == "ok"]["case_id"].iloc[0])
    target = tmp_path / "case.gif"
    assert main(["animate", out, "--case-id", str(case), "--out", str(target)]) == 0
    size, count = frames_of(target)
    stored = loopsim.read_snapshots(out)
    assert (stored["case_id"] == case).sum() == SNAPSHOTS  # the run reached t = 3
    assert count == SNAPSHOTS and size == (672, 304)  # 8.4 x 3.8 in at 80 dpi
    assert target.stat().st_size < 3e6
    assert loopsim.animate(out, str(tmp_path / "five.gif"), case_id=case, frames=5, dpi=40) == 5
    assert frames_of(tmp_path / "five.gif") == ((336, 152), 5)


def test_animate_a_run_file(tmp_path):
    run = tmp_path / "run.parquet"
    assert main(["run", "--g0", "60", "--theta0", "30", "--n", "4", "--t-end", "1",
                 "--snapshots", "7", "--no-twin", "--out", str(run)]) == 0
    assert main(["animate", str(run), "--out", str(tmp_path / "run.gif"), "--dpi", "50"]) == 0
    assert frames_of(tmp_path / "run.gif")[1] == 7


def test_animate_refuses_bad_input_and_leaves_nothing(sweep, tmp_path, capsys, monkeypatch):
    out, frame = sweep
    cases = frame["case_id"].tolist()

    def refused(argv, *words):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith("loopsim: error:") and err.count("\n") == 1, err
        for word in words:
            assert word in err, (word, err)

    gif = str(tmp_path / "a.gif")
    refused(["animate", out, "--case-id", "99", "--out", gif], "no finished case 99")
    refused(["animate", out, "--out", gif], "--case-id")
    refused(["animate", out, "--case-id", str(cases[0]), "--out", str(tmp_path / "a.png")],
            ".gif or .mp4")
    refused(["animate", out, "--case-id", str(cases[0]), "--out", gif, "--frames", "1"],
            "--frames")
    blocker = tmp_path / "file"
    blocker.write_text("")
    refused(["animate", out, "--case-id", str(cases[0]), "--out", str(blocker / "a.gif")],
            "--out")
    blocker.unlink()
    monkeypatch.setattr("shutil.which", lambda name: None)
    refused(["animate", out, "--case-id", str(cases[0]), "--out", str(tmp_path / "a.mp4")],
            "ffmpeg", "a.gif")
    assert os.listdir(tmp_path) == []


def test_animate_refuses_a_case_without_snapshots(tmp_path, capsys):
    out = str(tmp_path / "s")
    sweeps.run_sweep(sweeps.SweepConfig(cases=sweeps.grid_cases([10.0], [30.0], [4], 1),
                                        t_end=0.3, twin=False), out, threads=1, quiet=True)
    target = tmp_path / "a.gif"
    assert main(["animate", out, "--case-id", "0", "--out", str(target)]) == 2
    err = capsys.readouterr().err
    assert "has no snapshots" in err and "--snapshots-for 0" in err and err.count("\n") == 1
    assert not target.exists()


def test_report_names_a_diagram_it_cannot_draw(sweep, tmp_path, monkeypatch):
    """A table the figure functions refuse (several models, several cells at one point)
    still gets its page, with the reason in place of the diagram."""
    from loopsim import figures

    out, _ = sweep

    def refuse(frame, *args, **kwargs):
        raise ValueError("the table mixes models [('local', None), ('nonlocal', 0.01)]")

    monkeypatch.setattr(figures, "phase_diagram", refuse)
    target = tmp_path / "r.html"
    loopsim.report(out, str(target))
    page, content = parse(target)
    assert page.images == [] and "not drawn: the table mixes models" in content
    assert len(page.tables["cells"]) == 5


def _counts_cell(content, label):
    """The text of the report's counts row whose header starts with ``label``."""
    found = re.search(re.escape(label) + r"[^<]*</th><td[^>]*>([^<]*)</td>", content)
    assert found, label
    return html.unescape(found.group(1))


def _committed_report_cell(tmp_path, sweep, label):
    """The counts row ``label`` of the report of a committed sweep under data/."""
    out = tmp_path / "r.html"
    assert main(["report", os.path.join(DATA, sweep), "--out", str(out)]) == 0
    return _counts_cell(out.read_text(encoding="utf-8"), label)


def test_report_of_rows_without_terminal_state_says_not_recorded(tmp_path):
    """Issue 54.1: data/convergence_runs/default_t12 (80 rows, none with terminal_state:
    written before it existed) reported "still moving at their end: 0"."""
    sweep = os.path.join("convergence_runs", "default_t12")
    moving = _committed_report_cell(tmp_path, sweep, "still moving at their end")
    assert moving.startswith("not recorded (unknown) for 80 of 80 cases"), moving
    counts = outcome_statistics.outcome_counts(loopsim.read_results(os.path.join(DATA, sweep)))
    assert counts["unsteady"] is None and counts["unsteady_not_recorded"] == 80


def test_report_of_a_sweep_without_twins_says_not_checked(tmp_path):
    """Audit L6: the report of a --no-twin sweep read "not determined: 0"."""
    undetermined = _committed_report_cell(tmp_path, os.path.join("rest_runs", "range_rest_t36"),
                                          "not determined")
    assert undetermined.startswith("not checked (unknown): no case ran a twin"), undetermined
