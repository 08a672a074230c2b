"""Files written whole or not at all, and read back verified: temporaries named for their
process (removed by the next write into their directory once it has died, and by the
process itself when a signal ends it at once: ``loopsim._signals``), atomic writes with
Parquet page checksums and a content hash, and the checked reader that raises
:class:`DamagedFile`."""
import glob
import hashlib
import json
import os
import re
import socket
import tempfile

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from .._signals import track_temporary, untrack_temporary


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


def make_directories(path):
    """``os.makedirs(path, exist_ok=True)`` without its recursion (one call per level: a
    legal path 1 000 directories deep exhausted Python's stack): the missing directories
    are made from the outermost in, each with the umask's mode, and removed again if a
    deeper one cannot be made (ENAMETOOLONG past PATH_MAX).  Returns the directories it
    made, outermost first (for :func:`remove_directories` when what goes in them fails).
    FileExistsError where a component is a file."""
    path = os.path.abspath(os.fspath(path))
    missing = []
    while not os.path.isdir(path):
        missing.append(path)
        parent = os.path.dirname(path)
        if parent == path:
            break
        path = parent
    made = []
    try:
        for directory in reversed(missing):
            try:
                os.mkdir(directory)
                made.append(directory)
            except FileExistsError:
                if not os.path.isdir(directory):
                    raise
    except OSError:
        remove_directories(made)   # nothing half-made is left behind
        raise
    return made


def remove_directories(made):
    """Remove the directories ``make_directories`` returned, innermost first, as far as
    they are empty (another process may have written into one meanwhile)."""
    for directory in reversed(made):
        try:
            os.rmdir(directory)
        except OSError:
            break


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
    """(fd, path, the directories made for it) of a new temporary file in ``directory``
    named for this host and process, with the mode an ordinary ``open`` gives (0666 less
    the umask; mkstemp's is 0600), registered for removal should a signal end the process
    at once (``_signals.remove_temporaries``).  The directory is made if absent (output
    paths are checked before any work); the temporaries that dead processes left in it
    are removed first (:func:`remove_stale_temporaries`)."""
    made = make_directories(directory)
    try:
        remove_stale_temporaries(directory)
        fd, tmp = tempfile.mkstemp(prefix=_temporary_prefix(), suffix=suffix, dir=directory)
    except OSError:   # a name past PATH_MAX in directories that fit: remove those made here
        remove_directories(made)
        raise
    track_temporary(tmp)
    os.fchmod(fd, 0o666 & ~_umask())
    return fd, tmp, made


def write_json_atomically(data, path):
    """Write JSON to a temporary file in the target directory, then rename into place
    (:func:`write_file_atomically`)."""
    def write(tmp):
        with open(tmp, "w") as handle:
            json.dump(data, handle, indent=1)

    write_file_atomically(path, write)


def write_file_atomically(path, write):
    """Call ``write(temporary_path)`` on a temporary file named for this process in the
    target directory (with the target's extension), then rename it into place: a file
    is there whole or not at all (a full disk leaves no empty or partial file, an
    exception or a signal no temporary; the temporaries of dead processes in that
    directory are removed first)."""
    fd, tmp, made = _temporary(os.path.dirname(os.path.abspath(path)),
                               os.path.splitext(path)[1])
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        remove_directories(made)   # a target's name past PATH_MAX leaves no directories
        raise
    finally:
        untrack_temporary(tmp)


def write_table_atomically(table, path):
    """Write to a temporary file in the target directory, then rename into place; with
    Parquet page checksums (CRC32) and :data:`CONTENT_KEY`, a SHA-256 of the content and
    metadata (:func:`content_hash`), in the file's metadata."""
    meta = {_text(k): _text(v) for k, v in (table.schema.metadata or {}).items()
            if _text(k) != CONTENT_KEY}
    table = table.replace_schema_metadata(dict(meta, **{CONTENT_KEY: content_hash(table, meta)}))
    write_file_atomically(path, lambda tmp: pq.write_table(table, tmp,
                                                          write_page_checksum=True))


# ---- checksums: detecting damaged files -------------------------------------------------
#: Metadata key of a file's content hash (SHA-256, hex) written by write_table_atomically.
CONTENT_KEY = "content_sha256"


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


def record_hash(record):
    """SHA-256 (hex) of a JSON record (a dict: ``_sweep.json``, ``_seeds_auto.json``) less its
    :data:`CONTENT_KEY`, over its canonical text (sorted keys, no spaces)."""
    kept = {k: v for k, v in record.items() if k != CONTENT_KEY}
    text = json.dumps(kept, sort_keys=True, separators=(",", ":"), ensure_ascii=True)
    return hashlib.sha256(text.encode()).hexdigest()


def write_record_atomically(record, path):
    """Write a JSON record atomically with its checksum (:func:`record_hash` under
    :data:`CONTENT_KEY`), checked by :func:`record_hash_damage` when read."""
    record = json.loads(json.dumps({k: v for k, v in record.items() if k != CONTENT_KEY}))
    record[CONTENT_KEY] = record_hash(record)
    write_json_atomically(record, path)


def _one_off(name, key):
    """Whether ``name`` is ``key`` with one character changed (a flipped bit in a key)."""
    return len(name) == len(key) and sum(a != b for a, b in zip(name, key)) == 1


def record_hash_damage(record):
    """Why a decoded JSON record fails its checksum, or None: not an object, a
    :data:`CONTENT_KEY` that does not match, or that key misspelt.  None too for a record
    without one (written by a release before checksums: its reader checks its fields)."""
    if not isinstance(record, dict):
        return f"a JSON {type(record).__name__}, not an object"
    if CONTENT_KEY in record:
        return None if record[CONTENT_KEY] == record_hash(record) else \
            "content does not match its checksum"
    misspelt = [k for k in record if _one_off(k, CONTENT_KEY)]
    return f"its checksum's key reads {misspelt[0]!r}" if misspelt else None


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
        # The footer as the other readers see it (pq.ParquetFile decodes the nested
        # column paths, which read_table's Arrow schema does not need): a name there that
        # is not UTF-8 is damage too, not a bare UnicodeDecodeError later.
        pq.ParquetFile(path).reader.column_paths  # noqa: B018 - decoded for the check
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
