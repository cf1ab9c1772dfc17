"""Learning curve of a training run: ``python -m agents.curves RUN_DIR``.

Reads SB3's ``logs/progress.csv`` of a run directory of
:mod:`agents.train` and draws the mean training-episode return
(``rollout/ep_rew_mean``, stochastic actions) and the evaluation-callback
return (``eval/mean_reward``, deterministic actions) against environment
steps, with the elapsed wall time on a second axis. When the run has been
evaluated (``evaluation.json`` of :mod:`agents.evaluate`), the baselines'
mean returns are drawn as horizontal lines. Output: ``learning_curve.png``
in the run directory (or ``--out``).
"""
from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

__all__ = ["read_progress", "plot_learning_curve", "main"]


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


def main(argv: list[str] | None = None) -> Path:
    p = argparse.ArgumentParser(prog="python -m agents.curves",
                                description="Plot the learning curve of a training run.")
    p.add_argument("run_dir", type=Path, help="run directory of agents.train")
    p.add_argument("--out", type=Path, default=None,
                   help="output PNG (default RUN_DIR/learning_curve.png)")
    args = p.parse_args(sys.argv[1:] if argv is None else argv)
    try:
        path = plot_learning_curve(args.run_dir, args.out)
    except (FileNotFoundError, ValueError) as err:
        p.error(str(err))
    print(f"wrote {path}")
    return path


if __name__ == "__main__":
    main()
