"""Reruns of a sweep's failed cases with another method or tolerances, each attempt a
sweep of its own merged back into the directory's result files."""
import dataclasses
import os

import pyarrow as pa

from .. import refinement, storage, validation
from ..outcomes import Thresholds
from . import lock
from .cases import SweepConfig
from .orchestrate import run_sweep
from .seeds_auto import restate_stop_table


def config_from_dict(stored):
    """The SweepConfig of a stored configuration (``_sweep.json``'s ``config``)."""
    fields = {f.name for f in dataclasses.fields(SweepConfig)}
    values = {k: v for k, v in stored.items() if k in fields}
    values["thresholds"] = Thresholds(**stored.get("thresholds", {}))
    return SweepConfig(**values)


def rerun_failed(out, method, rtol, atol, **backend):
    """Rerun the failed cases of sweep ``out`` with another method (None: the sweep's) or
    tolerances.

    Attempt k is a sweep of its own in ``out/_reruns/k`` (the failed cases, the settings
    changed, no snapshots): re-running the same call resumes it.  Once it is complete,
    every result file holding those cases is rewritten with the new rows (its metadata
    lists the attempt) after the original was copied to ``out/_reruns/k/replaced/``.
    Returns (the results DataFrame, the number of cases rerun).  ``backend``: as for
    :func:`run_sweep` (threads, quiet, scheduler, local_cluster, workers, ...).  The
    directory is held (``lock``) throughout: refused while any sweep runs in it.
    """
    if method is not None:
        validation.check_choice("--method", method, refinement.METHOD_CHOICES)
    validation.check_real("--rtol", rtol, low=0.0, low_open=True)  # before anything is
    validation.check_real("--atol", atol, low=0.0)  # recorded: a refused rerun leaves no trace
    if os.path.isdir(out) and storage.is_seeds_auto(out):
        with lock.acquire(out, lock.holder(None, exclusive=True)):
            return _rerun_rounds(out, method, rtol, atol, **backend)
    stored = storage.read_sweep_file(out) if os.path.isdir(out) else None
    if stored is None:
        raise ValueError(f"no sweep at {out!r} (no {storage.SWEEP_FILE}) to rerun failed cases of")
    storage.check_layout(out)
    with lock.acquire(out, lock.holder(stored["fingerprint"], exclusive=True)):
        stored = storage.read_sweep_file(out)  # as it is now that no one else writes it
        return _rerun_sweep(out, stored, method, rtol, atol, **backend)


def _rerun_sweep(out, stored, method, rtol, atol, **backend):
    """:func:`rerun_failed` on the sweep directory ``out`` (its decoded ``_sweep.json``:
    ``stored``), held by this command."""
    base = config_from_dict(stored["config"])
    settings = dict(method=method or base.method, rtol=rtol, atol=atol)
    reruns = stored.get("reruns", [])
    open_attempt = next((r for r in reruns if not r["merged"]), None)
    if open_attempt is not None and open_attempt["settings"] != settings:
        raise ValueError(f"rerun {open_attempt['attempt']} of {out!r} is unfinished with "
                         f"{open_attempt['settings']}: finish it first (same options)")
    if open_attempt is None:
        frame = storage.read_results(out)
        failed = sorted(int(i) for i in frame.loc[frame["status"] != "ok", "case_id"])
        if not failed:
            return frame, 0
        current = {key: frame.set_index("case_id").loc[failed, key].unique().tolist()
                   for key in ("rtol", "atol")}
        if (current["rtol"] == [rtol] and current["atol"] == [atol]
                and base.method == method and not reruns):
            raise ValueError(f"the failed cases of {out!r} ran with these settings already; "
                             "give another --method, --rtol or --atol")
        open_attempt = dict(attempt=len(reruns) + 1, settings=settings, case_ids=failed,
                            merged=False)
        stored["reruns"] = reruns + [open_attempt]
        storage.write_record_atomically(stored, os.path.join(out, storage.SWEEP_FILE))
    ids = open_attempt["case_ids"]
    directory = os.path.join(out, storage.RERUN_DIR, str(open_attempt["attempt"]))
    config = dataclasses.replace(base, cases=[base.cases[i] for i in ids], snapshots_for=[],
                                 **settings)
    rerun = run_sweep(config, directory, **backend)
    _merge_rerun(out, stored["fingerprint"], directory, open_attempt["attempt"],
                 rerun.assign(case_id=[ids[i] for i in rerun["case_id"]]))
    open_attempt["merged"] = True
    storage.write_record_atomically(stored, os.path.join(out, storage.SWEEP_FILE))
    return storage.read_results(out), len(ids)


def _rerun_rounds(out, method, rtol, atol, **backend):
    """:func:`rerun_failed` on a finished ``--seeds auto`` directory: each round with failed
    cases is a sweep of its own, rerun in place.  The stop table's rows of the cells
    rerun are then decided again from their rows now (``seeds_auto.restate_stop_table``:
    a cell stopped as failed whose seeds were rescued no longer reads failed);
    ``read_results`` and ``summary`` read the rows as they are now."""
    if not os.path.isfile(os.path.join(out, storage.STOPS_FILE)):
        raise ValueError(f"the --seeds auto sweep in {out!r} has not finished: re-run its "
                         "command first (its later rounds are planned from these rows)")
    rows = storage.read_results(out)  # every round checked before any rerun
    reran = 0
    for index in sorted(rows.loc[rows["status"] != "ok", "round"].unique()):
        directory = storage.round_directory(out, int(index))
        stored = storage.read_sweep_file(directory)
        last = (stored.get("reruns") or [None])[-1]
        settings = dict(method=method or stored["config"]["method"], rtol=rtol, atol=atol)
        if last is not None and last["merged"] and last["settings"] == settings:
            continue  # rerun with these settings by an earlier, interrupted call
        reran += rerun_failed(directory, method, rtol, atol, **backend)[1]
    restate_stop_table(out)  # also where an earlier call was cut short before it
    return storage.read_results(out), reran


def _merge_rerun(out, fingerprint, directory, attempt, rows):
    """Put the rerun ``rows`` (case ids of the sweep) into the result files holding those
    cases; a file already carrying ``attempt`` in its metadata is done (so a merge cut
    short by a kill resumes)."""
    replaced = os.path.join(directory, "replaced")
    storage.make_directories(replaced)
    new = pa.Table.from_pandas(rows, schema=storage.RESULT_SCHEMA, preserve_index=False)
    by_id = set(rows["case_id"])
    for (start, stop), path in sorted(storage.chunk_files(out).items()):
        meta = storage.read_metadata(path)
        if attempt in meta.get("reruns", []):
            continue
        written = storage.read_table_checked(path, storage.requires_hash(storage.read_sweep_file(out)))
        table = storage.result_table(written)
        mask = [i in by_id for i in table.column("case_id").to_pylist()]
        if not any(mask):
            continue
        storage.write_table_atomically(written, os.path.join(replaced, os.path.basename(path)))
        keep = table.filter(pa.array([not m for m in mask]))
        ids = set(table.column("case_id").to_pylist())
        fresh = new.filter(pa.array([i in ids for i in new.column("case_id").to_pylist()]))
        merged = pa.concat_tables([keep, fresh]).sort_by("case_id")
        meta = storage.provenance(sweep_fingerprint=fingerprint, positions=[start, stop],
                             reruns=meta.get("reruns", []) + [attempt])
        storage.write_table_atomically(merged.replace_schema_metadata(meta), path)
