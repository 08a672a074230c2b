"""A round of bad inputs against the command line, as a new user would type them.

    python scripts/bad_inputs.py DIR

DIR is a scratch directory.  Every command must be refused before any work: exit
status 2 and exactly one line on stderr starting "loopsim: error:" (or, from argparse,
"loopsim: error:" too), and nothing left in DIR/out*.  Prints one line per input and a
count at the end; exits 1 if any input was not refused that way.
"""
import os
import subprocess
import sys

RUN = ["run", "--n", "6", "--g0", "60", "--theta0", "30", "--t-end", "0.01"]
SWEEP = ["sweep", "--n", "6", "--g0", "60", "--theta0", "30", "--t-end", "0.01"]


def cases(d):
    """(label, argv) of the round: each must be refused."""
    f = lambda name: os.path.join(d, name)  # noqa: E731
    out = f("out-sweep")
    bad = []
    for value in ("-1", "0", "6.5", "abc", "129", "1000000", "nan", ""):
        bad.append((f"run --n {value!r}", RUN + ["--n", value]))
    for flag, value in [("--g0", "-1"), ("--g0", "nan"), ("--g0", "inf"), ("--g0", "abc"),
                        ("--theta0", "-1"), ("--theta0", "91"), ("--theta0", "nan"),
                        ("--t-end", "0"), ("--t-end", "-1"), ("--t-end", "inf"),
                        ("--rtol", "0"), ("--rtol", "-1e-6"), ("--atol", "-1"), ("--w", "-1"),
                        ("--perturbation", "-0.1"), ("--perturbation", "2"),
                        ("--seed", "-1"), ("--seed", "1.5"), ("--snapshots", "0"),
                        ("--snapshots", "100000"), ("--method", "euler"), ("--n-max", "0"),
                        ("--n-max", "500"), ("--tail-tol", "0"), ("--tail-tol", "-1")]:
        bad.append((f"run {flag} {value}", RUN + [flag, value]))
    bad += [
        ("run unknown option", RUN + ["--bogus"]),
        ("run without --theta0", ["run", "--n", "6", "--g0", "60"]),
        ("run --theta0 and --initial", RUN + ["--initial", f("short.csv")]),
        ("run --initial missing", ["run", "--n", "6", "--g0", "60", "--initial", f("missing.csv")]),
        ("run --initial empty", ["run", "--n", "6", "--g0", "60", "--initial", f("empty.csv")]),
        ("run --initial 2 points", ["run", "--n", "6", "--g0", "60", "--initial", f("short.csv")]),
        ("run --initial no x,y,z", ["run", "--n", "6", "--g0", "60", "--initial", f("nocols.csv")]),
        ("run --initial NaN", ["run", "--n", "6", "--g0", "60", "--initial", f("nan.csv")]),
        ("run --initial fake parquet", ["run", "--n", "6", "--g0", "60", "--initial", f("fake.parquet")]),
        ("run --initial /dev/zero", ["run", "--n", "6", "--g0", "60", "--initial", "/dev/zero"]),
        ("run --initial FIFO", ["run", "--n", "6", "--g0", "60", "--initial", f("fifo")]),
        ("run --initial a directory", ["run", "--n", "6", "--g0", "60", "--initial", d]),
        ("run --out a directory", RUN + ["--out", d]),
        ("run --out empty", RUN + ["--out", ""]),
        ("run --case-id without --initial", RUN + ["--case-id", "3"]),
        ("sweep --g0 1:2", ["sweep", "--n", "6", "--g0", "1:2", "--theta0", "30", "--out", out]),
        ("sweep --g0 1:2:0", ["sweep", "--n", "6", "--g0", "1:2:0", "--theta0", "30", "--out", out]),
        ("sweep --g0 1:2:1e9", ["sweep", "--n", "6", "--g0", "1:2:1000000000", "--theta0", "30",
                                "--out", out]),
        ("sweep --theta0 100", ["sweep", "--n", "6", "--g0", "60", "--theta0", "100", "--out", out]),
        ("sweep --n 0", SWEEP + ["--n", "0", "--out", out]),
        ("sweep --n 6.5", SWEEP + ["--n", "6.5", "--out", out]),
        ("sweep --seeds 0", SWEEP + ["--seeds", "0", "--out", out]),
        ("sweep --threads 0", SWEEP + ["--threads", "0", "--out", out]),
        ("sweep --threads 1000", SWEEP + ["--threads", "1000", "--out", out]),
        ("sweep --chunk-size 0", SWEEP + ["--chunk-size", "0", "--out", out]),
        ("sweep --snapshots-for 5", SWEEP + ["--snapshots-for", "5", "--out", out]),
        ("sweep --method euler", SWEEP + ["--method", "euler", "--out", out]),
        ("sweep --shard 2/2", SWEEP + ["--shard", "2/2", "--out", out]),
        ("sweep --shard x", SWEEP + ["--shard", "x", "--out", out]),
        ("sweep no --out", SWEEP),
        ("sweep --out empty", SWEEP + ["--out", ""]),
        ("sweep --out a file", SWEEP + ["--out", f("short.csv")]),
        ("sweep --cases missing", ["sweep", "--n", "6", "--cases", f("missing.csv"), "--out", out]),
        ("sweep --cases theta0 abc", ["sweep", "--n", "6", "--cases", f("cases_bad.csv"), "--out", out]),
        ("sweep --cases n 6.5", ["sweep", "--n", "6", "--cases", f("cases_frac.csv"), "--out", out]),
        ("sweep --cases seed -1", ["sweep", "--n", "6", "--cases", f("cases_seed.csv"), "--out", out]),
        ("sweep --cases /dev/zero", ["sweep", "--n", "6", "--cases", "/dev/zero", "--out", out]),
        ("sweep --cases and --g0", ["sweep", "--n", "6", "--cases", f("cases_seed.csv"), "--g0", "1",
                                    "--out", out]),
        ("sweep --rerun-failed missing", ["sweep", "--rerun-failed", f("missing")]),
        ("stability --n 2", ["stability", "--n", "2"]),
        ("stability --n 1000", ["stability", "--n", "1000"]),
        ("stability --theta0 95", ["stability", "--theta0", "95"]),
        ("stability --paper --n-max 0", ["stability", "--paper", "--n-max", "0"]),
        ("branch --n 2", ["branch", "--n", "2"]),
        ("branch --q-max 5", ["branch", "--q-max", "5"]),
        ("figures missing dir", ["figures", f("missing"), "--out", f("figs")]),
        ("unknown command", ["simulate"]),
        ("no command", []),
    ]
    return bad


def prepare(d):
    """The files some inputs name: a two-point curve (``short.csv``, also a file where a
    directory is wanted) and an empty one.  Missing output directories are made, not
    refused, so none is among the inputs."""
    with open(os.path.join(d, "short.csv"), "w") as handle:
        handle.write("x,y,z\n1,0,0\n0,1,0\n")
    open(os.path.join(d, "empty.csv"), "w").close()


def main():
    directory = os.path.abspath(sys.argv[1])
    prepare(directory)
    failures = 0
    tried = cases(directory)
    for label, argv in tried:
        done = subprocess.run([sys.executable, "-m", "loopsim"] + argv, capture_output=True,
                              text=True, timeout=600)
        lines = done.stderr.strip().splitlines()
        ok = done.returncode == 2 and len(lines) == 1 and lines[0].startswith("loopsim: error")
        left = [p for p in os.listdir(directory) if p.startswith("out")]
        ok = ok and not left
        failures += not ok
        print(f"{'refused' if ok else 'NOT REFUSED'}  rc={done.returncode}  {label}: "
              f"{lines[-1] if lines else '(no stderr)'}"[:200], flush=True)
    print(f"{len(tried) - failures} of {len(tried)} bad inputs refused with one line and exit 2")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
