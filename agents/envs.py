"""Environment construction for training and evaluation: a picklable
factory (for worker processes), the vectorised stack

    SubprocVecEnv (n_envs > 1) or DummyVecEnv → VecMonitor → VecNormalize

with every sub-environment seeded ``seed + index``, and the command-line
handling of environment arguments shared by the commands
(``--env-kwargs KEY=VALUE ...``): :func:`parse_key_values` reads them and
:func:`make_checked_env` / :func:`check_env_kwargs` try them on one
environment in the current process, so that a bad keyword is reported
before any worker process starts or any file is written.
"""
from __future__ import annotations

import copy
from pathlib import Path

__all__ = ["EnvFactory", "make_vec_env", "load_normalization", "parse_key_values",
           "episode_arguments",
           "make_checked_env", "check_env_kwargs", "normalize_for_space"]


def _set_dotted(mapping: dict, key: str, value) -> None:
    head, _, rest = key.partition(".")
    if not rest:
        mapping[head] = value
        return
    sub = mapping.get(head)
    if not isinstance(sub, dict):
        sub = {}
    mapping[head] = sub
    _set_dotted(sub, rest, value)


def parse_key_values(items, *, into: dict | None = None, option: str = "--env-kwargs") -> dict:
    """``KEY=VALUE`` strings set over a copy of ``into`` (default empty).

    Parameters
    ----------
    items : iterable of str
        ``key=value`` strings; the value is parsed as YAML (``40`` is an
        int, ``0.5`` a float, ``{r: 0.1}`` a mapping, ``[1, 2]`` a list); a
        dotted key (``kernel_params.r=0.1``) sets one entry of a nested
        mapping and keeps its other entries. Later items win.
    into : dict, optional
        The mapping to start from (not modified).
    option : str
        The option name used in error messages.

    Returns
    -------
    dict

    Raises
    ------
    ValueError
        For an item without ``=``, an empty key or a value that is not
        valid YAML.
    """
    import yaml

    out = copy.deepcopy(dict(into or {}))
    for item in items:
        key, sep, text = str(item).partition("=")
        key = key.strip()
        if not sep or not key or any(not part for part in key.split(".")):
            raise ValueError(f"{option} entries are key=value, got {item!r}")
        try:
            value = yaml.safe_load(text)
        except yaml.YAMLError as err:
            raise ValueError(f"{option} {key}: the value {text!r} is not valid YAML "
                             f"({err})") from None
        _set_dotted(out, key, value)
    return out


def make_checked_env(env_id: str, env_kwargs: dict | None = None, *, seed: int | None = 0):
    """``gymnasium.make(env_id, **env_kwargs)`` and one ``reset(seed=seed)``.

    The environment is returned after the reset; a ``TypeError`` or
    ``ValueError`` of the construction or of the reset (an unknown
    keyword, a value out of range) is raised as a ``ValueError`` whose
    message names the environment and the keywords and carries the
    environment's own message.
    """
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the ids)

    env_kwargs = dict(env_kwargs or {})
    try:
        env = gym.make(env_id, **env_kwargs)
    except (TypeError, ValueError) as err:
        raise ValueError(f"invalid env_kwargs {env_kwargs} for {env_id}: {err}") from err
    try:
        env.reset(seed=seed)
    except (TypeError, ValueError) as err:
        env.close()
        raise ValueError(f"invalid env_kwargs {env_kwargs} for {env_id}: reset failed: "
                         f"{err}") from err
    except BaseException:
        env.close()
        raise
    return env


def registered_env_id(value: str) -> str:
    """``value`` if it is a registered environment id: the package's, or
    ``module:id`` with a module that registers ``id`` when imported (as
    :func:`gymnasium.make` reads it, so that worker processes import it
    too); else ``argparse.ArgumentTypeError`` listing the package's ids.
    The type of the commands' ``--env``."""
    import argparse

    from iceenvs.facts import env_spec

    try:
        env_spec(value)
    except ValueError as err:
        raise argparse.ArgumentTypeError(f"invalid choice: {err}") from None
    return value


def check_env_kwargs(env_id: str, env_kwargs: dict | None = None, *, seed: int | None = 0) -> None:
    """Build one environment with ``env_kwargs``, reset it once and close it
    (:func:`make_checked_env`); raises ``ValueError`` when it cannot."""
    make_checked_env(env_id, env_kwargs, seed=seed).close()


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


#: how the sub-environments of a run are stepped (``--vectorization``)
VECTORIZATIONS = ("auto", "native", "subproc", "dummy")


def has_native_vector_env(env_id: str) -> bool:
    """Whether the registration of ``env_id`` has a ``vector_entry_point``."""
    from iceenvs.facts import env_spec

    return env_spec(env_id).vector_entry_point is not None


def native_vector_env(env_id: str, n_envs: int, env_kwargs: dict | None = None):
    """The environment's own vector environment (``vector_entry_point`` of its
    registration, built by ``gymnasium.make_vec``) as an SB3 ``VecEnv``
    (:class:`agents.vec.GymnasiumVecEnv`).

    Raises
    ------
    ValueError
        When the registration has no vector entry point.
    """
    import gymnasium as gym

    from .vec import GymnasiumVecEnv

    if not has_native_vector_env(env_id):
        raise ValueError(f"{env_id} has no native vector environment (its registration has no "
                         f"vector_entry_point); use vectorization 'subproc' or 'dummy'")
    return GymnasiumVecEnv(gym.make_vec(env_id, num_envs=n_envs,
                                        vectorization_mode="vector_entry_point",
                                        **(env_kwargs or {})))


def normalize_for_space(normalize: dict, space) -> dict:
    """The arguments of :class:`VecNormalize` for observations of ``space``:
    maps (a ``Box`` of three axes: a costmap, an image) are left out of
    the observation statistics, since the environment scales them itself
    and a running mean and deviation per cell would make each cell's scale
    its own (and divide an image the policy divides by 255 again).

    A map observation is not normalised (``norm_obs`` false); a ``Dict``
    observation normalises its other parts (``norm_obs_keys``), unless the
    arguments name the keys themselves. Rewards are normalised as asked.

    >>> from gymnasium.spaces import Box, Dict
    >>> space = Dict({"costmap": Box(0, 5, (3, 64, 40)), "vector": Box(-1, 1, (8,))})
    >>> normalize_for_space({"norm_obs": True}, space)
    {'norm_obs': True, 'norm_obs_keys': ['vector']}
    """
    from gymnasium.spaces import Dict

    from .observations import is_map_space

    normalize = dict(normalize)
    if not normalize.get("norm_obs", True):
        return normalize
    if is_map_space(space):
        normalize["norm_obs"] = False
    elif isinstance(space, Dict) and normalize.get("norm_obs_keys") is None:
        keys = [key for key, part in space.spaces.items() if not is_map_space(part)]
        if keys:
            normalize["norm_obs_keys"] = keys
        else:
            normalize["norm_obs"] = False
    return normalize


def make_vec_env(env_id: str, *, n_envs: int, seed: int, env_kwargs: dict | None = None,
                 normalize: dict | None = None, training: bool = True,
                 stats_path: str | Path | None = None, vectorization: str = "auto"):
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
        normalisation); maps in the observation are left out of its
        observation statistics (:func:`normalize_for_space`).
    training : bool
        ``False`` builds an evaluation stack: statistics frozen, rewards
        not normalised.
    stats_path : path, optional
        Load the normalisation statistics from this ``vecnormalize.pkl``.
    vectorization : str
        ``"native"``: the environment's own vector environment
        (:func:`native_vector_env`); ``"subproc"``: one worker process per
        environment; ``"dummy"``: all in this process, one after the other;
        ``"auto"`` (default): for several environments, native where the
        registration has a vector entry point, else subproc; dummy for one
        (one simulation runs faster without the batched call).

    Returns
    -------
    VecEnv

    Raises
    ------
    ValueError
        For an unknown ``vectorization``, or ``"native"`` without a vector
        entry point.
    """
    from stable_baselines3.common.vec_env import (DummyVecEnv, SubprocVecEnv, VecMonitor,
                                                  VecNormalize)

    if vectorization not in VECTORIZATIONS:
        raise ValueError(f"unknown vectorization {vectorization!r}; valid: "
                         f"{', '.join(VECTORIZATIONS)}")
    if vectorization == "auto":
        vectorization = ("dummy" if n_envs == 1 else
                         "native" if has_native_vector_env(env_id) else "subproc")
    if vectorization == "native":
        venv = native_vector_env(env_id, n_envs, env_kwargs)
    else:
        fns = [EnvFactory(env_id, env_kwargs, seed + i) for i in range(n_envs)]
        venv = SubprocVecEnv(fns) if vectorization == "subproc" else DummyVecEnv(fns)
    venv.seed(seed)
    venv = VecMonitor(venv)
    if stats_path is not None and Path(stats_path).exists():
        venv = VecNormalize.load(str(stats_path), venv)
    elif normalize is not None:
        venv = VecNormalize(venv, **normalize_for_space(normalize, venv.observation_space))
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


def episode_arguments(p, *, episodes: int, seed: int, kwargs_help: str) -> None:
    """Add ``--episodes``, ``--seed`` (episode k seeded SEED + k) and
    ``--env-kwargs`` to the parser ``p`` of a command that sails a planner's
    episodes."""
    p.add_argument("--episodes", type=int, default=episodes, help=f"episodes ({episodes})")
    p.add_argument("--seed", type=int, default=seed, help="episode k is seeded SEED + k")
    p.add_argument("--env-kwargs", nargs="*", default=[], metavar="KEY=VALUE", help=kwargs_help)
