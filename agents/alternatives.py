"""How an id's reference agent compares with other trainings of the same id.

Usage::

    python -m agents.alternatives REFERENCE CANDIDATE [CANDIDATE ...]
        [--labels NAME ...] [--out docs/agents/diagnostics/<env-name>-alternatives]

Each directory is what ``python -m agents.benchmark ship`` wrote for a set of
training seeds: the kept seed's run files and ``seeds.json``, which holds
every seed's returns on the selection episodes (seeded 50000 + k) and on the
benchmark's (40000 + k). ``REFERENCE`` is usually the id's reference agent
(``docs/agents/reference/<env-name>``); a candidate is another algorithm, or
the same with other hyperparameters, shipped elsewhere (``ship --out DIR``).
Nothing is played again: every set was scored on the same episodes.

The table gives each set's kept seed on the selection episodes too: the
score that chose it, and that may choose among the sets.

Each candidate is compared with the reference twice. Its kept seed against
the reference's kept seed, paired by benchmark episode; and its training
seeds against the reference's, paired by training seed (the difference of
each seed's benchmark mean, seeds matched by number), which shows whether
the whole recipe does better rather than one lucky seed.

Writes ``alternatives.json`` and ``alternatives.md``.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from .diagnostics import stamped, write_record

__all__ = ["read_set", "compare_sets", "markdown", "main"]


def read_set(directory: Path, label: str | None = None) -> dict:
    """A shipped set of seeds: its ``seeds.json``, the kept run's algorithm
    and a label (default the algorithm, upper case)."""
    import yaml

    from .benchmark import run_summary
    from .waypoint_follower import STUDENT

    directory = Path(directory)
    path = directory / "seeds.json"
    if (directory / "args.yaml").is_file():
        algo = yaml.safe_load((directory / "args.yaml").read_text())["algo"]
    elif (directory / STUDENT).is_file():
        algo = run_summary(directory)["algo"]
    else:
        algo = None
    if not path.is_file() or algo is None:
        raise ValueError(f"{directory} is not a directory written by agents.benchmark ship "
                         f"(no seeds.json, or neither args.yaml nor {STUDENT})")
    seeds = json.loads(path.read_text())
    return dict(label=label or (algo.upper() if algo.islower() else algo), algo=algo,
                directory=str(directory), **seeds)


def _paired(a: list[float], b: list[float]) -> dict:
    from .rollouts import stats

    s = stats(np.asarray(a, dtype=float) - np.asarray(b, dtype=float))
    return dict(diff=s["mean"], sem=s["sem"], n=s["n"])


def compare_sets(reference: dict, candidates: list[dict]) -> dict:
    """Every set's summary and each candidate's paired differences with
    ``reference`` (:func:`read_set` dicts)."""
    sets = [reference, *candidates]
    if len({s["env"] for s in sets}) != 1:
        raise ValueError(f"the sets are of several environments: "
                         f"{sorted({s['env'] for s in sets})}")
    if len({s["evaluation_episodes"] for s in sets}) != 1:
        raise ValueError("the sets were scored on different benchmark episodes")

    def kept(s):
        return next(x for x in s["seeds"] if x["seed"] == s["chosen_seed"])

    rows = []
    for s in sets:
        k = kept(s)
        steps = [x["training"].get("steps", np.nan) for x in s["seeds"]]
        wall = [x["training"].get("wall_seconds", np.nan) for x in s["seeds"]]
        row = dict(label=s["label"], algo=s["algo"], seeds=[x["seed"] for x in s["seeds"]],
                   steps=float(np.mean(steps)), minutes=float(np.mean(wall)) / 60.0,
                   unit=s["seeds"][0]["training"].get("unit", "steps"),
                   selection=k["selection"], evaluation=k["evaluation"],
                   across_seeds=s["across_seeds"], command=s["command"])
        if s is not reference:
            row["kept_vs_reference"] = _paired(k["returns"], kept(reference)["returns"])
            mine = {x["seed"]: x["evaluation"]["mean"] for x in s["seeds"]}
            theirs = {x["seed"]: x["evaluation"]["mean"] for x in reference["seeds"]}
            common = sorted(set(mine) & set(theirs))
            row["seeds_vs_reference"] = (_paired([mine[n] for n in common],
                                                 [theirs[n] for n in common])
                                         if len(common) > 1 else None)
        rows.append(row)
    return dict(env=reference["env"], evaluation_episodes=reference["evaluation_episodes"],
                rows=rows)


def markdown(record: dict) -> str:
    from .metrics import format_pm

    ref = record["rows"][0]["label"]
    lines = [f"`{record['command']}` (commit `{record['commit']}`, {record['date']}). "
             f"Each set's kept seed was chosen on 20 selection episodes (seeded 50000 + k); "
             f"returns are on the benchmark's {record['evaluation_episodes']}. \"Kept\" pairs "
             f"the kept seeds by episode; \"by seed\" pairs each training seed's mean with "
             f"the seed of the same number of the reference, {ref}. Mean ± standard error.",
             "", "| training | seeds | steps a seed | minutes a seed | kept seed: selection "
             "| kept seed: benchmark | across seeds | kept − reference | by seed − reference |",
             "|---|---|---|---|---|---|---|---|---|"]
    for row in record["rows"]:
        a = row["across_seeds"]
        kept = row.get("kept_vs_reference")
        by_seed = row.get("seeds_vs_reference")
        lines.append(
            f"| {row['label']} | {len(row['seeds'])} | {row['steps']:.0f}"
            f"{' decisions (5 steps each)' if row.get('unit') == 'decisions' else ''} | "
            f"{row['minutes']:.0f} | {format_pm(row['selection']['mean'], row['selection']['sem'])}"
            f" | {format_pm(row['evaluation']['mean'], row['evaluation']['sem'])}"
            f" | {a['mean']:.4g} ({a['min']:.4g}–{a['max']:.4g}) | "
            f"{format_pm(kept['diff'], kept['sem']) if kept else '–'} | "
            f"{format_pm(by_seed['diff'], by_seed['sem']) if by_seed else '–'} |")
    return "\n".join(lines) + "\n"


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m agents.alternatives",
                                description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("reference", type=Path, help="the reference set (agents.benchmark ship)")
    p.add_argument("candidates", nargs="+", type=Path, help="the sets compared with it")
    p.add_argument("--labels", nargs="+", default=None, metavar="NAME",
                   help="a name per set, the reference's first (default: the algorithms)")
    p.add_argument("--out", type=Path, default=None,
                   help="default docs/agents/diagnostics/<env-name>-alternatives")
    return p


def main(argv: list[str] | None = None) -> dict:
    raw = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    args = parser.parse_args(raw)
    dirs = [args.reference, *args.candidates]
    if args.labels is not None and len(args.labels) != len(dirs):
        parser.error(f"--labels: {len(args.labels)} names for {len(dirs)} sets")
    labels = args.labels or [None] * len(dirs)
    try:
        sets = [read_set(d, label) for d, label in zip(dirs, labels)]
        record = compare_sets(sets[0], sets[1:])
    except ValueError as err:
        parser.error(str(err))
    record = stamped("agents.alternatives", raw, record)
    write_record(args.out, record["env"], "alternatives", record, markdown(record))
    return record


if __name__ == "__main__":
    main()
