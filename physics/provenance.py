"""Where a result comes from: the source commit it was computed with.

Every record the project writes (a benchmark suite's, a leaderboard's, an
evaluation's) names its command, host and date; :func:`source_commit` adds
the commit of the checkout the code ran from, so that a record can be
traced to the code that made it.

>>> commit = source_commit()
>>> commit is None or len(commit.split("+")[0]) == 12
True
"""
from __future__ import annotations

import subprocess
from pathlib import Path

__all__ = ["source_commit", "MODIFIED"]

#: appended to the commit when tracked files differ from it
MODIFIED = "+modified"


def source_commit(root: str | Path | None = None) -> str | None:
    """The abbreviated (12-digit) git commit of the checkout at ``root``
    (default: the one this package runs from), with :data:`MODIFIED`
    appended when tracked files differ from it; ``None`` outside a git
    checkout (an installed package) or without git."""
    root = Path(__file__).resolve().parent.parent if root is None else Path(root)
    if not (root / ".git").exists():
        return None
    try:
        head = subprocess.run(["git", "-C", str(root), "rev-parse", "--short=12", "HEAD"],
                              capture_output=True, text=True, timeout=30)
        if head.returncode != 0:
            return None
        changed = subprocess.run(["git", "-C", str(root), "diff", "--quiet", "HEAD", "--"],
                                 capture_output=True, timeout=30).returncode != 0
    except (OSError, subprocess.SubprocessError):
        return None
    return head.stdout.strip() + (MODIFIED if changed else "")
