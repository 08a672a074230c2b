"""Fault injection (issue 14): damaged result files (truncated, zero length, a flipped bit)
are detected, moved aside and recomputed; damaged --initial results are refused; sizes
are bounded before any work; Ctrl-C on ``loopsim run``; temporaries of killed runs."""
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import loopsim
from loopsim import storage, sweeps, validation
from loopsim.cli import main

DETERMINISTIC = [c for c in storage.RESULT_SCHEMA.names if c != "wall_s"]


def _config():
    cases = sweeps.grid_cases([10.0, 60.0], [30.0], [4], seeds=1)
    return sweeps.SweepConfig(cases=cases, t_end=0.2, chunk_size=1, snapshots_for=[1],
                              snapshot_count=3)


@pytest.fixture(scope="module")
def pristine(tmp_path_factory):
    """A 2-case sweep (one file per case, case 1 with snapshots) and its rows."""
    out = str(tmp_path_factory.mktemp("pristine") / "s")
    frame = sweeps.run_sweep(_config(), out, threads=1, quiet=True)
    return out, frame


@pytest.fixture
def sweep(tmp_path, pristine):
    out = str(tmp_path / "s")
    shutil.copytree(pristine[0], out)
    return out


def _same_rows(a, b):
    pd.testing.assert_frame_equal(a[DETERMINISTIC].reset_index(drop=True),
                                  b[DETERMINISTIC].reset_index(drop=True), check_exact=True)


def _silent_flip(path, column):
    """Flip, in place, the first bit (bit 0 of a byte, from the start) that plain
    ``pq.read_table`` reads without an error as other values of ``column``: silent
    corruption before checksums.  Returns the byte offset."""
    original = open(path, "rb").read()
    expected = pq.read_table(path).column(column)
    meta = pq.ParquetFile(path).metadata.row_group(0)
    chunk = next(meta.column(i) for i in range(meta.num_columns)
                 if meta.column(i).path_in_schema.split(".")[0] == column)
    start = min(o for o in (chunk.dictionary_page_offset, chunk.data_page_offset) if o)
    for offset in range(start, start + chunk.total_compressed_size):
        data = bytearray(original)
        data[offset] ^= 1
        with open(path, "wb") as handle:
            handle.write(bytes(data))
        try:
            changed = not pq.read_table(path).column(column).equals(expected)
        except Exception:  # noqa: BLE001 - a flip the reader notices: not silent
            continue
        if changed:
            return offset
    raise AssertionError(f"no silent flip of {column} found in {path}")


def _damage(path, how):
    if how == "truncated":
        os.truncate(path, os.path.getsize(path) // 2)
    elif how == "zero length":
        os.truncate(path, 0)
    elif how == "zeroed":
        size = os.path.getsize(path)
        with open(path, "wb") as handle:
            handle.write(bytes(size))
    else:
        _silent_flip(path, how)


@pytest.mark.parametrize("how", ["truncated", "zero length", "zeroed", "theta_final_deg",
                                 "case_id", "x_final"])
def test_damaged_result_file_is_reported_then_recomputed(sweep, pristine, capsys, how):
    """read_results names the damaged file in one line; the sweep's command moves it to
    _quarantine/ with a one-line warning and recomputes exactly its cases."""
    name = storage.CHUNK_PATTERN.format(0, 1)
    _damage(os.path.join(sweep, name), how)
    with pytest.raises(ValueError) as error:
        loopsim.read_results(sweep)
    message = str(error.value)
    assert name in message and "damaged" in message and "\n" not in message, message
    argv = ["sweep", "--g0", "10,60", "--theta0", "30", "--n", "4", "--t-end", "0.2",
            "--chunk-size", "1", "--snapshots-for", "1", "--snapshots", "3", "--quiet",
            "--threads", "1", "--out", sweep]
    assert main(argv) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("loopsim: warning: ") and name in err[0], err
    assert [n.split(".parquet")[0] for n in os.listdir(os.path.join(sweep, "_quarantine"))] == [
        name.split(".parquet")[0]]
    _same_rows(loopsim.read_results(sweep), pristine[1])


def test_damaged_snapshot_file_recomputes_its_piece(sweep, pristine):
    snapshots = os.path.join(sweep, storage.SNAPSHOT_DIR, storage.CHUNK_PATTERN.format(1, 2))
    _silent_flip(snapshots, "x")
    with pytest.raises(ValueError, match="damaged"):
        loopsim.read_snapshots(sweep)
    with pytest.warns(UserWarning, match="snapshot file"):
        frame = sweeps.run_sweep(_config(), sweep, threads=1, quiet=True)
    _same_rows(frame, pristine[1])
    pd.testing.assert_frame_equal(loopsim.read_snapshots(sweep),
                                  loopsim.read_snapshots(pristine[0]))
    assert len(os.listdir(os.path.join(sweep, "_quarantine"))) == 2  # result and snapshots


def test_random_bit_flips_are_detected_or_harmless(sweep, pristine):
    """40 random single-bit flips of one result file: each is detected or changes no value
    that read_results returns (flips in unused statistics or padding)."""
    path = os.path.join(sweep, storage.CHUNK_PATTERN.format(1, 2))
    original = open(path, "rb").read()
    rng = np.random.default_rng(14)
    outcomes = []
    for bit in rng.choice(len(original) * 8, 40, replace=False):
        data = bytearray(original)
        data[bit // 8] ^= 1 << int(bit % 8)
        with open(path, "wb") as handle:
            handle.write(bytes(data))
        try:
            frame = loopsim.read_results(sweep)
        except ValueError:
            outcomes.append("detected")
            continue
        assert frame.equals(pristine[1]), f"bit {bit} changed values silently"
        outcomes.append("harmless")
    assert "detected" in outcomes


def test_every_footer_byte_flip_is_damage_or_harmless(sweep):
    """Every byte of one chunk's footer (column names, the nested list's names, field and
    file metadata, the Arrow schema) flipped in its top bit, the one that makes text
    undecodable, and every seventh byte in its low bit: each flip either leaves names,
    values and metadata as written or makes the file damaged, for both readers a sweep
    uses (the checked table and the footer's metadata); never another exception (a flip in
    the nested names of ``x_final`` raised a bare UnicodeDecodeError from
    ``ParquetFile.column_paths``), never a silent change."""
    path = os.path.join(sweep, storage.CHUNK_PATTERN.format(0, 1))
    original = open(path, "rb").read()
    expected, expected_meta = storage.read_table_checked(path), storage.read_metadata(path)
    footer = int.from_bytes(original[-8:-4], "little")
    outcomes = {"harmless": 0, "damaged": 0}
    flips = [(offset, 7) for offset in range(len(original) - 8 - footer, len(original) - 8)]
    flips += [(offset, 0) for offset, _ in flips[::7]]
    for offset, bit in flips:
        data = bytearray(original)
        data[offset] ^= 1 << bit
        with open(path, "wb") as handle:
            handle.write(bytes(data))
        try:
            table, meta = storage.read_table_checked(path, True), storage.read_metadata(path)
        except storage.DamagedFile as damaged:
            assert damaged.path == path and path in str(damaged), (offset, bit)
            outcomes["damaged"] += 1
            continue
        # the same names and values (a flip may turn string into large_string)
        assert table.column_names == expected.column_names, (offset, bit)
        assert table.to_pylist() == expected.to_pylist(), (offset, bit)
        assert meta == expected_meta, (offset, bit)
        outcomes["harmless"] += 1
    assert outcomes["damaged"] > 1000 and outcomes["harmless"] > 100, outcomes


def test_undecodable_nested_name_is_damage_named_and_quarantined(sweep, pristine, capsys):
    """The flip that escaped (a non-UTF-8 byte in ``x_final``'s nested list names): every
    reader names the file as damaged in one line, and the resume quarantines and
    recomputes it."""
    name = storage.CHUNK_PATTERN.format(0, 1)
    path = os.path.join(sweep, name)
    original = open(path, "rb").read()
    footer = original[len(original) - 8 - int.from_bytes(original[-8:-4], "little"):]
    offset = len(original) - len(footer) + footer.index(b"element")
    data = bytearray(original)
    data[offset] ^= 0x80
    with open(path, "wb") as handle:
        handle.write(bytes(data))
    pq.read_table(path)  # the Arrow reader alone does not notice
    for reader in (loopsim.read_results, lambda out: loopsim.summarize(loopsim.read_results(out))):
        with pytest.raises(ValueError) as error:
            reader(sweep)
        assert name in str(error.value) and "damaged" in str(error.value), error.value
    argv = ["sweep", "--g0", "10,60", "--theta0", "30", "--n", "4", "--t-end", "0.2",
            "--chunk-size", "1", "--snapshots-for", "1", "--snapshots", "3", "--quiet",
            "--threads", "1", "--out", sweep]
    assert main(argv) == 0
    assert name in capsys.readouterr().err
    assert len(os.listdir(os.path.join(sweep, storage.QUARANTINE_DIR))) == 1
    _same_rows(loopsim.read_results(sweep), pristine[1])


def test_file_without_its_checksum_is_damaged(sweep):
    """A result file rewritten without the content hash (or a flip that hid its key) is
    not trusted in a sweep that writes checksums."""
    path = os.path.join(sweep, storage.CHUNK_PATTERN.format(0, 1))
    table = pq.read_table(path)
    meta = {k: v for k, v in table.schema.metadata.items() if k != storage.CONTENT_KEY.encode()}
    pq.write_table(table.replace_schema_metadata(meta), path)
    with pytest.raises(ValueError, match="no content_sha256"):
        loopsim.read_results(sweep)


def test_page_checksums_are_written_and_verified(tmp_path):
    """Without the content hash, the Parquet page CRCs alone catch a flipped data byte."""
    path = str(tmp_path / "t.parquet")
    table = pa.table({"v": np.arange(256, dtype=np.float64)})
    storage.write_table_atomically(table, path)
    assert pq.ParquetFile(path).metadata.row_group(0).column(0).total_compressed_size > 0
    plain = str(tmp_path / "plain.parquet")
    pq.write_table(table, plain, write_page_checksum=True, compression="none")
    data = bytearray(open(plain, "rb").read())
    data[200] ^= 1  # inside the values of the only data page
    open(plain, "wb").write(bytes(data))
    assert not pq.read_table(plain).column("v").equals(table.column("v"))  # silent without
    with pytest.raises(storage.DamagedFile, match="unreadable"):
        storage.read_table_checked(plain)


def test_content_hash_ignores_layout_not_values():
    table = pa.table({"a": [1.0, 2.0, 3.0], "x": [[1.0], [2.0, 3.0], []]})
    chunked = pa.concat_tables([table.slice(0, 1), table.slice(1)])
    assert storage.content_hash(chunked, {}) == storage.content_hash(table, {})
    changed = table.set_column(0, "a", pa.array([1.0, 2.0, 3.0000000000000004]))
    assert storage.content_hash(changed, {}) != storage.content_hash(table, {})
    assert storage.content_hash(table, {"k": "v"}) != storage.content_hash(table, {"k": "w"})


def test_damaged_initial_results_are_refused(tmp_path, capsys):
    """A flipped bit in a run file's coefficients used to change the start shape silently."""
    run = str(tmp_path / "run.parquet")
    assert main(["run", "--g0", "60", "--theta0", "30", "--n", "4", "--t-end", "0.05",
                 "--out", run]) == 0
    capsys.readouterr()
    _silent_flip(run, "x")
    assert main(["run", "--n", "6", "--initial", run, "--t-end", "0.01"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "damaged" in err and run in err, err


def test_damaged_chunk_as_initial_is_refused(sweep, capsys):
    path = os.path.join(sweep, storage.CHUNK_PATTERN.format(1, 2))
    _silent_flip(path, "x_final")
    assert main(["run", "--n", "6", "--initial", path, "--t-end", "0.01"]) == 2
    assert "damaged" in capsys.readouterr().err
    assert main(["run", "--n", "6", "--initial", sweep, "--case-id", "0", "--t-end", "0.01"]) == 2
    assert "damaged" in capsys.readouterr().err


def test_damaged_run_file_is_refused_by_animate_and_figures(sweep, tmp_path, capsys):
    """Issue 46.1: a flipped bit in a run file's coefficients used to be drawn with exit 0;
    ``animate`` and ``figures`` read run files checked, as sweep chunks are read."""
    run = str(tmp_path / "run.parquet")
    assert main(["run", "--g0", "60", "--theta0", "30", "--n", "4", "--t-end", "0.05",
                 "--snapshots", "5", "--no-twin", "--out", run]) == 0
    capsys.readouterr()
    _silent_flip(run, "x")
    gif, figs = tmp_path / "a.gif", tmp_path / "figs"
    for argv in (["animate", run, "--out", str(gif)],
                 ["figures", sweep, run, "--out", str(figs), "--only", "evolution"]):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert len(err.splitlines()) == 1 and "damaged" in err and run in err, err
    assert not gif.exists() and not figs.exists()


def test_damaged_parquet_cases_file_is_refused(tmp_path, capsys):
    """Issue 46.1: a cases file loopsim wrote (with checksums) is read checked too."""
    path = str(tmp_path / "cases.parquet")
    storage.write_table_atomically(pa.table({"g0": np.linspace(10.0, 60.0, 50),
                                        "theta0_deg": np.full(50, 30.0)}), path)
    _silent_flip(path, "g0")
    assert main(["sweep", "--n", "4", "--cases", path, "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "damaged" in err and path in err, err
    assert not (tmp_path / "s").exists()


# ---- sizes and inputs bounded before any work --------------------------------------------
def _point_file(path, rows):
    s = np.linspace(0.0, 2 * np.pi, rows, endpoint=False)
    pd.DataFrame(dict(x=np.cos(s), y=np.sin(s), z=0.1 * np.sin(2 * s))).to_csv(path, index=False)
    return str(path)


@pytest.mark.parametrize("argv, words", [
    (["run", "--g0", "60", "--theta0", "30", "--n", "500"], ["--n", "at most 128", "500"]),
    (["run", "--g0", "60", "--theta0", "30", "--n", "auto", "--n-max", "100000"],
     ["--n-max", "100000"]),
    (["run", "--n", "6", "--g0", "60", "--theta0", "30", "--snapshots", "10000000"],
     ["--snapshots", "10000000"]),
    (["run", "--n", "6", "--g0", "60", "--theta0", "30", "--out", ""], ["--out is empty"]),
    (["run", "--n", "6", "--g0", "60", "--initial", "/dev/zero"], ["/dev/zero", "not a regular file"]),
    (["sweep", "--n", "6", "--g0", "1:2:1000000000", "--theta0", "30", "--out", "{tmp}/s"],
     ["--g0", "1000000000"]),
    (["sweep", "--n", "6", "--g0", "1:2:1000", "--theta0", "1:80:1001", "--out", "{tmp}/s"],
     ["1001000 cases"]),
    (["sweep", "--g0", "10", "--theta0", "30", "--n", "200", "--out", "{tmp}/s"],
     ["n must be at most 128"]),
    (["sweep", "--n", "6", "--g0", "10", "--theta0", "30", "--snapshots-for", "0", "--snapshots",
      "100000", "--out", "{tmp}/s"], ["100000"]),
    (["sweep", "--n", "6", "--cases", "/dev/zero", "--out", "{tmp}/s"], ["not a regular file"]),
    (["sweep", "--n", "6", "--g0", "10", "--theta0", "30", "--out", ""], ["--out is empty"]),
    (["stability", "--paper", "--n-max", "100000"], ["--n-max", "100000"]),
    (["stability", "--n", "100000"], ["--n", "100000"]),
    (["branch", "--n", "129"], ["--n", "at most 48", "129"]),
    (["sweep", "--n", "6", "--g0", "10", "--theta0", "30", "--dask", "--workers", "1000", "--out",
      "{tmp}/s"], ["--workers", "1000"]),
    (["sweep", "--n", "6", "--g0", "10", "--theta0", "30", "--scheduler", "notanaddress", "--out",
      "{tmp}/s"], ["--scheduler", "notanaddress"]),
    (["sweep", "--n", "6", "--g0", "10", "--theta0", "30", "--scheduler", "", "--out", "{tmp}/s"],
     ["--scheduler", "''"]),
    (["figures", "{tmp}/s", "--out", "{tmp}/figs", "--branch-n", "500"], ["branch_n", "500"]),
    (["figures", "{tmp}/s", "--out", "{tmp}/figs", "--branch-n", "2"], ["branch_n", "2"]),
    (["figures", "{tmp}/s", "--out", "{tmp}/figs", "--dpi", "1000000"], ["dpi", "1000000"]),
    (["figures", "{tmp}/s", "--out", "{tmp}/figs", "--only", "bogus"], ["bogus"]),
    (["figures", "{tmp}/s", "--out", "{tmp}/figs", "--gallery-theta0", "200"],
     ["gallery_theta0", "200"]),
    (["run", "--n", "6", "--g0", "60", "--theta0", "30", "--n-max", "40"], ["--n-max applies only"]),
    (["run", "--n", "6", "--g0", "60", "--theta0", "30", "--tail-tol", "1e-4"], ["--tail-tol applies"]),
    (["sweep", "--n", "6", "--g0", "10", "--theta0", "30", "--tail-tol", "1e-4", "--out", "{tmp}/s"],
     ["--tail-tol applies only"]),
    (["sweep", "--g0", "10", "--theta0", "30", "--n", "auto", "--n-max", "4", "--out",
      "{tmp}/s"], ["--n-max 4 is below", "6"]),
])
def test_sizes_refused_in_one_line_before_work(tmp_path, capsys, argv, words):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and all(w in err for w in words), err
    assert not (tmp_path / "s").exists() and not (tmp_path / "figs").exists()


@pytest.mark.parametrize("header, rows, words", [
    ("g0,theta0_deg,method", ["10,30,3"], ["column method", "3"]),
    ("g0,theta0_deg,colour", ["10,30,red"], ["unknown column 'colour'"]),
    ("g0,theta0_deg,g0", ["10,30,20"], ["column 'g0' twice"]),
])
def test_cases_file_columns_checked(tmp_path, capsys, header, rows, words):
    path = tmp_path / "cases.csv"
    path.write_text(header + "\n" + "\n".join(rows) + "\n")
    assert main(["sweep", "--n", "6", "--cases", str(path), "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and all(w in err for w in words), err
    assert not (tmp_path / "s").exists()


@pytest.mark.parametrize("lines, words", [
    (["g0,theta0_deg,seed", "10,30,0", "60,30,0", "10,30.0,0"],
     ["one case twice", "rows 0 and 2", "g0=10, theta0_deg=30"]),
    (["g0,theta0_deg,method", "10,30,rkf45", "10,30,"],  # rkf45: the sweep's method here
     ["cases 0 and 1 are one case twice", "method=rkf45"]),
    (None, ["cases 0 and 2 are one case twice", "--g0"]),
])
def test_a_case_given_twice_is_refused_before_anything_is_written(tmp_path, capsys, lines,
                                                                   words):
    """Issue 46.5: a cases file (or a grid) holding one case twice used to run it twice,
    and ``summary`` and ``report`` then refused the directory."""
    if lines is None:
        given = ["--g0", "10,60,10", "--theta0", "30"]
    else:
        (tmp_path / "cases.csv").write_text("\n".join(lines) + "\n")
        given = ["--cases", str(tmp_path / "cases.csv")]
    out = tmp_path / "s"
    assert main(["sweep", "--n", "6", *given, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and err.startswith("loopsim: error: "), err
    assert all(w in err for w in words), err
    assert not out.exists()


def test_refused_rerun_options_leave_the_directory_usable(sweep, capsys):
    """An invalid --rtol or --atol of --rerun-failed is refused before anything is
    recorded in _sweep.json, so a later valid rerun is not blocked by it."""
    before = open(os.path.join(sweep, storage.SWEEP_FILE)).read()
    for bad in (["--rtol", "0"], ["--atol", "-1"]):
        assert main(["sweep", "--rerun-failed", sweep, "--quiet"] + bad) == 2
        assert open(os.path.join(sweep, storage.SWEEP_FILE)).read() == before
    assert main(["sweep", "--rerun-failed", sweep, "--method", "radau5", "--quiet"]) == 0


@pytest.mark.parametrize("option", [["--model", "nonlocal"], ["--slenderness", "0"],
                                    ["--slenderness", "1e-3"], ["--p-halfwidth", "0.1"]])
def test_rerun_refuses_every_option_it_would_ignore(sweep, capsys, option):
    """Issue 36.6: --model and --slenderness (any value, 0 included) are refused like every
    other option that is not --method, --rtol or --atol, and nothing is recorded."""
    before = open(os.path.join(sweep, storage.SWEEP_FILE)).read()
    assert main(["sweep", "--rerun-failed", sweep, "--method", "radau5", *option]) == 2
    err = capsys.readouterr().err
    assert f"{option[0]} does not apply with --rerun-failed" in err, err
    assert open(os.path.join(sweep, storage.SWEEP_FILE)).read() == before


def test_cases_file_slenderness_of_a_local_row_is_refused(tmp_path, capsys):
    """Issue 36.10: a row of model local with a slenderness is refused in one line, as the
    command line refuses the pair, instead of dropping the slenderness."""
    path = tmp_path / "cases.csv"
    path.write_text("g0,theta0_deg,model,slenderness\n10,30,nonlocal,1e-3\n"
                    "10,30,local,1e-3\n")
    assert main(["sweep", "--n", "6", "--cases", str(path), "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "case 1" in err and "'local'" in err, err
    assert not (tmp_path / "s").exists()


def test_point_files_bounded_by_size_rows_and_kind(tmp_path, capsys):
    fifo = str(tmp_path / "fifo")
    os.mkfifo(fifo)  # opening it would block: refused from its kind
    big = str(tmp_path / "big.csv")
    with open(big, "wb") as handle:  # a sparse file: no disk used
        handle.truncate(validation.MAX_POINT_FILE_BYTES + 1)
    rows = _point_file(tmp_path / "rows.csv", validation.MAX_POINTS + 1)
    for path, word in ((fifo, "not a regular file"), (big, "MiB"),
                       (rows, f"more than {validation.MAX_POINTS} points")):
        assert main(["run", "--n", "6", "--g0", "60", "--initial", path]) == 2
        err = capsys.readouterr().err
        assert len(err.splitlines()) == 1 and word in err and path in err, err


def test_cases_file_rows_bounded(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(validation, "MAX_CASES", 3)
    path = tmp_path / "cases.csv"
    path.write_text("g0,theta0_deg\n" + "10,30\n" * 4)
    assert main(["sweep", "--n", "6", "--cases", str(path), "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert "more than 3 rows" in err and not (tmp_path / "s").exists()


# ---- loopsim run: signals and temporaries -------------------------------------------------
def _handler_installed(pid, signum):
    """Whether process ``pid`` catches ``signum`` (Linux: SigCgt in /proc/PID/status)."""
    with open(f"/proc/{pid}/status") as handle:
        for line in handle:
            if line.startswith("SigCgt:"):
                return bool(int(line.split()[1], 16) >> (signum - 1) & 1)
    return False


def _integrating(pid):
    """Whether process ``pid`` runs its integration thread (named
    ``signals.NATIVE_THREAD_NAME`` in /proc/PID/task/TID/comm): then the command's own
    signal handling is in place, however long loading and compiling took."""
    from loopsim.sweeps.signals import NATIVE_THREAD_NAME

    for task in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{task}/comm") as handle:
                if handle.read().strip() == NATIVE_THREAD_NAME:
                    return True
        except OSError:
            pass
    return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("signum, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_run_stops_on_a_signal_in_one_line(tmp_path, signum, status):
    """A long 3D run (over 30 s): the signal lands during the integration, 1 s after its
    thread has started (:func:`_integrating`, whatever the machine's load); exit 130 / 143
    within seconds, one line, no traceback, nothing written."""
    out = tmp_path / "run.parquet"
    process = subprocess.Popen(
        [sys.executable, "-m", "loopsim", "run", "--g0", "300", "--theta0", "80", "--n", "8",
         "--t-end", "40", "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True)
    deadline = time.monotonic() + 120
    while not _integrating(process.pid):
        assert process.poll() is None and time.monotonic() < deadline, process.communicate()
        time.sleep(0.05)
    time.sleep(1.0)
    sent = time.monotonic()
    process.send_signal(signum)
    stdout, stderr = process.communicate(timeout=60)
    assert time.monotonic() - sent < 5.0
    assert process.returncode == status, stderr
    assert stderr.splitlines() == [
        f"loopsim: interrupted by {signal.Signals(signum).name}: the run was stopped; "
        "nothing written"], stderr
    assert stdout == "" and os.listdir(tmp_path) == []


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("command", [["run", "--n", "6", "--g0", "60", "--theta0", "30"],
                                     ["sweep", "--n", "6", "--g0", "10,60", "--theta0", "30"]])
@pytest.mark.parametrize("delay", [0.0, 0.3, 0.8])
def test_a_signal_while_loading_is_one_line_and_exit_130(tmp_path, command, delay):
    """Ctrl-C in the first second (NumPy, Numba and pandas still loading): one line, exit
    130, no traceback; the program's handler is in place from the package's first line."""
    argv = command + (["--out", str(tmp_path / "s")] if command[0] == "sweep" else [])
    process = subprocess.Popen([sys.executable, "-m", "loopsim"] + argv,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not _handler_installed(process.pid, signal.SIGTERM):  # Python catches SIGINT anyway
        assert process.poll() is None and time.monotonic() < deadline, process.communicate()
        time.sleep(0.01)
    time.sleep(delay)
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr
    assert len(stderr.splitlines()) == 1 and "Traceback" not in stderr, stderr
    assert stderr.startswith("loopsim: interrupted by SIGINT"), stderr


def test_run_out_removes_temporaries_of_killed_runs_only(tmp_path, capsys):
    host = socket.gethostname()
    child = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True, check=True)
    dead = tmp_path / f".tmp-{host}-{int(child.stdout)}-abc.parquet"  # a run killed mid-write
    live = tmp_path / f".tmp-{host}-{os.getpid()}-abc.parquet"  # a process still writing
    dead.write_bytes(b"partial")
    live.write_bytes(b"partial")
    out = tmp_path / "run.parquet"
    assert main(["run", "--g0", "60", "--theta0", "30", "--n", "4", "--t-end", "0.05",
                 "--out", str(out)]) == 0
    assert out.exists() and live.exists() and not dead.exists()
    storage.read_table_checked(str(out), require_hash=True)


def _dead_pid():
    """The id of a process that has ended."""
    child = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True, check=True)
    return int(child.stdout)


def _run_file(path, snapshots):
    assert main(["run", "--g0", "60", "--theta0", "30", "--n", "4", "--t-end", "1",
                 "--snapshots", str(snapshots), "--no-twin", "--out", str(path)]) == 0
    return str(path)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="signals, one host")
@pytest.mark.parametrize("signum, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_during_animate_leaves_no_temporary(tmp_path, capsys, signum, status):
    """Issue 46.6: a signal while ``animate`` writes (its early handler ends the process at
    once) used to leave a 0-byte ``.tmp-*`` file: now one line, exit 130 / 143, nothing."""
    run = _run_file(tmp_path / "run.parquet", 60)
    capsys.readouterr()
    out = tmp_path / "anim"
    out.mkdir()
    process = subprocess.Popen([sys.executable, "-m", "loopsim", "animate", run, "--out",
                                str(out / "a.gif"), "--frames", "60"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not list(out.glob(".tmp-*")):  # the write has begun: frames being drawn
        assert process.poll() is None and time.monotonic() < deadline, process.communicate()
        time.sleep(0.01)
    process.send_signal(signum)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == status, stderr
    assert len(stderr.splitlines()) == 1 and "Traceback" not in stderr, stderr
    assert listing_of(out) == []


def test_the_next_write_removes_temporaries_of_dead_writers(tmp_path, capsys):
    """Issue 46.6: a temporary left by a killed ``animate`` (SIGKILL: nothing can remove it
    then) goes with the next write into its directory; a live process's stays."""
    run = _run_file(tmp_path / "run.parquet", 5)
    out = tmp_path / "anim"
    out.mkdir()
    host = socket.gethostname()
    dead = out / f".tmp-{host}-{_dead_pid()}-abc.gif"
    live = out / f".tmp-{host}-{os.getpid()}-abc.gif"
    dead.write_bytes(b"")
    live.write_bytes(b"")
    assert main(["animate", run, "--out", str(out / "a.gif"), "--dpi", "40"]) == 0
    assert listing_of(out) == sorted(["a.gif", live.name])


def test_edited_sweep_file_is_damaged(sweep):
    """A flipped value in _sweep.json's configuration no longer matches its checksum, nor,
    in a record of a release before whole-record checksums, its fingerprint."""
    path = os.path.join(sweep, storage.SWEEP_FILE)
    text = open(path).read()
    assert '"t_end": 0.2' in text
    open(path, "w").write(text.replace('"t_end": 0.2', '"t_end": 0.3'))
    with pytest.raises(ValueError, match="_sweep.json' is damaged .content does not match its "
                                         "checksum"):
        loopsim.read_results(sweep)
    older = json.loads(open(path).read())
    del older[storage.CONTENT_KEY]
    storage.write_json_atomically(older, path)
    with pytest.raises(ValueError, match="_sweep.json' is damaged.*fingerprint"):
        loopsim.read_results(sweep)


def test_lost_sidecar_and_damaged_file_repaired_together(sweep, pristine):
    """_sweep.json lost and a result file truncated: the same sweep restores the one and
    recomputes the other; a stray copy is ignored with a warning, never merged."""
    os.remove(os.path.join(sweep, storage.SWEEP_FILE))
    os.truncate(os.path.join(sweep, storage.CHUNK_PATTERN.format(1, 2)), 100)
    shutil.copy(os.path.join(sweep, storage.CHUNK_PATTERN.format(0, 1)),
                os.path.join(sweep, "chunk-0000000-0000001 (copy).parquet"))
    with pytest.warns(UserWarning) as caught:
        frame = sweeps.run_sweep(_config(), sweep, threads=1, quiet=True)
    messages = [str(w.message) for w in caught]
    assert any("damaged" in m for m in messages) and any("stray copy" in m for m in messages)
    _same_rows(frame, pristine[1])
    assert storage.read_sweep_file(sweep)["checksums"] == storage.CONTENT_KEY


def test_disk_full_is_an_environment_error_and_the_sweep_resumes(tmp_path, capsys, monkeypatch):
    """Writing a result file fails with ENOSPC: one line, exit 3 (not 2, bad input), no
    temporary left; once space is back the same command resumes to the full table."""
    import errno

    import pyarrow.parquet as parquet

    from loopsim.cli import EXIT_ENVIRONMENT, main

    out = tmp_path / "full"
    argv = ["sweep", "--g0", "30,60", "--theta0", "30", "--n", "4", "--t-end", "0.2",
            "--quiet", "--out", str(out)]
    real_write = parquet.write_table

    def no_space(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(parquet, "write_table", no_space)
    assert main(argv) == EXIT_ENVIRONMENT == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "No space left on device" in err[0]
    assert not list(out.glob(".tmp-*"))
    monkeypatch.setattr(parquet, "write_table", real_write)
    assert main(argv) == 0
    assert len(loopsim.read_results(str(out))) == 2


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_FSIZE, /proc")
def test_file_size_limit_is_an_environment_error(sweep, tmp_path):
    """Issue 46.7: a write past the file-size limit (``ulimit -f``; EFBIG) is the machine's
    fault like a full disk: one line, exit 3 (not 2, bad input), no file or temporary."""
    import resource

    def limited():
        resource.setrlimit(resource.RLIMIT_FSIZE, (2048, resource.getrlimit(
            resource.RLIMIT_FSIZE)[1]))

    table = tmp_path / "out" / "cells.parquet"
    table.parent.mkdir()
    done = subprocess.run([sys.executable, "-m", "loopsim", "summary", sweep, "--out",
                           str(table)], capture_output=True, text=True, preexec_fn=limited,
                          timeout=300)
    assert done.returncode == 3, done.stderr
    err = done.stderr.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("loopsim: error:") and "too large" in err[0], err
    assert listing_of(table.parent) == []


@pytest.mark.parametrize("command", ["summary", "figures"])
def test_disk_full_leaves_no_empty_figure(sweep, tmp_path, capsys, monkeypatch, command):
    """Issue 36.11: a figure that cannot be written (ENOSPC) exits 3 and leaves no PNG, not
    a 0-byte one, and no temporary."""
    import errno

    from matplotlib.figure import Figure

    def no_space(self, fname, *args, **kwargs):
        with open(fname, "wb"):  # what a full disk leaves: the file made, nothing in it
            pass
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(Figure, "savefig", no_space)
    figures = tmp_path / "figs"
    argv = (["summary", sweep, "--figure", str(figures / "cells.png")] if command == "summary"
            else ["figures", sweep, "--out", str(figures), "--only", "phase"])
    if command == "summary":
        figures.mkdir()
    assert main(argv) == 3
    assert "No space left on device" in capsys.readouterr().err
    assert listing_of(figures) == []


def listing_of(path):
    return sorted(os.listdir(path)) if os.path.isdir(path) else []


def test_output_that_takes_no_files_is_refused_before_work(tmp_path, capsys, monkeypatch):
    """--out under /proc is an input error (exit 2) found before integrating; a
    read-only filesystem is the machine's (exit 3); one line each, nothing left."""
    from loopsim import api

    def no_work(*args, **kwargs):
        raise AssertionError("integration started before the output path was checked")

    monkeypatch.setattr(api, "simulate", no_work)
    if os.path.isdir("/proc"):
        assert main(["run", "--n", "6", "--g0", "60", "--theta0", "30", "--out", "/proc/x.parquet"]) == 2
        err = capsys.readouterr().err
        assert len(err.splitlines()) == 1 and "/proc" in err and "takes no files" in err, err

    import errno
    import tempfile

    def read_only(*args, **kwargs):
        raise OSError(errno.EROFS, "Read-only file system")

    monkeypatch.setattr(tempfile, "mkstemp", read_only)
    for argv in (["run", "--n", "6", "--g0", "60", "--theta0", "30", "--out", str(tmp_path / "r.parquet")],
                 ["sweep", "--n", "6", "--g0", "60", "--theta0", "30", "--out", str(tmp_path / "s")]):
        assert main(argv) == 3
        err = capsys.readouterr().err
        assert len(err.splitlines()) == 1 and "Read-only file system" in err, err
    assert os.listdir(tmp_path) == []


def test_perturbation_larger_than_the_loop_is_refused(tmp_path, capsys):
    from loopsim.cli import main

    assert main(["run", "--n", "6", "--g0", "60", "--theta0", "30", "--perturbation", "2"]) == 2
    err = capsys.readouterr().err
    assert "perturbation must be at most 0.5" in err and len(err.strip().splitlines()) == 1
    out = tmp_path / "s"
    assert main(["sweep", "--n", "6", "--g0", "60", "--theta0", "30", "--perturbation", "0.9",
                 "--out", str(out)]) == 2
    assert "perturbation" in capsys.readouterr().err
    with pytest.raises(ValueError, match="perturbation"):
        loopsim.simulate(60.0, 30.0, n=6, perturbation=1.0)


@pytest.mark.slow
def test_soak_200_random_kills_lose_and_duplicate_nothing(tmp_path):
    """SIGKILL a sweep at 200 random moments (seeded), resuming after each kill: the final
    table equals the uninterrupted one, with no case lost or duplicated and no temporary
    left.  Slow (process start-up per kill): ``pytest -m slow``."""
    from loopsim.cli import main

    args = ["sweep", "--g0", "20:200:6", "--theta0", "20,50,80", "--n", "4", "--t-end", "1.5",
            "--chunk-size", "1", "--threads", "1", "--quiet"]
    reference = tmp_path / "reference"
    assert main(args + ["--out", str(reference)]) == 0
    killed = tmp_path / "killed"
    command = [sys.executable, "-m", "loopsim"] + args + ["--out", str(killed)]
    rng = np.random.default_rng(14)
    for _ in range(200):
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        time.sleep(rng.uniform(0.0, 4.0))
        process.kill()
        process.wait()
        done = loopsim.read_results(str(killed)) if (killed / "_sweep.json").exists() else None
        if done is not None:
            assert done["case_id"].is_unique
    assert main(args + ["--out", str(killed)]) == 0
    resumed = loopsim.read_results(str(killed))
    expected = loopsim.read_results(str(reference))
    assert list(resumed["case_id"]) == list(range(18))
    columns = [c for c in expected.columns if c != "wall_s"]
    pd.testing.assert_frame_equal(resumed[columns], expected[columns], check_exact=True)
    assert not list(killed.glob(".tmp-*"))


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_ctrl_c_with_dask_is_one_line_and_leaves_no_process(tmp_path):
    """SIGINT while a local Dask cluster works: exit 130, no traceback (no
    CommClosedError from the shutdown), and none of the program's processes alive 1 s
    after it ended."""
    import psutil

    out = tmp_path / "s"
    process = subprocess.Popen(
        [sys.executable, "-m", "loopsim", "sweep", "--n", "6", "--g0", "100:250:8", "--theta0", "30,60",
         "--chunk-size", "1", "--dask", "--workers", "2", "--out", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300  # the workers may compile first
    parent = psutil.Process(process.pid)
    while not list(out.glob("chunk-*.parquet")):  # the workers are at work
        assert process.poll() is None and time.monotonic() < deadline, process.communicate()
        time.sleep(0.1)
    children = parent.children(recursive=True)
    assert len(children) >= 2
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr
    lines = [line for line in stderr.splitlines()  # less the notice and progress lines
             if not line.startswith(("loopsim: compiling", "cases "))]
    assert "Traceback" not in stderr and "Error" not in stderr, stderr
    assert len(lines) == 1 and lines[0].startswith("loopsim: interrupted by SIGINT"), stderr
    time.sleep(1.0)
    alive = [c.pid for c in children if c.is_running() and c.status() != psutil.STATUS_ZOMBIE]
    assert alive == [], alive


def _as_if_older_release(path, dropped):
    """Rewrite the result file ``path`` without the columns ``dropped``, as a release
    before they existed wrote it (its metadata and a fresh content hash kept)."""
    table = pq.read_table(path)
    storage.write_table_atomically(
        table.drop_columns([name for name in dropped if name in table.schema.names]), path)


def test_a_resume_across_releases_says_which_columns_older_rows_lack(tmp_path, capsys):
    """Issue 54.1: rows without terminal_state (an older release) counted as not moving
    (0 where the sweep run whole today reports its count), and the resume that mixed
    them with rows that record it said nothing."""
    from loopsim import outcome_statistics

    sweep = str(tmp_path / "s")
    command = ["sweep", "--g0", "10,60", "--theta0", "30", "--n", "4", "--t-end", "0.2",
               "--chunk-size", "1", "--no-twin", "--threads", "1", "--quiet", "--out", sweep]
    assert main(command) == 0
    first, second = sorted(storage.chunk_files(sweep).values())
    _as_if_older_release(first, storage.MOTION_FIELDS + ("early_stop",))
    os.remove(second)
    capsys.readouterr()
    assert main(command) == 0  # the resume: case 1 again, on this release
    out, err = capsys.readouterr()
    lines = [line for line in err.splitlines() if "terminal_state" in line]
    assert len(lines) == 1 and "1 of the 2 rows lack column(s) terminal_state" in lines[0], err
    assert "still moving at their end (column 'terminal_state'): not recorded (unknown) " \
           "for 1 of 2 cases" in out
    frame = loopsim.read_results(sweep)
    assert frame["terminal_state"].isna().tolist() == [True, False]
    counts = outcome_statistics.outcome_counts(frame)
    assert counts["unsteady"] is None and counts["unsteady_not_recorded"] == 1
    assert frame.get("early_stop", pd.Series()).tolist() == [True, True]  # the sweep's
    assert main(command) == 0  # nothing to resume: the table still mixes, and says so
    assert "1 of the 2 rows lack column(s) terminal_state" in capsys.readouterr().err
