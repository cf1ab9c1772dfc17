"""How much return any policy could gain on Convergence-v0: a ceiling from the rate limit.

Usage::

    python -m agents.ceiling [--episodes 20] [--seed 50000] [--processes 1]
        [--out docs/agents/diagnostics/Convergence-v0-ceiling] [--no-progress]

The concentration of Convergence-v0 changes only at the rate the agent
sets, within ``max_rate`` (the box is remapped affinely, A(t) = A₀ + rate·t),
so after t steps it lies within t · δ of its start A₀, with δ = ``max_rate``
times the seconds the engine advances a step / 3600 (about 1/900: a step
is ``control_interval``, 2 s, rounded to whole time steps).
The reward of a step is the closeness of A to the target A*, times a
pressure safety factor of at most 1, so no policy earns more at step t than

    c_t = max(0, 1 − max(0, |A₀ − A*| − t · δ) / s),    s = ``concentration_scale``,

and no policy's return exceeds Σ c_t (:func:`rate_limited_ceiling`). The
bound ignores the pressure; it is a theorem of the task's definition, not a
policy. Where the hand-written controller's return comes close to it,
there is little left for any learner to gain.

The command plays the controller and the reference agent
(``docs/agents/reference/Convergence-v0``) on tuning episodes (seeded
50000 + k, never the benchmark's) and splits each one's shortfall from the
ceiling into the approach (steps where c_t < 1: the rate limit binds) and
the hold (c_t = 1: only the policy's accuracy and the pressure cost
reward). Writes ``ceiling.json`` (summaries and the mean reward per step),
``ceiling.md`` and ``ceiling.png``.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from .diagnostics import DIAGNOSTICS_DIR, add_episode_arguments, check_episodes, stamped

__all__ = ["rate_limited_ceiling", "step_change", "analyse", "markdown", "plot", "main"]

ENV_ID = "iceenvs/Convergence-v0"
DEFAULT_OUT = DIAGNOSTICS_DIR / "Convergence-v0-ceiling"
AGENT = "agent"


def rate_limited_ceiling(start: float, target: float, *, steps: int, step_change: float,
                         scale: float) -> np.ndarray:
    """The most reward any policy can earn at each of ``steps`` steps (index
    t − 1 for step t) when the concentration starts at ``start``, moves by at
    most ``step_change`` a step and earns ``1 − |A − target| / scale``
    (clipped to [0, 1]) times a factor of at most 1."""
    if steps < 0 or step_change < 0 or scale <= 0:
        raise ValueError(f"steps ({steps}) and step_change ({step_change}) must be >= 0 and "
                         f"scale ({scale}) > 0")
    t = np.arange(1, steps + 1)
    gap = np.maximum(0.0, abs(start - target) - t * step_change)
    return np.clip(1.0 - gap / scale, 0.0, 1.0)


def step_change(env) -> float:
    """The most the concentration of a reset Convergence-v0 can move in one
    step: ``max_rate`` times the time the engine advances a step (whole
    time steps: ``control_interval`` rounded to a multiple of ``dt``)."""
    u = env.unwrapped
    seconds = round(u.control_interval / u.sim.dt) * u.sim.dt
    return float(u.episode["max_rate"]) * seconds / 3600.0


def _episode_ceilings(seeds) -> tuple[dict, list[np.ndarray]]:
    """The default Convergence-v0's steps and reward scale, and the ceiling
    per step of each episode (reset with each seed)."""
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the ids)

    env = gym.make(ENV_ID)
    try:
        const = dict(steps=int(env.spec.max_episode_steps),
                     scale=float(env.unwrapped.reward_params["concentration_scale"]))
        ceilings, changes = [], []
        for seed in seeds:
            env.reset(seed=seed)
            ep = env.unwrapped.episode
            changes.append(step_change(env))
            ceilings.append(rate_limited_ceiling(ep["concentration"], ep["target"],
                                                 step_change=changes[-1], **const))
        const["step_change"] = max(changes)
        return const, ceilings
    finally:
        env.close()


def _mean_sem(values) -> dict:
    from .rollouts import stats

    s = stats(np.asarray(values, dtype=float))
    return dict(mean=s["mean"], sem=s["sem"], n=s["n"])


def analyse(*, episodes: int = 20, seed: int = 50000, processes: int = 1,
            progress: bool = True, root: Path | None = None) -> dict:
    """The ceiling, the controller and the reference agent (when one is
    kept under ``root``) on episodes seeded ``seed`` + k."""
    from .benchmark import play
    from .reference import reference_dir

    check_episodes(episodes, seed)
    const, ceilings = _episode_ceilings(range(seed, seed + episodes))
    recipes = {"heuristic": ("baseline", "heuristic", {})}
    agent_dir = reference_dir(ENV_ID, root)
    if (agent_dir / "model.zip").is_file():
        recipes[AGENT] = ("trained", str(agent_dir), {})
    runs = play(ENV_ID, recipes, episodes=episodes, seed=seed, processes=processes,
                progress=progress)
    ceilings = np.array(ceilings)
    approach = ceilings < 1.0
    rows = {"ceiling": dict(returns=[float(c) for c in ceilings.sum(axis=1)],
                            per_step=ceilings.mean(axis=0))}
    for name, eps in runs.items():
        rewards = np.zeros((episodes, const["steps"]))
        for k, e in enumerate(eps):
            rewards[k, :len(e["rewards"])] = e["rewards"]   # a broken episode earns 0 after
        short = ceilings - rewards
        rows[name] = dict(returns=[float(r) for r in rewards.sum(axis=1)],
                          per_step=rewards.mean(axis=0),
                          approach=[float(s) for s in (short * approach).sum(axis=1)],
                          hold=[float(s) for s in (short * ~approach).sum(axis=1)])
    summary = {}
    for name, row in rows.items():
        summary[name] = dict(ret=_mean_sem(row["returns"]))
        if name != "ceiling":
            summary[name]["below_ceiling"] = _mean_sem(
                np.subtract(rows["ceiling"]["returns"], row["returns"]))
            summary[name]["approach"] = _mean_sem(row["approach"])
            summary[name]["hold"] = _mean_sem(row["hold"])
    if AGENT in rows:
        summary[AGENT]["minus_heuristic"] = _mean_sem(
            np.subtract(rows[AGENT]["returns"], rows["heuristic"]["returns"]))
    return dict(env=ENV_ID, episodes=episodes, seed=seed, constants=const,
                targets=[e["task"]["target"] for e in runs["heuristic"]],
                starts=[e["task"]["concentration"] for e in runs["heuristic"]],
                summary=summary,
                returns={n: [round(v, 4) for v in r["returns"]] for n, r in rows.items()},
                per_step={n: [round(float(v), 5) for v in r["per_step"]]
                          for n, r in rows.items()})


def _pm(s: dict) -> str:
    from .metrics import format_pm

    return format_pm(s["mean"], s["sem"])


def markdown(record: dict) -> str:
    """``ceiling.md``: the returns, the shortfall from the ceiling and where
    it is lost."""
    c = record["constants"]
    s = record["summary"]
    lines = [f"`{record['command']}` (commit `{record['commit']}`, {record['date']}). "
             f"{record['episodes']} episodes seeded {record['seed']} + k; the concentration "
             f"moves at most {c['step_change']:.4g} a step over {c['steps']} steps, and the "
             f"reward falls to 0 at {c['scale']:g} from the target. Mean ± standard error over "
             f"the episodes; the shortfalls are paired by episode.", "",
             "| policy | return | below the ceiling | lost in the approach | lost in the hold |",
             "|---|---|---|---|---|",
             f"| ceiling (no policy passes it) | {_pm(s['ceiling']['ret'])} | 0 | 0 | 0 |"]
    for name in ("heuristic", AGENT):
        if name in s:
            lines.append(f"| {'reference agent' if name == AGENT else 'controller'} | "
                         f"{_pm(s[name]['ret'])} | {_pm(s[name]['below_ceiling'])} | "
                         f"{_pm(s[name]['approach'])} | {_pm(s[name]['hold'])} |")
    if AGENT in s:
        lines += ["", f"The reference agent minus the controller: "
                      f"{_pm(s[AGENT]['minus_heuristic'])}."]
    return "\n".join(lines) + "\n"


def plot(record: dict, path: Path) -> None:
    """``ceiling.png``: the policies' mean shortfall from the ceiling per
    step (left), and each episode's shortfall against its target (right)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = {"ceiling": "ceiling", "heuristic": "controller", AGENT: "reference agent"}
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 3.8))
    top = np.array(record["per_step"]["ceiling"])
    steps = np.arange(1, len(top) + 1)
    for name in ("heuristic", AGENT):
        if name in record["per_step"]:
            ax.plot(steps, top - np.array(record["per_step"][name]), label=labels[name])
    ax.fill_between(steps, 0, 1, where=top < 1, color="0.9", transform=ax.get_xaxis_transform(),
                    label="approach (mean ceiling < 1)")
    ax.set(xlabel="step", ylabel="ceiling − reward",
           title="shortfall per step, mean over the episodes")
    ax.legend()
    ceiling = np.array(record["returns"]["ceiling"])
    for name in ("heuristic", AGENT):
        if name in record["returns"]:
            bx.scatter(record["targets"], ceiling - np.array(record["returns"][name]), s=14,
                       label=labels[name])
    bx.set(xlabel="target concentration A*", ylabel="ceiling − return",
           title="shortfall per episode")
    bx.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m agents.ceiling", description=__doc__.split(
        "\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    add_episode_arguments(p)
    p.add_argument("--reference", type=Path, default=None,
                   help="the folder of reference agents (default docs/agents/reference)")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT)
    return p


def main(argv: list[str] | None = None) -> dict:
    raw = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    args = parser.parse_args(raw)
    if args.processes < 1:
        parser.error("--processes must be >= 1")
    try:
        record = analyse(episodes=args.episodes, seed=args.seed, processes=args.processes,
                         progress=not args.no_progress, root=args.reference)
    except ValueError as err:
        parser.error(str(err))
    record = stamped("agents.ceiling", raw, record)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "ceiling.json").write_text(json.dumps(record, indent=1) + "\n")
    (args.out / "ceiling.md").write_text(markdown(record))
    plot(record, args.out / "ceiling.png")
    s = record["summary"]
    print(f"ceiling {_pm(s['ceiling']['ret'])}, controller {_pm(s['heuristic']['ret'])} "
          f"({_pm(s['heuristic']['below_ceiling'])} below it); wrote {args.out / 'ceiling.md'}")
    return record


if __name__ == "__main__":
    main()
