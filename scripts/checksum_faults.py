"""Single-bit flips of the files loopsim writes, and the cost of checksums (issues 14, 54).

    python scripts/checksum_faults.py [--flips 6000] [--every-file 150] [--advice 20]
                                      [--seed 1] [--parts result-file,every-file,advice,costs]

``result-file``: runs the 6-case sweep of the tests (g0 10, 60, 150 x theta0 30, 60, n = 4,
t = 0.3, chunk size 2) in a temporary directory, flips ``--flips`` random bits of its
second result file one at a time and counts, for plain ``pyarrow.parquet.read_table``
(values only) and for ``loopsim.read_results``: flips that raise (detected), that return
the same rows (harmless: statistics, padding), and that return other values without an
error (silent).

``every-file``: every file loopsim writes and reads back, ``--every-file`` random bits
each, one at a time: a sweep directory's ``_sweep.json``, result and snapshot files, a
``--seeds auto`` directory's ``_seeds_auto.json``, stop table and round files, and a run
file (``run --out``, read back by ``--initial``).  Each flip goes through the file's
readers (``read_results``, ``read_snapshots``, ``read_stop_table``, ``load_initial``)
and is counted refused (a one-line ValueError), harmless (the same result), silent
(another result, no error) or crash (any other exception).  Exits 1 if any is silent or
a crash.

``advice``: ``--advice`` flips of each JSON record (``_sweep.json``, ``_seeds_auto.json``,
a round's ``_sweep.json``), each through the sweep's own command: it must resume to the
same rows, or refuse in one line whose advice, followed (the record moved away, the
command run again), resumes to the same rows; anything else counts as wedged (exit 1).

``costs``: times writing and reading a 32-row result file and a run file with and
without page checksums and the content hash (best of 30).
"""
import argparse
import contextlib
import io
import os
import random
import shutil
import sys
import tempfile
import time
import warnings

import pyarrow as pa
import pyarrow.parquet as pq

import loopsim
from loopsim import api, storage, sweeps


def flips(out, count, seed):
    work = out + "-flipped"
    shutil.copytree(out, work)
    name = storage.CHUNK_PATTERN.format(2, 4)
    path = os.path.join(work, name)
    original = open(path, "rb").read()
    reference = loopsim.read_results(out)
    plain_reference = pq.read_table(path).replace_schema_metadata(None)
    chosen = random.Random(seed).sample(range(len(original) * 8), count)
    plain = dict(error=0, harmless=0, silent=0)
    checked = dict(detected=0, harmless=0, silent=0)
    for bit in chosen:
        data = bytearray(original)
        data[bit // 8] ^= 1 << (bit % 8)
        with open(path, "wb") as handle:
            handle.write(bytes(data))
        try:
            same = pq.read_table(path).replace_schema_metadata(None).equals(plain_reference)
            plain["harmless" if same else "silent"] += 1
        except Exception:  # noqa: BLE001
            plain["error"] += 1
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                frame = loopsim.read_results(work)
            checked["harmless" if frame.equals(reference) else "silent"] += 1
        except ValueError:
            checked["detected"] += 1
    print(f"{name}: {len(original)} bytes; {count} of {len(original) * 8} bits flipped one at "
          "a time")
    print(f"  plain pq.read_table: {plain}")
    print(f"  loopsim.read_results: {checked}")


def best_ms(function, repeats=30):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return 1e3 * min(times)


def costs(out, tmp):
    chunk = pq.read_table(os.path.join(out, storage.CHUNK_PATTERN.format(0, 2)))
    result = api.simulate(60.0, 30.0, n=16, t_span=(0.0, 1.0), snapshots=1000)
    tables = {"32-row result file": pa.concat_tables([chunk] * 16),
              "run file, 1000 snapshots, n = 16": storage.trajectory_table(result)}
    for label, table in tables.items():
        meta = {k: v for k, v in (table.schema.metadata or {}).items()
                if k != storage.CONTENT_KEY.encode()}
        table = table.replace_schema_metadata(meta)
        paths = {k: os.path.join(tmp, f"{k}.parquet") for k in ("plain", "crc", "full")}
        write = [best_ms(lambda: pq.write_table(table, paths["plain"])),
                 best_ms(lambda: pq.write_table(table, paths["crc"], write_page_checksum=True)),
                 best_ms(lambda: storage.write_table_atomically(table, paths["full"])),
                 best_ms(lambda: storage.content_hash(table, {}))]
        read = [best_ms(lambda: pq.read_table(paths["plain"])),
                best_ms(lambda: pq.read_table(paths["crc"], page_checksum_verification=True)),
                best_ms(lambda: storage.read_table_checked(paths["full"]))]
        sizes = [os.path.getsize(p) for p in paths.values()]
        print(f"{label}: {sizes[0]} bytes plain, {sizes[1]} with page CRCs, {sizes[2]} with "
              "CRCs and hash")
        print(f"  write ms: plain {write[0]:.2f}, CRC {write[1]:.2f}, CRC + hash + temporary "
              f"+ rename {write[2]:.2f} (hash alone {write[3]:.2f})")
        print(f"  read ms: plain {read[0]:.2f}, CRC checked {read[1]:.2f}, CRC and hash "
              f"checked {read[2]:.2f}")


# ---- every file: flips through each file's readers --------------------------------------
def _outcome(read, reference):
    """refused / harmless / silent / crash: what ``read()`` did with a damaged file."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            value = read()
    except ValueError as exc:  # DamagedFile is one
        return "refused" if "\n" not in str(exc) else "crash"
    except Exception:  # noqa: BLE001 - anything else is a crash: a traceback for the user
        return "crash"
    return "harmless" if _same(value, reference) else "silent"


def _same(value, reference):
    if isinstance(value, tuple):
        return all(_same(v, r) for v, r in zip(value, reference))
    if hasattr(value, "equals"):
        return value.equals(reference)
    return bool((value == reference).all()) if hasattr(value, "all") else value == reference


_GRID = ["sweep", "--g0", "10,60", "--theta0", "30", "--n", "6", "--t-end", "0.05", "--no-twin",
         "--threads", "1", "--quiet"]
#: The commands that write the directories of the every-file part (``--out`` appended).
SWEEP_COMMAND = _GRID + ["--chunk-size", "1", "--snapshots-for", "0", "--snapshots", "3"]
AUTO_COMMAND = _GRID + ["--seeds", "auto", "--min-seeds", "2", "--max-seeds", "2"]


def _written_files(tmp):
    """{label: (path, readers)}: every file loopsim writes and reads back, in small
    directories made here; readers: {name: function of no arguments}."""
    from loopsim import shapes
    from loopsim.cli import main as loopsim_main

    sweep, auto, run = (os.path.join(tmp, name) for name in ("sweep", "auto", "run.parquet"))
    with contextlib.redirect_stdout(io.StringIO()):  # their summaries: not wanted here
        assert loopsim_main(SWEEP_COMMAND + ["--out", sweep]) == 0
        assert loopsim_main(AUTO_COMMAND + ["--out", auto]) == 0
        assert loopsim_main(["run", "--g0", "10", "--theta0", "30", "--n", "6", "--t-end",
                             "0.05", "--out", run]) == 0
    results = dict(read_results=lambda: loopsim.read_results(sweep))
    snapshots = dict(read_snapshots=lambda: loopsim.read_snapshots(sweep))
    rounds = dict(read_results=lambda: loopsim.read_results(auto))
    round_zero = storage.round_directory(auto, 0)
    files = {"sweep _sweep.json": (os.path.join(sweep, storage.SWEEP_FILE), results)}
    for path in sorted(storage.chunk_files(sweep).values()):
        files[f"sweep {os.path.basename(path)}"] = (path, results)
    for path in sorted(storage.chunk_files(sweep, "snapshots").values()):
        files[f"sweep _snapshots/{os.path.basename(path)}"] = (path, snapshots)
    files["auto _seeds_auto.json"] = (os.path.join(auto, storage.SEEDS_FILE), rounds)
    files["auto seeds_auto.parquet"] = (os.path.join(auto, storage.STOPS_FILE), dict(
        read_stop_table=lambda: storage.read_stop_table(auto)))
    files["auto round-00/_sweep.json"] = (os.path.join(round_zero, storage.SWEEP_FILE), rounds)
    for path in sorted(storage.chunk_files(round_zero).values()):
        files[f"auto round-00/{os.path.basename(path)}"] = (path, rounds)
    files["run file"] = (run, dict(load_initial=lambda: shapes.load_initial(run, 6)[0]))
    return files


def every_file(tmp, count, seed):
    """Flip ``count`` random bits of each file of :func:`_written_files`, one at a time;
    print a line per file and reader and the totals; return the totals."""
    rng = random.Random(seed)
    totals = dict(refused=0, harmless=0, silent=0, crash=0)
    for label, (path, readers) in _written_files(tmp).items():
        original = open(path, "rb").read()
        references = {name: read() for name, read in readers.items()}
        counts = {name: dict(refused=0, harmless=0, silent=0, crash=0) for name in readers}
        for bit in rng.sample(range(len(original) * 8), min(count, len(original) * 8)):
            data = bytearray(original)
            data[bit // 8] ^= 1 << (bit % 8)
            with open(path, "wb") as handle:
                handle.write(bytes(data))
            for name, read in readers.items():
                counts[name][_outcome(read, references[name])] += 1
        with open(path, "wb") as handle:
            handle.write(original)
        for name, found in counts.items():
            print(f"{label} ({len(original)} bytes), {name}: " + ", ".join(
                f"{k} {v}" for k, v in found.items()))
            for key in totals:
                totals[key] += found[key]
    print("every file, all readers: " + ", ".join(f"{k} {v}" for k, v in totals.items()))
    return totals


def advice(tmp, count, seed):
    """The JSON records (``_sweep.json``, ``_seeds_auto.json``, a round's ``_sweep.json``),
    ``count`` flips each: the sweep's own command must refuse in one line or resume as if
    nothing happened; refused, its advice is followed (the record moved away, the command
    run again), which must resume the directory to the same rows.  Returns the totals."""
    from loopsim.cli import main as loopsim_main

    rng = random.Random(seed)
    totals = {"refused, advice resumed": 0, "accepted, same rows": 0, "wedged": 0}
    for kind, command, record in (("sweep", SWEEP_COMMAND, storage.SWEEP_FILE),
                                  ("auto", AUTO_COMMAND, storage.SEEDS_FILE),
                                  ("auto", AUTO_COMMAND, os.path.join("round-00",
                                                                      storage.SWEEP_FILE))):
        pristine = os.path.join(tmp, kind)
        reference = loopsim.read_results(pristine)
        size = os.path.getsize(os.path.join(pristine, record))
        found = dict.fromkeys(totals, 0)
        for bit in rng.sample(range(size * 8), min(count, size * 8)):
            work = os.path.join(tmp, f"advice-{kind}")
            shutil.rmtree(work, ignore_errors=True)
            shutil.copytree(pristine, work)
            path = os.path.join(work, record)
            data = bytearray(open(path, "rb").read())
            data[bit // 8] ^= 1 << (bit % 8)
            open(path, "wb").write(bytes(data))
            found[_resume(loopsim_main, command + ["--out", work], path, reference)] += 1
        print(f"{kind} {record}: " + ", ".join(f"{k} {v}" for k, v in found.items()))
        for key in totals:
            totals[key] += found[key]
    print("records, the sweep's command: " + ", ".join(f"{k} {v}" for k, v in totals.items()))
    return totals


def _resume(loopsim_main, argv, record, reference):
    """What the sweep's command ``argv`` makes of a directory whose ``record`` is flipped."""
    out = argv[-1]
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()) \
            as err, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        status = loopsim_main(argv)
        if status == 0:
            same = _same(loopsim.read_results(out), reference)
            return "accepted, same rows" if same else "wedged"
        lines = err.getvalue().splitlines()
        if status != 2 or len(lines) != 1 or "move it away" not in lines[0]:
            return "wedged"
        os.replace(record, record + ".damaged")
        if loopsim_main(argv) != 0 or not _same(loopsim.read_results(out), reference):
            return "wedged"
    return "refused, advice resumed"


PARTS = ("result-file", "every-file", "advice", "costs")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flips", type=int, default=6000)
    parser.add_argument("--every-file", type=int, default=150, metavar="N",
                        help="bits flipped per file in the every-file part")
    parser.add_argument("--advice", type=int, default=20, metavar="N",
                        help="bits flipped per JSON record in the advice part")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--parts", default=",".join(PARTS),
                        help=f"which parts, comma-separated: {', '.join(PARTS)}")
    args = parser.parse_args()
    parts = args.parts.split(",")
    unknown = sorted(set(parts) - set(PARTS))
    if unknown:
        parser.error(f"unknown part(s) {unknown}: choose from {list(PARTS)}")
    bad = 0
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "s")
        cases = sweeps.grid_cases([10.0, 60.0, 150.0], [30.0, 60.0], [4], seeds=1)
        sweeps.run_sweep(sweeps.SweepConfig(cases=cases, t_end=0.3, chunk_size=2), out,
                         threads=1, quiet=True)
        if "result-file" in parts:
            flips(out, args.flips, args.seed)
        if "every-file" in parts:
            totals = every_file(tmp, args.every_file, args.seed)
            bad = totals["silent"] + totals["crash"]
        elif "advice" in parts:
            _written_files(tmp)  # the directories the advice part damages
        if "advice" in parts:
            totals = advice(tmp, args.advice, args.seed)
            bad += totals["wedged"]
        if "costs" in parts:
            costs(out, tmp)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
