"""Parquet output with the provenance a reader needs (pyarrow schema metadata)."""
import datetime
import json
import os
import tempfile

import numba
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from . import __version__, diagnostics

COEFFICIENT_LAYOUT = (
    "x coefficients: row-major (component x,y,z; coefficient [a0, a1..an, b1..bn]) "
    "with f(s) = a0 + sum_k a_k cos ks + b_k sin ks, s in [0, 2pi); "
    "multiplier: the tension Lagrange multiplier T in the same layout; "
    "physical tension N = T + |x''|^2"
)


def provenance(**extra):
    """Schema-level metadata common to every table loopsim writes."""
    meta = {
        "loopsim_version": __version__,
        "numba_version": numba.__version__,
        "numpy_version": np.__version__,
        "pyarrow_version": pa.__version__,
        "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(),
        "coefficient_layout": COEFFICIENT_LAYOUT,
    }
    meta.update(extra)
    return {key: value if isinstance(value, str) else json.dumps(value)
            for key, value in meta.items()}


def write_table_atomically(table, path):
    """Write to a temporary file in the target directory, then rename into place."""
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=".parquet", dir=directory)
    os.close(fd)
    try:
        pq.write_table(table, tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def trajectory_table(result, command_line=None):
    """One row per snapshot: time, shape coefficients, multiplier and diagnostics."""
    k = result.x.shape[-1]
    rows = [diagnostics.tension_extremes(x, m) for x, m in zip(result.x, result.multiplier)]
    columns = {
        "t": pa.array(result.t, pa.float64()),
        "theta_deg": pa.array([diagnostics.tilt_deg(x) for x in result.x], pa.float64()),
        "aspect_ratio": pa.array([diagnostics.aspect_ratio(x) for x in result.x], pa.float64()),
        "tension_max": pa.array([r[0] for r in rows], pa.float64()),
        "tension_min": pa.array([r[1] for r in rows], pa.float64()),
        "length_error": pa.array(
            [diagnostics.relative_length_error(x) for x in result.x], pa.float64()),
        "x": pa.FixedSizeListArray.from_arrays(
            pa.array(result.x.reshape(-1), pa.float64()), 3 * k),
        "multiplier": pa.FixedSizeListArray.from_arrays(
            pa.array(result.multiplier.reshape(-1), pa.float64()), k),
    }
    table = pa.table(columns)
    meta = provenance(summary=result.summary(), command_line=command_line or [])
    return table.replace_schema_metadata(meta)


def write_trajectory(result, path, command_line=None):
    """Write a run's snapshots to Parquet (atomically)."""
    write_table_atomically(trajectory_table(result, command_line), path)


def read_metadata(path):
    """Decoded schema metadata of a loopsim Parquet file."""
    raw = pq.read_schema(path).metadata or {}
    out = {}
    for key, value in raw.items():
        key, value = key.decode(), value.decode()
        try:
            out[key] = json.loads(value)
        except json.JSONDecodeError:
            out[key] = value
    return out
