"""Output paths a thousand directories deep (2 003 characters, legal on Linux: PATH_MAX is
4 096) are made without recursion (``storage.make_directories``); longer ones than the
system takes are a one-line error that leaves no directories behind.  Issue 54.9:
``os.makedirs`` recursed once per level and ``sweep``, ``run``, ``report``, ``summary``,
``animate`` and ``figures`` ended in a RecursionError traceback.

Each test removes its deep trees itself: pytest's own clean-up (``shutil.rmtree``, recursive
on Python 3.11) cannot, and a tree left in the temporary root failed the next session's
clean-up with a RecursionError after every test had passed."""
import os

import pytest

import loopsim
from loopsim import storage
from loopsim.cli import main

DEPTH = 1000


@pytest.fixture(scope="module")
def deep(tmp_path_factory):
    """A directory whose path ends in 1 000 levels of ``d/`` (none made yet), and a small
    sweep and run to read."""
    root = tmp_path_factory.mktemp("deep")
    sweep, run = str(root / "sweep"), str(root / "run.parquet")
    assert main(["sweep", "--g0", "10", "--theta0", "30", "--n", "6", "--t-end", "0.05",
                 "--quiet", "--out", sweep]) == 0
    assert main(["run", "--g0", "10", "--theta0", "30", "--n", "6", "--t-end", "0.05",
                 "--out", run]) == 0
    yield dict(root=str(root), sweep=sweep, run=run)
    remove_tree(str(root))


def remove_tree(root):
    """``shutil.rmtree`` without recursion: an explicit stack of directories, each removed
    once it is empty."""
    stack = [root]
    while stack:
        entries = list(os.scandir(stack[-1]))
        below = [entry.path for entry in entries if entry.is_dir(follow_symlinks=False)]
        if below:
            stack.extend(below)
            continue
        for entry in entries:
            os.unlink(entry.path)
        os.rmdir(stack.pop())


def _deep_path(root, leaf):
    return os.path.join(root, *["d"] * DEPTH, leaf)


@pytest.mark.parametrize("command", ["sweep", "run", "summary", "report", "animate",
                                     "figures"])
def test_each_command_writes_under_a_thousand_directories(deep, command, capsys):
    root = os.path.join(deep["root"], command)
    out = _deep_path(root, {"sweep": "s", "run": "r.parquet", "summary": "s.parquet",
                            "report": "r.html", "animate": "a.gif",
                            "figures": "figs"}[command])
    assert len(os.path.relpath(out, root)) > 2000
    argv = {
        "sweep": ["sweep", "--g0", "10", "--theta0", "30", "--n", "6", "--t-end", "0.05",
                  "--quiet", "--out", out],
        "run": ["run", "--g0", "10", "--theta0", "30", "--n", "6", "--t-end", "0.05",
                "--out", out],
        "summary": ["summary", deep["sweep"], "--out", out],
        "report": ["report", deep["sweep"], "--out", out],
        "animate": ["animate", deep["run"], "--out", out],
        "figures": ["figures", deep["sweep"], "--only", "aspect", "--out", out],
    }[command]
    assert main(argv) == 0, capsys.readouterr().err
    assert os.path.exists(out)
    if command == "sweep":
        assert len(loopsim.read_results(out)) == 1


def test_make_directories_is_makedirs_without_recursion(tmp_path):
    deep = _deep_path(str(tmp_path), "leaf")
    storage.make_directories(deep)
    assert os.path.isdir(deep)
    storage.make_directories(deep)  # exist_ok
    remove_tree(str(tmp_path / "d"))
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(FileExistsError):
        storage.make_directories(str(blocker / "below"))


def test_a_path_longer_than_the_system_takes_is_one_line(tmp_path, capsys):
    out = os.path.join(str(tmp_path), *["d"] * 2100, "s")  # 4 200+ characters
    assert main(["sweep", "--g0", "10", "--theta0", "30", "--n", "6", "--t-end", "0.05",
                 "--quiet", "--out", out]) == 2
    err = capsys.readouterr().err
    assert err.startswith("loopsim: error:") and len(err.splitlines()) == 1
    assert "File name too long" in err
    assert os.listdir(tmp_path) == []  # the levels it could make are removed again


def test_a_file_name_past_the_limit_in_directories_that_fit_leaves_none(deep, tmp_path, capsys):
    """The review's case: the directories fit under PATH_MAX (4 096), the file in them does
    not; the write failed after every level was made and left 2 033 of them."""
    levels = (4080 - len(str(tmp_path))) // 2
    out = os.path.join(str(tmp_path), *["d"] * levels, "s.parquet")
    assert len(os.path.dirname(out)) < 4096 <= len(out) + 30
    assert main(["summary", deep["sweep"], "--out", out]) == 2
    err = capsys.readouterr().err
    assert err.startswith("loopsim: error:") and len(err.splitlines()) == 1
    assert os.listdir(tmp_path) == []
