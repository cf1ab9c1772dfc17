"""What chaos alone does to a return: a policy against its own twin.

Usage::

    python -m agents.chaos --env iceenvs/FloeClustering-v0 [--policy heuristic]
        [--epsilon 1e-6] [--episodes 20] [--seed 50000] [--processes 1]
        [--out docs/agents/diagnostics/<env-name>-chaos] [--no-progress]

A floe field is chaotic: two runs whose actions differ in the sixth digit
part after some collisions, and their returns differ by whatever the task
makes of two unrelated trajectories. The twin of a policy acts as the
policy does, plus a seeded Gaussian perturbation of ``epsilon`` (in action
units) on every action; it is not a better or a worse policy. Its paired
difference with the policy on the same episodes is the control that any
comparison of two policies on that environment has to beat: two standard
errors of the twins' difference over the benchmark's episodes is the
smallest gain the benchmark can resolve there, whatever learns it. Where
the twins' difference is as large as that of two different policies, the
return measures the chaos rather than the policy.

Writes ``chaos.json`` (the returns and the comparison) and ``chaos.md``.
Episodes default to the tuning episodes (50000 + k), never the benchmark's.
"""
from __future__ import annotations

import argparse

import numpy as np

from .diagnostics import check_episodes, diagnostic_parser, resolvable, run_diagnostic

__all__ = ["Twin", "twins", "resolvable", "markdown", "main"]



class Twin:
    """The baseline ``inner`` (a name of :func:`agents.baselines.make_baseline`)
    with every action perturbed by ``epsilon`` × a standard normal draw
    (seeded per episode), clipped to the action space."""

    def __init__(self, env, seed: int = 0, *, inner: str = "heuristic", epsilon: float = 1e-6):
        from .baselines import make_baseline

        if not epsilon > 0:
            raise ValueError(f"epsilon must be > 0, got {epsilon}")
        self.inner = make_baseline(inner, env, seed=seed)
        self.epsilon = float(epsilon)
        self.space = env.action_space
        self.rng = np.random.default_rng(seed)

    def reset(self, seed: int | None = None) -> None:
        self.inner.reset(seed)
        self.rng = np.random.default_rng(None if seed is None else [seed, 7])

    def predict(self, obs, deterministic: bool = True):
        action, state = self.inner.predict(obs, deterministic=deterministic)
        action = np.asarray(action, dtype=float)
        moved = action + self.epsilon * self.rng.standard_normal(action.shape)
        return np.clip(moved, self.space.low, self.space.high).astype(self.space.dtype), state


def twins(env_id: str, *, policy: str = "heuristic", epsilon: float = 1e-6,
          episodes: int = 20, seed: int = 50000, processes: int = 1,
          progress: bool = True, others: tuple[str, ...] = ("zero",)) -> dict:
    """The policy, its twin and ``others`` on episodes seeded ``seed`` + k:
    their returns and the paired differences of the policy with each."""
    from .benchmark import play
    from .rollouts import compare, stats

    check_episodes(episodes, seed)
    if not epsilon > 0:
        raise ValueError(f"epsilon must be > 0, got {epsilon}")
    recipes = {policy: ("baseline", policy, {}),
               "twin": ("policy", "agents.chaos:Twin", {"inner": policy, "epsilon": epsilon}),
               **{o: ("baseline", o, {}) for o in others if o != policy}}
    runs = play(env_id, recipes, episodes=episodes, seed=seed, processes=processes,
                progress=progress)
    differences = {name: compare(runs[policy], eps) for name, eps in runs.items()
                   if name != policy}
    twin = np.array([a["ret"] - b["ret"] for a, b in zip(runs[policy], runs["twin"])])
    return dict(env=env_id, policy=policy, epsilon=epsilon, episodes=episodes, seed=seed,
                returns={n: stats(np.array([e["ret"] for e in eps])) for n, eps in runs.items()},
                episode_returns={n: [round(e["ret"], 4) for e in eps] for n, eps in runs.items()},
                differences=differences, twin_std=float(np.std(twin, ddof=1)))


def markdown(record: dict) -> str:
    from .metrics import format_pm
    from .reference import EVAL_EPISODES

    p = record["policy"]
    lines = [f"`{record['command']}` (commit `{record['commit']}`, {record['date']}). "
             f"{record['episodes']} episodes seeded {record['seed']} + k; the twin is the "
             f"{p} with every action moved by {record['epsilon']:g} × a normal draw. "
             f"Returns are mean ± standard error; differences are paired by episode.", "",
             f"| policy | return | {p} − policy | standard deviation of the difference |",
             "|---|---|---|---|",
             f"| {p} | {format_pm(record['returns'][p]['mean'], record['returns'][p]['sem'])} "
             f"| 0 | 0 |"]
    for name, d in record["differences"].items():
        n = record["episodes"]
        label = f"twin ({p}, perturbed)" if name == "twin" else name
        ret = record["returns"][name]
        lines.append(f"| {label} | {format_pm(ret['mean'], ret['sem'])} | "
                     f"{format_pm(d['diff'], d['sem'])} | {d['sem'] * np.sqrt(n):.3g} |")
    lines += ["", f"Chaos alone moves a return by {record['twin_std']:.3g} (standard deviation "
                  f"of the twins' difference), so over the benchmark's {EVAL_EPISODES} episodes "
                  f"a gain smaller than {resolvable(record, EVAL_EPISODES):.3g} is not resolved "
                  f"(two standard errors)."]
    return "\n".join(lines) + "\n"


def build_parser() -> argparse.ArgumentParser:
    p = diagnostic_parser("agents.chaos", __doc__, "chaos")
    p.add_argument("--policy", default="heuristic", help="the baseline and its twin")
    p.add_argument("--others", nargs="*", default=["zero"],
                   help="baselines compared with the policy beside the twin")
    p.add_argument("--epsilon", type=float, default=1e-6)
    return p


def main(argv: list[str] | None = None) -> dict:
    record, _ = run_diagnostic(
        "agents.chaos", "chaos", build_parser(), argv,
        lambda args: twins(args.env, policy=args.policy, epsilon=args.epsilon,
                           episodes=args.episodes, seed=args.seed, processes=args.processes,
                           progress=not args.no_progress, others=tuple(args.others)),
        markdown)
    return record


if __name__ == "__main__":
    main()
