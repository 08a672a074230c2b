"""``loopsim report``: one self-contained HTML page of a sweep directory.

The page holds, in this order: the command and its provenance (loopsim version,
creation times, machine: the result files' metadata, ``storage.read_results``); the
counts by regime, resolved and determined (``outcome_statistics.outcome_counts``: the numbers
``loopsim sweep`` closes with); the phase diagram (``figures.phase_diagram``), or for
a ``--seeds auto`` directory the regime probabilities per cell and the distribution
panels (``figures.distribution_summary``, without the steady branch); the failed cases
with their status and the rerun command (``outcome_statistics.RERUN_COMMAND``); the
costliest cases and the total cost (``outcome_statistics.costliest``,
``outcome_statistics.cost``); and the per-cell table (``outcome_statistics.summarize``: the
table ``loopsim summary`` prints).  Images are PNG data
URIs; the page loads nothing from the network and runs no script.

Orchestration only: every number comes from ``loopsim.outcome_statistics`` and every image from
``loopsim.figures``.
"""
import base64
import html
import io as _bytes
import os

from . import render_defaults

#: Columns of the per-cell table shown (those present), in order: the cell's inputs
#: first (``outcome_statistics.CELL_INPUTS``), then these.
CELL_COLUMNS = ("seeds", "resolved", "determined", "steady", "p_stable", "p_in_plane", "p_3d",
                "p_failed", "p_3d_low", "p_3d_high", "tilt_median", "tilt_median_low",
                "tilt_median_high", "aspect_median", "wall_s")
#: Costliest cases listed by default; resolution of the embedded figures
#: (``loopsim.render_defaults``).
COSTLIEST, REPORT_DPI = render_defaults.REPORT_COSTLIEST, render_defaults.REPORT_DPI

_STYLE = """body{font-family:sans-serif;max-width:72em;margin:1.5em auto;padding:0 1em;
color:#222}table{border-collapse:collapse;font-size:0.85em;margin:0.5em 0 1.2em}
td,th{border:1px solid #ccc;padding:0.2em 0.5em;text-align:right}th{background:#eee}
code,pre{background:#f4f4f4;padding:0.1em 0.3em}pre{white-space:pre-wrap;padding:0.5em}
img{max-width:100%}.warn{color:#a00}"""


def png_data_uri(fig, dpi=REPORT_DPI):
    """The figure ``fig`` as a ``data:image/png;base64,...`` URI (the figure is closed)."""
    import matplotlib.pyplot as plt

    buffer = _bytes.BytesIO()
    try:
        fig.savefig(buffer, format="png", dpi=dpi)
    finally:
        plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buffer.getvalue()).decode("ascii")


def _cell(value):
    import pandas as pd

    if value is None or value is pd.NA:  # unknown (summary's steady without early stop)
        return ""
    if isinstance(value, float):
        return "" if value != value else f"{value:.4g}"
    return html.escape(str(value))


def table_html(frame, columns=None, table_id=None):
    """An HTML table of ``frame`` (its ``columns``, default all): a header row, then one
    row per row, floats to 4 significant digits (NaN and unknown values as empty cells)."""
    columns = [c for c in (columns or frame.columns) if c in frame]
    head = "".join(f"<th>{html.escape(str(c))}</th>" for c in columns)
    body = "".join("<tr>" + "".join(f"<td>{_cell(v)}</td>" for v in row) + "</tr>\n"
                   for row in frame[columns].itertuples(index=False))
    ident = f' id="{table_id}"' if table_id else ""
    return f"<table{ident}><thead><tr>{head}</tr></thead><tbody>\n{body}</tbody></table>"


def _counts_text(counts):
    return ", ".join(f"{k} {v}" for k, v in counts.items()) or "none"


def _provenance(meta, sweep_dir):
    command = meta.get("command_line") or []
    created = (meta.get("created_utc_first"), meta.get("created_utc_last"))
    rows = [("sweep directory", sweep_dir),
            ("loopsim version", meta.get("loopsim_version", "not recorded")),
            ("created (UTC)", created[0] if created[0] == created[1]
             else f"{created[0]} to {created[1]}"),
            ("machine", meta.get("machine", "not recorded (written before loopsim 0.3)")),
            ("result files", meta.get("files", "")),
            ("reruns of failed cases", len(meta.get("reruns", []) or []))]
    if "rounds" in meta:
        rows.append(("--seeds auto rounds", meta["rounds"]))
    lines = "".join(f"<tr><th>{html.escape(k)}</th><td style='text-align:left'>"
                    f"{html.escape(str(v))}</td></tr>" for k, v in rows)
    shown = " ".join(command) if isinstance(command, list) else str(command)
    return (f"<h2>Command and provenance</h2><pre>{html.escape(shown or 'not recorded')}</pre>"
            f"<table id='provenance'>{lines}</table>")


def _counts(counts, stopped):
    from . import outcome_statistics

    items = [("cases", counts["cases"]), ("by regime", _counts_text(counts["regimes"])),
             ("not resolved at their n", f"{counts['unresolved']} (regimes among them: "
              f"{_counts_text(counts['unresolved_regimes'])})"),
             ("resolved", counts["cases"] - counts["unresolved"]),
             ("not determined (a twin ends elsewhere)",
              outcome_statistics.undetermined_text(counts)),
             ("still moving at their end (terminal_state unsteady)",
              outcome_statistics.unsteady_text(counts)),
             ("failed", counts["failed"])]
    if stopped is not None:
        items.append(("points, why their seeds stopped", f"{stopped['points']}: "
                      f"{_counts_text(stopped['reasons'])} (seeds per point "
                      f"{stopped['seeds_min']}-{stopped['seeds_max']})"))
    rows = "".join(f"<tr><th>{html.escape(k)}</th><td style='text-align:left'>"
                   f"{html.escape(str(v))}</td></tr>" for k, v in items)
    return f"<h2>Outcomes</h2><table id='counts'>{rows}</table>"


def _figures(frame, cells, seeds_auto):
    """The figure section: the diagram, or why it is not drawn (a table that mixes models,
    or holds several cells at one point: the figure functions refuse those)."""
    from . import figures

    title = ("regime probabilities per cell and distributions over seeds" if seeds_auto
             else "phase diagram")
    try:
        fig = (figures.distribution_summary(cells, frame) if seeds_auto
               else figures.phase_diagram(frame, rest_window=figures.rest_window_for(frame)))
    except ValueError as exc:
        return (f"<h2>{html.escape(title.capitalize())}</h2><p class='warn'>not drawn: "
                f"{html.escape(str(exc))}</p>")
    return (f"<h2>{html.escape(title.capitalize())}</h2>"
            f"<img alt='{html.escape(title)}' src='{png_data_uri(fig)}'>")


#: The settling columns of the report's per-cell settling table (``loopsim.survival``).
SETTLING_SHOWN = ("at_rest", "rest_observed", "rest_inside", "rest_below", "rest_outside",
                  "p_rest_t10", "p_rest_t10_low", "p_rest_t10_high",
                  "t_rest_median", "t_rest_median_low", "t_rest_median_high", "t_rest_q95",
                  "escape_events", "escape_rate", "escape_rate_low", "escape_rate_high")
#: The survival curves are drawn for at most this many cells (one curve each), and only
#: for a sweep run past the paper's horizon (a run-to-rest sweep, ``--t-end`` > 10).
SURVIVAL_CELLS_MAX = 10


def settling_section(frame, cells):
    """The settling section: per cell, how many came to rest, P(at rest by t = 10), the
    median settling time and the escape rate (``loopsim.survival``), and the survival
    curves of a run-to-rest sweep; empty where the rows were not tested for rest."""
    from . import figures, survival

    if "at_rest" not in cells:
        return ""
    inputs = [c for c in cells.columns if c in ("g0", "theta0_deg", "t_end")]
    parts = ["<h2>Settling</h2><p>A loop comes to rest when it passes the steady test "
             "(stop_reason steady; its settling time is t_final); one still moving at its "
             "t_end is censored there. P(at rest by the paper's horizon t = 10) with its 95 % "
             "interval (Wilson where every run was observed to t = 10, else Kaplan–Meier), "
             "the Kaplan–Meier median settling time with its interval (NaN: not reached "
             "within the runs), the escape rate after t = 10 (NaN: fewer than 3 loops came "
             "to rest after t = 10), and where the loops at rest lie in the stable branch's "
             "tilt window (docs/sweeps.md).</p>",
             table_html(cells, inputs + [c for c in SETTLING_SHOWN if c in cells], "settling")]
    if len(cells) <= SURVIVAL_CELLS_MAX and frame["t_end"].max() > survival.PAPER_HORIZON:
        fig = figures.survival_curves(frame)
        parts.append(f"<img alt='survival of not yet at rest' src='{png_data_uri(fig)}'>")
    return "".join(parts)


def _failed(frame, sweep_dir):
    from . import outcome_statistics

    failed = frame[frame["status"] != "ok"]
    if not len(failed):
        return "<h2>Failed cases</h2><p>none</p>"
    command = outcome_statistics.RERUN_COMMAND.format(out=sweep_dir)
    return (f"<h2>Failed cases</h2><p class='warn'>{len(failed)} of {len(frame)} cases failed "
            f"(reason: column <code>status</code>); rerun them with:</p>"
            f"<pre id='rerun'>{html.escape(command)}</pre>"
            + table_html(failed, ["case_id", "g0", "theta0_deg", "seed", "n_used", "method",
                                  "status", "t_final", "wall_s"], "failed"))


def _cost(frame, count):
    from . import outcome_statistics

    total = outcome_statistics.cost(frame)
    return (f"<h2>Cost</h2><p id='total-cost'>{total['cases']} cases, "
            f"{total['wall_s']:.4g} s of integration in all (wall_s summed), "
            f"{total['nfev']} right-hand sides, {total['twin_nfev']} more in twins.</p>"
            f"<p>The {min(count, len(frame))} costliest cases:</p>"
            + table_html(outcome_statistics.costliest(frame, count), table_id="costliest"))


def report_html(sweep_dir, seed=0, costliest=COSTLIEST):
    """The HTML page of the sweep directory ``sweep_dir`` (see the module docstring), as a
    string.  ``seed``: the bootstrap seed of the per-cell table (as ``loopsim summary
    --seed``); ``costliest``: how many of the costliest cases to list.  ValueError (one
    line) for a directory that cannot be read or holds no finished case."""
    from . import figures, outcome_statistics, storage

    frame = figures.read_sweep(sweep_dir)
    seeds_auto = storage.is_seeds_auto(sweep_dir)
    stopped = None
    if seeds_auto and os.path.isfile(os.path.join(sweep_dir, storage.STOPS_FILE)):
        stopped = outcome_statistics.stop_counts(storage.read_stop_table(sweep_dir))
    window = None
    if "stop_reason" in frame and frame["stop_reason"].eq("steady").any():
        from .stability import rest_window  # where the loops at rest lie

        window = rest_window.window_for(frame)
    cells = outcome_statistics.summarize(frame, seed=seed, rest_window=window)
    shown = [c for c in cells.columns if c in outcome_statistics.CELL_INPUTS] + list(CELL_COLUMNS)
    meta = frame.attrs.get("loopsim", {})
    title = f"loopsim report: {os.path.basename(os.path.abspath(sweep_dir))}"
    parts = [
        f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
        f"<title>{html.escape(title)}</title><style>{_STYLE}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
        _provenance(meta, sweep_dir),
        _counts(outcome_statistics.outcome_counts(frame), stopped),
        _figures(frame, cells, seeds_auto),
        settling_section(frame, cells),
        _failed(frame, sweep_dir),
        _cost(frame, costliest),
        f"<h2>Per cell</h2><p>One row per cell (<code>loopsim summary {html.escape(sweep_dir)}"
        f" --seed {seed}</code>): regime probabilities with 95 % Wilson intervals, median "
        "terminal tilt (deg) with its 95 % bootstrap interval, median aspect ratio, "
        "wall_s summed.</p>" + table_html(cells, shown, "cells"),
        "</body></html>\n",
    ]
    return "\n".join(parts)


def report(sweep_dir, out, seed=0, costliest=COSTLIEST):
    """Write the one-page HTML report of a sweep directory.

    The page (see the module docstring) holds the command and provenance, the counts by
    regime, resolved and determined, the phase diagram (for ``--seeds auto``: the
    regime probabilities and distribution panels), the failed cases with the rerun
    command, the costliest cases and the total cost, and the per-cell table of
    ``loopsim summary``.  Images are embedded as PNG data URIs; the page needs no
    network and no JavaScript.

    Parameters
    ----------
    sweep_dir : str or os.PathLike
        A sweep directory (``loopsim sweep --out``), ``--seeds auto`` ones included.
    out : str or os.PathLike
        The HTML file to write.
    seed : int, default 0
        Seed of the per-cell table's bootstrap intervals (as ``loopsim summary --seed``).
    costliest : int, default 10
        How many of the costliest cases (largest ``wall_s``) to list.

    Returns
    -------
    str or os.PathLike
        ``out``.

    Raises
    ------
    ValueError
        One line: ``out`` cannot be written (checked before any work), or the directory
        is missing, unreadable or holds no finished case.  The file is written
        atomically: a failed write leaves none.

    Examples
    --------
    The README's main job's report is ``loopsim.report("runs/phase", "runs/phase.html")``;
    here a small sweep's:

    >>> import loopsim
    >>> rows = loopsim.sweep([10.0, 40.0], 30.0, "runs/two", n=6, t_end=0.5, twin=False)
    >>> loopsim.report("runs/two", "runs/two.html")
    'runs/two.html'
    """
    from . import storage, validation

    validation.check_output_file("out", out)
    page = report_html(os.fspath(sweep_dir), seed=seed, costliest=costliest)

    def write(path):
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(page)

    storage.write_file_atomically(os.fspath(out), write)
    return out
