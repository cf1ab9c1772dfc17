"""A short PPO training, compared with the baselines: ``python -m agents.demo``.

Trains PPO on ``iceenvs/Convergence-v0`` with the budget of
``agents/hyperparams/demo.yaml`` (40 000 steps, two environment
processes: about 140 s on two cores), then runs the policy and the
random, zero-action and hand-written baselines on the same 20 seeded
episodes with :mod:`agents.evaluate` in two processes (about 25 s), and
prints the returns, the paired
differences and one line per baseline saying whether the policy beats it
by more than two standard errors of the paired difference, and why not
where it does not.

    python -m agents.demo [--timesteps N] [--episodes N] [--seed S] [--out DIR]
    python -m agents.demo --seeds 0 1 2 --record docs/agents/demo

With ``--seeds`` it trains and evaluates one seed after the other (run
directories ``OUT/seed_S``) and prints one row per seed; ``--record DIR``
writes that comparison to ``DIR/seeds.json`` and ``DIR/seeds.md``.
"""
from __future__ import annotations

import argparse
import contextlib
import datetime
import io
import json
import os
import platform
import shlex
import sys
import time
from pathlib import Path

import yaml

from .evaluate import main as evaluate_main
from .rollouts import verdict
from .train import HYPERPARAMS_DIR, main as train_main

__all__ = ["CONFIG_FILE", "BASELINES", "LABELS", "load_config", "overrides", "run_seed",
           "returns_table", "summary_row",
           "verdicts", "seeds_markdown", "main"]

CONFIG_FILE = HYPERPARAMS_DIR / "demo.yaml"
#: the baselines of the comparison, in the order of the table
BASELINES = ("random", "zero", "heuristic")
POLICY = "ppo policy"
#: the baselines as the verdicts name them
LABELS = {"random": "random actions", "zero": "the zero action",
          "heuristic": "the hand-written controller"}


def load_config(path: str | Path = CONFIG_FILE) -> dict:
    """The demo's environment, algorithm, budget and hyperparameters."""
    with open(path) as fh:
        return yaml.safe_load(fh)


def overrides(config: dict) -> list[str]:
    """The demo's hyperparameters as ``key=value`` arguments of
    ``agents.train --hyperparams`` (values in JSON, which YAML reads)."""
    return [f"{key}={json.dumps(value)}" for key, value in config["hyperparams"].items()]


def run_seed(config: dict, seed: int, timesteps: int, episodes: int, out: Path,
             progress: bool = True) -> dict:
    """Train one seed and evaluate it; returns the evaluation report of
    :mod:`agents.evaluate` (``evaluation.json``) with the run directory,
    the training command and the wall times added."""
    quiet = [] if progress else ["--no-progress"]
    train_args = ["--env", config["env"], "--algo", config["algo"], "--timesteps", str(timesteps),
                  "--seed", str(seed), "--out", str(out), "--force", "--eval-freq", "0",
                  "--save-freq", "0", "--hyperparams", *overrides(config)]
    t0 = time.perf_counter()
    run_dir = train_main(train_args + quiet)
    t1 = time.perf_counter()
    print(f"trained in {round(t1 - t0, 1):.0f} s; evaluating on {episodes} seeded episodes ...",
          flush=True)
    # the full table (every final physics metric) goes to evaluation.md; the
    # demo prints the returns only
    with contextlib.redirect_stdout(io.StringIO()):
        evaluate_main([str(run_dir), "--episodes", str(episodes), "--baselines",
                       ",".join(BASELINES), "--processes", str(config.get("eval_processes", 1)),
                       *quiet])
    t2 = time.perf_counter()
    report = json.loads((Path(run_dir) / "evaluation.json").read_text())
    report.pop("episodes_detail", None)
    report.update(run_dir=str(run_dir), training_seed=seed, timesteps=timesteps,
                  train_command=shlex.join(["python", "-m", "agents.train", *train_args]),
                  train_seconds=round(t1 - t0, 1), evaluate_seconds=round(t2 - t1, 1))
    return report


def _thousands(n: int) -> str:
    return f"{n:,}".replace(",", " ")


def _pm(stats: dict) -> str:
    return f"{stats['mean']:.1f} ± {stats['sem']:.1f}"


def _diff(c: dict) -> str:
    return f"{c['diff']:+.1f} [{c['sem']:.2g}]"


def returns_table(report: dict) -> str:
    """The returns of one evaluation and the paired differences, as Markdown."""
    s, c = report["summaries"], report["comparisons"]
    lines = ["| policy | return (mean ± standard error) | PPO − policy, paired by seed "
             "[standard error] | PPO (by > 2 standard errors) |",
             "|---|---|---|---|",
             f"| PPO | {_pm(s[POLICY]['return'])} | | |"]
    for name in BASELINES:
        lines.append(f"| {name} | {_pm(s[name]['return'])} | {_diff(c[name])} | "
                     f"{verdict(c[name])} |")
    return "\n".join(lines)


def verdicts(report: dict, notes: dict | None = None) -> list[str]:
    """One sentence per baseline: beaten by more than two standard errors
    of the paired difference, or not; ``notes`` (baseline → text, the
    ``notes`` of the configuration, where ``{timesteps}`` and ``{episodes}``
    stand for the training budget) says why when a baseline scores more."""
    notes = notes or {}
    c = report["comparisons"]
    steps = report["timesteps"]
    length = report["summaries"][POLICY]["length"]["mean"]
    fill = dict(timesteps=_thousands(steps), episodes=_thousands(round(steps / length)))
    out = []
    for name in BASELINES:
        d, label = c[name], LABELS.get(name, name)
        if d["beats"]:
            z = d["diff"] / d["sem"] if d["sem"] > 0 else float("inf")
            out.append(f"PPO beats {label} by {d['diff']:+.1f} per episode ({z:.1f} standard "
                       f"errors of the paired difference).")
        elif d["diff"] < 0 and name in notes:
            out.append(f"PPO does not beat {label}: it scores {-d['diff']:.1f} less per episode "
                       f"(standard error {d['sem']:.2g}). " + notes[name].strip().format(**fill))
        else:
            out.append(f"PPO does not beat {label} by more than two standard errors: "
                       f"{d['diff']:+.1f} per episode (standard error {d['sem']:.2g}).")
    return out


def summary_row(report: dict) -> str:
    """One Markdown row of the per-seed table."""
    s, c = report["summaries"], report["comparisons"]
    cells = [str(report["training_seed"]), _pm(s[POLICY]["return"])]
    cells += [_pm(s[name]["return"]) for name in BASELINES]
    cells += [_diff(c[name]) + (" ✓" if c[name]["beats"] else " ✗") for name in BASELINES]
    cells += [f"{report['train_seconds']:.0f}", f"{report['evaluate_seconds']:.0f}"]
    return "| " + " | ".join(cells) + " |"


def seeds_markdown(reports: list[dict], command: str, meta: dict) -> str:
    """The per-seed comparison as a Markdown page."""
    first = reports[0]
    head = ["training seed", "PPO", *BASELINES, *(f"PPO − {n} [SE]" for n in BASELINES),
            "training [s]", "evaluation [s]"]
    lines = [f"PPO on `{first['env']}`, {_thousands(first['timesteps'])} training steps per "
             f"seed with the hyperparameters of `agents/hyperparams/demo.yaml`; every seed's "
             f"policy and the baselines on the same {first['episodes']} episodes (episode k seeded "
             f"{first['seed']} + k). Returns: mean ± standard error; differences: mean of the "
             f"paired differences [standard error]; ✓: PPO better by more than two standard "
             f"errors.", "",
             f"`{command}` ({meta['machine']}, {meta['date']}; load average "
             f"{meta['load_before']} before, {meta['load_after']} after)", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += [summary_row(r) for r in reports]
    return "\n".join(lines) + "\n"


def build_parser(prog: str, config: dict) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n")[0],
                                epilog=f"environment {config['env']}, algorithm {config['algo']}; "
                                       f"budget and hyperparameters: agents/hyperparams/"
                                       f"{CONFIG_FILE.name}")
    p.add_argument("--timesteps", type=int, default=config["timesteps"],
                   help=f"training steps per seed (default {config['timesteps']})")
    p.add_argument("--episodes", type=int, default=config["episodes"],
                   help=f"evaluation episodes per policy (default {config['episodes']})")
    seeds = p.add_mutually_exclusive_group()
    seeds.add_argument("--seed", type=int, default=None, help="training seed (default 0)")
    seeds.add_argument("--seeds", type=int, nargs="+", metavar="S",
                       help="several training seeds, one after the other")
    p.add_argument("--out", type=Path, default=Path("runs/demo/agents"),
                   help="run directory, overwritten; with --seeds the parent of one "
                        "directory per seed (default runs/demo/agents)")
    p.add_argument("--record", type=Path, default=None, metavar="DIR",
                   help="write the per-seed comparison to DIR/seeds.json and DIR/seeds.md")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bars")
    return p


def main(argv: list[str] | None = None, prog: str = "python -m agents.demo"):
    """Train, evaluate and print; returns the evaluation summaries of the
    (last) seed."""
    config = load_config()
    argv = list(sys.argv[1:] if argv is None else argv)
    p = build_parser(prog, config)
    args = p.parse_args(argv)
    if args.timesteps < 1 or args.episodes < 2:
        p.error(f"--timesteps must be at least 1 and --episodes at least 2 (a standard error "
                f"needs two), got {args.timesteps} and {args.episodes}")
    if args.seeds is not None and len(set(args.seeds)) != len(args.seeds):
        p.error(f"--seeds must differ, got {args.seeds}")
    seeds = args.seeds if args.seeds is not None else [args.seed or 0]
    progress = not args.no_progress
    load_before = " ".join(f"{x:.1f}" for x in os.getloadavg())

    reports = []
    t_start = time.perf_counter()
    for seed in seeds:
        out = args.out if args.seeds is None else args.out / f"seed_{seed}"
        print(f"Training PPO on {config['env']} for {_thousands(args.timesteps)} steps "
              f"(seed {seed}, {config['hyperparams'].get('n_envs', 1)} environment processes) ...",
              flush=True)
        report = run_seed(config, seed, args.timesteps, args.episodes, out, progress)
        reports.append(report)
        steps = report["summaries"]["zero"]["length"]["mean"]
        print(f"\n{config['env']}: {args.episodes} episodes per policy (episode k seeded "
              f"{report['seed']} + k); a return is the sum of {steps:.0f} rewards in [0, 1]\n")
        print(returns_table(report) + "\n")
        for line in verdicts(report, config.get("notes")):
            print(line)
        print(f"\ntrained in {report['train_seconds']:.0f} s, evaluated in "
              f"{report['evaluate_seconds']:.0f} s; full table, episodes and plot in "
              f"{report['run_dir']}/evaluation.{{md,json,png}}\n", flush=True)
    if len(reports) > 1 or args.record is not None:
        meta = dict(machine=f"{platform.machine()}, {os.cpu_count()} cores",
                    date=datetime.date.today().isoformat(), load_before=load_before,
                    load_after=" ".join(f"{x:.1f}" for x in os.getloadavg()),
                    total_seconds=round(time.perf_counter() - t_start, 1))
        command = shlex.join(["python", "-m", "agents.demo", *argv])
        page = seeds_markdown(reports, command, meta)
        print(page)
        if args.record is not None:
            args.record.mkdir(parents=True, exist_ok=True)
            (args.record / "seeds.md").write_text(page)
            with open(args.record / "seeds.json", "w") as fh:
                json.dump(dict(command=command, config=config, **meta, runs=reports), fh,
                          indent=1)
            print(f"record: {args.record / 'seeds.md'}, {args.record / 'seeds.json'}")
    return reports[-1]["summaries"]


if __name__ == "__main__":
    main()
