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

The program's standard streams (:func:`guard_streams`): a stream closed at start
(``2>&-``) is given ``/dev/null``, so that no file the program opens takes its number; a
diagnostics stream (stderr) that is closed or whose reader has gone never stops the
work (what would be said is dropped); stdout whose reader has gone (``| head -1``) is
noted (:func:`stdout_gone`) and its writes end the command, which then exits quietly
(``exit_codes.EXIT_BROKEN_PIPE``).
"""
import errno
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
    try:
        os.write(2, f"loopsim: interrupted by {name}: stopped (files already written are "
                    "complete; a sweep resumes when re-run)\n".encode())
    except OSError:  # stderr's reader has gone: nothing to say it to
        pass
    end_children()
    remove_temporaries()
    os._exit(128 + signum)


def install_early():
    """For the ``loopsim`` program: its standard streams guarded (:func:`guard_streams`);
    SIGINT and SIGTERM exit at once, in one line."""
    if is_program():
        guard_streams()
        for signum in (signal.SIGINT, signal.SIGTERM):
            signal.signal(signum, _exit_at_once)


# ---- the standard streams ---------------------------------------------------------------
#: errno values of a stream that cannot take more output: its reader has gone (EPIPE), it
#: was closed (EBADF), or the terminal hung up (EIO).
_STREAM_GONE = frozenset({errno.EPIPE, errno.EBADF, errno.EIO})


def _open_null(fd):
    """Put ``/dev/null`` at file descriptor ``fd`` (for reading at 0, writing elsewhere)."""
    null = os.open(os.devnull, os.O_RDONLY if fd == 0 else os.O_WRONLY)
    if null != fd:
        os.dup2(null, fd)
        os.close(null)


class GuardedStream:
    """A text stream (``sys.stdout`` or ``sys.stderr``) whose writes cannot fail for a
    reader gone or a descriptor closed: on the first such error the descriptor gets
    ``/dev/null`` (so that nothing buffered fails again at exit) and later output is
    dropped.  ``raises``: whether that first error is raised again (stdout: the command's
    output is lost, so the command stops) or swallowed (stderr: diagnostics never stop
    the work).  Everything else is the wrapped stream's."""

    def __init__(self, stream, fd, raises):
        self._stream, self._fd, self._raises = stream, fd, raises
        self.gone = False

    def _failed(self, exc):
        if not isinstance(exc, OSError) or exc.errno not in _STREAM_GONE:
            raise exc
        if not self.gone:
            self.gone = True
            _open_null(self._fd)
            self._stream = open(os.devnull, "w")  # noqa: SIM115 - lives as long as the stream
            if self._raises:
                raise exc

    def write(self, text):
        try:
            return self._stream.write(text)
        except OSError as exc:
            self._failed(exc)
            return len(text)

    def flush(self):
        try:
            self._stream.flush()
        except OSError as exc:
            self._failed(exc)

    def __getattr__(self, name):
        return getattr(self._stream, name)


def guard_streams():
    """Guard the program's standard streams (see the module's docstring): descriptors 0-2
    closed at start get ``/dev/null`` (Python then has no ``sys.stderr``: it gets one), and
    ``sys.stdout`` and ``sys.stderr`` become :class:`GuardedStream` s."""
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            _open_null(fd)
    for name, fd in (("stdout", 1), ("stderr", 2)):
        stream = getattr(sys, name)
        if isinstance(stream, GuardedStream):
            continue
        if stream is None:  # closed at start: Python made no stream for it
            stream = open(fd, "w", buffering=1, errors="backslashreplace",  # noqa: SIM115
                          closefd=False)
        setattr(sys, name, GuardedStream(stream, fd, raises=name == "stdout"))


def stdout_gone():
    """Whether the program's stdout lost its reader (``| head -1``) while a command wrote."""
    return getattr(sys.stdout, "gone", False) is True
