"""Faults of the processes around a sweep, not of its files (issue 54): concurrent starts
into one directory, and closed or broken standard streams.

    python scripts/process_faults.py [--tries 3] [--parts starts,streams]

``starts`` (``--tries`` times each, every try in a new directory): two different sweeps
started at the same instant; the same sweep twice; shards 0/2 and 1/2 of one sweep; a
sweep killed outright (SIGKILL) and started again.  Expected: of two different sweeps
or two copies of one, exactly one runs and the other is refused at once (exit 2, one
line naming the directory and the holder's pid), the directory then reads back whole as
the winner's; shards both run and together give the whole sweep; after a SIGKILL the
next start resumes (its stale lock removed).

``streams``: a sweep with stderr closed (``2>&-``), a sweep whose stderr reader has gone,
a run with stdin, stdout and stderr closed, ``loopsim summary DIR`` whose stdout reader
has gone (``| head -1``).  Expected: the work done and its files written (exit 0), and
for the summary exit 141 with nothing said (``loopsim.exit_codes.EXIT_BROKEN_PIPE``).

Prints one line per scenario (as expected / not) and the totals; exits 1 if any was not
as expected.  Takes a minute or two (each try starts fresh processes).
"""
import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time

import loopsim
from loopsim import storage
from loopsim.exit_codes import EXIT_BROKEN_PIPE

#: The sweep every scenario runs (``--out`` appended); with progress lines on stderr (not
#: --quiet) where the streams are the fault.
LOUD_SWEEP = [sys.executable, "-m", "loopsim", "sweep", "--g0", "10,60,120,200", "--theta0",
              "30,60,80", "--n", "6", "--t-end", "6", "--no-twin", "--threads", "1",
              "--chunk-size", "1"]
#: Its cases (2-3 s of work: a start finds the other still running after loading).
CASES = 12
SWEEP = LOUD_SWEEP + ["--quiet"]


def _start(argv, **streams):
    streams = dict(dict(stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True), **streams)
    return subprocess.Popen(argv, **streams)


def _finish(processes):
    """(exit status, stdout, stderr) of each process, once it has ended."""
    results = []
    for process in processes:
        stdout, stderr = process.communicate(timeout=600)
        results.append((process.returncode, stdout, stderr))
    return results


def _reads_whole(out, cases=CASES):
    try:
        return len(loopsim.read_results(out)) == cases
    except ValueError:
        return False


def _one_ran_one_refused(out, results):
    """Exactly one exit 0, the other exit 2 with one line naming ``out`` and a pid; the
    directory whole."""
    statuses = sorted(r[0] for r in results)
    refused = [r[2] for r in results if r[0] == 2]
    return (statuses == [0, 2] and len(refused[0].splitlines()) == 1
            and repr(out) in refused[0] and "(pid " in refused[0] and _reads_whole(out))


def different_sweeps(root, index):
    out = os.path.join(root, f"different-{index}")
    results = _finish([_start(SWEEP + ["--out", out]),
                       _start(SWEEP + ["--rtol", "1e-5", "--out", out])])
    return _one_ran_one_refused(out, results)


def same_sweep_twice(root, index):
    out = os.path.join(root, f"same-{index}")
    results = _finish([_start(SWEEP + ["--out", out]) for _ in range(2)])
    return _one_ran_one_refused(out, results)


def two_shards(root, index):
    out = os.path.join(root, f"shards-{index}")
    results = _finish([_start(SWEEP + ["--shard", f"{i}/2", "--out", out]) for i in range(2)])
    return [r[0] for r in results] == [0, 0] and _reads_whole(out)


def killed_then_started(root, index):
    out = os.path.join(root, f"killed-{index}")
    process = _start(SWEEP + ["--out", out])
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and process.poll() is None:
        if os.path.isdir(out) and storage.chunk_files(out):
            break  # a case written, the others running: kill it now
        time.sleep(0.02)
    process.send_signal(signal.SIGKILL)
    process.communicate()
    status, _, _ = _finish([_start(SWEEP + ["--out", out])])[0]
    holders = [n for n in os.listdir(out) if n.startswith("_sweep.lock.")]
    return status == 0 and _reads_whole(out) and not holders


STARTS = {"two different sweeps at once": different_sweeps,
          "the same sweep twice at once": same_sweep_twice,
          "shards 0/2 and 1/2 at once": two_shards,
          "SIGKILL, then the same command": killed_then_started}


def _close_fds(*fds):
    return lambda: [os.close(fd) for fd in fds]


def stderr_closed(root):
    out = os.path.join(root, "stderr-closed")
    process = _start(LOUD_SWEEP + ["--progress-every", "0.001", "--out", out], stderr=None,
                     preexec_fn=_close_fds(2))
    return _finish([process])[0][0] == 0 and _reads_whole(out)


def stderr_reader_gone(root):
    out = os.path.join(root, "stderr-gone")
    process = _start(LOUD_SWEEP + ["--progress-every", "0.001", "--out", out])
    process.stderr.close()
    process.stdout.read()
    return process.wait(timeout=600) == 0 and _reads_whole(out)


def all_streams_closed(root):
    out = os.path.join(root, "all-closed.parquet")
    process = subprocess.Popen([sys.executable, "-m", "loopsim", "run", "--g0", "10",
                                "--theta0", "30", "--n", "6", "--t-end", "0.05", "--out", out],
                               preexec_fn=_close_fds(0, 1, 2))
    if process.wait(timeout=600) != 0:
        return False
    try:
        return len(storage.read_table_checked(out, True)) > 0
    except (OSError, ValueError):
        return False


def stdout_reader_gone(root):
    out = os.path.join(root, "stderr-closed")  # the sweep written above
    if not os.path.isdir(out):
        loopsim.sweep([10.0, 60.0], 30.0, out, n=6, t_end=0.05, twin=False)
    process = _start([sys.executable, "-m", "loopsim", "summary", out])
    process.stdout.close()
    stderr = process.stderr.read()
    return process.wait(timeout=600) == EXIT_BROKEN_PIPE and stderr == ""


STREAMS = {"sweep with stderr closed (2>&-)": stderr_closed,
           "sweep whose stderr reader has gone": stderr_reader_gone,
           "run with stdin, stdout and stderr closed": all_streams_closed,
           "summary whose stdout reader has gone (| head -1)": stdout_reader_gone}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tries", type=int, default=3)
    parser.add_argument("--parts", default="starts,streams")
    args = parser.parse_args()
    parts = args.parts.split(",")
    if set(parts) - {"starts", "streams"}:
        parser.error(f"--parts: starts and/or streams, got {args.parts!r}")
    totals = dict(expected=0, unexpected=0)
    with tempfile.TemporaryDirectory() as root:
        if "starts" in parts:
            for label, scenario in STARTS.items():
                outcomes = [scenario(root, i) for i in range(args.tries)]
                print(f"{label}: as expected {sum(outcomes)} of {len(outcomes)}")
                totals["expected"] += sum(outcomes)
                totals["unexpected"] += len(outcomes) - sum(outcomes)
        if "streams" in parts:
            for label, scenario in STREAMS.items():
                ok = scenario(root)
                print(f"{label}: {'as expected' if ok else 'NOT as expected'}")
                totals["expected" if ok else "unexpected"] += 1
    print(f"process faults: as expected {totals['expected']}, not {totals['unexpected']}")
    return 1 if totals["unexpected"] else 0


if __name__ == "__main__":
    sys.exit(main())
