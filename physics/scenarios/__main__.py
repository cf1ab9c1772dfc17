"""``python -m physics.scenarios``: the ``ice-scenarios`` command line."""
import sys

from .cli import main

sys.exit(main())
