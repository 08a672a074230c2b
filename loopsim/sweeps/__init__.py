"""Ensemble sweeps: cases -> pieces -> Parquet files in a directory, resumable.

A sweep directory is a Parquet dataset (``pandas.read_parquet(DIR)`` returns the
rows): ``_sweep.json`` (the configuration and its fingerprint, written once,
first), one ``chunk-SSSSSSS-EEEEEEE.parquet`` per finished piece at the top,
snapshots in ``_snapshots/``.  Cases are laid out in a fixed order of positions
(:func:`case_order`, a golden-ratio stride, so neighbours differ); chunk k is
positions [k c, (k + 1) c) for chunk size c, and a file holds the positions
[S, E) of a finished piece of a chunk, written under a temporary name and
renamed into place.  A resume computes the positions no file holds, so a
changed chunk size, a piece cut short by a signal and job-array shards all
fit.  Cases run on a work queue of this machine's threads or as Dask tasks.  No numerics
here: integration is ``batch``, start shapes ``shapes``, summaries ``api``,
tables ``storage``.

One module per job, each layer importing only those above it:

* ``cases``: the configuration (:class:`SweepConfig`), grids, cases files, checks;
* ``chunks``: positions, chunks and the pieces still to compute;
* ``directory``: the sweep directory made, checked, repaired and written into;
* ``lock``: one command at a time in a directory (shards of one sweep side by side);
* ``runner``: a piece's cases integrated into rows (:func:`run_chunk`, :func:`run_piece`);
* ``progress``: the progress line and its cost-weighted ETA;
* ``signals``: SIGINT / SIGTERM as a stop flag (:class:`SweepInterrupted`);
* ``local``, ``dask_backend``: the backends (a work queue of threads, Dask tasks);
* ``orchestrate``: :func:`run_sweep` and :func:`sweep`, the top level;
* ``rerun``: reruns of the failed cases (:func:`rerun_failed`);
* ``seeds_auto``: ``--seeds auto``, rounds of sweeps until each cell is sharp
  (:func:`run_seeds_auto`).

This package's names are the public API of sweeps; ``loopsim.ensemble``, their
earlier home, re-exports them unchanged.
"""
from ..outcomes import REGIMES, Thresholds, classify
from .cases import (
    CASE_COLUMNS, CASE_OVERRIDES, SweepConfig, case_option, grid_cases, parse_values,
    read_cases_file, validate,
)
from .chunks import canonical_chunks, case_order, chunk_case_ids, pending_pieces
from .directory import FIELD_NOTES, repair_directory, write_piece
from .orchestrate import run_sweep, sweep, warn_mixed_columns
from .progress import AUTO_COST_EXPONENT, Progress, case_weight
from .rerun import config_from_dict, rerun_failed
from .runner import case_ladder, case_method, run_chunk, run_piece
from .seeds_auto import run_seeds_auto
from .signals import SweepInterrupted, in_background, stop_event, stop_on_signals

__all__ = [
    "AUTO_COST_EXPONENT", "CASE_COLUMNS", "CASE_OVERRIDES", "FIELD_NOTES", "Progress",
    "REGIMES", "SweepConfig", "SweepInterrupted", "Thresholds", "canonical_chunks",
    "case_ladder", "case_method", "case_option", "case_order", "case_weight",
    "chunk_case_ids", "classify", "config_from_dict", "grid_cases", "in_background",
    "parse_values", "pending_pieces", "read_cases_file", "repair_directory", "rerun_failed",
    "run_chunk", "run_piece", "run_seeds_auto", "run_sweep", "stop_event",
    "stop_on_signals", "sweep", "validate", "warn_mixed_columns", "write_piece",
]
