"""``python -m seaice_gym``: the ``seaice`` command."""
import sys

from .cli import main

sys.exit(main())
