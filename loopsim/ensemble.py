"""Ensemble sweeps: cases -> chunks -> Parquet files in a directory, resumable.

A sweep directory holds ``sweep.json`` (the configuration, written first) and
one ``chunk-KKKKK.parquet`` per finished chunk, each written under a
temporary name and renamed into place.  A chunk is the unit of work: chunk k
holds the cases with ``case_id % n_chunks == k`` (interleaved, so every
chunk mixes cheap and costly corners of the grid).  Re-running the same sweep
skips finished chunks; a different configuration in the same directory is
refused.  No numerics here: integration is ``batch``, start shapes
``shapes``, summaries ``api``, tables ``io``.
"""
import dataclasses
import itertools
import json
import math
import os
import sys
import time

import numpy as np
import pandas as pd
import pyarrow as pa

from . import api, batch, diagnostics, integrators, io, models, shapes, validation
from .config import (
    DEFAULT_ATOL, DEFAULT_LENGTH_TOL, DEFAULT_MAX_STEPS, DEFAULT_PERTURBATION, DEFAULT_RTOL,
    DEFAULT_STEADY_INTERVAL, DEFAULT_STEADY_TOL, DEFAULT_T_END, DEFAULT_W, RESOLVED_LENGTH_ERROR,
    RESOLVED_TAIL,
)

CONFIG_FILE = "sweep.json"
CHUNK_PATTERN = io.CHUNK_PATTERN
SNAPSHOT_PATTERN = io.SNAPSHOT_PATTERN
REGIMES = ("stable", "in-plane", "3d", "failed")


@dataclasses.dataclass(frozen=True)
class Thresholds:
    """Regime thresholds (paper §6: stable = shape and tilt unchanged; in-plane = shape
    changed, tilt unchanged; 3d = tilt changed).

    tilt_change_deg: |θ_final − θ0| above which the tilt has changed.
    shape_change: |aspect ratio_final − aspect ratio_initial| above which the shape has.
    resolved_length_error, resolved_tail: a case is resolved at its n when its worst
    transient relative length error and its terminal spectral tail stay at or below
    these (``config.RESOLVED_LENGTH_ERROR``, ``config.RESOLVED_TAIL``).
    """

    tilt_change_deg: float = 1.0
    shape_change: float = 0.01
    resolved_length_error: float = RESOLVED_LENGTH_ERROR
    resolved_tail: float = RESOLVED_TAIL

    def resolved(self, length_error_max, spectral_tail):
        """Whether a case with these diagnostics is resolved at its n."""
        return bool(length_error_max <= self.resolved_length_error
                    and spectral_tail <= self.resolved_tail)


def classify(theta0_deg, theta_final_deg, aspect_initial, aspect_final, ok, thresholds=Thresholds()):
    """Regime label of one case: 'stable', 'in-plane', '3d' or 'failed' (status not ok)."""
    if not ok:
        return "failed"
    if abs(theta_final_deg - theta0_deg) > thresholds.tilt_change_deg:
        return "3d"
    if abs(aspect_final - aspect_initial) > thresholds.shape_change:
        return "in-plane"
    return "stable"


# ---- the table (schema: io.RESULT_SCHEMA) ----------------------------------
FIELD_NOTES = {
    "wall_s": "share of the chunk's wall time x threads, in proportion to nfev",
    "x_final": "terminal shape coefficients, row-major (3, 2n+1): " + io.COEFFICIENT_LAYOUT,
    "regime": "stable | in-plane | 3d | failed (see thresholds)",
    "stop_reason": "t_end | steady (terminal state reached early) | the failure",
    "length_error_max": "largest |relative length error| along the trajectory (transient)",
    "resolved": "length_error_max <= thresholds.resolved_length_error and spectral_tail <= "
                "thresholds.resolved_tail: n resolves the case (False: raise n; its terminal "
                "outcome is not converged)",
}


# ---- configuration -------------------------------------------------------
def parse_values(text, name, integer=False):
    """'START:STOP:NUM' (linspace, ends included) or 'v1,v2,...' -> list of numbers."""
    convert = int if integer else float
    try:
        if ":" in text:
            start, stop, num = text.split(":")
            num = int(num)
            if num < 1:
                raise ValueError
            values = np.linspace(float(start), float(stop), num).tolist()
        else:
            values = [convert(v) for v in text.split(",") if v.strip()]
        if not values or not all(math.isfinite(v) for v in values):
            raise ValueError
    except ValueError:
        form = "v1,v2,..." if integer else "START:STOP:NUM or v1,v2,..."
        raise ValueError(f"{name} must be {form}, got {text!r}") from None
    return [convert(v) for v in values]


@dataclasses.dataclass
class SweepConfig:
    """Everything that determines a sweep's results (stored in sweep.json)."""

    cases: list  # of dicts: g0, theta0_deg, n, seed, perturbation
    t_end: float = DEFAULT_T_END
    rtol: float = DEFAULT_RTOL
    atol: float = DEFAULT_ATOL
    w: float = DEFAULT_W
    method: str = "rkf45"
    max_steps: int = DEFAULT_MAX_STEPS
    length_tol: float = DEFAULT_LENGTH_TOL
    chunk_size: int = 32
    early_stop: bool = True
    snapshots_for: list = dataclasses.field(default_factory=list)  # case ids
    snapshot_count: int = 101
    steady_interval: float = DEFAULT_STEADY_INTERVAL
    steady_tol: float = DEFAULT_STEADY_TOL
    thresholds: Thresholds = Thresholds()

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


def _case_row(path, i, row):
    """A case dict from one row of a cases file (types checked, cell by cell)."""
    return dict(g0=_cell(path, i, "g0", row.g0, False),
                theta0_deg=_cell(path, i, "theta0_deg", row.theta0_deg, False),
                n=_cell(path, i, "n", row.n, True), seed=_cell(path, i, "seed", row.seed, True),
                perturbation=_cell(path, i, "perturbation", row.perturbation, False))


def read_cases_file(path, perturbation=DEFAULT_PERTURBATION, n=6):
    """Cases from a CSV or Parquet table: columns g0, theta0_deg (required), n, seed, perturbation."""
    try:
        frame = pd.read_parquet(path) if str(path).endswith(".parquet") else pd.read_csv(path)
    except Exception as exc:  # noqa: BLE001 - any reader failure is the same user error
        raise ValueError(f"cannot read cases file {path!r}: {exc}".splitlines()[0]) from None
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
    for case_id, case in enumerate(config.cases):
        try:
            validation.check_real("g0", case["g0"], low=0.0)
            validation.check_tilt("theta0_deg", case["theta0_deg"])
            validation.check_integer("n", case["n"], 1)
            validation.check_integer("seed", case["seed"], 0)
            validation.check_real("perturbation", case["perturbation"], low=0.0)
        except ValueError as exc:
            raise ValueError(f"case {case_id}: {exc}") from None
    validation.check_real("t_end", config.t_end, low=0.0, low_open=True)
    validation.check_real("rtol", config.rtol, low=0.0, low_open=True)
    validation.check_real("atol", config.atol, low=0.0)
    validation.check_real("w", config.w, low=0.0)
    validation.check_integer("chunk_size", config.chunk_size, 1)
    validation.check_integer("snapshot_count", config.snapshot_count, 2)
    for case_id in config.snapshots_for:
        if not 0 <= case_id < len(config.cases):
            raise ValueError(f"--snapshots-for names case {case_id}, but the sweep has cases "
                             f"0..{len(config.cases) - 1}")
    validation.check_choice("method", config.method, integrators.METHODS)


# ---- running ---------------------------------------------------------------
def chunk_case_ids(config, chunk):
    return list(range(chunk, len(config.cases), config.n_chunks))


def _start(case):
    """Keyword arguments of ``shapes.start_shape`` (and ``simulate``) for a case's start."""
    if case.get("initial"):  # a case started from a file (cases column "initial")
        return dict(initial=case["initial"], initial_case_id=case.get("initial_case_id"),
                    n=case["n"], perturbation=case["perturbation"], seed=case["seed"])
    return dict(theta0_deg=case["theta0_deg"], n=case["n"], perturbation=case["perturbation"],
                seed=case["seed"])


def _result_row(config, case_id, case, x0, x, status_code, counts, worst_length, wall_s, t_final):
    """One row of RESULT_SCHEMA for a finished case with final coefficients x (3, 2n+1)."""
    n = case["n"]
    if not np.all(np.isfinite(x)):
        x = x0  # keep the row finite; the status says why
    problem = models.local_sbt.make_problem(n, case["g0"], config.w)
    u, multiplier = api.velocity_and_multiplier(problem, x)
    inputs = dict(g0=case["g0"], theta0_deg=case["theta0_deg"], n=n, t_end=config.t_end,
                  rtol=config.rtol, atol=config.atol, w=config.w,
                  perturbation=case["perturbation"], seed=case["seed"])
    row = api.terminal_summary(
        inputs, x, u, multiplier, status=integrators.STATUS_NAMES[status_code], t_final=t_final,
        wall_s=wall_s, **dict(zip(integrators.COUNTS, (int(c) for c in counts))))
    aspect0 = diagnostics.aspect_ratio(x0)
    row.update(
        case_id=case_id, aspect_ratio_initial=aspect0, x_final=x.ravel().tolist(),
        length_error_max=float(worst_length), stop_reason=integrators.STOP_REASONS[status_code],
        resolved=config.thresholds.resolved(worst_length, row["spectral_tail"]),
        regime=classify(case["theta0_deg"], row["theta_final_deg"], aspect0, row["aspect_ratio"],
                        status_code in integrators.SUCCESS, config.thresholds),
    )
    return row


def _traced_case(config, case_id):
    """A case with snapshots: its row and trajectory come from one ``api.simulate`` run,
    so they agree exactly (its steps land on the snapshot times)."""
    case = config.cases[case_id]
    result = api.simulate(
        case["g0"], **_start(case), t_span=(0.0, config.t_end),
        snapshots=config.snapshot_count, rtol=config.rtol, atol=config.atol, w=config.w,
        method=config.method, max_steps=config.max_steps, length_tol=config.length_tol,
        steady_tol=config.steady_tol if config.early_stop else None,
        steady_interval=config.steady_interval)
    row = _result_row(config, case_id, case, result.x[0], result.x_final, result.status_code,
                      [getattr(result, name) for name in integrators.COUNTS],
                      result.length_error_max, result.wall_s, result.t_final)
    table = io.trajectory_table(result).replace_schema_metadata(None)
    for name in ("x", "multiplier"):  # orders differ between cases: variable-length lists
        table = table.set_column(table.schema.get_field_index(name), name,
                                 table.column(name).cast(pa.list_(pa.float64())))
    return row, table.add_column(0, "case_id", pa.array([case_id] * table.num_rows, pa.int64()))


def run_chunk(config, chunk, threads):
    """Integrate one chunk's cases.

    Returns (results Table in RESULT_SCHEMA, snapshots Table or None).  Cases
    without snapshots run in the parallel batch kernel, grouped by n; their
    ``wall_s`` is the batch's wall time x threads shared in proportion to RHS
    evaluations.
    """
    ids = chunk_case_ids(config, chunk)
    traced = sorted(set(ids) & set(config.snapshots_for))
    by_order = {}
    for case_id in ids:
        if case_id not in traced:
            by_order.setdefault(config.cases[case_id]["n"], []).append(case_id)
    start = time.perf_counter()
    outputs = []
    for n, members in sorted(by_order.items()):
        cases = [config.cases[i] for i in members]
        x0 = np.array([shapes.start_shape(**_start(c))[0].ravel() for c in cases])
        result = batch.integrate_cases(
            integrators.METHODS[config.method], models.local_sbt.make_operators(n),
            [(c["g0"], config.w) for c in cases], x0, config.t_end, config.step_options(),
            cost=[diagnostics.stability_parameter(c["g0"], c["theta0_deg"]) for c in cases])
        outputs.append((members, x0, result))
    wall = time.perf_counter() - start
    total_rhs = sum(int(result[3][:, 2].sum()) for _, _, result in outputs) or 1
    rows = {}
    for members, x0, (y_final, t_final, status, counts, worst) in outputs:
        for b, case_id in enumerate(members):
            shape = (3, x0.shape[1] // 3)
            rows[case_id] = _result_row(
                config, case_id, config.cases[case_id], x0[b].reshape(shape),
                y_final[b].reshape(shape), int(status[b]), counts[b], worst[b],
                wall * threads * counts[b, 2] / total_rhs, float(t_final[b]))
    snapshots = []
    for case_id in traced:
        rows[case_id], table = _traced_case(config, case_id)
        snapshots.append(table)
    table = pa.Table.from_pylist([rows[i] for i in sorted(rows)], schema=io.RESULT_SCHEMA)
    return table, (pa.concat_tables(snapshots) if snapshots else None)


class Progress:
    """One status line on stderr: done/total, rate, ETA, failures (quiet: final line only)."""

    def __init__(self, total, done, quiet=False, stream=sys.stderr):
        self.total, self.done, self.failures = total, done, 0
        self.quiet, self.stream = quiet, stream
        self.start, self.started_with = time.perf_counter(), done
        self.live = not quiet and stream.isatty()

    def update(self, cases, failures):
        self.done += cases
        self.failures += failures
        if self.live:
            self.stream.write("\r" + self._line())
            self.stream.flush()

    def _line(self):
        elapsed = time.perf_counter() - self.start
        rate = (self.done - self.started_with) / elapsed if elapsed > 0 else 0.0
        eta = (self.total - self.done) / rate if rate > 0 else float("nan")
        eta_text = f"{eta:6.0f}s" if math.isfinite(eta) else "     ?"
        return (f"cases {self.done}/{self.total} ({100 * self.done / self.total:3.0f}%) "
                f"{rate:6.2f} case/s ETA {eta_text} failures {self.failures}")

    def close(self):
        self.stream.write(("\r" if self.live else "") + self._line() + "\n")
        self.stream.flush()


def _prepare_directory(out, config, command_line):
    """Create or check ``out``: a sweep directory holds one configuration only.  Nothing
    is removed unless the configuration matches, and then only dead processes' temporaries."""
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, CONFIG_FILE)
    stored = dict(config=config.as_dict(), command_line=command_line)
    if os.path.exists(path):
        with open(path) as handle:
            previous = json.load(handle)["config"]
        current = json.loads(json.dumps(config.as_dict()))
        if previous != current:
            changed = sorted(k for k in set(previous) | set(current) if previous.get(k) != current.get(k))
            raise ValueError(f"{out!r} holds a different sweep (differs in: {', '.join(changed)}); "
                             "use another --out")
    _check_chunks_belong(out, config)
    io.remove_stale_temporaries(out)
    if os.path.exists(path):
        return
    tmp = path + ".tmp"
    with open(tmp, "w") as handle:
        json.dump(stored, handle, indent=1)
    os.replace(tmp, path)


def _check_chunks_belong(out, config):
    """Refuse a directory whose chunk files were written by another sweep (a lost or
    replaced sweep.json must not make old rows pass for new ones)."""
    current = json.loads(json.dumps(config.as_dict()))
    for chunk, path in io.numbered_files(out).items():
        stored = io.read_metadata(path).get("sweep_config")
        if stored != current or chunk >= config.n_chunks:
            raise ValueError(f"{path!r} belongs to a different sweep than this command's; "
                             "use another --out, or move that file away")


def finished_chunks(out):
    return set(io.numbered_files(out))


def run_sweep(config, out, threads=None, quiet=False, command_line=None):
    """Run (or resume) a sweep into directory ``out``; returns the results DataFrame."""
    import numba

    validate(config)
    _prepare_directory(out, config, command_line or [])
    threads = threads or numba.config.NUMBA_NUM_THREADS
    numba.set_num_threads(threads)
    done = finished_chunks(out)
    progress = Progress(len(config.cases), sum(len(chunk_case_ids(config, c)) for c in done), quiet)
    metadata = io.provenance(
        sweep_config=config.as_dict(), thresholds=dataclasses.asdict(config.thresholds),
        command_line=command_line or [], field_notes=FIELD_NOTES,
    )
    for chunk in range(config.n_chunks):
        if chunk in done:
            continue
        table, snapshots = run_chunk(config, chunk, threads)
        table = table.replace_schema_metadata(metadata)
        if snapshots is not None:  # written before the chunk: a finished chunk has its snapshots
            io.write_table_atomically(snapshots.replace_schema_metadata(metadata),
                                      os.path.join(out, SNAPSHOT_PATTERN.format(chunk)))
        io.write_table_atomically(table, os.path.join(out, CHUNK_PATTERN.format(chunk)))
        failures = sum(1 for s in table.column("status").to_pylist() if s != "ok")
        progress.update(table.num_rows, failures)
    progress.close()
    return io.read_results(out)
