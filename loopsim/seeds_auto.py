"""``--seeds auto``: rounds of sweeps that add seeds to each cell until its answer is sharp.

The directory ``out`` holds :data:`SEEDS_FILE` (the cells, the targets and the sweep's
other options: what determines the result), one ordinary sweep directory per round
(``round-00``, ``round-01``, ...: checksummed, resumable, readable with ``read_results``)
and, once every cell has stopped, :data:`STOPS_FILE`, one row per cell saying why it
stopped (``seeding``: deterministic, sharp or cap).  Round r's cases are planned from the
rows of rounds < r only, by ``seeding.decide``; those rows are reproducible bit for bit, so
re-running the command after an interruption plans the same rounds and resumes the one it
stopped in.  :func:`read_seeds_auto` gives all rounds' rows as one table.
"""
import dataclasses
import json
import os

import pandas as pd
import pyarrow as pa

from . import io, seeding

SEEDS_FILE = "_seeds_auto.json"
STOPS_FILE = "seeds_auto.parquet"
ROUND_DIR = "round-{:02d}"
#: The inputs that tell the cells apart (the seed never does).
CELL_KEYS = ("g0", "theta0_deg", "n", "perturbation")


def is_seeds_auto(out):
    """Whether ``out`` is a ``--seeds auto`` directory."""
    return os.path.isfile(os.path.join(out, SEEDS_FILE))


def _cell_key(case):
    return tuple(float(case[k]) for k in CELL_KEYS)


def _prepare(out, config, targets, command_line):
    """Create ``out`` or check that it holds this very ``--seeds auto`` sweep."""
    record = dict(layout=1, targets=dataclasses.asdict(targets),
                  config=json.loads(json.dumps(config.as_dict())))
    path = os.path.join(out, SEEDS_FILE)
    if os.path.isfile(path):
        with open(path) as handle:
            stored = json.load(handle)
        if {k: stored.get(k) for k in record} != record:
            changed = sorted(
                [f"targets.{k}" for k in record["targets"]
                 if stored.get("targets", {}).get(k) != record["targets"][k]]
                + [k for k in record["config"]
                   if stored.get("config", {}).get(k) != record["config"][k]])
            raise ValueError(f"{out!r} holds a different --seeds auto sweep (differs in: "
                             f"{', '.join(changed) or 'its layout'}); use another --out")
        return
    if os.path.isfile(os.path.join(out, io.SWEEP_FILE)):
        raise ValueError(f"{out!r} holds a sweep with fixed seeds; use another --out")
    os.makedirs(out, exist_ok=True)
    io.write_json_atomically(dict(record, command_line=command_line or [],
                                  **json.loads(json.dumps(io.provenance()))), path)


def plan_round(cells, rows, targets):
    """The cases of the next round: for each cell (a case dict, its seed ignored) whose
    rows so far (``rows``: DataFrame of finished rows, possibly empty) do not yet
    decide it, the seeds from its count up to the size ``seeding.decide`` asks for."""
    groups = {} if rows is None or not len(rows) else {
        key: group.sort_values("seed") for key, group in rows.groupby(list(CELL_KEYS))}
    cases = []
    for cell in cells:
        have = groups.get(_cell_key(cell), _EMPTY)
        reason, wanted = seeding.decide(have, targets)
        if reason == seeding.CONTINUE:
            cases.extend(dict(cell, seed=seed) for seed in range(len(have), wanted))
    return cases


_EMPTY = pd.DataFrame(dict(regime=[], theta_final_deg=[], aspect_ratio=[], seed=[]))


def stop_table(cells, rows, targets):
    """One row per cell: its inputs, seeds, rounds, stop reason and interval widths."""
    groups = {key: group for key, group in rows.groupby(list(CELL_KEYS))}
    records = []
    for cell in cells:
        group = groups[_cell_key(cell)]
        records.append(seeding.cell_record(CELL_KEYS, _cell_key(cell), group, targets,
                                           int(group["round"].max()) + 1))
    return pd.DataFrame(records)


def run_seeds_auto(config, out, targets, *, run_round, command_line=None, announce=None):
    """Run (or resume) ``--seeds auto`` into ``out``; returns (rows, stop table).

    ``config``: the sweep's configuration whose cases are the cells (one case per cell,
    seed 0); ``run_round(config, directory)`` runs one ordinary sweep (the caller's
    backend and progress); ``announce(text)``: one line per round (or None).
    """
    targets.check()
    cells = [dict(case, seed=0) for case in config.cases]
    if len({_cell_key(c) for c in cells}) != len(cells):
        raise ValueError("--seeds auto needs distinct cells (g0, theta0, n, perturbation)")
    _prepare(out, config, targets, command_line)
    rows = None
    index = 0
    while True:
        cases = plan_round(cells, rows, targets)
        if not cases:
            break
        directory = os.path.join(out, ROUND_DIR.format(index))
        if announce is not None:
            open_cells = len({_cell_key(c) for c in cases})
            announce(f"seeds auto: round {index}: {open_cells} of {len(cells)} cells open, "
                     f"{len(cases)} cases")
        frame = run_round(dataclasses.replace(config, cases=cases), directory)
        frame = frame.assign(round=index)
        rows = frame if rows is None else pd.concat([rows, frame], ignore_index=True)
        index += 1
    table = stop_table(cells, rows, targets)
    meta = io.provenance(seeds_auto=json.dumps(dataclasses.asdict(targets)))
    io.write_table_atomically(pa.Table.from_pandas(table, preserve_index=False)
                              .replace_schema_metadata(meta), os.path.join(out, STOPS_FILE))
    return read_seeds_auto(out), table


def read_seeds_auto(out):
    """Every round's rows of a ``--seeds auto`` directory as one DataFrame: each round read
    and checked by ``read_results``, a ``round`` column added, ``case_id`` renumbered in
    (round, case_id) order; ``attrs["loopsim"]`` from the first round, with the targets."""
    with open(os.path.join(out, SEEDS_FILE)) as handle:
        stored = json.load(handle)
    frames = []
    index = 0
    while os.path.isdir(os.path.join(out, ROUND_DIR.format(index))):
        frame = io.read_results(os.path.join(out, ROUND_DIR.format(index)))
        frames.append(frame.assign(round=index))
        index += 1
    if not frames:
        raise ValueError(f"{out!r} is a --seeds auto directory with no round yet: run its "
                         "command")
    rows = pd.concat(frames, ignore_index=True)
    rows["case_id"] = range(len(rows))
    attrs = dict(frames[0].attrs.get("loopsim", {}))
    attrs.update(seeds_auto=stored["targets"], rounds=index)
    rows.attrs["loopsim"] = attrs
    return rows
