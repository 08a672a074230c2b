"""Single-bit flips of a sweep's result file, and the cost of checksums (issue 14).

    python scripts/checksum_faults.py [--flips 6000] [--seed 1]

Runs the 6-case sweep of the tests (g0 10, 60, 150 x theta0 30, 60, n = 4, t = 0.3,
chunk size 2) in a temporary directory, flips ``--flips`` random bits of its second
result file one at a time and counts, for plain ``pyarrow.parquet.read_table`` (values
only) and for ``loopsim.read_results``: flips that raise (detected), that return the same
rows (harmless: statistics, padding), and that return other values without an error
(silent).  Then times writing and reading a 32-row result file and a run file with and
without page checksums and the content hash (best of 30).
"""
import argparse
import os
import random
import shutil
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


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flips", type=int, default=6000)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "s")
        cases = sweeps.grid_cases([10.0, 60.0, 150.0], [30.0, 60.0], [4], seeds=1)
        sweeps.run_sweep(sweeps.SweepConfig(cases=cases, t_end=0.3, chunk_size=2), out,
                         threads=1, quiet=True)
        flips(out, args.flips, args.seed)
        costs(out, tmp)


if __name__ == "__main__":
    main()
