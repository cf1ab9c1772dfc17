"""What the ship's sensors cost: ``python -m benchmarks.bench_sensors``
(``seaice bench sensors``).

    python -m benchmarks.bench_sensors [--concentrations 0.2 0.3 0.4 0.5] [--seed 1]
                                 [--calls 2000] [--quiet] [--quick] [--json PATH | --no-json]
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from . import harness

SUITE = "sensors"
TITLE = "Ship sensors"
DESCRIPTION = """
Wall time of one call of each sensor of the ship environments, on the ice
field of `iceenvs/ShipNavigation-v1` at each concentration (seeded), with
the ship after 60 steps of the straight line (120 m, its bow in the ice),
each called as the environment calls it: the sector lidar (the compiled
`lidar_scan` of `ice_lidar`, v1's 15 sectors over the half-disc ahead,
250 m), the swath sensor (v1's measurement of it, the compiled
`swath_scan` of `ice_swath`: 9 courses over ±40°, bands 0-100 m and
100-250 m, weighted by the floes' expected impulses) and the egocentric
image (the environment's `occupancy_image`, 64 × 64 pixels of 150 m, with
its argument checks). Each is timed as the best of
five loops of `--calls` calls after a warm-up loop (compilation excluded;
the kernels are serial). The costmap (`ShipEnv.costmap`, the compiled
`costmap_scan` of `iceenvs.costmap`: 5 m cells from 20 m behind the ship
to 300 m ahead, the channel's width across) is timed likewise, and again
reaching 500 m ahead (`costmap_ahead=500`, an environment of its own on
the same field sailed alike). Beside them, the mean wall time of the next 30
environment steps (a zero action) of the same field, the lidar's and
the swath's share of it (v1's vector observation computes both once a
step, the image only with `obs_type="image"` or `"dict"`), and the
costmap's (once a step with `obs_type="costmap"` or `"costmap_dict"`,
once a decision for the waypoint learner).
"""

#: sizes of ``--quick``
QUICK = dict(concentrations=[0.2], calls=50, steps=3)
#: straight-line steps before the timing: the ship 120 m on, its bow in the ice
SAIL_IN = 60
#: the reach [m] ahead of the second costmap timed (the lattice planner's horizon)
FAR_AHEAD = 500.0


def bench_sensors(concentrations=(0.2, 0.3, 0.4, 0.5), seed: int = 1, calls: int = 2000,
                  steps: int = 30, quiet: bool = False) -> list[dict]:
    """Per-call wall times [s] of the sensors and of a step (see :data:`DESCRIPTION`)."""
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the ids)

    rows = []
    bar = harness.Progress(len(concentrations) * 6, "sensors", quiet)
    with bar:
        for a in concentrations:
            env = gym.make("iceenvs/ShipNavigation-v1", concentration=float(a))
            far = gym.make("iceenvs/ShipNavigation-v1", concentration=float(a),
                           costmap_ahead=FAR_AHEAD)
            try:
                for e in (env, far):
                    e.reset(seed=seed)
                    zero = np.zeros(e.action_space.shape, e.action_space.dtype)
                    for _ in range(SAIL_IN):
                        e.step(zero)
                row = dict(concentration=float(a), floes=int(env.unwrapped.sim.radii.size))
                calls_of = {**_sensor_calls(env.unwrapped), "costmap_far": far.unwrapped.costmap}
                for name, call in calls_of.items():
                    def loop(call=call):
                        for _ in range(calls):
                            call()
                    row[name] = harness.best_time(loop) / calls
                    bar.advance()
                t0 = time.perf_counter()
                for _ in range(steps):
                    env.step(zero)
                row["step"] = (time.perf_counter() - t0) / steps
                bar.advance()
            finally:
                env.close()
                far.close()
            rows.append(row)
            bar.log(f"  A = {a:g}: lidar {row['lidar'] * 1e6:.3g} µs, swath "
                    f"{row['swath'] * 1e6:.3g} µs, image {row['image'] * 1e6:.3g} µs, costmap "
                    f"{row['costmap'] * 1e6:.3g} µs ({row['costmap_far'] * 1e6:.3g} µs to "
                    f"{FAR_AHEAD:g} m), "
                    f"step {row['step'] * 1e3:.3g} ms")
    return rows


def _sensor_calls(u) -> dict:
    """{name: call} of each sensor of the ship environment ``u`` (unwrapped)
    on its present state: the swath and the image through the
    environment's own methods, the lidar, which the environment calls
    inside its compiled measurements, with the arguments they pass."""
    from iceenvs.ship_sensors import lidar_scan, scan_box

    sim = u.sim
    box = sim.box
    pose = sim.ship.motion                  # x, y and heading first, as a ship row of the measurements
    setting = np.array([u.lidar_sectors, math.pi, u.lidar_range])
    packed_box = scan_box(float(box.lx), float(box.ly), box.periodic)
    return {
        "lidar": lambda: lidar_scan(pose, sim.positions, sim.radii, setting, packed_box),
        "swath": lambda: u.extra_values([u]),
        "image": u._image,
        "costmap": u.costmap,
    }


def sensors_table(rows: list[dict]) -> dict:
    """The table of a :func:`bench_sensors` result."""
    return harness.table(
        "Ship sensors on the fields of ShipNavigation-v1, one call",
        ["A", "floes", "lidar [µs]", "swath [µs]", "image [µs]", "costmap [µs]",
         f"costmap to {FAR_AHEAD:g} m [µs]", "env step [ms]", "lidar + swath / step",
         "costmap / step", f"costmap to {FAR_AHEAD:g} m / step"],
        [[r["concentration"], r["floes"], r["lidar"] * 1e6, r["swath"] * 1e6,
          r["image"] * 1e6, r["costmap"] * 1e6, r["costmap_far"] * 1e6, r["step"] * 1e3,
          (r["lidar"] + r["swath"]) / r["step"], r["costmap"] / r["step"],
          r["costmap_far"] / r["step"]]
         for r in rows])


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    p.add_argument("--concentrations", type=float, nargs="+", default=[0.2, 0.3, 0.4, 0.5])
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--calls", type=int, default=2000, help="calls per timed loop")
    args, argv = harness.parse(p, argv)
    if args.calls < 1:
        p.error("--calls must be at least 1")
    if any(not 0.0 < a <= 0.9 for a in args.concentrations):
        p.error("--concentrations must lie in (0, 0.9]")
    conc, calls, steps = ((QUICK["concentrations"], QUICK["calls"], QUICK["steps"])
                          if args.quick else (args.concentrations, args.calls, 30))
    t0 = time.perf_counter()
    rows = bench_sensors(conc, args.seed, calls, steps, quiet=args.quiet)
    record = harness.make_record(
        SUITE, TITLE, DESCRIPTION, harness.command_line(SUITE, argv), [sensors_table(rows)],
        dict(seed=args.seed, calls=calls, steps=steps, quick=args.quick, rows=rows),
        time.perf_counter() - t0)
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
