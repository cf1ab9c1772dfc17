"""Environment steps per second: ``python -m iceenvs.bench``; the effect of
the reduced-stiffness option: ``python -m iceenvs.bench --stiffness``.

Every registered environment in its default configuration, on one core
(Numba limited to one thread), random actions from a seeded action space,
after a warm-up episode start and 5 steps that compile everything. Each
figure is the best of three segments of ``--steps`` steps; an episode end
inside a segment resets the env (the reset is timed too, as in training).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time

REPEATS = 3


def _time_env(env_id: str, steps: int, seed: int = 0) -> dict:
    import gymnasium as gym
    import numpy as np

    import iceenvs  # noqa: F401

    env = gym.make(env_id)
    env.action_space.seed(seed)
    env.reset(seed=seed)
    for _ in range(5):
        env.step(env.action_space.sample())
    best = 0.0
    errors = 0
    for r in range(REPEATS):
        env.reset(seed=seed + r + 1)
        t0 = time.perf_counter()
        for _ in range(steps):
            _, _, term, trunc, info = env.step(env.action_space.sample())
            errors += "error" in info
            if term or trunc:
                env.reset()
        best = max(best, steps / (time.perf_counter() - t0))
    spec = env.unwrapped
    env.close()
    return dict(id=env_id, rate=best, errors=errors,
                interval=float(getattr(spec, "control_interval", getattr(spec, "days_per_step",
                                                                          np.nan))))


def _child(env_id: str, steps: int) -> dict:
    env = dict(os.environ, NUMBA_NUM_THREADS="1")
    out = subprocess.run([sys.executable, "-m", "iceenvs.bench", "--child", env_id,
                          "--steps", str(steps)], capture_output=True, text=True, env=env,
                         check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def stiffness_effect(scales=(1.0, 0.1, 0.01), steps: int = 60, seed: int = 3) -> list[dict]:
    """Run WindDrift-v0 (wind 10 m/s along x, 60 steps of 5 s) and
    Convergence-v0 (1 per hour from A = 0.80, 150 steps of 2 s) with the same seed and actions at several
    ``stiffness_scale`` values; report steps/s and the observables averaged
    over the last third of the run."""
    import gymnasium as gym
    import numpy as np

    import iceenvs  # noqa: F401

    cases = [("iceenvs/WindDrift-v0", np.array([0.5, 0.0]), {}),
             ("iceenvs/Convergence-v0", np.array([1.0]), {"concentration": 0.8})]
    keys = ("concentration", "u_x", "z_c", "f_nr", "pressure", "largest_cluster")
    rows = []
    for env_id, action, options in cases:
        for scale in scales:
            env = gym.make(env_id, stiffness_scale=scale)
            env.reset(seed=seed, options=options)
            env.step(action)
            t0 = time.perf_counter()
            record = []
            for _ in range(steps if "WindDrift" in env_id else 150):
                _, _, term, trunc, info = env.step(action)
                record.append([info["physics"][k] for k in keys])
                if term or trunc:
                    break
            rate = len(record) / (time.perf_counter() - t0)
            tail = np.array(record[-max(1, len(record) // 3):])
            rows.append(dict(id=env_id, scale=scale, rate=rate, steps=len(record),
                             dt=env.unwrapped.sim.dt,
                             **{k: float(v) for k, v in zip(keys, tail.mean(axis=0))}))
            env.close()
    return rows


TARGETS = {"ThicknessDistribution-v0": 5000, "FloeClustering-v0": 200}


def main(argv=None) -> None:
    from iceenvs import ENV_IDS

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=100, help="steps per timed segment")
    parser.add_argument("--stiffness", action="store_true",
                        help="compare stiffness_scale = 1, 0.1, 0.01 instead")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.stiffness:
        print("| id | stiffness_scale | Δt [s] | steps/s | A | u_x [m/s] | Z_c | f_nr | "
              "p [N/m] | F_c,1/F_tot |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for r in stiffness_effect():
            print(f"| `{r['id']}` | {r['scale']:g} | {r['dt']:.3g} | {r['rate']:.0f} | "
                  f"{r['concentration']:.3f} | {r['u_x']:.3f} | {r['z_c']:.2f} | "
                  f"{r['f_nr']:.2f} | {r['pressure']:.3g} | {r['largest_cluster']:.2f} |",
                  flush=True)
        return
    if args.child:
        print(json.dumps(_time_env(args.child, args.steps)))
        return
    import numba

    print(f"Environment steps per second, one core, {platform.machine()}, "
          f"numba {numba.__version__}\n")
    print("| id | steps/s | target | model time per step | physics errors |")
    print("|---|---|---|---|---|")
    for env_id in ENV_IDS:
        name = env_id.split("/")[1]
        steps = args.steps * (20 if name.startswith("Thickness") else 1)
        r = _child(env_id, steps)
        unit = "days" if name.startswith("Thickness") else "s"
        print(f"| `{env_id}` | {r['rate']:.0f} | ≥ {TARGETS.get(name, 50)} | "
              f"{r['interval']:g} {unit} | {r['errors']} |", flush=True)


if __name__ == "__main__":
    main()
