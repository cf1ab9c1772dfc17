"""Sustained environment steps per second: ``python -m benchmarks.bench_environments``
(``seaice bench environments``); the effect of the reduced-stiffness option:
``python -m benchmarks.bench_environments --stiffness``.

    python -m benchmarks.bench_environments [--ids WindDrift-v0 ...] [--seconds 20] [--runs 3]
                                      [--warmup 2] [--seed 0] [--quick] [--no-peer]
                                      [--json PATH | --no-json]
    python -m benchmarks.bench_environments --stiffness [--json PATH]
"""
from __future__ import annotations

import math
import statistics
import sys
import time

from . import harness

SUITE = "environments"
TITLE = "Environments"
DESCRIPTION = """
Sustained steps per second of every registered environment in its default
configuration, each in a fresh process with Numba limited to one thread,
random actions from a seeded action space. After a warm-up (an episode start
and 5 steps, which compile or load the kernels, then 2 seconds of untimed
steps), three consecutive runs of whole episodes, at least 20 wall seconds
each, are timed: each run starts with a fresh episode and ends with the
first episode end after its 20 seconds, and every episode's reset is timed
too, as in training. So a run weighs every part of an episode as an
episode does (a ship's transit costs little before the ship reaches the ice
and most where it has set the pack moving): these are the rates training
sees. The
table gives the mean steps/s over the runs, their range and standard
deviation, the resets and the physics errors (steps with `info["error"]`).

When ShipNavigation-v0 is among them, the peer environment BenchNPIN
`ship-ice-v0` (pymunk; its package installed by the command into a
virtualenv of its own, see `benchmarks.benchnpin_peer`) is timed in the
same run with the same protocol, beside ShipNavigation-v0 in its default
configuration and at a number of floes like BenchNPIN's (the brash preset
at A = 0.09); the second table gives the ratios.
"""
STIFFNESS_TITLE = "Reduced stiffness"
STIFFNESS_DESCRIPTION = """
The `stiffness_scale` option of the Hertz environments, same seed and actions:
WindDrift-v0 with a 10 m/s wind along x for 60 steps of 5 s, and
Convergence-v0 at 1 per hour (`max_rate=1`) from Ā = 0.80 for 150 steps of
2 s, or until the pressure passes the failure threshold; steps/s and the
observables averaged over the last third of the run.
"""
WARMUP_STEPS = 5
#: settings of ``--quick``
QUICK = dict(seconds=0.5, runs=2, warmup=0.0)


#: ShipNavigation-v0 at a number of floes like BenchNPIN's ship-ice-v0 (124–141)
PEER_LIKE = dict(floe_sizes="brash", concentration=0.09)


def measure_env(env_id: str, seconds: float = 20.0, runs: int = 3, seed: int = 0,
                warmup: float = 2.0, kwargs: dict | None = None) -> dict:
    """Sustained steps/s of ``env_id`` (made with ``kwargs``) in this
    process: ``runs`` consecutive timed runs of whole episodes, at least
    ``seconds`` each, after the warm-up, each episode with its reset."""
    import gymnasium as gym

    import iceenvs  # noqa: F401
    from iceenvs.warmup import random_steps

    env = gym.make(env_id, **(kwargs or {}))
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
    floes = getattr(spec, "n_floes", None) if hasattr(spec, "lidar_sectors") else None
    env.close()
    return dict(id=env_id, rates=rates, mean=statistics.fmean(rates), min=min(rates),
                max=max(rates), std=statistics.stdev(rates) if len(rates) > 1 else 0.0,
                steps=steps, seconds=walls, resets=resets, errors=errors,
                interval=float(interval), unit=unit, kwargs=dict(kwargs or {}), floes=floes)


def _child(env_id: str, seconds: float, runs: int, seed: int, warmup: float,
           kwargs: dict | None = None) -> dict:
    """:func:`measure_env` in a fresh process limited to one Numba thread."""
    try:
        return harness.spawn_call(measure_env, env_id, seconds, runs, seed, warmup, kwargs,
                                  threads=1)
    except harness.ChildError as exc:
        tail = (str(exc).strip().splitlines() or ["(no output)"])[-1]
        return dict(id=env_id, failed=tail)


COLUMNS = ["id", "steps/s (mean)", "min–max", "std", "target", "model time per step",
           "resets", "physics errors"]


def env_row(r: dict) -> list:
    """One environment's row of the table."""
    if "failed" in r:
        return [f"`{r['id']}`", f"failed: {r['failed']}", "", "", "", "", "", ""]
    from iceenvs.facts import env_facts

    return [f"`{r['id']}`", f"{r['mean']:.0f}", f"{r['min']:.0f}–{r['max']:.0f}",
            f"{r['std']:.0f}", f"≥ {env_facts(r['id']).speed_target:g}", f"{r['interval']:g} {r['unit']}",
            r["resets"], r["errors"]]


def environments_table(result: dict) -> dict:
    """The table of a :func:`run_benchmark` result."""
    st = result["settings"]
    return harness.table(
        f"Sustained environment steps per second, one core (Numba: 1 thread), {st['runs']} "
        f"runs of whole episodes, ≥ {st['seconds']:g} s each, after a warm-up",
        COLUMNS, [env_row(r) for r in result["environments"]],
        "The spread within one run is a few per cent; the load of a shared host moves the "
        "rates of two runs of the command further apart than that.")


def run_benchmark(ids, seconds: float = 20.0, runs: int = 3, seed: int = 0, warmup: float = 2.0,
                  quiet: bool = False) -> dict:
    """Measure every id in its own process; returns the settings and one
    row per environment (``environments``)."""
    result = dict(settings=dict(seconds=seconds, runs=runs, seed=seed, warmup=warmup,
                                warmup_steps=WARMUP_STEPS, threads=1),
                  environments=[])
    with harness.Progress(len(ids), "environments", quiet) as bar:
        bar.log("| " + " | ".join(COLUMNS) + " |")
        bar.log("|" + "---|" * len(COLUMNS))
        for env_id in ids:
            row = _child(env_id, seconds, runs, seed, warmup)
            result["environments"].append(row)
            bar.advance()
            bar.log("| " + " | ".join(map(str, env_row(row))) + " |")
    return result


PEER_COLUMNS = ["environment", "floes", "model time per step", "steps/s (mean)", "min–max",
                "ratio to BenchNPIN (range)"]


def peer_comparison(seconds: float, runs: int, seed: int, warmup: float,
                    quiet: bool = False) -> dict:
    """BenchNPIN ``ship-ice-v0`` (in its own virtualenv,
    :mod:`benchmarks.benchnpin_peer`), ShipNavigation-v0 (default and
    :data:`PEER_LIKE`) and ShipNavigation-v1 (default) timed one after the
    other with the same protocol."""
    from . import benchnpin_peer

    ours = "iceenvs/ShipNavigation-v0"
    with harness.Progress(4, "BenchNPIN side by side", quiet) as bar:
        try:
            peer = benchnpin_peer.measure(seconds=seconds, runs=runs, seed=seed)
        except RuntimeError as exc:
            peer = dict(failed=str(exc).strip().splitlines()[-1])
        bar.advance()
        default = _child(ours, seconds, runs, seed, warmup)
        bar.advance()
        like = _child(ours, seconds, runs, seed, warmup, PEER_LIKE)
        bar.advance()
        v1 = _child("iceenvs/ShipNavigation-v1", seconds, runs, seed, warmup)
        bar.advance()
    return dict(peer=peer, default=default, peer_like=like, v1=v1)


def peer_table(result: dict) -> dict:
    """The table of a :func:`peer_comparison` result."""
    peer = result["peer"]
    rows = []
    if "failed" in peer:
        rows.append(["BenchNPIN `ship-ice-v0`", f"failed: {peer['failed']}", "", "", "", ""])
    else:
        cfg = peer.get("config", {})
        per = cfg.get("floes_per_episode") or {}
        floes = f"{per['min']}–{per['max']}" if per else cfg.get("floes", "")
        rows.append([f"BenchNPIN `ship-ice-v0` {peer.get('version', '')}, A = "
                     f"{cfg.get('concentration', math.nan):g}", floes,
                     f"{peer.get('interval', math.nan):g} s", f"{peer['mean']:.1f}",
                     f"{peer['min']:.1f}–{peer['max']:.1f}", "1"])
    for key, label in (("default", "`ShipNavigation-v0` (default: A 0.2–0.6, pack floes)"),
                       ("peer_like", "`ShipNavigation-v0`, brash floes, A = 0.09"),
                       ("v1", "`ShipNavigation-v1` (default: A 0.2–0.5, AUTO-IceNav's "
                              "floes, 1 km of ice)")):
        r = result.get(key)
        if r is None:                  # a record from before v1 joined the comparison
            continue
        if "failed" in r:
            rows.append([label, f"failed: {r['failed']}", "", "", "", ""])
            continue
        ratio = ""
        if "failed" not in peer:
            ratio = (f"{r['mean'] / peer['mean']:.1f} ({r['min'] / peer['max']:.1f}–"
                     f"{r['max'] / peer['min']:.1f})")
        rows.append([label, r.get("floes", ""), f"{r['interval']:g} {r['unit']}",
                     f"{r['mean']:.0f}", f"{r['min']:.0f}–{r['max']:.0f}", ratio])
    return harness.table(
        "Ship navigation side by side with BenchNPIN ship-ice-v0 (one core each, same "
        "protocol, one benchmark run)", PEER_COLUMNS, rows,
        "Floes: those of the last episode measured (BenchNPIN: the range over the episodes "
        "it ran). The range of a ratio divides the slowest run of one by the fastest of the "
        "other. BenchNPIN's ship is 2 m long at 0.3 m/s (a step sails 0.24 m, an eighth of "
        "its length), ours 76.2 m at 2 m/s (a step sails 4 m, a nineteenth); their Froude "
        "numbers, 0.068 and 0.073, are about the same.")


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


def stiffness_table(rows: list[dict]) -> dict:
    """The table of a :func:`stiffness_effect` result."""
    return harness.table(
        "Reduced stiffness: same seed and actions",
        ["id", "stiffness_scale", "Δt [s]", "steps/s", "A", "u_x [m/s]", "Z_c", "f_nr",
         "p [N/m]", "F_c,1/F_tot"],
        [[f"`{r['id']}`", f"{r['scale']:g}", f"{r['dt']:.3g}", f"{r['rate']:.0f}",
          f"{r['concentration']:.3f}", f"{r['u_x']:.3f}", f"{r['z_c']:.2f}", f"{r['f_nr']:.2f}",
          f"{r['pressure']:.3g}", f"{r['largest_cluster']:.2f}"] for r in rows])


def resolve_ids(ids, known) -> list[str]:
    out = []
    for i in ids:
        full = i if "/" in i else f"iceenvs/{i}"
        if full not in known:
            raise SystemExit(f"unknown environment {i!r}; known: {', '.join(known)}")
        out.append(full)
    return out


def main(argv=None, prog: str | None = None) -> int:
    from iceenvs import ENV_IDS

    parser = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    parser.add_argument("--ids", nargs="+", metavar="ID",
                        help="environments to time, e.g. WindDrift-v0 (default: all)")
    parser.add_argument("--seconds", type=float, default=None,
                        help="minimum wall seconds of each timed run (default 20)")
    parser.add_argument("--runs", type=int, default=None,
                        help="timed runs per environment (default 3)")
    parser.add_argument("--warmup", type=float, default=None,
                        help="untimed seconds of steps after the compiling steps (default 2)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the episodes and actions")
    parser.add_argument("--no-peer", action="store_true",
                        help="skip timing BenchNPIN ship-ice-v0 beside ShipNavigation-v0")
    parser.add_argument("--stiffness", action="store_true",
                        help="compare stiffness_scale = 1, 0.1, 0.01 instead (writes a record "
                             "only with --json)")
    args, argv = harness.parse(parser, argv)
    settings = dict(seconds=20.0, runs=3, warmup=2.0)
    if args.quick:
        settings.update(QUICK)
    settings.update({k: getattr(args, k) for k in settings if getattr(args, k) is not None})
    if settings["seconds"] <= 0 or settings["runs"] < 1 or settings["warmup"] < 0:
        parser.error("--seconds must be positive, --runs at least 1, --warmup not negative")
    command = harness.command_line(SUITE, argv)
    t0 = time.perf_counter()
    if args.stiffness:
        rows = stiffness_effect()
        record = harness.make_record(SUITE, STIFFNESS_TITLE, STIFFNESS_DESCRIPTION, command,
                                     [stiffness_table(rows)], dict(rows=rows),
                                     time.perf_counter() - t0)
        args.no_json = args.no_json or not any(a.startswith(("--json", "--docs")) for a in argv)
        harness.finish(args, record)
        return 0
    ids = resolve_ids(args.ids, ENV_IDS) if args.ids else list(ENV_IDS)
    result = run_benchmark(ids, settings["seconds"], settings["runs"], args.seed,
                           settings["warmup"], args.quiet)
    tables = [environments_table(result)]
    if "iceenvs/ShipNavigation-v0" in ids and not args.no_peer:
        result["peer"] = peer_comparison(settings["seconds"], settings["runs"], args.seed,
                                         settings["warmup"], args.quiet)
        tables.append(peer_table(result["peer"]))
    record = harness.make_record(SUITE, TITLE, DESCRIPTION, command,
                                 tables, dict(result, quick=args.quick),
                                 time.perf_counter() - t0,
                                 machine=harness.machine_info(numba_threads=1))
    harness.finish(args, record, show=False)
    return 1 if any("failed" in r for r in result["environments"]) else 0


if __name__ == "__main__":
    sys.exit(main())
