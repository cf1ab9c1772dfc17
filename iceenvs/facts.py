"""What an environment says about itself, beyond Gymnasium's spaces.

Every environment class carries an :class:`EnvFacts` as its ``facts``
attribute. Everything that works on *any* environment reads them from
there instead of keeping a table of env ids:

- the agents (:mod:`agents`) log ``metrics``, plot ``main_metric`` and
  compare ``compared_metric``;
- ``make_baseline(name, env)`` finds the environment's own ``controllers``
  (``"heuristic"`` is the hand-written controller of the task);
- the warm-up (:mod:`iceenvs.warmup`), the benchmarks and the shared tests
  build the ``small`` instance.

>>> from iceenvs.facts import env_facts
>>> facts = env_facts("iceenvs/Convergence-v0")
>>> facts.main_metric
'concentration'
>>> sorted(facts.controllers)
['heuristic']

Adding an environment is described on the docs' Contributing page.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any
from collections.abc import Mapping

__all__ = ["EnvFacts", "env_facts", "env_spec", "env_creator", "registered_ids"]


@dataclass(frozen=True)
class EnvFacts:
    """The facts of one environment.

    Parameters
    ----------
    summary : str
        The task in one line (the environment tables of the docs).
    main_metric : str
        The logged name of the metric that says most about the task (the
        trace plotted by ``agents.evaluate``).
    metrics : mapping, optional
        ``{key of info["physics"]: logged name}``: the physics entries that
        training logs and evaluation reports. ``None`` (the default) logs
        every finite scalar entry under its own name.
    episode_metrics : tuple of str
        Top-level ``info`` entries (the episode so far, e.g. a ship's
        path length) logged beside the physics.
    compared_metric : (str, bool), optional
        A final metric that evaluation compares like the return, and
        whether lower is better.
    controllers : mapping
        ``{baseline name: class}``: the environment's own controllers, each
        built as ``cls(env, seed)`` with the ``predict`` interface of
        :class:`iceenvs.controllers.Controller`. ``"heuristic"`` names the
        hand-written controller of the task.
    small : mapping
        ``gymnasium.make`` keywords of a small instance: seconds per episode
        for the tests and the warm-up (the kernels' types do not depend on
        the size).
    speed_target : float
        Sustained steps/s on one core that the environments benchmark
        expects of the default instance (its table shows it beside the
        measured rate).
    """

    summary: str
    main_metric: str
    metrics: Mapping[str, str] | None = None
    episode_metrics: tuple[str, ...] = ()
    compared_metric: tuple[str, bool] | None = None
    controllers: Mapping[str, type] = field(default_factory=dict)
    small: Mapping[str, Any] = field(default_factory=dict)
    speed_target: float = 50.0

    def __post_init__(self):
        for name in ("summary", "main_metric"):
            if not isinstance(getattr(self, name), str) or not getattr(self, name):
                raise ValueError(f"EnvFacts.{name} must be a non-empty string, got "
                                 f"{getattr(self, name)!r}")
        if self.metrics is not None and self.main_metric not in (
                *self.metrics.values(), *self.episode_metrics):
            raise ValueError(f"EnvFacts.main_metric {self.main_metric!r} is not among the "
                             f"logged names {sorted(self.metrics.values())} or the episode "
                             f"metrics {list(self.episode_metrics)}")
        if self.compared_metric is not None and (
                len(self.compared_metric) != 2 or not isinstance(self.compared_metric[1], bool)):
            raise ValueError(f"EnvFacts.compared_metric must be (name, lower_is_better), got "
                             f"{self.compared_metric!r}")
        for name, cls in self.controllers.items():
            if not callable(cls):
                raise ValueError(f"EnvFacts.controllers[{name!r}] must be a class (env, seed) "
                                 f"-> controller, got {cls!r}")
        # frozen all the way down: the facts are shared by every instance
        for name in ("metrics", "controllers", "small"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, MappingProxyType(dict(value)))
        object.__setattr__(self, "episode_metrics", tuple(self.episode_metrics))

    def logged_metrics(self, info: dict) -> dict[str, float]:
        """The logged metrics of one ``info`` dict of a step or reset: the
        mapped scalar entries of ``info["physics"]`` (every finite scalar
        entry without a map) and the episode metrics; non-finite values are
        NaN. Empty when the info holds no physics."""
        physics = info.get("physics")
        if not physics:
            return {}
        names = self.metrics
        if names is None:
            names = {k: k for k, v in physics.items() if isinstance(v, (int, float))}
        out = {}
        for key, name in names.items():
            if key in physics:
                out[name] = _finite(physics[key])
        for key in self.episode_metrics:
            if key in info:
                out[key] = _finite(info[key])
        return out


def _finite(value) -> float:
    value = float(value)
    return value if math.isfinite(value) else float("nan")


def env_spec(env_id: str):
    """The Gymnasium ``EnvSpec`` of ``env_id``, which may be ``module:id``
    for an id that the module registers when imported (as
    :func:`gymnasium.make` reads it).

    Raises
    ------
    ValueError
        When the module cannot be imported or the id is not registered (the
        message lists the package's ids).
    """
    import importlib

    import gymnasium as gym

    import iceenvs

    module, _, name = env_id.rpartition(":")
    if module:
        try:
            importlib.import_module(module)
        except ImportError as err:
            raise ValueError(f"{env_id!r}: cannot import {module!r} ({err})") from None
    try:
        return gym.spec(name)
    except gym.error.Error as err:
        raise ValueError(f"{env_id!r} is not a registered environment id ({err}); the "
                         f"package's ids: {', '.join(iceenvs.ENV_IDS)}") from None


def env_creator(env_id: str):
    """The class (or function) that ``gymnasium.make(env_id)`` calls."""
    from gymnasium.envs.registration import load_env_creator

    entry = env_spec(env_id).entry_point
    return load_env_creator(entry) if isinstance(entry, str) else entry


def env_facts(env_id: str) -> EnvFacts:
    """The :class:`EnvFacts` of a registered environment id.

    Raises
    ------
    ValueError
        For an unknown id, or an environment whose class declares no facts.
    """
    creator = env_creator(env_id)
    facts = getattr(creator, "facts", None)
    if not isinstance(facts, EnvFacts):
        raise ValueError(f"{env_id} declares no facts: its class "
                         f"{getattr(creator, '__name__', creator)!r} needs a 'facts' attribute "
                         f"of type iceenvs.facts.EnvFacts")
    return facts


def registered_ids(namespace: str = "iceenvs") -> tuple[str, ...]:
    """Every id registered in Gymnasium's ``namespace`` (the package's own
    ids, and any added by other code in that namespace), in registration
    order."""
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the package's ids)

    return tuple(i for i, spec in gym.registry.items() if spec.namespace == namespace)

