"""One sweep at a time in a directory: who holds it is checked, and recorded, before any
case runs or any file is written.

Each command that writes a sweep directory (a sweep, a ``--seeds auto`` sweep, a
``--rerun-failed``) holds it for as long as it runs: a holder file
``_sweep.lock.HOST.PID.K`` (JSON: who, since when, which sweep, which shard), on which it
keeps an exclusive ``flock``.  The kernel releases that lock when the process ends, however
it ends (a SIGKILL included), so a holder file whose lock can be taken is stale and is
removed: a dead process never wedges the directory.  Holder files are checked and made
under a short exclusive ``flock`` on the directory itself (or, on a filesystem that
refuses one there, on the file :data:`MUTEX_FILE`), so two commands started at the same
instant see each other.

A start is refused, with one line naming the directory and the holder (pid, host, start,
command), when a live holder runs another sweep (another configuration fingerprint), a
rerun of failed cases, or this same sweep on cases this one would compute too (no
``--shard``, the same shard, or shards that share chunks).  Shards of one sweep that share
no chunk (``--shard 0/4`` and ``--shard 1/4``) run side by side, as job arrays do.
"""
import datetime
import errno
import fcntl
import glob
import itertools
import json
import math
import os
import socket
import sys
import time

from .. import storage
from .._signals import track_temporary, untrack_temporary

#: Holder files: ``_sweep.lock.HOST.PID.K`` (a leading "_": dataset readers skip them).
HOLDER_PREFIX = "_sweep.lock."
#: The file locked around the check and registration where the directory itself cannot be
#: ``flock``-ed (some network filesystems); an empty file, left in place.
MUTEX_FILE = "_sweep.lock"
#: Longest wait for another command's check and registration (a fraction of a second).
MUTEX_TIMEOUT_S = 30.0
_COUNTER = itertools.count()


def holder(fingerprint, shard=None, exclusive=False):
    """What a command records about itself: the ``fingerprint`` of what it computes, its
    ``shard`` (I, N) or None, and whether it admits no one else (``exclusive``: a rerun
    of failed cases rewrites result files)."""
    return dict(fingerprint=fingerprint, shard=list(shard) if shard else None,
                exclusive=bool(exclusive))


def shards_overlap(first, second):
    """Whether two shards (I, N), or None for all chunks, have a chunk k in common:
    k = I1 mod N1 and k = I2 mod N2 has a solution iff I1 = I2 mod gcd(N1, N2)."""
    if first is None or second is None:
        return True
    (i1, n1), (i2, n2) = first, second
    return (i1 - i2) % math.gcd(n1, n2) == 0


def conflict(out, mine, theirs):
    """The one-line reason why ``mine`` (a :func:`holder`) may not start in ``out`` while
    ``theirs`` (a live holder's record) runs there, or None."""
    who = (f"pid {theirs.get('pid')} on {theirs.get('host')}, since "
           f"{theirs.get('started_utc', '?')[:19]} UTC: "
           f"{' '.join(theirs.get('command_line') or [])[:160]}")
    if theirs.get("exclusive") or mine["exclusive"]:
        what = "a rerun of its failed cases" if theirs.get("exclusive") else "a sweep"
        return (f"{out!r} is in use by {what} ({who}); wait for it to end, then run this "
                "command again")
    if theirs.get("fingerprint") != mine["fingerprint"]:
        return (f"{out!r} is in use by another sweep ({who}); use another --out, or wait "
                "for it to end")
    if shards_overlap(mine["shard"], theirs.get("shard")):
        return (f"{out!r} is being written by this same sweep already ({who}); a second "
                "copy would compute the same cases: wait for it to end (the command then "
                "resumes), or give each copy its own --shard I/N")
    return None


class _Mutex:
    """An exclusive ``flock`` on the directory ``out`` (else on its :data:`MUTEX_FILE`),
    held around the check and registration of holders."""

    def __init__(self, out):
        self.out, self.fd = out, None

    def __enter__(self):
        try:
            self.fd = os.open(self.out, os.O_RDONLY | os.O_DIRECTORY)
            self._wait(self.fd)
        except OSError as exc:  # a filesystem without flock on directories (NFS)
            if exc.errno not in (errno.EBADF, errno.EINVAL, errno.ENOLCK, errno.EOPNOTSUPP):
                raise
            self._close()
            self.fd = os.open(os.path.join(self.out, MUTEX_FILE), os.O_RDWR | os.O_CREAT, 0o666)
            self._wait(self.fd)
        return self

    def _wait(self, fd):
        deadline = time.monotonic() + MUTEX_TIMEOUT_S
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                return
            except BlockingIOError:
                if time.monotonic() > deadline:
                    raise ValueError(f"{self.out!r}: another command has held its lock for "
                                     f"more than {MUTEX_TIMEOUT_S:g} s while starting; try "
                                     "again") from None
                time.sleep(0.02)

    def _close(self):
        if self.fd is not None:
            os.close(self.fd)  # releases the flock
            self.fd = None

    def __exit__(self, *exc):
        self._close()


def _read_live(path):
    """The record of the holder file ``path`` if its owner is alive (its flock is held),
    else None: the file of a dead owner is removed."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except FileNotFoundError:
        return None
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:  # held: its owner is alive
            with os.fdopen(os.dup(fd)) as handle:
                try:
                    return json.load(handle)
                except ValueError:
                    return {}
        try:
            os.remove(path)  # stale: its owner died without removing it
        except FileNotFoundError:
            pass
        return None
    finally:
        os.close(fd)


class DirectoryLock:
    """This command's hold on a sweep directory (:func:`acquire`); :meth:`release` ends it
    (idempotent; the process ending ends it too)."""

    def __init__(self, path, fd):
        self.path, self.fd = path, fd

    def release(self):
        if self.fd is None:
            return
        try:
            os.remove(self.path)
        except FileNotFoundError:
            pass
        untrack_temporary(self.path)
        os.close(self.fd)
        self.fd = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()


def acquire(out, mine, command_line=None):
    """Hold the existing directory ``out`` for ``mine`` (a :func:`holder`): a one-line
    ValueError naming the directory and the holder when a live one conflicts
    (:func:`conflict`); stale holder files are removed.  Returns a :class:`DirectoryLock`."""
    with _Mutex(out):
        for path in sorted(glob.glob(os.path.join(glob.escape(out), HOLDER_PREFIX + "*"))):
            theirs = _read_live(path)
            if theirs is not None:
                reason = conflict(out, mine, theirs)
                if reason is not None:
                    raise ValueError(reason)
        host = socket.gethostname()
        path = os.path.join(out, f"{HOLDER_PREFIX}{host}.{os.getpid()}.{next(_COUNTER)}")
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        track_temporary(path)  # removed should a signal end the process at once
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        record = dict(mine, pid=os.getpid(), host=host,
                      started_utc=datetime.datetime.now(datetime.timezone.utc).isoformat(),
                      command_line=list(command_line if command_line is not None
                                        else sys.argv))
        os.write(fd, json.dumps(record).encode())
    return DirectoryLock(path, fd)


def hold(out, mine, command_line=None):
    """:func:`acquire` on ``out``, made first if absent (``storage.make_directories``)."""
    storage.make_directories(out)
    return acquire(out, mine, command_line)
