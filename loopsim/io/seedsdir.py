"""The ``--seeds auto`` directory (``sweeps.seeds_auto``): its layout, and its rounds' rows
read as one table; :func:`read_results` reads either kind of directory.

Layout: :data:`SEEDS_FILE` (the cells, the targets and the sweep's other options), one
ordinary sweep directory per round (:data:`ROUND_DIR`), and, once every cell has stopped,
:data:`STOPS_FILE` (one row per cell: why it stopped).
"""
import json
import os

import pandas as pd

from . import sweepdir
from .integrity import read_table_checked

SEEDS_FILE = "_seeds_auto.json"
STOPS_FILE = "seeds_auto.parquet"
ROUND_DIR = "round-{:02d}"


def is_seeds_auto(out):
    """Whether ``out`` is a ``--seeds auto`` directory."""
    return os.path.isfile(os.path.join(out, SEEDS_FILE))


def round_directory(out, index):
    """The sweep directory of round ``index`` of ``out``."""
    return os.path.join(out, ROUND_DIR.format(index))


def read_seeds_file(out):
    """The stored record of a ``--seeds auto`` directory (None if there is none)."""
    path = os.path.join(out, SEEDS_FILE)
    if not os.path.isfile(path):
        return None
    try:
        with open(path, encoding="utf-8") as handle:
            return json.load(handle)
    except (OSError, ValueError) as exc:
        raise ValueError(f"{path!r} is unreadable ({exc}); it holds the --seeds auto "
                         "sweep's cells and targets: restore it or use another --out") from None


def read_seeds_auto(out):
    """Every round's rows of a ``--seeds auto`` directory as one DataFrame: each round read
    and checked by ``sweepdir.read_results``, a ``round`` column added, ``case_id``
    renumbered in (round, case_id) order; ``attrs["loopsim"]`` is the first round's, with
    the targets (``seeds_auto``) and the number of rounds."""
    stored = read_seeds_file(out)
    frames = []
    while os.path.isdir(round_directory(out, len(frames))):
        frame = sweepdir.read_results(round_directory(out, len(frames)))
        frames.append(frame.assign(round=len(frames)))
    if not frames:
        raise ValueError(f"{out!r} is a --seeds auto directory with no round yet: run its "
                         "command")
    rows = pd.concat(frames, ignore_index=True)
    rows["case_id"] = range(len(rows))
    meta = dict(frames[0].attrs.get("loopsim", {}))
    meta.update(seeds_auto=stored["targets"], rounds=len(frames))
    rows.attrs["loopsim"] = meta
    return rows


def read_results(out):
    """All finished cases of a sweep directory (``sweepdir.read_results``) or of a
    ``--seeds auto`` directory (:func:`read_seeds_auto`) as a DataFrame."""
    if os.path.isdir(out) and is_seeds_auto(out):
        return read_seeds_auto(out)
    return sweepdir.read_results(out)


def read_stop_table(out):
    """The stop table of a finished ``--seeds auto`` directory: one row per cell (its
    inputs, ``seeds``, ``rounds``, ``stop_reason``, ``p_halfwidth``, ``tilt_halfwidth_deg``)."""
    path = os.path.join(out, STOPS_FILE)
    if not os.path.isfile(path):
        raise ValueError(f"{out!r} has no {STOPS_FILE}: its --seeds auto sweep has not "
                         "finished (re-run its command)")
    return read_table_checked(path, True).to_pandas()
