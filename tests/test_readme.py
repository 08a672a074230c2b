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
    # the main job installs the package alone: it needs none of the test extra
    assert commands[0].startswith("pip install -e . && ")
    assert commands[1].startswith("pip install -e '.[test]' && ")
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


def readme_text():
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as handle:
        return handle.read()


def test_readme_is_a_front_door():
    """At most 100 lines; the output's column table one link away; the settings for the
    top of the range linked; no study history (it lives in docs/studies/ and CHANGELOG.md)."""
    text = readme_text()
    assert text.count("\n") <= 100
    assert "](docs/sweeps.md#table-columns)" in text
    assert "docs/choosing-n-method-rtol.md#above-g0--250" in text
    assert re.search(r"^\| above g0 ≈ 250", text, re.M)  # the regime table's row for high q


def test_the_main_job_needs_no_test_extra():
    """What the main job imports is in the package's own dependencies, not only in the
    test extra (pytest, hypothesis, duckdb, mkdocs)."""
    import tomllib

    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as handle:
        project = tomllib.load(handle)["project"]
    extra_only = {re.split(r"[<>=\[]", r)[0] for r in project["optional-dependencies"]["test"]}
    extra_only -= {re.split(r"[<>=\[]", r)[0] for r in project["dependencies"]}
    probe = ("import sys, loopsim.cli, loopsim.sweeps, loopsim.figures, loopsim.storage; "
             "print(' '.join(sorted(m.split('.')[0] for m in sys.modules)))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          cwd=ROOT, timeout=300)
    assert done.returncode == 0, done.stderr
    imported = set(done.stdout.split())
    assert not imported & {name.replace("-", "_") for name in extra_only}
