"""What an imitation error of a given size is: the spread of a waypoint
teacher's decisions, and the error that normal noise of σ on them makes,
as a share of that spread.

A waypoint student (:mod:`agents.waypoints`) is scored by its squared
error against its teacher's decisions, as a share of the decisions'
variance (both clipped to [−1, 1]). A teacher that errs on purpose,
:class:`agents.waypoints.LatticeWaypoints` with ``noise`` σ, sails what an
imitation error of that kind costs in return (on the leaderboard, paired
with the teacher). This module gives the other axis: on the teacher's own
episodes, field by field as the leaderboard seeds them, the variance of
its decisions and, for each σ, the mean of (clip(w + e) − clip(w))² with e
drawn normal of σ (from a generator seeded by ``seed``), as a share of
that variance: the σ at which the noisy teacher errs as much as a student
does. Run::

    python -m agents.imitation_error --teacher costmap-lattice \\
        --env-kwargs costmap_ahead=500 --concentrations 0.2,0.3,0.4 \\
        --episodes 20 --seed 40000 --noise 0.03,0.06,0.12,0.24 --out DIR

It writes ``DIR/imitation-error.json`` (settings, and by concentration the
decisions, their variance and each σ's share) and ``DIR/imitation-error.md``
(the table). ``plot`` draws what the noisy teachers of a leaderboard run
lost to their teacher against σ, from the episodes that run wrote::

    python -m agents.imitation_error plot --board BOARD \\
        --reference costmap-lattice-500 --noisy noise-1=0.01,noise-3=0.03 \\
        --out FIGURE.png
"""
from __future__ import annotations

import argparse
import json
import shlex
import sys
import time
from pathlib import Path

import numpy as np

__all__ = ["error_share", "decision_spread", "spread_markdown", "losses", "plot_losses",
           "main", "RECORD"]

#: the record and its table, in the output directory
RECORD, TABLE = "imitation-error.json", "imitation-error.md"


def error_share(labels: np.ndarray, sigma: float, rng: np.random.Generator) -> float:
    """The squared error of the decisions ``labels`` (unclipped w, one row a
    decision) with normal errors of ``sigma`` added, both clipped to
    [−1, 1], as a share of the clipped decisions' variance (over all
    entries, as a student's fit is scored)."""
    w = np.asarray(labels, dtype=float)
    if w.ndim != 2 or len(w) < 2:
        raise ValueError(f"labels must be two or more decisions, one a row, got shape {w.shape}")
    if isinstance(sigma, bool) or not (np.isfinite(sigma) and sigma >= 0.0):
        raise ValueError(f"sigma must be a standard deviation >= 0, got {sigma!r}")
    clipped = np.clip(w, -1.0, 1.0)
    variance = float(np.var(clipped))
    if variance == 0.0:
        raise ValueError("the decisions do not vary: an error has no share of their variance")
    noisy = np.clip(w + rng.normal(0.0, sigma, w.shape), -1.0, 1.0)
    return float(np.mean((noisy - clipped) ** 2)) / variance


def decision_spread(env_id: str, env_kwargs: dict, concentrations, episodes: int, seed: int,
                    noises, teacher: str = "costmap-lattice", progress: bool = True) -> dict:
    """Sail the waypoint teacher ``teacher`` alone on ``episodes`` fields at
    each concentration (field k seeded ``seed`` + k, as the leaderboard
    seeds them) and return, by concentration, its decisions' count and
    variance (clipped) and each σ of ``noises``' :func:`error_share`
    (the errors drawn from a generator seeded ``seed``, one per
    concentration)."""
    from .waypoints import sail

    noises = [float(s) for s in noises]
    if not noises:
        raise ValueError("give at least one noise level")
    out = {}
    for c in concentrations:
        _, labels, _, returns, _ = sail(env_id, {**env_kwargs, "concentration": float(c)}, None,
                                        1.0, episodes, seed, f"A = {c:g}", progress,
                                        "waypoints", 2, teacher)
        labels = np.asarray(labels, dtype=float)
        rng = np.random.default_rng(seed)
        out[f"{float(c):g}"] = {
            "decisions": int(len(labels)),
            "variance": float(np.var(np.clip(labels, -1.0, 1.0))),
            "mean_return": float(np.mean(returns)),
            "share": {f"{s:g}": error_share(labels, s, rng) for s in noises}}
    return out


def _share_text(share: float) -> str:
    return f"{share:.2g}"


def spread_markdown(record: dict) -> str:
    """The record's table: for each σ, its error's share of the decisions'
    variance at each concentration."""
    by_c = record["spread"]
    cs = list(by_c)
    noises = list(next(iter(by_c.values()))["share"])
    lines = ["| | " + " | ".join(f"A = {c}" for c in cs) + " |",
             "|---|" + "---|" * len(cs),
             "| decisions | " + " | ".join(str(by_c[c]["decisions"]) for c in cs) + " |",
             "| their variance (clipped to [−1, 1]) | "
             + " | ".join(f"{by_c[c]['variance']:.3f}" for c in cs) + " |"]
    for s in noises:
        lines.append(f"| σ = {s}: error's share of the variance | "
                     + " | ".join(_share_text(by_c[c]["share"][s]) for c in cs) + " |")
    s = record["settings"]
    lines += ["", f"The teacher ({s['teacher']}) alone on {s['episodes']} "
              f"field{'s' if s['episodes'] != 1 else ''} a concentration, field k seeded "
              f"{s['seed']} + k"
              + (f", made with {', '.join(f'{k}={v}' for k, v in s['env_kwargs'].items())}"
                 if s["env_kwargs"] else "")
              + f"; {record['seconds']:.0f} s.", ""]
    return "\n".join(lines)


def losses(board: dict, reference: str, noisy: dict) -> dict:
    """From a leaderboard's episodes ``board`` (by concentration, by policy:
    the episodes of :func:`agents.leaderboard.read_board`): for each policy
    of ``noisy`` (name: σ) the paired return minus ``reference``'s at each
    concentration, as :func:`agents.rollouts.compare` gives it."""
    from .rollouts import compare

    out = {}
    for a, policies in board.items():
        missing = [n for n in (reference, *noisy) if n not in policies]
        if missing:
            raise ValueError(f"not on the board at A = {a}: {', '.join(missing)} "
                             f"(policies: {', '.join(policies)})")
        out[a] = {name: compare(policies[name], policies[reference]) for name in noisy}
    return out


def plot_losses(lost: dict, noisy: dict, reference: str, path: Path) -> None:
    """Return − ``reference``'s (mean ± standard error over the fields)
    against σ, one line a concentration."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    order = sorted(noisy, key=noisy.get)
    sigma = np.array([noisy[n] for n in order])
    fig, ax = plt.subplots(figsize=(6.0, 4.0))
    for a, by in lost.items():
        ax.errorbar(sigma, [by[n]["diff"] for n in order], yerr=[by[n]["sem"] for n in order],
                    marker="o", capsize=3, label=f"A = {a}")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlabel("σ of the errors on each waypoint decision w")
    ax.set_ylabel(f"return − {reference}'s (paired)")
    ax.set_title("What an imitation error costs the teacher's episodes")
    ax.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _plot_main(argv) -> int:
    from .leaderboard import RECORD as BOARD_RECORD, read_board

    p = argparse.ArgumentParser(prog="python -m agents.imitation_error plot",
                                description=plot_losses.__doc__.split("\n\n")[0])
    p.add_argument("--board", type=Path, required=True,
                   help="a leaderboard's output directory, with the episodes.json its run wrote")
    p.add_argument("--reference", required=True, help="the teacher's name on the board")
    p.add_argument("--noisy", required=True, metavar="NAME=SIGMA,...",
                   help="the noisy teachers' names on the board and their σ")
    p.add_argument("--out", type=Path, required=True, help="the figure (.png)")
    args = p.parse_args(argv)
    try:
        noisy = {}
        for item in args.noisy.split(","):
            name, sep, value = item.partition("=")
            if not sep or not name:
                raise ValueError(f"--noisy takes NAME=SIGMA items, got {item!r}")
            noisy[name] = float(value)
        board = read_board(args.board)[1] if (args.board / BOARD_RECORD).is_file() else None
        if board is None:
            raise ValueError(f"{args.board} holds no episodes.json: run the leaderboard's "
                             f"command there first")
        lost = losses(board, args.reference, noisy)
    except ValueError as exc:
        p.error(str(exc))
    plot_losses(lost, noisy, args.reference, args.out)
    print(f"wrote {args.out}")
    return 0


def main(argv=None) -> int:
    from .envs import parse_key_values
    from .leaderboard import DEFAULT_ENV
    from .waypoints import TEACHERS

    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] == ["plot"]:
        return _plot_main(argv[1:])
    p = argparse.ArgumentParser(prog="python -m agents.imitation_error",
                                description=__doc__.split("\n\n")[0])
    p.add_argument("--env", default=DEFAULT_ENV)
    p.add_argument("--env-kwargs", nargs="*", default=[], metavar="KEY=VALUE",
                   help="gymnasium.make keywords of the fields (YAML values)")
    p.add_argument("--teacher", choices=TEACHERS, default="costmap-lattice")
    p.add_argument("--concentrations", default="0.2,0.3,0.4")
    p.add_argument("--episodes", type=int, default=20)
    p.add_argument("--seed", type=int, default=40_000)
    p.add_argument("--noise", default="0.03,0.06,0.12,0.24",
                   help="the standard deviations σ, comma-separated")
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--no-progress", action="store_true")
    args = p.parse_args(argv)
    try:
        concentrations = [float(c) for c in args.concentrations.split(",")]
        noises = [float(s) for s in args.noise.split(",")]
    except ValueError as exc:
        p.error(f"--concentrations and --noise are comma-separated numbers: {exc}")
    if args.episodes < 1:
        p.error(f"--episodes must be at least 1, got {args.episodes}")
    if any(not (np.isfinite(s) and s >= 0.0) for s in noises):
        p.error(f"--noise levels are standard deviations >= 0, got {args.noise}")
    try:
        env_kwargs = parse_key_values(args.env_kwargs)
        began = time.perf_counter()
        spread = decision_spread(args.env, env_kwargs, concentrations, args.episodes,
                                 args.seed, noises, args.teacher,
                                 progress=not args.no_progress)
    except ValueError as exc:
        p.error(str(exc))
    record = {"settings": {"env_id": args.env, "env_kwargs": env_kwargs,
                           "teacher": args.teacher, "episodes": args.episodes,
                           "seed": args.seed, "noise": noises},
              "spread": spread, "seconds": round(time.perf_counter() - began, 1),
              "command": shlex.join(["python", "-m", "agents.imitation_error", *argv])}
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / RECORD).write_text(json.dumps(record, indent=2) + "\n")
    table = spread_markdown(record)
    (args.out / TABLE).write_text(table)
    print(table)
    return 0


if __name__ == "__main__":
    sys.exit(main())
