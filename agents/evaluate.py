"""Evaluate a trained policy against baselines on the same seeded episodes.

    python -m agents.evaluate RUN_DIR [--episodes 20] [--seed S]
        [--baselines random,zero,heuristic[,constant]] [--constant FILE.json]
        [--env-kwargs key=value ...] [--default-config] [--processes N] [--out DIR]
    python -m agents.evaluate --baseline NAME --env ID [--episodes N]
        [--env-kwargs key=value ...] [--constant FILE.json]
    python -m agents.evaluate --render DIR
        (the table and the plot again from DIR's evaluation.json)

Episode k of every policy starts from ``reset(seed=S + k)``. The trained
policy sees observations normalised with the run's saved statistics
(``vecnormalize.pkl``, frozen); the baselines see raw observations. The
environment is built with the run's ``env_kwargs`` but those of its
training configuration alone (:data:`TRAINING_ONLY_KWARGS`: soft ice, which
a run may train on and is evaluated without), with ``--env-kwargs`` set
over them (the observation and action spaces must stay those of the run).
``--default-config`` plays it on the environment's default configuration
instead, with only the run's own way of acting and observing
(:data:`agents.rollouts.AGENT_KWARGS`), as the benchmark plays a reference
agent. The arguments are tried on one environment first, and a bad keyword exits
with status 2 and the environment's message.

The baseline ``constant`` plays the best constant action of a grid search
(:mod:`agents.constant`): the first result of ``--constant FILE.json``
(written by ``python -m agents.constant``; giving the file implies the
baseline), or else of a search run here with the defaults of
:func:`agents.constant.search_constant_actions`, on episodes seeded apart
from the evaluation episodes. Its row in the table names the action.

Output (in ``--out``, default the run directory): ``evaluation.md``
(printed as well), ``evaluation.json``, ``evaluation.png`` and
``episodes.json``.

``evaluation.md`` is for people: the mean ± standard error of the mean of
the return and of the final physics metrics, each with a readable header
in its display unit (:data:`agents.metrics.METRIC_UNITS`: an impulse per
metre in kN s/m, energies in MJ), three significant figures for the
mean and two for the error, without exponents. The return, the success
and the task's main metrics come first; where they do not fit in one
table, the other metrics follow in a second, one column per policy.
Under the tables: the task parameters drawn per episode (the values
drawn; episode k of every policy draws the same), those the environment
arguments fixed, and for a ship environment how to play the
leaderboard's fields (``--env-kwargs concentration=A`` with the default
seed: episode k is field k of :mod:`agents.leaderboard` at concentration
A). Then the paired differences of the return and of the compared
metric.

``evaluation.json`` is the record, in SI units: the command, the source
commit (:mod:`physics.provenance`), the host and the date, the summaries
(mean, std, standard error), the comparisons and the task. ``episodes.json`` holds
the episodes behind it: every episode's return, final metrics, drawn task
parameters (``task``), and rewards and main physics metric per step
(large, and not committed with a documented record).
``evaluation.png`` draws the reward and the task's main
physics metric against step, per policy, with each episode's target
where the task has one. The policy beats a baseline when the mean of the
paired differences of return exceeds two standard errors of that mean.
"""
from __future__ import annotations

import argparse
import datetime
import json
import shlex
import re
import sys
from pathlib import Path

import numpy as np

from iceenvs.facts import env_facts
from physics.provenance import source_commit

from .metrics import (HEADLINE, LAST_STEP, TARGET_METRICS, env_name, format_pm, metric_header,
                      metric_unit, scaled, significant)
from .rollouts import (TrainedPolicy, checkpoint_files, compare, evaluate, evaluate_in_processes,
                       rounded, run_episode, summarise, verdict)

#: the episodes behind an evaluation's record, beside it
EPISODES = "episodes.json"

__all__ = ["TrainedPolicy", "run_episode", "evaluate", "evaluate_in_processes", "summarise",
           "compare", "markdown_table", "table_columns", "task_report", "task_lines",
           "plot_trajectories", "metric_differences", "render", "main"]


#: the most quantity columns of one table; with more, the metrics that are
#: not among the first follow in a second table, one column per policy
MAX_COLUMNS = 9


def table_columns(env_id: str, keys) -> tuple[list[str], list[str]]:
    """The quantities of the main table and those of the second: the
    return, then the success, the task's main metric, its target, the
    compared metric and :data:`agents.metrics.HEADLINE` where logged (a
    final value that is only the last step's excepted), then the rest; all
    in one table when they fit in :data:`MAX_COLUMNS` columns."""
    keys = list(keys)
    facts = env_facts(env_id)
    first = ["return", "success", facts.main_metric, *TARGET_METRICS,
             *(facts.compared_metric or ())[:1], *HEADLINE]
    first = [k for k in dict.fromkeys(first) if k in keys and k not in LAST_STEP]
    first = first[:MAX_COLUMNS]
    rest = [k for k in keys if k not in first]
    if len(keys) <= MAX_COLUMNS:          # one table, the episode length last
        return first + sorted(rest, key=lambda k: k == "length"), []
    return first, rest


def _cell(name: str, s: dict | None) -> str:
    """Mean ± standard error of a summary entry, in the display unit."""
    if not s:
        return "–"
    return format_pm(scaled(name, s["mean"]), scaled(name, s["sem"]))


def _short(name: str, value: float) -> str:
    """``value`` of ``name`` in its display unit, three significant figures
    at most, without trailing zeros."""
    text = significant(scaled(name, value))
    return text.rstrip("0").rstrip(".") if "." in text else text


def _range_text(name: str, low: float, high: float) -> str:
    if low == high:
        return _short(name, low)
    return f"{_short(name, low)} to {_short(name, high)}"


def task_lines(task: dict, episodes: int, seed: int) -> list[str]:
    """The Markdown lines that say which task parameters were drawn per
    episode (with the range of the values drawn), which the environment
    arguments fixed, and how to play the leaderboard's fields
    (:func:`task_report`)."""
    lines = []
    drawn = task.get("drawn") or {}
    if drawn:
        items = []
        for name, d in drawn.items():
            text = f"{metric_header(name)} {_range_text(name, d['min'], d['max'])}"
            if d["min"] == d["max"] and episodes > 1:
                text += " in every episode"
            if d.get("range") is not None:
                low, high = d["range"]
                text += f" (drawn from {_short(name, low)} to {_short(name, high)})"
            items.append(text)
        lines += [f"Task parameters drawn per episode (the same draws for every policy: "
                  f"episode k of each is seeded {seed} + k): " + "; ".join(items) + ".", ""]
    fixed = task.get("fixed") or {}
    if fixed:
        lines += ["Fixed for every episode by the environment arguments: " + ", ".join(
            f"{name} = {value:g}" if isinstance(value, (int, float)) else name
            for name, value in fixed.items()) + ".", ""]
    if task.get("leaderboard"):
        concentration = fixed.get("concentration")
        lines.append("The leaderboard (`python -m agents.leaderboard`) fixes the concentration "
                     "per row: `--env-kwargs concentration=A` with the default `--seed 10000` "
                     "(and the leaderboard's other environment arguments, none by default) "
                     "plays its fields at concentration A, episode k being field k.")
        if isinstance(concentration, (int, float)) and seed == 10_000:
            fields = "its field 0" if episodes == 1 else f"its fields 0 to {episodes - 1}"
            other = " ".join(f"{k}={v}" for k, v in (task.get("other_kwargs") or {}).items())
            lines[-1] += (f" These episodes are {fields} at A = {concentration:g} of "
                          + (f"a leaderboard run with `--env-kwargs {other}`." if other
                             else "the default leaderboard."))
        lines.append("")
    return lines


def made_line(report: dict) -> list[str]:
    """How a record was made: its command, commit, host and date (those of
    them it has)."""
    if not report.get("command"):
        return []
    about = "; ".join(str(report[k]) for k in ("commit", "host", "date") if report.get(k))
    return [f"`{report['command']}`" + (f" ({about})" if about else ""), ""]


def markdown_table(env_id: str, summaries: dict, comparisons: dict, episodes: int,
                   seed: int, labels: dict | None = None,
                   metric_comparisons: dict | None = None, task: dict | None = None,
                   made: dict | None = None) -> str:
    """The comparison as Markdown: one row per policy, one column per
    quantity (mean ± standard error of the mean, in the display units of
    :data:`agents.metrics.METRIC_UNITS`), the quantities that do not fit
    in a second table (one column per policy), then the task parameters
    drawn or fixed (``task``: :func:`task_report`) and the paired
    comparisons; ``labels`` maps a policy name to the text of its rows
    (default: the name)."""
    labels = labels or {}
    first, rest = table_columns(env_id, next(iter(summaries.values())))
    lines = [f"## Evaluation on `{env_id}`", "", *made_line(made or {}),
             f"{episodes} episodes per policy, episode k seeded {seed} + k, the same episodes "
             f"for every policy. Each cell is the mean ± the standard error of the mean over "
             f"the episodes (the standard deviation over the episodes is "
             f"√{episodes} times it; both are in `evaluation.json`, in SI units); the physics "
             f"metrics are their values at the end of the episode.", "",
             "| policy | " + " | ".join(metric_header(k) for k in first) + " |",
             "|---|" + "---|" * len(first)]
    for name, summary in summaries.items():
        cells = [_cell(k, summary.get(k)) for k in first]
        lines.append(f"| {labels.get(name, name)} | " + " | ".join(cells) + " |")
    if rest:
        names = list(summaries)
        lines += ["", "The other final metrics (mean ± standard error):", "",
                  "| metric | " + " | ".join(labels.get(n, n) for n in names) + " |",
                  "|---|" + "---|" * len(names)]
        for k in rest:
            lines.append(f"| {metric_header(k)} | "
                         + " | ".join(_cell(k, summaries[n].get(k)) for n in names) + " |")
    lines.append("")
    lines += task_lines(task or {}, episodes, seed)
    if comparisons:
        lines += ["Return of the policy minus the baseline's, paired by seed "
                  "(mean ± standard error of the difference):", "",
                  "| baseline | return difference | the policy (by > 2 standard errors) |",
                  "|---|---|---|"]
        for name, c in comparisons.items():
            lines.append(f"| {labels.get(name, name)} | {format_pm(c['diff'], c['sem'])} | "
                         f"{verdict(c)} |")
        lines.append("")
    if metric_comparisons:
        metric, lower = env_facts(env_id).compared_metric
        lines += [f"Final {metric_unit(metric).header} of the policy minus the baseline's, "
                  f"paired by seed ({'lower' if lower else 'higher'} is better; mean ± "
                  f"standard error of the difference):", "",
                  f"| baseline | difference of the {metric_header(metric)} | "
                  f"the policy (by > 2 standard errors) |", "|---|---|---|"]
        for name, c in metric_comparisons.items():
            lines.append(f"| {labels.get(name, name)} | "
                         f"{format_pm(scaled(metric, c['diff']), scaled(metric, c['sem']))} | "
                         f"{verdict(c)} |")
        lines.append("")
    return "\n".join(lines).rstrip("\n") + "\n"


def task_report(env, env_kwargs: dict, results: dict) -> dict:
    """What the episodes' task was: ``drawn`` (per parameter drawn anew each
    episode, the least and largest value drawn and the range it is drawn
    from where the environment has one), ``fixed`` (the parameters that
    the environment draws unless its arguments fix them, as
    ``env_kwargs`` did), ``leaderboard`` (a ship environment whose
    fields the leaderboard plays at fixed concentrations) and
    ``other_kwargs`` (``env_kwargs`` but the concentration: those of the
    leaderboard run whose fields these episodes are)."""
    from iceenvs.ship_env import ShipEnv

    base = env.unwrapped
    given = getattr(base, "task", None) or {}
    episodes = next(iter(results.values()))
    drawn = {}
    for name in dict.fromkeys(k for e in episodes for k in e.get("task", {})):
        values = [e["task"][name] for e in episodes if name in e.get("task", {})]
        rng = given.get(f"{name}_range")
        drawn[name] = dict(min=min(values), max=max(values),
                           range=[float(r) for r in rng] if rng is not None else None)
    drawable = [*getattr(base, "drawn", ()),
                *(p.name for p in getattr(base, "task_parameters", ()) if p.default is None)]
    fixed = {name: env_kwargs[name] for name in dict.fromkeys(drawable) if name in env_kwargs}
    ship = isinstance(base, ShipEnv) and "concentration" in given
    other = {k: v for k, v in env_kwargs.items() if k != "concentration"}
    return dict(drawn=drawn, fixed=fixed, leaderboard=ship, other_kwargs=other)


def plot_trajectories(env_id: str, results: dict, path: str | Path) -> None:
    """Reward and the main physics metric (in its display unit) against
    step, one colour per policy (thin lines: episodes, thick: the mean
    over episodes); on the metric's panel, each episode's target where the
    task logs one (:data:`agents.metrics.TARGET_METRICS`), dashed grey."""
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
                values = np.asarray(e[key], dtype=float)
                if key == "trace" and metric:
                    values = scaled(metric, values)
                ax.plot(values, color=colour, alpha=0.2, lw=0.7)
                grid[i, :len(values)] = values
            with np.errstate(all="ignore"):
                mean = np.nanmean(grid, axis=0) if np.isfinite(grid).any() else grid[0]
            ax.plot(mean, color=colour, lw=2, label=name if j == 0 else None)
    targets = _episode_targets(results)
    if targets and metric:
        drawn = any(name in e.get("task", {}) for eps in results.values() for e in eps
                    for name in TARGET_METRICS)
        for i, (length, value) in enumerate(targets.values()):
            axes[1].hlines(scaled(metric, value), 0, max(length - 1, 1), colors="0.4", lw=0.8,
                           linestyles="--", zorder=1,
                           label=None if i else ("target (drawn per episode)" if drawn
                                                 else "target"))
        axes[1].legend(loc="best", fontsize="small")
    axes[0].set_ylabel("reward")
    axes[0].legend(loc="best", fontsize="small")
    axes[1].set_ylabel(metric_header(metric) if metric else "physics metric")
    axes[1].set_xlabel("step")
    fig.suptitle(env_id)
    plots.savefig(fig, path, dpi=100, palette=True)


def _episode_targets(results: dict) -> dict:
    """``{seed: (longest length, target)}`` of the episodes whose final
    metrics hold a target of the main metric (the same per seed for every
    policy)."""
    out = {}
    for episodes in results.values():
        for e in episodes:
            value = next((e["final"][t] for t in TARGET_METRICS if t in e["final"]), None)
            if value is None or not np.isfinite(value):
                continue
            length = out.get(e["seed"], (0, value))[0]
            out[e["seed"]] = (max(length, len(e["trace"])), value)
    return out


def _checkpoint(value: str) -> int | str:
    """A ``--checkpoint``: a number of steps or ``best``."""
    from .runs import BEST

    if value == BEST:
        return BEST
    try:
        steps = int(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a number of steps or {BEST!r}, got {value!r}") from None
    if steps < 0:
        raise argparse.ArgumentTypeError(f"a number of steps >= 0, got {steps}")
    return steps


def build_parser(prog: str = "python -m agents.evaluate") -> argparse.ArgumentParser:
    from .baselines import GENERIC
    from .envs import registered_env_id

    p = argparse.ArgumentParser(prog=prog,
                                description="Compare a trained policy with baselines.")
    p.add_argument("run_dir", nargs="?", type=Path, help="run directory of agents.train")
    p.add_argument("--checkpoint", type=_checkpoint, metavar="STEPS|best",
                   help="evaluate the run's checkpoint saved at STEPS steps, or its evaluation "
                        "callback's best model (best), instead of its final model (its results "
                        "go to RUN_DIR/checkpoint_STEPS or RUN_DIR/checkpoint_best)")
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
    p.add_argument("--default-config", action="store_true",
                   help="play a trained run on the environment's default configuration, with "
                        "only its own way of acting and observing (as the benchmark and the "
                        "leaderboard play it), not the task it trained on")
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
    p.add_argument("--render", type=Path, default=None, metavar="DIR",
                   help="only write DIR/evaluation.md and evaluation.png again from "
                        "DIR/evaluation.json (e.g. a record written by an older version)")
    return p


def metric_differences(env_id: str, episodes: dict, names) -> dict:
    """The compared metric of ``env_id`` (its facts' ``compared_metric``)
    of the first policy of ``episodes`` (``{policy: [episode dicts]}``)
    minus that of each of ``names``, paired by seed
    (:func:`agents.rollouts.compare`); empty when the environment compares
    none."""
    compared = env_facts(env_id).compared_metric
    if compared is None:
        return {}
    metric, lower = compared
    first = episodes[next(iter(episodes))]
    return {n: compare(first, episodes[n], metric, lower) for n in names}


def render(out: Path) -> str:
    """Write ``evaluation.md`` and ``evaluation.png`` of ``out`` again from
    its ``evaluation.json``, with the table and plot of this version;
    returns the table. The paired comparisons of the compared metric are
    computed from the episodes when the record lacks them."""
    from .constant import format_action

    report = json.loads((Path(out) / "evaluation.json").read_text())
    detail = report.pop("episodes_detail", None)
    if (Path(out) / EPISODES).exists():
        detail = json.loads((Path(out) / EPISODES).read_text())
    env_id = report["env"]
    comparisons = report.get("comparisons") or {}
    metric_comparisons = report.get("metric_comparisons")
    if metric_comparisons is None and comparisons and detail is not None:
        metric_comparisons = metric_differences(env_id, detail, comparisons)
    labels = {}
    if report.get("constant") and "constant" in report["summaries"]:
        labels["constant"] = f"constant {format_action(report['constant']['action'])}"
    table = markdown_table(env_id, report["summaries"], comparisons, report["episodes"],
                           report["seed"], labels, metric_comparisons, report.get("task"),
                           made=report)
    (Path(out) / "evaluation.md").write_text(table)
    if detail is not None:                 # the figure needs the episodes
        plot_trajectories(env_id, detail, Path(out) / "evaluation.png")
    return table


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


#: environment arguments of a training configuration that a trained run is
#: not evaluated with unless asked (``--env-kwargs``): soft ice trains faster,
#: and the task is the default ice's
TRAINING_ONLY_KWARGS = ("stiffness_scale",)


def evaluation_kwargs(env_kwargs: dict) -> dict:
    """A run's ``env_kwargs`` without :data:`TRAINING_ONLY_KWARGS`: those it
    is evaluated with by default."""
    return {k: v for k, v in env_kwargs.items() if k not in TRAINING_ONLY_KWARGS}


def _kwargs_words(kwargs: dict) -> str:
    return ", ".join(f"{k}={v}" for k, v in kwargs.items())


def main(argv: list[str] | None = None, prog: str = "python -m agents.evaluate") -> dict:
    """Command-line entry point (``prog``: the command's name in the help);
    returns the summaries per policy."""
    from iceenvs.facts import registered_ids

    from .baselines import ConstantPolicy, check_policy_names, make_baseline
    from .constant import format_action
    from .envs import make_checked_env, parse_key_values
    from .policy import split_policies
    from .rollouts import policy_recipe

    parser = build_parser(prog)
    args = parser.parse_args(argv)
    if args.render is not None:
        if not (args.render / "evaluation.json").is_file():
            parser.error(f"--render: {args.render / 'evaluation.json'} does not exist")
        print(render(args.render))
        return json.loads((args.render / "evaluation.json").read_text())["summaries"]
    if args.episodes < 1:
        parser.error("--episodes must be >= 1")
    if args.processes < 1:
        parser.error(f"--processes must be >= 1, got {args.processes}")
    try:
        names = split_policies(args.baselines)
    except ValueError as err:
        parser.error(f"--baselines: {err}")
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
        from .waypoint_follower import STUDENT

        if (Path(args.run_dir) / STUDENT).is_file():
            parser.error(f"{args.run_dir} holds a waypoint student, which reads the environment "
                         f"it plays: play it with python -m agents.leaderboard --policies "
                         f"'student=agents.waypoints:WaypointStudent?run={args.run_dir}'")
        try:
            checkpoint_files(args.run_dir, args.checkpoint)
        except FileNotFoundError as err:
            parser.error(str(err))
        trained = TrainedPolicy(args.run_dir, args.checkpoint)
        env_id, base_kwargs = trained.env_id, (
            dict(trained.agent_kwargs) if args.default_config
            else evaluation_kwargs(trained.env_kwargs))
        dropped = {k: v for k, v in trained.env_kwargs.items() if k not in base_kwargs}
        if dropped:
            print(f"the run trained with {_kwargs_words(dropped)}; it is evaluated on the "
                  f"environment's default (--env-kwargs "
                  f"{' '.join(f'{k}=...' for k in dropped)} to evaluate it there)",
                  file=sys.stderr)
        policies[f"{trained.args['algo']} policy"] = trained
        out = args.out or (args.run_dir if args.checkpoint is None
                           else args.run_dir / f"checkpoint_{args.checkpoint}")
    try:
        check_policy_names(names, env_id)
    except ValueError as err:
        parser.error(str(err))
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
        task = task_report(env, env_kwargs, results)
    finally:
        env.close()
    facts = env_facts(env_id)
    summaries = {name: summarise(eps) for name, eps in results.items()}
    comparisons, metric_comparisons = {}, {}
    if args.baseline is None:
        first = next(iter(results))
        comparisons = {n: compare(results[first], results[n]) for n in names}
        metric_comparisons = metric_differences(env_id, results, names)
    from .leaderboard import host_signature

    made = dict(command=shlex.join([*prog.split(), *map(str, sys.argv[1:] if argv is None
                                                         else argv)]),
                commit=source_commit(), host=host_signature(),
                date=datetime.date.today().isoformat())
    table = markdown_table(env_id, summaries, comparisons, args.episodes, args.seed, labels,
                           metric_comparisons, task, made=made)
    print(table)
    out.mkdir(parents=True, exist_ok=True)
    (out / "evaluation.md").write_text(table)
    report = dict(**made, env=env_id, env_kwargs=env_kwargs, episodes=args.episodes,
                  seed=args.seed,
                  constant=constant, summaries=summaries, comparisons=comparisons,
                  metric_comparisons=metric_comparisons,
                  main_metric=facts.main_metric, task=task)
    episodes = {n: [dict(seed=e["seed"], ret=e["ret"], length=e["length"],
                         terminated=e["terminated"], final=e["final"], task=e.get("task", {}),
                         rewards=rounded(e["rewards"]), trace=rounded(e["trace"]))
                    for e in eps] for n, eps in results.items()}
    with open(out / "evaluation.json", "w") as fh:
        json.dump(report, fh)
    with open(out / EPISODES, "w") as fh:
        json.dump(episodes, fh)
    plot_trajectories(env_id, results, out / "evaluation.png")
    return summaries


if __name__ == "__main__":
    main(sys.argv[1:])
