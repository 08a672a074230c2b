"""``--seeds auto``: rounds of sweeps that add seeds to each cell until its answer is sharp.

The directory (``storage.seedsdir``) holds the cells, the targets and the sweep's other
options, one ordinary sweep directory per round (checksummed, resumable) and, once every
cell has stopped, the stop table: one row per cell saying why it stopped
(``seeds_auto_rule``: failed, deterministic, sharp or cap; rescued where a later
``--rerun-failed`` replaced failed runs: :func:`restate_stop_table`).  Round r's cases
are planned from the rows of rounds < r only, by ``seeds_auto_rule.decide``; those rows are reproducible bit for bit, so
re-running the command after an interruption plans the same rounds and resumes the one
it stopped in.  Each round's configuration fingerprint is recorded in the directory's
record before the round runs, so that a round copied in from elsewhere is refused on
read as on resume (``storage.check_rounds``).  Orchestration only: the rule is ``seeds_auto_rule``,
the runs ``run_sweep``.
"""
import dataclasses
import json
import os
import warnings

import pandas as pd
import pyarrow as pa

from .. import (
    columns, outcome_statistics, outcomes, seeds_auto_rule, storage, validation,
)
from . import lock
from .cases import validate

#: The inputs that tell the cells apart (the seed never does).  Every other input of a
#: cell (``outcome_statistics.CELL_INPUTS``: model, slenderness, rtol, t_end, method, w ...) is one
#: option of the whole sweep here: ``--seeds auto`` takes a grid, never a cases file.
CELL_KEYS = ("g0", "theta0_deg", "n", "perturbation")
_NO_ROWS = pd.DataFrame(dict(regime=[], theta_final_deg=[], aspect_ratio=[], seed=[]))


def cell_key(case):
    """A case's cell: its :data:`CELL_KEYS` as floats."""
    return tuple(float(case[k]) for k in CELL_KEYS)


def _record(config, targets):
    return dict(layout=1, targets=dataclasses.asdict(targets),
                config=json.loads(json.dumps(config.as_dict())))


def _differences(stored, record):
    """The record's keys whose stored value differs (``storage.FINGERPRINT_IGNORES`` left out:
    the chunk size may change on resume)."""
    defaults = dataclasses.asdict(seeds_auto_rule.SeedTargets())
    changed = [f"targets.{k}" for k in record["targets"]
               if stored.get("targets", {}).get(k, defaults[k]) != record["targets"][k]]
    changed += [k for k in record["config"] if k not in storage.FINGERPRINT_IGNORES
                and stored.get("config", {}).get(k) != record["config"][k]]
    if stored.get("layout") != record["layout"] and not changed:
        changed = ["its layout"]
    return sorted(changed)


def prepare(out, config, targets, command_line):
    """Write the record of this ``--seeds auto`` sweep into the directory ``out``, or check
    that it holds this very one (the same cells, targets and options, the chunk size
    aside); a one-line ValueError otherwise.  Returns what it made (the record, or
    nothing) for :func:`_undo`."""
    record = _record(config, targets)
    stored = storage.read_seeds_file(out)
    if stored is not None:
        changed = _differences(stored, record)
        if changed:
            raise ValueError(f"{out!r} holds a different --seeds auto sweep (differs in: "
                             f"{', '.join(changed)}); use another --out")
        return []
    if os.path.isfile(os.path.join(out, storage.SWEEP_FILE)):
        raise ValueError(f"{out!r} holds a sweep with fixed --seeds; use another --out")
    if os.path.isdir(storage.round_directory(out, 0)):
        warnings.warn(f"{os.path.join(out, storage.SEEDS_FILE)!r} is missing although "
                      f"{out!r} holds rounds: rebuilt from this command's options, each "
                      "round checked against them as it resumes", stacklevel=2)
    storage.write_seeds_file(out, dict(record, rounds=[], command_line=command_line or [],
                                       **json.loads(json.dumps(storage.provenance()))))
    return [os.path.join(out, storage.SEEDS_FILE)]


def _make_directory(out):
    """Make ``out`` if absent; the directories made, outermost first (for :func:`_undo`)."""
    made = []
    missing = os.path.abspath(out)
    while not os.path.exists(missing):
        made.insert(0, missing)
        missing = os.path.dirname(missing)
    storage.make_directories(out)
    return made


def _fingerprint(config, targets):
    """What a ``--seeds auto`` sweep computes, as a fingerprint (``storage.config_fingerprint``
    of its options and targets; the chunk size aside): the directory's holder records it."""
    return storage.config_fingerprint(dict(json.loads(json.dumps(config.as_dict())),
                                           seeds_auto_targets=dataclasses.asdict(targets)))


def _undo(made):
    """Remove what :func:`prepare` made (its record) or :func:`_make_directory` (the
    directories, if empty): a command refused before its first round leaves the file
    system as it was."""
    for path in reversed(made):
        try:
            os.remove(path) if os.path.isfile(path) else os.rmdir(path)
        except OSError:
            return


def _round_record_missing(out):
    """Whether a round directory of ``out`` has lost its ``_sweep.json`` (moved away as its
    damage advised): the rounds are then planned again, and each resumes and rewrites it."""
    index = 0
    while os.path.isdir(storage.round_directory(out, index)):
        if not os.path.isfile(os.path.join(storage.round_directory(out, index),
                                           storage.SWEEP_FILE)):
            return True
        index += 1
    return False


def _record_round(out, index, fingerprint):
    """Record round ``index``'s fingerprint in the directory's record before it runs; a
    ValueError if another one is recorded there (its rows would not be this sweep's)."""
    stored = storage.read_seeds_file(out)
    rounds = stored.setdefault("rounds", [])
    if index < len(rounds):
        if rounds[index] != fingerprint:
            raise ValueError(f"{storage.round_directory(out, index)!r} was planned with other "
                             "cases "
                             "than this sweep's rows now ask for (a round replaced, or rows "
                             "changed); use another --out")
        return
    stored["rounds"] = rounds + [fingerprint]
    storage.write_seeds_file(out, stored)


def check_size(cells, targets):
    """ValueError unless the most cases the sweep can reach (every cell at
    ``max_seeds``) fit in one sweep's ``validation.MAX_CASES``: checked before any work."""
    largest = len(cells) * targets.max_seeds
    if largest > validation.MAX_CASES:
        raise ValueError(f"--seeds auto could reach {len(cells)} points x --max-seeds "
                         f"{targets.max_seeds} = {largest} cases, more than a sweep's "
                         f"{validation.MAX_CASES}: lower --max-seeds or split the grid")


def _groups(rows):
    if rows is None or not len(rows):
        return {}
    return {key: group.sort_values("seed") for key, group in rows.groupby(list(CELL_KEYS))}


def _sampled(rows, targets):
    """Whether a cell with finished ``rows`` is checked in distribution (and so runs its
    later seeds without twins): its runs are samples and ``check_seeds`` > 0."""
    return targets.check_seeds > 0 and len(rows) > 0 and seeds_auto_rule.runs_are_samples(rows)


def plan_round(cells, rows, targets, twins=True):
    """The next round's cases: for each cell (a case dict; its seed is ignored) whose rows
    so far (``rows``, a DataFrame or None) do not decide it, the seeds from its count up to
    the size ``seeds_auto_rule.decide`` asks for; without twins (``twin=False``) where the sweep
    runs them (``twins``) but the cell's runs are samples."""
    groups = _groups(rows)
    cases = []
    for cell in cells:
        have = groups.get(cell_key(cell), _NO_ROWS)
        reason, wanted = seeds_auto_rule.decide(have, targets)
        if reason == seeds_auto_rule.CONTINUE:
            extra = dict(twin=False) if twins and _sampled(have, targets) else {}
            cases.extend(dict(cell, seed=seed, **extra) for seed in range(len(have), wanted))
    return cases


def expected_costs(cases, rows, twins=True):
    """{case index: expected seconds} of a round's cases from their cells' finished rows:
    the mean of ``wall_s``, scaled by (nfev + twin_nfev) / nfev where the case runs its
    twin (``twins`` and not ``twin=False``); None for a round with a cell that has no rows
    yet (the first)."""
    groups = _groups(rows)
    costs = {}
    for i, case in enumerate(cases):
        have = groups.get(cell_key(case))
        if have is None or not len(have):
            return None
        nfev = have["nfev"].to_numpy(float).clip(1.0)
        twin = (1.0 + have["twin_nfev"].to_numpy(float) / nfev
                if twins and case.get("twin", True) else 1.0)
        costs[i] = float((have["wall_s"].to_numpy(float) * twin).mean())
    return costs


def _twinned(rows):
    """The rows whose twin's outcome is recorded (``twin_regime``)."""
    if "twin_regime" not in rows:
        return rows.iloc[:0]
    return rows[rows["twin_regime"].notna()]


def plan_check(cells, rows, targets):
    """The distribution check's cases: for each sampled cell (:func:`_sampled`), the
    stricter sample is its twins (each the run of its seed at the stricter tolerances,
    recorded in its row) topped up to ``check_seeds`` with seeds that ran without a twin,
    in seed order: those are the cases to run."""
    groups = _groups(rows)
    cases = []
    for cell in cells:
        have = groups[cell_key(cell)]
        if _sampled(have, targets):
            need = max(0, targets.check_seeds - len(_twinned(have)))
            untwinned = sorted(int(s) for s in have["seed"][~have.index.isin(
                _twinned(have).index)])
            cases.extend(dict(cell, seed=seed) for seed in untwinned[:need])
    return cases


def stricter_sample(cells, rows, targets, checks):
    """The stricter sample of every sampled cell: its twins' outcomes (as rows: regime,
    tilt and aspect ratio the twin's) and its check runs (``checks``, or None)."""
    groups = _groups(rows)
    twins = [_twinned(groups[cell_key(cell)]) for cell in cells
             if _sampled(groups[cell_key(cell)], targets)]
    twins = [t.assign(regime=t["twin_regime"], theta_final_deg=t["twin_theta_final_deg"],
                      aspect_ratio=t["twin_aspect_ratio"]) for t in twins if len(t)]
    frames = twins + ([checks] if checks is not None and len(checks) else [])
    return pd.concat(frames, ignore_index=True) if frames else None


def check_config(config, cases):
    """The check's configuration: ``cases`` at the twins' stricter tolerances
    (``outcomes.twin_tolerances``), without twins."""
    rtol, atol, tail_tol = outcomes.twin_tolerances(config.rtol, config.atol, config.tail_tol)
    return dataclasses.replace(config, cases=cases, rtol=rtol, atol=atol, tail_tol=tail_tol,
                               twin=False)


#: The check's columns in the stop table, from ``outcome_statistics.compare``.
CHECK_COLUMNS = {"seeds_b": "check_seeds", "verdict": "check_verdict",
                 "tilt_ks_p": "check_tilt_ks_p", "aspect_ks_p": "check_aspect_ks_p",
                 "regime_p": "check_regime_p", "tilt_wasserstein": "check_tilt_wasserstein"}


def _runs(rows):
    """How a cell's answer was decided: "none" (no run succeeded), "samples"
    (``seeds_auto_rule.runs_are_samples``) or "trajectories"."""
    if not seeds_auto_rule.any_succeeded(rows):
        return "none"
    return "samples" if seeds_auto_rule.runs_are_samples(rows) else "trajectories"


def stop_table(cells, rows, targets, checks=None):
    """One row per cell: its inputs, seeds, rounds, stop reason and interval half-widths;
    how its answer was decided (``runs``: "trajectories", each twin-checked or
    deterministic, "samples", or "none" where every run failed; ``twins``: rows with a
    twin) and, for sampled cells, the
    distribution check against its stricter sample (``check_seeds`` of them: its twins and
    its check runs, ``checks``; :func:`stricter_sample`)."""
    groups = _groups(rows)
    table = pd.DataFrame([
        dict(seeds_auto_rule.cell_record(CELL_KEYS, cell_key(cell), groups[cell_key(cell)], targets,
                                 int(groups[cell_key(cell)]["round"].max()) + 1),
             runs=_runs(groups[cell_key(cell)]),
             twins=int(groups[cell_key(cell)]["determined"].notna().sum()))
        for cell in cells])
    empty = dict(check_seeds=0, check_verdict="", **{
        name: float("nan") for name in CHECK_COLUMNS.values()
        if name not in ("check_seeds", "check_verdict")})
    table = table.assign(**empty)
    stricter = stricter_sample(cells, rows, targets, checks)
    if stricter is not None:
        sampled = pd.concat([groups[cell_key(cell)] for cell in cells
                             if _sampled(groups[cell_key(cell)], targets)])
        verdicts = outcome_statistics.compare(sampled, stricter, by=list(CELL_KEYS)).rename(
            columns=CHECK_COLUMNS)
        keys = list(CELL_KEYS)
        table = table.drop(columns=list(CHECK_COLUMNS.values())).merge(
            verdicts[keys + list(CHECK_COLUMNS.values())], on=keys, how="left")
        table["check_seeds"] = table["check_seeds"].fillna(0).astype("int64")
        table["check_verdict"] = table["check_verdict"].fillna("")
    table["n"] = table["n"].astype("int64")  # an order (every cell has one): never a float
    return table


def run_seeds_auto(config, out, targets, *, run_round, command_line=None, announce=None):
    """Run (or resume) ``--seeds auto`` into ``out``; returns (rows, stop table).

    ``config``: the sweep's configuration with one case per cell (its seed ignored);
    ``run_round(config, directory, weights)``: runs one ordinary sweep and returns its
    rows (the caller's backend and progress; ``weights``: the cases' expected costs, or
    None, for ``run_sweep``); ``announce(text)``: called with one line per round.  Once
    every cell has stopped, the cells whose runs are samples are checked in distribution
    (:func:`plan_check`, in ``out/check``; not with ``config.twin`` False: no stricter
    runs at all) and the stop table records the verdicts.
    Every input is checked before anything is written; a command that fails before its
    first round leaves nothing behind.  A finished directory (its stop table written) is
    read back, not planned again (a ``--rerun-failed`` may have replaced failed rows),
    unless a round has lost its ``_sweep.json``: planned again, the rounds resume and the
    lost file is rewritten (a round whose rows a rerun changed may then be refused).
    """
    targets.check()
    cells = [dict(case, seed=0) for case in config.cases]
    validate(dataclasses.replace(config, cases=cells))  # distinct cells among the rest
    check_size(cells, targets)
    directories = _make_directory(out)
    try:
        with lock.acquire(out, lock.holder(_fingerprint(config, targets)), command_line):
            return _run_rounds(config, out, targets, cells, run_round, command_line, announce)
    except BaseException:
        _undo(directories)  # those this call made, if empty (the record is gone with them)
        raise


def _run_rounds(config, out, targets, cells, run_round, command_line, announce):
    """:func:`run_seeds_auto` in the directory ``out``, held by this command."""
    made = prepare(out, config, targets, command_line)
    if (not made and os.path.isfile(os.path.join(out, storage.STOPS_FILE))
            and not _round_record_missing(out)):
        return storage.read_seeds_auto(out), storage.read_stop_table(out)
    rows = None
    index = 0
    existing = 0  # rounds already there (a record rebuilt: :func:`prepare`)
    while made and os.path.isdir(storage.round_directory(out, existing)):
        existing += 1
    try:
        while True:
            cases = plan_round(cells, rows, targets, twins=config.twin)
            if not cases:
                break
            if announce is not None:
                sampled = sum(not c.get("twin", True) for c in cases)
                announce(f"seeds auto: round {index}: {len({cell_key(c) for c in cases})} of "
                         f"{len(cells)} cells open, {len(cases)} cases"
                         + (f" ({sampled} without twins: their cells' runs are samples)"
                            if sampled else ""))
            round_config = dataclasses.replace(config, cases=cases)
            _record_round(out, index, storage.config_fingerprint(
                json.loads(json.dumps(round_config.as_dict()))))
            frame = run_round(round_config, storage.round_directory(out, index),
                              expected_costs(cases, rows, config.twin)).assign(round=index)
            rows = frame if rows is None else pd.concat([rows, frame], ignore_index=True)
            index += 1
    except BaseException as exc:
        # a record made by this call goes again when it added no rows: a fresh
        # directory's, or one rebuilt that a round already there refused (other options)
        refused = isinstance(exc, ValueError) and index < existing
        if made and (refused or not os.path.isdir(storage.round_directory(out, 0))):
            _undo(made)
        raise
    checks = None
    cases = plan_check(cells, rows, targets) if config.twin else []  # --no-twin: no check
    if cases:  # (a cell whose twins make up check_seeds is checked against them alone)
        if announce is not None:
            announce(f"seeds auto: distribution check: {len({cell_key(c) for c in cases})} "
                     f"cells whose runs are samples, {len(cases)} cases at 10x stricter "
                     "tolerances")
        checks = run_round(check_config(config, cases), os.path.join(out, storage.CHECK_DIR),
                           expected_costs(cases, rows, twins=False))
    table = stop_table(cells, rows, targets, checks)
    write_stop_table(out, table, targets)
    return storage.read_seeds_auto(out), table


def write_stop_table(out, table, targets):
    """Write the stop table ``table`` of the ``--seeds auto`` directory ``out`` (atomically,
    each column described, the targets in its metadata)."""
    meta = storage.provenance(seeds_auto_targets=json.dumps(dataclasses.asdict(targets)))
    storage.write_table_atomically(
        storage.described(pa.Table.from_pandas(table, preserve_index=False)
                          .replace_schema_metadata(meta), columns.STOP_COLUMNS),
        os.path.join(out, storage.STOPS_FILE))


def rerun_cells(out):
    """The cells (:func:`cell_key`) of the ``--seeds auto`` directory ``out`` holding a
    case whose failed run a merged ``--rerun-failed`` attempt replaced (from each round's
    ``_sweep.json``)."""
    cells = set()
    index = 0
    while os.path.isdir(storage.round_directory(out, index)):
        stored = storage.read_sweep_file(storage.round_directory(out, index)) or {}
        cases = stored.get("config", {}).get("cases", [])
        for attempt in stored.get("reruns", []):
            if attempt.get("merged"):
                cells.update(cell_key(cases[i]) for i in attempt["case_ids"])
        index += 1
    return cells


def restate_stop_table(out):
    """After ``--rerun-failed`` replaced failed runs of the finished ``--seeds auto``
    directory ``out``: the stop table's rows of the cells it touched (:func:`rerun_cells`)
    computed again from their rows now (seeds, stop reason, interval half-widths, how
    their answer was decided, the distribution check), so that nothing derived from it
    says "failed" of a cell with successful seeds.  A cell the rule would now give more
    seeds (``seeds_auto_rule.CONTINUE``) stops as ``seeds_auto_rule.RESCUED``: a finished
    sweep adds none.  The other rows stay as written.  Returns the table."""
    stops = storage.read_stop_table(out)
    touched = rerun_cells(out)
    keys = [tuple(float(v) for v in row) for row in stops[list(CELL_KEYS)].to_numpy()]
    if not touched & set(keys):
        return stops
    record = storage.read_seeds_file(out)
    targets = seeds_auto_rule.SeedTargets(**record["targets"])
    cells = [dict(case, seed=0) for case in record["config"]["cases"]]
    check = os.path.join(out, storage.CHECK_DIR)
    checks = storage.read_results(check) if os.path.isdir(check) else None
    fresh = stop_table(cells, storage.read_seeds_auto(out), targets, checks)
    fresh["stop_reason"] = fresh["stop_reason"].replace(seeds_auto_rule.CONTINUE,
                                                        seeds_auto_rule.RESCUED)
    fresh_keys = [tuple(float(v) for v in row) for row in fresh[list(CELL_KEYS)].to_numpy()]
    by_key = dict(zip(fresh_keys, range(len(fresh))))
    rows = [fresh.iloc[by_key[key]] if key in touched else stops.iloc[i]
            for i, key in enumerate(keys)]
    table = pd.DataFrame(rows, columns=stops.columns).reset_index(drop=True).astype(
        stops.dtypes.to_dict())
    if not table.equals(stops):
        write_stop_table(out, table, targets)
    return table
