"""What the diagnostics of a task (:mod:`agents.ceiling`, :mod:`agents.chaos`,
:mod:`agents.oracle`) share: their episodes, which are never the benchmark's,
and the stamp of their records."""
from __future__ import annotations

import argparse
import json
import math
import shlex
import sys
import time
from pathlib import Path

__all__ = ["DIAGNOSTICS_DIR", "add_episode_arguments", "check_episodes", "diagnostic_parser",
           "parse_arguments", "resolvable", "run_diagnostic", "stamped", "write_record"]

#: where the diagnostics' records live, one directory ``<env-name>-<kind>`` each
DIAGNOSTICS_DIR = Path("docs") / "agents" / "diagnostics"


def add_episode_arguments(p: argparse.ArgumentParser) -> None:
    """``--episodes``, ``--seed`` (default: the tuning episodes, 50000 + k),
    ``--processes`` and ``--no-progress``."""
    p.add_argument("--episodes", type=int, default=20)
    p.add_argument("--seed", type=int, default=50000,
                   help="episode k is seeded SEED + k (default: the tuning episodes)")
    p.add_argument("--processes", type=int, default=1)
    p.add_argument("--no-progress", action="store_true")


def diagnostic_parser(module: str, doc: str, kind: str) -> argparse.ArgumentParser:
    """The parser of ``python -m module``: ``--env``, the episode arguments
    and ``--out`` (default :data:`DIAGNOSTICS_DIR` / ``<env-name>-<kind>``)."""
    p = argparse.ArgumentParser(prog=f"python -m {module}", description=doc.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--env", required=True, help="a registered environment id")
    add_episode_arguments(p)
    p.add_argument("--out", type=Path, default=None,
                   help=f"default docs/agents/diagnostics/<env-name>-{kind}")
    return p


def resolvable(record: dict, episodes: int = 40) -> float:
    """Two standard errors of the twins' difference over ``episodes``
    episodes: the smallest gain a paired benchmark of that size resolves."""
    return 2.0 * record["twin_std"] / math.sqrt(episodes)


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


def parse_arguments(parser: argparse.ArgumentParser, argv: list[str]) -> argparse.Namespace:
    """``parser``'s arguments (it has ``--env`` and :func:`add_episode_arguments`'),
    with the id checked against the registered ones and ``--processes`` >= 1."""
    import iceenvs

    args = parser.parse_args(argv)
    if args.env not in iceenvs.ENV_IDS:
        parser.error(f"--env: {args.env!r} is not one of {', '.join(iceenvs.ENV_IDS)}")
    if args.processes < 1:
        parser.error("--processes must be >= 1")
    return args


def write_record(out: Path | None, env_id: str, kind: str, record: dict, text: str) -> Path:
    """Write ``<kind>.json`` and ``<kind>.md`` (``text``) to ``out`` (default
    :data:`DIAGNOSTICS_DIR` / ``<env-name>-<kind>``), print the text and
    return the directory."""
    out = out or DIAGNOSTICS_DIR / f"{env_id.split('/')[-1]}-{kind}"
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{kind}.json").write_text(json.dumps(record, indent=1) + "\n")
    (out / f"{kind}.md").write_text(text)
    print(text)
    print(f"wrote {out / (kind + '.md')}")
    return out


def run_diagnostic(module: str, kind: str, parser: argparse.ArgumentParser,
                   argv: list[str] | None, compute, markdown) -> tuple[dict, Path]:
    """The command ``python -m module``: parse ``argv`` (default the command
    line), ``compute(args)`` the record (a ``ValueError`` becomes a usage
    error), stamp it and write it with its ``markdown(record)``; returns the
    record and its directory."""
    raw = list(sys.argv[1:] if argv is None else argv)
    args = parse_arguments(parser, raw)
    try:
        record = compute(args)
    except ValueError as err:
        parser.error(str(err))
    record = stamped(module, raw, record)
    return record, write_record(args.out, args.env, kind, record, markdown(record))
