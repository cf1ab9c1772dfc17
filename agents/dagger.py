"""DAgger: imitate a planner on the states the student itself visits.

Behaviour cloning (:mod:`agents.pretrain`) fits the student to the
teacher's decisions on the teacher's own episodes. Where the student errs
it drifts into states the teacher never showed it, and errors compound
(Ross, Gordon and Bagnell, AISTATS 2011). DAgger (*dataset aggregation*)
lets the student drive and asks the teacher what it would do there:

1. **Round 0** is behaviour cloning: the teacher sails ``episodes``
   episodes (seeded ``seed + k``), and the student is fitted to its
   actions (:func:`agents.pretrain.fit_policy`).
2. **Round r ≥ 1:** ``episodes`` new episodes (seeded ``seed + r ·
   episodes + k``, never a field of an earlier round) in which, at each
   step, the teacher's action is played with probability β^r (``beta``;
   the classic schedule, so that the first rounds stay near the teacher)
   and the student's mean action otherwise. The teacher labels *every*
   visited state with its own action, played or not: it is called at
   every step, so a planner keeps its route and replans from wherever
   the student took the ship.
3. The labelled states of every round are **aggregated**, and the student
   is fitted again to all of them, from its current weights.

The teacher may read what the student cannot (the lattice planner reads
every floe; :mod:`agents.planners`): DAgger distils a privileged planner
into a sensor-only policy, and how close the student comes is what its
observation can carry.

As a warm start of ``agents.train`` it is the ``pretrain`` hyperparameter
with ``rounds`` > 0 (:data:`agents.pretrain.PRETRAIN_DEFAULTS`), e.g.::

    pretrain:
      teacher: lattice
      episodes: 10
      rounds: 3
      beta: 0.5
      anchor: 1.0

and PPO then fine-tunes the student, kept near the teacher's labels by the
anchor (:class:`agents.pretrain.BehaviourAnchor`, on the aggregated data).
``pretrain.yaml`` records each round: its β, the decisions it added, the
return of its episodes and the student's fit.

**How well the student imitates where it was not fitted**::

    python -m agents.dagger RUN_DIR [RUN_DIR ...] [--checkpoint 0] [--episodes 4]
        [--seed 60000] [--env-kwargs KEY=VALUE ...] [--out FILE.md]

sails the teacher on fields the student never saw (seeded ``seed + k``,
apart from the warm start's, the leaderboard's and the benchmark's), as the
run observes and acts (its agent keywords, on the default ice unless
``--env-kwargs`` says otherwise), and compares the student's action on each
state with the teacher's: the held-out mean squared error beside the error
of the last fit on its own data (``pretrain.yaml``), both against the
variance of the teacher's actions.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from . import observations as obs_rows

__all__ = ["student_rollouts", "aggregate", "dagger", "held_out_error", "main"]


def student_rollouts(policy, normalizer, env_id: str, env_kwargs: dict, teacher: str,
                     episodes: int, seed: int, beta: float, progress: bool = False,
                     label: str = "DAgger"):
    """Sail ``episodes`` episodes of ``gymnasium.make(env_id, **env_kwargs)``
    (seeded ``seed + k``) with the teacher's action played with probability
    ``beta`` and the SB3 ``policy``'s mean action otherwise (on the
    observation normalised by ``normalizer``, a ``VecNormalize`` or None);
    the teacher labels every step.

    Returns
    -------
    (Demonstrations, list[float], float)
        The visited raw observations with the *teacher's* actions, the
        rewards and episode starts; the return of each episode; the share
        of steps on which the teacher's action was played. The coin of each
        step is drawn from a generator seeded by ``seed``.
    """
    import gymnasium as gym
    from tqdm.auto import tqdm

    from .baselines import make_baseline
    from .pretrain import Demonstrations

    if not 0.0 <= beta <= 1.0:
        raise ValueError(f"beta must lie in [0, 1], got {beta!r}")
    coin = np.random.default_rng(seed)
    env = gym.make(env_id, **env_kwargs)
    obs_list, labels, rewards, starts, returns = [], [], [], [], []
    played = 0
    try:
        planner = make_baseline(teacher, env, seed=seed)
        for k in tqdm(range(episodes), desc=label, unit="episode", disable=not progress):
            obs, _ = env.reset(seed=seed + k)
            planner.reset(seed + k)
            done, first, total = False, True, 0.0
            while not done:
                wanted = np.asarray(planner.predict(obs)[0], dtype=np.float32).reshape(
                    env.action_space.shape)
                if coin.random() < beta:
                    action, played = wanted, played + 1
                else:
                    seen = normalizer.normalize_obs(obs) if normalizer is not None else obs
                    action = np.asarray(policy.predict(seen, deterministic=True)[0],
                                        dtype=np.float32).reshape(env.action_space.shape)
                obs_list.append(obs_rows.as_float32(obs, copy=True))
                labels.append(wanted)
                starts.append(first)
                obs, reward, terminated, truncated, _ = env.step(action)
                rewards.append(float(reward))
                total += float(reward)
                done, first = terminated or truncated, False
            returns.append(total)
    finally:
        env.close()
    steps = max(len(labels), 1)
    return Demonstrations(obs_list, labels, rewards, starts), returns, played / steps


def aggregate(a, b):
    """The demonstrations ``a`` followed by ``b`` (their episodes kept whole)."""
    from .pretrain import Demonstrations

    if isinstance(a.obs, dict):
        obs = {key: np.concatenate([a.obs[key], b.obs[key]]) for key in a.obs}
    else:
        obs = np.concatenate([a.obs, b.obs])
    return Demonstrations(obs, np.concatenate([a.actions, b.actions]),
                          np.concatenate([a.rewards, b.rewards]),
                          np.concatenate([a.episode_starts, b.episode_starts]))


def dagger(model, norm, env_id: str, env_kwargs: dict, demos, settings: dict, gamma: float,
           progress: bool = False, deadline: float | None = None):
    """Rounds 1 … ``settings["rounds"]`` of DAgger on ``model`` (an SB3
    actor-critic already fitted to the teacher's demonstrations ``demos``,
    round 0), its observations normalised by ``norm`` (a ``VecNormalize``
    or None), refitting on the aggregate after each round.

    With ``deadline`` (a ``time.perf_counter`` value) no round begins that
    would not end by then at the pace of the rounds so far.

    Returns
    -------
    (Demonstrations, list[dict])
        The aggregated demonstrations and one record per round: ``round``,
        ``beta``, ``decisions`` added, ``teacher_share`` (of the steps
        played), ``mean_return`` of its episodes, the fit
        (:func:`agents.pretrain.fit_policy`) and ``seconds``.
    """
    from .pretrain import refit

    rounds, episodes = settings["rounds"], settings["episodes"]
    records = []
    began = time.perf_counter()
    for r in range(1, rounds + 1):
        if deadline is not None and r > 1:
            now = time.perf_counter()
            if now + (now - began) / (r - 1) > deadline:
                break
        start = time.perf_counter()
        beta = float(settings["beta"]) ** r
        new, returns, share = student_rollouts(
            model.policy, norm, env_id, env_kwargs, settings["teacher"], episodes,
            settings["seed"] + r * episodes, beta, progress=progress, label=f"DAgger round {r}")
        demos = aggregate(demos, new)
        fit = refit(model.policy, norm, demos, new, gamma, settings, settings["seed"] + r,
                    deadline)
        records.append({"round": r, "beta": beta, "decisions": len(new),
                        "teacher_share": round(share, 4),
                        "mean_return": float(np.mean(returns)), **fit,
                        "seconds": round(time.perf_counter() - start, 1)})
    return demos, records


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
    import argparse
    import json
    import shlex
    import sys

    from .envs import parse_key_values

    p = argparse.ArgumentParser(prog="python -m agents.dagger",
                                description="How well a student of a warm start imitates its "
                                            "teacher on fields it was not fitted on.")
    p.add_argument("runs", nargs="+", type=Path, help="run directories of agents.train")
    p.add_argument("--checkpoint", default=None,
                   help="the checkpoint at this many steps (0: the student before PPO)")
    p.add_argument("--episodes", type=int, default=4, help="teacher episodes (4)")
    p.add_argument("--seed", type=int, default=60000, help="episode k is seeded SEED + k")
    p.add_argument("--env-kwargs", nargs="*", default=[], metavar="KEY=VALUE",
                   help="gymnasium.make keywords over the run's own")
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
    command = "python -m agents.dagger " + shlex.join(sys.argv[1:] if argv is None else argv)
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
