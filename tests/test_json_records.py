"""The JSON records of a sweep directory (``_sweep.json``) and a ``--seeds auto`` directory
(``_seeds_auto.json``) are checksummed like every file loopsim writes
(``storage.write_record_atomically``): a damaged one is a one-line error naming it in every
reader and command, and the advice given, followed (move it away, re-run the sweep's
command), leads to a directory that resumes.  Issue 54.3: a renamed key gave a
``KeyError: 'cases'`` traceback; a flipped round fingerprint gave advice that wedged the
directory; a flipped target refused the user's own command."""
import json
import os
import shutil

import pandas as pd
import pytest

import loopsim
from loopsim import storage
from loopsim.cli import main

AUTO = ["sweep", "--g0", "10,40", "--theta0", "30", "--n", "6", "--t-end", "0.05",
        "--no-twin", "--threads", "1", "--quiet", "--seeds", "auto", "--min-seeds", "2",
        "--max-seeds", "4"]


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("auto") / "a")
    assert main(AUTO + ["--out", out]) == 0
    return out


@pytest.fixture
def auto(tmp_path, finished):
    out = str(tmp_path / "a")
    shutil.copytree(finished, out)
    return out


def _record_path(out):
    return os.path.join(out, storage.SEEDS_FILE)


def _edit(out, change):
    """Change the record's text as a flipped bit or a careless editor would."""
    path = _record_path(out)
    with open(path) as handle:
        text = handle.read()
    with open(path, "w") as handle:
        handle.write(change(text))


def _flip_round(text):
    fingerprint = json.loads(text)["rounds"][0]
    return text.replace(fingerprint, fingerprint[:-1] + ("0" if fingerprint[-1] != "0" else "1"))


DAMAGE = {
    "renamed key": lambda text: text.replace('"cases"', '"cbses"', 1),
    "flipped round fingerprint": _flip_round,
    "flipped target": lambda text: text.replace('"max_seeds": 4', '"max_seeds": 5', 1),
}


def _one_line_error(capsys):
    err = capsys.readouterr().err
    assert err.startswith("loopsim: error:") and len(err.splitlines()) == 1, err
    return err


@pytest.mark.parametrize("damage", sorted(DAMAGE))
def test_a_damaged_record_is_one_line_everywhere_and_the_advice_resumes(
        auto, tmp_path, capsys, damage):
    expected = loopsim.read_results(auto)
    _edit(auto, DAMAGE[damage])
    with pytest.raises(ValueError, match="is damaged") as caught:
        loopsim.read_results(auto)
    assert storage.SEEDS_FILE in str(caught.value) and "\n" not in str(caught.value)
    for argv in (["summary", auto], ["report", auto, "--out", str(tmp_path / "r.html")],
                 AUTO + ["--out", auto]):
        assert main(argv) == 2, argv
        err = _one_line_error(capsys)
        assert "is damaged" in err and "move it away" in err
    # the advice, followed: the record moved away, the sweep's own command resumes
    os.replace(_record_path(auto), _record_path(auto) + ".damaged")
    assert main(AUTO + ["--out", auto]) == 0
    assert "rebuilt from this command's options" in capsys.readouterr().err
    resumed = loopsim.read_results(auto)
    columns = [c for c in expected.columns if c != "wall_s"]
    pd.testing.assert_frame_equal(resumed[columns], expected[columns])
    assert main(["summary", auto]) == 0


def test_a_rebuild_with_other_options_is_refused_and_leaves_no_record(auto, capsys):
    """The rebuilt record is checked against the rounds: another perturbation is refused
    at round 0, and the record it made is gone again, so the right command still works."""
    os.remove(_record_path(auto))
    assert main(AUTO + ["--perturbation", "0.02", "--out", auto]) == 2
    assert "holds a different sweep" in capsys.readouterr().err
    assert not os.path.exists(_record_path(auto))
    assert main(AUTO + ["--out", auto]) == 0


def test_a_misspelt_checksum_key_is_damage(auto):
    _edit(auto, lambda text: text.replace(f'"{storage.CONTENT_KEY}"', '"content_sha257"'))
    with pytest.raises(ValueError, match="checksum's key reads 'content_sha257'"):
        loopsim.read_results(auto)


def test_a_record_of_a_release_before_checksums_still_reads_and_resumes(auto, capsys):
    """No checksum: its structure is checked instead (a missing 'cases' is damage)."""
    record = storage.read_seeds_file(auto)
    del record[storage.CONTENT_KEY]
    storage.write_json_atomically(record, _record_path(auto))
    assert len(loopsim.read_results(auto)) == 4
    assert main(AUTO + ["--out", auto]) == 0
    del record["config"]["cases"]
    storage.write_json_atomically(record, _record_path(auto))
    with pytest.raises(ValueError, match="damaged \\(no 'config' with its 'cases'\\)"):
        loopsim.read_results(auto)


SWEEP = ["sweep", "--g0", "10,40", "--theta0", "30", "--n", "6", "--t-end", "0.05",
         "--no-twin", "--threads", "1", "--quiet"]


@pytest.mark.parametrize("field, old, new", [
    ("checksums", '"checksums": "content_sha256"', '"checksums": "content_sha257"'),
    ("loopsim_version", '"loopsim_version": "0.', '"loopsim_version": "1.'),
    ("layout", '"layout": 2', '"layout": 3'),
])
def test_a_flip_outside_the_configuration_of_sweep_json_is_damage(tmp_path, capsys, field,
                                                                   old, new):
    """The fingerprint covers the configuration only: a flip in ``checksums`` (which says
    whether result files must carry their hash), the versions or the layout went
    unseen.  The advice, followed, rewrites the record and the sweep reads again."""
    out = str(tmp_path / "s")
    assert main(SWEEP + ["--out", out]) == 0
    expected = loopsim.read_results(out)
    path = os.path.join(out, storage.SWEEP_FILE)
    with open(path) as handle:
        text = handle.read()
    assert old in text, field
    with open(path, "w") as handle:
        handle.write(text.replace(old, new, 1))
    with pytest.raises(ValueError, match="damaged .content does not match its checksum"):
        loopsim.read_results(out)
    assert main(["summary", out]) == 2
    assert "move it away" in _one_line_error(capsys)
    os.replace(path, path + ".damaged")
    assert main(SWEEP + ["--out", out]) == 0
    pd.testing.assert_frame_equal(loopsim.read_results(out), expected)


def test_a_damaged_round_record_of_a_finished_directory_resumes_as_advised(auto, capsys):
    """A round's ``_sweep.json`` damaged in a finished ``--seeds auto`` directory: its
    advice (move it away, re-run the sweep's command) used to leave a round with result
    files and no configuration, which the finished directory's command read back
    without restoring."""
    expected = loopsim.read_results(auto)
    path = os.path.join(storage.round_directory(auto, 0), storage.SWEEP_FILE)
    with open(path) as handle:
        text = handle.read()
    with open(path, "w") as handle:
        handle.write(text.replace('"t_end": 0.05', '"t_end": 0.06', 1))
    assert main(AUTO + ["--out", auto]) == 2
    assert "move it away" in _one_line_error(capsys)
    os.replace(path, path + ".damaged")
    assert main(AUTO + ["--out", auto]) == 0
    columns = [c for c in expected.columns if c != "wall_s"]
    pd.testing.assert_frame_equal(loopsim.read_results(auto)[columns], expected[columns])
