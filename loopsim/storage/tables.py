"""Table schemas and provenance: the declared schema of a sweep's rows, the metadata
every table carries, a run's trajectory table, and reading a file's metadata back."""
import datetime
import json
import numbers
import os
import platform
import socket

import numba
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from .. import columns, diagnostics
from .._version import __version__
from .integrity import DamagedFile, write_table_atomically


COEFFICIENT_LAYOUT = (
    "x coefficients: row-major (component x,y,z; coefficient [a0, a1..an, b1..bn]) "
    "with f(s) = a0 + sum_k a_k cos ks + b_k sin ks, s in [0, 2pi); "
    "multiplier: the tension Lagrange multiplier T in the same layout; "
    "physical tension N = T + |x''|^2"
)


#: Summary fields, in order; they are also the sweep table's columns.
INPUT_FIELDS = ("g0", "theta0_deg", "n", "q0", "t_end", "rtol", "atol", "w", "perturbation",
                "seed", "model", "slenderness")
RUN_FIELDS = ("method", "n_used", "status", "t_final", "steps_accepted", "steps_rejected",
              "nfev", "njev", "nlu", "wall_s", "tail_max")
#: What the end state means (``loopsim.outcomes``).
OUTCOME_FIELDS = ("regime", "resolved", "determined", "theta_uncertainty_deg",
                  "aspect_uncertainty", "twin_nfev", "twin_regime", "twin_theta_final_deg",
                  "twin_aspect_ratio")
#: Whether the end is a terminal state, and the motion before it (``loopsim.late_motion``).
MOTION_FIELDS = ("terminal_state", "late_tilt_mean_deg", "late_tilt_min_deg",
                 "late_tilt_max_deg", "late_aspect_mean", "late_aspect_min", "late_aspect_max",
                 "time_since_swing")
SUMMARY_FIELDS = (INPUT_FIELDS + RUN_FIELDS + tuple(d.name for d in diagnostics.REGISTRY)
                  + OUTCOME_FIELDS + MOTION_FIELDS)

_FLOAT = pa.float64()
_INT = pa.int64()
_SUMMARY_TYPES = {
    "n": _INT, "seed": _INT, "model": pa.string(), "method": pa.string(), "n_used": _INT, "status": pa.string(),
    "steps_accepted": _INT,
    "steps_rejected": _INT, "nfev": _INT, "njev": _INT, "nlu": _INT,
    "regime": pa.string(), "resolved": pa.bool_(), "determined": pa.bool_(), "twin_nfev": _INT,
    "twin_regime": pa.string(), "terminal_state": pa.string(),
    **{d.name: pa.from_numpy_dtype(np.dtype(d.dtype)) for d in diagnostics.REGISTRY},
}
#: The declared schema of every sweep chunk (and of :func:`read_results`); each field
#: carries its unit and description (``loopsim.columns``) in its metadata.
RESULT_SCHEMA = pa.schema(
    [pa.field(name, kind, metadata=columns.field_metadata(name)) for name, kind in
     [("case_id", _INT)]
     + [(name, _SUMMARY_TYPES.get(name, _FLOAT)) for name in SUMMARY_FIELDS]
     + [("stop_reason", pa.string()), ("early_stop", pa.bool_()), ("aspect_ratio_initial", _FLOAT),
        ("length_error_max", _FLOAT), ("x_final", pa.list_(_FLOAT))]]
)


def coefficients(row):
    """The terminal shape of a results row as a (3, 2n + 1) coefficient array.

    Parameters
    ----------
    row : pandas.Series, dict or array_like
        A row of ``loopsim.read_results`` (or a dict) with the column ``x_final``, or
        that column's value itself (3 (2n + 1) numbers, row-major).

    Returns
    -------
    numpy.ndarray
        Shape (3, 2n + 1), in L/2π: rows x, y, z, each [a0, a1..an, b1..bn] with
        f(s) = a0 + Σ a_k cos ks + b_k sin ks (``COEFFICIENT_LAYOUT``).

    Raises
    ------
    KeyError
        ``row`` has no ``x_final``.
    ValueError
        The values cannot be laid out as three rows.

    Examples
    --------
    >>> import loopsim
    >>> loopsim.coefficients([0.0, 1.0, 0.0] + [0.0] * 6).shape
    (3, 3)
    """
    values = row if isinstance(row, (list, tuple, np.ndarray)) else row["x_final"]
    return np.asarray(values, dtype=float).reshape(3, -1)


def machine():
    """The machine a table is written on, as one line: host name, platform, CPU count."""
    return f"{socket.gethostname()} ({platform.platform()}, {os.cpu_count()} CPUs)"


def provenance(**extra):
    """Schema-level metadata common to every table loopsim writes."""
    meta = {
        "loopsim_version": __version__,
        "numba_version": numba.__version__,
        "numpy_version": np.__version__,
        "pyarrow_version": pa.__version__,
        "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(),
        "machine": machine(),
        "coefficient_layout": COEFFICIENT_LAYOUT,
    }
    meta.update(extra)
    return {key: value if isinstance(value, str) else json.dumps(value)
            for key, value in meta.items()}


def described(table, declarations):
    """``table`` with each field's unit and description (``loopsim.columns``) in its
    metadata; the schema's own metadata is kept."""
    schema = pa.schema([field.with_metadata(columns.field_metadata(field.name, declarations))
                        for field in table.schema], metadata=table.schema.metadata)
    return table.cast(schema)


def trajectory_table(result, command_line=None):
    """One row per snapshot: time, shape coefficients, multiplier and diagnostics."""
    k = result.x.shape[-1]
    rows = [diagnostics.evaluate(diagnostics.State(x, u, m, result.inputs["g0"]), trajectory=True)
            for x, u, m in zip(result.x, result.u, result.multiplier)]
    data = {"t": pa.array(result.t, pa.float64())}
    for d in diagnostics.REGISTRY:
        if d.trajectory:
            data[d.trajectory] = pa.array([r[d.trajectory] for r in rows],
                                          pa.from_numpy_dtype(np.dtype(d.dtype)))
    data.update({
        "x": pa.FixedSizeListArray.from_arrays(
            pa.array(result.x.reshape(-1), pa.float64()), 3 * k),
        "multiplier": pa.FixedSizeListArray.from_arrays(
            pa.array(result.multiplier.reshape(-1), pa.float64()), k),
    })
    table = described(pa.table(data), columns.TRAJECTORY_COLUMNS)
    meta = provenance(summary=result.summary(), command_line=command_line or [])
    return table.replace_schema_metadata(meta)


def write_trajectory(result, path, command_line=None):
    """Write a run's snapshots to Parquet (atomically)."""
    write_table_atomically(trajectory_table(result, command_line), path)


def read_metadata(path):
    """Decoded schema metadata of a loopsim Parquet file; ``integrity.DamagedFile`` naming
    it where its footer cannot be read or decoded (OSError where it cannot be opened)."""
    try:
        raw = {key.decode(): value.decode()
               for key, value in (pq.read_schema(path).metadata or {}).items()}
    except (FileNotFoundError, PermissionError, IsADirectoryError):
        raise
    except Exception as exc:  # noqa: BLE001 - a footer we wrote that does not decode: damage
        raise DamagedFile(path, f"unreadable footer: {type(exc).__name__}: {str(exc)[:80]}") \
            from None
    out = {}
    for key, value in raw.items():
        try:
            out[key] = json.loads(value)
        except json.JSONDecodeError:
            out[key] = value
    return out


# ---- study tables: a partial run never replaces a fuller table -------------------------
def study_keys(frame, key_columns):
    """The rows of a study table (or a grid's columns: any mapping of equal-length columns)
    as a set of keys over ``key_columns``: numbers rounded to 9 decimals (past the last
    bit of the grids' values), anything else as text."""
    return {tuple(round(float(v), 9) if isinstance(v, numbers.Real) else str(v) for v in row)
            for row in zip(*(frame[c] for c in key_columns))}


def keys_a_write_would_drop(path, keys, key_columns):
    """(held, dropped): the keys (:func:`study_keys`) of the table at ``path`` and those of
    them missing from ``keys``, what writing a table of ``keys`` over it would lose; two
    empty sets where there is no file.  ValueError (one line) where the table cannot be
    read: it is then kept as it is."""
    if not os.path.isfile(path):
        return set(), set()
    try:
        held = study_keys(pq.read_table(path, columns=list(key_columns)).to_pandas(),
                          key_columns)
    except Exception as exc:  # noqa: BLE001 - any unreadable table is kept as it is
        raise ValueError(f"{path!r} cannot be read to compare its rows ({exc})") from None
    return held, held - set(keys)
