"""Episodes and their statistics: what evaluation, the constant-action
search and the task analysis share.

:func:`run_episode` plays one seeded episode, :func:`evaluate` (or
:func:`evaluate_in_processes`) plays every policy on the same seeded
episodes, :func:`summarise` and :func:`compare` turn them into means,
standard errors and paired differences. :class:`TrainedPolicy` gives a
saved model the ``predict`` interface of the baselines.

A trained run acts and observes as it was trained: the environment
arguments of :data:`AGENT_KWARGS` (how the agent commands and what it
sees, not the task) come from the run when it is evaluated beside the
baselines, and the task's from the evaluation. The ice fields do not
depend on them, so the episodes stay paired.
"""
from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import yaml

from iceenvs.facts import env_facts

from .observations import as_float32
from .runs import (checkpoint_paths_checked, run_env_id,  # noqa: F401  (re-exported)
                   trained_argument)

__all__ = ["TrainedPolicy", "trained_argument", "episode_task", "run_episode", "evaluate",
           "evaluate_in_processes", "process_pool", "policy_from_recipe", "rounded", "stats",
           "summarise", "compare", "verdict",
           "AGENT_KWARGS", "run_agent_kwargs", "run_env_id", "trained_policy"]

#: environment arguments that set how an agent acts and what it sees rather
#: than the task (the action, the observation and the sensors' settings): a
#: trained run is evaluated with its own
AGENT_KWARGS = ("control", "obs_type", "lidar_sectors", "lidar_range", "image_size",
                "image_extent", "swath_rays", "swath_fan", "swath_bands", "swath_frame",
                "swath_edge", "course_guard", "costmap_cell", "costmap_behind", "costmap_ahead")


def run_agent_kwargs(run_dir: str | Path) -> dict:
    """The :data:`AGENT_KWARGS` a run of :mod:`agents.train` was trained
    with (from its ``hyperparams.yaml``; empty when it kept the defaults),
    or a waypoint student's run (from its ``waypoints.json``)."""
    from .waypoint_follower import student_record

    student = student_record(run_dir)
    if student is not None:
        return _agent_part(student["settings"].get("env_kwargs") or {})
    with open(Path(run_dir) / "hyperparams.yaml") as fh:
        return _agent_part(yaml.safe_load(fh).get("env_kwargs") or {})


def trained_policy(run_dir: str | Path, env, seed: int = 0, checkpoint: int | str | None = None):
    """The policy of a run directory for ``env``: a :class:`TrainedPolicy`
    for a run of :mod:`agents.train` (``env`` unused), a
    :class:`agents.waypoint_follower.WaypointStudent` for a waypoint
    student's run (a :class:`agents.waypoints.WaypointResidual` for a
    residual on the costmap lattice), which reads ``env`` (made with the
    run's :func:`run_agent_kwargs`). Either has ``env_id`` and ``agent_kwargs``."""
    from .waypoint_follower import (WaypointResidual, WaypointStudent, is_residual,
                                    student_record)

    student = student_record(run_dir)
    if student is None:
        return TrainedPolicy(run_dir, checkpoint)
    if checkpoint is not None:
        raise ValueError(f"{run_dir} is a waypoint student's run: it keeps no checkpoints "
                         f"(asked for {checkpoint!r})")
    agent = run_agent_kwargs(run_dir)
    made = dict(env.spec.kwargs)
    differ = {k: v for k, v in agent.items()
              if made.get(k, getattr(env.unwrapped, k, None)) != v}
    if differ:
        raise ValueError(f"the waypoint student of {run_dir} was trained with {differ}: make "
                         f"the environment with them (gymnasium.make(..., **agent_kwargs))")
    player = WaypointResidual if is_residual(run_dir) else WaypointStudent
    policy = player(env, seed, run=str(run_dir))
    policy.env_id, policy.agent_kwargs = student["settings"]["env_id"], agent
    return policy


def _agent_part(env_kwargs: dict) -> dict:
    """The :data:`AGENT_KWARGS` among ``env_kwargs``."""
    return {k: v for k, v in env_kwargs.items() if k in AGENT_KWARGS}


def checkpoint_files(run_dir: Path, checkpoint: int | str | None = None) -> tuple[Path, Path]:
    """(model, normalisation statistics) of a run of :mod:`agents.train`
    (:func:`agents.runs.checkpoint_paths_checked`)."""
    return checkpoint_paths_checked(run_dir, checkpoint)


class TrainedPolicy:
    """A saved SB3 model with the ``predict`` interface of the baselines,
    normalising raw observations with the run's frozen statistics.

    Parameters
    ----------
    run_dir : path
        A run directory of :mod:`agents.train`.
    """

    def __init__(self, run_dir: str | Path, checkpoint: int | str | None = None):
        from .envs import load_normalization
        from .train import algo_class

        run_dir = Path(run_dir)
        model, stats = checkpoint_files(run_dir, checkpoint)
        with open(run_dir / "args.yaml") as fh:
            self.args = yaml.safe_load(fh)
        with open(run_dir / "hyperparams.yaml") as fh:
            self.hyperparams = yaml.safe_load(fh)
        self.env_id = self.args["env"]
        self.env_kwargs = self.hyperparams.get("env_kwargs") or {}
        #: the run's :data:`AGENT_KWARGS`, with which it is evaluated
        self.agent_kwargs = _agent_part(self.env_kwargs)
        self.model = algo_class(self.args["algo"]).load(model, device="cpu")
        self.normalization = load_normalization(stats, self.env_id, self.env_kwargs)

    def reset(self, seed: int | None = None) -> None:
        """Nothing to reset: the policy is memoryless."""

    def predict(self, obs, state=None, episode_start=None, deterministic: bool = True):
        obs = as_float32(obs)
        if self.normalization is not None:
            obs = as_float32(self.normalization.normalize_obs(obs))
        return self.model.predict(obs, deterministic=deterministic)


def episode_task(env, info: dict) -> dict[str, float]:
    """The task parameters drawn for this episode and their values, as
    floats: those the environment's arguments leave at ``None`` ("drawn
    every episode") that the reset's ``info["task"]`` holds as a number.
    Empty for an environment without task parameters in its info."""
    task = info.get("task") or {}
    given = getattr(env.unwrapped, "task", None)
    if not isinstance(given, dict):
        return {}
    out = {}
    for name, value in given.items():
        drawn = task.get(name)
        if value is None and isinstance(drawn, (int, float, np.integer, np.floating)) \
                and not isinstance(drawn, bool):
            out[name] = float(drawn)
    return out


def _course_guard(env):
    """For a ship commanded by course with a course guard, ``overrides(action)``:
    1 when the autopilot will hold another course than the one commanded
    (:meth:`iceenvs.ship_navigation_v1.ShipNavigationV1Env.guarded_course`),
    else 0; None for any other environment."""
    u = env.unwrapped
    if getattr(u, "control", None) != "course" or not hasattr(u, "guarded_course") \
            or (getattr(u, "episode", None) or {}).get("course_guard") is None:
        return None

    def overrides(action) -> int:
        course = float(np.clip(np.ravel(action)[0], -1.0, 1.0)) * u.episode["max_course"]
        return int(abs(u.guarded_course(course) - course) > 1e-9)
    return overrides


def run_episode(env, policy, seed: int, main_metric: str | None) -> dict:
    """One episode from ``reset(seed=seed)``: return, length, final physics
    metrics, the per-step rewards and main metric, and the task
    parameters drawn for the episode (``task``: :func:`episode_task`); for
    a ship in a channel, the steps it ended outside (``outside_steps``) and,
    commanded by course with a guard, the steps on which the guard held
    another course than the one commanded (``guard_overrides``)."""
    logged_metrics = env_facts(env.spec.id).logged_metrics
    obs, info = env.reset(seed=seed)
    task = episode_task(env, info)
    policy.reset(seed)
    rewards, trace = [], []
    final = logged_metrics(info)
    thinking = 0.0
    guard = _course_guard(env)
    overrides = outside = 0
    while True:
        t0 = time.perf_counter()
        action, _ = policy.predict(obs, deterministic=True)
        thinking += time.perf_counter() - t0
        if guard is not None:
            overrides += guard(action)
        obs, reward, terminated, truncated, info = env.step(action)
        outside += abs(info.get("physics", {}).get("channel_offset", 0.0)) > 1.0
        rewards.append(float(reward))
        metrics = logged_metrics(info)
        final = metrics or final
        trace.append(metrics.get(main_metric, math.nan) if main_metric else math.nan)
        if terminated or truncated:
            break
    out = dict(seed=seed, ret=float(np.sum(rewards)), length=len(rewards),
               terminated=bool(terminated), final=final, rewards=rewards, trace=trace,
               decision_ms=1e3 * thinking / max(len(rewards), 1), task=task)
    if "channel_offset" in info.get("physics", {}):
        out["outside_steps"] = int(outside)
    if guard is not None:
        out["guard_overrides"] = int(overrides)
    plans = getattr(policy, "decision_times", None)
    if plans:
        out["plan_ms"] = 1e3 * float(np.mean(plans))
        out["plans"] = len(plans)
    return out


def evaluate(env, policies: dict, *, episodes: int, seed: int, progress: bool = True) -> dict:
    """Run every policy of ``{name: policy}`` in ``env`` on episodes seeded
    ``seed, seed + 1, …``; returns ``{name: [episode dicts]}``.

    The baselines must have been made for this very ``env``
    (:func:`agents.baselines.make_baseline`): the model-based controllers
    read its state."""
    from tqdm.auto import tqdm

    main_metric = env_facts(env.spec.id).main_metric
    results = {}
    with tqdm(total=episodes * len(policies), unit="episode", desc="evaluating",
              disable=not progress) as bar:
        for name, policy in policies.items():
            own = _own_env(env, getattr(policy, "agent_kwargs", {}))
            try:
                results[name] = []
                for k in range(episodes):
                    results[name].append(run_episode(own, policy, seed + k, main_metric))
                    bar.update()
            finally:
                if own is not env:
                    own.close()
    return results


def _own_env(env, agent_kwargs: dict):
    """``env``, or, when ``agent_kwargs`` change it, the same task made with
    them."""
    import gymnasium as gym

    kwargs = dict(env.spec.kwargs)
    if all(kwargs.get(k) == v for k, v in agent_kwargs.items()):
        return env
    return gym.make(env.spec.id, **{**kwargs, **agent_kwargs})


#: the environment and the policies of a worker of :func:`evaluate_in_processes`
_WORKER: dict = {}


def _worker_episode(env_id: str, env_kwargs: dict, env_seed: int, name: str, recipe: tuple,
                    episode_seed: int) -> dict:
    """One episode in a worker process: the worker builds its environment
    once (``reset(seed=env_seed)``, as the evaluation's main process does)
    and each policy once from its recipe, then runs
    :func:`run_episode`."""
    from .envs import make_checked_env

    if not _WORKER:
        import torch

        torch.set_num_threads(1)
        _WORKER.update(envs={}, policies={})
    key = (env_id, repr(sorted(env_kwargs.items())), env_seed)
    envs = _WORKER["envs"]
    if key not in envs:
        envs[key] = make_checked_env(env_id, env_kwargs, seed=env_seed)
    env = envs[key]
    policies = _WORKER["policies"]
    if (key, name) not in policies:
        policies[key, name] = policy_from_recipe(recipe, env, env_seed)
    return run_episode(env, policies[key, name], episode_seed, env_facts(env_id).main_metric)


def policy_recipe(name: str) -> tuple:
    """The recipe of a baseline's name, or of a policy of one's own
    (``module:Class``, checked here: :func:`agents.policy.check_reference`),
    for :func:`evaluate_in_processes`."""
    from .policy import check_reference, is_reference, search_path

    if is_reference(name):
        return ("policy", check_reference(name), {"search": search_path(name)})
    return ("baseline", name, {})


def policy_from_recipe(recipe: tuple, env, seed: int):
    """The policy a recipe (:func:`evaluate_in_processes`) makes for
    ``env``: a trained run, a policy of one's own (imported here, from its
    search path) or a baseline."""
    from .baselines import make_baseline
    from .policy import make_policy

    kind, target, kwargs = recipe
    if kind == "trained":
        return trained_policy(target, env, seed, **kwargs)
    if kind == "policy":
        return make_policy(target, env, seed=seed, **kwargs)
    return make_baseline(target, env, seed=seed, **kwargs)


def process_pool(processes: int):
    """A pool of ``processes`` worker processes for
    :func:`evaluate_in_processes` (started by forkserver where there is
    one), to keep between evaluations: each worker keeps its environments
    and its policies, by name, from one evaluation to the next."""
    import concurrent.futures
    import multiprocessing

    method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
    return concurrent.futures.ProcessPoolExecutor(
        processes, mp_context=multiprocessing.get_context(method))


def evaluate_in_processes(env_id: str, env_kwargs: dict, recipes: dict, *, episodes: int,
                          seed: int, processes: int, progress: bool = True,
                          pool=None) -> dict:
    """:func:`evaluate` with the episodes shared among ``processes`` worker
    processes; the same results, since every episode starts from
    ``reset(seed=seed + k)`` and the policies are deterministic or, like
    the random baseline, re-seeded with each episode.

    ``recipes`` maps a policy name to ``("trained", run_dir, {})``,
    ``("baseline", baseline_name, constructor_kwargs)`` or ``("policy",
    reference, {"search": directories})`` (:func:`policy_recipe`); every worker builds
    its own environment (``gymnasium.make(env_id, **env_kwargs)``, first
    reset with ``seed``; a trained run's with its :data:`AGENT_KWARGS`) and
    policies from them. ``pool`` (:func:`process_pool`, then left open)
    runs them instead of a pool of ``processes`` made for this call; as its
    workers keep each policy by its name, a policy played in an earlier
    evaluation of the same pool must come under a name of its own."""
    import concurrent.futures
    import contextlib

    from tqdm.auto import tqdm

    results = {name: [None] * episodes for name in recipes}
    with (contextlib.nullcontext(pool) if pool is not None else process_pool(processes)) \
            as pool, tqdm(total=episodes * len(recipes), unit="episode", desc="evaluating",
                          disable=not progress) as bar:
        kwargs = {name: {**env_kwargs, **(run_agent_kwargs(recipe[1])
                                          if recipe[0] == "trained" else {})}
                  for name, recipe in recipes.items()}
        jobs = {pool.submit(_worker_episode, env_id, kwargs[name], seed, name, recipe, seed + k):
                (name, k) for name, recipe in recipes.items() for k in range(episodes)}
        for job in concurrent.futures.as_completed(jobs):
            name, k = jobs[job]
            results[name][k] = job.result()
            bar.update()
    return results


def rounded(values, digits: int = 6) -> list:
    """Floats to ``digits`` significant digits (the per-step series of the
    JSON report)."""
    return [float(f"{v:.{digits}g}") for v in values]


def stats(values) -> dict:
    """Mean, std (ddof 1), standard error and count of ``values``."""
    x = np.asarray(values, dtype=float)
    n = x.size
    std = float(np.std(x, ddof=1)) if n > 1 else 0.0
    return dict(mean=float(np.mean(x)), std=std, sem=std / math.sqrt(n), n=int(n))


def summarise(episodes: list[dict]) -> dict:
    """Mean, std (ddof 1) and standard error of the return, the length and
    every final physics metric over episodes."""
    out = {"return": stats([e["ret"] for e in episodes]),
           "length": stats([e["length"] for e in episodes])}
    for key in episodes[0]["final"]:
        out[key] = stats([e["final"].get(key, math.nan) for e in episodes])
    return out


def compare(policy: list[dict], baseline: list[dict], metric: str | None = None,
            lower_is_better: bool = False) -> dict:
    """Paired comparison on the same seeds of the returns (or of the final
    physics ``metric``): mean difference (policy − baseline), its standard
    error, whether the policy is better by more than two standard errors
    (``beats``: higher, or lower with ``lower_is_better``), whether it is
    worse by more than two (``loses``) and the :func:`verdict`."""
    def value(e):
        return e["ret"] if metric is None else e["final"].get(metric, math.nan)

    d = np.array([value(p) - value(b) for p, b in zip(policy, baseline)])
    s = stats(d)
    gain = -s["mean"] if lower_is_better else s["mean"]
    out = dict(diff=s["mean"], sem=s["sem"], beats=bool(gain > 2.0 * s["sem"] and gain > 0),
               loses=bool(-gain > 2.0 * s["sem"] and gain < 0))
    out["verdict"] = verdict(out)
    return out


def verdict(comparison: dict) -> str:
    """``"beats"`` or ``"loses"`` where the paired difference of a
    :func:`compare` is more than two standard errors from zero, else
    ``"neither"``."""
    return ("beats" if comparison.get("beats") else "loses" if comparison.get("loses")
            else "neither")
