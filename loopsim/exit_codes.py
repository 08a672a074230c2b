"""Which failures are the machine's, not the input's: the OSError numbers on which the
command line exits 3 (``cli.common.EXIT_ENVIRONMENT``); and the status of a command whose
output's reader went away.  Plain constants, no NumPy."""
import errno

#: OSError numbers that are the machine's fault, not the input's: the command line exits
#: 3 on them (a full disk, a read-only filesystem, an I/O error, no memory or files left,
#: a file-size limit reached: ``ulimit -f``, or the filesystem's largest file).
ENVIRONMENT_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EIO,
                                errno.ENOMEM, errno.EMFILE, errno.ENFILE, errno.EFBIG})

#: Exit status when stdout's reader has gone (``loopsim summary DIR | head -1``): the
#: command stops writing and exits quietly, without a message or traceback, with the
#: status a shell reports for a Unix tool ended by SIGPIPE (128 + 13, as ``yes | head -1``
#: under ``set -o pipefail``).  Not 2: nothing was wrong with the input.  A closed or
#: broken stderr is no reason to stop at all (``loopsim._signals.guard_streams``).
EXIT_BROKEN_PIPE = 141
