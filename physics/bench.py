"""The benchmarks moved to the :mod:`benchmarks` package, one module per
suite: ``python -m benchmarks.<suite>`` or ``seaice bench <suite>``.

``python -m physics.bench <suite> [options]`` keeps working: it runs the
suite's ``main`` with the options (``phases`` is the ``hertz_phases``
suite), e.g. ``python -m physics.bench hertz --quick``.
"""
from __future__ import annotations

import sys

#: the names this command used before the suites moved
_RENAMED = {"phases": "hertz_phases"}


def main(argv: list[str] | None = None) -> int:
    """Run the suite named by the first argument with the others."""
    from benchmarks import SUITES
    from benchmarks import main as run_suite

    argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
    names = ", ".join([*SUITES, *_RENAMED])
    if not argv or argv[0] in ("-h", "--help"):
        print(f"usage: python -m physics.bench SUITE [options]  (SUITE: {names})\n\n{__doc__}")
        return 0 if argv else 2
    suite = _RENAMED.get(argv[0], argv[0])
    if suite not in SUITES:
        print(f"python -m physics.bench: unknown suite {argv[0]!r} (choose from {names})",
              file=sys.stderr)
        return 2
    return run_suite(suite, argv[1:])


if __name__ == "__main__":
    sys.exit(main())
