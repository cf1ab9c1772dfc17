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

The engine step runs in one compiled call (:func:`drive`). The end of the
step is the environment's: :class:`HertzVectorEnv` has each sub-environment
measure, score and observe with its own code, one after the other
(:class:`~iceenvs.base.ControlEnv`'s step in three parts), and an
environment whose ``vector_base`` is a subclass makes it in batch. The ship
environments step as one :class:`iceenvs.ship_measures.ShipBatch`
(measurements, rewards, ends of episodes, observations, metrics and info as
arrays over the sub-environments), and their single environment steps as a
batch of one: the step is written once.

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
from gymnasium.vector.utils import batch_space, concatenate, create_empty_array

from physics.hertz import KernelLists, advance_together

from .base import PHYSICS_ERRORS, HertzEnv, sanitise_actions

__all__ = ["HertzVectorEnv", "drive", "batch_infos", "row_info", "set_row", "put_row", "vector_class"]


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

    env_class: type[HertzEnv] = HertzEnv
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
        if self.env_class is HertzEnv:
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
        self._obs = create_empty_array(self.single_observation_space, self.num_envs)
        self._lists = KernelLists()
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
        obs, infos = [], []
        for k, env in enumerate(self.envs):
            o, info = env.reset(seed=seeds[k], options=opts[k])
            obs.append(o)
            infos.append(info)
        self._ready = True
        return self._batch(obs), batch_infos(infos)

    def step(self, actions):
        """One step of every sub-environment; the engines advance together."""
        if not self._ready:
            raise RuntimeError("call reset() before step()")
        actions, replaced = sanitise_actions(self._checked_actions(actions),
                                             self.single_action_space)
        errors = drive(self.envs, actions, self._lists)
        obs, rewards, terminated, infos = self._results(actions, replaced, errors)
        truncated = np.zeros(self.num_envs, dtype=bool)
        if self.max_episode_steps is not None:
            truncated[:] = [env._steps >= self.max_episode_steps for env in self.envs]
        for k in np.flatnonzero(terminated | truncated):
            final = ({key: value[k] for key, value in obs.items()} if isinstance(obs, dict)
                     else obs[k].copy())
            final_info = row_info(infos, k)
            o, info = self.envs[k].reset()
            self._reset_row(k)
            put_row(obs, k, o)
            infos = set_row(self, infos, info, k)
            infos = self._add_info(infos, {"final_obs": final, "final_info": final_info}, k)
        return obs, rewards, terminated, truncated, infos

    def _results(self, actions, replaced, errors) -> tuple:
        """(observations, rewards, terminated, info) of a step whose engines
        ran (``errors[k]``: the physics failure of sub-environment k, or
        None): each sub-environment measures, rewards and observes with its
        own code, one after the other."""
        obs, infos = [], []
        rewards = np.zeros(self.num_envs)
        terminated = np.zeros(self.num_envs, dtype=bool)
        for k, env in enumerate(self.envs):
            result = None
            if errors[k] is None:
                try:
                    now = env._measure()
                except PHYSICS_ERRORS as err:
                    errors[k] = err
                else:
                    result = env._finish_step(actions[k], int(replaced[k]), now)
            if result is None:
                result = env._failed_step(errors[k], int(replaced[k]))
            o, rewards[k], terminated[k], _, info = result
            obs.append(o)
            infos.append(info)
        return self._batch(obs), rewards, terminated, batch_infos(infos)

    def _reset_row(self, k: int) -> None:
        """After sub-environment k started a new episode (a subclass that
        keeps per-episode rows updates them)."""

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
        k = self._index(index)
        self.envs[k].restore(snapshot)
        self._reset_row(k)

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

    def _batch(self, obs: list):
        self._obs = concatenate(self.single_observation_space, obs, self._obs)
        return self._obs.copy() if not isinstance(self._obs, dict) else {
            key: value.copy() for key, value in self._obs.items()}

    def __repr__(self):
        return f"{type(self).__name__}(num_envs={self.num_envs})"


def drive(envs: Sequence[HertzEnv], actions: np.ndarray,
          lists: KernelLists | None = None) -> list[BaseException | None]:
    """The first part of a step of the environments ``envs`` (of one class
    and configuration, each with its episode running), which the native
    vector environments and the single ship environments (a batch of one)
    share: each counts the step and applies its sanitised action
    ``actions[k]``, then their engines advance together by the control
    interval (:func:`physics.hertz.advance_together`, with the typed lists
    ``lists`` kept by the caller). Returns per environment ``None`` or the
    physics error that ends its episode (in applying the action, or in the
    engine)."""
    errors: list[BaseException | None] = [None] * len(envs)
    for k, env in enumerate(envs):
        env._took_action(actions[k])
        try:
            env._apply_action(actions[k])
        except PHYSICS_ERRORS as err:
            errors[k] = err
    moving = [k for k in range(len(envs)) if errors[k] is None]
    if moving:
        for k, err in zip(moving, advance_together([envs[k].sim for k in moving],
                                                   envs[0].control_interval, lists=lists)):
            errors[k] = err
    return errors


def batch_infos(infos: Sequence[dict]) -> dict[str, Any]:
    """The infos of the sub-environments as one Gymnasium vector info: what
    :meth:`gymnasium.vector.VectorEnv._add_info` builds from them one by
    one (a dict of arrays, each key with its mask ``_key`` of the
    sub-environments that have it, nested dicts likewise; numbers in an
    array of the first one's type, arrays stacked, anything else in an
    object array), a column at a time."""
    n = len(infos)
    keys = list(infos[0]) if n else []
    if not (n and all(list(info) == keys for info in infos)):
        return _key_by_key(infos)
    # the common case: every sub-environment has the same keys, in one order
    out: dict[str, Any] = {}
    for key, values in zip(keys, zip(*(info.values() for info in infos))):
        first = values[0]
        array = None
        if isinstance(first, dict):
            if all(isinstance(v, dict) for v in values):
                array = batch_infos(values)
        else:
            array = _column(first, values)
        if array is None:
            array = _key_by_key([{key: v} for v in values])[key]
        out[key], out["_" + key] = array, np.ones(n, dtype=np.bool_)
    return out


def put_row(obs, k: int, value) -> None:
    """Sub-environment k's observation ``value`` into the batched ``obs``
    (an array, or a dict of arrays for a Dict space)."""
    if isinstance(obs, dict):
        for key in obs:
            obs[key][k] = value[key]
    else:
        obs[k] = value


def row_info(infos: dict[str, Any], k: int) -> dict[str, Any]:
    """Sub-environment k's info out of a vector info: the keys whose mask
    is set for k, numbers as Python numbers (the inverse of
    :func:`batch_infos` for one row)."""
    out = {}
    for key, value in infos.items():
        if key.startswith("_") or not infos.get("_" + key, np.zeros(k + 1, bool))[k]:
            continue
        if isinstance(value, dict):
            out[key] = row_info(value, k)
        elif value.dtype == object:
            out[key] = value[k]
        elif value.ndim == 1:
            out[key] = value[k].item()
        else:
            out[key] = value[k].copy()
    return out


def set_row(vector_env: VectorEnv, infos: dict[str, Any], info: dict[str, Any],
            k: int) -> dict[str, Any]:
    """``infos`` with sub-environment k's entries replaced by ``info``:
    its keys set (Gymnasium's ``_add_info``), the others' masks cleared
    for k."""
    for key, value in infos.items():
        if key.startswith("_") or key in info:
            continue
        infos["_" + key][k] = False
        if isinstance(value, dict):
            set_row(vector_env, value, {}, k)
        elif value.dtype != object:
            value[k] = 0
        else:
            value[k] = None
    return vector_env._add_info(infos, info, k)


def _key_by_key(infos: Sequence[dict]) -> dict[str, Any]:
    """:func:`batch_infos` for infos whose keys differ: key by key, each
    sub-environment's value put in its row."""
    n = len(infos)
    out: dict[str, Any] = {}
    for key in dict.fromkeys(k for info in infos for k in info):
        values = [info.get(key, _MISSING) for info in infos]
        present = [v is not _MISSING for v in values]
        first = next(v for v in values if v is not _MISSING)
        if isinstance(first, dict):
            array = batch_infos([{} if v is _MISSING else v for v in values])
        else:
            array = _empty_column(first, n)
            for k, v in enumerate(values):
                if v is not _MISSING:
                    array[k] = v
        out[key], out["_" + key] = array, np.array(present, dtype=np.bool_)
    return out


_MISSING = object()


def _is_number(value) -> bool:
    """Whether ``_add_info`` keeps ``value`` in an array of its own type."""
    return _is_number_type(type(value))


def _is_number_type(kind: type) -> bool:
    """Whether values of type ``kind`` are numbers for :func:`_is_number`."""
    return kind in (int, float, bool) or issubclass(kind, np.number)


def _empty_column(first, n: int) -> np.ndarray:
    """The array that ``_add_info`` starts a key with, from its first value."""
    if _is_number(first):
        return np.zeros(n, dtype=type(first))
    if isinstance(first, np.ndarray):
        return np.zeros((n,) + first.shape, dtype=first.dtype)
    return np.full(n, None, dtype=object)


def _column(first, values: Sequence) -> np.ndarray | None:
    """The column of a key that every sub-environment has, in one call where
    that gives what filling :func:`_empty_column` one by one gives (numbers
    of the first one's type; arrays of one shape and dtype); else None."""
    if _is_number(first):
        # the distinct types, each tested once: a column is mostly of one
        return (np.array(values, dtype=type(first))
                if all(_is_number_type(t) for t in set(map(type, values))) else None)
    if isinstance(first, np.ndarray) and all(
            isinstance(v, np.ndarray) and v.shape == first.shape and v.dtype == first.dtype
            for v in values):
        return np.stack(values)
    return None


def vector_class(env_class: type[HertzEnv]) -> type[HertzVectorEnv]:
    """The native vector environment of ``env_class``: a subclass, named after
    it, of its ``vector_base`` (``None``: :class:`HertzVectorEnv`)."""
    name = env_class.__name__.removesuffix("Env") + "VectorEnv"
    return type(name, (env_class.vector_base or HertzVectorEnv,), {
        "env_class": env_class, "__module__": env_class.__module__,
        "__doc__": f"N :class:`{env_class.__name__}` stepped together (:mod:`iceenvs.vector`)."})
