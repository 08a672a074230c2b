"""A sweep's configuration and its cases: value lists and grids, cases files (CSV or
Parquet), and the checks a configuration passes before any work."""
import dataclasses
import itertools
import json
import math
import os
import re

import numpy as np
import pandas as pd

from .. import integrators, models, refinement, shapes, storage, validation
from ..columns import CASE_COLUMNS, CASE_OVERRIDES  # declared with the other columns
from ..defaults import (
    DEFAULT_ATOL, DEFAULT_CHUNK_SIZE, DEFAULT_LENGTH_TOL, DEFAULT_MAX_STEPS, DEFAULT_N_MAX,
    MODEL_CHOICES,
    DEFAULT_PERTURBATION, DEFAULT_RTOL, DEFAULT_STEADY_INTERVAL, DEFAULT_STEADY_TOL,
    DEFAULT_T_END, DEFAULT_TAIL_TOL, DEFAULT_W,
)
from ..outcomes import Thresholds


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


#: SweepConfig fields left out of ``as_dict`` at these values (the local model).
UNRECORDED_DEFAULTS = {"model": "local", "slenderness": None}


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
    n_auto: bool = False  # restart a case from t0 at the next order past tail_tol (refinement)
    n_max: int = DEFAULT_N_MAX
    tail_tol: float = DEFAULT_TAIL_TOL
    twin: bool = True  # run each case's stricter twin (loopsim.outcomes: determined or not)
    model: str = "local"  # the hydrodynamic model (defaults.MODEL_CHOICES; models.Model)
    slenderness: float = None  # a/L of the nonlocal model

    def step_options(self):
        return integrators.step_options(
            self.rtol, self.atol, max_steps=self.max_steps, constraint_tol=self.length_tol,
            steady_interval=self.steady_interval if self.early_stop else 0.0,
            steady_tol=self.steady_tol)

    def as_dict(self):
        """The fields as a dict; ``model`` and ``slenderness`` only where not the local
        model's (so a sweep begun before they existed keeps its fingerprint)."""
        values = dataclasses.asdict(self)
        for name, default in UNRECORDED_DEFAULTS.items():
            if values[name] == default:
                del values[name]
        return values

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
    for key in ("rtol", "t_end", "slenderness"):
        value = getattr(row, key, None)
        if value is not None and not (isinstance(value, float) and math.isnan(value)):
            case[key] = _cell(path, i, key, value, False)
    for key, choices in (("method", refinement.METHOD_CHOICES), ("model", MODEL_CHOICES)):
        value = getattr(row, key, None)
        if value is None or (not isinstance(value, str) and pd.isna(value)) or (
                isinstance(value, str) and not value.strip()):
            continue
        if not isinstance(value, str) or value.strip() not in choices:
            raise ValueError(f"cases file {path!r}, row {i}, column {key}: must be one of "
                             f"{', '.join(choices)}, got {value!r}")
        case[key] = value.strip()
    return case


def case_option(config, case, key):
    """A case's ``rtol``, ``t_end``, ``model``, ``slenderness`` or ``twin``: its own (a
    cases-file column; ``twin``: set by ``--seeds auto`` for a cell whose runs are samples)
    or the sweep's."""
    return case.get(key, getattr(config, key))


def case_model(config, case):
    """A case's ``models.Model``: its own model and slenderness (cases-file columns) or the
    sweep's; a local case has no slenderness."""
    name = case_option(config, case, "model")
    return models.choose(name, case_option(config, case, "slenderness")
                         if name == "nonlocal" else None)


def read_cases_file(path, perturbation=DEFAULT_PERTURBATION, n=6, auto_top=None):
    """Cases from a CSV or Parquet table: columns g0, theta0_deg (required), n, seed,
    perturbation, and per case (overriding the sweep's options) method, rtol, t_end,
    model, slenderness.  ``auto_top``: with ``--n auto``, the ladder's top; a row that
    starts from a point file (column ``initial``) and gives no n then starts at the order
    its content needs (``shapes.auto_start_order``), as ``run --initial`` does."""
    validation.check_input_file("cases file", path, validation.MAX_CASES_FILE_BYTES)
    limit = validation.MAX_CASES
    try:
        if str(path).endswith(".parquet"):
            import pyarrow.parquet as pq

            parquet = pq.ParquetFile(path)
            rows = parquet.metadata.num_rows
            names = parquet.schema_arrow.names
            # checked as loopsim's own files are (a table loopsim wrote carries checksums)
            frame = None if rows > limit else storage.read_table_checked(path).to_pandas()
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
    n_given = "n" in frame.columns
    frame = frame.assign(**{k: v for k, v in dict(n=n, seed=0, perturbation=perturbation,
                                                  theta0_deg=math.nan).items() if k not in frame})
    cases = [_case_row(path, i, row) for i, row in enumerate(frame.itertuples())]
    for i, case in enumerate(cases):  # optional column initial (file or results), initial_case_id
        if given is not None and given["initial"].iloc[i] and str(frame["initial"].iloc[i]).strip():
            case_id = frame["initial_case_id"].iloc[i] if "initial_case_id" in frame else None
            case_id = None if case_id is None or pd.isna(case_id) else int(case_id)
            source = str(frame["initial"].iloc[i]).strip()
            try:
                if auto_top is not None and not (n_given and given["n"].iloc[i]):
                    where = source if os.path.isabs(source) else os.path.normpath(
                        os.path.join(os.path.dirname(str(path)), source))
                    order = shapes.auto_start_order(where, case_id, n, auto_top)
                    case = dict(case, n=case["n"] if order is None else order)
                cases[i] = shapes.initial_case(
                    case, source,
                    case_id, os.path.dirname(str(path)),
                    "perturbation" in given and bool(given["perturbation"].iloc[i]))
            except ValueError as exc:
                raise ValueError(f"cases file row {i}: {exc}") from None
    repeat = repeated_case(cases)
    if repeat is not None:
        first, second = repeat
        raise ValueError(f"cases file {path!r} holds one case twice: rows {first} and {second} "
                         f"(counted from 0: {describe_case(cases[first])}); a sweep runs each "
                         "case once, remove one of them")
    return cases


def describe_case(case):
    """A case's inputs as one line: 'g0=10, theta0_deg=30, n=6, seed=0, ...'."""
    return ", ".join(f"{key}={value:g}" if isinstance(value, float) else f"{key}={value}"
                     for key, value in case.items())


def _case_key(values):
    """A hashable key of a case's values (its items; as JSON where a value is not
    hashable)."""
    try:
        return frozenset(values.items())
    except TypeError:
        return json.dumps(values, sort_keys=True, default=str)


def repeated_case(cases, config=None):
    """(i, j), i < j, of the first case ``j`` that repeats an earlier case ``i`` (the same
    inputs; with ``config``, a per-case override equal to the sweep's option is the same
    as none, as :func:`case_option` reads it), or None where every case is distinct."""
    options = {} if config is None else {key: getattr(config, key) for key in CASE_OVERRIDES}
    seen = {}
    for index, case in enumerate(cases):
        key = _case_key({**options, **case})
        if key in seen:
            return seen[key], index
        seen[key] = index
    return None


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
            if "twin" in case and not isinstance(case["twin"], bool):
                raise ValueError(f"twin must be True or False, got {case['twin']!r}")
            if case.get("slenderness") is not None and case_option(config, case,
                                                                   "model") != "nonlocal":
                raise ValueError(f"slenderness {case['slenderness']!r} applies only to the "
                                 "nonlocal model, and this case's model is "
                                 f"{case_option(config, case, 'model')!r}")
            models.check_order(case_model(config, case), case["n"],
                               "n_start" if config.n_auto else "n")
        except ValueError as exc:
            raise ValueError(f"case {case_id}: {exc}") from None
    repeat = repeated_case(config.cases, config)
    if repeat is not None:
        raise ValueError(f"cases {repeat[0]} and {repeat[1]} are one case twice "
                         f"({describe_case(config.cases[repeat[0]])}); a sweep runs each case "
                         "once (a value given twice in --g0, --theta0 or --n?)")
    if config.slenderness is not None and not any(
            case_option(config, case, "model") == "nonlocal" for case in config.cases):
        raise ValueError(f"slenderness applies only to the nonlocal model, got slenderness="
                         f"{config.slenderness!r} and no case of model 'nonlocal'")
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
