"""The ``--seeds auto`` directory (``sweeps.seeds_auto``): its layout, and its rounds' rows
read as one table; :func:`read_results` reads either kind of directory.

Layout: :data:`SEEDS_FILE` (the cells, the targets and the sweep's other options, and
the fingerprints of its rounds; checksummed: :func:`write_seeds_file`), one
ordinary sweep directory per round (:data:`ROUND_DIR`), and, once every cell has stopped,
:data:`STOPS_FILE` (one row per cell: why it stopped).
"""
import json
import os
import re

import pandas as pd

from . import sweepdir
from .integrity import (
    CONTENT_KEY, read_table_checked, record_hash_damage, write_record_atomically,
)

SEEDS_FILE = "_seeds_auto.json"
STOPS_FILE = "seeds_auto.parquet"
ROUND_DIR = "round-{:02d}"
#: The distribution check of the cells whose runs are samples: an ordinary sweep directory.
CHECK_DIR = "check"


def is_seeds_auto(out):
    """Whether ``out`` is a ``--seeds auto`` directory."""
    return os.path.isfile(os.path.join(out, SEEDS_FILE))


def round_directory(out, index):
    """The sweep directory of round ``index`` of ``out``."""
    return os.path.join(out, ROUND_DIR.format(index))


#: What a damaged or unreadable record tells the user to do: the sweep's own command
#: rebuilds a missing record from its options, checking each round against it (a round
#: planned with other options is refused), and resumes.
_REBUILD_ADVICE = ("it holds the --seeds auto sweep's cells, targets and rounds: restore it "
                   "from a copy, or move it away (to {path}.damaged, say) and re-run the "
                   "sweep's command with its options: it rebuilds the record and resumes")


def write_seeds_file(out, record):
    """Write ``out``'s record (:data:`SEEDS_FILE`) atomically, with its checksum
    (``integrity.write_record_atomically``)."""
    write_record_atomically(record, os.path.join(out, SEEDS_FILE))


def record_damage(record):
    """Why a decoded ``--seeds auto`` record is damaged, or None: its checksum fails, or
    (a record of a release before checksums) a field it needs is missing or of the wrong
    kind, or its checksum's key is misspelt."""
    damage = record_hash_damage(record)
    if damage is not None or CONTENT_KEY in record:
        return damage
    config, targets = record.get("config"), record.get("targets")
    if not isinstance(targets, dict):
        return "no 'targets'"
    if not isinstance(config, dict) or not isinstance(config.get("cases"), list) or not all(
            isinstance(case, dict) for case in config["cases"]):
        return "no 'config' with its 'cases'"
    rounds = record.get("rounds", [])
    if not isinstance(rounds, list) or not all(isinstance(r, str) for r in rounds):
        return "'rounds' is not a list of fingerprints"
    return None


def read_seeds_file(out):
    """The stored record of a ``--seeds auto`` directory (None if there is none), checked
    (:func:`record_damage`): a one-line ValueError naming the file and what to do when it
    is unreadable or damaged."""
    path = os.path.join(out, SEEDS_FILE)
    if not os.path.isfile(path):
        return None
    advice = _REBUILD_ADVICE.format(path=path)
    try:
        with open(path, encoding="utf-8") as handle:
            record = json.load(handle)
    except (OSError, ValueError) as exc:
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ValueError(f"{path!r} is unreadable ({reason}); {advice}") from None
    damage = record_damage(record)
    if damage is not None:
        raise ValueError(f"{path!r} is damaged ({damage}); {advice}")
    return record


def _without(config, keys):
    return {k: v for k, v in config.items() if k not in keys}


def check_rounds(out, stored, count):
    """ValueError naming the first of ``out``'s ``count`` round directories that is not
    this sweep's: its configuration fingerprint is not the one recorded for it before it
    ran (``stored["rounds"]``, the decoded record), or, in a directory recorded before
    fingerprints were, its options differ from the record's or it holds a case of no cell."""
    recorded = stored.get("rounds")
    ignored = ("cases",) + sweepdir.FINGERPRINT_IGNORES
    options = _without(stored["config"], ignored)
    cells = [_without(case, ("seed",)) for case in stored["config"]["cases"]]
    for index in range(count):
        directory = round_directory(out, index)
        config = sweepdir.read_sweep_file(directory)
        if config is None:
            continue  # a round cut short before it wrote its configuration: no rows
        if recorded is not None:
            foreign = index >= len(recorded) or config["fingerprint"] != recorded[index]
        else:
            foreign = _without(config["config"], ignored) != options or any(
                _without(case, ("seed",)) not in cells for case in config["config"]["cases"])
        if foreign:
            raise ValueError(f"{directory!r} is not a round of the --seeds auto sweep in "
                             f"{out!r} (its cases or options are not the ones this sweep "
                             "planned: copied in from another sweep?); move it away")


def check_round_directory(out, fingerprint):
    """ValueError when ``out`` is a ``--seeds auto`` directory, or one of its rounds about
    to be run with a configuration (``fingerprint``) other than the one recorded for it:
    a directory of one kind never takes a sweep of another."""
    if is_seeds_auto(out):
        raise ValueError(f"{out!r} holds a --seeds auto sweep; use another --out (or its "
                         "--seeds auto command, to resume it)")
    parent, name = os.path.split(os.path.abspath(out))
    match = re.fullmatch(ROUND_DIR.replace("{:02d}", r"(\d{2,})"), name)
    if match and is_seeds_auto(parent):
        recorded = (read_seeds_file(parent) or {}).get("rounds") or []
        index = int(match[1])
        if index >= len(recorded) or recorded[index] != fingerprint:
            raise ValueError(f"{out!r} is round {index} of the --seeds auto sweep in "
                             f"{parent!r}, planned with other cases and options; use another "
                             "--out")


def read_seeds_auto(out):
    """Every round's rows of a ``--seeds auto`` directory as one DataFrame: each round read
    and checked by ``sweepdir.read_results``, a ``round`` column added, ``case_id``
    renumbered in (round, case_id) order; ``attrs["loopsim"]`` is the first round's, with
    the targets (``seeds_auto``) and the number of rounds."""
    stored = read_seeds_file(out)
    count = 0
    while os.path.isdir(round_directory(out, count)):
        count += 1
    check_rounds(out, stored, count)
    frames = []
    for index in range(count):
        frame = sweepdir.read_results(round_directory(out, index))
        frames.append(frame.assign(round=index))
    if not frames:
        raise ValueError(f"{out!r} is a --seeds auto directory with no round yet: run its "
                         "command")
    rows = pd.concat(frames, ignore_index=True)
    rows["case_id"] = range(len(rows))
    meta = dict(frames[0].attrs.get("loopsim", {}))
    lacking = {}  # rows lacking a column, over every round (a resume across releases)
    for frame in frames:
        for name, count in frame.attrs.get("loopsim", {}).get("not_recorded", {}).items():
            lacking[name] = lacking.get(name, 0) + count
    meta.update(seeds_auto=stored["targets"], rounds=len(frames), not_recorded=lacking)
    rows.attrs["loopsim"] = meta
    return rows


def read_results(out):
    """All finished cases of a sweep directory as a DataFrame sorted by ``case_id``.

    The same rows as ``pandas.read_parquet(out)``, checked: every result file must read
    back whole with its page checksums and content hash (a damaged file is a one-line
    ValueError naming it: re-running the sweep's command moves it aside and recomputes
    its cases), carry the fingerprint of the configuration in ``_sweep.json`` and hold
    exactly the cases its name says; no case may appear twice.  A ``--seeds auto``
    directory is read round by round (``read_seeds_auto``): its rows get a ``round``
    column and ``case_id`` is renumbered in (round, case_id) order.

    Parameters
    ----------
    out : str
        A sweep directory (``loopsim sweep --out``, ``loopsim.sweep``) or a
        ``--seeds auto`` directory.

    Returns
    -------
    pandas.DataFrame
        One row per finished case, with the columns of ``loopsim.columns.RESULT_COLUMNS``
        (inputs, run statistics, the terminal state's diagnostics, ``regime``,
        ``resolved``, ``determined``, ``x_final`` in L/2π; units in docs/sweeps.md).
        ``frame.attrs["loopsim"]`` holds the sweep's configuration, thresholds,
        versions, command line, reruns and each column's unit and description.  A sweep
        still running gives the cases finished so far.

    Raises
    ------
    ValueError
        ``out`` is not a sweep directory, has lost its ``_sweep.json``, holds a damaged
        file, a file of another sweep or a case twice, or is a layout-1 directory
        (loopsim 0.2.0 and earlier releases).

    Examples
    --------
    A sweep directory (the README's main job writes ``runs/phase``), here a small one:

    >>> import loopsim
    >>> rows = loopsim.sweep([10.0, 40.0], 30.0, "runs/two", n=6, t_end=0.5, twin=False)
    >>> frame = loopsim.read_results("runs/two")
    >>> frame.groupby("regime").size()
    regime
    stable    2
    dtype: int64
    """
    if os.path.isdir(out) and is_seeds_auto(out):
        return read_seeds_auto(out)
    return sweepdir.read_results(out)


def read_stop_table(out):
    """The stop table of a finished ``--seeds auto`` directory: why each cell stopped.

    Parameters
    ----------
    out : str
        A ``--seeds auto`` directory whose sweep has finished.

    Returns
    -------
    pandas.DataFrame
        One row per cell, with the columns of ``loopsim.columns.STOP_COLUMNS`` (its
        inputs, ``seeds``, ``rounds``, ``stop_reason``, ``p_halfwidth``,
        ``tilt_halfwidth_deg`` in degrees, ``runs``, ``twins`` and the distribution check of
        sampled cells); each column's unit and description are in the file's field
        metadata.

    Raises
    ------
    ValueError
        The sweep has not finished (no stop table yet).
    loopsim.storage.DamagedFile
        The stop table fails its checksums or content hash.

    Examples
    --------
    >>> import loopsim
    >>> from loopsim import storage
    >>> rows = loopsim.sweep(10.0, 30.0, "runs/seeds", n=6, t_end=0.5, seeds="auto",
    ...                      max_seeds=4)
    >>> storage.read_stop_table("runs/seeds")[["g0", "theta0_deg", "seeds", "stop_reason"]]
         g0  theta0_deg  seeds    stop_reason
    0  10.0        30.0      4  deterministic
    """
    path = os.path.join(out, STOPS_FILE)
    if not os.path.isfile(path):
        raise ValueError(f"{out!r} has no {STOPS_FILE}: its --seeds auto sweep has not "
                         "finished (re-run its command)")
    return read_table_checked(path, True).to_pandas()
