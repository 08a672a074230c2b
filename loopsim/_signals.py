"""Ctrl-C from the first instant of the ``loopsim`` program.

Loading the package (NumPy, Numba, pandas) and compiling kernels take seconds, before
any command installs its own signal handling.  For the ``loopsim`` program (never for a
Python user importing the package) :func:`install_early` makes SIGINT and SIGTERM end the
process in those seconds with one line and exit status 128 + signum (130, 143), without
a traceback.  Commands replace the handler with their own while they work (a sweep keeps
what has finished; ``sweeps.stop_on_signals``) and restore it afterwards.

Ending at once (``os._exit``) skips the cleanup of an atomic write in progress
(``storage.integrity``), so the temporary files this process is writing are registered here
(:func:`track_temporary`) and removed before it exits (:func:`remove_temporaries`).
"""
import os
import signal
import sys


def is_program(argv=None, orig_argv=None):
    """Whether this process is the ``loopsim`` command: its console script, or
    ``python -m loopsim`` (whose sys.argv[0] is still "-m" while the package loads)."""
    argv = sys.argv if argv is None else argv
    orig_argv = getattr(sys, "orig_argv", []) if orig_argv is None else orig_argv
    program = os.path.abspath(argv[0]) if argv and argv[0] not in ("", "-m", "-c") else ""
    if os.path.basename(program) == "loopsim" or program.endswith(
            os.path.join("loopsim", "__main__.py")):
        return True
    return any(a == "-m" and b == "loopsim" for a, b in zip(orig_argv, orig_argv[1:]))


#: Temporary files of atomic writes in progress in this process (``storage.integrity``).
_TEMPORARIES = set()


def track_temporary(path):
    """Register ``path``, a temporary file this process is writing, for
    :func:`remove_temporaries`."""
    _TEMPORARIES.add(path)


def untrack_temporary(path):
    """Forget ``path`` (renamed into place, or removed)."""
    _TEMPORARIES.discard(path)


def remove_temporaries():
    """Remove the registered temporary files (the process is ending without their own
    cleanup: a write cut short leaves no ``.tmp-*`` file)."""
    for path in list(_TEMPORARIES):
        try:
            os.remove(path)
        except OSError:
            pass
        _TEMPORARIES.discard(path)


def end_children():
    """Kill what the program started and has not ended (Dask workers, multiprocessing's
    resource tracker), so that it leaves no orphan and no orphan's warning behind."""
    try:
        import psutil  # installed with dask.distributed
    except ImportError:
        return
    children = psutil.Process().children(recursive=True)
    for child in children:
        try:
            child.kill()
        except psutil.Error:
            pass
    psutil.wait_procs(children, timeout=1.0)


def _exit_at_once(signum, frame):
    name = signal.Signals(signum).name
    os.write(2, f"loopsim: interrupted by {name}: stopped (files already written are "
                "complete; a sweep resumes when re-run)\n".encode())
    end_children()
    remove_temporaries()
    os._exit(128 + signum)


def install_early():
    """For the ``loopsim`` program: SIGINT and SIGTERM exit at once, in one line."""
    if is_program():
        for signum in (signal.SIGINT, signal.SIGTERM):
            signal.signal(signum, _exit_at_once)
