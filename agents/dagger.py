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

How well a student imitates on fields it was not fitted on:
:mod:`agents.held_out`.
"""
from __future__ import annotations

import time

import numpy as np

from . import observations as obs_rows

__all__ = ["student_rollouts", "aggregate", "dagger"]


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

