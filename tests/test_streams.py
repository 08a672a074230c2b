"""The program's standard streams (``loopsim._signals.guard_streams``): a closed or broken
stderr never stops the work; stdout's reader gone ends a command quietly with exit
status 141 (``exit_codes.EXIT_BROKEN_PIPE``), never 2 (bad input) nor a traceback."""
import os
import subprocess
import sys

import pytest

import loopsim
from loopsim import storage
from loopsim.exit_codes import EXIT_BROKEN_PIPE

SWEEP = ["sweep", "--g0", "10,40", "--theta0", "30", "--n", "6", "--t-end", "0.05",
         "--threads", "1", "--progress-every", "0.001"]


def _loopsim(args, **streams):
    return subprocess.Popen([sys.executable, "-m", "loopsim"] + args, **streams)


@pytest.mark.parametrize("how", ["closed", "reader gone"])
def test_sweep_with_closed_or_broken_stderr_does_its_work(tmp_path, how):
    """Not --quiet, so progress lines go to stderr.  Issue 54.6: with ``2>&-`` the sweep
    exited 1 with no chunk written and nothing said."""
    out = tmp_path / "s"
    if how == "closed":
        process = _loopsim(SWEEP + ["--out", str(out)], stdout=subprocess.PIPE,
                           stdin=subprocess.DEVNULL,
                           preexec_fn=lambda: os.close(2))  # noqa: PLW1509 - the fault itself
    else:
        process = _loopsim(SWEEP + ["--out", str(out)], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
        process.stderr.close()  # before the program writes a byte to it
    stdout = process.communicate(timeout=300)[0].decode()
    assert process.returncode == 0, stdout
    assert stdout.startswith(f"2 cases in {out}")
    assert len(loopsim.read_results(str(out))) == 2


def test_run_with_every_standard_stream_closed_writes_its_file(tmp_path):
    """stdin, stdout and stderr all closed: the files the program opens must not take
    their numbers (a later write to fd 2 would land in a data file).  A guard: this one
    passed before issue 54 too."""
    out = tmp_path / "run.parquet"

    def close_all():
        for fd in (0, 1, 2):
            os.close(fd)

    process = _loopsim(["run", "--g0", "10", "--theta0", "30", "--n", "6", "--t-end", "0.05",
                        "--out", str(out)], preexec_fn=close_all)  # noqa: PLW1509
    assert process.wait(timeout=300) == 0
    assert len(storage.read_table_checked(str(out), True)) > 0


def test_summary_into_a_pipe_whose_reader_has_gone_exits_quietly(tmp_path):
    """``loopsim summary DIR | head -1``: exit 141, nothing on stderr.  Issue 54.11: exit 2
    and 'loopsim: error: [Errno 32] Broken pipe'."""
    out = tmp_path / "s"
    loopsim.sweep([10.0, 40.0], 30.0, str(out), n=6, t_end=0.05, twin=False)
    process = _loopsim(["summary", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    process.stdout.close()  # the reader is gone before the summary is printed
    stderr = process.communicate(timeout=300)[1].decode()
    assert process.returncode == EXIT_BROKEN_PIPE == 141
    assert stderr == ""


def test_a_command_cut_short_by_its_reader_is_told_apart_from_bad_input(tmp_path):
    """The quiet exit is for stdout's reader only: bad input into the same pipe is still
    its one-line error and exit 2."""
    process = _loopsim(["summary", str(tmp_path / "absent")], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE)
    process.stdout.close()
    stderr = process.communicate(timeout=300)[1].decode()
    assert process.returncode == 2
    assert stderr.startswith("loopsim: error:") and len(stderr.splitlines()) == 1
