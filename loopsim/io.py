"""Tables: the declared schemas, Parquet writing with provenance, and the readers.

Every table loopsim writes carries schema-level metadata (versions, the
coefficient layout, the run or sweep configuration); files are written to a
temporary name and renamed into place.
"""
import datetime
import functools
import glob
import hashlib
import json
import math
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

from . import columns, diagnostics
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
RUN_FIELDS = ("method", "n_used", "status", "t_final", "steps_accepted", "steps_rejected",
              "nfev", "njev", "nlu", "wall_s", "tail_max")
#: What the end state means (``loopsim.outcomes``).
OUTCOME_FIELDS = ("regime", "resolved", "determined", "theta_uncertainty_deg",
                  "aspect_uncertainty", "twin_nfev")
SUMMARY_FIELDS = (INPUT_FIELDS + RUN_FIELDS + tuple(d.name for d in diagnostics.REGISTRY)
                  + OUTCOME_FIELDS)

_FLOAT = pa.float64()
_INT = pa.int64()
_SUMMARY_TYPES = {
    "n": _INT, "seed": _INT, "method": pa.string(), "n_used": _INT, "status": pa.string(),
    "steps_accepted": _INT,
    "steps_rejected": _INT, "nfev": _INT, "njev": _INT, "nlu": _INT,
    "regime": pa.string(), "resolved": pa.bool_(), "determined": pa.bool_(), "twin_nfev": _INT,
    **{d.name: pa.from_numpy_dtype(np.dtype(d.dtype)) for d in diagnostics.REGISTRY},
}
#: The declared schema of every sweep chunk (and of :func:`read_results`); each field
#: carries its unit and description (``loopsim.columns``) in its metadata.
RESULT_SCHEMA = pa.schema(
    [pa.field(name, kind, metadata=columns.field_metadata(name)) for name, kind in
     [("case_id", _INT)]
     + [(name, _SUMMARY_TYPES.get(name, _FLOAT)) for name in SUMMARY_FIELDS]
     + [("stop_reason", pa.string()), ("aspect_ratio_initial", _FLOAT),
        ("length_error_max", _FLOAT), ("x_final", pa.list_(_FLOAT))]]
)


def coefficients(row):
    """The (3, 2n + 1) coefficient array of a results row's ``x_final`` (a row of
    :func:`read_results`, a dict, or the list itself): x, y, z, each [a0, a1..an,
    b1..bn] (``COEFFICIENT_LAYOUT``)."""
    values = row if isinstance(row, (list, tuple, np.ndarray)) else row["x_final"]
    return np.asarray(values, dtype=float).reshape(3, -1)


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


#: A sweep directory is a Parquet dataset: result files ``chunk-SSSSSSS-EEEEEEE.parquet`` at
#: the top (positions [S, E) of the sweep's case order), everything else under names that
#: dataset readers skip (a leading "_" or "."): the configuration once in ``_sweep.json``,
#: snapshots in ``_snapshots/`` (same file names), reruns of failed cases in ``_reruns/``.
SWEEP_FILE = "_sweep.json"
SNAPSHOT_DIR = "_snapshots"
RERUN_DIR = "_reruns"
LAYOUT = 2
CHUNK_PATTERN = "chunk-{:07d}-{:07d}.parquet"
_CHUNK_NAME = re.compile(r"chunk-(\d{7,})-(\d{7,})\.parquet")
#: Names of the first layout (loopsim 0.2.0 and before): refused with a one-line error.
_OLD_LAYOUT = re.compile(r"sweep\.json|(chunk|snapshots)-\d{5}\.parquet")
#: Configuration fields that change no row: left out of the fingerprint, so a resume may
#: change them.
FINGERPRINT_IGNORES = ("chunk_size",)


@functools.lru_cache(maxsize=8)
def case_order(count):
    """Position -> case id for a sweep of ``count`` cases: p -> p * stride mod count, with
    stride the integer nearest count / golden ratio that is coprime to count.  Neighbouring
    positions lie far apart in the grid, so every chunk mixes cheap and costly corners; the
    order depends on the case count only, never on the chunk size."""
    stride = max(1, round(count * 0.6180339887498949))
    while math.gcd(stride, count) != 1:
        stride += 1
    return tuple(p * stride % count for p in range(count))


def check_rows(path, positions, case_ids, count):
    """ValueError unless the result file ``path`` named for ``positions`` (start, stop)
    holds exactly the cases of those positions (a copy under another name does not)."""
    order = case_order(count)
    if sorted(case_ids) != sorted(order[p] for p in range(*positions)):
        raise ValueError(f"{path!r} holds other cases than its name says (a renamed copy?); "
                         "move it away")


def config_fingerprint(config):
    """SHA-256 (first 16 hex digits) of a sweep configuration (a dict), without
    ``FINGERPRINT_IGNORES``: every result file carries it, instead of the configuration."""
    kept = {k: v for k, v in config.items() if k not in FINGERPRINT_IGNORES}
    text = json.dumps(kept, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


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


def check_layout(directory):
    """One-line ValueError for a directory written by the first layout (``sweep.json``,
    ``chunk-KKKKK.parquet``): it cannot be resumed or read by this version."""
    if not os.path.isdir(directory):
        return
    old = sorted(name for name in os.listdir(directory) if _OLD_LAYOUT.fullmatch(name))
    if old:
        raise ValueError(
            f"{directory!r} is a sweep directory of loopsim <= 0.2.0 ({old[0]}): this version "
            "neither resumes nor reads it; re-run the sweep into a new --out (its chunk files "
            f"stay readable with pandas.read_parquet({os.path.join(directory, 'chunk-*.parquet')!r}"
            " file by file)")


def chunk_files(directory, kind="chunk"):
    """{(start, stop): path} of a sweep directory's result files (``kind="snapshots"``:
    its snapshot files), named exactly ``chunk-SSSSSSS-EEEEEEE.parquet``; any other
    ``chunk-*`` file (a stray copy) is ignored with a warning naming it."""
    if kind == "snapshots":
        directory = os.path.join(directory, SNAPSHOT_DIR)
    found = {}
    for path in sorted(glob.glob(os.path.join(directory, "chunk-*"))):
        match = _CHUNK_NAME.fullmatch(os.path.basename(path))
        if match is None or int(match[1]) >= int(match[2]):
            warnings.warn(f"ignoring {path!r}: not a {kind} file of this sweep (stray copy?)",
                          stacklevel=2)
            continue
        found[int(match[1]), int(match[2])] = path
    return found


def overlapping(ranges):
    """The first pair of position ranges (start, stop) that share a position, or None."""
    ordered = sorted(ranges)
    for first, second in zip(ordered, ordered[1:]):
        if second[0] < first[1]:
            return first, second
    return None


def read_sweep_file(directory):
    """The decoded ``_sweep.json`` of a sweep directory, or None when there is none."""
    path = os.path.join(directory, SWEEP_FILE)
    if not os.path.exists(path):
        return None
    try:
        with open(path) as handle:
            stored = json.load(handle)
        stored["fingerprint"], stored["config"]  # noqa: B018 - both must be there
        if config_fingerprint(stored["config"]) != stored["fingerprint"]:
            raise ValueError("its configuration does not match its fingerprint")
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        raise ValueError(f"{path!r} is damaged ({type(exc).__name__}: {exc}); move it away and "
                         "re-run the sweep's command to rewrite it") from None
    return stored


def _umask():
    """The process umask (read without changing it where /proc allows)."""
    try:
        with open("/proc/self/status") as handle:
            for line in handle:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except OSError:
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _temporary(directory, suffix):
    """(fd, path) of a new temporary file in ``directory`` named for this host and process,
    with the mode an ordinary ``open`` gives (0666 less the umask; mkstemp's is 0600).
    The directory is made if absent (output paths are checked before any work)."""
    os.makedirs(directory, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=_temporary_prefix(), suffix=suffix, dir=directory)
    os.fchmod(fd, 0o666 & ~_umask())
    return fd, tmp


def write_json_atomically(data, path):
    """Write JSON to a temporary file in the target directory, then rename into place."""
    fd, tmp = _temporary(os.path.dirname(os.path.abspath(path)), ".json")
    try:
        with os.fdopen(fd, "w") as handle:
            json.dump(data, handle, indent=1)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def write_table_atomically(table, path):
    """Write to a temporary file in the target directory, then rename into place; with
    Parquet page checksums (CRC32) and :data:`CONTENT_KEY`, a SHA-256 of the content and
    metadata (:func:`content_hash`), in the file's metadata."""
    meta = {_text(k): _text(v) for k, v in (table.schema.metadata or {}).items()
            if _text(k) != CONTENT_KEY}
    table = table.replace_schema_metadata(dict(meta, **{CONTENT_KEY: content_hash(table, meta)}))
    fd, tmp = _temporary(os.path.dirname(os.path.abspath(path)), ".parquet")
    os.close(fd)
    try:
        pq.write_table(table, tmp, write_page_checksum=True)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


# ---- checksums: detecting damaged files -------------------------------------------------
#: Metadata key of a file's content hash (SHA-256, hex) written by write_table_atomically.
CONTENT_KEY = "content_sha256"
#: Where a sweep moves damaged result files (and their snapshots) before recomputing them.
QUARANTINE_DIR = "_quarantine"


def _text(value):
    return value.decode() if isinstance(value, bytes) else str(value)


def _hash_array(digest, array):
    """Feed one array's values (not its buffers' layout: chunking, offsets, a list's fixed
    or variable size do not count) into ``digest``."""
    digest.update(f"|{len(array)}:{array.null_count}|".encode())
    if array.null_count:
        digest.update(np.asarray(array.is_null().to_numpy(zero_copy_only=False)).tobytes())
    kind = array.type
    if pa.types.is_fixed_size_list(kind):
        digest.update(np.full(len(array), kind.list_size, np.int64).tobytes())
        _hash_array(digest, array.flatten())
    elif pa.types.is_list(kind) or pa.types.is_large_list(kind):
        digest.update(array.value_lengths().fill_null(0).to_numpy(zero_copy_only=False)
                      .astype(np.int64).tobytes())
        _hash_array(digest, array.flatten())
    elif pa.types.is_boolean(kind):
        digest.update(array.fill_null(False).to_numpy(zero_copy_only=False)
                      .astype(np.uint8).tobytes())
    elif pa.types.is_integer(kind) or pa.types.is_floating(kind):
        digest.update(array.fill_null(0).to_numpy(zero_copy_only=False).tobytes())
    else:  # strings and anything else: their values as JSON
        digest.update(json.dumps(array.to_pylist(), default=str).encode())


def content_hash(table, metadata):
    """SHA-256 (hex) of a table's column names, field metadata and values and of its schema metadata
    ``metadata`` (a dict, without :data:`CONTENT_KEY` and pyarrow's own ``ARROW:`` keys):
    written into every file loopsim writes, checked by :func:`read_table_checked`."""
    digest = hashlib.sha256()
    for key in sorted(metadata):
        if key != CONTENT_KEY and not key.startswith("ARROW:"):
            digest.update(f"{key}\0{metadata[key]}\0".encode())
    for field, column in zip(table.schema, table.columns):
        digest.update(f"\0column {field.name}\0".encode())
        for key, value in sorted((field.metadata or {}).items()):  # units, descriptions
            digest.update(b"\0field " + key + b"\0" + value)
        _hash_array(digest, column.combine_chunks())
    return digest.hexdigest()


class DamagedFile(ValueError):
    """A file that cannot be read back as written: unreadable (truncated, zero length, not
    Parquet), a page checksum that fails, or a content hash that does not match."""

    def __init__(self, path, reason):
        super().__init__(f"{path!r} is damaged ({reason})")
        self.path, self.reason = path, reason


def read_table_checked(path, require_hash=False):
    """The whole table of a Parquet file, its page checksums (where written) and its
    content hash (:data:`CONTENT_KEY`, where present; always with ``require_hash``)
    verified.  :class:`DamagedFile` if any fails; OSError where the file cannot be opened."""
    try:
        table = pq.read_table(path, page_checksum_verification=True)
    except (FileNotFoundError, PermissionError, IsADirectoryError):
        raise
    except Exception as exc:  # noqa: BLE001 - whatever the reader says, the file is damaged
        lines = str(exc).strip().splitlines()
        raise DamagedFile(path, f"unreadable: {lines[0] if lines else type(exc).__name__}") \
            from None
    try:  # a flipped bit in the footer may leave names or metadata undecodable
        meta = {_text(k): _text(v) for k, v in (table.schema.metadata or {}).items()}
        stored = meta.get(CONTENT_KEY)
        matches = stored is not None and content_hash(table, meta) == stored
    except Exception as exc:  # noqa: BLE001 - anything unreadable in a file we wrote is damage
        raise DamagedFile(path, f"unreadable: {type(exc).__name__}: {str(exc)[:80]}") from None
    if stored is None:
        if require_hash:
            raise DamagedFile(path, f"no {CONTENT_KEY} in its metadata")
        return table
    if not matches:
        raise DamagedFile(path, "content does not match its checksum")
    return table


def quarantine(directory, path, reason):
    """Move a damaged file into ``directory/_quarantine/`` (never deleted: a user may want
    it) and warn in one line; False when it is gone already (moved by a twin sweep)."""
    target_dir = os.path.join(directory, QUARANTINE_DIR)
    os.makedirs(target_dir, exist_ok=True)
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y%m%dT%H%M%S")
    name = os.path.relpath(path, directory).replace(os.sep, "-")  # _snapshots-chunk-...
    target = os.path.join(target_dir, f"{name}.{stamp}-{os.getpid()}")
    while os.path.exists(target):
        target += "+"
    try:
        os.replace(path, target)
    except FileNotFoundError:
        return False
    warnings.warn(f"{path!r} is damaged ({reason}): moved to {target!r}; its cases are "
                  "recomputed", stacklevel=2)
    return True


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
    """Trajectory snapshots of the cases chosen with ``snapshots_for`` (a DataFrame): the
    snapshot files whose result file is there (one cut short has none)."""
    if not os.path.isdir(out):
        return pd.DataFrame()
    check_layout(out)
    finished = chunk_files(out)
    paths = [p for key, p in sorted(chunk_files(out, "snapshots").items()) if key in finished]
    if not paths:
        return pd.DataFrame()
    try:
        tables = [read_table_checked(p) for p in paths]
    except DamagedFile as exc:
        raise ValueError(f"{exc}; re-run the sweep's command: it moves the file to "
                         f"{QUARANTINE_DIR}/ and recomputes its cases") from None
    frame = pa.concat_tables([t.replace_schema_metadata(None) for t in tables]).to_pandas()
    return frame.sort_values(["case_id", "t"], kind="stable").reset_index(drop=True)


def check_files_belong(stored, files):
    """ValueError naming the first result file of ``files`` ({(start, stop): path}) that
    does not carry the fingerprint of ``stored`` (the decoded ``_sweep.json``) or lies
    beyond its cases."""
    count = len(stored["config"]["cases"])
    for (start, stop), path in sorted(files.items()):
        meta = read_metadata(path)
        if meta.get("sweep_fingerprint") != stored["fingerprint"] or stop > count:
            raise ValueError(f"{path!r} belongs to a different sweep than this one's "
                             f"configuration ({SWEEP_FILE}; fingerprints "
                             f"{meta.get('sweep_fingerprint')!r} and {stored['fingerprint']!r}, "
                             f"positions to {stop} of {count}); use another --out, or move "
                             "that file away")
        if meta.get("positions") != [start, stop]:
            raise ValueError(f"{path!r} holds other cases than its name says (a renamed "
                             "copy?); move it away")


def check_no_overlap(files):
    """ValueError naming two result files that hold the same positions (cases)."""
    pair = overlapping(files)
    if pair is not None:
        raise ValueError(f"{files[pair[1]]!r} repeats cases of {files[pair[0]]!r} (a copied file, "
                         "or sweeps with different --chunk-size run at the same time); move "
                         "one of them away")


def requires_hash(stored):
    """Whether the result files of a sweep (its decoded ``_sweep.json``) must carry a
    content hash: those of sweeps begun since checksums exist (``"checksums"`` in it)."""
    return bool(stored) and stored.get("checksums") == CONTENT_KEY


def result_table(table):
    """A verified result file's table in RESULT_SCHEMA (metadata dropped)."""
    table = table.replace_schema_metadata(None)
    if not table.schema.equals(RESULT_SCHEMA):
        table = table.select(RESULT_SCHEMA.names).cast(RESULT_SCHEMA)
    return table


def damaged_files(out, files, stored):
    """[(key, path, reason)] of the result files ``files`` ({(start, stop): path}) of sweep
    directory ``out`` that are damaged, or whose snapshot file is (both must then be
    recomputed).  Files gone meanwhile (a twin sweep's clean-up) are left out."""
    found = []
    for key, path in sorted(files.items()):
        snapshot = os.path.join(out, SNAPSHOT_DIR, os.path.basename(path))
        try:
            read_table_checked(path, requires_hash(stored))
            if os.path.exists(snapshot):
                read_table_checked(snapshot, requires_hash(stored))
        except DamagedFile as exc:
            found.append((key, path, str(exc.reason) if exc.path == path
                          else f"its snapshot file {exc.path!r}: {exc.reason}"))
        except FileNotFoundError:
            continue
    return found


def read_results(out):
    """All finished cases of a sweep directory as a DataFrame sorted by case_id.

    The same rows as ``pandas.read_parquet(out)``, checked: every file must read back
    whole with its page checksums and content hash (:func:`read_table_checked`; a damaged
    file is a one-line ValueError naming it: the sweep's command repairs it), carry the
    fingerprint of the configuration in ``_sweep.json``, and no case may appear twice.
    The sweep's metadata (configuration, thresholds, versions, command line, reruns)
    is in ``frame.attrs["loopsim"]``.
    """
    if not os.path.isdir(out):
        raise ValueError(f"no sweep directory at {out!r}")
    check_layout(out)
    files = chunk_files(out)
    stored = read_sweep_file(out)
    if stored is None:
        if not files:
            raise ValueError(f"{out!r} is not a sweep directory (no {SWEEP_FILE}, no result "
                             "files): give the directory a sweep's --out named")
        raise ValueError(f"{out!r} has result files but no {SWEEP_FILE} (the sweep's "
                         "configuration): re-run the sweep's command to restore it")
    tables = {}
    for key in sorted(files):
        try:
            tables[key] = result_table(read_table_checked(files[key], requires_hash(stored)))
        except DamagedFile as exc:
            raise ValueError(f"{exc}; re-run the sweep's command: it moves the file to "
                             f"{QUARANTINE_DIR}/ and recomputes its cases") from None
    check_files_belong(stored, files)
    check_no_overlap(files)
    paths = [files[key] for key in sorted(files)]
    if not paths:
        return RESULT_SCHEMA.empty_table().to_pandas()
    for key in sorted(files):
        check_rows(files[key], key, tables[key].column("case_id").to_pylist(),
                   len(stored["config"]["cases"]))
    table = pa.concat_tables([tables[key] for key in sorted(files)])
    frame = table.to_pandas().sort_values("case_id", kind="stable").reset_index(drop=True)
    duplicated = frame["case_id"][frame["case_id"].duplicated()]
    if len(duplicated):
        raise ValueError(f"{out!r} holds case_id {int(duplicated.iloc[0])} more than once "
                         f"({len(duplicated)} duplicate rows): a chunk file was copied or "
                         "renamed; move the extra files away")
    meta = read_metadata(paths[0])
    meta.update(sweep_config=stored["config"], thresholds=stored["config"].get("thresholds"),
                command_line=stored.get("command_line", []),
                field_notes=stored.get("field_notes", {}), reruns=stored.get("reruns", []),
                columns={name: dict(unit=unit, description=text)
                         for name, (unit, text) in columns.RESULT_COLUMNS.items()})
    frame.attrs["loopsim"] = meta
    return frame
