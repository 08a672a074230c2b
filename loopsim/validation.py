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
    """A file path that can be written: its directory exists and is writable, and the path
    is not a directory.  Checked before any work, so no run is lost to a bad --out."""
    path = os.fspath(path)
    if not path:
        raise ValueError(f"{name} is empty")
    directory = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path):
        raise ValueError(f"{name} {path!r} is a directory")
    if not os.path.isdir(directory):
        raise ValueError(f"{name} {path!r}: no such directory {directory!r}")
    if not os.access(directory, os.W_OK | os.X_OK):
        raise ValueError(f"{name} {path!r}: directory {directory!r} is not writable")
    return path


def check_tilt(name, value, allow_zero=True):
    """A tilt in degrees: [0, 90], or (0, 90] where a tilt fixes g0 from q."""
    return check_real(name, value, low=0.0, high=90.0, low_open=not allow_zero)
