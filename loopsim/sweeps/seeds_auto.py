"""``--seeds auto``: rounds of sweeps that add seeds to each cell until its answer is sharp.

The directory (``io.seedsdir``) holds the cells, the targets and the sweep's other
options, one ordinary sweep directory per round (checksummed, resumable) and, once every
cell has stopped, the stop table: one row per cell saying why it stopped
(``seeding``: deterministic, sharp or cap).  Round r's cases are planned from the rows of
rounds < r only, by ``seeding.decide``; those rows are reproducible bit for bit, so
re-running the command after an interruption plans the same rounds and resumes the one
it stopped in.  Orchestration only: the rule is ``seeding``, the runs ``run_sweep``.
"""
import dataclasses
import json
import os

import pandas as pd
import pyarrow as pa

from .. import io, seeding

#: The inputs that tell the cells apart (the seed never does).
CELL_KEYS = ("g0", "theta0_deg", "n", "perturbation")
_NO_ROWS = pd.DataFrame(dict(regime=[], theta_final_deg=[], aspect_ratio=[], seed=[]))


def cell_key(case):
    """A case's cell: its :data:`CELL_KEYS` as floats."""
    return tuple(float(case[k]) for k in CELL_KEYS)


def _record(config, targets):
    return dict(layout=1, targets=dataclasses.asdict(targets),
                config=json.loads(json.dumps(config.as_dict())))


def prepare(out, config, targets, command_line):
    """Make ``out`` for this ``--seeds auto`` sweep, or check that it holds this very one
    (the same cells, targets and options); a one-line ValueError otherwise."""
    record = _record(config, targets)
    stored = io.read_seeds_file(out)
    if stored is not None:
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
        raise ValueError(f"{out!r} holds a sweep with fixed --seeds; use another --out")
    os.makedirs(out, exist_ok=True)
    io.write_json_atomically(dict(record, command_line=command_line or [],
                                  **json.loads(json.dumps(io.provenance()))),
                             os.path.join(out, io.SEEDS_FILE))


def _groups(rows):
    if rows is None or not len(rows):
        return {}
    return {key: group.sort_values("seed") for key, group in rows.groupby(list(CELL_KEYS))}


def plan_round(cells, rows, targets):
    """The next round's cases: for each cell (a case dict; its seed is ignored) whose rows
    so far (``rows``, a DataFrame or None) do not decide it, the seeds from its count up to
    the size ``seeding.decide`` asks for."""
    groups = _groups(rows)
    cases = []
    for cell in cells:
        have = groups.get(cell_key(cell), _NO_ROWS)
        reason, wanted = seeding.decide(have, targets)
        if reason == seeding.CONTINUE:
            cases.extend(dict(cell, seed=seed) for seed in range(len(have), wanted))
    return cases


def stop_table(cells, rows, targets):
    """One row per cell: its inputs, seeds, rounds, stop reason and interval half-widths."""
    groups = _groups(rows)
    return pd.DataFrame([
        seeding.cell_record(CELL_KEYS, cell_key(cell), groups[cell_key(cell)], targets,
                            int(groups[cell_key(cell)]["round"].max()) + 1)
        for cell in cells])


def run_seeds_auto(config, out, targets, *, run_round, command_line=None, announce=None):
    """Run (or resume) ``--seeds auto`` into ``out``; returns (rows, stop table).

    ``config``: the sweep's configuration with one case per cell (its seed ignored);
    ``run_round(config, directory)``: runs one ordinary sweep and returns its rows (the
    caller's backend and progress); ``announce(text)``: called with one line per round.
    """
    targets.check()
    cells = [dict(case, seed=0) for case in config.cases]
    if len({cell_key(c) for c in cells}) != len(cells):
        raise ValueError("--seeds auto needs distinct cells (g0, theta0, n, perturbation)")
    prepare(out, config, targets, command_line)
    rows = None
    index = 0
    while True:
        cases = plan_round(cells, rows, targets)
        if not cases:
            break
        if announce is not None:
            announce(f"seeds auto: round {index}: {len({cell_key(c) for c in cases})} of "
                     f"{len(cells)} cells open, {len(cases)} cases")
        frame = run_round(dataclasses.replace(config, cases=cases),
                          io.round_directory(out, index)).assign(round=index)
        rows = frame if rows is None else pd.concat([rows, frame], ignore_index=True)
        index += 1
    table = stop_table(cells, rows, targets)
    meta = io.provenance(seeds_auto_targets=json.dumps(dataclasses.asdict(targets)))
    io.write_table_atomically(pa.Table.from_pandas(table, preserve_index=False)
                              .replace_schema_metadata(meta), os.path.join(out, io.STOPS_FILE))
    return io.read_seeds_auto(out), table
