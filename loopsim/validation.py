"""Input checks shared by every entry point: one-line ``ValueError``s naming the value."""
import math
import numbers
import os

import numpy as np


def check_real(name, value, low=-math.inf, high=math.inf, low_open=False):
    """A finite real number in [low, high] (or (low, high] with ``low_open``), as float."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} must be a real number, got {value!r}")
    value = float(value)
    too_low = value <= low if low_open else value < low
    if not math.isfinite(value) or too_low or value > high:
        bound = "(" if low_open else "["
        raise ValueError(f"{name} must be finite and in {bound}{low}, {high}], got {value!r}")
    return value


#: Largest RMS size of the seeded perturbation: half the loop's radius (lengths in L/2π,
#: so the unperturbed loop has radius 1).  Beyond it the "perturbation" is the shape.
MAX_PERTURBATION = 0.5


def check_perturbation(name, value):
    """An RMS perturbation size in [0, MAX_PERTURBATION], as float."""
    value = check_real(name, value, low=0.0)
    if value > MAX_PERTURBATION:
        raise ValueError(f"{name} must be at most {MAX_PERTURBATION} (half the loop's radius: a "
                         f"larger one is not a perturbation of the loop), got {value!r}")
    return value


def check_integer(name, value, low):
    """An integer ≥ low (bools refused), as int."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral) \
            or value < low:
        raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
    return int(value)


def check_choice(name, value, choices):
    """One of ``choices``."""
    if value not in choices:
        raise ValueError(f"{name} must be one of {sorted(choices)}, got {value!r}")
    return value


def check_output_file(name, path):
    """A file path that can be written: not a directory, and its directory exists and is
    writable or can be made (as ``--out`` directories are: :func:`check_output_directory`).
    Checked before any work, so no run is lost to a bad path; nothing is created here."""
    path = os.fspath(path)
    if not path:
        raise ValueError(f"{name} is empty")
    if os.path.isdir(path):
        raise ValueError(f"{name} {path!r} is a directory")
    check_output_directory(name, os.path.dirname(os.path.abspath(path)))
    return path


def check_tilt(name, value, allow_zero=True):
    """A tilt in degrees: [0, 90], or (0, 90] where a tilt fixes g0 from q."""
    return check_real(name, value, low=0.0, high=90.0, low_open=not allow_zero)


# ---- sizes: bounded before any work --------------------------------------------------------
#: Largest truncation order accepted (--n, --n-max, a case's n, an initial shape's n).  One
#: right-hand side costs about 0.3 s at n = 128 and 6 s at n = 256 (measured on a loaded
#: 2-core machine, docs/cli.md, "Limits"), and the explicit step shrinks like n^-4: beyond 128 a
#: single run takes days.
MAX_N = 128
#: Most snapshots per run or traced sweep case: each is a step end, and at n = 128 they hold
#: 3 arrays of 3 x 257 doubles, 185 MB for 10 000.
MAX_SNAPSHOTS = 10_000
#: Most cases per sweep (the product of the grid's axes, or a cases file's rows): setting up
#: 900 000 cases took 75 s and 1.7 GB here, and their _sweep.json is about 95 MB.
MAX_CASES = 1_000_000
#: Most points of a point file: the curve fit checks every pair of segments for crossings
#: (1 000 points took 12 s, 10 000 took 81 s here).
MAX_POINTS = 10_000
#: Largest file read as a point file, a cases file, or results for --initial.
MAX_POINT_FILE_BYTES = 16 * 2**20
MAX_CASES_FILE_BYTES = 256 * 2**20
MAX_RESULTS_FILE_BYTES = 2**30


#: Largest order of the steady branch (``loopsim branch --n``, ``figures --branch-n``): the
#: continuation solves dense Newton systems of size ~6n at every point of the branch, so
#: its cost grows like n^3 per point; beyond 48 one branch takes hours.
MAX_BRANCH_N = 48
#: Most worker processes of a local Dask cluster: this machine's cores.  Each worker is a
#: process (about 320 MB) that compiles its own kernels; more than the cores only compete.
MAX_WORKERS = os.cpu_count() or 1
#: Largest figure resolution: 1200 dpi is print quality; a 6 x 4 inch figure is then
#: 35 megapixels, and 10^6 dpi would ask matplotlib for terapixels.
MAX_DPI = 1200


def check_order(name, value):
    """A truncation order 1 <= n <= MAX_N, as int."""
    value = check_integer(name, value, 1)
    if value > MAX_N:
        raise ValueError(f"{name} must be at most {MAX_N} (one right-hand side takes about "
                         f"0.3 s at n = 128 and the explicit step shrinks like n^-4), got {value}")
    return value


def check_count(name, value, low, high, why):
    """An integer in [low, high] (``why``: the reason for the upper bound), as int."""
    value = check_integer(name, value, low)
    if value > high:
        raise ValueError(f"{name} must be at most {high} ({why}), got {value}")
    return value


def check_input_file(name, path, max_bytes):
    """A regular file (not a device, FIFO or directory) of at most ``max_bytes``, so that
    reading it is bounded; one-line ValueError naming it otherwise."""
    import stat

    path = os.fspath(path)
    try:
        info = os.stat(path)
    except OSError as exc:
        raise ValueError(f"cannot read {name} {path!r}: {exc.strerror or exc}") from None
    if not stat.S_ISREG(info.st_mode):
        raise ValueError(f"{name} {path!r} is not a regular file")
    if info.st_size > max_bytes:
        raise ValueError(f"{name} {path!r} is {info.st_size / 2**20:.1f} MiB, more than the "
                         f"{max_bytes / 2**20:.0f} MiB read")
    return path


from .exit_codes import ENVIRONMENT_ERRNOS  # noqa: E402 - re-exported


def _probe_writable(name, path, directory):
    """Create and remove a file in ``directory``: the one sure test that it takes files
    (os.access passes a read-only filesystem, /proc and, for root, any mode bits).  A
    machine's refusal (read-only filesystem, full disk) is re-raised as OSError naming
    ``path``; any other refusal is a one-line ValueError."""
    import tempfile

    try:
        fd, probe = tempfile.mkstemp(prefix=".loopsim-probe-", dir=directory)
        os.close(fd)
        os.remove(probe)
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        if exc.errno in ENVIRONMENT_ERRNOS:
            raise OSError(exc.errno, f"{name} {path!r}: {directory!r} takes no files: "
                                     f"{reason}") from None
        raise ValueError(f"{name} {path!r}: {directory!r} takes no files: {reason}") from None


def check_output_directory(name, path):
    """A directory that exists and takes files, or can be made (its nearest existing
    parent is a directory that takes files): checked before any work, by creating and
    removing a probe file; nothing else is created."""
    path = os.fspath(path)
    if not path.strip():
        raise ValueError(f"{name} is empty")
    if os.path.exists(path):
        if not os.path.isdir(path):
            raise ValueError(f"{name} {path!r} is not a directory")
        _probe_writable(name, path, path)
        return path
    parent = os.path.dirname(os.path.abspath(path))
    while not os.path.exists(parent):
        parent = os.path.dirname(parent)
    if not os.path.isdir(parent):
        raise ValueError(f"{name} {path!r} cannot be made: {parent!r} is not a directory")
    _probe_writable(name, path, parent)
    return path
