"""scripts/bad_inputs.py's round of bad inputs, run in process: every one refused before
any work, with exit status 2 and one line on stderr."""
import importlib.util
import os

import pytest

from loopsim.cli import main

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _script():
    spec = importlib.util.spec_from_file_location(
        "bad_inputs", os.path.join(ROOT, "scripts", "bad_inputs.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


SCRIPT = _script()
CASES = SCRIPT.cases("{tmp}")


@pytest.mark.parametrize("label, argv", CASES, ids=[label for label, _ in CASES])
def test_bad_input_refused_in_one_line(tmp_path, capsys, label, argv):
    SCRIPT.prepare(str(tmp_path))
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    try:
        status = main(argv)
    except SystemExit as stop:  # argparse's own refusals
        status = stop.code
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2, (label, status, err)
    assert len(err) == 1 and err[0].startswith("loopsim: error"), (label, err)
    assert not [p for p in os.listdir(tmp_path) if p.startswith("out")], label
