"""The cold first run: a loopsim command from a fresh copy of the package with empty caches.

Usage: python benchmarks/bench_cold_start.py [--baseline REV] [--repeats 3]
                                             [--command "run --g0 60 --theta0 30"]
                                             [--out FILE.json]

Each measurement copies the package (``loopsim/`` of the working tree, or of git
revision REV for ``--baseline``, through ``git archive``) into a new temporary
directory, as a fresh clone has it (no ``__pycache__``, new timestamps), points
``NUMBA_CACHE_DIR`` and ``XDG_CACHE_HOME`` at new empty directories, and runs
``python -m loopsim COMMAND`` there in a subprocess: its wall time, its CPU time (user +
system of the child process, ``os.times``), the number of specialisations it compiled
and cached (object files ``*.nbc`` written to the empty cache: one per function and
argument types) and, for a run (``--json`` added), the ``compile_s`` it reports.  Only the installed
dependencies (NumPy, Numba, ...) are shared with other runs.  With ``--baseline`` the
two trees alternate (baseline first), so that a machine whose speed drifts, or that
other jobs share, affects both alike; compare them only within one invocation.
"""
import argparse
import json
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def package_copy(revision, into):
    """Copy loopsim/ (of the working tree, or of git revision ``revision``) below ``into``."""
    if revision is None:
        shutil.copytree(os.path.join(ROOT, "loopsim"), os.path.join(into, "loopsim"),
                        ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        return
    archive = subprocess.run(["git", "-C", ROOT, "archive", revision, "loopsim"],
                             check=True, capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", into], input=archive, check=True)


def cached_specialisations(directory):
    """How many compiled specialisations Numba cached below ``directory`` (object files)."""
    return sum(name.endswith(".nbc") for _, _, names in os.walk(directory) for name in names)


def cold_run(revision, command):
    """One cold run of ``command``: (wall s, exit code, stdout, stderr, specialisations cached)."""
    with tempfile.TemporaryDirectory(prefix="loopsim-cold-") as tmp:
        os.mkdir(os.path.join(tmp, "src"))
        package_copy(revision, os.path.join(tmp, "src"))
        env = dict(os.environ, PYTHONPATH=os.path.join(tmp, "src"),
                   NUMBA_CACHE_DIR=os.path.join(tmp, "numba"),
                   XDG_CACHE_HOME=os.path.join(tmp, "cache"), LOOPSIM_QUIET_COMPILE="1")
        words = shlex.split(command)
        argv = [sys.executable, "-m", "loopsim"] + words + (["--json"] if words[0] == "run" else [])
        started = time.perf_counter()
        process = subprocess.Popen(argv, cwd=tmp, env=env, stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, text=True)
        stdout, stderr = process.communicate()
        wall = time.perf_counter() - started
        return wall, process.returncode, stdout, stderr, cached_specialisations(tmp)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--command", default="run --g0 60 --theta0 30",
                        help="loopsim command line (a run without --json: it is added, and "
                        "the run's compile_s read from it; a relative --out lands in the "
                        "run's temporary directory)")
    parser.add_argument("--baseline", metavar="REV",
                        help="also time git revision REV, alternating with the working tree")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", metavar="FILE.json")
    args = parser.parse_args()
    trees = ([args.baseline] if args.baseline else []) + [None]
    rows = []
    print(f"`loopsim {args.command}`, empty caches, {os.cpu_count()} CPUs, "
          f"load average {os.getloadavg()[0]:.1f} at the start")
    print(f"{'tree':<14} {'wall_s':>7} {'cpu_s':>7} {'compile_s':>9} {'compiled':>8}")
    for repeat in range(args.repeats):
        for revision in trees:
            before = os.times()
            wall, code, stdout, stderr, specialisations = cold_run(revision, args.command)
            after = os.times()
            cpu = (after.children_user - before.children_user
                   + after.children_system - before.children_system)
            if code != 0:
                sys.exit(f"exit {code} from {args.command!r}:\n{stderr}")
            compile_s = (json.loads(stdout).get("compile_s", float("nan"))
                         if shlex.split(args.command)[0] == "run" else float("nan"))
            name = revision or "working tree"
            rows.append(dict(tree=name, repeat=repeat, wall_s=wall, cpu_s=cpu,
                             compile_s=compile_s, compiled=specialisations,
                             load=os.getloadavg()[0]))
            print(f"{name:<14} {wall:7.1f} {cpu:7.1f} {compile_s:9.1f} {specialisations:8d}",
                  flush=True)
    print(f"load average {os.getloadavg()[0]:.1f} at the end")
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(dict(command=args.command, rows=rows), handle, indent=1)


if __name__ == "__main__":
    main()
