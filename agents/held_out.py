"""A student of a warm start against its teacher on fields it was not
fitted on: ``python -m agents.held_out``.

A student fitted to a teacher's decisions (behaviour cloning, DAgger:
:mod:`agents.pretrain`, :mod:`agents.dagger`) may reproduce them on the
states it was fitted to and not elsewhere::

    python -m agents.held_out RUN_DIR [RUN_DIR ...] [--checkpoint 0] [--episodes 4]
        [--seed 60000] [--env-kwargs KEY=VALUE ...] [--out FILE.md]

sails the teacher on fields the student never saw (seeded ``seed + k``,
apart from the warm start's, the leaderboard's and the benchmark's), as the
run observes and acts (its agent keywords, on the default ice unless
``--env-kwargs`` says otherwise), and compares the student's action on each
state with the teacher's: the held-out mean squared error beside the error
of the warm start's last fit on its own data (``pretrain.yaml``), both
against the variance of the teacher's actions. ``--out FILE.md`` writes the
table, and ``FILE.json`` beside it the numbers and the command.
"""
from __future__ import annotations

import argparse
import json
import shlex
import sys
from pathlib import Path

import numpy as np

__all__ = ["held_out_error", "main"]


def held_out_error(run_dir, checkpoint=None, *, episodes: int = 4, seed: int = 60000,
                   env_kwargs: dict | None = None) -> dict:
    """The student of ``run_dir`` (its ``checkpoint``; :class:`agents.rollouts.TrainedPolicy`)
    against its teacher (the run's ``pretrain.teacher``) on ``episodes`` of
    the teacher's own episodes seeded ``seed + k``: ``held_out_mse`` (the
    student's deterministic action against the teacher's, both within the
    action space), ``variance`` (of the teacher's actions), ``fitted_mse``
    and ``fitted_variance`` (the last fit of the warm start, on its own
    data), and ``decisions``."""
    import yaml

    from .pretrain import collect
    from .rollouts import TrainedPolicy

    policy = TrainedPolicy(run_dir, checkpoint)
    report = yaml.safe_load((Path(run_dir) / "pretrain.yaml").read_text())
    kwargs = {**policy.agent_kwargs, **(env_kwargs or {})}
    demos = collect(policy.env_id, kwargs, report["teacher"], episodes, seed)
    predicted, _ = policy.predict(demos.obs)
    predicted = np.asarray(predicted, dtype=np.float64).reshape(demos.actions.shape)
    last = (report.get("dagger") or [report])[-1]
    return {"run": str(run_dir), "checkpoint": checkpoint, "teacher": report["teacher"],
            "episodes": episodes, "seed": seed, "env_kwargs": kwargs, "decisions": len(demos),
            "held_out_mse": float(np.mean((predicted - demos.actions) ** 2)),
            "variance": float(np.var(demos.actions)),
            "fitted_mse": float(last["action_mse"]),
            "fitted_variance": float(last["action_variance"])}


def main(argv: list[str] | None = None) -> list[dict]:
    from .envs import episode_arguments, parse_key_values

    p = argparse.ArgumentParser(prog="python -m agents.held_out",
                                description="How well a student of a warm start imitates its "
                                            "teacher on fields it was not fitted on.")
    p.add_argument("runs", nargs="+", type=Path, help="run directories of agents.train")
    p.add_argument("--checkpoint", default=None,
                   help="the checkpoint at this many steps (0: the student before PPO)")
    episode_arguments(p, episodes=4, seed=60000,
                      kwargs_help="gymnasium.make keywords over the run's own")
    p.add_argument("--out", type=Path, default=None, help="write the table (Markdown) here")
    args = p.parse_args(sys.argv[1:] if argv is None else argv)
    if args.episodes < 1:
        p.error(f"--episodes must be at least 1, got {args.episodes}")
    checkpoint = None if args.checkpoint is None else int(args.checkpoint)
    try:
        kwargs = parse_key_values(args.env_kwargs)
        rows = [held_out_error(run, checkpoint, episodes=args.episodes, seed=args.seed,
                               env_kwargs=kwargs) for run in args.runs]
    except (FileNotFoundError, KeyError, ValueError) as err:
        p.error(str(err))
    command = "python -m agents.held_out " + shlex.join(sys.argv[1:] if argv is None else argv)
    lines = [f"`{command}`: the teacher's episodes seeded {args.seed} + k "
             f"({args.episodes} a run, {rows[0]['decisions']} decisions in the first), as the "
             f"runs observe and act ({rows[0]['env_kwargs']}). Mean squared error of the "
             "student's action against the teacher's, and over the variance of the "
             "teacher's actions.", "",
             "| run | held-out error | / variance | last fit's error on its data | / variance |",
             "|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {Path(r['run']).name} | {r['held_out_mse']:.3g} | "
                     f"{r['held_out_mse'] / r['variance']:.1%} | {r['fitted_mse']:.3g} | "
                     f"{r['fitted_mse'] / r['fitted_variance']:.1%} |")
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(text)
        args.out.with_suffix(".json").write_text(
            json.dumps({"command": command, "rows": rows}, indent=1) + "\n")
    return rows


if __name__ == "__main__":
    main()
