"""A short training and evaluation: ``python -m agents.demo``.

Trains PPO on ``iceenvs/ThicknessDistribution-v0`` (the fast, ODE-based
environment) for a small budget, then evaluates the policy against the
random, zero-action and hand-written baselines on the same seeded episodes
and prints the comparison table. The full runs documented in the README
use the same commands with the YAML budgets; this one only shows the way.

    python -m agents.demo [--timesteps 20000] [--episodes 10] [--out DIR]
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from .evaluate import main as evaluate_main
from .train import main as train_main

__all__ = ["main"]

ENV_ID = "iceenvs/ThicknessDistribution-v0"


def main(argv: list[str] | None = None, prog: str = "python -m agents.demo") -> dict:
    """Train, evaluate, print; returns the evaluation summaries."""
    p = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n")[0])
    p.add_argument("--timesteps", type=int, default=20_000,
                   help="training budget in environment steps (default 20000)")
    p.add_argument("--episodes", type=int, default=10,
                   help="evaluation episodes per policy (default 10)")
    p.add_argument("--seed", type=int, default=0, help="training seed (default 0)")
    p.add_argument("--out", type=Path, default=Path("runs/demo/agents"),
                   help="run directory, overwritten (default runs/demo/agents)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bars")
    args = p.parse_args(sys.argv[1:] if argv is None else argv)
    if args.timesteps < 1 or args.episodes < 1:
        p.error("--timesteps and --episodes must be at least 1")

    quiet = ["--no-progress"] if args.no_progress else []
    print(f"Training PPO on {ENV_ID} for {args.timesteps} steps ...", flush=True)
    t0 = time.perf_counter()
    run_dir = train_main(["--env", ENV_ID, "--algo", "ppo", "--timesteps", str(args.timesteps),
                          "--seed", str(args.seed), "--out", str(args.out), "--force",
                          "--eval-freq", "0", "--save-freq", "0", *quiet])
    t1 = time.perf_counter()
    print(f"trained in {t1 - t0:.0f} s; evaluating on {args.episodes} seeded episodes ...\n",
          flush=True)
    summaries = evaluate_main([str(run_dir), "--episodes", str(args.episodes), *quiet])
    print(f"\nevaluated in {time.perf_counter() - t1:.0f} s; table, episodes and plot in "
          f"{run_dir}/evaluation.{{md,json,png}}")
    return summaries


if __name__ == "__main__":
    main()
