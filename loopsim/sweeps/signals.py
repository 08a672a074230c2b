"""Stopping on a signal: SIGINT and SIGTERM set a flag that a sweep (or ``loopsim run``)
checks, so finished work is written before :class:`SweepInterrupted` is raised."""
import contextlib
import ctypes
import signal
import sys
import threading


class SweepInterrupted(KeyboardInterrupt):
    """A sweep stopped by SIGINT or SIGTERM; every finished case was written first.
    ``exit_status``: 128 + the signal number (130, 143)."""

    def __init__(self, signum, out, done, total):
        super().__init__(f"interrupted by {signal.Signals(signum).name}")
        self.signum, self.out, self.done, self.total = signum, out, done, total
        self.exit_status = 128 + signum


# The one signal handling of every command that runs kernels (sweeps and ``loopsim run``).
@contextlib.contextmanager
def stop_on_signals(stop):
    """While running, SIGINT and SIGTERM set ``stop`` (a threading.Event, its ``signum``
    attribute the signal) instead of raising: the sweep notices within 0.1 s, writes
    what has finished and raises :class:`SweepInterrupted`.  Outside the main thread
    (no signals there) this does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        stop.signum = signum
        stop.set()

    previous = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


#: The operating system's name of :func:`in_background`'s thread (Linux: /proc/PID/task/
#: TID/comm, at most 15 bytes), so that ``top -H``, profilers and tests can tell the
#: integration apart from the threads of loading and compiling.
NATIVE_THREAD_NAME = "loopsim-work"


def _name_native_thread(name):
    """Give the calling thread ``name`` in the operating system (Linux prctl(PR_SET_NAME);
    elsewhere nothing)."""
    if sys.platform.startswith("linux"):
        try:
            ctypes.CDLL(None).prctl(15, name.encode()[:15], 0, 0, 0)  # 15: PR_SET_NAME
        except (OSError, AttributeError):
            pass


def in_background(stop, function, *args):
    """function(*args) in a daemon thread, waited for in slices of 0.1 s; its result (its
    exception re-raised), or None once ``stop`` is set: then the thread runs on unused
    (a Numba kernel cannot be cut short; the process is about to exit)."""
    box = {}

    def target():
        _name_native_thread(NATIVE_THREAD_NAME)
        try:
            box["result"] = function(*args)
        except BaseException as exc:  # noqa: BLE001 - handed to the waiting thread
            box["error"] = exc

    thread = threading.Thread(target=target, daemon=True, name="loopsim-sweep-unit")
    thread.start()
    while thread.is_alive():
        thread.join(0.1)
        if stop.is_set():
            return None
    if "error" in box:
        raise box["error"]
    return box["result"]


def stop_event():
    """A stop flag for :func:`stop_on_signals`: a threading.Event with ``signum`` None."""
    stop = threading.Event()
    stop.signum = None
    return stop
