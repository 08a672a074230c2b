"""The sweep directory's files: its layout and case order, the configuration file and
its fingerprint, the result files' names and checks, quarantine of damaged files, and
the readers :func:`read_results` and :func:`read_snapshots`."""
import datetime
import functools
import glob
import hashlib
import json
import math
import os
import re
import warnings

import pandas as pd
import pyarrow as pa

from .. import columns
from .integrity import (
    CONTENT_KEY, DamagedFile, make_directories, read_table_checked, record_hash_damage,
)
from .tables import MOTION_FIELDS, RESULT_SCHEMA, read_metadata


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
#: Names of layout 1, the only layout of the 0.2.0 release and those before it: refused with
#: a one-line error.  Layout 2 (``_sweep.json``, whose ``layout`` field says 2) is the layout
#: of 0.3.0; the development builds between the two releases, whose tables still say
#: ``loopsim_version`` 0.2.0, wrote layout 2 too, so the layout, not the version, decides.
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


def check_layout(directory):
    """One-line ValueError for a directory written by the first layout (``sweep.json``,
    ``chunk-KKKKK.parquet``): it cannot be resumed or read by this version."""
    if not os.path.isdir(directory):
        return
    old = sorted(name for name in os.listdir(directory) if _OLD_LAYOUT.fullmatch(name))
    if old:
        raise ValueError(
            f"{directory!r} is a layout-1 sweep directory (loopsim 0.2.0 and earlier releases; "
            f"{old[0]}): this version "
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
    """The decoded ``_sweep.json`` of a sweep directory, or None when there is none; a
    one-line ValueError when it is damaged: its checksum (``content_sha256``, where the
    record has one: older releases wrote none) or its fingerprint fails, or a field is
    missing."""
    path = os.path.join(directory, SWEEP_FILE)
    if not os.path.exists(path):
        return None
    try:
        with open(path) as handle:
            stored = json.load(handle)
        damage = record_hash_damage(stored)  # a whole-record checksum, where written
        if damage is None:
            stored["fingerprint"], stored["config"]  # noqa: B018 - both must be there
            if config_fingerprint(stored["config"]) != stored["fingerprint"]:
                damage = "its configuration does not match its fingerprint"
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        damage = f"{type(exc).__name__}: {exc}"
    if damage is not None:
        raise ValueError(f"{path!r} is damaged ({damage}); move it away and re-run the "
                         "sweep's command to rewrite it")
    return stored


#: Where a sweep moves damaged result files (and their snapshots) before recomputing them.
QUARANTINE_DIR = "_quarantine"


def quarantine(directory, path, reason):
    """Move a damaged file into ``directory/_quarantine/`` (never deleted: a user may want
    it) and warn in one line; False when it is gone already (moved by a twin sweep)."""
    target_dir = os.path.join(directory, QUARANTINE_DIR)
    make_directories(target_dir)
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


def read_snapshots(out):
    """The stored trajectories of a sweep: one row per snapshot of each case chosen with
    ``snapshots_for`` (``--snapshots-for``).

    Only the snapshot files whose result file is there are read (a piece cut short has
    none), each checked (page checksums, content hash).

    Parameters
    ----------
    out : str
        A sweep directory.

    Returns
    -------
    pandas.DataFrame
        The columns of ``loopsim.columns.TRAJECTORY_COLUMNS`` (``case_id``, ``t`` in t_u,
        ``theta_deg``, ``x`` in L/2π ...), sorted by (case_id, t); empty when no
        snapshot was stored or ``out`` does not exist.

    Raises
    ------
    ValueError
        A damaged snapshot file (named; the sweep's command recomputes it), or a
        layout-1 directory.

    Examples
    --------
    >>> import loopsim
    >>> rows = loopsim.sweep(150, 60, "runs/one", n=6, t_end=1.0, snapshots_for=[0])
    >>> loopsim.read_snapshots("runs/one").groupby("case_id")["t"].max()
    case_id
    0    1.0
    Name: t, dtype: float64
    """
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


#: Columns added since result files were first written, with the value their rows had
#: before (a file written earlier holds local-model rows without these columns).
ADDED_COLUMNS = {"model": "local", "slenderness": None, "twin_regime": None,
                 "twin_theta_final_deg": None, "twin_aspect_ratio": None,
                 **{name: None for name in MOTION_FIELDS}, "early_stop": None}
#: The added columns whose value in an older file's rows is known exactly (the local
#: model; ``early_stop`` from the sweep's configuration): the others are not recorded
#: there (null: unknown, :func:`not_recorded_columns`).
KNOWN_BEFORE = ("model", "slenderness", "early_stop")


def not_recorded_columns(table):
    """The columns of RESULT_SCHEMA that the rows of a result file's ``table`` do not
    record (added since the file was written, value unknown: not in :data:`KNOWN_BEFORE`)."""
    return [name for name in ADDED_COLUMNS
            if name not in KNOWN_BEFORE and name not in table.schema.names]


def result_table(table, early_stop=None):
    """A verified result file's table in RESULT_SCHEMA (metadata dropped; columns added
    since the file was written filled in from ``ADDED_COLUMNS``; ``early_stop``: the
    sweep's, for files written before rows recorded it)."""
    table = table.replace_schema_metadata(None)
    for name, value in dict(ADDED_COLUMNS, early_stop=early_stop).items():
        if name not in table.schema.names:
            kind = RESULT_SCHEMA.field(name).type
            table = table.append_column(name, pa.array([value] * table.num_rows, kind))
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


#: Metadata that describes one file, not the table its rows join (:func:`table_metadata`).
PER_FILE_KEYS = ("positions", CONTENT_KEY, "created_utc")


def table_metadata(files_meta):
    """The metadata of a table joined from files with metadata ``files_meta`` (a list of
    dicts, in file order): what every file shares; for a key whose value differs between
    files (say, loopsim_version after a resume with another release), the sorted distinct
    values; instead of each file's positions, content hash and creation time, the number of
    files and the first and last creation times."""
    meta = {}
    for key in dict.fromkeys(k for m in files_meta for k in m):
        if key in PER_FILE_KEYS:
            continue
        values = [m[key] for m in files_meta if key in m]
        distinct = sorted({json.dumps(v, sort_keys=True) for v in values})
        meta[key] = values[0] if len(distinct) == 1 else [json.loads(v) for v in distinct]
    created = sorted(m["created_utc"] for m in files_meta if "created_utc" in m)
    meta.update(files=len(files_meta), created_utc_first=created[0] if created else None,
                created_utc_last=created[-1] if created else None)
    return meta


def mixed_columns_text(frame):
    """One line where some rows of a results table (``read_results``) lack columns that
    the others record (a sweep resumed across releases: the older rows were written before
    the columns existed), naming the columns and how many rows lack each; None where
    none is mixed."""
    lacking = frame.attrs.get("loopsim", {}).get("not_recorded", {}) or {}
    mixed = {name: rows for name, rows in lacking.items() if 0 < rows < len(frame)}
    if not mixed:
        return None
    groups = {}
    for name, rows in mixed.items():
        groups.setdefault(rows, []).append(name)
    parts = [f"{rows} of the {len(frame)} rows lack column(s) {', '.join(names)}"
             for rows, names in sorted(groups.items(), reverse=True)]
    return ("; ".join(parts) + ": written by an older release, before the columns existed, "
            "and resumed by this one; their values (and the counts over them: still moving "
            "at the end ...) are not recorded (null, unknown) for those rows, never 0")


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
    tables, lacking = {}, {}
    early_stop = stored["config"].get("early_stop", True)
    for key in sorted(files):
        try:
            written = read_table_checked(files[key], requires_hash(stored))
        except DamagedFile as exc:
            raise ValueError(f"{exc}; re-run the sweep's command: it moves the file to "
                             f"{QUARANTINE_DIR}/ and recomputes its cases") from None
        for name in not_recorded_columns(written):
            lacking[name] = lacking.get(name, 0) + written.num_rows
        tables[key] = result_table(written, early_stop)
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
    meta = table_metadata([read_metadata(path) for path in paths])
    meta.update(sweep_config=stored["config"], thresholds=stored["config"].get("thresholds"),
                command_line=stored.get("command_line", []),
                field_notes=stored.get("field_notes", {}), reruns=stored.get("reruns", []),
                not_recorded=lacking,
                columns={name: dict(unit=unit, description=text)
                         for name, (unit, text) in columns.RESULT_COLUMNS.items()})
    frame.attrs["loopsim"] = meta
    return frame
