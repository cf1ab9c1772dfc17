"""Learning curve of a training run: ``python -m agents.curves RUN_DIR``.

Reads SB3's ``logs/progress.csv`` of a run directory of
:mod:`agents.train` and draws the mean training-episode return
(``rollout/ep_rew_mean``, stochastic actions) and the evaluation-callback
return (``eval/mean_reward``, deterministic actions) against environment
steps, with the elapsed wall time on a second axis. When the run has been
evaluated (``evaluation.json`` of :mod:`agents.evaluate`), the baselines'
mean returns are drawn as horizontal lines. Output: ``learning_curve.png``
in the run directory (or ``--out``).

With several run directories (``python -m agents.curves RUN1 RUN2 RUN3
--out PNG``: the training seeds of one recipe) it draws every seed's
training curve on one figure, and beside it the mean return of each DAgger
round of their warm starts, where they had some.
"""
from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

__all__ = ["read_progress", "plot_learning_curve", "dagger_rounds", "plot_seeds", "main"]


def read_progress(run_dir: str | Path) -> dict[str, list[tuple[float, float]]]:
    """``{"train": [(steps, return)], "eval": [...], "time": [(steps, s)]}``
    from the run's ``logs/progress.csv`` (rows without a value skipped)."""
    path = Path(run_dir) / "logs" / "progress.csv"
    if not path.is_file():
        raise FileNotFoundError(f"{path} does not exist: is {run_dir} a run directory of "
                                "agents.train?")
    columns = {"train": "rollout/ep_rew_mean", "eval": "eval/mean_reward",
               "time": "time/time_elapsed"}
    out = {key: [] for key in columns}
    with open(path, newline="") as fh:
        for row in csv.DictReader(fh):
            steps = row.get("time/total_timesteps", "")
            for key, column in columns.items():
                if steps and row.get(column, ""):
                    out[key].append((float(steps), float(row[column])))
    if not out["train"] and not out["eval"]:
        raise ValueError(f"{path} holds no returns yet")
    return out


def plot_learning_curve(run_dir: str | Path, path: str | Path | None = None) -> Path:
    """Draw the learning curve of ``run_dir`` to ``path`` (default
    ``RUN_DIR/learning_curve.png``); returns the path."""
    from physics.scenarios import plots

    plt = plots.pyplot()
    run_dir = Path(run_dir)
    path = Path(path) if path is not None else run_dir / "learning_curve.png"
    progress = read_progress(run_dir)
    fig, ax = plt.subplots(figsize=(7, 4.2))
    if progress["train"]:
        x, y = zip(*progress["train"])
        ax.plot(x, y, lw=1.2, label="training episodes (stochastic)")
    if progress["eval"]:
        x, y = zip(*progress["eval"])
        ax.plot(x, y, "o-", ms=3, lw=1.2, label="evaluation callback (deterministic)")
    evaluation = run_dir / "evaluation.json"
    if evaluation.is_file():
        summaries = json.loads(evaluation.read_text())["summaries"]
        styles = iter([(":", "0.3"), ("--", "0.3"), ("-.", "0.3"), (":", "C3"), ("--", "C2"),
                       ("-.", "C4")])
        for name, summary in summaries.items():
            if name.endswith("policy"):
                continue
            ls, colour = next(styles, ("-", "0.5"))
            ax.axhline(summary["return"]["mean"], color=colour, lw=1, ls=ls,
                       label=f"{name} (mean of the evaluation)")
    ax.set_xlabel("environment steps")
    ax.set_ylabel("episode return")
    if progress["time"]:
        steps, seconds = zip(*progress["time"])
        rate = steps[-1] / max(seconds[-1], 1e-9)
        top = ax.secondary_xaxis("top", functions=(lambda s: s / rate / 60.0,
                                                   lambda m: m * 60.0 * rate))
        top.set_xlabel("wall time [min]")
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(alpha=0.3)
    path.parent.mkdir(parents=True, exist_ok=True)
    return plots.savefig(fig, path, dpi=110, palette=True)


def dagger_rounds(run_dir: str | Path) -> list[tuple[int, float, float]]:
    """``[(round, beta, mean return)]`` of the DAgger rounds of a run's warm
    start (``pretrain.yaml``; :mod:`agents.dagger`), empty without them."""
    import yaml

    path = Path(run_dir) / "pretrain.yaml"
    if not path.is_file():
        return []
    report = yaml.safe_load(path.read_text()) or {}
    return [(r["round"], r["beta"], r["mean_return"]) for r in report.get("dagger") or []]


def plot_seeds(run_dirs, path: str | Path) -> Path:
    """The learning curves of several runs of one recipe (its training
    seeds) on one figure, each seed's training-episode return against the
    steps and, where the runs began with DAgger rounds, beside it the mean
    return of each round's episodes (the student driving with probability
    1 − β); returns the path."""
    from physics.scenarios import plots

    plt = plots.pyplot()
    runs = [Path(r) for r in run_dirs]
    rounds = {r: dagger_rounds(r) for r in runs}
    panels = 2 if any(rounds.values()) else 1
    fig, axes = plt.subplots(1, panels, figsize=(6.0 * panels, 4.0), squeeze=False)
    ax = axes[0, -1]
    for k, run in enumerate(runs):
        progress = read_progress(run)
        if progress["train"]:
            x, y = zip(*progress["train"])
            ax.plot(x, y, lw=1.2, color=f"C{k}", label=run.name)
    ax.set(xlabel="environment steps (PPO)", ylabel="training-episode return (stochastic)",
           title="PPO")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    if panels == 2:
        ax0 = axes[0, 0]
        for k, run in enumerate(runs):
            if rounds[run]:
                r, _, ret = zip(*rounds[run])
                ax0.plot(r, ret, "o-", color=f"C{k}", lw=1.2, label=run.name)
        ax0.set_xticks(sorted({r for run in runs for r, _, _ in rounds[run]}))
        ax0.set(xlabel="DAgger round r (the teacher plays with probability β^r)",
                ylabel="mean return of the round's episodes (its own fields)",
                title="DAgger")
        ax0.grid(alpha=0.3)
        ax0.legend(fontsize=8)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return plots.savefig(fig, path, dpi=110, palette=True)


def main(argv: list[str] | None = None) -> Path:
    p = argparse.ArgumentParser(prog="python -m agents.curves",
                                description="Plot the learning curve of a training run, or "
                                            "those of several seeds of one recipe.")
    p.add_argument("run_dir", type=Path, nargs="+",
                   help="run directory of agents.train; several: one figure of their seeds")
    p.add_argument("--out", type=Path, default=None,
                   help="output PNG (default RUN_DIR/learning_curve.png; needed for several)")
    args = p.parse_args(sys.argv[1:] if argv is None else argv)
    if len(args.run_dir) > 1 and args.out is None:
        p.error("several run directories need --out")
    try:
        if len(args.run_dir) > 1:
            path = plot_seeds(args.run_dir, args.out)
        else:
            path = plot_learning_curve(args.run_dir[0], args.out)
    except (FileNotFoundError, ValueError) as err:
        p.error(str(err))
    print(f"wrote {path}")
    return path


if __name__ == "__main__":
    main()
