"""Gymnasium vector environments as Stable-Baselines3 ``VecEnv``.

Gymnasium (1.x) and Stable-Baselines3 batch environments differently:

- a Gymnasium ``step`` returns ``terminated`` and ``truncated``; SB3's returns
  ``dones`` (either) and ``info["TimeLimit.truncated"]``;
- Gymnasium's ``info`` is one dict of arrays, with a mask ``_key`` per key;
  SB3's ``infos`` are one dict per sub-environment;
- with ``AutoresetMode.SAME_STEP``, Gymnasium returns the reset observation
  of an ended episode in the step that ends it and the last one in
  ``info["final_obs"]``; SB3 expects the reset observation and the last one
  in ``info["terminal_observation"]``;
- Gymnasium seeds with ``reset(seed=[...])``, SB3 with ``seed(s)`` then
  ``reset()``.

:class:`GymnasiumVecEnv` wraps a Gymnasium vector environment whose
``metadata["autoreset_mode"]`` is ``AutoresetMode.SAME_STEP`` and gives SB3
exactly what its :class:`~stable_baselines3.common.vec_env.DummyVecEnv`
gives for the same sub-environments: the same observations, rewards,
``dones`` and per-environment infos, step for step. A vector environment
that steps all its sub-environments in one call then trains with SB3 as a
native one.

>>> import gymnasium as gym
>>> from gymnasium.vector import AutoresetMode, SyncVectorEnv
>>> venv = SyncVectorEnv([lambda: gym.make("CartPole-v1")] * 2,
...                      autoreset_mode=AutoresetMode.SAME_STEP)
>>> env = GymnasiumVecEnv(venv)
>>> env.seed(0); obs = env.reset()
"""
from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from stable_baselines3.common.vec_env.base_vec_env import VecEnv

__all__ = ["GymnasiumVecEnv", "unbatch_info"]


def unbatch_info(info: dict, n: int) -> list[dict[str, Any]]:
    """The ``n`` per-environment dicts of a Gymnasium vector ``info`` (a dict
    of arrays, each key with its mask ``_key`` of the environments that set
    it; nested dicts likewise). NumPy scalars become Python numbers."""
    out: list[dict[str, Any]] = [{} for _ in range(n)]
    for key, value in info.items():
        if key.startswith("_"):
            continue
        mask = info.get("_" + key)
        if isinstance(value, dict):
            parts = unbatch_info(value, n)
        elif isinstance(value, np.ndarray) and value.ndim == 1 and value.dtype != object:
            parts = value.tolist()          # a column at once, as Python numbers
        else:
            parts = value
        if mask is None or mask.all():
            for row, v in zip(out, parts):
                row[key] = v.item() if isinstance(v, np.generic) else v
            continue
        for i in np.flatnonzero(mask).tolist():
            v = parts[i]
            out[i][key] = v.item() if isinstance(v, np.generic) else v
    return out


class GymnasiumVecEnv(VecEnv):
    """A Gymnasium vector environment seen by SB3 as a ``VecEnv``.

    Parameters
    ----------
    venv : gymnasium.vector.VectorEnv
        Its ``metadata["autoreset_mode"]`` must be
        ``AutoresetMode.SAME_STEP`` (an ended episode is reset in the step
        that ends it, as SB3 expects).

    Raises
    ------
    ValueError
        For another autoreset mode (the message names it).
    """

    def __init__(self, venv: VectorEnv):
        mode = venv.metadata.get("autoreset_mode")
        if mode != AutoresetMode.SAME_STEP:
            raise ValueError(f"GymnasiumVecEnv needs a vector environment with autoreset_mode "
                             f"AutoresetMode.SAME_STEP (an episode reset in the step that ends "
                             f"it), got {mode!r}")
        self.venv = venv
        super().__init__(venv.num_envs, venv.single_observation_space,
                         venv.single_action_space)
        self.render_mode = venv.render_mode
        self._actions: np.ndarray | None = None

    def reset(self):
        seeds = None if all(s is None for s in self._seeds) else list(self._seeds)
        options = self._options[0] if self._options else {}
        if any(o != options for o in self._options):
            raise ValueError("a Gymnasium vector environment takes one reset options dict for "
                             "all its sub-environments, got different ones")
        obs, info = self.venv.reset(seed=seeds, options=options or None)
        self.reset_infos = unbatch_info(info, self.num_envs)
        self._reset_seeds()
        self._reset_options()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions)

    def step_wait(self):
        obs, rewards, terminated, truncated, info = self.venv.step(self._actions)
        n = self.num_envs
        dones = np.logical_or(terminated, truncated)
        now = unbatch_info({k: v for k, v in info.items()
                            if k not in ("final_obs", "_final_obs", "final_info", "_final_info")},
                           n)
        final = unbatch_info({k: info[k] for k in ("final_obs", "_final_obs", "final_info",
                                                   "_final_info") if k in info}, n)
        infos = []
        for i in range(n):
            if dones[i]:
                # SB3's convention: the step's info with the last observation,
                # the reset's info apart
                step_info = dict(final[i].get("final_info", {}))
                step_info["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
                step_info["terminal_observation"] = final[i]["final_obs"]
                infos.append(step_info)
                self.reset_infos[i] = now[i]
            else:
                infos.append(now[i])
        return obs, np.asarray(rewards, dtype=np.float32), dones, infos

    def close(self) -> None:
        self.venv.close()

    # -- what SB3 asks of the sub-environments ---------------------------------------------

    def _envs(self, indices) -> list:
        envs = getattr(self.venv, "envs", None)
        if envs is None:
            raise AttributeError(f"{type(self.venv).__name__} does not expose its "
                                 f"sub-environments")
        return [envs[i] for i in self._get_indices(indices)]

    def get_attr(self, attr_name: str, indices=None) -> list[Any]:
        if indices is None and attr_name in ("render_mode", "metadata", "spec"):
            return [getattr(self.venv, attr_name, None)] * self.num_envs
        return [getattr(env, attr_name) for env in self._envs(indices)]

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        for env in self._envs(indices):
            setattr(env, attr_name, value)

    def env_method(self, method_name: str, *method_args, indices=None, **method_kwargs):
        return [getattr(env, method_name)(*method_args, **method_kwargs)
                for env in self._envs(indices)]

    def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
        from stable_baselines3.common import env_util

        try:
            envs = self._envs(indices)
        except AttributeError:
            return [False] * len(list(self._get_indices(indices)))
        return [env_util.is_wrapped(env, wrapper_class) for env in envs]

    def get_images(self):
        if self.render_mode != "rgb_array":
            return [None] * self.num_envs
        # a native vector environment draws one chosen sub-environment
        return [env.render() if getattr(env, "render_mode", None) == "rgb_array" else None
                for env in self._envs(None)]
