"""``python -m loopsim.cli``: the ``loopsim`` command (as ``python -m loopsim``)."""
import sys

from . import main

sys.exit(main())
