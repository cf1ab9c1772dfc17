"""The reference agents and their benchmark: ``python -m agents.benchmark``.

Two steps, each a command:

``ship`` picks the best of an id's trained seeds and keeps it as the id's
reference agent (:mod:`agents.reference`)::

    python -m agents.benchmark ship runs/reference/WindDrift-v0/seed_* [--episodes 20]

A run is one of :mod:`agents.train` or a waypoint student's
(:mod:`agents.waypoints`; ShipNavigation-v1's reference agent is one).
Every seed's final model plays the same selection episodes (seeded
:data:`agents.reference.TUNE_EVAL_SEED` + k: not the benchmark's) and the
benchmark's episodes (:data:`agents.reference.EVAL_SEED` + k), on the
environment's default configuration but for the run's own way of acting
and observing (:data:`agents.rollouts.AGENT_KWARGS`); the seed of the best
selection score is copied to ``docs/agents/reference/<env-name>/``
(:data:`agents.reference.KEPT_FILES`, replacing the agent kept there
before; other files and folders there stay) with ``seeds.json``: each seed's
scores, returns on the benchmark's episodes, training summary and learning
curve. Choosing on other episodes than those reported keeps the choice
from flattering the benchmark.

``run`` (the default) plays every reference agent beside the baselines on
the benchmark's episodes and writes the record and the page::

    python -m agents.benchmark [run] [--ids WindDrift-v0 ...] [--episodes 40]
        [--processes 2] [--out docs/agents/benchmark] [--keep]
    python -m agents.benchmark --merge A/benchmark.json B/benchmark.json  # runs of other ids
    python -m agents.benchmark --render          # the page again from the record

Per id: the agent's return (mean ± standard error over the episodes), the
spread of its training seeds (from ``seeds.json``), and the paired
differences with zero, random, the best constant action
(``docs/agents/tasks/constant_<env-name>.json``), the hand-written
controller and, for the ship tasks, the other controllers and the planners.
An id without a reference agent keeps its row, with its baselines. Output:
``benchmark.json``, ``benchmark.md`` (the table, included in the docs'
training page), ``details.md`` (per id, the paired differences with every
baseline) and ``learning_curves.png`` (every seed of every agent).
"""
from __future__ import annotations

import argparse
import json
import shlex
import shutil
import sys
import time
from pathlib import Path

import numpy as np
import yaml

from .diagnostics import DIAGNOSTICS_DIR  # the ceiling, chaos and oracle records the rows note

__all__ = ["ship", "run_summary", "benchmark_id", "markdown", "details_markdown", "main",
           "DEFAULT_OUT", "AGENT", "STUDENT_ALGO", "FINETUNED_ALGO"]

DEFAULT_OUT = Path("docs") / "agents" / "benchmark"
#: the name of the reference agent among the policies of a row
AGENT = "agent"
#: how the table names a waypoint student (agents.waypoints) kept as a reference agent
STUDENT_ALGO = "DAgger waypoint student"
#: ... and one fine-tuned by PPO on its decisions (agents.waypoint_rl)
FINETUNED_ALGO = "PPO-tuned waypoint student"
#: where the best constant action of each id is kept (agents.tasks)
TASKS_DIR = Path("docs") / "agents" / "tasks"


# -- ship ------------------------------------------------------------------------------------
def _learning_curve(run_dir: Path) -> dict:
    """The evaluation callback's scores (steps, mean, std) and the training
    episodes' mean return against steps, thinned to at most 200 points."""
    out = {"eval": [], "train": []}
    npz = run_dir / "eval" / "evaluations.npz"
    if npz.is_file():
        data = np.load(npz)
        out["eval"] = [[int(s), float(np.mean(r)), float(np.std(r))]
                       for s, r in zip(data["timesteps"], data["results"])]
    try:
        from .curves import read_progress

        train = read_progress(run_dir)["train"]
    except (FileNotFoundError, ValueError):
        train = []
    if len(train) > 200:
        train = [train[i] for i in np.linspace(0, len(train) - 1, 200).astype(int)]
    out["train"] = [[int(s), float(r)] for s, r in train]
    return out


def play(env_id: str, recipes: dict, *, episodes: int, seed: int, processes: int,
         progress: bool) -> dict:
    """``{name: [episode dicts]}`` of every recipe
    (:func:`agents.rollouts.evaluate_in_processes`) on episodes seeded
    ``seed`` + k of the default environment (a trained run's with its
    :data:`AGENT_KWARGS`); in this process for one."""
    import gymnasium as gym

    from .rollouts import evaluate, evaluate_in_processes, policy_from_recipe, run_agent_kwargs

    if processes > 1:
        return evaluate_in_processes(env_id, {}, recipes, episodes=episodes, seed=seed,
                                     processes=processes, progress=progress)
    envs = {}   # one environment per way of acting and observing
    try:
        policies = {}
        for name, recipe in recipes.items():
            agent = run_agent_kwargs(recipe[1]) if recipe[0] == "trained" else {}
            key = repr(sorted(agent.items()))
            if key not in envs:
                envs[key] = gym.make(env_id, **agent)
            policies[name] = (envs[key], policy_from_recipe(recipe, envs[key], seed))
        out = {}
        for name, (env, policy) in policies.items():
            out.update(evaluate(env, {name: policy}, episodes=episodes, seed=seed,
                                progress=progress))
        return out
    finally:
        for env in envs.values():
            env.close()


def _play(run_dir: Path, episodes: int, seed: int, processes: int, progress: bool) -> list[float]:
    """The returns of a run's final model on episodes seeded ``seed`` + k."""
    from .rollouts import run_env_id

    env_id = run_env_id(run_dir)
    runs = play(env_id, {"run": ("trained", str(run_dir), {})}, episodes=episodes, seed=seed,
                processes=processes, progress=progress)
    return [e["ret"] for e in runs["run"]]


def _student_training(record: dict) -> dict:
    """A waypoint student's training in the terms of ``training.yaml``:
    the decisions it learnt from (``steps``, ``unit``) and its wall time;
    for imitation its rounds and its imitation error on held-out fields,
    for fine-tuning the run it started from (whose own time is not
    counted)."""
    from .waypoint_follower import student_record

    if "rounds" in record:
        return dict(steps=int(sum(r["decisions"] for r in record["rounds"])),
                    unit="decisions", wall_seconds=record.get("seconds"),
                    rounds=len(record["rounds"]), held_out=record.get("held_out"))
    out = dict(steps=int(record["decisions"]), unit="decisions",
               wall_seconds=record.get("seconds"), started_from=record["settings"].get("run"),
               finetune_decisions=int(record["decisions"]),
               finetune_seconds=record.get("seconds"))
    try:
        start = student_record(out["started_from"]) if out["started_from"] else None
    except FileNotFoundError:
        start = None
    if start is not None and "rounds" in start:     # the imitation it started from, counted in
        imitation = _student_training(start)
        out.update(steps=out["steps"] + imitation["steps"],
                   wall_seconds=(out["wall_seconds"] or 0.0) + (imitation["wall_seconds"] or 0.0),
                   imitation_decisions=imitation["steps"],
                   imitation_seconds=imitation["wall_seconds"], held_out=imitation["held_out"])
    return out


def _student_curve(record: dict) -> dict:
    """A waypoint student's training as a learning curve (no evaluation
    callback): each DAgger round's mean return (the teacher's and the
    student's decisions mixed) against the decisions taught so far (none
    for a fine-tuning: its record has the return by window of episodes)."""
    taught, train = 0, []
    for r in record.get("rounds", []):
        taught += r["decisions"]
        train.append([taught, float(r["mean_return"])])
    return {"eval": [], "train": train}


def run_summary(run: Path) -> dict:
    """What a run directory (of :mod:`agents.train`, or a waypoint student's)
    says of its training: ``seed``, ``training`` (``training.yaml``'s
    entries: ``steps``, ``wall_seconds``, ...), ``curve``, ``algo`` (the
    algorithm as the table names it), ``env_kwargs`` and ``command``."""
    from .waypoint_follower import student_record

    run = Path(run)
    student = student_record(run)
    if student is not None:
        # a kept agent's training.yaml (written by ship) holds what its record alone cannot
        # say: the imitation a fine-tuning started from
        kept = yaml.safe_load((run / "training.yaml").read_text()) \
            if (run / "training.yaml").is_file() else None
        return dict(seed=int(student["settings"]["seed"]),
                    training=kept or _student_training(student),
                    curve=_student_curve(student),
                    algo=STUDENT_ALGO if "rounds" in student else FINETUNED_ALGO,
                    env_kwargs=student["settings"].get("env_kwargs") or {},
                    command=student.get("command") or "")
    if not (run / "model.zip").is_file() or not (run / "args.yaml").is_file():
        raise ValueError(f"{run} is not a finished run of agents.train (no model.zip or "
                         f"args.yaml) nor of agents.waypoints train (no student.zip)")
    args = yaml.safe_load((run / "args.yaml").read_text())
    training = yaml.safe_load((run / "training.yaml").read_text()) \
        if (run / "training.yaml").is_file() else {}
    hp = yaml.safe_load((run / "hyperparams.yaml").read_text()) \
        if (run / "hyperparams.yaml").is_file() else {}
    command = (run / "command.txt").read_text().strip() if (run / "command.txt").is_file() \
        else ""
    return dict(seed=int(args["seed"]), training=training or {}, curve=_learning_curve(run),
                algo=args["algo"], env_kwargs=hp.get("env_kwargs") or {},
                command=command)


def portable_command(text: str) -> str:
    """A run's ``command.txt`` as anyone runs it: ``python -m ...`` in place
    of the interpreter's path on the machine that trained it."""
    words = shlex.split(text)
    if words and Path(words[0]).name.startswith("python"):
        words[0] = "python"
    return shlex.join(words) + "\n"


def ship(run_dirs: list[Path], *, episodes: int = 20, processes: int = 1,
         progress: bool = True, out: Path | None = None,
         evaluation_episodes: int | None = None) -> Path:
    """Score each seed's run on ``episodes`` selection episodes and
    ``evaluation_episodes`` (default :data:`agents.reference.EVAL_EPISODES`)
    of the benchmark's, keep the best as the id's reference agent (in
    ``out``, default ``docs/agents/reference/<env-name>``) and write
    ``seeds.json`` beside it; returns the reference directory."""
    from .reference import (EVAL_EPISODES, EVAL_SEED, KEPT_FILES, MAX_BYTES, TUNE_EVAL_SEED,
                            drop_optimizer_states, reference_dir)
    from .rollouts import run_env_id, stats

    evaluation_episodes = evaluation_episodes or EVAL_EPISODES
    runs = [Path(r) for r in run_dirs]
    if not runs:
        raise ValueError("ship needs at least one run directory")
    summaries = [run_summary(run) for run in runs]   # refuses what is not a finished run
    kinds = {s["algo"] in (STUDENT_ALGO, FINETUNED_ALGO) for s in summaries}
    if len(kinds) != 1:
        raise ValueError("the runs mix waypoint students and runs of agents.train: ship one "
                         "kind at a time")
    envs = {run_env_id(run) for run in runs}
    if len(envs) != 1:
        raise ValueError(f"the runs are of several environments: {sorted(envs)}")
    env_id = envs.pop()
    seeds = []
    for run, summary in zip(runs, summaries):
        print(f"{run}: {episodes} selection episodes, then {evaluation_episodes} benchmark "
              f"episodes", flush=True)
        selection = _play(run, episodes, TUNE_EVAL_SEED, processes, progress)
        evaluation = _play(run, evaluation_episodes, EVAL_SEED, processes, progress)
        seeds.append(dict(seed=summary["seed"], run=run.name,
                          selection=stats(np.array(selection)),
                          evaluation=stats(np.array(evaluation)), returns=evaluation,
                          training=summary["training"], curve=summary["curve"]))
    best = max(seeds, key=lambda s: s["selection"]["mean"])
    target = Path(out) if out is not None else reference_dir(env_id)
    target.mkdir(parents=True, exist_ok=True)
    for name in (*KEPT_FILES, "seeds.json"):   # the agent kept before; anything else stays
        (target / name).unlink(missing_ok=True)
    source = runs[seeds.index(best)]
    for name in KEPT_FILES:
        if (source / name).is_file():
            shutil.copy2(source / name, target / name)
    chosen = summaries[seeds.index(best)]
    if not (target / "training.yaml").is_file():      # a waypoint student's, from its record
        (target / "training.yaml").write_text(yaml.safe_dump(chosen["training"], sort_keys=False))
    (target / "command.txt").write_text(portable_command(
        (target / "command.txt").read_text() if (target / "command.txt").is_file()
        else chosen["command"]))
    means = [s["evaluation"]["mean"] for s in seeds]
    record = dict(env=env_id, chosen_seed=best["seed"],
                  chosen_by=f"the best mean return on {episodes} selection episodes seeded "
                            f"{TUNE_EVAL_SEED} + k",
                  evaluation_episodes=f"{evaluation_episodes} seeded {EVAL_SEED} + k",
                  across_seeds=dict(mean=float(np.mean(means)), std=float(np.std(means, ddof=1))
                                    if len(means) > 1 else 0.0, min=float(np.min(means)),
                                    max=float(np.max(means))),
                  seeds=seeds, command=shlex.join(["python", "-m", "agents.benchmark", "ship",
                                                   *map(str, run_dirs)]))
    (target / "seeds.json").write_text(json.dumps(record, indent=1) + "\n")
    size = sum(p.stat().st_size for p in target.rglob("*") if p.is_file())   # all it holds
    if size > MAX_BYTES and (target / "model.zip").is_file():
        saved = drop_optimizer_states(target / "model.zip",
                                      yaml.safe_load((target / "args.yaml").read_text())["algo"])
        size -= saved
        print(f"dropped the optimisers' moments from the kept model ({saved / 1024:.0f} kB): "
              f"it plays as trained, and fine-tuning it starts them afresh", flush=True)
    print(f"kept seed {best['seed']} of {len(seeds)} in {target} ({size / 1024:.0f} kB); "
          f"benchmark returns across seeds {', '.join(f'{m:.4g}' for m in means)}", flush=True)
    if size > MAX_BYTES:
        raise ValueError(f"{target} holds {size} bytes, more than the {MAX_BYTES} a reference "
                         f"agent may keep: a smaller network, or fewer files")
    return target


# -- run -------------------------------------------------------------------------------------
def _baseline_recipes(env_id: str) -> dict:
    """The baselines of a row: random, zero, the best constant action (when
    searched), the hand-written controller and the environment's other
    controllers and planners."""
    from iceenvs.facts import env_facts

    from .baselines import baseline_names, load_results
    from .metrics import env_name
    from .planners import ON_REQUEST, PLANNERS

    recipes = {name: ("baseline", name, {}) for name in ("zero", "random")}
    search = TASKS_DIR / f"constant_{env_name(env_id)}.json"
    if search.is_file():
        action = load_results(search)["results"][0]["action"]
        recipes["constant"] = ("baseline", "constant", {"action": list(action)})
    recipes["heuristic"] = ("baseline", "heuristic", {})
    own = env_facts(env_id).controllers
    for name in baseline_names(env_id):
        if name in ON_REQUEST:
            continue
        if name in PLANNERS or (name in own and own[name] is not own.get("heuristic")):
            recipes[name] = ("baseline", name, {})
    return recipes


def benchmark_id(env_id: str, *, episodes: int, processes: int, progress: bool = True,
                 root: Path | None = None) -> dict:
    """One row: every policy's returns on the benchmark's episodes, and the
    reference agent's paired differences with each baseline (the agents
    under ``root``, default ``docs/agents/reference``)."""
    from .reference import EVAL_SEED, is_reference, reference_dir
    from .rollouts import compare, stats

    recipes = _baseline_recipes(env_id)
    agent_dir = reference_dir(env_id, root)
    has_agent = is_reference(agent_dir)
    if has_agent:
        recipes = {AGENT: ("trained", str(agent_dir), {}), **recipes}
    t0 = time.perf_counter()
    runs = play(env_id, recipes, episodes=episodes, seed=EVAL_SEED, processes=processes,
                progress=progress)
    row = dict(id=env_id, episodes=episodes, seed=EVAL_SEED,
               returns={name: stats(np.array([e["ret"] for e in eps]))
                        for name, eps in runs.items()},
               first_returns={name: [e["ret"] for e in eps[:2]] for name, eps in runs.items()},
               seconds=round(time.perf_counter() - t0, 1), agent=None)
    if has_agent:
        seeds = json.loads((agent_dir / "seeds.json").read_text()) \
            if (agent_dir / "seeds.json").is_file() else {}
        summary = run_summary(agent_dir)
        training = summary["training"]
        row["agent"] = dict(
            algo=summary["algo"], seed=summary["seed"], steps=training.get("steps"),
            unit=training.get("unit", "steps"),
            wall_seconds=training.get("wall_seconds"), host=training.get("host"),
            env_kwargs=summary["env_kwargs"], across_seeds=seeds.get("across_seeds"),
            seeds=[dict(seed=s["seed"], mean=s["evaluation"]["mean"],
                        sem=s["evaluation"]["sem"], steps=s["training"].get("steps"),
                        wall_seconds=s["training"].get("wall_seconds"))
                   for s in seeds.get("seeds", [])],
            command=(agent_dir / "command.txt").read_text().strip())
        row["differences"] = {name: compare(runs[AGENT], eps) for name, eps in runs.items()
                              if name != AGENT}
    return row


def _pm(s: dict) -> str:
    from .metrics import format_pm

    return format_pm(s["mean"], s["sem"])


def task_table_note(env_id: str) -> str:
    """``"; no controller beat the best constant action in the task table"``
    when the task table (``docs/agents/tasks/tasks.json``, :mod:`agents.tasks`)
    found no controller, planner or trained policy beating the id's best
    constant action by two standard errors (a task a constant action may
    solve), else empty."""
    path = TASKS_DIR / "tasks.json"
    if not path.is_file():
        return ""
    row = next((r for r in json.loads(path.read_text())["rows"] if r["id"] == env_id), None)
    from .tasks import beating_constant

    if row is None or beating_constant(row):
        return ""
    return "; no controller beat the best constant action in the task table"


def ceiling_note(env_id: str) -> str:
    """``"; the controller is within D ± SE of the return no policy passes"``
    where a ceiling record (:mod:`agents.ceiling`) bounds the id's return,
    else empty."""
    name = env_id.split("/")[-1]
    path = DIAGNOSTICS_DIR / f"{name}-ceiling" / "ceiling.json"
    if not path.is_file():
        return ""
    below = json.loads(path.read_text())["summary"]["heuristic"]["below_ceiling"]
    return (f"; the controller is within {_pm(below)} of the return no policy passes "
            f"([ceiling](/reference-agents.md#why-an-agent-cannot-win-{name.lower()}))")


def oracle_note(env_id: str) -> str:
    """``"; a search on the true model gains D ± SE over the controller
    beyond foresight of the chaos, ..."`` where an oracle record
    (:mod:`agents.oracle`) exists for the id, with the smallest gain the
    benchmark resolves where a chaos record (:mod:`agents.chaos`) exists;
    else empty."""
    from .diagnostics import resolvable
    from .reference import EVAL_EPISODES

    name = env_id.split("/")[-1]
    path = DIAGNOSTICS_DIR / f"{name}-oracle" / "oracle.json"
    if not path.is_file():
        return ""
    d = json.loads(path.read_text())["differences"]["oracle − chaos oracle"]
    note = (f"; a search on the true model gains {_pm(dict(mean=d['diff'], sem=d['sem']))} "
            f"over the controller beyond foresight of the chaos")
    chaos = DIAGNOSTICS_DIR / f"{name}-chaos" / "chaos.json"
    if chaos.is_file():
        limit = resolvable(json.loads(chaos.read_text()), EVAL_EPISODES)
        note += f"; the benchmark's {EVAL_EPISODES} episodes resolve gains of {limit:.2g} or more"
    return note + f" ([oracle](/reference-agents.md#what-a-policy-could-gain-{name.lower()}))"


def markdown(record: dict) -> str:
    """``benchmark.md``: one row per id (:func:`details_markdown` has the
    paired differences of each)."""
    from .rollouts import verdict

    lines = [f"Made by `{record['command']}` at commit `{record['commit']}`, {record['date']}. "
             f"Every policy plays the same {record['episodes']} episodes per id (episode k "
             f"seeded {record['seed']} + k, fixed before any agent was trained or tuned), on the "
             f"environment's default configuration. Returns are mean ± standard error over the "
             f"episodes; \"across seeds\" is the mean (min–max) of the training seeds' "
             f"returns on the same episodes; differences are the agent's return minus the "
             f"baseline's, paired by episode.", "",
             "| id | agent | training | return | across seeds | best baseline | agent − best "
             "baseline | verdict |", "|---|---|---|---|---|---|---|---|"]
    for row in record["rows"]:
        returns = row["returns"]
        baselines = {n: s for n, s in returns.items() if n != AGENT}
        best = max(baselines, key=lambda n: baselines[n]["mean"])
        name = row["id"].split("/")[-1]
        if row["agent"] is None:
            lines.append(f"| `{row['id']}` | none yet | — | — | — | {best} "
                         f"{_pm(baselines[best])} | — | no reference agent"
                         f"{task_table_note(row['id'])} |")
            continue
        a = row["agent"]
        spread = a.get("across_seeds") or {}
        across = (f"{spread['mean']:.4g} ({spread['min']:.4g}–{spread['max']:.4g}), "
                  f"{len(a['seeds'])} seeds" if spread else "—")
        hours = f"{a['wall_seconds'] / 60:.0f} min" if a.get("wall_seconds") else "?"
        soft = " (soft ice)" if a["env_kwargs"].get("stiffness_scale", 1.0) != 1.0 else ""
        d = row["differences"][best]
        solved = task_table_note(row["id"]) + ceiling_note(row["id"]) + oracle_note(row["id"])
        lines.append(f"| [`{row['id']}`](/reference-agents.md#{name.lower()}) | "
                     f"{a['algo'].upper() if a['algo'].islower() else a['algo']}, seed "
                     f"{a['seed']} | {a['steps']} {a.get('unit', 'steps')}{soft}, {hours} | "
                     f"{_pm(returns[AGENT])} | {across} | {best} {_pm(baselines[best])} | "
                     f"{d['diff']:+.3g} ± {d['sem']:.2g} | {verdict(d)}{solved} |")
    return "\n".join(lines) + "\n"


def details_markdown(record: dict) -> str:
    """``details.md``: per id with a reference agent, its command, host,
    training seeds and the paired differences with every baseline."""
    from .rollouts import verdict

    lines = []
    for row in record["rows"]:
        if row["agent"] is None:
            continue
        name = row["id"].split("/")[-1]
        a = row["agent"]
        lines += ["", f"### {name}", "",
                  f"`{a['command']}`; " + (
                      f"trained on {a['host']['cpu']} ({a['host']['logical_cpus']} logical "
                      f"CPUs). " if a.get("host") else "its training did not record its host. ") +
                  "Seeds: " + ", ".join(
                      f"{s['seed']}: {s['mean']:.4g} ± {s['sem']:.2g} ({s['steps']} "
                      f"{a.get('unit', 'steps')}, "
                      f"{(s['wall_seconds'] or 0) / 60:.0f} min)" for s in a["seeds"]) + ".", "",
                  "| baseline | its return | agent − baseline (paired) | the agent (by > 2 SE) |",
                  "|---|---|---|---|"]
        for base, d in row["differences"].items():
            lines.append(f"| {base} | {_pm(row['returns'][base])} | {d['diff']:+.3g} ± "
                         f"{d['sem']:.2g} | {verdict(d)} |")
    return "\n".join(lines) + "\n"


def plot_curves(record: dict, path: Path, root: Path | None = None) -> None:
    """``learning_curves.png``: the evaluation callback's score of every
    training seed of every reference agent against steps."""
    from physics.scenarios import plots

    from .reference import reference_dir

    rows = [r for r in record["rows"] if r["agent"] is not None]
    plt = plots.pyplot()
    n = max(len(rows), 1)
    cols = min(n, 4)
    fig, axes = plt.subplots((n + cols - 1) // cols, cols, figsize=(3.6 * cols,
                                                                    3.0 * ((n + cols - 1) // cols)),
                             squeeze=False)
    for ax, row in zip(axes.flat, rows):
        seeds_file = reference_dir(row["id"], root) / "seeds.json"
        seeds = json.loads(seeds_file.read_text())["seeds"] if seeds_file.is_file() else []
        student = (row["agent"] or {}).get("unit") == "decisions"
        if student and not any(s["curve"]["eval"] or s["curve"]["train"] for s in seeds):
            ax.text(0.5, 0.5, "a waypoint student: no evaluation callback\n(its training's "
                    "record is in its directory)", ha="center", va="center",
                    transform=ax.transAxes, fontsize=8)
        for k, s in enumerate(seeds):
            curve = s["curve"]["eval"]
            if curve:
                x, y, sd = map(np.array, zip(*curve))
                ax.plot(x, y, color=f"C{k}", lw=1.2, label=f"seed {s['seed']}")
                ax.fill_between(x, y - sd, y + sd, color=f"C{k}", alpha=0.15)
            elif student and s["curve"]["train"]:
                # a waypoint student has no evaluation callback: each DAgger round's
                # episodes (teacher and student mixed) against the decisions taught
                x, y = map(np.array, zip(*s["curve"]["train"]))
                ax.plot(x, y, "o-", color=f"C{k}", lw=1.2, ms=3,
                        label=f"seed {s['seed']} (DAgger rounds)")
        best = max((n for n in row["returns"] if n != AGENT),
                   key=lambda n: row["returns"][n]["mean"])
        ax.axhline(row["returns"][best]["mean"], color="k", ls="--", lw=0.9,
                   label=f"{best} (benchmark)")
        ax.set(title=row["id"].split("/")[-1], xlabel="decisions taught" if student else "steps",
               ylabel="evaluation return")
        ax.legend(fontsize=7)
    for ax in list(axes.flat)[len(rows):]:
        ax.set_axis_off()
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def merge(records: list[dict]) -> dict:
    """One record of several runs' rows (a later record's row of an id
    replaces an earlier one's), their commands joined in order.

    Raises
    ------
    ValueError
        When the records played other episodes (count or first seed)."""
    from iceenvs import ENV_IDS

    first = records[0]
    for other in records[1:]:
        for key in ("episodes", "seed"):
            if other[key] != first[key]:
                raise ValueError(f"the records differ in {key}: {first[key]} and {other[key]}")
    rows = {}
    for record in records:
        rows.update({row["id"]: row for row in record["rows"]})
    order = sorted(rows, key=lambda i: ENV_IDS.index(i) if i in ENV_IDS else len(ENV_IDS))
    return dict(command="` then `".join(r["command"] for r in records),
                commit=records[-1]["commit"], date=records[-1]["date"],
                host=records[-1].get("host"), episodes=first["episodes"], seed=first["seed"],
                rows=[rows[i] for i in order])


def build_parser() -> argparse.ArgumentParser:
    from iceenvs import ENV_IDS

    names = [e.split("/")[1] for e in ENV_IDS]
    p = argparse.ArgumentParser(prog="python -m agents.benchmark",
                                description="Ship the reference agents and benchmark them.")
    p.add_argument("action", nargs="?", choices=("run", "ship"), default="run")
    p.add_argument("runs", nargs="*", type=Path, help="ship: the run directories of one id's "
                                                      "training seeds")
    p.add_argument("--ids", nargs="+", choices=names, default=names, metavar="NAME",
                   help="run: the ids (default all): " + ", ".join(names))
    p.add_argument("--episodes", type=int, default=None,
                   help="run: episodes per policy (default 40); ship: selection episodes "
                        "(default 20)")
    p.add_argument("--processes", type=int, default=2, help="worker processes (default 2)")
    p.add_argument("--out", type=Path, default=None,
                   help=f"run: the record's directory (default {DEFAULT_OUT}); ship: the "
                        f"reference directory (default docs/agents/reference/<env-name>)")
    p.add_argument("--reference", type=Path, default=None, metavar="DIR",
                   help="run: the folder of the reference agents (default docs/agents/reference)")
    p.add_argument("--keep", action="store_true",
                   help="run: keep the rows of the ids not run from --out's benchmark.json")
    p.add_argument("--merge", nargs="+", type=Path, default=None, metavar="JSON",
                   help="run: join the rows of these benchmark.json files (of runs over "
                        "different ids, e.g. in parallel) into --out, without playing")
    p.add_argument("--render", action="store_true",
                   help="only write benchmark.md and the figure again from benchmark.json")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bars")
    return p


def main(argv: list[str] | None = None) -> dict | Path:
    from iceenvs import ENV_IDS
    from physics.provenance import source_commit

    from .reference import EVAL_EPISODES, EVAL_SEED

    raw = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    args = parser.parse_args(raw)
    if args.episodes is not None and args.episodes < 2:
        parser.error("--episodes must be >= 2 (a standard error needs two)")
    if args.processes < 1:
        parser.error("--processes must be >= 1")
    if args.action == "ship":
        if not args.runs:
            parser.error("ship takes the run directories of one id's training seeds")
        try:
            return ship(args.runs, episodes=args.episodes or 20, processes=args.processes,
                        progress=not args.no_progress, out=args.out)
        except ValueError as err:
            parser.error(str(err))
    if args.runs:
        parser.error("run takes no run directories (did you mean ship?)")
    out = args.out or DEFAULT_OUT
    path = out / "benchmark.json"
    if args.render:
        if not path.is_file():
            parser.error(f"--render: {path} does not exist")
        record = json.loads(path.read_text())
    elif args.merge:
        try:
            record = merge([json.loads(Path(f).read_text()) for f in args.merge])
        except (OSError, ValueError, KeyError) as err:
            parser.error(f"--merge: {err}")
        out.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(record, indent=1) + "\n")
    else:
        episodes = args.episodes or EVAL_EPISODES
        old = json.loads(path.read_text()) if args.keep and path.is_file() else None
        if old is not None and old["episodes"] != episodes:
            parser.error(f"--keep: {path} has {old['episodes']} episodes, this run {episodes}")
        from .leaderboard import host_signature

        command = shlex.join(["python", "-m", "agents.benchmark", *raw])
        if old is not None:
            command = f"{old['command']}` then `{command}"
        rows = []
        out.mkdir(parents=True, exist_ok=True)
        for name in args.ids:
            print(f"{name}: {episodes} episodes per policy ...", flush=True)
            rows.append(benchmark_id(f"iceenvs/{name}", episodes=episodes,
                                     processes=args.processes, progress=not args.no_progress,
                                     root=args.reference))
            done = {r["id"] for r in rows}
            kept = [r for r in (old or {}).get("rows", []) if r["id"] not in done] + rows
            kept.sort(key=lambda r: ENV_IDS.index(r["id"]) if r["id"] in ENV_IDS
                      else len(ENV_IDS))
            # written after every id, so that an interrupted run keeps the rows it made
            record = dict(command=command, commit=source_commit(),
                          date=time.strftime("%Y-%m-%d"), host=host_signature(),
                          episodes=episodes, seed=EVAL_SEED, rows=kept)
            path.write_text(json.dumps(record, indent=1) + "\n")
    (out / "benchmark.md").write_text(markdown(record))
    (out / "details.md").write_text(details_markdown(record).lstrip("\n"))
    plot_curves(record, out / "learning_curves.png", args.reference)
    print(f"wrote {out / 'benchmark.md'}")
    return record


if __name__ == "__main__":
    main()
