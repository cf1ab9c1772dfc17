"""Set-up shared by the whole test suite.

Test modules import the reference helpers as a package,
``from reference.dem import ...``, and never each other. For that the
``tests`` directory is on ``sys.path``, and so is the project root, ahead of
it: the test folders named like the packages (``tests/physics``,
``tests/iceenvs``, ``tests/agents``) must never be taken for them.
``pythonpath`` in ``pyproject.toml`` arranges this; it is repeated here for
runs under another configuration.
"""
from __future__ import annotations

import sys
from pathlib import Path

_TESTS = Path(__file__).resolve().parent
for _path in (str(_TESTS), str(_TESTS.parent)):      # the root ends up first
    if _path not in sys.path:
        sys.path.insert(0, _path)
