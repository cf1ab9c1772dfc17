"""Shared plumbing of the floe environments: :class:`FloeEnv`.

A floe environment owns one engine (``self.sim``), turns an action into
forcing, advances the engine by the control interval, measures the
observables of :mod:`iceenvs.observations` and scores them with a reward
function of :mod:`iceenvs.rewards`. Subclasses say only what differs:

* ``_make_sim(rng, options)`` — a new engine for an episode;
* ``_apply_action(action)`` — the (clipped) action into forcing;
* ``_measure()`` — the raw physical observables (dict of SI values);
* ``_terminated(now)`` — task failure;
* class attributes ``extra_features`` (entries after the common ones),
  ``action_names`` and the default ``reward_fn``.

Data flow of one step::

    action → NaN/inf → 0, clip → forcing → engine.advance(control interval)
      → observables (SI dict) → reward(prev, action, now) and float32 vector
"""
from __future__ import annotations

import math
from typing import Callable

import gymnasium as gym
import numpy as np

from physics import PaperPreset
from physics.hertz import hertz_time_step, scaled_contact  # noqa: F401  (used by the envs)
from physics.params import check_range

from .observations import FLOE_FEATURES, Feature, normalise

__all__ = ["ControlEnv", "FloeEnv", "sanitise_action", "scaled_contact", "hertz_time_step"]


def sanitise_action(action, space: gym.spaces.Box) -> np.ndarray:
    """The action as float64 of the space's shape with NaN and ±inf set to
    0 and every entry clipped into the space's bounds."""
    a = np.array(action, dtype=np.float64).reshape(space.shape)
    a[~np.isfinite(a)] = 0.0
    return np.clip(a, space.low, space.high)


class ControlEnv(gym.Env):
    """The control loop every environment of the suite shares.

    One step: sanitise the action → ``_apply_action`` → ``_advance`` →
    ``_measure`` (raw SI dict) → ``_reward`` → observation ``_vector`` and
    ``_info``. A physics failure (FloatingPointError, RuntimeError,
    ValueError) or a non-finite reward ends the episode with
    ``info["error"]`` and ``failure_reward``; the episode is truncated after
    ``episode_steps`` steps.

    Failures are absorbing: when an episode is terminated (task failure
    of ``_terminated`` or a physics failure) before its last step, the
    steps it had left are charged the failing step's reward if that is
    negative (:meth:`_failure_return`). Ending an episode early therefore
    never pays more than living on in the failed state; without this, a
    task whose per-step rewards are negative would reward breaking the
    ice. Subclasses build their model in ``reset`` and
    then call ``_begin_episode``; they provide the hooks named above,
    ``_ready`` (a model exists) and ``_frame`` (an RGB array).
    """

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 10}
    failure_reward = -10.0
    _renderer = None

    def _set_render_mode(self, render_mode: str | None) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be one of {self.metadata['render_modes']} or "
                             f"None, got {render_mode!r}")
        self.render_mode = render_mode

    # -- hooks --------------------------------------------------------------------------
    def _ready(self) -> bool:
        raise NotImplementedError

    def _apply_action(self, action: np.ndarray) -> None:
        raise NotImplementedError

    def _advance(self) -> None:
        raise NotImplementedError

    def _measure(self) -> dict:
        raise NotImplementedError

    def _vector(self, now: dict) -> np.ndarray:
        raise NotImplementedError

    def _info(self, now: dict) -> dict:
        raise NotImplementedError

    def _terminated(self, now: dict) -> bool:
        return False

    def _reward(self, action: np.ndarray, now: dict) -> float:
        return float(self.reward_fn(self._prev, action, now, **self.reward_params))

    def _frame(self) -> np.ndarray:
        raise NotImplementedError

    def _failure_return(self, reward: float) -> float:
        """The reward of a terminating step: ``reward`` plus, for each step
        the episode had left, ``min(reward, 0)`` (the failed state is
        absorbing)."""
        left = max(int(self.episode_steps) - int(self._steps), 0)
        return reward + left * min(reward, 0.0)

    # -- the loop -----------------------------------------------------------------------
    def _begin_episode(self):
        """Zero action, first measurement and observation of a new episode;
        returns what ``reset`` returns."""
        self._steps = 0
        self._last_action = np.zeros(self.action_space.shape[0])
        self._apply_action(self._last_action)
        now = self._measure()
        self._prev = now
        self._obs = self._vector(now)
        if self.render_mode == "human":
            self.render()
        return self._obs.copy(), self._info(now)

    def step(self, action):
        if not self._ready():
            raise RuntimeError("call reset() before step()")
        a = sanitise_action(action, self.action_space)
        self._last_action = a
        self._steps += 1
        try:
            self._apply_action(a)
            self._advance()
            now = self._measure()
        except (FloatingPointError, RuntimeError, ValueError) as err:
            # a physics failure ends the episode instead of crashing the caller
            info = self._info(self._prev)
            info["error"] = f"{type(err).__name__}: {err}"
            return (self._obs.copy(), self._failure_return(float(self.failure_reward)), True,
                    False, info)
        reward = self._reward(a, now)
        info = self._info(now)
        terminated = bool(self._terminated(now))
        if not math.isfinite(reward):
            info["error"] = f"non-finite reward {reward}"
            reward, terminated = float(self.failure_reward), True
        if terminated:
            reward = self._failure_return(reward)
        self._prev = now
        self._obs = self._vector(now)
        truncated = self._steps >= self.episode_steps and not terminated
        if self.render_mode == "human":
            self.render()
        return self._obs.copy(), reward, terminated, truncated, info

    # -- rendering ----------------------------------------------------------------------
    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode="
                            "'rgb_array' or 'human' to gymnasium.make")
            return None
        if not self._ready():
            raise RuntimeError("call reset() before render()")
        frame = self._frame()
        if self.render_mode == "rgb_array":
            return frame
        from .rendering import Window

        if self._renderer is None:
            self._renderer = Window(type(self).__name__, frame.shape[1], frame.shape[0],
                                    self.metadata["render_fps"])
        self._renderer.show(frame)
        return None

    def close(self):
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


class FloeEnv(ControlEnv):
    """Base of the floe environments (not registered itself).

    Parameters common to every floe environment
    -------------------------------------------
    n_floes : int — number of floes
    concentration : float — ice concentration Ā of the start state
    preset : PaperPreset — parameter table (FSD, material, forcing)
    control_interval : float — model seconds per env step
    episode_steps : int — env steps before the episode is truncated
    reward_fn : callable, optional — ``reward(prev, action, now, **reward_params)``
    reward_params : dict, optional — overrides of the task's reward parameters
    stiffness_scale : float — multiplies Young's modulus (Hertz envs); < 1
        trades contact stiffness for a longer time step (faster training)
    cluster_gap : float — largest gap [m] between two floes of a cluster
    render_mode : None, "rgb_array" or "human"
    """

    extra_features: tuple[Feature, ...] = ()
    action_names: tuple[str, ...] = ()
    reward_fn: Callable = None

    def __init__(self, *, n_floes: int, concentration: float, preset: PaperPreset,
                 control_interval: float, episode_steps: int, reward_fn=None,
                 reward_params: dict | None = None, stiffness_scale: float = 1.0,
                 cluster_gap: float = 0.1, render_mode: str | None = None):
        check_range("n_floes", n_floes, 2, None)
        check_range("concentration", concentration, 0.0, 1.0, low_open=True, high_open=True)
        check_range("control_interval", control_interval, 0.0, None, low_open=True)
        check_range("episode_steps", episode_steps, 1, None)
        check_range("cluster_gap", cluster_gap, 0.0, None)
        if not isinstance(preset, PaperPreset):
            raise TypeError(f"preset must be a PaperPreset (e.g. physics.HERMAN2013), "
                            f"got {type(preset).__name__}")
        self._set_render_mode(render_mode)
        self.n_floes = int(n_floes)
        self.concentration = float(concentration)
        self.preset = preset
        self.control_interval = float(control_interval)
        self.episode_steps = int(episode_steps)
        self.stiffness_scale = float(stiffness_scale)
        self.contact = scaled_contact(preset.contact, stiffness_scale)
        self.cluster_gap = float(cluster_gap)
        if reward_fn is not None:
            if not callable(reward_fn):
                raise TypeError("reward_fn must be callable as reward(prev, action, now, **params)")
            self.reward_fn = reward_fn
        else:
            self.reward_fn = type(self).reward_fn
        self.reward_params = self.default_reward_params()
        unknown = set(reward_params or ()) - set(self.reward_params)
        if unknown and reward_fn is None:
            raise ValueError(f"unknown reward parameters {sorted(unknown)}; this task has "
                             f"{sorted(self.reward_params)}")
        self.reward_params.update(reward_params or {})

        self.features = FLOE_FEATURES + self.extra_features
        n_act = self.action_space.shape[0]
        low = np.array([f.low for f in self.features] + [-1.0] * n_act, dtype=np.float32)
        high = np.array([f.high for f in self.features] + [1.0] * n_act, dtype=np.float32)
        self.observation_space = gym.spaces.Box(low, high, dtype=np.float32)
        self.sim = None
        self._steps = 0
        self._last_action = np.zeros(n_act)
        self._prev = None
        self._obs = None

    # -- to be provided by subclasses ------------------------------------------------
    def default_reward_params(self) -> dict:
        return {}

    def _make_sim(self, rng: np.random.Generator, options: dict):
        raise NotImplementedError

    def _ready(self) -> bool:
        return self.sim is not None

    def _advance(self) -> None:
        self.sim.advance(self.control_interval)

    # -- gymnasium API ----------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        options = dict(options or {})
        self._reset_options(options)
        self.sim = self._make_sim(self.np_random, options)
        return self._begin_episode()

    def _reset_options(self, options: dict) -> None:
        """Task options of ``reset(options=...)`` (subclasses read theirs)."""
        if options:
            raise ValueError(f"unknown reset options {sorted(options)}")

    def _vector(self, now: dict) -> np.ndarray:
        vec = normalise(now, self.features)
        return np.concatenate([vec, self._last_action.astype(np.float32)])

    def _info(self, now: dict) -> dict:
        return {"physics": dict(now), "time": float(self.sim.time), "steps": self._steps}


class HertzEnv(FloeEnv):
    """Base of the environments over the Hertz engine
    (:class:`physics.HertzSimulation`): measurement from the engine's
    contacts and Love–Weber stress, frames with force chains.

    ``impact_speed`` [m/s] is the largest relative speed at impact the time
    step must resolve (wind of 20 m/s drives floes at about 0.5 m/s).
    """

    impact_speed = 1.0

    def _hertz_sim(self, field, box, forcing):
        from physics import HertzSimulation

        dt = hertz_time_step(field, box, self.contact, self.impact_speed,
                             self.preset.time_step,
                             self.stiffness_scale)
        return HertzSimulation(field, box, self.contact, forcing, dt=dt,
                               impact_speed=self.impact_speed, parallel=False)

    def _contact_physics(self) -> dict:
        from physics.observables import stress

        from .observations import floe_physics

        sim = self.sim
        self._contacts = sim.contacts()
        area = sim.box.area
        st = stress(self._contacts, area, n_floes=sim.n_floes, per_floe=False)
        mobile = sim.inv_mass > 0
        return floe_physics(sim.positions, sim.velocities, sim.mass, sim.radius, sim.box,
                            self._contacts, st.tensor, area, mobile,
                            cluster_gap=self.cluster_gap)

    def _measure(self) -> dict:
        return self._contact_physics()

    def _frame(self) -> np.ndarray:
        from .rendering import draw_floes

        sim = self.sim
        c = self._contacts
        return draw_floes(sim.positions, sim.radius, (sim.box.lx, sim.box.ly),
                          np.hypot(sim.velocities[:, 0], sim.velocities[:, 1]),
                          frozen=sim.inv_mass == 0, contact_i=c.i, contact_j=c.j,
                          contact_force=c.normal_force)
