"""Floes at rest cost nothing, and change nothing: ``python -m benchmarks.bench_resting``.

    python -m benchmarks.bench_resting [--seeds 10] [--env-steps 100] [--quiet] [--quick]
                                 [--json PATH | --no-json]
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from . import harness

SUITE = "resting"
TITLE = "Floes at rest"
DESCRIPTION = """
What skipping the floes at rest (`HertzSimulation(skip_resting=True)`) changes
and what it saves. The statistics: seeded reference transits of the
`ship-transit` scenario (the platform supply vessel at 2 m/s through a band of
Herman (2013) floes at rest, no wind, its quick geometry: a band of 200 m in a
channel 160 m wide), at A = 0.3 and 0.6, with the prescribed and the dynamic
ship (constant thrust, heading autopilot), each run with the option on and
off: the mean over the seeds of the total impulse of the finished collisions,
the ice resistance and the speed loss over the window with the whole hull in
the band, the energy the hull gave to the ice and the number of collisions,
with the relative difference of the means (on − off) / off and the largest
per-seed difference over the standard deviation across the seeds. The speed:
env steps/s of `iceenvs/ShipNavigation-v0` with `length=1100, width=200,
goal_distance=1000, floe_sizes="brash", concentration=0.4` (1903 floes)
and action 0 from `reset(seed=0)`, the option on and off in two environments
that take turns, blocks of ten steps each.
"""
QUICK = dict(seeds=2, concentrations=(0.3,), env_steps=4)
FULL = dict(seeds=10, concentrations=(0.3, 0.6), env_steps=100)
SPEED = 2.0
GEOMETRY = dict(band_length=200.0, channel_width=160.0)
METRICS = ("impulse", "resistance", "energy", "collisions", "speed_loss")


def transit(concentration: float, dynamic: bool, seed: int, skip_resting: bool) -> dict:
    """One reference transit; its totals (see the description) and the
    number of floes."""
    from physics.scenarios.config import bundled_configs, load_config
    from physics.scenarios.ship_transit import autopilot, build_simulation

    p = load_config(bundled_configs()["ship-transit"]).resolve(GEOMETRY)
    case = dict(concentration=concentration, speed=SPEED, dynamic=int(dynamic), wind=0.0,
                walls=0)
    sim, geo, constants = build_simulation(p, case, seed, skip_resting=skip_resting)
    heading = float(sim.ship.heading)
    max_time = p["max_time_factor"] * (geo["end_bow"] - geo["x_ship"] - geo["bow"]) / SPEED
    impulse, collisions, energy = 0.0, 0, 0.0
    window = []
    while sim.time < max_time:
        sim.advance(p["output_interval"])
        r = sim.ship.records()
        log = sim.ship.collisions()
        sim.ship.clear()
        impulse += float(np.sum(np.hypot(log["impulse_surge"], log["impulse_sway"])))
        collisions += log["floe"].size
        energy += float(np.sum(r["ice_power"]) * sim.dt)
        bow = r["x"] + geo["bow"] * np.cos(r["heading"])
        inside = (bow >= geo["x0"] + geo["length"]) & (bow <= geo["x1"])
        window.append(np.column_stack([-r["ice_surge"][inside], r["surge"][inside]]))
        if dynamic:
            sim.ship.command(yaw_moment=autopilot(sim.ship, heading))
        if sim.ship.position[0] + geo["bow"] * math.cos(sim.ship.heading) >= geo["end_bow"]:
            break
    w = np.concatenate(window)
    return dict(impulse=impulse, collisions=float(collisions), energy=energy,
                resistance=float(w[:, 0].mean()), speed_loss=1.0 - float(w[:, 1].mean()) / SPEED,
                floes=constants["n_floes"], awake=int(sim.n_awake))


def statistics(seeds: int, concentrations, quiet: bool) -> list[dict]:
    """Per (A, mode): the metrics of every seed with the option on and off."""
    cases = [(c, d) for c in concentrations for d in (False, True)]
    out = []
    with harness.Progress(len(cases) * seeds * 2, SUITE, quiet) as bar:
        for c, dynamic in cases:
            runs = {True: [], False: []}
            for seed in range(seeds):
                for skip in (True, False):
                    runs[skip].append(transit(c, dynamic, seed, skip))
                    bar.advance()
            out.append(dict(concentration=c, dynamic=dynamic, on=runs[True], off=runs[False]))
    return out


def env_speed(env_steps: int, quiet: bool) -> dict:
    """Env steps/s of the long brash channel with the option on and off,
    two environments taking turns in blocks of ten steps."""
    import gymnasium as gym

    import iceenvs  # noqa: F401

    envs = {}
    for skip in (True, False):
        env = gym.make("iceenvs/ShipNavigation-v0", length=1100, width=200, goal_distance=1000,
                       floe_sizes="brash", concentration=0.4)
        env.reset(seed=0)
        env.unwrapped.sim.skip_resting = skip       # the environments turn it on
        envs[skip] = env
    action = np.zeros(envs[True].action_space.shape, dtype=np.float32)
    for env in envs.values():
        env.step(action)                            # compile outside the timing
    spent = {True: 0.0, False: 0.0}
    done = 0
    with harness.Progress(env_steps, "env steps", quiet, unit="step") as bar:
        while done < env_steps:
            k = min(10, env_steps - done)
            for skip, env in envs.items():
                t = time.perf_counter()
                for _ in range(k):
                    env.step(action)
                spent[skip] += time.perf_counter() - t
            done += k
            bar.advance(k)
    sims = {skip: env.unwrapped.sim for skip, env in envs.items()}
    same = bool(np.array_equal(sims[True].positions, sims[False].positions))
    sim = sims[True]
    touching = np.zeros(sim.n_floes, dtype=bool)
    contacts = sim.contacts()
    touching[contacts.i] = touching[contacts.j] = True
    touching[sim.hull_contacts()[0]] = True
    return dict(steps=env_steps, on=env_steps / spent[True], off=env_steps / spent[False],
                floes=sim.n_floes, awake=int(sim.n_awake), touching=int(touching.sum()),
                max_position_difference=float(np.abs(sims[True].positions
                                                     - sims[False].positions).max()),
                identical=same)


def statistics_table(stats: list[dict]) -> dict:
    rows = []
    for s in stats:
        mode = "dynamic" if s["dynamic"] else "prescribed"
        for m in METRICS:
            if m == "speed_loss" and not s["dynamic"]:
                continue
            on = np.array([r[m] for r in s["on"]])
            off = np.array([r[m] for r in s["off"]])
            spread = float(off.std(ddof=1)) if off.size > 1 else math.nan
            rel = (on.mean() - off.mean()) / abs(off.mean()) if off.mean() != 0 else math.nan
            worst = float(np.abs(on - off).max())
            rows.append([s["concentration"], mode, m, float(on.mean()), float(off.mean()),
                         f"{100 * rel:.2g} %", worst / spread if spread > 0 else math.nan])
    return harness.table("Transits with the option on and off",
                         ["A", "ship", "metric", "mean on", "mean off", "relative difference",
                          "largest seed difference / spread"], rows,
                         "spread: standard deviation of the metric across the seeds (option "
                         "off); impulse [N s], resistance [N], energy [J], speed loss [-]")


def speed_table(speed: dict) -> dict:
    return harness.table("ShipNavigation-v0, long brash channel",
                         ["floes", "env steps", "on [steps/s]", "off [steps/s]", "speed-up",
                          "awake at the end", "touching a floe or the hull",
                          "same positions"],
                         [[speed["floes"], speed["steps"], speed["on"], speed["off"],
                           speed["on"] / speed["off"], speed["awake"],
                           speed.get("touching", math.nan),
                           "bit for bit" if speed["identical"]
                           else f"within {speed['max_position_difference']:.2g} m"]],
                         "Awake floes are integrated at every sub-step; those that touch "
                         "nothing drift, and only those touching need the contact time step.")


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    p.add_argument("--seeds", type=int, default=None, help="seeds per case (default 10)")
    p.add_argument("--env-steps", type=int, default=None,
                   help="env steps timed per option (default 100)")
    args, argv = harness.parse(p, argv)
    sizes = dict(QUICK if args.quick else FULL)
    for key in ("seeds", "env_steps"):
        value = getattr(args, key)
        if value is not None:
            if value < 2 and key == "seeds" or value < 1:
                p.error(f"--{key.replace('_', '-')} must be at least {2 if key == 'seeds' else 1}, "
                        f"got {value}")
            sizes[key] = value
    t0 = time.perf_counter()
    speed = env_speed(sizes["env_steps"], args.quiet)
    stats = statistics(sizes["seeds"], sizes["concentrations"], args.quiet)
    record = harness.make_record(
        SUITE, TITLE, DESCRIPTION, harness.command_line(SUITE, argv),
        [speed_table(speed), statistics_table(stats)],
        dict(sizes, quick=args.quick, speed=speed, statistics=stats), time.perf_counter() - t0)
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
