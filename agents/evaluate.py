"""Evaluate a trained policy against baselines on the same seeded episodes.

    python -m agents.evaluate RUN_DIR [--episodes 20] [--seed S]
        [--baselines random,zero,heuristic[,constant]] [--constant FILE.json]
        [--env-kwargs key=value ...] [--processes N] [--out DIR]
    python -m agents.evaluate --baseline NAME --env ID [--episodes N]
        [--env-kwargs key=value ...] [--constant FILE.json]

Episode k of every policy starts from ``reset(seed=S + k)``. The trained
policy sees observations normalised with the run's saved statistics
(``vecnormalize.pkl``, frozen); the baselines see raw observations. The
environment is built with the run's ``env_kwargs``, with ``--env-kwargs``
set over them (the observation and action spaces must stay those of the
run); the arguments are tried on one environment first, and a bad keyword
exits with status 2 and the environment's message.

The baseline ``constant`` plays the best constant action of a grid search
(:mod:`agents.constant`): the first result of ``--constant FILE.json``
(written by ``python -m agents.constant``; giving the file implies the
baseline), or else of a search run here with the defaults of
:func:`agents.constant.search_constant_actions`, on episodes seeded apart
from the evaluation episodes. Its row in the table names the action.

Output (in ``--out``, default the run directory): ``evaluation.md`` (a
Markdown table of mean ± std and standard error of the return and of the
final physics metrics, printed as well), ``evaluation.json`` (every
episode's return, final metrics, and rewards and main physics metric per
step) and ``evaluation.png`` (reward and the task's main physics metric
against step, per policy). The policy beats a
baseline when the mean of the paired differences of return exceeds two
standard errors of that mean.
"""
from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

import numpy as np

from iceenvs.facts import env_facts

from .metrics import env_name
from .rollouts import (TrainedPolicy, checkpoint_files, compare, evaluate, evaluate_in_processes,
                       rounded, run_episode, summarise)

__all__ = ["TrainedPolicy", "run_episode", "evaluate", "evaluate_in_processes", "summarise",
           "compare", "markdown_table", "plot_trajectories", "main"]


def markdown_table(env_id: str, summaries: dict, comparisons: dict, episodes: int,
                   seed: int, labels: dict | None = None,
                   metric_comparisons: dict | None = None) -> str:
    """The comparison as Markdown: one row per policy, one column per
    quantity (mean ± std, standard error in brackets); ``labels`` maps a
    policy name to the text of its rows (default: the name)."""
    labels = labels or {}
    keys = list(next(iter(summaries.values())))
    lines = [f"## Evaluation on `{env_id}`", "",
             f"{episodes} episodes per policy, episode k seeded {seed} + k; mean ± std "
             f"[standard error] of the return and of the final physics metrics.", "",
             "| policy | " + " | ".join(keys) + " |",
             "|---|" + "---|" * len(keys)]
    for name, summary in summaries.items():
        cells = [f"{summary[k]['mean']:.4g} ± {summary[k]['std']:.3g} [{summary[k]['sem']:.2g}]"
                 for k in keys]
        lines.append(f"| {labels.get(name, name)} | " + " | ".join(cells) + " |")
    if comparisons:
        lines += ["", "Return of the policy minus the baseline's, paired by seed "
                  "(mean [standard error of the difference]):", "",
                  "| baseline | difference | beaten by > 2 standard errors |", "|---|---|---|"]
        for name, c in comparisons.items():
            lines.append(f"| {labels.get(name, name)} | {c['diff']:.4g} [{c['sem']:.2g}] | "
                         f"{'yes' if c['beats'] else 'no'} |")
    if metric_comparisons:
        metric, lower = env_facts(env_id).compared_metric
        lines += ["", f"Final `{metric}` of the policy minus the baseline's, paired by seed "
                  f"({'lower' if lower else 'higher'} is better):", "",
                  "| baseline | difference | better by > 2 standard errors |", "|---|---|---|"]
        for name, c in metric_comparisons.items():
            lines.append(f"| {labels.get(name, name)} | {c['diff']:.4g} [{c['sem']:.2g}] | "
                         f"{'yes' if c['beats'] else 'no'} |")
    return "\n".join(lines) + "\n"


def plot_trajectories(env_id: str, results: dict, path: str | Path) -> None:
    """Reward and the main physics metric against step, one colour per
    policy (thin lines: episodes, thick: the mean over episodes)."""
    from physics.scenarios import plots

    plt = plots.pyplot()
    metric = env_facts(env_id).main_metric
    fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for k, (name, episodes) in enumerate(results.items()):
        colour = f"C{k}"
        for j, key in enumerate(("rewards", "trace")):
            ax = axes[j]
            n = max(len(e[key]) for e in episodes)
            grid = np.full((len(episodes), n), np.nan)
            for i, e in enumerate(episodes):
                ax.plot(e[key], color=colour, alpha=0.2, lw=0.7)
                grid[i, :len(e[key])] = e[key]
            with np.errstate(all="ignore"):
                mean = np.nanmean(grid, axis=0) if np.isfinite(grid).any() else grid[0]
            ax.plot(mean, color=colour, lw=2, label=name if j == 0 else None)
    axes[0].set_ylabel("reward")
    axes[0].legend(loc="best", fontsize="small")
    axes[1].set_ylabel(metric or "physics metric")
    axes[1].set_xlabel("step")
    fig.suptitle(env_id)
    plots.savefig(fig, path, dpi=100)


def build_parser(prog: str = "python -m agents.evaluate") -> argparse.ArgumentParser:
    from .baselines import GENERIC
    from .envs import registered_env_id

    p = argparse.ArgumentParser(prog=prog,
                                description="Compare a trained policy with baselines.")
    p.add_argument("run_dir", nargs="?", type=Path, help="run directory of agents.train")
    p.add_argument("--checkpoint", type=int, metavar="STEPS",
                   help="evaluate the run's checkpoint saved at STEPS steps instead of its "
                        "final model (its results go to RUN_DIR/checkpoint_STEPS)")
    p.add_argument("--episodes", type=int, default=20, help="episodes per policy (default 20)")
    p.add_argument("--seed", type=int, default=10_000,
                   help="episode k is seeded SEED + k (default 10000, away from training)")
    p.add_argument("--baselines", default="random,zero,heuristic",
                   help="comma-separated baselines to compare with ('' for none): "
                        + ", ".join(GENERIC) + " and the environment's own controllers "
                        "(heuristic, and straight, reactive for the ship environments), or "
                        "a policy of one's own, module:Class or path/to/file.py:Class "
                        "(agents.policy)")
    p.add_argument("--baseline", help="evaluate this baseline (or module:Class) alone "
                                      "(with --env)")
    p.add_argument("--env", type=registered_env_id, metavar="ID",
                   help="environment id for --baseline (module:id for an environment that "
                        "module registers)")
    p.add_argument("--env-kwargs", nargs="+", default=[], metavar="KEY=VALUE",
                   help="gymnasium.make arguments (VALUE is YAML); with RUN_DIR set over the "
                        "run's env_kwargs")
    p.add_argument("--constant", type=Path, default=None, metavar="FILE.json",
                   help="results of python -m agents.constant: the baseline 'constant' plays "
                        "their best action (default: search here); implies 'constant'")
    p.add_argument("--out", type=Path, default=None,
                   help="output directory (default: the run directory, or "
                        "runs/agents/baseline_<env-name>_<name>)")
    p.add_argument("--processes", type=int, default=1,
                   help="worker processes that share the episodes (default 1: this process); "
                        "the results do not depend on it")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    return p


def _disjoint_seed(first: int, count: int, avoid_first: int, avoid_count: int) -> int:
    """``first``, or the seed right after the avoided range when the
    episodes ``first … first + count − 1`` would overlap it."""
    if first < avoid_first + avoid_count and avoid_first < first + count:
        return avoid_first + avoid_count
    return first


def constant_action(parser: argparse.ArgumentParser, args: argparse.Namespace, env_id: str,
                    env_kwargs: dict) -> tuple[list[float], dict]:
    """The action of the baseline ``constant`` and where it comes from:
    the best result of ``--constant FILE.json``, or of a search run now
    with the defaults of :func:`agents.constant.search_constant_actions`
    on seeds apart from the evaluation episodes."""
    from .baselines import best_action, load_results
    from .constant import GRID, SEARCH_SEED, SEEDS, format_action, search_constant_actions

    evaluated = (args.seed, args.episodes)
    if args.constant is not None:
        try:
            report = load_results(args.constant)
            action = best_action(report)
        except (OSError, ValueError, KeyError, TypeError) as err:
            parser.error(f"--constant {args.constant}: {err}")
        if report.get("env") != env_id:
            parser.error(f"--constant {args.constant} holds a search on {report.get('env')}, "
                         f"not on {env_id}")
        if (report.get("env_kwargs") or {}) != env_kwargs:
            print(f"warning: --constant {args.constant} was searched with env_kwargs "
                  f"{report.get('env_kwargs')}, the evaluation uses {env_kwargs}",
                  file=sys.stderr)
        seeds = report["results"][0].get("seeds") or []
        if seeds and _disjoint_seed(min(seeds), len(seeds), *evaluated) != min(seeds):
            print(f"warning: --constant {args.constant} was searched on seeds {min(seeds)}…"
                  f"{max(seeds)}, which overlap the evaluation episodes", file=sys.stderr)
        source = dict(file=str(args.constant), grid=report.get("grid"), seeds=seeds)
    else:
        seed = _disjoint_seed(SEARCH_SEED, SEEDS, *evaluated)
        print(f"searching for the best constant action on {env_id} (grid of {GRID} points "
              f"per action dimension, {SEEDS} episodes each seeded {seed} + k) ...",
              flush=True)
        results = search_constant_actions(env_id, env_kwargs=env_kwargs, grid=GRID,
                                          seeds=SEEDS, seed=seed,
                                          progress=not args.no_progress)
        action = best_action(results)
        source = dict(search=True, grid=GRID, seeds=results[0]["seeds"],
                      mean=results[0]["mean"], sem=results[0]["sem"])
        print(f"best constant action {format_action(action)}: mean return "
              f"{results[0]['mean']:.4g} [{results[0]['sem']:.2g}]", flush=True)
    return action, source


def main(argv: list[str] | None = None, prog: str = "python -m agents.evaluate") -> dict:
    """Command-line entry point (``prog``: the command's name in the help);
    returns the summaries per policy."""
    from iceenvs.facts import registered_ids

    from .baselines import ConstantPolicy, baseline_names, make_baseline
    from .constant import format_action
    from .envs import make_checked_env, parse_key_values
    from .policy import is_reference
    from .rollouts import policy_recipe

    parser = build_parser(prog)
    args = parser.parse_args(argv)
    if args.episodes < 1:
        parser.error("--episodes must be >= 1")
    if args.processes < 1:
        parser.error(f"--processes must be >= 1, got {args.processes}")
    names = [n.strip() for n in args.baselines.split(",") if n.strip()]
    if args.baseline is not None:
        names = [args.baseline]
    elif args.constant is not None and "constant" not in names:
        names.append("constant")
    if args.constant is not None and "constant" not in names:
        parser.error(f"--constant is for the baseline 'constant', not {args.baseline!r}")

    policies = {}
    trained = None
    if args.baseline is not None:
        if args.run_dir is not None:
            parser.error("give either RUN_DIR or --baseline, not both")
        if args.checkpoint is not None:
            parser.error("--checkpoint is a checkpoint of a RUN_DIR, not of a baseline")
        if args.env is None:
            parser.error(f"--baseline needs --env, one of: {', '.join(registered_ids())}")
        env_id, base_kwargs = args.env, {}
        label = re.sub(r"[^A-Za-z0-9_.-]+", "_", args.baseline.rpartition("/")[2]).strip("_")
        out = args.out or Path("runs") / "agents" / f"baseline_{env_name(env_id)}_{label}"
    else:
        if args.run_dir is None:
            parser.error("give a RUN_DIR, or --baseline NAME --env ID")
        try:
            checkpoint_files(args.run_dir, args.checkpoint)
        except FileNotFoundError as err:
            parser.error(str(err))
        trained = TrainedPolicy(args.run_dir, args.checkpoint)
        env_id, base_kwargs = trained.env_id, trained.env_kwargs
        policies[f"{trained.args['algo']} policy"] = trained
        out = args.out or (args.run_dir if args.checkpoint is None
                           else args.run_dir / f"checkpoint_{args.checkpoint}")
    valid = baseline_names(env_id)
    unknown = [n for n in names if n not in valid and not is_reference(n)]
    if unknown:
        parser.error(f"unknown baselines {unknown} for {env_id}; valid baselines: "
                     f"{', '.join(valid)}, or a policy of one's own as module:Class or "
                     f"path/to/file.py:Class")
    try:
        env_kwargs = parse_key_values(args.env_kwargs, into=base_kwargs)
        env = make_checked_env(env_id, env_kwargs, seed=args.seed)
    except ValueError as err:
        parser.error(str(err))

    try:
        if trained is not None:
            for kind in ("observation_space", "action_space"):
                run_shape = getattr(trained.model, kind).shape
                if getattr(env, kind).shape != run_shape:
                    parser.error(f"with env_kwargs {env_kwargs} the {kind.replace('_', ' ')} "
                                 f"has shape {getattr(env, kind).shape}, the run's policy "
                                 f"needs {run_shape}")
        labels = {}
        recipes = {}
        if trained is not None:
            recipes[next(iter(policies))] = ("trained", str(args.run_dir),
                                             dict(checkpoint=args.checkpoint))
        constant = None
        if "constant" in names:
            action, source = constant_action(parser, args, env_id, env_kwargs)
            constant = dict(action=action, **source)
        for name in names:
            if name == "constant":
                try:
                    policies[name] = ConstantPolicy(env, args.seed, action=constant["action"])
                except ValueError as err:
                    parser.error(f"--constant {args.constant}: {err}")
                labels[name] = f"constant {format_action(policies[name].action)}"
                recipes[name] = ("baseline", name, dict(action=policies[name].action))
            else:
                try:
                    recipes[name] = policy_recipe(name)
                    policies[name] = make_baseline(name, env, seed=args.seed)
                except ValueError as err:
                    parser.error(str(err))
        if args.processes > 1:
            results = evaluate_in_processes(env_id, env_kwargs, recipes, episodes=args.episodes,
                                            seed=args.seed, processes=args.processes,
                                            progress=not args.no_progress)
        else:
            results = evaluate(env, policies, episodes=args.episodes, seed=args.seed,
                               progress=not args.no_progress)
    finally:
        env.close()
    facts = env_facts(env_id)
    summaries = {name: summarise(eps) for name, eps in results.items()}
    comparisons, metric_comparisons = {}, {}
    if args.baseline is None:
        first = next(iter(results))
        comparisons = {n: compare(results[first], results[n]) for n in names}
        if facts.compared_metric is not None:
            metric, lower = facts.compared_metric
            metric_comparisons = {n: compare(results[first], results[n], metric, lower)
                                  for n in names}
    table = markdown_table(env_id, summaries, comparisons, args.episodes, args.seed, labels,
                           metric_comparisons)
    print(table)
    out.mkdir(parents=True, exist_ok=True)
    (out / "evaluation.md").write_text(table)
    report = dict(env=env_id, env_kwargs=env_kwargs, episodes=args.episodes, seed=args.seed,
                  constant=constant, summaries=summaries, comparisons=comparisons,
                  metric_comparisons=metric_comparisons,
                  main_metric=facts.main_metric,
                  episodes_detail={n: [dict(seed=e["seed"], ret=e["ret"], length=e["length"],
                                            terminated=e["terminated"], final=e["final"],
                                            rewards=rounded(e["rewards"]),
                                            trace=rounded(e["trace"]))
                                       for e in eps] for n, eps in results.items()})
    with open(out / "evaluation.json", "w") as fh:
        json.dump(report, fh)
    plot_trajectories(env_id, results, out / "evaluation.png")
    return summaries


if __name__ == "__main__":
    main(sys.argv[1:])
