"""The planners' demonstrations as Minari datasets: ``python -m agents.datasets``.

Offline reinforcement learning and imitation learn from recorded
episodes. Minari (Farama Foundation) is the standard format for them: a
dataset holds each episode's observations, actions, rewards,
terminations and truncations, with the environment's spec, so that
``minari.load_dataset(ID).recover_environment()`` makes the environment
again. This command sails a baseline (a planner or controller of
:func:`agents.baselines.make_baseline`, such as the privileged ``lattice``
planner) on seeded episodes and writes them as one::

    python -m agents.datasets --env iceenvs/ShipNavigation-v1 --teacher lattice
        [--episodes 20] [--seed 30000] [--env-kwargs obs_type=costmap_dict ...]
        [--root runs/datasets] [--name lattice-v0]

Episode k is seeded ``seed + k``, apart from the leaderboard's and the
benchmark's fields. The dataset's id is ``seaice-gym/<env name>/<name>``
(e.g. ``seaice-gym/ShipNavigation-v1/lattice-v0``) under ``--root``, which
becomes ``MINARI_DATASETS_PATH``; beside it, ``<name>.json`` summarises it
(episodes, steps, the return's mean and standard error, the command, the
commit). Minari's hdf5 files are large, so the summaries are what records
keep. :func:`demonstrations` reads a dataset back as
:class:`agents.pretrain.Demonstrations`, for behaviour cloning.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import shlex
import sys
import time
import warnings
from pathlib import Path

import numpy as np

__all__ = ["NAMESPACE", "dataset_id", "sail", "write_dataset", "load", "demonstrations",
           "build_parser", "main"]

#: the namespace of the suite's datasets
NAMESPACE = "seaice-gym"
DEFAULT_ROOT = Path("runs") / "datasets"


def dataset_id(env_id: str, name: str) -> str:
    """``seaice-gym/<env name>/<name>``: Minari's id of a dataset of
    ``env_id`` (its name without the ``iceenvs/`` namespace)."""
    if not name or "/" in name:
        raise ValueError(f"a dataset name is one part such as 'lattice-v0', got {name!r}")
    return f"{NAMESPACE}/{env_id.split('/')[-1]}/{name}"


def sail(env, teacher: str, episodes: int, seed: int, progress: bool = False) -> list:
    """``episodes`` episodes of the baseline ``teacher`` on ``env``, seeded
    ``seed + k``, as Minari episode buffers (observations one longer than
    the actions: the last is the one the episode ended on)."""
    from minari.data_collector import EpisodeBuffer
    from tqdm.auto import tqdm

    from .baselines import make_baseline
    from .observations import as_float32

    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ValueError(f"episodes must be an integer >= 1, got {episodes!r}")
    policy = make_baseline(teacher, env, seed=seed)
    buffers = []
    for k in tqdm(range(episodes), desc=f"{teacher} episodes", unit="episode",
                  disable=not progress):
        obs, _ = env.reset(seed=seed + k)
        policy.reset(seed + k)
        seen, actions, rewards, ends, cuts = [as_float32(obs, copy=True)], [], [], [], []
        done = False
        while not done:
            action = np.asarray(policy.predict(obs)[0], dtype=np.float32).reshape(
                env.action_space.shape)
            obs, reward, terminated, truncated, _ = env.step(action)
            seen.append(as_float32(obs, copy=True))
            actions.append(action)
            rewards.append(float(reward))
            ends.append(bool(terminated))
            cuts.append(bool(truncated))
            done = terminated or truncated
        if isinstance(seen[0], dict):
            observations = {key: np.stack([o[key] for o in seen]) for key in seen[0]}
        else:
            observations = np.stack(seen)
        buffers.append(EpisodeBuffer(id=k, seed=seed + k, observations=observations,
                                     actions=np.stack(actions), rewards=rewards,
                                     terminations=ends, truncations=cuts, infos={}))
    return buffers


def _float_space(space):
    """``space`` with its boxes as float32 (the buffers hold float32
    observations, as the training stack sees them)."""
    import gymnasium as gym

    if isinstance(space, gym.spaces.Dict):
        return gym.spaces.Dict({k: _float_space(v) for k, v in space.spaces.items()})
    if isinstance(space, gym.spaces.Box) and space.dtype != np.float32:
        return gym.spaces.Box(space.low.astype(np.float32), space.high.astype(np.float32),
                              space.shape, dtype=np.float32)
    return space


def write_dataset(env_id: str, env_kwargs: dict, teacher: str, episodes: int, seed: int,
                  root: Path, name: str, progress: bool = False) -> dict:
    """Sail the episodes and write them as the Minari dataset
    :func:`dataset_id` under ``root``; returns the summary also written to
    ``root / f"{name}.json"``. An existing dataset of that id is refused."""
    import gymnasium as gym
    import minari

    import iceenvs  # noqa: F401  (registers the ids)

    from physics.provenance import source_commit

    ident = dataset_id(env_id, name)
    root = Path(root)
    if (root / ident).exists():
        raise FileExistsError(f"dataset {ident} exists under {root}; choose another --name or "
                              f"delete it")
    os.environ["MINARI_DATASETS_PATH"] = str(root.resolve())
    env = gym.make(env_id, **env_kwargs)
    began = time.perf_counter()
    try:
        buffers = sail(env, teacher, episodes, seed, progress=progress)
        with warnings.catch_warnings():
            # Minari asks for a code permalink, an author and their email, which a
            # local dataset need not have
            warnings.simplefilter("ignore", UserWarning)
            dataset = minari.create_dataset_from_buffers(
                ident, buffers, env=env, algorithm_name=f"{teacher} (agents.baselines)",
                description=f"{teacher} on {env_id} with {env_kwargs or 'defaults'}, "
                            f"episode k seeded {seed} + k",
                observation_space=_float_space(env.observation_space), data_format="hdf5")
    finally:
        env.close()
    returns = [float(np.sum(b.rewards)) for b in buffers]
    summary = {
        "dataset_id": ident, "env": env_id, "env_kwargs": env_kwargs, "teacher": teacher,
        "episodes": dataset.total_episodes, "steps": dataset.total_steps, "seed": seed,
        "return_mean": float(np.mean(returns)),
        "return_sem": float(np.std(returns, ddof=1) / math.sqrt(len(returns)))
        if len(returns) > 1 else math.nan,
        "seconds": round(time.perf_counter() - began, 1),
        "command": "python -m agents.datasets " + shlex.join(sys.argv[1:])
        if Path(sys.argv[0]).stem == "datasets" else None,
        "commit": source_commit(),
    }
    (root / f"{name}.json").write_text(json.dumps(summary, indent=1) + "\n")
    return summary


def load(root: Path, ident: str):
    """The Minari dataset ``ident`` under ``root``."""
    import minari

    os.environ["MINARI_DATASETS_PATH"] = str(Path(root).resolve())
    return minari.load_dataset(ident)


def demonstrations(dataset):
    """A Minari dataset's episodes as :class:`agents.pretrain.Demonstrations`
    (each step's observation before its action, the action, the reward)."""
    from .pretrain import Demonstrations

    obs, actions, rewards, starts = [], [], [], []
    for episode in dataset.iterate_episodes():
        n = len(episode.actions)
        o = episode.observations
        obs.append({k: v[:n] for k, v in o.items()} if isinstance(o, dict) else o[:n])
        actions.append(episode.actions)
        rewards.append(episode.rewards)
        starts.append(np.arange(n) == 0)
    if not obs:
        raise ValueError("the dataset holds no episode")
    if isinstance(obs[0], dict):
        stacked = {k: np.concatenate([o[k] for o in obs]) for k in obs[0]}
    else:
        stacked = np.concatenate(obs)
    return Demonstrations(stacked, np.concatenate(actions), np.concatenate(rewards),
                          np.concatenate(starts))


def build_parser(prog: str = "python -m agents.datasets") -> argparse.ArgumentParser:
    from .envs import episode_arguments, registered_env_id

    p = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n\n")[0])
    p.add_argument("--env", required=True, type=registered_env_id, help="environment id")
    p.add_argument("--teacher", required=True,
                   help="baseline that sails the episodes (e.g. lattice, swath)")
    episode_arguments(p, episodes=20, seed=30000,
                      kwargs_help="gymnasium.make keywords (e.g. obs_type=costmap_dict)")
    p.add_argument("--root", type=Path, default=DEFAULT_ROOT,
                   help=f"Minari's datasets folder ({DEFAULT_ROOT})")
    p.add_argument("--name", default=None,
                   help="dataset name with its version (default: TEACHER-v0)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


def main(argv: list[str] | None = None, prog: str = "python -m agents.datasets") -> dict:
    parser = build_parser(prog)
    args = parser.parse_args(argv)
    from .envs import parse_key_values

    try:
        kwargs = parse_key_values(args.env_kwargs)
        summary = write_dataset(args.env, kwargs, args.teacher, args.episodes, args.seed,
                                args.root, args.name or f"{args.teacher}-v0",
                                progress=not args.no_progress)
    except (ValueError, FileExistsError) as err:
        parser.error(str(err))
    print(json.dumps(summary, indent=1))
    return summary


if __name__ == "__main__":
    main()
