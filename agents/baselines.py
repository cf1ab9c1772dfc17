"""Baseline policies with the ``predict`` interface of SB3 models.

``predict(obs, deterministic=True) -> (action, None)`` accepts one
observation or a batch. Every baseline reads the *raw* observation of the
environment (not a normalised one) and may keep state within an episode;
``reset(seed)`` starts a new episode: every one satisfies the
:class:`agents.policy.Policy` protocol.

The baselines follow one naming scheme. The generic ones of this module
(``*Policy``: :class:`RandomPolicy`, :class:`ZeroPolicy`,
:class:`ConstantPolicy`) need only the action space and apply to every
environment. The environment's own controllers (``*Controller``, in
:mod:`iceenvs`) need only the environment and are named in its facts
(:class:`iceenvs.facts.EnvFacts`). The planners of :mod:`agents.planners`
(``*Planner``) may read privileged state (the floes of a ship
environment):

================  ==========================================================
name              policy
================  ==========================================================
``random``        uniform samples of the action space, seeded
``zero``          the all-zero action, clipped into the space
``constant``      one fixed action (``action=``; :mod:`agents.constant` finds the best)
``heuristic``     the hand-written controller of the environment
``straight``      ship environments: full speed straight to the goal line
``reactive``      ship environments: steer for the least obstructed lidar sector
``swath``         ShipNavigation-v1: steer for the swath sensor's course of least cost
``lattice``       ship environments: the lattice planner of :mod:`agents.planners`
``rollout``       ship environments: the rollout planner of :mod:`agents.planners`
``module:Class``  a policy of one's own (:mod:`agents.policy`)
================  ==========================================================

>>> env = gymnasium.make("iceenvs/Convergence-v0")
>>> policy = make_baseline("heuristic", env)
>>> obs, _ = env.reset(seed=0)
>>> action, _ = policy.predict(obs)
"""
from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np

from iceenvs.controllers import Controller
from iceenvs.facts import env_facts

from .policy import is_reference, make_policy

__all__ = ["Baseline", "RandomPolicy", "ZeroPolicy", "ConstantPolicy", "GENERIC", "baseline_names",
           "make_baseline", "load_results", "best_action"]

#: the base class of every baseline (:class:`iceenvs.controllers.Controller`)
Baseline = Controller


class RandomPolicy(Baseline):
    """Uniform random actions from a copy of the action space seeded with
    ``seed`` (re-seeded with each episode's seed by ``reset``)."""

    def __init__(self, env, seed: int = 0):
        super().__init__(env, seed)
        s = self.action_space
        self._space = gym.spaces.Box(s.low, s.high, s.shape, s.dtype, seed=self.seed)

    def reset(self, seed: int | None = None) -> None:
        if seed is not None:
            self._space.seed(int(seed))

    def act(self, obs):
        return self._space.sample()


class ZeroPolicy(Baseline):
    """The all-zero action clipped into the action space: no wind, no
    convergence, the kernel's own redistribution rate."""

    def act(self, obs):
        return np.zeros(self.action_space.shape)


def _check_action(space, action) -> np.ndarray:
    """``action`` as an array of the space's shape, finite and inside the
    bounds (a relative tolerance of 1e-6 of the box width for rounding)."""
    try:
        a = np.array(action, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ValueError(f"a constant action must be an array of numbers, got {action!r}: "
                         f"{err}") from None
    shape = tuple(space.shape)
    if a.shape != shape:
        raise ValueError(f"a constant action must have the action space's shape {shape}, got "
                         f"{a.shape} ({action!r})")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"a constant action must be finite, got {action!r}")
    low = np.asarray(space.low, dtype=np.float64)
    high = np.asarray(space.high, dtype=np.float64)
    width = np.where(np.isfinite(high - low), high - low, 1.0)
    tol = 1e-6 * np.maximum(width, 1.0)
    if np.any(a < low - tol) or np.any(a > high + tol):
        raise ValueError(f"constant action {a.tolist()} is outside the action space "
                         f"[{low.tolist()}, {high.tolist()}]")
    return np.clip(a, low, high)


class ConstantPolicy(Baseline):
    """The same action at every step.

    Parameters
    ----------
    env : gymnasium.Env
        The environment (its action space must be a ``Box``).
    seed : int
        Unused (the policy is deterministic); kept for the baseline
        interface ``(env, seed)``.
    action : array-like, optional
        The action, of the action space's shape and inside its bounds.
        Default: the centre of the box, (low + high) / 2.

    Raises
    ------
    ValueError
        For an action of the wrong shape, not finite or out of bounds, or
        no action with an unbounded box.
    """

    def __init__(self, env, seed: int = 0, *, action=None):
        super().__init__(env, seed)
        space = self.action_space
        if action is None:
            low = np.asarray(space.low, dtype=np.float64)
            high = np.asarray(space.high, dtype=np.float64)
            if not (np.all(np.isfinite(low)) and np.all(np.isfinite(high))):
                raise ValueError("an unbounded action space has no centre; pass action=")
            action = 0.5 * (low + high)
        self.action = _check_action(space, action).astype(space.dtype)

    @classmethod
    def best(cls, env, results, seed: int = 0) -> ConstantPolicy:
        """The policy of the best action of a search: ``results`` is the list
        of :func:`search_constant_actions`, or the path of the JSON file of
        ``python -m agents.constant``."""
        return cls(env, seed, action=best_action(results))

    def act(self, obs):
        return self.action.copy()

    def __repr__(self) -> str:
        return f"ConstantPolicy(action={self.action.tolist()})"


# -- results of a constant-action search (python -m agents.constant) ----------------------------
def load_results(path: str | Path) -> dict:
    """The JSON report of ``python -m agents.constant`` (``env``,
    ``env_kwargs``, ``grid``, ``seeds``, ``results``, …)."""
    with open(path) as fh:
        report = json.load(fh)
    if not isinstance(report, dict) or not report.get("results"):
        raise ValueError(f"{path} holds no constant-action results")
    return report


def best_action(results) -> list[float]:
    """The action of the first (best) result: ``results`` is the list of
    :func:`agents.constant.search_constant_actions`, a report of
    :func:`load_results` or the path of such a report."""
    if isinstance(results, (str, Path)):
        results = load_results(results)
    if isinstance(results, dict):
        results = results.get("results")
    if not results:
        raise ValueError("no constant-action results")
    return list(results[0]["action"])


#: the baselines of every environment: name → constructor ``(env, seed)``
GENERIC = {"random": RandomPolicy, "zero": ZeroPolicy, "constant": ConstantPolicy}


def _env_id(env: gym.Env) -> str | None:
    return env.spec.id if getattr(env, "spec", None) is not None else None


def _planners(env_id: str | None) -> dict:
    """The planners of :mod:`agents.planners` that apply to ``env_id``: all
    of them for a ship environment (one that offers ``ice_near``), none
    otherwise."""
    if env_id is None:
        return {}
    from iceenvs.facts import env_creator

    from .planners import PLANNERS

    return dict(PLANNERS) if hasattr(env_creator(env_id), "ice_near") else {}


def baseline_names(env_id: str | None = None) -> list[str]:
    """The baselines of ``env_id``: the generic ones, the environment's own
    controllers and, for a ship environment, the planners of
    :mod:`agents.planners` (every generic one without an id)."""
    names = list(GENERIC)
    if env_id is not None:
        names += [n for n in env_facts(env_id).controllers if n not in names]
        names += [n for n in _planners(env_id) if n not in names]
    return names


#: how a policy of one's own is named, in the messages that list the valid names
OWN_POLICY = "a policy of one's own as module:Class or path/to/file.py:Class"


def check_policy_names(names, env_id: str, also: str = "") -> None:
    """Raise ValueError unless every name of ``names`` is a baseline of
    ``env_id`` or a policy by reference (``module:Class``); the message
    names the unknown ones and lists the valid ones (then ``also``, another
    kind of name the caller takes)."""
    valid = baseline_names(env_id)
    unknown = [n for n in names if n not in valid and not is_reference(n)]
    if unknown:
        what = "policy" if len(unknown) == 1 else "policies"
        raise ValueError(f"unknown {what} {', '.join(map(repr, unknown))} for {env_id}; valid: "
                         f"{', '.join(valid)}, or {OWN_POLICY}{also}")


def make_baseline(name: str, env: gym.Env, seed: int = 0, **kwargs) -> Baseline:
    """The baseline ``name`` for ``env``: a generic one (:data:`GENERIC`),
    one of the environment's controllers (its facts' ``controllers``) or a
    policy class named by reference (``module:Class``, :mod:`agents.policy`);
    ``kwargs`` go to its constructor (``action=`` for ``"constant"``).

    Raises
    ------
    ValueError
        For a name that is neither (the message lists the valid ones).
    """
    if name in GENERIC:
        return GENERIC[name](env, seed, **kwargs)
    if is_reference(name):                  # a policy of one's own: module:Class
        return make_policy(name, env, seed, **kwargs)
    env_id = _env_id(env)
    controllers = {**env_facts(env_id).controllers, **_planners(env_id)} \
        if env_id is not None else {}
    if name not in controllers:
        where = env_id or type(env).__name__
        raise ValueError(f"unknown baseline {name!r} for {where}; valid baselines: "
                         f"{', '.join(baseline_names(env_id))}")
    return controllers[name](env, seed, **kwargs)
