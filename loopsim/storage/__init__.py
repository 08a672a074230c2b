"""Tables: the declared schemas, Parquet writing with provenance, and the readers.

Every table loopsim writes carries schema-level metadata (versions, the
coefficient layout, the run or sweep configuration); files are written to a
temporary name and renamed into place.

Three modules, each importing only those before it; every public name is
re-exported here (``loopsim.storage.read_results`` and so on):

* ``integrity``: atomic writes, temporaries, content hashes, the checked reader;
* ``tables``: schemas, provenance, trajectory tables, a file's metadata;
* ``sweepdir``: the sweep directory's layout and files, ``read_snapshots``;
* ``seedsdir``: the ``--seeds auto`` directory (rounds of sweeps), and ``read_results``,
  which reads either kind.
"""
from .integrity import (
    CONTENT_KEY, DamagedFile, content_hash, make_directories, read_table_checked, record_hash,
    record_hash_damage, remove_stale_temporaries, write_record_atomically,
    write_file_atomically, write_json_atomically, write_table_atomically,
)
from .sweepdir import (
    CHUNK_PATTERN, FINGERPRINT_IGNORES, LAYOUT, QUARANTINE_DIR, RERUN_DIR, SNAPSHOT_DIR,
    SWEEP_FILE, case_order, check_files_belong, check_layout, check_no_overlap, check_rows,
    chunk_files, config_fingerprint, damaged_files, mixed_columns_text, overlapping, quarantine,
    read_snapshots, read_sweep_file, requires_hash, result_table, table_metadata,
)
from .seedsdir import (
    CHECK_DIR, ROUND_DIR, SEEDS_FILE, STOPS_FILE, check_round_directory, check_rounds,
    is_seeds_auto, read_results, read_seeds_auto, read_seeds_file, read_stop_table, record_damage,
    round_directory, write_seeds_file,
)
from .tables import (
    COEFFICIENT_LAYOUT, INPUT_FIELDS, MOTION_FIELDS, OUTCOME_FIELDS, RESULT_SCHEMA, RUN_FIELDS, SUMMARY_FIELDS,
    coefficients, described, keys_a_write_would_drop, provenance, read_metadata, study_keys,
    trajectory_table, write_trajectory,
)

__all__ = [
    "CHUNK_PATTERN", "COEFFICIENT_LAYOUT", "CONTENT_KEY", "DamagedFile", "FINGERPRINT_IGNORES",
    "INPUT_FIELDS", "LAYOUT", "MOTION_FIELDS", "OUTCOME_FIELDS", "QUARANTINE_DIR", "RERUN_DIR", "RESULT_SCHEMA",
    "RUN_FIELDS", "SNAPSHOT_DIR", "SUMMARY_FIELDS", "SWEEP_FILE", "case_order",
    "check_files_belong", "check_layout", "check_no_overlap", "check_rows", "chunk_files",
    "coefficients", "config_fingerprint", "content_hash", "damaged_files", "described",
    "make_directories",
    "overlapping", "provenance", "quarantine", "read_metadata", "read_results",
    "read_snapshots", "read_sweep_file", "read_table_checked", "remove_stale_temporaries",
    "requires_hash", "result_table", "table_metadata", "trajectory_table", "write_json_atomically",
    "CHECK_DIR", "ROUND_DIR", "SEEDS_FILE", "STOPS_FILE", "check_round_directory", "check_rounds",
    "is_seeds_auto", "mixed_columns_text", "read_seeds_auto",
    "read_seeds_file", "read_stop_table", "record_damage", "round_directory",
    "write_seeds_file", "record_hash", "record_hash_damage", "write_record_atomically",
    "write_file_atomically", "write_table_atomically", "write_trajectory",
    "study_keys", "keys_a_write_would_drop",
]
