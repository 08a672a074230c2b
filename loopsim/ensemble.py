"""Ensemble sweeps: cases -> pieces -> Parquet files in a directory, resumable.

A sweep directory is a Parquet dataset (``pandas.read_parquet(DIR)`` returns the
rows): ``_sweep.json`` (the configuration and its fingerprint, written once,
first), one ``chunk-SSSSSSS-EEEEEEE.parquet`` per finished piece at the top,
snapshots in ``_snapshots/``.  Cases are laid out in a fixed order of positions
(:func:`case_order`, a golden-ratio stride, so neighbours differ); chunk k is
positions [k c, (k + 1) c) for chunk size c, and a file holds the positions
[S, E) of a finished piece of a chunk, written under a temporary name and
renamed into place.  A resume computes the positions no file holds, so a
changed chunk size, a piece cut short by a signal and job-array shards all
fit.  Cases run on a work queue of this machine's threads or as Dask tasks.  No numerics
here: integration is ``batch``, start shapes ``shapes``, summaries ``api``,
tables ``io``.
"""
import contextlib
import dataclasses
import functools
import itertools
import json
import math
import os
import queue
import re
import signal
import sys
import threading
import time
import warnings

import numpy as np
import pandas as pd
import pyarrow as pa

from . import (
    api, columns, diagnostics, integrators, io, models, outcomes, refinement, shapes, spectral,
    validation,
)
from . import _jitcache
from ._blas import one_blas_thread
from .config import (
    DEFAULT_ATOL, DEFAULT_AUTO_CHUNK_SIZE, DEFAULT_CHUNK_SIZE, DEFAULT_LENGTH_TOL,
    DEFAULT_MAX_STEPS, DEFAULT_N, DEFAULT_N_MAX, DEFAULT_PERTURBATION, DEFAULT_RTOL,
    DEFAULT_STEADY_INTERVAL, DEFAULT_STEADY_TOL, DEFAULT_T_END, DEFAULT_TAIL_TOL, DEFAULT_W,
)
from .outcomes import REGIMES, Thresholds, classify  # noqa: F401 - re-exported

# ---- the table (schema: io.RESULT_SCHEMA; every column described in loopsim.columns) ----
FIELD_NOTES = {name: text for name, (_, text) in columns.RESULT_COLUMNS.items()}


# ---- configuration -------------------------------------------------------
def parse_values(text, name, integer=False):
    """'START:STOP:NUM' (linspace, ends included) or 'v1,v2,...' -> list of numbers; NUM at
    most ``validation.MAX_CASES`` (checked before anything is built)."""
    convert = int if integer else float
    num = None
    try:
        if ":" in text:
            start, stop, num = text.split(":")
            num = int(num)
            if num < 1:
                raise ValueError
            if num <= validation.MAX_CASES:
                values = np.linspace(float(start), float(stop), num).tolist()
        else:
            values = [convert(v) for v in text.split(",") if v.strip()]
        if num is None or num <= validation.MAX_CASES:
            if not values or not all(math.isfinite(v) for v in values):
                raise ValueError
    except ValueError:
        form = "v1,v2,..." if integer else "START:STOP:NUM or v1,v2,..."
        raise ValueError(f"{name} must be {form}, got {text!r}") from None
    if num is not None and num > validation.MAX_CASES:
        raise ValueError(f"{name} asks for {num} values, more than a sweep's "
                         f"{validation.MAX_CASES} cases: {text!r}")
    return [convert(v) for v in values]


@dataclasses.dataclass
class SweepConfig:
    """Everything that determines a sweep's results (stored in _sweep.json)."""

    cases: list  # of dicts: g0, theta0_deg, n (the start with n_auto), seed, perturbation
    t_end: float = DEFAULT_T_END
    rtol: float = DEFAULT_RTOL
    atol: float = DEFAULT_ATOL
    w: float = DEFAULT_W
    method: str = "rkf45"
    max_steps: int = DEFAULT_MAX_STEPS
    length_tol: float = DEFAULT_LENGTH_TOL
    chunk_size: int = DEFAULT_CHUNK_SIZE
    early_stop: bool = True
    snapshots_for: list = dataclasses.field(default_factory=list)  # case ids
    snapshot_count: int = 101
    steady_interval: float = DEFAULT_STEADY_INTERVAL
    steady_tol: float = DEFAULT_STEADY_TOL
    thresholds: Thresholds = Thresholds()
    n_auto: bool = False  # raise n during each run (loopsim.refinement)
    n_max: int = DEFAULT_N_MAX
    tail_tol: float = DEFAULT_TAIL_TOL
    twin: bool = True  # run each case's stricter twin (loopsim.outcomes: determined or not)

    def step_options(self):
        return integrators.step_options(
            self.rtol, self.atol, max_steps=self.max_steps, constraint_tol=self.length_tol,
            steady_interval=self.steady_interval if self.early_stop else 0.0,
            steady_tol=self.steady_tol)

    def as_dict(self):
        return dataclasses.asdict(self)

    @property
    def n_chunks(self):
        return max(1, math.ceil(len(self.cases) / self.chunk_size))


def grid_cases(g0_values, theta0_values, n_values, seeds, perturbation=DEFAULT_PERTURBATION):
    """Cartesian product, case_id in the order n, g0, θ0, seed."""
    return [
        dict(g0=float(g0), theta0_deg=float(theta), n=int(n), seed=int(seed),
             perturbation=float(perturbation))
        for n, g0, theta, seed in itertools.product(n_values, g0_values, theta0_values, range(seeds))
    ]


def _cell(path, row, column, value, integer):
    """One value of a cases file as float or int, or a one-line error naming file, row
    (counted from 0, as in pandas) and column."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"cases file {path!r}, row {row}, column {column}: not a number: "
                         f"{value!r}") from None
    if integer:
        if not number.is_integer():
            raise ValueError(f"cases file {path!r}, row {row}, column {column}: must be an "
                             f"integer, got {value!r}")
        return int(number)
    return number


#: Optional per-case columns of a cases file that override the sweep's option.
CASE_OVERRIDES = ("method", "rtol", "t_end")
#: Every column a cases file may have.
CASE_COLUMNS = ("g0", "theta0_deg", "n", "seed", "perturbation", "initial",
                "initial_case_id") + CASE_OVERRIDES


def _check_case_columns(path, names):
    """One-line ValueError for a duplicate or unknown column of a cases file (pandas
    renames a CSV's second ``g0`` to ``g0.1``)."""
    seen = set()
    for name in names:
        base = re.sub(r"\.\d+$", "", str(name)) if str(name) not in CASE_COLUMNS else str(name)
        if base in seen or (base != str(name) and base in CASE_COLUMNS):
            raise ValueError(f"cases file {path!r} has column {base!r} twice")
        if base not in CASE_COLUMNS:
            raise ValueError(f"cases file {path!r} has an unknown column {str(name)!r}; "
                             f"known: {', '.join(CASE_COLUMNS)}")
        seen.add(base)


def _case_row(path, i, row):
    """A case dict from one row of a cases file (types checked, cell by cell); the
    optional ``CASE_OVERRIDES`` enter only where the cell is given."""
    case = dict(g0=_cell(path, i, "g0", row.g0, False),
                theta0_deg=_cell(path, i, "theta0_deg", row.theta0_deg, False),
                n=_cell(path, i, "n", row.n, True), seed=_cell(path, i, "seed", row.seed, True),
                perturbation=_cell(path, i, "perturbation", row.perturbation, False))
    for key in ("rtol", "t_end"):
        value = getattr(row, key, None)
        if value is not None and not (isinstance(value, float) and math.isnan(value)):
            case[key] = _cell(path, i, key, value, False)
    method = getattr(row, "method", None)
    if method is not None and not isinstance(method, str) and not pd.isna(method):
        raise ValueError(f"cases file {path!r}, row {i}, column method: must be one of "
                         f"{', '.join(refinement.METHOD_CHOICES)}, got {method!r}")
    if isinstance(method, str) and method.strip():
        if method.strip() not in refinement.METHOD_CHOICES:
            raise ValueError(f"cases file {path!r}, row {i}, column method: must be one of "
                             f"{', '.join(refinement.METHOD_CHOICES)}, got {method!r}")
        case["method"] = method.strip()
    return case


def case_option(config, case, key):
    """A case's ``rtol`` or ``t_end``: its own (a cases-file column) or the sweep's."""
    return case.get(key, getattr(config, key))


def read_cases_file(path, perturbation=DEFAULT_PERTURBATION, n=6):
    """Cases from a CSV or Parquet table: columns g0, theta0_deg (required), n, seed,
    perturbation, and per case (overriding the sweep's options) method, rtol, t_end."""
    validation.check_input_file("cases file", path, validation.MAX_CASES_FILE_BYTES)
    limit = validation.MAX_CASES
    try:
        if str(path).endswith(".parquet"):
            import pyarrow.parquet as pq

            parquet = pq.ParquetFile(path)
            rows = parquet.metadata.num_rows
            names = parquet.schema_arrow.names
            frame = None if rows > limit else pd.read_parquet(path)
        else:
            frame = pd.read_csv(path, nrows=limit + 1)
            rows, names = len(frame), list(frame.columns)
    except Exception as exc:  # noqa: BLE001 - any reader failure is the same user error
        raise ValueError(f"cannot read cases file {path!r}: {exc}".splitlines()[0]) from None
    if rows > limit:
        raise ValueError(f"cases file {path!r} has more than {limit} rows (a sweep's most "
                         "cases)")
    _check_case_columns(path, names)
    missing = {"g0"} | ({"theta0_deg"} if "initial" not in frame.columns else set())
    missing -= set(frame.columns)
    if missing:
        raise ValueError(f"cases file {path!r} lacks column(s) {sorted(missing)}")
    given = frame.notna() if "initial" in frame.columns else None  # per-cell: value given?
    frame = frame.assign(**{k: v for k, v in dict(n=n, seed=0, perturbation=perturbation,
                                                  theta0_deg=math.nan).items() if k not in frame})
    cases = [_case_row(path, i, row) for i, row in enumerate(frame.itertuples())]
    for i, case in enumerate(cases):  # optional column initial (file or results), initial_case_id
        if given is not None and given["initial"].iloc[i] and str(frame["initial"].iloc[i]).strip():
            case_id = frame["initial_case_id"].iloc[i] if "initial_case_id" in frame else None
            try:
                cases[i] = shapes.initial_case(
                    case, str(frame["initial"].iloc[i]).strip(),
                    None if case_id is None or pd.isna(case_id) else int(case_id),
                    os.path.dirname(str(path)),
                    "perturbation" in given and bool(given["perturbation"].iloc[i]))
            except ValueError as exc:
                raise ValueError(f"cases file row {i}: {exc}") from None
    return cases


def validate(config):
    """One-line ValueError naming the first bad value."""
    if not config.cases:
        raise ValueError("the sweep has no cases")
    if len(config.cases) > validation.MAX_CASES:
        raise ValueError(f"the sweep has {len(config.cases)} cases, more than "
                         f"{validation.MAX_CASES}: split it into several sweeps")
    for case_id, case in enumerate(config.cases):
        try:
            validation.check_real("g0", case["g0"], low=0.0)
            validation.check_tilt("theta0_deg", case["theta0_deg"])
            validation.check_order("n", case["n"])
            validation.check_integer("seed", case["seed"], 0)
            validation.check_perturbation("perturbation", case["perturbation"])
            for key in ("rtol", "t_end"):
                if key in case:
                    validation.check_real(key, case[key], low=0.0, low_open=True)
            if "method" in case:
                validation.check_choice("method", case["method"], refinement.METHOD_CHOICES)
        except ValueError as exc:
            raise ValueError(f"case {case_id}: {exc}") from None
    validation.check_real("t_end", config.t_end, low=0.0, low_open=True)
    validation.check_real("rtol", config.rtol, low=0.0, low_open=True)
    validation.check_real("atol", config.atol, low=0.0)
    validation.check_real("w", config.w, low=0.0)
    validation.check_integer("chunk_size", config.chunk_size, 1)
    validation.check_count("snapshot_count", config.snapshot_count, 2, validation.MAX_SNAPSHOTS,
                           "each is a step end and a stored state")
    for case_id in config.snapshots_for:
        if not 0 <= case_id < len(config.cases):
            raise ValueError(f"--snapshots-for names case {case_id}, but the sweep has cases "
                             f"0..{len(config.cases) - 1}")
    validation.check_choice("method", config.method, refinement.METHOD_CHOICES)
    validation.check_order("n_max", config.n_max)
    validation.check_real("tail_tol", config.tail_tol, low=0.0, low_open=True)


# ---- running ---------------------------------------------------------------
def _start(case):
    """Keyword arguments of ``shapes.start_shape`` (and ``simulate``) for a case's start."""
    if case.get("initial"):  # a case started from a file (cases column "initial")
        return dict(initial=case["initial"], initial_case_id=case.get("initial_case_id"),
                    n=case["n"], perturbation=case["perturbation"], seed=case["seed"])
    return dict(theta0_deg=case["theta0_deg"], n=case["n"], perturbation=case["perturbation"],
                seed=case["seed"])


def case_method(config, case):
    """The integrator of a case: its own or the sweep's, chosen per case if "auto"."""
    method = case.get("method", config.method)
    if method != "auto":
        return method
    return refinement.auto_method(diagnostics.stability_parameter(case["g0"], case["theta0_deg"]),
                                  case["n"], config.n_auto)


def case_ladder(config, case):
    """The truncation orders a case may use: its n, or with ``n_auto`` the ladder above it."""
    n = case["n"]
    return refinement.orders(n, max(n, config.n_max)) if config.n_auto else (n,)


def _result_row(config, case_id, case, x0, x, status_code, counts, worst, wall_s, t_final,
                method, twin=None):
    """One row of RESULT_SCHEMA for a finished case with final coefficients x (3, 2 n_used + 1);
    worst = (largest length error, largest spectral tail); ``twin``: the twin's end state
    (``api.twin_end_state``) or None."""
    n_used = (x.shape[1] - 1) // 2
    ok = status_code in integrators.SUCCESS
    end = outcomes.end_state(case["theta0_deg"], diagnostics.aspect_ratio(x0), x, ok,
                             config.thresholds)
    if not np.all(np.isfinite(x)):
        x = spectral.resize(x0, n_used)  # keep the row finite; the status says why
    problem = models.local_sbt.make_problem(n_used, case["g0"], config.w)
    u, multiplier = api.velocity_and_multiplier(problem, x)
    inputs = dict(g0=case["g0"], theta0_deg=case["theta0_deg"], n=case["n"],
                  t_end=case_option(config, case, "t_end"),
                  rtol=case_option(config, case, "rtol"), atol=config.atol, w=config.w,
                  perturbation=case["perturbation"], seed=case["seed"])
    determinacy = (dict(outcomes.NO_TWIN) if twin is None else
                   outcomes.determinacy(end, twin, twin["nfev"], config.thresholds))
    row = api.terminal_summary(
        inputs, x, u, multiplier, method=method, n_used=n_used,
        status=integrators.STATUS_NAMES[status_code], t_final=t_final, wall_s=wall_s,
        tail_max=float(worst[1]), regime=end["regime"],
        resolved=config.thresholds.resolved(worst[0], worst[1]), **determinacy,
        **dict(zip(integrators.COUNTS, (int(c) for c in counts))))
    row.update(
        case_id=case_id, aspect_ratio_initial=diagnostics.aspect_ratio(x0),
        x_final=x.ravel().tolist(), length_error_max=float(worst[0]),
        stop_reason=integrators.STOP_REASONS[status_code])
    return row


def _traced_case(config, case_id):
    """A case with snapshots: its row and trajectory come from one ``api.simulate`` run,
    so they agree exactly (snapshots come from dense output: the steps, and so the row,
    are those of the batch kernel)."""
    case = config.cases[case_id]
    method = case_method(config, case)
    start = dict(_start(case), **({"n": "auto", "n_start": case["n"]} if config.n_auto else {}))
    with warnings.catch_warnings():  # the row says it, and the sweep's summary counts it
        warnings.simplefilter("ignore", api.LoopsimWarning)
        result = api.simulate(
            case["g0"], **start, t_span=(0.0, case_option(config, case, "t_end")),
            snapshots=config.snapshot_count, rtol=case_option(config, case, "rtol"),
            atol=config.atol, w=config.w,
            method=method, max_steps=config.max_steps, length_tol=config.length_tol,
            steady_tol=config.steady_tol if config.early_stop else None,
            steady_interval=config.steady_interval, n_max=config.n_max,
            tail_tol=config.tail_tol, twin=config.twin)
    row = _result_row(config, case_id, case, result.x[0], result.x_final, result.status_code,
                      [getattr(result, name) for name in integrators.COUNTS],
                      (result.length_error_max, result.tail_max), result.wall_s,
                      result.t_final, method, result.twin)
    table = io.trajectory_table(result).replace_schema_metadata(None)
    for name in ("x", "multiplier"):  # orders differ between cases: variable-length lists
        table = table.set_column(table.schema.get_field_index(name), name,
                                 table.column(name).cast(pa.list_(pa.float64())))
    table = table.add_column(0, "case_id", pa.array([case_id] * table.num_rows, pa.int64()))
    return row, io.described(table, columns.TRAJECTORY_COLUMNS)


def run_chunk(config, chunk, threads):
    """Integrate one chunk's cases.

    Returns (results Table in RESULT_SCHEMA, snapshots Table or None).  Cases
    without snapshots run in the batch kernel (``refinement.integrate_cases``: a fixed
    n is a ladder of one order; parallel over ``threads`` lanes, serial on one), grouped
    by starting n, method and rtol; their ``wall_s`` is the batch's wall time x threads
    shared in proportion to RHS evaluations (a single case: its own wall time).
    """
    ids = chunk_case_ids(config, chunk)
    traced = sorted(set(ids) & set(config.snapshots_for))
    groups = {}
    for case_id in ids:
        if case_id not in traced:
            case = config.cases[case_id]
            key = (case["n"], case_method(config, case), case_option(config, case, "rtol"))
            groups.setdefault(key, []).append(case_id)
    start = time.perf_counter()
    compiled = _jitcache.compile_seconds()
    outputs = []
    for (n, method, rtol), members in sorted(groups.items()):
        cases = [config.cases[i] for i in members]
        x0 = [shapes.start_shape(**_start(c))[0] for c in cases]
        run = functools.partial(
            refinement.integrate_cases, integrators.METHODS[method],
            [(c["g0"], config.w) for c in cases], x0,
            [case_option(config, c, "t_end") for c in cases],
            ladder=case_ladder(config, cases[0]),
            cost=[diagnostics.stability_parameter(c["g0"], c["theta0_deg"]) for c in cases])
        options = config.step_options()._replace(rtol=float(rtol))
        result = run(options=options, tail_tol=config.tail_tol)
        twins = None
        if config.twin:
            twin_rtol, twin_atol, twin_tail = outcomes.twin_tolerances(
                options.rtol, options.atol, config.tail_tol)
            twins = run(options=options._replace(rtol=twin_rtol, atol=twin_atol),
                        tail_tol=twin_tail)
        outputs.append((members, x0, method, result, twins))
    wall = time.perf_counter() - start - (_jitcache.compile_seconds() - compiled)
    total_rhs = sum(int(result[4][:, 2].sum())
                    + (0 if twins is None else int(twins[4][:, 2].sum()))
                    for *_, result, twins in outputs) or 1
    rows = {}
    for members, x0, method, (x_final, _, t_final, status, counts, worst), twins in outputs:
        for b, case_id in enumerate(members):
            case = config.cases[case_id]
            twin = None
            if twins is not None:
                twin = dict(outcomes.end_state(
                    case["theta0_deg"], diagnostics.aspect_ratio(x0[b]), twins[0][b],
                    int(twins[3][b]) in integrators.SUCCESS, config.thresholds),
                    nfev=int(twins[4][b, 2]))
            rows[case_id] = _result_row(
                config, case_id, case, x0[b], x_final[b], int(status[b]),
                counts[b], worst[b], wall * threads * counts[b, 2] / total_rhs,
                float(t_final[b]), method, twin)
    snapshots = []
    for case_id in traced:
        rows[case_id], table = _traced_case(config, case_id)
        snapshots.append(table)
    table = pa.Table.from_pylist([rows[i] for i in sorted(rows)], schema=io.RESULT_SCHEMA)
    return table, (pa.concat_tables(snapshots) if snapshots else None)


# ---- where the cases go: positions, chunks, pieces ----------------------------------
case_order = io.case_order


def canonical_chunks(config):
    """The chunks of ``config.chunk_size`` consecutive positions (the last one shorter)."""
    size, count = config.chunk_size, len(config.cases)
    return [range(start, min(start + size, count)) for start in range(0, count, size)]


def chunk_case_ids(config, chunk):
    """Sorted case ids of a piece of work: ``chunk`` a range of positions (see
    :func:`case_order`), or an int k, the k-th of :func:`canonical_chunks`."""
    if not isinstance(chunk, range):
        chunk = canonical_chunks(config)[int(chunk)]
    order = case_order(len(config.cases))
    return sorted(order[p] for p in chunk)


def pending_pieces(config, covered, shard=None):
    """Position ranges still to compute: every chunk (of shard ``(i, n)``: the chunks k
    with k % n == i) less the positions ``covered`` (ranges of the files already there).
    A function of the configuration, the chunk size and the files only, so identical
    sweeps run side by side compute the same pieces and write the same file names; a
    changed chunk size only cuts the remaining positions differently (no case is lost or
    computed twice)."""
    pieces = []
    for k, chunk in enumerate(canonical_chunks(config)):
        if shard is not None and k % shard[1] != shard[0]:
            continue
        start = chunk.start
        for low, high in sorted(covered):
            if high <= start or low >= chunk.stop:
                continue
            if low > start:
                pieces.append(range(start, low))
            start = max(start, high)
        if start < chunk.stop:
            pieces.append(range(start, chunk.stop))
    return pieces


def write_piece(out, fingerprint, piece, table, snapshots):
    """Write a finished piece (positions ``piece``): its snapshots first, so that a result
    file always has its snapshots, then its results, each atomically.  The files carry
    the sweep's fingerprint and their positions, not the configuration."""
    meta = io.provenance(sweep_fingerprint=fingerprint, positions=[piece.start, piece.stop])
    name = io.CHUNK_PATTERN.format(piece.start, piece.stop)
    if snapshots is not None:
        os.makedirs(os.path.join(out, io.SNAPSHOT_DIR), exist_ok=True)
        io.write_table_atomically(snapshots.replace_schema_metadata(meta),
                                  os.path.join(out, io.SNAPSHOT_DIR, name))
    io.write_table_atomically(table.replace_schema_metadata(meta), os.path.join(out, name))


def run_piece(config, piece, threads=None, out=None, fingerprint=None):
    """One task of a sweep (what a Dask worker runs): :func:`run_chunk` on the positions
    ``piece`` with ``threads`` Numba threads (None: the process's default).  With ``out``
    the worker writes the piece itself and returns only (piece, case_id and status);
    without, it returns (piece, results, snapshots) for the caller to write."""
    import numba

    if threads:
        numba.set_num_threads(min(int(threads), numba.config.NUMBA_NUM_THREADS))
    table, snapshots = run_chunk(config, piece, numba.get_num_threads())
    if out is None:
        return piece, table, snapshots
    write_piece(out, fingerprint, piece, table, snapshots)
    return piece, table.select(["case_id", "status"]), None


# ---- progress in a terminal or a log file ----------------------------------------------
#: ``--n auto`` sweeps: a 3D case's wall time grows like q0**AUTO_COST_EXPONENT.  Fitted
#: (log-log least squares) to the 24 3D cases among the first 32 of the resolved main-job
#: grid (radau5, rtol 1e-6, t = 10): exponent 3.95, and 0.058 s × (q0 / 11)^3.95 meets the
#: cheap cases' median, 0.066 s, at q0 = 11 (docs/earlier-n-auto.md).
AUTO_COST_EXPONENT = 4.0


def case_weight(case, n_auto=False):
    """Estimated relative cost of a case, for the ETA.  Fixed n: n², times 3 when q0 > 11
    (3D loops: 2.7× the RHS evaluations of stable ones in docs/performance.md; one
    RHS costs about n^1.7).  ``n_auto``: n² × (q0 / 11)^4 when q0 > 11 (the resolved 3D
    transient climbs to n = 24–32, and its cost spans 1 s to minutes with q0)."""
    theta = case.get("theta0_deg", math.nan)
    q0 = diagnostics.stability_parameter(case["g0"], theta) if math.isfinite(theta) else 0.0
    if q0 <= 11.0:
        return float(case["n"] ** 2)
    return case["n"] ** 2 * ((q0 / 11.0) ** AUTO_COST_EXPONENT if n_auto else 3.0)


def _duration(seconds):
    if not math.isfinite(seconds):
        return "?"
    seconds = int(round(seconds))
    return f"{seconds // 3600}h{seconds // 60 % 60:02d}m{seconds % 60:02d}s"


class Progress:
    """Progress on stderr: a live line in a terminal; in a log file (not a TTY) one line
    every ``interval`` seconds, and a last one at the end.  Done/total, rate, ETA weighted
    by :func:`case_weight` (both from the time worked: kernel compilation left out),
    failures.  ``quiet``: nothing."""

    def __init__(self, weights, done_ids, quiet=False, stream=None, interval=30.0):
        self.stream = sys.stderr if stream is None else stream
        self.weights = weights  # {case_id: weight} of the cases this run is responsible for
        self.total, self.done, self.failures = len(weights), len(done_ids), 0
        self.weight_left = sum(weights.values()) - sum(weights[i] for i in done_ids)
        self.weight_run, self.cases_run = 0.0, 0
        self.start = self.last = time.perf_counter()
        self.compiled = _jitcache.compile_seconds()  # compilation is not work: not in the ETA
        self.quiet, self.interval = quiet, interval
        self.live = not quiet and self.stream.isatty()
        self.printed = None  # the last line written to a log (not repeated by close)

    def update(self, case_ids, failures):
        self.done += len(case_ids)
        self.cases_run += len(case_ids)
        self.failures += failures
        weight = sum(self.weights.get(i, 0.0) for i in case_ids)
        self.weight_run += weight
        self.weight_left -= weight
        now = time.perf_counter()
        if self.live:
            self.stream.write("\r" + self._line())
            self.stream.flush()
        elif not self.quiet and now - self.last >= self.interval:
            self.printed = self._line()
            self.stream.write(self.printed + "\n")
            self.stream.flush()
            self.last = now

    def _line(self):
        elapsed = time.perf_counter() - self.start
        working = max(elapsed - (_jitcache.compile_seconds() - self.compiled), 1e-9)
        rate = self.cases_run / working
        eta = (working * max(self.weight_left, 0.0) / self.weight_run if self.weight_run
               else math.nan)
        return (f"cases {self.done}/{self.total} ({100 * self.done / max(self.total, 1):3.0f}%) "
                f"{rate:6.2f} case/s elapsed {_duration(elapsed)} ETA {_duration(eta)} "
                f"failures {self.failures}")

    def close(self):
        if self.quiet:
            return
        line = self._line()
        if self.live or line != self.printed:
            self.stream.write(("\r" if self.live else "") + line + "\n")
            self.stream.flush()


# ---- stopping on a signal ----------------------------------------------------------------
class SweepInterrupted(KeyboardInterrupt):
    """A sweep stopped by SIGINT or SIGTERM; every finished case was written first.
    ``exit_status``: 128 + the signal number (130, 143)."""

    def __init__(self, signum, out, done, total):
        super().__init__(f"interrupted by {signal.Signals(signum).name}")
        self.signum, self.out, self.done, self.total = signum, out, done, total
        self.exit_status = 128 + signum


@contextlib.contextmanager
def _stop_on_signals(stop):
    """While running, SIGINT and SIGTERM set ``stop`` (a threading.Event, its ``signum``
    attribute the signal) instead of raising: the sweep notices within 0.1 s, writes
    what has finished and raises :class:`SweepInterrupted`.  Outside the main thread
    (no signals there) this does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        stop.signum = signum
        stop.set()

    previous = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


def _in_background(stop, function, *args):
    """function(*args) in a daemon thread, waited for in slices of 0.1 s; its result (its
    exception re-raised), or None once ``stop`` is set: then the thread runs on unused
    (a Numba kernel cannot be cut short; the process is about to exit)."""
    box = {}

    def target():
        try:
            box["result"] = function(*args)
        except BaseException as exc:  # noqa: BLE001 - handed to the waiting thread
            box["error"] = exc

    thread = threading.Thread(target=target, daemon=True, name="loopsim-sweep-unit")
    thread.start()
    while thread.is_alive():
        thread.join(0.1)
        if stop.is_set():
            return None
    if "error" in box:
        raise box["error"]
    return box["result"]


def stop_event():
    """A stop flag for :func:`stop_on_signals`: a threading.Event with ``signum`` None."""
    stop = threading.Event()
    stop.signum = None
    return stop


#: The one signal handling of every command that runs kernels (sweeps and ``loopsim run``).
stop_on_signals = _stop_on_signals
in_background = _in_background


# ---- the sweep directory -----------------------------------------------------------------
def _prepare_directory(out, config, command_line):
    """Create or check ``out`` and return the configuration's fingerprint.  A directory
    holds one configuration: every result file must carry its fingerprint.  Files wholly
    contained in another (a piece written on interrupt and later recomputed by a side-by-
    side identical sweep) are redundant and removed; partial overlaps are refused.  Then
    only dead processes' temporaries are removed."""
    io.check_layout(out)
    os.makedirs(out, exist_ok=True)
    current = json.loads(json.dumps(config.as_dict()))
    fingerprint = io.config_fingerprint(current)
    stored = io.read_sweep_file(out)
    if stored is not None and stored["fingerprint"] != fingerprint:
        previous = stored["config"]
        changed = sorted(k for k in set(previous) | set(current)
                         if k not in io.FINGERPRINT_IGNORES and previous.get(k) != current.get(k))
        raise ValueError(f"{out!r} holds a different sweep (differs in: "
                         f"{', '.join(changed) or 'its fingerprint'}); use another --out")
    files = io.chunk_files(out)
    repair_directory(out, files, stored)
    files = io.chunk_files(out)
    io.check_files_belong(dict(config=current, fingerprint=fingerprint), files)
    _remove_contained(out, files, len(config.cases))
    io.check_no_overlap(io.chunk_files(out))
    io.remove_stale_temporaries(out)
    io.remove_stale_temporaries(os.path.join(out, io.SNAPSHOT_DIR))
    if stored is None:
        hashed = all(io.CONTENT_KEY in io.read_metadata(path) for path in files.values())
        io.write_json_atomically(dict(
            layout=io.LAYOUT, fingerprint=fingerprint, config=current, command_line=command_line,
            field_notes=FIELD_NOTES, reruns=[],
            **({"checksums": io.CONTENT_KEY} if hashed else {}),
            **json.loads(json.dumps(io.provenance()))),
            os.path.join(out, io.SWEEP_FILE))
    return fingerprint


def repair_directory(out, files, stored):
    """Self-repair before a resume: every result file (and its snapshot file) is read back
    whole and checked (readable, Parquet page checksums, content hash); a damaged one is
    moved to ``out/_quarantine/`` with a one-line warning, so its cases are computed
    again.  Returns the number of files moved."""
    moved = 0
    for _, path, reason in io.damaged_files(out, files, stored):
        snapshot = os.path.join(out, io.SNAPSHOT_DIR, os.path.basename(path))
        if os.path.exists(snapshot):
            io.quarantine(out, snapshot, reason)
        moved += io.quarantine(out, path, reason)
    return moved


def _remove_contained(out, files, count):
    """Remove result files (and their snapshots) whose positions another file holds too,
    once that file's rows are checked to be the cases its name says."""
    import pyarrow.parquet as pq

    widest = None
    for start, stop in sorted(files, key=lambda key: (key[0], -key[1])):
        if widest is not None and start >= widest[0] and stop <= widest[1]:
            ids = pq.read_table(files[widest], columns=["case_id"]).column("case_id")
            io.check_rows(files[widest], widest, ids.to_pylist(), count)
            name = os.path.basename(files[start, stop])
            for path in (os.path.join(out, io.SNAPSHOT_DIR, name), files[start, stop]):
                if os.path.exists(path):
                    os.remove(path)
        elif widest is None or stop > widest[1]:
            widest = (start, stop)


def _covered_ids(config, covered):
    order = case_order(len(config.cases))
    return [order[p] for low, high in covered for p in range(low, high)]


def _failures(table):
    return sum(1 for s in table.column("status").to_pylist() if s != "ok")


# ---- running -------------------------------------------------------------------------------
def _joined(parts):
    """Finished tasks [(positions, results, snapshots)] of consecutive positions, in
    order -> one (positions, results, snapshots)."""
    snapshots = [p[2] for p in parts if p[2] is not None]
    return (range(parts[0][0].start, parts[-1][0].stop), pa.concat_tables([p[1] for p in parts]),
            pa.concat_tables(snapshots) if snapshots else None)


def _write_unfinished(out, fingerprint, piece, parts):
    """Write the finished tasks {start: (positions, results, snapshots)} of an unfinished
    piece: those from the piece's start as one shorter piece, each later one on its own."""
    done = [parts[k] for k in sorted(parts)]
    prefix, reached = 0, piece.start
    while prefix < len(done) and done[prefix][0].start == reached:
        reached = done[prefix][0].stop
        prefix += 1
    if prefix:
        write_piece(out, fingerprint, *_joined(done[:prefix]))
    for task in done[prefix:]:
        write_piece(out, fingerprint, *task)


def _queue_worker(config, tasks, results, halt):
    """One worker thread of :func:`_run_local`: tasks (piece index, positions) from
    ``tasks`` until it is empty or ``halt`` is set, each on one Numba thread (the kernels
    release the GIL), their outputs or the first exception onto ``results``."""
    import numba

    numba.set_num_threads(1)  # per thread in Numba: set in the thread that runs
    while not halt.is_set():
        try:
            index, part = tasks.get_nowait()
        except queue.Empty:
            return
        try:
            results.put((index, part, run_chunk(config, part, 1), None))
        except BaseException as exc:  # noqa: BLE001 - handed to the sweep's thread
            results.put((index, part, None, exc))
            return


def _run_local(config, out, fingerprint, pieces, threads, unit, progress, stop):
    """The pieces' cases on a work queue served by ``threads`` worker threads, one Numba
    thread each: tasks of ``unit`` consecutive positions go, in position order, to
    whichever worker is free, so a costly case holds up one core, not the others.  A
    piece is written as soon as all its tasks are done.  On a stop request (or an
    error) no task starts any more; of each unfinished piece, the finished tasks from
    its start are written as one shorter piece and every later finished task as a piece
    of its own (so identical sweeps stopped side by side write identical, disjoint or
    nested files, never overlapping ones); the running tasks are lost (their threads
    run on, unseen, until the kernel returns)."""
    tasks, results, halt = queue.SimpleQueue(), queue.SimpleQueue(), threading.Event()
    count = 0
    for index, piece in enumerate(pieces):
        for start in range(piece.start, piece.stop, unit):
            tasks.put((index, range(start, min(start + unit, piece.stop))))
            count += 1
    finished = {}  # piece index -> {task start: (positions, results, snapshots)}
    left = [len(piece) for piece in pieces]  # positions still to finish, per piece
    error = None

    def collect(index, part, output):
        finished.setdefault(index, {})[part.start] = (part,) + tuple(output)
        progress.update(output[0].column("case_id").to_pylist(), _failures(output[0]))
        left[index] -= len(part)
        if not left[index]:
            parts = finished.pop(index)
            write_piece(out, fingerprint, *_joined([parts[k] for k in sorted(parts)]))

    with one_blas_thread():  # BLAS's own threads would oversubscribe the cores
        for k in range(min(threads, count)):
            threading.Thread(target=_queue_worker, args=(config, tasks, results, halt),
                             daemon=True, name=f"loopsim-sweep-{k}").start()
        try:
            while count and error is None and not stop.is_set():
                try:
                    index, part, output, error = results.get(timeout=0.1)
                except queue.Empty:
                    continue
                count -= 1
                if error is None:
                    collect(index, part, output)
        finally:
            halt.set()  # workers finish their running task and stop
            while True:  # results already handed over are kept
                try:
                    index, part, output, late_error = results.get_nowait()
                except queue.Empty:
                    break
                if late_error is None:
                    collect(index, part, output)
            for index, parts in finished.items():
                _write_unfinished(out, fingerprint, pieces[index], parts)
    if error is not None:
        raise error


def _dask_client(scheduler, workers):
    """(client, cluster or None): connected to ``scheduler``, or to a new LocalCluster of
    ``workers`` processes, one task at a time each."""
    import logging

    from dask.distributed import Client, LocalCluster

    if scheduler is not None:
        if not re.fullmatch(r"(\w+://)?[^\s:/]+:\d+", str(scheduler)):
            raise ValueError(f"--scheduler must be an address like tcp://host:8786, got "
                             f"{scheduler!r}")
        try:
            return Client(scheduler, timeout="30s"), None
        except (OSError, ValueError, TypeError) as exc:
            raise ValueError(f"cannot connect to the Dask scheduler {scheduler!r}: "
                             f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}"
                             ) from None
    # NUMBA_NUM_THREADS is left alone: a worker process that compiles re-reads it and
    # refuses a value other than the one its thread pool started with (seen with env=
    # here); each task sets its own thread count instead (run_piece)
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           dashboard_address=None, silence_logs=logging.ERROR)
    return Client(cluster), cluster


def _close_cluster(cluster, grace):
    """Close a LocalCluster; with ``grace`` (seconds, after a signal) its worker processes,
    busy in a kernel that cannot be cut short, are killed rather than waited for."""
    if grace is None:
        cluster.close()
        return
    for nanny in cluster.workers.values():
        try:
            nanny.process.process.kill()
        except Exception:  # noqa: BLE001 - gone already, or another distributed layout
            pass
    cluster.close(timeout=grace)


def _run_dask(config, out, fingerprint, pieces, threads, progress, stop, client, write):
    """The pieces as Dask tasks (one per piece); the configuration is sent once to every
    worker.  ``write``: "worker" (each worker writes its piece into ``out``, a shared
    directory) or "client" (results come back and this process writes them)."""
    shared = client.scatter(config, broadcast=True)
    futures = [client.submit(run_piece, shared, piece, threads,
                             out if write == "worker" else None, fingerprint, pure=False)
               for piece in pieces]
    pending = set(futures)
    try:
        while pending and not stop.is_set():
            finished = [f for f in pending if f.done()]
            if not finished:
                stop.wait(0.05)
                continue
            for future in finished:
                pending.discard(future)
                piece, table, snapshots = future.result()
                if write == "client":
                    write_piece(out, fingerprint, piece, table, snapshots)
                progress.update(table.column("case_id").to_pylist(), _failures(table))
    finally:
        if pending:
            client.cancel(list(pending))


def run_sweep(config, out, threads=None, quiet=False, command_line=None, *, scheduler=None,
              local_cluster=False, workers=None, shard=None, unit=None, write="client",
              progress_interval=30.0, stream=None):
    """Run (or resume) a sweep into directory ``out``; returns the results DataFrame.

    Backends: this machine's cores (default; ``threads`` worker threads, default all
    cores, serving a work queue of cases: :func:`_run_local`), a
    Dask cluster at ``scheduler`` or, with ``local_cluster``, a new Dask LocalCluster
    of ``workers`` processes (``threads`` Numba threads each, default 1).  ``shard``
    (i, n): only the chunks k with k % n == i (job arrays).  ``unit``: positions per
    task of the local work queue (default 1: a signal loses at most the cases in
    flight).
    SIGINT/SIGTERM: finished cases are written, then :class:`SweepInterrupted` is
    raised (the running tasks' cases are lost; called from Python, their worker threads
    run on until their kernel returns, then stop).
    ``write`` (Dask): "client" (default: pieces come back and this process writes them;
    no shared filesystem needed) or "worker" (each worker writes its pieces into ``out``,
    which it must see at the same path); measured equal (docs/sweeps.md, "Dask and job arrays").
    """
    import numba

    validate(config)
    if shard is not None and not (0 <= shard[0] < shard[1]):
        raise ValueError(f"shard must be I/N with 0 <= I < N, got {shard[0]}/{shard[1]}")
    distributed = scheduler is not None or local_cluster
    if write not in ("worker", "client"):
        raise ValueError(f"write must be 'worker' or 'client', got {write!r}")
    for name, value in (("threads", threads), ("unit", unit)):
        if value is not None:
            validation.check_integer(name, value, 1)
    if workers is not None:
        validation.check_count("workers", workers, 1, validation.MAX_WORKERS,
                               "this machine's cores: each worker is a process that compiles "
                               "its own kernels, and more than the cores only compete")
    client = cluster = None
    stop = stop_event()
    if distributed:  # connected first: a scheduler refused leaves no directory behind
        workers = workers or max(1, numba.config.NUMBA_NUM_THREADS // (threads or 1))
        client, cluster = _dask_client(scheduler, workers)
    try:
        fingerprint = _prepare_directory(out, config, command_line or [])
        covered = io.chunk_files(out)
        pieces = pending_pieces(config, covered, shard)
        mine = _covered_ids(config, [(c.start, c.stop)
                                     for k, c in enumerate(canonical_chunks(config))
                                     if shard is None or k % shard[1] == shard[0]])
        done = set(_covered_ids(config, covered)) & set(mine)
        progress = Progress({i: case_weight(config.cases[i], config.n_auto) for i in mine},
                            done, quiet, stream, progress_interval)
        with _stop_on_signals(stop):
            if distributed and pieces:
                _run_dask(config, out, fingerprint, pieces, threads or (1 if cluster else None),
                          progress, stop, client, write)
            elif pieces:
                threads = threads or numba.config.NUMBA_NUM_THREADS
                _run_local(config, out, fingerprint, pieces, threads, unit or 1, progress,
                           stop)
    finally:
        if client is not None:
            grace = 1 if stop.is_set() else None  # on a signal: no waiting for tasks
            if grace is not None:  # connections cut short are expected now, not errors
                import logging

                logging.getLogger("distributed").setLevel(logging.CRITICAL)
            client.close(**({} if grace is None else dict(timeout=grace)))
            if cluster is not None:
                _close_cluster(cluster, grace)
    progress.close()
    if stop.is_set():
        raise SweepInterrupted(stop.signum, out, progress.done, progress.total)
    return io.read_results(out)


def sweep(g0, theta0_deg, out, *, n=6, seeds=1, method=None, quiet=True, threads=None,
          scheduler=None, local_cluster=False, workers=None, **options):
    """The Python form of ``loopsim sweep``: every (g0, θ0, seed) of the grid into the
    sweep directory ``out`` (made, or resumed), returned as the results DataFrame
    (:func:`io.read_results`).

    ``g0`` and ``theta0_deg``: values (numbers or sequences); ``n``: an order, a
    sequence of orders, or "auto"; ``seeds``: seeds 0..seeds-1 per point; ``method``:
    as in ``simulate`` (default rkf45 at a fixed n, auto with ``n="auto"``).  Every
    other keyword is a :class:`SweepConfig` field under its own name (``t_end``,
    ``rtol``, ``atol``, ``w``, ``early_stop``, ``twin``, ``n_max``, ``tail_tol``,
    ``chunk_size``, ...) or ``perturbation``.  Backends as :func:`run_sweep`.  The
    directory is the one the command line writes: either may resume the other.
    """
    auto = isinstance(n, str)
    if auto and n != "auto":
        raise ValueError(f"n must be an order, a sequence of orders or 'auto', got {n!r}")
    perturbation = options.pop("perturbation", DEFAULT_PERTURBATION)
    unknown = set(options) - {f.name for f in dataclasses.fields(SweepConfig)} - {"cases"}
    if unknown or "cases" in options:
        raise ValueError(f"unknown sweep option(s) {sorted(unknown or {'cases'})}")
    axes = [np.atleast_1d(np.asarray(v, dtype=float)).tolist() for v in (g0, theta0_deg)]
    orders = [DEFAULT_N] if auto else [int(v) for v in np.atleast_1d(n)]
    seeds = validation.check_integer("seeds", seeds, 1)
    cases = grid_cases(axes[0], axes[1], orders, seeds, perturbation)
    options.setdefault("chunk_size", DEFAULT_AUTO_CHUNK_SIZE if auto else DEFAULT_CHUNK_SIZE)
    config = SweepConfig(cases=cases, method=method or ("auto" if auto else "rkf45"),
                         n_auto=auto, **options)
    return run_sweep(config, os.fspath(out), threads=threads, quiet=quiet,
                     command_line=["loopsim.sweep(...)"], scheduler=scheduler,
                     local_cluster=local_cluster, workers=workers)


# ---- rerunning the failed cases -------------------------------------------------------------
def config_from_dict(stored):
    """The SweepConfig of a stored configuration (``_sweep.json``'s ``config``)."""
    fields = {f.name for f in dataclasses.fields(SweepConfig)}
    values = {k: v for k, v in stored.items() if k in fields}
    values["thresholds"] = Thresholds(**stored.get("thresholds", {}))
    return SweepConfig(**values)


def rerun_failed(out, method, rtol, atol, **backend):
    """Rerun the failed cases of sweep ``out`` with another method (None: the sweep's) or
    tolerances.

    Attempt k is a sweep of its own in ``out/_reruns/k`` (the failed cases, the settings
    changed, no snapshots): re-running the same call resumes it.  Once it is complete,
    every result file holding those cases is rewritten with the new rows (its metadata
    lists the attempt) after the original was copied to ``out/_reruns/k/replaced/``.
    Returns (the results DataFrame, the number of cases rerun).  ``backend``: as for
    :func:`run_sweep` (threads, quiet, scheduler, local_cluster, workers, ...).
    """
    if method is not None:
        validation.check_choice("--method", method, refinement.METHOD_CHOICES)
    validation.check_real("--rtol", rtol, low=0.0, low_open=True)  # before anything is
    validation.check_real("--atol", atol, low=0.0)  # recorded: a refused rerun leaves no trace
    stored = io.read_sweep_file(out) if os.path.isdir(out) else None
    if stored is None:
        raise ValueError(f"no sweep at {out!r} (no {io.SWEEP_FILE}) to rerun failed cases of")
    io.check_layout(out)
    base = config_from_dict(stored["config"])
    settings = dict(method=method or base.method, rtol=rtol, atol=atol)
    reruns = stored.get("reruns", [])
    open_attempt = next((r for r in reruns if not r["merged"]), None)
    if open_attempt is not None and open_attempt["settings"] != settings:
        raise ValueError(f"rerun {open_attempt['attempt']} of {out!r} is unfinished with "
                         f"{open_attempt['settings']}: finish it first (same options)")
    if open_attempt is None:
        frame = io.read_results(out)
        failed = sorted(int(i) for i in frame.loc[frame["status"] != "ok", "case_id"])
        if not failed:
            return frame, 0
        current = {key: frame.set_index("case_id").loc[failed, key].unique().tolist()
                   for key in ("rtol", "atol")}
        if (current["rtol"] == [rtol] and current["atol"] == [atol]
                and base.method == method and not reruns):
            raise ValueError(f"the failed cases of {out!r} ran with these settings already; "
                             "give another --method, --rtol or --atol")
        open_attempt = dict(attempt=len(reruns) + 1, settings=settings, case_ids=failed,
                            merged=False)
        stored["reruns"] = reruns + [open_attempt]
        io.write_json_atomically(stored, os.path.join(out, io.SWEEP_FILE))
    ids = open_attempt["case_ids"]
    directory = os.path.join(out, io.RERUN_DIR, str(open_attempt["attempt"]))
    config = dataclasses.replace(base, cases=[base.cases[i] for i in ids], snapshots_for=[],
                                 **settings)
    rerun = run_sweep(config, directory, **backend)
    _merge_rerun(out, stored["fingerprint"], directory, open_attempt["attempt"],
                 rerun.assign(case_id=[ids[i] for i in rerun["case_id"]]))
    open_attempt["merged"] = True
    io.write_json_atomically(stored, os.path.join(out, io.SWEEP_FILE))
    return io.read_results(out), len(ids)


def _merge_rerun(out, fingerprint, directory, attempt, rows):
    """Put the rerun ``rows`` (case ids of the sweep) into the result files holding those
    cases; a file already carrying ``attempt`` in its metadata is done (so a merge cut
    short by a kill resumes)."""
    import pyarrow.parquet as pq

    replaced = os.path.join(directory, "replaced")
    os.makedirs(replaced, exist_ok=True)
    new = pa.Table.from_pandas(rows, schema=io.RESULT_SCHEMA, preserve_index=False)
    by_id = set(rows["case_id"])
    for (start, stop), path in sorted(io.chunk_files(out).items()):
        meta = io.read_metadata(path)
        if attempt in meta.get("reruns", []):
            continue
        table = io.result_table(io.read_table_checked(path, io.requires_hash(
            io.read_sweep_file(out))))
        mask = [i in by_id for i in table.column("case_id").to_pylist()]
        if not any(mask):
            continue
        io.write_table_atomically(pq.read_table(path),
                                  os.path.join(replaced, os.path.basename(path)))
        keep = table.filter(pa.array([not m for m in mask]))
        ids = set(table.column("case_id").to_pylist())
        fresh = new.filter(pa.array([i in ids for i in new.column("case_id").to_pylist()]))
        merged = pa.concat_tables([keep, fresh]).sort_by("case_id")
        meta = io.provenance(sweep_fingerprint=fingerprint, positions=[start, stop],
                             reruns=meta.get("reruns", []) + [attempt])
        io.write_table_atomically(merged.replace_schema_metadata(meta), path)
