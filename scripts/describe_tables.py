"""Give the committed tables in data/ their columns' units and descriptions.

Usage: python scripts/describe_tables.py [--check]

Each ``data/*.parquet`` table is matched to its declarations in ``loopsim.columns``
(``TABLES`` below) and rewritten with every field's ``unit`` and ``description`` in its
metadata, orders (``n``) as int64, and the directory it was made from recorded by name
only (``summary_of``: never a machine's path).  The values are not recomputed: the script
reads each column back after writing and stops with an error unless it is bit-identical
to the column before (an integer order compared with the float it replaces, which must be
integral).  The schema metadata is kept (provenance: the version that computed the table,
its ``created_utc``), with ``columns_described_by`` added where the script changed the
file; the content hash is recomputed.  A file already described (by this script, or
written by a loopsim that declares its columns) is left as it is: running it again
changes nothing (``--check`` exits 1 if a file would change, 0 otherwise, writing
nothing).
"""
import argparse
import os
import sys

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

import loopsim
from loopsim import columns, storage

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "data")
#: file name: the declarations of its columns.
TABLES = {
    "seeds_auto_grid_summary.parquet": columns.SUMMARY_COLUMNS,
    "seeds_auto_grid_stops.parquet": columns.STOP_COLUMNS,
    "seeds_auto_grid_compare_n32.parquet": columns.COMPARE_COLUMNS,
    "paper_range_summary.parquet": columns.SUMMARY_COLUMNS,
    "paper_range_stops.parquet": columns.STOP_COLUMNS,
    "convergence_top.parquet": columns.CONVERGENCE_COLUMNS,
    "phase_n6_cases.parquet": columns.RESULT_COLUMNS,
    "phase_n4_cases.parquet": columns.RESULT_COLUMNS,
    "phase_n8_cases.parquet": columns.RESULT_COLUMNS,
    "rest_study.parquet": columns.REST_STUDY_COLUMNS,
    "paper_range_rest_summary.parquet": columns.SUMMARY_COLUMNS,
    "paper_range_overview.parquet": columns.RANGE_OVERVIEW_COLUMNS,
}
#: Columns that hold integer orders (written as floats before 0.3.0).
INTEGER_COLUMNS = ("n",)


def described_table(table, declarations):
    """``table`` with its integer orders as int64, no machine path in its metadata and every
    field's unit and description (``storage.described``); its content hash left to the writer."""
    for name in INTEGER_COLUMNS:
        if name in table.column_names and not pa.types.is_integer(table.schema.field(name).type):
            values = table[name]
            filled = pc.fill_null(values, 0).to_numpy()
            if not np.array_equal(filled, np.round(filled)):
                raise ValueError(f"column {name!r} holds non-integral values: not an order")
            table = table.set_column(table.schema.get_field_index(name), name,
                                     pc.cast(values, pa.int64()))
    meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()
            if k.decode() != storage.CONTENT_KEY}
    if "summary_of" in meta:
        meta["summary_of"] = os.path.basename(os.path.normpath(meta["summary_of"]))
    return storage.described(table.replace_schema_metadata(meta), declarations)


def with_note(table):
    """``table`` with ``columns_described_by`` in its metadata: this script changed it."""
    meta = dict(table.schema.metadata)
    meta[b"columns_described_by"] = \
        f"scripts/describe_tables.py (loopsim {loopsim.__version__})".encode()
    return table.replace_schema_metadata(meta)


def same_values(before, after):
    """Whether every column of ``after`` holds bit for bit the values of ``before`` (an
    int64 order against the float it replaced: equal as numbers)."""
    if before.column_names != after.column_names or before.num_rows != after.num_rows:
        return False
    for name in before.column_names:
        a, b = before[name].combine_chunks(), after[name].combine_chunks()
        if a.type != b.type:
            if not (name in INTEGER_COLUMNS and pa.types.is_integer(b.type)):
                return False
            a = pc.cast(a, pa.float64())
            b = pc.cast(b, pa.float64())
        if pa.types.is_floating(a.type):
            left = np.asarray(a.to_numpy(zero_copy_only=False), dtype=np.float64)
            right = np.asarray(b.to_numpy(zero_copy_only=False), dtype=np.float64)
            if left.view(np.uint64).tolist() != right.view(np.uint64).tolist():
                return False
            if a.null_count or b.null_count:
                if not a.is_null().equals(b.is_null()):
                    return False
        elif not a.equals(b):
            return False
    return True


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true",
                        help="exit 1 if a file would change; write nothing")
    args = parser.parse_args(argv)
    stale = []
    for name, declarations in TABLES.items():
        path = os.path.normpath(os.path.join(DATA, name))
        before = storage.read_table_checked(path, True)
        table = described_table(before, declarations)
        if not same_values(before, table):
            raise SystemExit(f"describe_tables: error: {name}'s values would change")
        old_meta = {k: v for k, v in before.schema.metadata.items()
                    if k.decode() != storage.CONTENT_KEY}
        if table.schema.equals(before.schema.with_metadata(old_meta), check_metadata=True):
            print(f"{name}: unchanged")  # described already (by this script, or its writer)
            continue
        table = with_note(table)
        stale.append(name)
        if args.check:
            print(f"{name}: would change")
            continue
        storage.write_table_atomically(table, path)
        if not same_values(before, storage.read_table_checked(path, True)):
            storage.write_table_atomically(before, path)
            raise SystemExit(f"describe_tables: error: {name}'s values did not survive the "
                             "write; the file was restored")
        print(f"{name}: {len(before.column_names)} columns described, values bit-identical")
    return 1 if args.check and stale else 0


if __name__ == "__main__":
    sys.exit(main())
