"""The checks every environment of the package passes, for a new one too.

    python -m iceenvs.checks [ID ...]                 (default: every registered id)
    python -m iceenvs.checks --fingerprint [--exact-step] [ID ...]   (hashes of the behaviour)

Each check builds the environment at its small size (its facts'
:attr:`~iceenvs.facts.EnvFacts.small`) and raises ``AssertionError`` with
the reason when the environment breaks a convention:

- :func:`check_api`: Gymnasium's environment checker (spaces, seeding,
  ``reset``/``step`` signatures, rendering in every declared mode) passes
  without a warning;
- :func:`check_determinism`: the same seed and actions give the same
  observations and rewards, bit for bit;
- :func:`check_fuzz`: seeded wild actions (NaN, ±inf, far out of range)
  are sanitised: finite observations inside the space, finite rewards
  in the environment's ``reward_bounds``, no physics failure;
- :func:`check_rewards`: the reward contract of
  :class:`iceenvs.base.ControlEnv`: finite bounds, the failure's reward
  within them, and every reward of seeded random episodes too;
- :func:`check_facts`: the facts agree with the environment: the logged
  metrics exist, the main metric is among them after a step, and every
  controller acts inside the action space.

The test suite runs them on every registered id; the docs' Contributing
page runs them on a new environment.

:func:`fingerprint` hashes what an environment does (the observations,
rewards and episode ends of 3 seeds × 20 seeded random actions at its
default size): a change meant to leave the behaviour alone, such as a
restructuring, keeps every fingerprint on one machine and one set of
libraries. Floating-point results differ between processors (see
"Reproducible" in the docs' environments page), so fingerprints are
compared on one machine only.
"""
from __future__ import annotations

import argparse
import math
import sys
import warnings

import gymnasium as gym
import numpy as np

from .facts import env_facts

__all__ = ["make_small", "check_api", "check_determinism", "check_fuzz", "check_rewards",
           "check_facts",
           "check_all", "CHECKS", "fingerprint", "engine_step", "exact_step_kwargs"]


def make_small(env_id: str, **kwargs) -> gym.Env:
    """``gymnasium.make(env_id)`` at the small size of its facts
    (``kwargs`` on top)."""
    return gym.make(env_id, **{**env_facts(env_id).small, **kwargs})


def check_api(env_id: str) -> None:
    """Gymnasium's environment checker passes without a warning (rendering
    through ``rgb_array`` where the environment declares it)."""
    from gymnasium.utils.env_checker import check_env

    probe = make_small(env_id)
    modes = probe.metadata.get("render_modes", [])
    probe.close()
    env = make_small(env_id, **({"render_mode": "rgb_array"} if "rgb_array" in modes else {}))
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            check_env(env.unwrapped)
    finally:
        env.close()
    # the checker reports through gymnasium's logger ("WARN: ..."); those count
    messages = [str(w.message) for w in caught if "WARN" in str(w.message)]
    assert not messages, f"{env_id}: Gymnasium's checker warns: {messages}"


def _actions(space: gym.spaces.Space, n: int, seed: int) -> list:
    space = gym.spaces.Box(space.low, space.high, space.shape, space.dtype, seed=seed) \
        if isinstance(space, gym.spaces.Box) else space
    if not isinstance(space, gym.spaces.Box):
        space.seed(seed)
    return [space.sample() for _ in range(n)]


def _rollout(env_id: str, seed: int, actions: list) -> tuple[list, list]:
    env = make_small(env_id)
    try:
        obs, _ = env.reset(seed=seed)
        observations, rewards = [obs], []
        for a in actions:
            obs, reward, terminated, truncated, info = env.step(a)
            assert "error" not in info, f"{env_id}: the physics failed: {info['error']}"
            observations.append(obs)
            rewards.append(float(reward))
            if terminated or truncated:
                break
    finally:
        env.close()
    return observations, rewards


def _flat(obs) -> np.ndarray:
    if isinstance(obs, dict):
        return np.concatenate([np.ravel(obs[k]).astype(np.float64) for k in sorted(obs)])
    return np.ravel(obs)


def check_determinism(env_id: str, steps: int = 5, seed: int = 123) -> None:
    """Two instances, the same seed and the same ``steps`` actions: the
    same observations and rewards, bit for bit."""
    env = make_small(env_id)
    actions = _actions(env.action_space, steps, seed)
    env.close()
    obs_a, rew_a = _rollout(env_id, seed, actions)
    obs_b, rew_b = _rollout(env_id, seed, actions)
    assert len(obs_a) == len(obs_b), f"{env_id}: episodes of different lengths"
    for k, (a, b) in enumerate(zip(obs_a, obs_b)):
        assert np.array_equal(_flat(a), _flat(b)), f"{env_id}: observations differ at step {k}"
    assert rew_a == rew_b, f"{env_id}: rewards differ: {rew_a} against {rew_b}"


def check_fuzz(env_id: str, steps: int = 12, seed: int = 0) -> None:
    """Seeded wild actions (NaN, ±inf, 1e30, in range) are sanitised: the
    observations stay finite and inside the space, the rewards finite and
    within the environment's ``reward_bounds``, and the physics does not
    fail."""
    rng = np.random.default_rng(seed)
    env = make_small(env_id)
    try:
        space = env.action_space
        low, high = env.unwrapped.reward_bounds
        wild = np.array([np.nan, np.inf, -np.inf, 1e30, -1e30], dtype=np.float64)
        obs, _ = env.reset(seed=seed)
        for k in range(steps):
            action = rng.uniform(-1.0, 1.0, space.shape)
            mask = rng.random(space.shape) < 0.5
            action[mask] = rng.choice(wild, size=int(mask.sum()))
            obs, reward, terminated, truncated, info = env.step(action.astype(space.dtype))
            assert "error" not in info, f"{env_id}: action {action} broke the physics"
            flat = _flat(obs)
            assert np.all(np.isfinite(flat)), f"{env_id}: non-finite observation at step {k}"
            assert env.observation_space.contains(obs), f"{env_id}: observation outside its space"
            assert math.isfinite(reward) and low <= reward <= high, \
                f"{env_id}: reward {reward} outside [{low}, {high}]"
            if terminated or truncated:
                obs, _ = env.reset()
    finally:
        env.close()


def check_rewards(env_id: str, steps: int = 20, seed: int = 0) -> None:
    """The reward contract of :class:`iceenvs.base.ControlEnv`: the
    environment's ``reward_bounds`` are finite and ordered, its
    ``failure_reward`` lies within them, and so does every reward of
    ``steps`` seeded random actions (resetting when an episode ends)."""
    env = make_small(env_id)
    try:
        base = env.unwrapped
        low, high = (float(b) for b in base.reward_bounds)
        assert math.isfinite(low) and math.isfinite(high) and low < high, \
            f"{env_id}: reward_bounds {base.reward_bounds} are not finite and ordered"
        failure = float(base.failure_reward)
        assert low <= failure <= high, \
            f"{env_id}: failure_reward {failure} is outside reward_bounds ({low}, {high})"
        env.action_space.seed(seed)
        env.reset(seed=seed)
        for _ in range(steps):
            _, reward, terminated, truncated, _ = env.step(env.action_space.sample())
            assert low <= reward <= high, \
                f"{env_id}: reward {reward} is outside reward_bounds ({low}, {high})"
            if terminated or truncated:
                env.reset()
    finally:
        env.close()


def check_facts(env_id: str, steps: int = 3, seed: int = 0) -> None:
    """The facts agree with the environment: after ``steps`` steps every
    mapped metric is logged and the main metric is among the logged names;
    every controller acts inside the action space."""
    facts = env_facts(env_id)
    env = make_small(env_id)
    try:
        obs, info = env.reset(seed=seed)
        for name, cls in facts.controllers.items():
            controller = cls(env, seed)
            controller.reset(seed)
            action, state = controller.predict(obs)
            assert state is None and env.action_space.contains(action), \
                f"{env_id}: controller {name!r} acts outside the action space: {action}"
        for _ in range(steps):
            obs, _, terminated, truncated, info = env.step(env.action_space.sample())
            if terminated or truncated:
                break
        logged = facts.logged_metrics(info)
        assert facts.main_metric in logged, \
            f"{env_id}: main metric {facts.main_metric!r} is not logged ({sorted(logged)})"
        if facts.metrics is not None:
            missing = sorted(set(facts.metrics) - set(info.get("physics", {})))
            assert not missing, f"{env_id}: info['physics'] lacks the metrics {missing}"
    finally:
        env.close()


#: name → check, in the order :func:`check_all` runs them
CHECKS = {"api": check_api, "determinism": check_determinism, "fuzz": check_fuzz,
          "rewards": check_rewards, "facts": check_facts}


def check_all(env_id: str) -> None:
    """Every check of :data:`CHECKS` on ``env_id``."""
    for check in CHECKS.values():
        check(env_id)


def engine_step(env_id: str, kwargs: dict | None = None) -> str | None:
    """The engine step of ``env_id`` made with ``kwargs``: ``"fast"``
    (``free_drift=True``, the ship environments' default), ``"exact"``, or
    None for an environment without that choice."""
    env = gym.make(env_id, **(kwargs or {}))
    try:
        free = getattr(env.unwrapped, "free_drift", None)
    finally:
        env.close()
    return None if free is None else ("fast" if free else "exact")


def exact_step_kwargs(env_id: str) -> dict:
    """The keywords that give ``env_id`` the exact engine step: ``free_drift=False``
    for an environment with that choice (the ship environments, whose default
    is the fast step), none for the others."""
    return {} if engine_step(env_id) is None else {"free_drift": False}


def fingerprint(env_id: str, seeds: int = 3, steps: int = 20, kwargs: dict | None = None) -> str:
    """SHA-256 of the observations, rewards and episode ends of ``env_id``
    (default size, made with ``kwargs``) over ``seeds`` episodes seeded 0,
    1, … with ``steps`` random actions each (the action space seeded like
    the episode; an episode that ends is reset)."""
    import hashlib

    h = hashlib.sha256()
    for seed in range(seeds):
        env = gym.make(env_id, **(kwargs or {}))
        try:
            obs, _ = env.reset(seed=seed)
            env.action_space.seed(seed)
            h.update(_flat(obs).tobytes())
            for _ in range(steps):
                obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
                h.update(_flat(obs).tobytes())
                h.update(np.float64(reward).tobytes())
                h.update(bytes([bool(terminated), bool(truncated)]))
                if terminated or truncated:
                    obs, _ = env.reset()
                    h.update(_flat(obs).tobytes())
        finally:
            env.close()
    return h.hexdigest()


def main(argv: list[str] | None = None) -> int:
    from .facts import registered_ids

    p = argparse.ArgumentParser(prog="python -m iceenvs.checks",
                                description=__doc__.splitlines()[0])
    p.add_argument("ids", nargs="*", help="environment ids (default: every registered id)")
    p.add_argument("--fingerprint", action="store_true",
                   help="print each id's behaviour hash (fingerprint) instead of checking it")
    p.add_argument("--exact-step", action="store_true",
                   help="with --fingerprint: the ship environments with the exact engine step "
                        "(free_drift=False) instead of their default, the fast step")
    args = p.parse_args(argv)
    if args.exact_step and not args.fingerprint:
        p.error("--exact-step goes with --fingerprint")
    if args.fingerprint:
        for env_id in args.ids or registered_ids():
            kwargs = exact_step_kwargs(env_id) if args.exact_step else {}
            print(env_id, fingerprint(env_id, kwargs=kwargs), flush=True)
        return 0
    failed = 0
    for env_id in args.ids or registered_ids():
        for name, check in CHECKS.items():
            try:
                check(env_id)
            except (AssertionError, ValueError) as err:
                failed += 1
                print(f"{env_id}: {name}: FAILED: {err}", flush=True)
            else:
                print(f"{env_id}: {name}: ok", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
