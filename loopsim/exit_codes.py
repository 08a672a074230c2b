"""Which failures are the machine's, not the input's: the OSError numbers on which the
command line exits 3 (``cli.common.EXIT_ENVIRONMENT``).  Plain constants, no NumPy."""
import errno

#: OSError numbers that are the machine's fault, not the input's: the command line exits
#: 3 on them (a full disk, a read-only filesystem, an I/O error, no memory or files left,
#: a file-size limit reached: ``ulimit -f``, or the filesystem's largest file).
ENVIRONMENT_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EIO,
                                errno.ENOMEM, errno.EMFILE, errno.ENFILE, errno.EFBIG})
