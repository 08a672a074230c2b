"""The sweep directory: made or checked (one configuration per directory), repaired
before a resume, and the files of a finished piece written into it."""
import json
import os

from .. import columns, storage


# ---- the table (schema: storage.RESULT_SCHEMA; every column described in loopsim.columns) ----
FIELD_NOTES = {name: text for name, (_, text) in columns.RESULT_COLUMNS.items()}


def write_piece(out, fingerprint, piece, table, snapshots):
    """Write a finished piece (positions ``piece``): its snapshots first, so that a result
    file always has its snapshots, then its results, each atomically.  The files carry
    the sweep's fingerprint and their positions, not the configuration."""
    meta = storage.provenance(sweep_fingerprint=fingerprint, positions=[piece.start, piece.stop])
    name = storage.CHUNK_PATTERN.format(piece.start, piece.stop)
    if snapshots is not None:
        storage.make_directories(os.path.join(out, storage.SNAPSHOT_DIR))
        storage.write_table_atomically(snapshots.replace_schema_metadata(meta),
                                  os.path.join(out, storage.SNAPSHOT_DIR, name))
    storage.write_table_atomically(table.replace_schema_metadata(meta), os.path.join(out, name))


def prepare_directory(out, config, command_line):
    """Create or check ``out`` and return the configuration's fingerprint.  A directory
    holds one configuration: every result file must carry its fingerprint.  Files wholly
    contained in another (a piece written on interrupt and later recomputed by a side-by-
    side identical sweep) are redundant and removed; partial overlaps are refused.  Then
    only dead processes' temporaries are removed."""
    storage.check_layout(out)
    current = json.loads(json.dumps(config.as_dict()))
    fingerprint = storage.config_fingerprint(current)
    storage.check_round_directory(out, fingerprint)
    storage.make_directories(out)
    stored = storage.read_sweep_file(out)
    if stored is not None and stored["fingerprint"] != fingerprint:
        previous = stored["config"]
        changed = sorted(k for k in set(previous) | set(current)
                         if k not in storage.FINGERPRINT_IGNORES
                         and previous.get(k) != current.get(k))
        raise ValueError(f"{out!r} holds a different sweep (differs in: "
                         f"{', '.join(changed) or 'its fingerprint'}); use another --out")
    files = storage.chunk_files(out)
    repair_directory(out, files, stored)
    files = storage.chunk_files(out)
    storage.check_files_belong(dict(config=current, fingerprint=fingerprint), files)
    _remove_contained(out, files, len(config.cases))
    storage.check_no_overlap(storage.chunk_files(out))
    storage.remove_stale_temporaries(out)
    storage.remove_stale_temporaries(os.path.join(out, storage.SNAPSHOT_DIR))
    if stored is None:
        hashed = all(storage.CONTENT_KEY in storage.read_metadata(path) for path in files.values())
        storage.write_record_atomically(dict(
            layout=storage.LAYOUT, fingerprint=fingerprint, config=current,
            command_line=command_line,
            field_notes=FIELD_NOTES, reruns=[],
            **({"checksums": storage.CONTENT_KEY} if hashed else {}),
            **json.loads(json.dumps(storage.provenance()))),
            os.path.join(out, storage.SWEEP_FILE))
    return fingerprint


def repair_directory(out, files, stored):
    """Self-repair before a resume: every result file (and its snapshot file) is read back
    whole and checked (readable, Parquet page checksums, content hash); a damaged one is
    moved to ``out/_quarantine/`` with a one-line warning, so its cases are computed
    again.  Returns the number of files moved."""
    moved = 0
    for _, path, reason in storage.damaged_files(out, files, stored):
        snapshot = os.path.join(out, storage.SNAPSHOT_DIR, os.path.basename(path))
        if os.path.exists(snapshot):
            storage.quarantine(out, snapshot, reason)
        moved += storage.quarantine(out, path, reason)
    return moved


def _remove_contained(out, files, count):
    """Remove result files (and their snapshots) whose positions another file holds too,
    once that file's rows are checked to be the cases its name says."""
    widest = None
    for start, stop in sorted(files, key=lambda key: (key[0], -key[1])):
        if widest is not None and start >= widest[0] and stop <= widest[1]:
            ids = storage.read_table_checked(files[widest]).column("case_id")
            storage.check_rows(files[widest], widest, ids.to_pylist(), count)
            name = os.path.basename(files[start, stop])
            for path in (os.path.join(out, storage.SNAPSHOT_DIR, name), files[start, stop]):
                if os.path.exists(path):
                    os.remove(path)
        elif widest is None or stop > widest[1]:
            widest = (start, stop)
