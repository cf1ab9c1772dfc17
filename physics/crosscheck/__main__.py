"""``python -m physics.crosscheck all``: see :mod:`physics.crosscheck.report`."""
import sys

from .report import main

sys.exit(main())
