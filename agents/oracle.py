"""How much a controller that knows the exact model gains over a baseline: a rollout oracle.

Usage::

    python -m agents.oracle --env iceenvs/MarginalIceZone-v0 [--base heuristic]
        [--every 5] [--horizon 30] [--delta 0.5] [--epsilon 1e-6]
        [--episodes 20] [--seed 50000] [--processes 1]
        [--out docs/agents/diagnostics/<env-name>-oracle] [--no-progress]

The oracle (:class:`RolloutOracle`) improves a baseline by search on exact
copies of the environment: every ``every`` steps it copies the environment
and the baseline, plays each candidate for ``every`` steps and the baseline
after it, up to ``horizon`` steps ahead, and keeps the candidate whose
rewards sum highest. A candidate is the baseline's action moved by an
offset: none (the baseline itself, which wins ties), or ± ``delta`` on one
action entry at a time. Where the horizon reaches the end of the episode
the oracle never returns less than the baseline (rollout, Bertsekas 1997:
the baseline's continuation is always a candidate, so the planned return
can only grow from one decision to the next); a test checks it.

On a chaotic floe field the copies show the exact future, so the oracle
also profits from choosing whichever candidate happens to avoid a jam,
which no policy can foresee. The control is the *chaos oracle*: the same
search whose candidates are the baseline's action moved by ``epsilon`` ×
a normal draw (seeded), so that the candidates differ only in their
chaos. What the oracle gains over the chaos oracle, paired by episode, is
the gain that acting differently buys on the true model; what the chaos
oracle gains over the baseline is what foresight of the chaos alone buys.

Writes ``oracle.json`` (returns per policy and episode, the paired
differences), ``oracle.md`` and ``oracle.png``. Episodes default to the
tuning episodes (50000 + k), never the benchmark's.
"""
from __future__ import annotations

import argparse
import copy
import time
from pathlib import Path

import numpy as np

from .diagnostics import check_episodes, diagnostic_parser, run_diagnostic

__all__ = ["RolloutOracle", "oracles", "markdown", "plot", "main"]

#: the policies of a record beside the baseline, in the order of its tables
POLICIES = ("oracle", "chaos oracle")


class RolloutOracle:
    """A baseline improved by search on exact copies of ``env``.

    Parameters
    ----------
    env : gymnasium.Env
        The environment the oracle acts in; it is copied at every decision
        (``copy.deepcopy``), so it must be the very environment played.
    seed : int
        Seed of the chaos candidates' draws (re-seeded by each episode's seed).
    base : str
        The baseline improved (:func:`agents.baselines.make_baseline`).
    every : int
        Steps a chosen candidate is kept.
    horizon : int
        Steps of each rollout (``every`` of the candidate, then the
        baseline), cut at the end of the episode.
    delta : float
        Offset of the candidates in action units.
    epsilon : float or None
        If given, the candidates are the baseline's action plus ``epsilon``
        × a normal draw, as many as the offsets (the chaos control).
    """

    def __init__(self, env, seed: int = 0, *, base: str = "heuristic", every: int = 5,
                 horizon: int = 30, delta: float = 0.5, epsilon: float | None = None):
        from .baselines import make_baseline

        if every < 1 or horizon < every:
            raise ValueError(f"every ({every}) must be >= 1 and horizon ({horizon}) >= every")
        if not delta > 0 or (epsilon is not None and not epsilon > 0):
            raise ValueError(f"delta ({delta}) and epsilon ({epsilon}) must be > 0")
        self.env = env
        self.base = make_baseline(base, env, seed=seed)
        self.space = env.action_space
        self.every, self.horizon = int(every), int(horizon)
        self.epsilon = epsilon
        dim = int(np.prod(self.space.shape))
        eye = np.eye(dim).reshape((dim, *self.space.shape))
        self.offsets = [np.zeros(self.space.shape)] + [s * delta * e for e in eye
                                                       for s in (1.0, -1.0)]
        self.rng = np.random.default_rng(seed)
        self.reset(None)

    def reset(self, seed: int | None = None) -> None:
        self.base.reset(seed)
        self.rng = np.random.default_rng(None if seed is None else [seed, 11])
        self.step_in_episode = 0
        self.offset = self.offsets[0]
        self.changed = 0          # decisions that kept a candidate other than the baseline
        self.decisions = 0
        self.plans = []           # the best rollout's rewards at each decision

    def _candidates(self) -> list[np.ndarray]:
        if self.epsilon is None:
            return self.offsets
        return [self.offsets[0]] + [self.epsilon * self.rng.standard_normal(self.space.shape)
                                    for _ in self.offsets[1:]]

    def _act(self, base, obs, offset) -> np.ndarray:
        action, _ = base.predict(obs, deterministic=True)
        moved = np.asarray(action, dtype=float) + offset
        return np.clip(moved, self.space.low, self.space.high).astype(self.space.dtype)

    def _rollout(self, obs, offset) -> float:
        env, base = copy.deepcopy((self.env, self.base))   # together: a base reading env
        total = 0.0
        for k in range(self.horizon):
            obs, reward, terminated, truncated, _ = env.step(
                self._act(base, obs, offset if k < self.every else 0.0))
            total += float(reward)
            if terminated or truncated:
                break
        return total

    def predict(self, obs, state=None, episode_start=None, deterministic: bool = True):
        if self.step_in_episode % self.every == 0:
            candidates = self._candidates()
            scores = [self._rollout(obs, c) for c in candidates]
            best = int(np.argmax(scores))                 # the first of equals: the baseline
            self.offset = candidates[best]
            self.changed += best != 0
            self.decisions += 1
            self.plans.append(scores[best])
        self.step_in_episode += 1
        return self._act(self.base, obs, self.offset), state


def _recipes(base: str, every: int, horizon: int, delta: float, epsilon: float) -> dict:
    kwargs = dict(base=base, every=every, horizon=horizon, delta=delta)
    return {base: ("baseline", base, {}),
            "oracle": ("policy", "agents.oracle:RolloutOracle", kwargs),
            "chaos oracle": ("policy", "agents.oracle:RolloutOracle",
                             {**kwargs, "epsilon": epsilon})}


def oracles(env_id: str, *, base: str = "heuristic", every: int = 5, horizon: int = 30,
            delta: float = 0.5, epsilon: float = 1e-6, episodes: int = 20, seed: int = 50000,
            processes: int = 1, progress: bool = True) -> dict:
    """The baseline, the oracle and the chaos oracle on episodes seeded
    ``seed`` + k: their returns and the paired differences."""
    from .benchmark import play
    from .rollouts import compare, stats

    check_episodes(episodes, seed)
    if every < 1 or horizon < every or not delta > 0 or not epsilon > 0:
        raise ValueError(f"every ({every}) must be >= 1, horizon ({horizon}) >= every, and "
                         f"delta ({delta}) and epsilon ({epsilon}) > 0")
    t0 = time.perf_counter()
    runs = play(env_id, _recipes(base, every, horizon, delta, epsilon), episodes=episodes,
                seed=seed, processes=processes, progress=progress)
    pairs = {"oracle − " + base: ("oracle", base),
             "chaos oracle − " + base: ("chaos oracle", base),
             "oracle − chaos oracle": ("oracle", "chaos oracle")}
    differences = {}
    for label, (a, b) in pairs.items():
        d = compare(runs[a], runs[b])
        d["std"] = d["sem"] * np.sqrt(episodes)
        differences[label] = d
    return dict(env=env_id, base=base, every=every, horizon=horizon, delta=delta,
                epsilon=epsilon, episodes=episodes, seed=seed,
                seconds=round(time.perf_counter() - t0, 1),
                returns={n: stats([e["ret"] for e in eps]) for n, eps in runs.items()},
                episode_returns={n: [round(e["ret"], 4) for e in eps] for n, eps in runs.items()},
                differences=differences)


def markdown(record: dict) -> str:
    from .metrics import format_pm

    b = record["base"]
    lines = [f"`{record['command']}` (commit `{record['commit']}`, {record['date']}, "
             f"{record['seconds']:.0f} s). {record['episodes']} episodes seeded "
             f"{record['seed']} + k. Every {record['every']} steps the oracle keeps the best of "
             f"the {b} baseline's action and that action moved by ± {record['delta']:g} on one "
             f"entry, scored by a rollout of {record['horizon']} steps on an exact copy; the chaos "
             f"oracle chooses among moves of {record['epsilon']:g} × a normal draw. Returns are "
             f"mean ± standard error; differences are paired by episode.", "",
             "| policy | return |", "|---|---|"]
    for name in (b, *POLICIES):
        r = record["returns"][name]
        lines.append(f"| {name} | {format_pm(r['mean'], r['sem'])} |")
    lines += ["", "| difference | mean ± standard error | standard deviation | verdict |",
              "|---|---|---|---|"]
    for label, d in record["differences"].items():
        lines.append(f"| {label} | {format_pm(d['diff'], d['sem'])} | {d['std']:.3g} | "
                     f"{d['verdict']} |")
    return "\n".join(lines) + "\n"


def plot(record: dict, path: Path) -> None:
    """Every episode's paired differences (the record's three), with their
    means ± two standard errors."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    returns = {n: np.array(r) for n, r in record["episode_returns"].items()}
    b = record["base"]
    pairs = [("oracle", b), ("chaos oracle", b), ("oracle", "chaos oracle")]
    fig, ax = plt.subplots(figsize=(7.0, 3.4), constrained_layout=True)
    for k, ((x, y), colour) in enumerate(zip(pairs, ("C0", "C3", "C2"))):
        d = returns[x] - returns[y]
        ax.plot(k + np.linspace(-0.15, 0.15, d.size), d, "o", color=colour, alpha=0.7)
        ax.errorbar(k + 0.3, d.mean(), yerr=2 * d.std(ddof=1) / np.sqrt(d.size), fmt="s",
                    color="k", capsize=4)
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_xticks(range(len(pairs)), [f"{x} − {y}" for x, y in pairs])
    ax.set_ylabel("return difference per episode")
    ax.set_title(f"{record['env']}: search on exact copies (black: mean ± 2 SE)", fontsize=9)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def build_parser() -> argparse.ArgumentParser:
    p = diagnostic_parser("agents.oracle", __doc__, "oracle")
    p.add_argument("--base", default="heuristic", help="the baseline improved (default heuristic)")
    p.add_argument("--every", type=int, default=5, help="steps a choice is kept (default 5)")
    p.add_argument("--horizon", type=int, default=30, help="steps of a rollout (default 30)")
    p.add_argument("--delta", type=float, default=0.5, help="offset of the candidates")
    p.add_argument("--epsilon", type=float, default=1e-6,
                   help="offset scale of the chaos oracle's candidates")
    return p


def main(argv: list[str] | None = None) -> dict:
    record, out = run_diagnostic(
        "agents.oracle", "oracle", build_parser(), argv,
        lambda args: oracles(args.env, base=args.base, every=args.every, horizon=args.horizon,
                             delta=args.delta, epsilon=args.epsilon, episodes=args.episodes,
                             seed=args.seed, processes=args.processes,
                             progress=not args.no_progress),
        markdown)
    plot(record, out / "oracle.png")
    return record


if __name__ == "__main__":
    main()
