"""The README's two commands, taken from README.md itself (parsed, not copied), so an
edit there or a path check in the code cannot break them unnoticed."""
import os
import re
import shlex
import subprocess
import sys

import pandas as pd

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def readme_commands():
    """The commands of README.md's first bash block (comment lines dropped)."""
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as handle:
        text = handle.read()
    block = re.search(r"```bash\n(.*?)```", text, re.S).group(1)
    return [line for line in block.splitlines() if line.strip() and not line.startswith("#")]


def main_command():
    """The main job: the first command that runs ``loopsim sweep``, without its install
    step (``pip install ... &&``: the test runs in the installed package)."""
    line = next(c for c in readme_commands() if "loopsim sweep" in c)
    return shlex.split(line[line.index("loopsim sweep"):])


def with_option(words, option, value):
    words = list(words)
    words[words.index(option) + 1] = value
    return words


def test_readme_opens_with_the_install_the_main_job_and_the_tests():
    commands = readme_commands()
    assert len(commands) == 2
    assert all(c.startswith("pip install -e '.[test]' && ") for c in commands)
    assert "loopsim sweep" in commands[0] and "--figure" in main_command()
    assert commands[1].endswith("python -m pytest -q")
    with open(os.path.join(ROOT, ".ci", "run"), encoding="utf-8") as handle:
        assert "python -m pytest -q\n" in handle.read()  # CI runs the README's tests


def test_main_command_runs_on_a_fresh_directory(tmp_path):
    """The README's main job, only its grid shrunk to two stable cells, run in an empty
    directory (a fresh clone has no runs/): every output directory is made, the table
    and the figure are written, and every row is resolved and determined."""
    words = with_option(with_option(main_command(), "--g0", "10,40"), "--theta0", "30")
    done = subprocess.run([sys.executable, "-m", "loopsim"] + words[1:], cwd=tmp_path,
                          capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr
    out = words[words.index("--out") + 1]
    figure = words[words.index("--figure") + 1]
    assert os.path.getsize(tmp_path / figure) > 10_000
    frame = pd.read_parquet(tmp_path / out)
    assert len(frame) == 2 and frame["resolved"].all() and frame["determined"].all()
    assert set(frame["regime"]) == {"stable"}
    assert "2 cases in" in done.stdout
