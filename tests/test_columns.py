"""Every column loopsim writes or commits is declared: a unit and a description."""
import glob
import os
import subprocess
import sys

import pyarrow.parquet as pq
import pytest

from loopsim import columns

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA_TABLES = sorted(glob.glob(os.path.join(ROOT, "data", "*.parquet")))


def test_there_are_committed_tables():
    assert len(DATA_TABLES) >= 3


@pytest.mark.parametrize("path", DATA_TABLES, ids=os.path.basename)
def test_every_column_of_a_committed_table_has_a_unit_and_a_description(path):
    schema = pq.read_schema(path)
    for field in schema:
        meta = field.metadata or {}
        assert meta.get(b"unit", b"").strip(), f"{field.name}: no unit"
        assert meta.get(b"description", b"").strip(), f"{field.name}: no description"
    assert all(not value.startswith(b"/") for value in schema.metadata.values()), \
        "a machine path in the table's metadata"
    if "n" in schema.names:
        assert str(schema.field("n").type) == "int64"  # orders are integers


def test_committed_tables_match_the_declarations_script():
    """scripts/describe_tables.py --check: the files carry what loopsim.columns declares
    now (a changed declaration fails here until the script is re-run)."""
    done = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "describe_tables.py"),
                           "--check"], capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 0, done.stdout + done.stderr


@pytest.mark.parametrize("declarations", [columns.RESULT_COLUMNS, columns.TRAJECTORY_COLUMNS,
                                          columns.SUMMARY_COLUMNS, columns.COMPARE_COLUMNS,
                                          columns.STOP_COLUMNS])
def test_every_declaration_has_a_unit_and_a_description(declarations):
    for name, (unit, text) in declarations.items():
        assert unit.strip() and text.strip(), name


def test_summary_declarations_cover_every_cell_input_and_regime():
    from loopsim import outcome_statistics, outcomes

    assert set(outcome_statistics.CELL_INPUTS) <= set(columns.SUMMARY_COLUMNS)
    for regime in outcomes.REGIMES:
        assert f"p_{regime.replace('-', '_')}_high" in columns.SUMMARY_COLUMNS


@pytest.mark.parametrize("words, code, text", [
    (["--help"], 0, "which table"),
    (["trajectory"], 0, "| `t` |"),
    (["nonsense"], 2, "invalid choice: 'nonsense'"),
])
def test_the_module_prints_a_table_or_one_clear_error(words, code, text):
    """``python -m loopsim.columns --help`` once ended in a KeyError traceback."""
    done = subprocess.run([sys.executable, "-m", "loopsim.columns", *words],
                          capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == code, done.stderr
    assert text in done.stdout + done.stderr
    assert "Traceback" not in done.stderr
