"""The best constant action: a baseline that a trained policy should beat.

    python -m agents.constant --env ID [--grid 9] [--seeds 5] [--seed 20000]
        [--processes 2] [--env-kwargs key=value ...] [--out FILE.json]

:func:`search_constant_actions` evaluates every action of a regular grid
over the action box (``grid`` points per action dimension on
``[low, high]``, both ends included: 9 actions for a 1-D action and 81 for
a 2-D one with the default ``grid=9``) on the same seeded episodes and
ranks them by mean return. The episodes are seeded ``seed, seed + 1, …``
with a default of 20000, apart from the training seeds (0, 1, … and
1000 + …) and from the default evaluation episodes of
:mod:`agents.evaluate` (10000, 10001, …), so that the chosen action is not
picked on the episodes it is evaluated on.

:class:`ConstantPolicy` plays one fixed action. It is registered as the
baseline ``constant``: ``make_baseline("constant", env)`` plays the centre
of the action box, and ``ConstantPolicy(env, action=a)`` (or
``ConstantPolicy.best(env, results)`` with the results of a search, or
``ConstantPolicy.best(env, path)`` with the JSON file the command line
writes) plays ``a``. ``python -m agents.evaluate --baselines
random,zero,heuristic,constant [--constant FILE.json]`` evaluates the best
constant action next to the other baselines.

>>> results = search_constant_actions("iceenvs/Convergence-v0", grid=9, seeds=5)
>>> results[0]["action"], results[0]["mean"], results[0]["sem"]
"""
from __future__ import annotations

import argparse
import itertools
import json
import sys
from pathlib import Path

import numpy as np

from .baselines import ConstantPolicy, best_action, load_results

__all__ = ["ConstantPolicy", "SEARCH_SEED", "GRID", "SEEDS", "action_grid",
           "search_constant_actions", "load_results", "best_action", "markdown_table", "build_parser", "main"]

#: first episode seed of a search (away from the training and evaluation seeds)
SEARCH_SEED = 20_000
#: default points per action dimension and episodes per action of a search
GRID = 9
SEEDS = 5


# -- the search ----------------------------------------------------------------------------------
def action_grid(space, grid: int) -> np.ndarray:
    """Every action of a regular grid of ``grid`` points per dimension on
    ``[low, high]`` of a ``Box`` (ends included), one per row, the last
    dimension varying fastest; shape ``(grid ** d, d)`` for a 1-D box of d
    entries (other box shapes are flattened and restored by the caller)."""
    if isinstance(grid, bool) or not isinstance(grid, (int, np.integer)) or grid < 2:
        raise ValueError(f"grid must be an integer >= 2, got {grid!r}")
    low = np.asarray(space.low, dtype=np.float64).ravel()
    high = np.asarray(space.high, dtype=np.float64).ravel()
    if not (np.all(np.isfinite(low)) and np.all(np.isfinite(high))):
        raise ValueError("the action space must be bounded for a grid search")
    axes = [np.linspace(lo, hi, int(grid)) for lo, hi in zip(low, high)]
    return np.array(list(itertools.product(*axes)), dtype=np.float64).reshape(-1, low.size)


# state of a worker process: its environment, built once
_WORKER: dict = {}


def _init_worker(env_id: str, env_kwargs: dict, one_thread: bool) -> None:
    """Build the worker's environment (Numba kernels load from the disk
    cache); with several workers every one keeps to one thread."""
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the ids)

    if one_thread:
        try:
            import numba

            numba.set_num_threads(1)
        except (ImportError, ValueError):   # numba absent, or fewer threads than asked
            pass
    _WORKER["env"] = gym.make(env_id, **env_kwargs)


def _episode_return(env, action: np.ndarray, seed: int) -> float:
    """The return of one episode from ``reset(seed=seed)`` playing ``action``
    (the same episode loop as :func:`agents.evaluate.run_episode`)."""
    from .rollouts import run_episode

    policy = ConstantPolicy(env, action=action)
    return run_episode(env, policy, int(seed), None)["ret"]


def _run_tasks(tasks: list) -> list:
    """``[(i, k, return)]`` of ``(i, k, action, seed)`` tasks in this worker."""
    env = _WORKER["env"]
    return [(i, k, _episode_return(env, action, seed)) for i, k, action, seed in tasks]


def search_constant_actions(env_id: str, *, env_kwargs: dict | None = None, grid: int = GRID,
                            seeds: int = SEEDS, seed: int = SEARCH_SEED, processes: int = 2,
                            progress: bool = True) -> list[dict]:
    """Evaluate every action of a regular grid and rank them by mean return.

    Parameters
    ----------
    env_id : str
        Registered environment id.
    env_kwargs : dict, optional
        :func:`gymnasium.make` arguments (``max_episode_steps`` included).
    grid : int
        Points per action dimension on ``[low, high]`` (>= 2): ``grid ** d``
        actions for a d-dimensional action.
    seeds : int
        Episodes per action, seeded ``seed, seed + 1, …, seed + seeds − 1``
        (the same episodes for every action).
    seed : int
        The first episode seed (default :data:`SEARCH_SEED`).
    processes : int
        Worker processes (spawned; each builds its environment once, keeps
        Numba to one thread and runs many episodes; the kernels load from
        the disk cache). 1 runs everything in this process. A script that
        calls this with ``processes > 1`` needs the
        ``if __name__ == "__main__":`` guard of spawned multiprocessing.
    progress : bool
        Show a progress bar over the episodes.

    Returns
    -------
    list of dict
        One per action, best first (highest mean return; ties keep the
        grid order; a NaN mean last): ``action`` (list), ``mean``, ``std`` (ddof 1), ``sem``
        (standard error of the mean), ``returns`` (per episode, in seed
        order) and ``seeds``. The same arguments give the same numbers
        whatever ``processes``.

    Raises
    ------
    ValueError
        For bad arguments, an environment that rejects ``env_kwargs`` or an
        action space that is not a bounded ``Box``.
    """
    import gymnasium as gym
    from tqdm.auto import tqdm

    from .envs import make_checked_env
    from .rollouts import stats

    for name, value, least in (("seeds", seeds, 1), ("processes", processes, 1)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
            raise ValueError(f"{name} must be an integer >= {least}, got {value!r}")
    env_kwargs = dict(env_kwargs or {})
    episode_seeds = [int(seed) + k for k in range(int(seeds))]
    env = make_checked_env(env_id, env_kwargs, seed=episode_seeds[0])
    space = env.action_space
    if not isinstance(space, gym.spaces.Box):
        env.close()
        raise ValueError(f"{env_id} has a {type(space).__name__} action space; a constant-"
                         f"action search needs a Box")
    try:
        actions = action_grid(space, grid).reshape((-1,) + tuple(space.shape))
    except ValueError:
        env.close()
        raise
    tasks = [(i, k, actions[i], s) for i in range(len(actions))
             for k, s in enumerate(episode_seeds)]
    returns = np.full((len(actions), len(episode_seeds)), np.nan)
    bar = tqdm(total=len(tasks), unit="episode", desc="constant actions", disable=not progress)
    try:
        if processes == 1:
            for i, k, action, s in tasks:
                returns[i, k] = _episode_return(env, action, s)
                bar.update()
        else:
            env.close()
            env = None
            _run_in_workers(env_id, env_kwargs, tasks, returns, int(processes), bar)
    finally:
        bar.close()
        if env is not None:
            env.close()

    results = []
    for i, action in enumerate(actions):
        s = stats(returns[i])
        results.append(dict(action=[float(x) for x in np.ravel(action)], mean=s["mean"],
                            std=s["std"], sem=s["sem"],
                            returns=[float(r) for r in returns[i]], seeds=episode_seeds))
    # best first; ties keep the grid order and a NaN mean (a failed episode
    # without a finite reward) goes last
    order = sorted(range(len(results)), key=lambda i: (
        -results[i]["mean"] if np.isfinite(results[i]["mean"]) else np.inf, i))
    return [results[i] for i in order]


def _run_in_workers(env_id: str, env_kwargs: dict, tasks: list, returns: np.ndarray,
                    processes: int, bar) -> None:
    """Run the tasks in spawned worker processes, a chunk per call, filling
    ``returns`` by index (so the completion order does not matter)."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    # chunks of a few episodes: few round trips, yet a progress bar that moves
    # and work that stays balanced between the workers
    size = max(1, min(16, len(tasks) // (4 * processes)))
    chunks = [tasks[j:j + size] for j in range(0, len(tasks), size)]
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=processes, mp_context=context,
                             initializer=_init_worker,
                             initargs=(env_id, env_kwargs, True)) as pool:
        futures = [pool.submit(_run_tasks, chunk) for chunk in chunks]
        try:
            for future in as_completed(futures):
                done = future.result()
                for i, k, ret in done:
                    returns[i, k] = ret
                bar.update(len(done))
        except BaseException:
            for future in futures:
                future.cancel()
            raise


def format_action(action) -> str:
    """``[0.5, -1]`` → ``"(0.5, -1)"``."""
    return "(" + ", ".join(f"{float(x):.4g}" for x in np.ravel(action)) + ")"


def markdown_table(env_id: str, results: list[dict], *, grid: int, top: int = 10,
                   action_names=None) -> str:
    """The ``top`` best actions as Markdown, with the grid size."""
    n_dims = len(results[0]["action"]) if results else 0
    n_seeds = len(results[0]["returns"]) if results else 0
    first = results[0]["seeds"][0] if results and results[0].get("seeds") else None
    names = ", ".join(action_names) if action_names else f"{n_dims} entries"
    seeds = f"seeded {first} + k" if first is not None else ""
    lines = [f"## Best constant actions on `{env_id}`", "",
             f"Grid of {grid} points per action dimension ({names}): {len(results)} actions "
             f"({grid}^{n_dims}), {n_seeds} episodes each {seeds}; the top "
             f"{min(top, len(results))} by mean return.", "",
             "| rank | action | mean return | std | standard error |", "|---|---|---|---|---|"]
    for rank, r in enumerate(results[:top], start=1):
        lines.append(f"| {rank} | {format_action(r['action'])} | {r['mean']:.4g} | "
                     f"{r['std']:.3g} | {r['sem']:.2g} |")
    return "\n".join(lines) + "\n"


# -- command line --------------------------------------------------------------------------------
def build_parser() -> argparse.ArgumentParser:
    from iceenvs import ENV_IDS

    from .envs import registered_env_id

    p = argparse.ArgumentParser(prog="python -m agents.constant",
                                description="Search a grid of constant actions for the best "
                                            "one (a baseline for trained policies).")
    p.add_argument("--env", required=True, type=registered_env_id, metavar="ID",
                   help="a registered environment id: " + ", ".join(ENV_IDS)
                        + ", or one registered by your own code")
    p.add_argument("--grid", type=int, default=GRID,
                   help=f"points per action dimension on [low, high] (default {GRID})")
    p.add_argument("--seeds", type=int, default=SEEDS,
                   help=f"episodes per action (default {SEEDS})")
    p.add_argument("--seed", type=int, default=SEARCH_SEED,
                   help=f"episode k is seeded SEED + k (default {SEARCH_SEED}, away from the "
                        f"training and evaluation seeds)")
    p.add_argument("--processes", type=int, default=2, help="worker processes (default 2)")
    p.add_argument("--env-kwargs", nargs="+", default=[], metavar="KEY=VALUE",
                   help="gymnasium.make arguments (VALUE is YAML)")
    p.add_argument("--out", type=Path, default=None,
                   help="JSON file of all results (default "
                        "runs/agents/constant_<env-name>.json)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    return p


def main(argv: list[str] | None = None) -> list[dict]:
    """Command-line entry point; returns the results, best first."""
    from .envs import make_checked_env, parse_key_values
    from .metrics import env_name

    parser = build_parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    for name in ("grid", "seeds", "processes"):
        least = 2 if name == "grid" else 1
        if getattr(args, name) < least:
            parser.error(f"--{name} must be >= {least}")
    try:
        env_kwargs = parse_key_values(args.env_kwargs)
        env = make_checked_env(args.env, env_kwargs, seed=args.seed)
    except ValueError as err:
        parser.error(str(err))
    names = getattr(env.unwrapped, "action_names", None)
    names = [str(n) for n in names] if names else None
    env.close()
    out = args.out or Path("runs") / "agents" / f"constant_{env_name(args.env)}.json"
    print(f"searching {args.grid} points per action dimension on {args.env}, {args.seeds} "
          f"episodes each, in {args.processes} process(es) ...", flush=True)
    results = search_constant_actions(args.env, env_kwargs=env_kwargs, grid=args.grid,
                                      seeds=args.seeds, seed=args.seed,
                                      processes=args.processes, progress=not args.no_progress)
    print(markdown_table(args.env, results, grid=args.grid, action_names=names))
    report = dict(env=args.env, env_kwargs=env_kwargs, grid=args.grid, seeds=args.seeds,
                  seed=args.seed, n_actions=len(results), action_names=names,
                  results=results)
    out.parent.mkdir(parents=True, exist_ok=True)
    with open(out, "w") as fh:
        json.dump(report, fh, indent=2, allow_nan=True)
    print(f"wrote {len(results)} results to {out}")
    return results


if __name__ == "__main__":
    main()
