"""Does each task need a policy? ``python -m agents.tasks``.

For every environment (or those of ``--ids``) in its default
configuration: the best constant action of a grid search
(:func:`agents.constant.search_constant_actions`: ``--grid`` points per
action dimension, ``--seeds`` episodes each, seeded away from the
evaluation episodes), then the random, zero-action, best-constant and
hand-written policies on the same ``--episodes`` seeded episodes
(episode k seeded ``--seed`` + k), and the paired difference of the
hand-written controller's return over the best constant action's. A ship
environment's row adds its other controllers (the straight line) and its
planners (:mod:`agents.planners`, which read the ice), any trained
policy given with ``--trained`` and any other policy given with
``--policies``: a baseline's name or a policy of one's own,
``module:Class`` or ``path/to/file.py:Class?key=value``
(:mod:`agents.policy`), played in every environment of ``--ids``. A task needs a
policy when a controller that reacts to what it senses (the hand-written
one, a planner or a trained policy) beats every constant action by more
than two standard errors; the table says which.

Output in ``--out`` (default ``runs/agents/tasks``; the documented tables are
``--out docs/agents/tasks``): ``tasks.md`` (the
table, with command, machine and date), ``tasks.json`` (every number)
and ``constant_<env>.json`` per environment (the whole search; reused
with ``--reuse`` so that a table can be remade without searching again)::

    python -m agents.tasks [--ids Convergence-v0 ...] [--episodes 20] [--grid 9]
        [--seeds 5] [--processes 2] [--out DIR] [--reuse] [--keep]
        [--trained NAME=RUN_DIR[@STEPS] ...] [--policies NAME_OR_MODULE:CLASS,...]
    python -m agents.tasks --render [--out DIR]     # tasks.md again from tasks.json

``--keep`` keeps the rows of the environments not run from ``--out``'s
``tasks.json``.
"""
from __future__ import annotations

import argparse
import datetime
import json
import platform
import shlex
import sys
import time
from pathlib import Path

__all__ = ["analyse", "beating_constant", "task_table", "main"]

EVAL_SEED = 10_000
DEFAULT_OUT = Path("runs/agents/tasks")


def analyse(env_id: str, *, episodes: int, grid: int, seeds: int, processes: int,
            out: Path, reuse: bool = False, progress: bool = True,
            trained: dict | None = None, extra: list[str] | tuple = ()) -> dict:
    """The constant-action search and the baselines of one environment;
    returns a dict of the numbers (see :func:`task_table`). ``trained``:
    ``{name: (run_dir, checkpoint or None)}`` of trained policies of this
    environment to evaluate beside them; ``extra``: further policies, a
    baseline's name or a reference ``module:Class``
    (:func:`agents.baselines.make_baseline`)."""
    import gymnasium as gym

    import iceenvs  # noqa: F401

    from iceenvs.facts import env_facts

    from .baselines import ConstantPolicy, baseline_names, make_baseline
    from .baselines import load_results
    from .constant import search_constant_actions
    from .planners import ON_REQUEST, PLANNERS
    from .rollouts import TrainedPolicy, compare, evaluate, summarise
    from .metrics import env_name

    path = out / f"constant_{env_name(env_id)}.json"
    t0 = time.perf_counter()
    if reuse and path.exists():
        results = load_results(path)["results"]
    else:
        results = search_constant_actions(env_id, grid=grid, seeds=seeds,
                                          processes=processes, progress=progress)
        with open(path, "w") as fh:
            json.dump(dict(env=env_id, env_kwargs={}, grid=grid, seeds=seeds,
                           n_actions=len(results), results=results), fh, indent=1)
    t_search = time.perf_counter() - t0
    env = gym.make(env_id)
    try:
        policies = {name: make_baseline(name, env, EVAL_SEED)
                    for name in ("random", "zero", "heuristic")}
        policies["constant"] = ConstantPolicy(env, EVAL_SEED, action=results[0]["action"])
        # the environment's other controllers (the ship's straight line) and the planners
        own = env_facts(env_id).controllers
        planners = [n for n in baseline_names(env_id) if n not in ON_REQUEST and (
            n in PLANNERS or (n in own and own[n] is not own.get("heuristic")))]
        for name in planners:
            policies[name] = make_baseline(name, env, EVAL_SEED)
        for name, (run_dir, checkpoint) in (trained or {}).items():
            policies[name] = TrainedPolicy(run_dir, checkpoint)
        extra = [name for name in extra if name not in policies]
        for name in extra:
            policies[name] = make_baseline(name, env, EVAL_SEED)
        runs = evaluate(env, policies, episodes=episodes, seed=EVAL_SEED, progress=progress)
    finally:
        env.close()
    summaries = {name: summarise(eps)["return"] for name, eps in runs.items()}
    over = {name: compare(runs[name], runs["constant"])
            for name in ["heuristic", *planners, *(trained or {}), *extra]}
    return dict(id=env_id, best_action=list(results[0]["action"]),
                search_mean=results[0]["mean"], n_actions=len(results),
                returns=summaries,
                heuristic_minus_constant=over["heuristic"],
                planners=planners, trained=list(trained or {}), own=extra, over_constant=over,
                steps=int(gym.spec(env_id).max_episode_steps),
                seconds=time.perf_counter() - t0, search_seconds=t_search)


def beating_constant(row: dict) -> list[str]:
    """The policies of a row of :func:`analyse` (the controller, planners,
    trained and own policies) that beat the best constant action by more
    than two standard errors of the paired difference."""
    over = row.get("over_constant", {"heuristic": row["heuristic_minus_constant"]})
    return [name for name, d in over.items() if d["beats"]]


def task_table(rows: list[dict]) -> str:
    """Markdown: one row per environment."""
    from .constant import format_action

    lines = ["| id | steps per episode | best constant action (of) | constant | zero | random | "
             "controller | controller − constant [SE] | other controllers − constant [SE] | "
             "trained and own − constant [SE] | needs a policy |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        ret = r["returns"]
        c = r["heuristic_minus_constant"]
        over = r.get("over_constant", {"heuristic": c})

        def cell(name, ret=ret):
            return f"{ret[name]['mean']:.1f} ± {ret[name]['std']:.1f}"

        def diffs(names, over=over):
            return "<br>".join(f"{n}: {over[n]['diff']:+.1f} [{over[n]['sem']:.2g}]"
                               for n in names) or "—"

        winners = beating_constant(r)
        verdict = "yes (" + ", ".join(winners) + ")" if winners else "not shown"
        lines.append(f"| `{r['id']}` | {r['steps']} | {format_action(r['best_action'])} "
                     f"({r['n_actions']}) | {cell('constant')} | {cell('zero')} | "
                     f"{cell('random')} | {cell('heuristic')} | {c['diff']:+.1f} "
                     f"[{c['sem']:.2g}] | {diffs(r.get('planners', []))} | "
                     f"{diffs([*r.get('trained', []), *r.get('own', [])])} | {verdict} |")
    return "\n".join(lines) + "\n"


def _document(saved: dict) -> str:
    """tasks.md: what was run, then the table."""
    from .constant import SEARCH_SEED

    return (f"Returns over {saved['episodes']} episodes (episode k seeded {EVAL_SEED} + k; mean "
            f"± std), default configuration of each environment. The best constant action is "
            f"the best of a grid of {saved['grid']} points per action dimension, "
            f"{saved['seeds']} episodes each (seeds {SEARCH_SEED} + k). \"Controller\" is the "
            f"hand-written controller of `agents.baselines`; its difference from the best "
            f"constant action is paired by seed, as are those of the other controllers and planners "
            f"(ship environments: the straight line, and the lattice planner, which reads the "
            f"ice) and of the trained policies and policies of one's own. \"Needs a policy\" "
            f"names the "
            f"policies that beat the best constant action by more than two standard errors."
            f"\n\n`{saved['command']}` ({saved['machine']}, "
            f"{saved['date']})\n\n" + task_table(saved["rows"]))


def main(argv: list[str] | None = None) -> list[dict]:
    from iceenvs import ENV_IDS

    p = argparse.ArgumentParser(prog="python -m agents.tasks",
                                description=__doc__.splitlines()[0])
    names = [e.split("/")[1] for e in ENV_IDS]
    p.add_argument("--ids", nargs="+", choices=names, default=names, metavar="NAME",
                   help="environments (default all): " + ", ".join(names))
    p.add_argument("--episodes", type=int, default=20, help="evaluation episodes (default 20)")
    p.add_argument("--grid", type=int, default=9, help="constant actions per dimension (9)")
    p.add_argument("--seeds", type=int, default=5, help="search episodes per action (5)")
    p.add_argument("--processes", type=int, default=2, help="search processes (2)")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT,
                   help=f"output directory (default {DEFAULT_OUT})")
    p.add_argument("--reuse", action="store_true",
                   help="reuse the constant-action searches found in --out")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bars")
    p.add_argument("--render", action="store_true",
                   help="only write tasks.md again from the tasks.json in --out")
    p.add_argument("--keep", action="store_true",
                   help="keep the rows of the environments not run from --out's tasks.json")
    p.add_argument("--trained", action="append", default=[],
                   metavar="NAME=RUN_DIR[@STEPS]",
                   help="a trained policy (agents.train's run directory, of one of --ids; "
                        "@STEPS: its checkpoint at STEPS steps), repeatable")
    p.add_argument("--policies", default="", metavar="NAME,MODULE:CLASS,...",
                   help="further policies, comma-separated, played in every environment of "
                        "--ids: a baseline's name or a policy of one's own, module:Class or "
                        "path/to/file.py:Class (?key=value&... for its arguments; "
                        "agents.policy)")
    raw = sys.argv[1:] if argv is None else argv
    args = p.parse_args(raw)
    if args.render:
        saved = json.loads((args.out / "tasks.json").read_text())
        (args.out / "tasks.md").write_text(_document(saved))
        print(f"wrote {args.out / 'tasks.md'}")
        return saved["rows"]
    for name in ("episodes", "seeds", "processes"):
        if getattr(args, name) < 1:
            p.error(f"--{name} must be >= 1")
    if args.grid < 2:
        p.error("--grid must be >= 2")
    trained = _trained_runs(p, args.trained, args.ids)
    own = _own_policies(p, args.policies, args.ids)
    old = None
    if args.keep:
        path = args.out / "tasks.json"
        if not path.exists():
            p.error(f"--keep: {path} does not exist")
        old = json.loads(path.read_text())
        for key in ("episodes", "grid", "seeds"):
            if old[key] != getattr(args, key):
                p.error(f"--keep: {path} has {key} {old[key]}, this run {getattr(args, key)}")
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    for name in args.ids:
        print(f"{name}: searching {args.grid} points per action dimension, then "
              f"{args.episodes} episodes per policy ...", flush=True)
        rows.append(analyse(f"iceenvs/{name}", episodes=args.episodes, grid=args.grid,
                            seeds=args.seeds, processes=args.processes, out=args.out,
                            reuse=args.reuse, progress=not args.no_progress,
                            trained=trained.get(name), extra=own))
        print(task_table(rows[-1:]), flush=True)
    import numba

    command = shlex.join(["python", "-m", "agents.tasks", *raw])
    if old is not None:
        done = {r["id"] for r in rows}
        rows = sorted([r for r in old["rows"] if r["id"] not in done] + rows,
                      key=lambda r: ENV_IDS.index(r["id"]) if r["id"] in ENV_IDS else len(ENV_IDS))
        command = f"{old['command']}` then `{command}"
    saved = dict(command=command,
                 machine=f"{platform.machine()}, {platform.system()}, numba {numba.__version__}",
                 date=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d"),
                 episodes=args.episodes, grid=args.grid, seeds=args.seeds, rows=rows)
    (args.out / "tasks.md").write_text(_document(saved))
    with open(args.out / "tasks.json", "w") as fh:
        json.dump(saved, fh, indent=1)
    print(f"wrote {args.out / 'tasks.md'}")
    return rows


def _trained_runs(parser, items, ids) -> dict:
    """``{environment name: {policy name: (run_dir, checkpoint)}}`` of the
    ``--trained`` arguments, each checked to be a run of one of ``ids``."""
    import yaml

    from .rollouts import trained_argument

    out: dict = {}
    for item in items:
        try:
            name, run_dir, steps = trained_argument(item)
        except ValueError as err:
            parser.error(str(err))
        env = yaml.safe_load((Path(run_dir) / "args.yaml").read_text())["env"].split("/")[-1]
        if env not in ids:
            parser.error(f"--trained {item}: the run is of {env}, which is not among --ids")
        out.setdefault(env, {})[name] = (run_dir, steps)
    return out


def _own_policies(parser, text: str, ids) -> list[str]:
    """The names of ``--policies``, each a baseline of every environment of
    ``ids`` or a reference whose class imports; a bad one exits with the
    reason."""
    from .baselines import check_policy_names
    from .policy import check_reference, is_reference, split_policies

    try:
        names = split_policies(text)
    except ValueError as err:
        parser.error(f"--policies: {err}")
    for name in names:
        if is_reference(name):
            try:
                check_reference(name)
            except ValueError as err:
                parser.error(f"--policies: {err}")
            continue
        for env in ids:
            try:
                check_policy_names([name], f"iceenvs/{env}")
            except ValueError as err:
                parser.error(f"--policies: {err}")
    return names


if __name__ == "__main__":
    main()
