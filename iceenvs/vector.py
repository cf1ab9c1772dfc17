"""Native vector environments: N sub-environments of a Hertz environment whose
engines advance together, in one compiled call per step
(:func:`physics.hertz.advance_together`), in parallel over the cores.

``gymnasium.make_vec(id, num_envs=N, vectorization_mode="vector_entry_point")``
builds one for every environment registered with a ``vector_entry_point``
(:data:`iceenvs.ENV_IDS`; ``iceenvs.facts.env_spec(id).vector_entry_point``
says which). It keeps Gymnasium's vector conventions:

* ``metadata["autoreset_mode"]`` is ``AutoresetMode.SAME_STEP``: a sub-environment
  whose episode ends is reset in the same step; the step returns the first
  observation of the new episode, and ``info["final_obs"]`` and
  ``info["final_info"]`` (with their masks ``_final_obs``, ``_final_info``)
  hold the last observation and info of the one that ended;
* ``info`` is one dict of arrays with a mask ``_key`` per key, as
  :class:`gymnasium.vector.SyncVectorEnv` gives;
* episodes are truncated after the registered ``max_episode_steps`` (or the
  ``max_episode_steps`` given to ``make_vec``), as the single environment's
  ``TimeLimit`` does;
* ``reset(seed=s)`` seeds sub-environment k with ``s + k`` (a list gives each
  its seed). Sub-environment k then runs the episode of the single
  environment seeded ``s + k``, step for step: the engines do the same
  arithmetic in the same order, so the observations and rewards are the
  same numbers.

Task parameters are keyword arguments (for every sub-environment and every
episode) or reset options: one dict for all sub-environments, or a list of
N dicts, one per sub-environment. ``render_env=k`` chooses the
sub-environment that ``render()`` draws (``render_mode`` as in the single
environment).

The sub-environments' episodes are one :class:`iceenvs.step.Episodes`, the
batch whose step every environment takes (a single environment is a batch
of one): the engines advance in one compiled call, and the ship
environments measure, score and observe on columns over the
sub-environments. The step is written once.

>>> import gymnasium as gym
>>> import iceenvs  # noqa: F401
>>> envs = gym.make_vec("iceenvs/ShipNavigation-v0", num_envs=2,
...                     vectorization_mode="vector_entry_point")
>>> obs, info = envs.reset(seed=0)
>>> obs.shape
(2, 34)
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from .base import ControlEnv, sanitise_actions
from .step import Episodes
from .vector_info import batch_infos, put_row, row_info, set_row

__all__ = ["HertzVectorEnv", "batch_infos", "row_info", "set_row", "put_row", "vector_class"]


class HertzVectorEnv(VectorEnv):
    """N sub-environments of one Hertz environment class, stepped together.

    Subclasses set ``env_class`` (each environment module defines its own,
    e.g. :class:`iceenvs.ship_navigation.ShipNavigationVectorEnv`).

    Parameters
    ----------
    num_envs : int
        Number of sub-environments (>= 1).
    max_episode_steps : int, optional
        Episode length (``make_vec`` passes the registered one); ``None``:
        never truncated.
    render_mode : None, "rgb_array" or "human"
        The render mode of the sub-environment ``render_env``.
    render_env : int
        The sub-environment that :meth:`render` draws.
    **kwargs
        Arguments of the environment (the same for every sub-environment).

    Raises
    ------
    ValueError, TypeError
        A bad ``num_envs``, ``max_episode_steps`` or ``render_env``, or the
        environment's own error for a bad argument.
    """

    env_class: type[ControlEnv] = ControlEnv
    metadata = {"autoreset_mode": AutoresetMode.SAME_STEP, "render_modes": ["rgb_array", "human"]}

    def __init__(self, num_envs: int = 1, *, max_episode_steps: int | None = None,
                 render_mode: str | None = None, render_env: int = 0, **kwargs):
        for name, value, optional in (("num_envs", num_envs, False),
                                      ("max_episode_steps", max_episode_steps, True)):
            if value is None and optional:
                continue
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
                raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
        if (isinstance(render_env, bool) or not isinstance(render_env, (int, np.integer))
                or not 0 <= render_env < num_envs):
            raise ValueError(f"render_env must be the index of a sub-environment, 0 to "
                             f"{num_envs - 1}, got {render_env!r}")
        if self.env_class is ControlEnv:
            raise TypeError("HertzVectorEnv is a base class; use the vector environment of an "
                            "environment (its registration's vector_entry_point)")
        self.num_envs = int(num_envs)
        self.max_episode_steps = None if max_episode_steps is None else int(max_episode_steps)
        self.render_env = int(render_env)
        self.envs = [self.env_class(render_mode=render_mode if k == render_env else None,
                                    **kwargs) for k in range(self.num_envs)]
        first = self.envs[0]
        self.render_mode = self.envs[self.render_env].render_mode
        self.metadata = {**type(self).metadata, "render_fps": first.metadata["render_fps"]}
        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        #: the sub-environments' episodes and their step
        self.episodes = Episodes(self.envs)
        self._ready = False

    # -- Gymnasium API -----------------------------------------------------------------
    def reset(self, *, seed: int | Sequence[int | None] | None = None,
              options: dict[str, Any] | Sequence[dict[str, Any]] | None = None):
        """Reset every sub-environment: ``seed`` an int (sub-environment k gets
        ``seed + k``), a list of N seeds or ``None``; ``options`` one dict for
        all or a list of N dicts."""
        seeds = self._per_env("seed", seed, (int, np.integer), lambda s, k: s + k)
        opts = self._per_env("options", options, dict, lambda o, k: o)
        super().reset(seed=None)
        infos = [env.reset(seed=seeds[k], options=opts[k])[1]
                 for k, env in enumerate(self.envs)]
        self._ready = True
        return self.episodes.batched_obs(), batch_infos(infos)

    def step(self, actions):
        """One step of every sub-environment; the engines advance together."""
        if not self._ready:
            raise RuntimeError("call reset() before step()")
        actions, replaced = sanitise_actions(self._checked_actions(actions),
                                             self.single_action_space)
        obs, rewards, terminated, infos = self.episodes.step(actions, replaced)
        truncated = np.zeros(self.num_envs, dtype=bool)
        if self.max_episode_steps is not None:
            truncated[:] = self.episodes.steps >= self.max_episode_steps
        for k in np.flatnonzero(terminated | truncated):
            final = ({key: value[k] for key, value in obs.items()} if isinstance(obs, dict)
                     else obs[k].copy())
            final_info = row_info(infos, k)
            o, info = self.envs[k].reset()
            put_row(obs, k, o)
            infos = set_row(self, infos, info, k)
            infos = self._add_info(infos, {"final_obs": final, "final_info": final_info}, k)
        return obs, rewards, terminated, truncated, infos

    # -- snapshots ------------------------------------------------------------------------
    def snapshot(self, index: int | None = None):
        """The state of sub-environment ``index``'s episode now
        (:meth:`iceenvs.base.ControlEnv.snapshot`), or with ``index`` None
        a tuple of every sub-environment's.

        A sub-environment whose episode ended in a step was reset in that
        step (``AutoresetMode.SAME_STEP``): its snapshot holds the new
        episode from its first observation, with the random generator that
        drew it; the last observation and info of the episode that ended
        (``info["final_obs"]``, ``info["final_info"]``) are not in it. Its
        step count is in it, so the truncation after ``max_episode_steps``
        comes at the same step after a restore.

        Raises ``RuntimeError`` before the first ``reset`` and
        ``ValueError`` for an index that is not a sub-environment's."""
        if not self._ready:
            raise RuntimeError("call reset() before snapshot(): there is no episode to save")
        if index is None:
            return tuple(env.snapshot() for env in self.envs)
        return self.envs[self._index(index)].snapshot()

    def restore(self, snapshot, index: int | None = None) -> None:
        """Bring back sub-environment ``index``'s episode from ``snapshot``
        (of a sub-environment of a vector environment made with the same
        arguments, or of a single environment made with them); the others
        go on as they are. With ``index`` None, ``snapshot`` is the tuple of
        :meth:`snapshot` and every sub-environment is restored. The next
        steps give the restored sub-environments the observations, rewards,
        ends and infos they had after the snapshot, bit for bit, given the
        same actions.

        Raises ``RuntimeError`` before the first ``reset``, ``ValueError``
        for a bad index, a tuple of another length, or a snapshot of another
        environment or configuration, and ``TypeError`` for anything but a
        snapshot."""
        if not self._ready:
            raise RuntimeError("call reset() before restore(): restore into an environment "
                               "that has begun its episodes")
        if index is None:
            if not isinstance(snapshot, (tuple, list)) or len(snapshot) != self.num_envs:
                raise ValueError(f"restore without an index takes the tuple of "
                                 f"{self.num_envs} snapshots that snapshot() returns, got "
                                 f"{type(snapshot).__name__}"
                                 + (f" of {len(snapshot)}" if isinstance(snapshot, (tuple, list))
                                    else ""))
            for k, one in enumerate(snapshot):
                self.restore(one, k)
            return
        self.envs[self._index(index)].restore(snapshot)

    def _index(self, index) -> int:
        if (isinstance(index, bool) or not isinstance(index, (int, np.integer))
                or not 0 <= index < self.num_envs):
            raise ValueError(f"index must be that of a sub-environment, 0 to "
                             f"{self.num_envs - 1}, got {index!r}")
        return int(index)

    def render(self):
        """The frame of sub-environment ``render_env`` (``render_mode``
        "rgb_array"), or ``None``."""
        if not self._ready:
            raise RuntimeError("call reset() before render()")
        return self.envs[self.render_env].render()

    def close_extras(self, **kwargs):
        for env in self.envs:
            env.close()

    # -- helpers -------------------------------------------------------------------------
    def _per_env(self, name: str, value, kind, spread) -> list:
        """``value`` for each sub-environment: ``None`` for all, one value of
        type ``kind`` spread with ``spread(value, k)``, or a sequence of N."""
        n = self.num_envs
        if value is None:
            return [None] * n
        if isinstance(value, kind) and not isinstance(value, bool):
            return [spread(value, k) for k in range(n)]
        if isinstance(value, Sequence) and not isinstance(value, (str, bytes)):
            if len(value) != n:
                raise ValueError(f"{name} must have one entry per sub-environment "
                                 f"(num_envs={n}), got {len(value)}")
            return list(value)
        raise TypeError(f"{name} must be None, one {getattr(kind, '__name__', 'int')} for every "
                        f"sub-environment or a list of {n}, got {type(value).__name__}")

    def _checked_actions(self, actions) -> np.ndarray:
        a = np.asarray(actions, dtype=np.float64)
        shape = (self.num_envs,) + self.single_action_space.shape
        if a.shape != shape:
            if a.shape == (self.num_envs,) and self.single_action_space.shape == (1,):
                return a.reshape(shape)
            raise ValueError(f"actions of shape {a.shape}; this vector environment takes "
                             f"actions of shape {shape} (num_envs × the single action shape)")
        return a

    def __repr__(self):
        return f"{type(self).__name__}(num_envs={self.num_envs})"


def vector_class(env_class: type[ControlEnv]) -> type[HertzVectorEnv]:
    """The native vector environment of ``env_class``: a subclass of
    :class:`HertzVectorEnv`, named after it."""
    name = env_class.__name__.removesuffix("Env") + "VectorEnv"
    return type(name, (HertzVectorEnv,), {
        "env_class": env_class, "__module__": env_class.__module__,
        "__doc__": f"N :class:`{env_class.__name__}` stepped together (:mod:`iceenvs.vector`)."})
