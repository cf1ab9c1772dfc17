"""Sustained environment steps per second: ``python -m iceenvs.bench``; the
effect of the reduced-stiffness option: ``python -m iceenvs.bench --stiffness``.

Every registered environment (or those of ``--ids``) in its default
configuration, each in a fresh process with Numba limited to one thread,
random actions from a seeded action space. After a warm-up (an episode start
and 5 steps, which compile or load the kernels, then ``--warmup`` seconds of
untimed steps), ``--runs`` consecutive runs of at least ``--seconds`` wall
seconds each are timed; an episode that ends (terminated or truncated) is
reset inside the run and the reset is timed too, as in training. The table
gives the mean steps/s over the runs, their range and standard deviation,
the resets and the physics errors (steps with ``info["error"]``); the same
figures, the command, the machine and the date go to ``--json``
(default ``docs/benchmarks/environments.json``) and the table beside it
(``environments.md``), which the documentation includes.

    python -m iceenvs.bench [--ids WindDrift-v0 ...] [--seconds 20] [--runs 3]
                            [--warmup 2] [--json PATH]
    python -m iceenvs.bench --stiffness
"""
from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import shlex
import statistics
import subprocess
import sys
import time
from pathlib import Path

DEFAULT_JSON = Path("docs/benchmarks/environments.json")
WARMUP_STEPS = 5
TARGETS = {"ThicknessDistribution-v0": 5000, "FloeClustering-v0": 200}


def measure_env(env_id: str, seconds: float = 20.0, runs: int = 3, seed: int = 0,
                warmup: float = 2.0) -> dict:
    """Sustained steps/s of ``env_id`` in this process: ``runs`` consecutive
    timed runs of at least ``seconds`` each, after the warm-up, with resets
    at episode ends."""
    import gymnasium as gym

    import iceenvs  # noqa: F401

    from .warmup import random_steps

    env = gym.make(env_id)
    env.action_space.seed(seed)
    env.reset(seed=seed)
    random_steps(env, WARMUP_STEPS)
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < warmup:
        random_steps(env, 1)
    env.reset(seed=seed + 1)
    rates, steps, walls, resets, errors = [], [], [], 0, 0
    for _ in range(runs):
        n = 0
        t0 = time.perf_counter()
        while True:
            _, _, term, trunc, info = env.step(env.action_space.sample())
            n += 1
            errors += bool(info.get("error"))
            if term or trunc:
                env.reset()
                resets += 1
            wall = time.perf_counter() - t0
            if wall >= seconds:
                break
        rates.append(n / wall)
        steps.append(n)
        walls.append(wall)
    spec = env.unwrapped
    interval = getattr(spec, "control_interval", getattr(spec, "days_per_step", math.nan))
    unit = "days" if hasattr(spec, "days_per_step") and not hasattr(spec, "control_interval") \
        else "s"
    env.close()
    return dict(id=env_id, rates=rates, mean=statistics.fmean(rates), min=min(rates),
                max=max(rates), std=statistics.stdev(rates) if len(rates) > 1 else 0.0,
                steps=steps, seconds=walls, resets=resets, errors=errors,
                interval=float(interval), unit=unit)


def _child(env_id: str, seconds: float, runs: int, seed: int, warmup: float) -> dict:
    """:func:`measure_env` in a fresh process limited to one Numba thread."""
    env = dict(os.environ, NUMBA_NUM_THREADS="1")
    out = subprocess.run([sys.executable, "-m", "iceenvs.bench", "--child", env_id,
                          "--seconds", repr(seconds), "--runs", str(runs), "--seed", str(seed),
                          "--warmup", repr(warmup)],
                         capture_output=True, text=True, env=env)
    if out.returncode != 0:
        tail = (out.stderr.strip().splitlines() or ["(no output)"])[-1]
        return dict(id=env_id, failed=f"exit {out.returncode}: {tail}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def cpu_model() -> str | None:
    """The CPU model from /proc/cpuinfo (Linux), else what platform knows."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() in ("model name", "Hardware", "cpu model") and value.strip():
                    return value.strip()
    except OSError:
        pass
    return platform.processor() or None


def machine_info() -> dict:
    import numba

    return dict(platform=platform.platform(), machine=platform.machine(), cpu=cpu_model(),
                logical_cpus=os.cpu_count(), python=platform.python_version(),
                numba=numba.__version__, numba_threads=1)


def header(result: dict) -> str:
    """The title and column heads of the Markdown table."""
    st, m = result["settings"], result["machine"]
    return "\n".join([
        f"Sustained environment steps per second, one core (Numba: 1 thread), {st['runs']} runs "
        f"of ≥ {st['seconds']:g} s each after a warm-up; {m['cpu'] or m['machine']}, "
        f"numba {m['numba']}, {result['date'][:10]}", "",
        "| id | steps/s (mean) | min–max | std | target | model time per step | resets | "
        "physics errors |",
        "|---|---|---|---|---|---|---|---|"])


def format_row(r: dict) -> str:
    """One environment's row of the Markdown table."""
    name = r["id"].split("/")[-1]
    if "failed" in r:
        return f"| `{r['id']}` | failed: {r['failed']} | | | | | | |"
    return (f"| `{r['id']}` | {r['mean']:.0f} | {r['min']:.0f}–{r['max']:.0f} | {r['std']:.0f} | "
            f"≥ {TARGETS.get(name, 50)} | {r['interval']:g} {r['unit']} | {r['resets']} | "
            f"{r['errors']} |")


def format_table(result: dict) -> str:
    """The Markdown table of a :func:`run_benchmark` result."""
    return "\n".join([header(result), *map(format_row, result["environments"])])


def run_benchmark(ids, seconds: float = 20.0, runs: int = 3, seed: int = 0, warmup: float = 2.0,
                  command: str | None = None, on_start=None, on_row=None) -> dict:
    """Measure every id in its own process. ``on_start(result)`` is called
    before the first measurement, ``on_row(row)`` after each."""
    result = dict(command=command, machine=machine_info(),
                  date=datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                  settings=dict(seconds=seconds, runs=runs, seed=seed, warmup=warmup,
                                warmup_steps=WARMUP_STEPS, threads=1),
                  environments=[])
    if on_start is not None:
        on_start(result)
    for env_id in ids:
        row = _child(env_id, seconds, runs, seed, warmup)
        result["environments"].append(row)
        if on_row is not None:
            on_row(row)
    return result


def stiffness_effect(scales=(1.0, 0.1, 0.01), steps: int = 60, seed: int = 3) -> list[dict]:
    """Run WindDrift-v0 (wind 10 m/s along x, 60 steps of 5 s) and
    Convergence-v0 (1 per hour from A = 0.80, 150 steps of 2 s) with the same seed and actions at several
    ``stiffness_scale`` values; report steps/s and the observables averaged
    over the last third of the run."""
    import gymnasium as gym
    import numpy as np

    import iceenvs  # noqa: F401

    cases = [("iceenvs/WindDrift-v0", np.array([0.5, 0.0]), {}),
             ("iceenvs/Convergence-v0", np.array([1.0]), {"concentration": 0.8,
                                                          "max_rate": 1.0})]
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


def _resolve_ids(ids, known) -> list[str]:
    out = []
    for i in ids:
        full = i if "/" in i else f"iceenvs/{i}"
        if full not in known:
            raise SystemExit(f"unknown environment {i!r}; known: {', '.join(known)}")
        out.append(full)
    return out


def main(argv=None) -> int:
    from iceenvs import ENV_IDS

    argv = sys.argv[1:] if argv is None else list(argv)
    parser = argparse.ArgumentParser(prog="python -m iceenvs.bench", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--ids", nargs="+", metavar="ID",
                        help="environments to time, e.g. WindDrift-v0 (default: all)")
    parser.add_argument("--seconds", type=float, default=20.0,
                        help="minimum wall seconds of each timed run (default 20)")
    parser.add_argument("--runs", type=int, default=3, help="timed runs per environment (default 3)")
    parser.add_argument("--warmup", type=float, default=2.0,
                        help="untimed seconds of steps after the compiling steps (default 2)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the episodes and actions")
    parser.add_argument("--json", type=Path, default=DEFAULT_JSON,
                        help=f"where to write the results (default {DEFAULT_JSON})")
    parser.add_argument("--stiffness", action="store_true",
                        help="compare stiffness_scale = 1, 0.1, 0.01 instead")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.seconds <= 0 or args.runs < 1 or args.warmup < 0:
        parser.error("--seconds must be positive, --runs at least 1, --warmup not negative")
    if args.stiffness:
        print("| id | stiffness_scale | Δt [s] | steps/s | A | u_x [m/s] | Z_c | f_nr | "
              "p [N/m] | F_c,1/F_tot |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for r in stiffness_effect():
            print(f"| `{r['id']}` | {r['scale']:g} | {r['dt']:.3g} | {r['rate']:.0f} | "
                  f"{r['concentration']:.3f} | {r['u_x']:.3f} | {r['z_c']:.2f} | "
                  f"{r['f_nr']:.2f} | {r['pressure']:.3g} | {r['largest_cluster']:.2f} |",
                  flush=True)
        return 0
    if args.child:
        print(json.dumps(measure_env(args.child, args.seconds, args.runs, args.seed,
                                     args.warmup)))
        return 0
    ids = _resolve_ids(args.ids, ENV_IDS) if args.ids else list(ENV_IDS)
    command = shlex.join(["python", "-m", "iceenvs.bench", *argv])
    result = run_benchmark(ids, args.seconds, args.runs, args.seed, args.warmup, command,
                           on_start=lambda r: print(header(r), flush=True),
                           on_row=lambda row: print(format_row(row), flush=True))
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(result, indent=2, ensure_ascii=False) + "\n")
    markdown = args.json.with_suffix(".md")
    markdown.write_text(f"`{command}`\n\n" + format_table(result) + "\n")
    print(f"\nresults: {args.json}, table: {markdown}")
    return 1 if any("failed" in r for r in result["environments"]) else 0

if __name__ == "__main__":
    sys.exit(main())
