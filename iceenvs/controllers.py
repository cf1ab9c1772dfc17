"""Hand-written controllers: the base of every environment's own controllers.

A controller needs only the environment: it decides on the *raw*
observation (not a normalised one) and the environment's public
attributes, never on privileged state, so any policy could do the same;
its class is named ``*Controller``. It has the ``predict`` interface of a
Stable-Baselines3 model, ``predict(obs, deterministic=True) -> (action,
None)``, for one observation or a batch, may keep state within an
episode, and ``reset(seed)`` starts a new episode: it satisfies the
:class:`agents.policy.Policy` protocol. An environment names its
controllers in its facts (:class:`iceenvs.facts.EnvFacts`),
``"heuristic"`` for the hand-written controller of its task; the
controller classes live beside the environment they control
(``WindDriftController`` in :mod:`iceenvs.wind_drift`, the ship
controllers in :mod:`iceenvs.ship_controllers`). The planners of
:mod:`agents.planners` (``*Planner``, which may read privileged state) and
the generic baselines of :mod:`agents.baselines` (``*Policy``) build on
:class:`Controller` too; :func:`agents.baselines.make_baseline` builds
them all by name.
"""
from __future__ import annotations

import gymnasium as gym
import numpy as np

__all__ = ["Controller", "FloeController"]


class Controller:
    """Base of the controllers: batching, clipping and episode resets.

    Parameters
    ----------
    env : gymnasium.Env
        The environment the policy acts in (spaces, feature layout and
        task parameters are read from it).
    seed : int
        Seed of any random choice of the policy.
    """

    def __init__(self, env: gym.Env, seed: int = 0):
        self.env = env
        self.action_space = env.action_space
        self.observation_space = env.observation_space
        self.seed = int(seed)

    def reset(self, seed: int | None = None) -> None:
        """Start a new episode (``seed``: the episode's seed)."""

    def act(self, obs: np.ndarray) -> np.ndarray:
        """The action for one raw observation."""
        raise NotImplementedError

    def predict(self, obs, state=None, episode_start=None, deterministic: bool = True):
        """``(action, None)`` for one observation or a batch (first axis)."""
        obs = np.asarray(obs, dtype=np.float32)
        low, high = self.action_space.low, self.action_space.high
        if obs.ndim == len(self.observation_space.shape) + 1:
            actions = np.stack([np.clip(self.act(o), low, high) for o in obs])
            return actions.astype(self.action_space.dtype), None
        return np.clip(self.act(obs), low, high).astype(self.action_space.dtype), None


class FloeController(Controller):
    """A controller of a floe environment: observation entries by feature
    name."""

    def __init__(self, env, seed: int = 0):
        super().__init__(env, seed)
        names = [f.name for f in env.unwrapped.features]
        self._index = {n: k for k, n in enumerate(names)}
        self.reward_params = env.unwrapped.reward_params

    def _get(self, obs, name: str) -> float:
        return float(obs[self._index[name]])
