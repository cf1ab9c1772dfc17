"""What the diagnostics of a task (:mod:`agents.ceiling`, :mod:`agents.chaos`)
share: their episodes, which are never the benchmark's, and the stamp of
their records."""
from __future__ import annotations

import argparse
import shlex
import time

__all__ = ["add_episode_arguments", "check_episodes", "stamped"]


def add_episode_arguments(p: argparse.ArgumentParser) -> None:
    """``--episodes``, ``--seed`` (default: the tuning episodes, 50000 + k),
    ``--processes`` and ``--no-progress``."""
    p.add_argument("--episodes", type=int, default=20)
    p.add_argument("--seed", type=int, default=50000,
                   help="episode k is seeded SEED + k (default: the tuning episodes)")
    p.add_argument("--processes", type=int, default=1)
    p.add_argument("--no-progress", action="store_true")


def check_episodes(episodes: int, seed: int) -> None:
    """Refuse fewer than two episodes, and episodes that would include the
    benchmark's (:data:`agents.reference.EVAL_SEED` + k)."""
    from .reference import EVAL_EPISODES, EVAL_SEED

    if episodes < 2:
        raise ValueError("episodes must be >= 2 (a standard error needs two)")
    if seed < EVAL_SEED + EVAL_EPISODES and EVAL_SEED < seed + episodes:
        raise ValueError(f"episodes seeded {seed} + k would include the benchmark's "
                         f"({EVAL_SEED} + k); choose other seeds")


def stamped(module: str, argv: list[str], record: dict) -> dict:
    """``record`` after the command that made it, the commit and the date."""
    from physics.provenance import source_commit

    return dict(command=shlex.join(["python", "-m", module, *argv]), commit=source_commit(),
                date=time.strftime("%Y-%m-%d"), **record)
