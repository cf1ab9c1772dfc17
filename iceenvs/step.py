"""The step of every environment: :class:`Episodes`, the one owner of the
episodes' state.

An :class:`Episodes` holds N environments of one class and configuration
and every array that an episode changes outside its engine: the step count,
the last action, the last measurement and observation, the episode's sums
(the ship tasks' running totals), whether the last step failed and whether
the episode ended. A single environment is a batch of one (it makes its own
at construction); a native vector environment (:mod:`iceenvs.vector`) is a
batch of N whose environments join it. Either way a step is
:meth:`Episodes.step`, written once.

One step of the N environments::

    sanitised actions (NaN → 0, ±inf → bound, clip; the caller's)
      → count the step, keep the action
      → each environment applies its action (``apply_action``)
      → the engines advance by the control interval: together in one
        compiled call (:func:`physics.hertz.advance_together`) where the
        family says so (``engines_together``), else each its own (``advance``)
      → measure: on columns where the family measures in batch (the ships,
        ``measure_batch``), else each its ``measure()`` dict
      → reward: on columns where the reward function is the class's own and
        takes columns (``rewards_on_columns``), else each ``reward(action, now)``
      → the ends of the episodes (the class's ``ends``); a failure (the
        task's, the physics', a non-finite reward) pays ``failure_reward``
      → the episode sums (``update_sums``), the observations (on columns for
        a vector observation measured in batch, else each ``observe(now)``),
        and the info (each ``make_info(now)``, or on columns)

A physics failure of one environment (in applying its action, in its engine
or in its measurement) ends its episode alone; the others go on.

What an environment class declares (its task) is listed in
:class:`iceenvs.base.ControlEnv`; this module calls only those public hooks.
"""
from __future__ import annotations

import math

import numpy as np
from gymnasium.vector import VectorEnv
from gymnasium.vector.utils import concatenate, create_empty_array

from physics.hertz import KernelLists, advance_together

from .observations import observation_vectors
from .vector_info import batch_infos, set_row, spread_columns

__all__ = ["Episodes", "advance_all", "ROW_STATE", "PHYSICS_ERRORS", "as_measurement"]

#: the errors of a step that are physics failures: they end the episode
#: (``info["error"]``) instead of reaching the caller
PHYSICS_ERRORS = (FloatingPointError, RuntimeError, ValueError)

#: the per-episode arrays of one environment, as :meth:`Episodes.row_state` gives them
ROW_STATE = ("steps", "last_action", "prev", "obs", "sums", "failed", "ended")


def advance_all(envs, actions: np.ndarray, together: bool,
                lists: KernelLists | None = None) -> list[BaseException | None]:
    """The engine part of a step of ``envs`` (of one class and configuration,
    each with its episode running): each applies its action ``actions[k]``,
    then the engines advance by the control interval, together in one
    compiled call (:func:`physics.hertz.advance_together`, with the typed
    lists ``lists`` kept by the caller) or each its own. Returns per
    environment ``None`` or the physics error that ends its episode."""
    errors: list[BaseException | None] = [None] * len(envs)
    if not together:
        for k, env in enumerate(envs):
            try:
                env.apply_action(actions[k])
                env.advance()
            except PHYSICS_ERRORS as err:
                errors[k] = err
        return errors
    for k, env in enumerate(envs):
        try:
            env.apply_action(actions[k])
        except PHYSICS_ERRORS as err:
            errors[k] = err
    moving = [k for k, err in enumerate(errors) if err is None]
    if moving:
        for k, err in zip(moving, advance_together([envs[k].sim for k in moving],
                                                   envs[0].control_interval, lists=lists)):
            errors[k] = err
    return errors


class Episodes:
    """The episodes of ``envs`` (environments of one class and configuration)
    and their step.

    Parameters
    ----------
    envs : list of ControlEnv
        The environments; environment k joins as row k.
    single : bool
        The batch of a single environment: its step returns the
        environment's own observation and info dict (a native vector
        environment of N = 1 gets a vector info, as at any N).
    lists : KernelLists, optional
        The typed lists of the engines' compiled calls, kept from step to
        step (:class:`physics.hertz.KernelLists`).

    Attributes
    ----------
    steps : ndarray (N,) int — the steps of each episode so far
    last_action : ndarray (N, action size) — the last sanitised action
    prev : list — each episode's last measurement (a dict of SI values)
    obs : list — each episode's last observation
    sums : ndarray (N, len(sum_columns)) — each episode's sums (the ship
        tasks' :data:`~iceenvs.ship_measures.SUM_COLUMNS`; none for the others)
    failed : ndarray (N,) bool — the last step ended the episode by a failure
    ended : ndarray (N,) bool — the last step ended the episode (a failure or
        the task done)
    """

    def __init__(self, envs, *, single: bool = False, lists: KernelLists | None = None):
        self.envs = list(envs)
        n = self.num_envs = len(self.envs)
        if n < 1:
            raise ValueError("a batch of episodes needs at least one environment")
        if single and n != 1:
            raise ValueError(f"a single environment's batch holds one environment, not {n}")
        self.single = bool(single)
        e0 = self.envs[0]
        self.lists = KernelLists() if lists is None else lists
        self.together = e0.engines_together and (not single or e0.single_together)
        self.steps = np.zeros(n, dtype=np.int64)
        self.last_action = np.zeros((n,) + e0.action_space.shape)
        self.prev: list = [None] * n
        self.obs: list = [None] * n
        self.sums = np.zeros((n, len(e0.sum_columns)))
        self.failed = np.zeros(n, dtype=bool)
        self.ended = np.zeros(n, dtype=bool)
        # a family that measures in batch: the measurements' columns
        self._columns = bool(e0.measures_in_batch)
        self._names = tuple(e0.measure_names) if self._columns else ()
        self._prev_raw = np.zeros((n, len(self._names)))
        # the observation's entries that no measurement holds (``horizon``'s time_left)
        self._time_left = [j for j, f in enumerate(e0.features)
                           if f.name == "time_left"] if self._columns else []
        self._reward_kw: dict[str, np.ndarray] = {}
        self._task_rows: list = [None] * n
        self._task: dict | None = None
        self._obs_buffer = None
        for k, env in enumerate(self.envs):
            env.join(self, k)

    #: Gymnasium's builder of a vector info, which needs only ``num_envs``
    _add_info = VectorEnv._add_info

    # -- episodes begin -----------------------------------------------------------------
    def begin(self, k: int) -> tuple:
        """Environment k began an episode (its engine is made): zero action,
        first measurement and observation. Returns what ``reset`` returns."""
        env = self.envs[k]
        self.steps[k] = 0
        self.last_action[k] = 0.0
        self.failed[k] = self.ended[k] = False
        env.apply_action(self.last_action[k])
        now = env.measure()
        self.prev[k] = now
        self.obs[k] = env.observe(now)
        self._rebuild_row(k)
        if env.render_mode == "human":
            env.render()
        return _copy(self.obs[k]), env.make_info(now)

    def _rebuild_row(self, k: int) -> None:
        """The columns kept for a batch measured on columns, after row k
        began an episode or was restored."""
        if not self._columns:
            return
        env = self.envs[k]
        self._prev_raw[k] = [self.prev[k][name] for name in self._names]
        for key, value in env.reward_kwargs().items():
            self._reward_kw.setdefault(key, np.zeros(self.num_envs))[k] = value
        self._task_rows[k] = dict(env.episode)
        self._task = None

    def _task_columns(self) -> dict:
        """The episodes' tasks as columns (name → array over the rows)."""
        if self._task is None:
            task = batch_infos([row or {} for row in self._task_rows])
            self._task = {key: value for key, value in task.items() if not key.startswith("_")}
        return self._task

    # -- snapshots ----------------------------------------------------------------------
    def row_state(self, k: int) -> dict:
        """Row k's per-episode arrays (:data:`ROW_STATE`), as they are (a
        snapshot copies them)."""
        return {"steps": int(self.steps[k]), "last_action": self.last_action[k],
                "prev": self.prev[k], "obs": self.obs[k], "sums": self.sums[k],
                "failed": bool(self.failed[k]), "ended": bool(self.ended[k])}

    def set_row(self, k: int, state: dict) -> None:
        """Set row k's per-episode arrays to ``state`` (of :meth:`row_state`,
        taken of an environment of the same class and configuration)."""
        self.steps[k] = state["steps"]
        self.last_action[k] = state["last_action"]
        self.prev[k] = state["prev"]
        self.obs[k] = state["obs"]
        self.sums[k] = state["sums"]
        self.failed[k] = state["failed"]
        self.ended[k] = state["ended"]
        self._rebuild_row(k)

    # -- the step -------------------------------------------------------------------------
    def step(self, actions: np.ndarray, replaced: np.ndarray) -> tuple:
        """One step of every environment with its sanitised action
        ``actions[k]`` (``replaced[k]``: its entries that were not finite).
        Returns (observations, rewards, terminated, info): batched, or for
        a :attr:`single` batch the environment's observation and info dict
        (rewards and terminated stay arrays of one)."""
        self.steps += 1
        self.last_action[:] = actions
        errors = advance_all(self.envs, actions, self.together, self.lists)
        return self._finish(actions, replaced, errors)

    def _finish(self, actions, replaced, errors) -> tuple:
        """The end of a step whose engines ran (``errors[k]``: the physics
        failure of environment k, or None): measurements, rewards, ends,
        sums, observations and info."""
        n = self.num_envs
        rewards = np.zeros(n)
        terminated = np.zeros(n, dtype=bool)
        ok = [k for k in range(n) if errors[k] is None]
        if self._columns:
            infos = self._on_columns(np.array(ok, dtype=np.int64), errors, actions, replaced,
                                     rewards, terminated)
        else:
            infos = self._by_rows(ok, errors, actions, replaced, rewards, terminated)
        rows = infos if isinstance(infos, list) else None   # a dict each, or columns
        for k in range(n) if errors.count(None) < n else ():
            if errors[k] is None:
                continue
            env = self.envs[k]
            info = env.make_info(self.prev[k])
            info["error"] = f"{type(errors[k]).__name__}: {errors[k]}"
            info["nonfinite_action"] = int(replaced[k])
            rewards[k] = float(env.failure_reward)
            terminated[k] = True
            self.failed[k] = self.ended[k] = True
            if rows is not None:
                rows[k] = info
            else:
                infos = set_row(self, infos, info, k)
        if self.single:
            return _copy(self.obs[0]), rewards, terminated, rows[0]
        obs = self.batched_obs()
        return obs, rewards, terminated, batch_infos(rows) if rows is not None else infos

    def _keep(self, env, k: int, now: dict, reward: float, succeeded, failed, rewards,
              terminated) -> None:
        """Row k's end of a step that measured ``now``: its reward (the
        failure reward for a failure), end and flags, and ``now`` as its last
        measurement."""
        rewards[k] = env.failure_reward if failed else reward
        terminated[k] = bool(succeeded) or bool(failed)
        self.failed[k] = failed
        self.ended[k] = terminated[k]
        self.prev[k] = now

    def _by_rows(self, ok, errors, actions, replaced, rewards, terminated) -> list:
        """The step's end for a family that measures each environment on its
        own: each measures (``measure``), is rewarded (``reward``), ends
        (the class's ``ends``), observes and makes its info dict. Fills the
        rows ``ok`` of ``rewards`` and ``terminated`` (a physics failure of
        a measurement goes into ``errors``); returns the infos, one per row
        (None where the step failed)."""
        nows = []
        for k in ok:
            try:
                nows.append(self.envs[k].measure())
            except PHYSICS_ERRORS as err:
                errors[k] = err
        if len(nows) < len(ok):
            ok = [k for k in ok if errors[k] is None]
        infos: list = [None] * self.num_envs
        if not ok:
            return infos
        group = self.envs if len(ok) == self.num_envs else [self.envs[k] for k in ok]
        succeeded, failed = self.envs[0].ends(group, nows, None, None, None)
        for i, k in enumerate(ok):
            env, now = group[i], nows[i]
            reward = env.reward(actions[k], now)
            info = env.make_info(now)
            info["nonfinite_action"] = int(replaced[k])
            fail = bool(failed[i])
            if not math.isfinite(reward):
                info["error"] = f"non-finite reward {reward}"
                fail = True
            self._keep(env, k, now, reward, succeeded[i], fail, rewards, terminated)
            self.obs[k] = env.observe(now)
            if env.render_mode == "human":
                env.render()
            infos[k] = info
        return infos

    def _on_columns(self, ok, errors, actions, replaced, rewards, terminated):
        """The step's end for a family that measures a batch on columns (the
        ships): one ``measure_batch`` of the environments ``ok``, the rewards
        on columns (per environment for a single environment or a reward
        function of one's own), the ends (``ends``), the sums
        (``update_sums``) and the vector observations on columns. Fills the
        rows ``ok`` of ``rewards`` and ``terminated`` (a physics failure of
        the measurement fails every one, into ``errors``); returns the
        infos: for a single environment a list of its dict, else the
        columns (a vector info)."""
        n = self.num_envs
        if not ok.size:
            return [None] * n
        e0 = self.envs[0]
        full = ok.size == n
        group = self.envs if full else [self.envs[k] for k in ok]
        sums = self.sums if full else self.sums[ok]
        try:
            raw = e0.measure_batch(group, sums, self.lists)
        except PHYSICS_ERRORS as err:              # every measured one fails with it
            for k in ok:
                errors[k] = err
            return [None] * n
        nows = [as_measurement(self._names, row, e0.integer_measures) for row in raw]
        cols = dict(zip(self._names, raw.T))
        task = {key: value if full else value[ok] for key, value in self._task_columns().items()}
        if not self.single and e0.rewards_on_columns and all(
                env.reward_fn is type(env).reward_fn for env in self.envs):
            kw = {key: value if full else value[ok] for key, value in self._reward_kw.items()}
            prev = dict(zip(self._names, (self._prev_raw if full else self._prev_raw[ok]).T))
            reward = np.asarray(e0.reward_fn(prev, actions[ok], cols, **kw), dtype=float)
            reward = np.broadcast_to(reward, ok.shape).copy()
        else:
            reward = np.array([env.reward(actions[k], now)
                               for env, k, now in zip(group, ok, nows)], dtype=float)
        bad = ~np.isfinite(reward)
        succeeded, failed = e0.ends(group, nows, cols, sums, task)
        failed = np.asarray(failed, dtype=bool) | bad
        for i, (env, k, now) in enumerate(zip(group, ok, nows)):
            self._keep(env, k, now, reward[i], succeeded[i], failed[i], rewards, terminated)
        e0.update_sums(sums, cols)
        if not full:
            self.sums[ok] = sums
        self._prev_raw[ok] = raw
        if e0.observes_on_columns:
            features = raw[:, e0.feature_columns]
            for j in self._time_left:
                features[:, j] = [env.time_left() for env in group]
            for k, vector in zip(ok, observation_vectors(features, e0.features, actions[ok])):
                self.obs[k] = vector
        else:
            for env, k in zip(group, ok):
                self.obs[k] = env.observe(self.prev[k])
        for env in group:
            if env.render_mode == "human":
                env.render()
        if self.single:                      # a single environment: its info dict
            info = e0.make_info(nows[0])
            info["nonfinite_action"] = int(replaced[0])
            if bad[0]:
                info["error"] = f"non-finite reward {reward[0]}"
            return [info]
        columns = e0.info_columns(raw, sums, self.steps[ok], task)
        columns["nonfinite_action"] = np.asarray(replaced)[ok]
        infos = spread_columns(columns, ok, n)
        for i in np.flatnonzero(bad):
            infos = self._add_info(infos, {"error": f"non-finite reward {reward[i]}"}, ok[i])
        return infos

    def batched_obs(self):
        """The observations of every row as one batch (a fresh copy)."""
        space = self.envs[0].observation_space
        if self._obs_buffer is None:
            self._obs_buffer = create_empty_array(space, self.num_envs)
        self._obs_buffer = concatenate(space, self.obs, self._obs_buffer)
        return _copy(self._obs_buffer)


def as_measurement(names, row: np.ndarray, integers=()) -> dict:
    """One row of a batch's measurements as a measurement dict (the names
    ``integers`` as ints)."""
    now = dict(zip(names, row.tolist()))
    for name in integers:
        now[name] = int(now[name])
    return now


def _copy(obs):
    """A fresh copy of an observation (an array or a dict of arrays)."""
    if isinstance(obs, dict):
        return {key: value.copy() for key, value in obs.items()}
    return obs.copy()
