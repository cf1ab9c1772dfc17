"""Environment construction for training and evaluation: a picklable
factory (for worker processes) and the vectorised stack

    SubprocVecEnv (n_envs > 1) or DummyVecEnv → VecMonitor → VecNormalize

with every sub-environment seeded ``seed + index``.
"""
from __future__ import annotations

from pathlib import Path

__all__ = ["EnvFactory", "make_vec_env", "load_normalization"]


class EnvFactory:
    """Build one environment in the current process.

    Parameters
    ----------
    env_id : str
        A registered id, e.g. ``"iceenvs/Convergence-v0"``.
    env_kwargs : dict, optional
        Passed to :func:`gymnasium.make`.
    seed : int, optional
        Seeds the action space of the new environment (the episodes are
        seeded through ``VecEnv.seed``).

    Notes
    -----
    Calling the factory limits torch to one thread, so that every worker
    of a :class:`~stable_baselines3.common.vec_env.SubprocVecEnv` keeps to
    one core.
    """

    def __init__(self, env_id: str, env_kwargs: dict | None = None, seed: int | None = None):
        self.env_id = env_id
        self.env_kwargs = dict(env_kwargs or {})
        self.seed = seed

    def __call__(self):
        import gymnasium as gym
        import torch

        import iceenvs  # noqa: F401  (registers the ids)

        torch.set_num_threads(1)
        env = gym.make(self.env_id, **self.env_kwargs)
        if self.seed is not None:
            env.action_space.seed(self.seed)
        return env


def make_vec_env(env_id: str, *, n_envs: int, seed: int, env_kwargs: dict | None = None,
                 normalize: dict | None = None, training: bool = True,
                 stats_path: str | Path | None = None):
    """The vectorised environment stack of a run.

    Parameters
    ----------
    env_id : str
        Registered environment id.
    n_envs : int
        Number of environments; > 1 runs them in worker processes.
    seed : int
        Sub-environment ``i`` is seeded ``seed + i``.
    env_kwargs : dict, optional
        Passed to :func:`gymnasium.make`.
    normalize : dict, optional
        Keyword arguments of :class:`VecNormalize` (``None``: no
        normalisation).
    training : bool
        ``False`` builds an evaluation stack: statistics frozen, rewards
        not normalised.
    stats_path : path, optional
        Load the normalisation statistics from this ``vecnormalize.pkl``.

    Returns
    -------
    VecEnv
    """
    from stable_baselines3.common.vec_env import (DummyVecEnv, SubprocVecEnv, VecMonitor,
                                                  VecNormalize)

    fns = [EnvFactory(env_id, env_kwargs, seed + i) for i in range(n_envs)]
    venv = SubprocVecEnv(fns) if n_envs > 1 else DummyVecEnv(fns)
    venv.seed(seed)
    venv = VecMonitor(venv)
    if stats_path is not None and Path(stats_path).exists():
        venv = VecNormalize.load(str(stats_path), venv)
    elif normalize is not None:
        venv = VecNormalize(venv, **normalize)
    if isinstance(venv, VecNormalize) and not training:
        venv.training = False
        venv.norm_reward = False
    return venv


def load_normalization(stats_path: str | Path, env_id: str, env_kwargs: dict | None = None):
    """The saved :class:`VecNormalize` of a run for evaluation
    (``training=False``, ``norm_reward=False``), or ``None`` when the run
    has no statistics file. Use its ``normalize_obs`` on raw observations."""
    if not Path(stats_path).exists():
        return None
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    vn = VecNormalize.load(str(stats_path), DummyVecEnv([EnvFactory(env_id, env_kwargs)]))
    vn.training = False
    vn.norm_reward = False
    return vn
