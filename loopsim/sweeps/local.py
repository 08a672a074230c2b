"""The local backend: a sweep's pieces on a work queue served by this machine's
threads, one Numba thread each."""
import queue
import threading

import pyarrow as pa

from .._blas import one_blas_thread
from .directory import write_piece
from .progress import case_seconds, failures
from .chunks import chunk_case_ids
from .runner import run_chunk


def _joined(parts):
    """Finished tasks [(positions, results, snapshots)] of consecutive positions, in
    order -> one (positions, results, snapshots)."""
    snapshots = [p[2] for p in parts if p[2] is not None]
    return (range(parts[0][0].start, parts[-1][0].stop), pa.concat_tables([p[1] for p in parts]),
            pa.concat_tables(snapshots) if snapshots else None)


def _write_unfinished(out, fingerprint, piece, parts):
    """Write the finished tasks {start: (positions, results, snapshots)} of an unfinished
    piece: those from the piece's start as one shorter piece, each later one on its own."""
    done = [parts[k] for k in sorted(parts)]
    prefix, reached = 0, piece.start
    while prefix < len(done) and done[prefix][0].start == reached:
        reached = done[prefix][0].stop
        prefix += 1
    if prefix:
        write_piece(out, fingerprint, *_joined(done[:prefix]))
    for task in done[prefix:]:
        write_piece(out, fingerprint, *task)


def _queue_worker(config, tasks, results, halt):
    """One worker thread of :func:`run_local`: tasks (piece index, positions) from
    ``tasks`` until it is empty or ``halt`` is set, each on one Numba thread (the kernels
    release the GIL), their outputs or the first exception onto ``results``."""
    import numba

    numba.set_num_threads(1)  # per thread in Numba: set in the thread that runs
    while not halt.is_set():
        try:
            index, part = tasks.get_nowait()
        except queue.Empty:
            return
        try:
            results.put((index, part, run_chunk(config, part, 1), None))
        except BaseException as exc:  # noqa: BLE001 - handed to the sweep's thread
            results.put((index, part, None, exc))
            return


def run_local(config, out, fingerprint, pieces, threads, unit, progress, stop, weights=None):
    """The pieces' cases on a work queue served by ``threads`` worker threads, one Numba
    thread each: the pieces costliest first by ``weights`` ({case id: expected cost};
    longest processing time first keeps every core busy to the end), each piece's tasks of
    ``unit`` consecutive positions in position order, go to whichever worker is free, so a
    costly case holds up one core, not the others.  A
    piece is written as soon as all its tasks are done.  On a stop request (or an
    error) no task starts any more; of each unfinished piece, the finished tasks from
    its start are written as one shorter piece and every later finished task as a piece
    of its own (so identical sweeps stopped side by side write identical, disjoint or
    nested files, never overlapping ones); the running tasks are lost (their threads
    run on, unseen, until the kernel returns)."""
    tasks, results, halt = queue.SimpleQueue(), queue.SimpleQueue(), threading.Event()
    count = 0
    order = range(len(pieces)) if weights is None else sorted(
        range(len(pieces)), key=lambda k: -sum(weights[i] for i in chunk_case_ids(
            config, pieces[k])))
    for index in order:
        piece = pieces[index]
        for start in range(piece.start, piece.stop, unit):
            tasks.put((index, range(start, min(start + unit, piece.stop))))
            count += 1
    finished = {}  # piece index -> {task start: (positions, results, snapshots)}
    left = [len(piece) for piece in pieces]  # positions still to finish, per piece
    error = None

    def collect(index, part, output):
        finished.setdefault(index, {})[part.start] = (part,) + tuple(output)
        progress.update(output[0].column("case_id").to_pylist(), failures(output[0]),
                        case_seconds(output[0]))
        left[index] -= len(part)
        if not left[index]:
            parts = finished.pop(index)
            write_piece(out, fingerprint, *_joined([parts[k] for k in sorted(parts)]))

    with one_blas_thread():  # BLAS's own threads would oversubscribe the cores
        for k in range(min(threads, count)):
            threading.Thread(target=_queue_worker, args=(config, tasks, results, halt),
                             daemon=True, name=f"loopsim-sweep-{k}").start()
        try:
            while count and error is None and not stop.is_set():
                try:
                    index, part, output, error = results.get(timeout=0.1)
                except queue.Empty:
                    continue
                count -= 1
                if error is None:
                    collect(index, part, output)
        finally:
            halt.set()  # workers finish their running task and stop
            while True:  # results already handed over are kept
                try:
                    index, part, output, late_error = results.get_nowait()
                except queue.Empty:
                    break
                if late_error is None:
                    collect(index, part, output)
            for index, parts in finished.items():
                _write_unfinished(out, fingerprint, pieces[index], parts)
    if error is not None:
        raise error
