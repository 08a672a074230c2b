"""Tables: the declared schemas, Parquet writing with provenance, and the readers.

Every table loopsim writes carries schema-level metadata (versions, the
coefficient layout, the run or sweep configuration); files are written to a
temporary name and renamed into place.
"""
import datetime
import glob
import json
import os
import re
import socket
import tempfile
import warnings

import numba
import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from . import diagnostics
from ._version import __version__

COEFFICIENT_LAYOUT = (
    "x coefficients: row-major (component x,y,z; coefficient [a0, a1..an, b1..bn]) "
    "with f(s) = a0 + sum_k a_k cos ks + b_k sin ks, s in [0, 2pi); "
    "multiplier: the tension Lagrange multiplier T in the same layout; "
    "physical tension N = T + |x''|^2"
)


#: Summary fields, in order; they are also the sweep table's columns.
INPUT_FIELDS = ("g0", "theta0_deg", "n", "q0", "t_end", "rtol", "atol", "w", "perturbation",
                "seed")
RUN_FIELDS = ("status", "t_final", "steps_accepted", "steps_rejected", "nfev", "njev", "nlu",
              "wall_s")
SUMMARY_FIELDS = INPUT_FIELDS + RUN_FIELDS + tuple(d.name for d in diagnostics.REGISTRY)

_FLOAT = pa.float64()
_INT = pa.int64()
_SUMMARY_TYPES = {
    "n": _INT, "seed": _INT, "status": pa.string(), "steps_accepted": _INT,
    "steps_rejected": _INT, "nfev": _INT, "njev": _INT, "nlu": _INT,
    **{d.name: pa.from_numpy_dtype(np.dtype(d.dtype)) for d in diagnostics.REGISTRY},
}
#: The declared schema of every sweep chunk (and of :func:`read_results`).
RESULT_SCHEMA = pa.schema(
    [pa.field("case_id", _INT)]
    + [pa.field(name, _SUMMARY_TYPES.get(name, _FLOAT)) for name in SUMMARY_FIELDS]
    + [
        pa.field("regime", pa.string()),
        pa.field("stop_reason", pa.string()),
        pa.field("aspect_ratio_initial", _FLOAT),
        pa.field("length_error_max", _FLOAT),
        pa.field("resolved", pa.bool_()),
        pa.field("x_final", pa.list_(_FLOAT)),
    ]
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


#: Files of a sweep directory: chunk k and its snapshots, named exactly so.
CHUNK_PATTERN = "chunk-{:05d}.parquet"
SNAPSHOT_PATTERN = "snapshots-{:05d}.parquet"
_CHUNK_NAME = re.compile(r"chunk-(\d{5})\.parquet")
_SNAPSHOT_NAME = re.compile(r"snapshots-(\d{5})\.parquet")
#: Temporary files are named .tmp-HOST-PID-*: only their owner, or a later process on the
#: same host once the owner has died, may remove them.
_TEMP_NAME = re.compile(r"\.tmp-(?P<host>.+)-(?P<pid>\d+)-[^-]*$")


def _temporary_prefix():
    return f".tmp-{socket.gethostname()}-{os.getpid()}-"


def remove_stale_temporaries(directory):
    """Remove the temporary files in ``directory`` left by dead processes on this host
    (a write cut short by a kill); files of live processes and other hosts stay."""
    host = socket.gethostname()
    for path in glob.glob(os.path.join(directory, ".tmp-*")):
        match = _TEMP_NAME.match(os.path.basename(path))
        if match is None or match["host"] != host:
            continue
        try:
            os.kill(int(match["pid"]), 0)
        except ProcessLookupError:
            try:
                os.remove(path)
            except FileNotFoundError:
                pass
        except PermissionError:  # alive, another user's
            pass


def numbered_files(directory, kind="chunk"):
    """{k: path} of the chunk (or ``kind="snapshots"``) files of a sweep directory, named
    exactly ``chunk-KKKKK.parquet``; any other ``chunk-*`` file (a stray copy) is ignored
    with a warning naming it."""
    pattern = _CHUNK_NAME if kind == "chunk" else _SNAPSHOT_NAME
    found = {}
    for path in sorted(glob.glob(os.path.join(directory, f"{kind}-*"))):
        match = pattern.fullmatch(os.path.basename(path))
        if match is None:
            warnings.warn(f"ignoring {path!r}: not a {kind} file of this sweep (stray copy?)",
                          stacklevel=2)
            continue
        found[int(match[1])] = path
    return found


def write_table_atomically(table, path):
    """Write to a temporary file in the target directory, then rename into place."""
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=_temporary_prefix(), suffix=".parquet", dir=directory)
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
    rows = [diagnostics.evaluate(diagnostics.State(x, u, m, result.inputs["g0"]), trajectory=True)
            for x, u, m in zip(result.x, result.u, result.multiplier)]
    columns = {"t": pa.array(result.t, pa.float64())}
    for d in diagnostics.REGISTRY:
        if d.trajectory:
            columns[d.trajectory] = pa.array([r[d.trajectory] for r in rows],
                                             pa.from_numpy_dtype(np.dtype(d.dtype)))
    columns.update({
        "x": pa.FixedSizeListArray.from_arrays(
            pa.array(result.x.reshape(-1), pa.float64()), 3 * k),
        "multiplier": pa.FixedSizeListArray.from_arrays(
            pa.array(result.multiplier.reshape(-1), pa.float64()), k),
    })
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


def read_snapshots(out):
    """Trajectory snapshots of the cases chosen with ``snapshots_for`` (a DataFrame)."""
    paths = sorted(numbered_files(out, "snapshots").values()) if os.path.isdir(out) else []
    if not paths:
        return pd.DataFrame()
    frame = pa.concat_tables([pq.read_table(p) for p in paths]).to_pandas()
    return frame.sort_values(["case_id", "t"], kind="stable").reset_index(drop=True)


def read_results(out):
    """All finished cases of a sweep directory as a DataFrame sorted by case_id.

    The sweep's metadata (configuration, thresholds, versions, command line)
    is in ``frame.attrs["loopsim"]``.
    """
    if not os.path.isdir(out):
        raise ValueError(f"no sweep directory at {out!r}")
    paths = sorted(numbered_files(out).values())
    if not paths:
        return RESULT_SCHEMA.empty_table().to_pandas()
    configs = {p: read_metadata(p).get("sweep_config") for p in paths}
    if len({json.dumps(c, sort_keys=True) for c in configs.values()}) > 1:
        first = paths[0]
        other = next(p for p in paths if configs[p] != configs[first])
        raise ValueError(f"{out!r} mixes sweeps: {os.path.basename(other)!r} has another "
                         f"configuration than {os.path.basename(first)!r}; move the foreign "
                         "files away")
    table = pa.concat_tables([pq.read_table(p, schema=RESULT_SCHEMA) for p in paths])
    frame = table.to_pandas().sort_values("case_id", kind="stable").reset_index(drop=True)
    duplicated = frame["case_id"][frame["case_id"].duplicated()]
    if len(duplicated):
        raise ValueError(f"{out!r} holds case_id {int(duplicated.iloc[0])} more than once "
                         f"({len(duplicated)} duplicate rows): a chunk file was copied or "
                         "renamed; move the extra files away")
    frame.attrs["loopsim"] = read_metadata(paths[0])
    return frame
