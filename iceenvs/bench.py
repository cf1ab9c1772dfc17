"""The environment benchmark moved to :mod:`benchmarks.environments`:
``python -m benchmarks.environments`` or ``seaice bench environments``.

``python -m iceenvs.bench [options]`` keeps working: it runs
:func:`benchmarks.environments.main` with the same options.
"""
from __future__ import annotations

import sys


def main(argv: list[str] | None = None) -> int:
    """Run :func:`benchmarks.environments.main` with ``argv``."""
    from benchmarks.environments import main as run

    return run(argv)


if __name__ == "__main__":
    sys.exit(main())
