"""Collisions per second of the hard-disc engine: ``python -m
benchmarks.bench_harddisk`` (``seaice bench harddisk``).

    python -m benchmarks.bench_harddisk [--seed 1] [--quiet] [--quick] [--json PATH | --no-json]
"""
from __future__ import annotations

import sys
import time

import numpy as np

from physics.domain import PeriodicBox
from physics.floes import FloeField
from physics.forcing import Forcing
from physics.harddisk import HardDiskSimulation
from physics.params import HERMAN2011

from . import harness
from .harness import REPEATS

SUITE = "harddisk"
TITLE = "Hard-disc engine"
DESCRIPTION = """
Collisions per second of the event-driven hard-disc engine on one core,
compile time excluded:

* **elastic equal discs**, N = 10000, packing fraction 0.5, no drag, Gaussian
  velocities of 1 m/s per component, after 5 collisions per disc to lose the
  placement's structure; the best of five runs of 10⁶ collisions each;
* **the Herman (2011) set-up**: N = 3000, α_r = 1.5, mean diameter 2 m,
  Ā = 0.75, wind 10 m/s, ε = 0.85, Δt_max = 1 s, Δt_c = 0.1 s, timed over
  2·10⁵ collisions in the quasi-steady state after 4000 s of model time.
"""
#: the full benchmark's sizes
FULL = dict(gas_floes=10000, gas_collisions=1_000_000, herman_floes=3000, spin_up=4000.0,
            herman_collisions=200_000)
#: sizes of ``--quick``
QUICK = dict(gas_floes=1000, gas_collisions=20_000, herman_floes=300, spin_up=200.0,
             herman_collisions=2000)


def gas_field(n: int, eta: float, seed: int):
    """Equal discs of radius 0.5 m at packing fraction ``eta``, Gaussian
    velocities of 1 m/s per component with zero mean."""
    from physics.floes import place_floes

    r = 0.5
    length = float(np.sqrt(n * np.pi * r * r / eta))
    box = PeriodicBox(length)
    rng = np.random.default_rng(seed)
    pos = place_floes(np.full(n, r), box, rng)
    vel = rng.normal(0.0, 1.0, (n, 2))
    vel -= vel.mean(axis=0)
    return FloeField(pos, np.full(n, r), 1.0, vel), box


def herman_field(n: int, seed: int):
    """The floe field of the Herman (2011) set-up."""
    return HERMAN2011.floe_field(n, 0.75, seed=seed, velocity_std=0.01)


def elastic_sim(field, box) -> HardDiskSimulation:
    """The engine of the elastic gas."""
    return HardDiskSimulation(field, box, restitution=1.0, collision_duration=0.0)


def herman_sim(field, box) -> HardDiskSimulation:
    """The engine of the Herman (2011) set-up (wind, drag, TC model)."""
    P = HERMAN2011
    return HardDiskSimulation(field, box, restitution=P.contact.restitution,
                              forcing=Forcing(P.forcing), max_velocity_step=1.0,
                              collision_duration=0.1)


def time_collisions(sim, min_collisions: int, chunk: float) -> tuple[float, float, int]:
    """Advance in chunks of model time until ``min_collisions`` collisions;
    returns (collisions per wall second, model seconds, collisions)."""
    c0 = sim.collision_count
    t0 = sim.time
    w0 = time.perf_counter()
    while sim.collision_count - c0 < min_collisions:
        sim.advance(chunk)
    wall = time.perf_counter() - w0
    done = sim.collision_count - c0
    return done / wall, sim.time - t0, done


def bench_harddisk(seed: int = 1, quiet: bool = False, gas_floes: int = 10000,
                   gas_collisions: int = 1_000_000, herman_floes: int = 3000,
                   spin_up: float = 4000.0, herman_collisions: int = 200_000) -> list[dict]:
    """Collisions per second of the hard-disc engine (see :data:`DESCRIPTION`)."""
    rows = []
    with harness.Progress(REPEATS + 2, "harddisk", quiet) as bar:
        # warm-up: compile (or load) every kernel on a tiny system
        f, b = gas_field(200, 0.3, seed)
        elastic_sim(f, b).advance(1.0)
        field, box = gas_field(gas_floes, 0.5, seed)
        sim = elastic_sim(field, box)
        sim.advance(1.0)                          # about 5 collisions per disc
        bar.advance()
        best = 0.0
        for _ in range(REPEATS):
            rate, span, done = time_collisions(sim, gas_collisions, 1.0)
            best = max(best, rate)
            bar.advance()
        d = sim.diagnostics
        rows.append(dict(case=f"elastic, N = {gas_floes}, η = 0.5", rate=best, collisions=done,
                         model_time=span, repairs=sim.repairs,
                         crossings_per_collision=d["crossings"] / d["collisions"]))
        bar.log(f"  {rows[-1]['case']}: {best:.3g} collisions/s")

        field, box = herman_field(herman_floes, seed)
        sim = herman_sim(field, box)
        sim.advance(spin_up, progress=not quiet)
        rate, span, done = time_collisions(sim, herman_collisions, 100.0)
        bar.advance()
        m = sim.masses
        u = float((m * sim.velocities[:, 0]).sum() / m.sum())
        d = sim.diagnostics
        rows.append(dict(case=f"Herman 2011, N = {herman_floes}, Ā = 0.75", rate=rate,
                         collisions=done, model_time=span, repairs=sim.repairs,
                         crossings_per_collision=d["crossings"] / d["collisions"],
                         mean_drift=u, spin_up=spin_up))
        bar.log(f"  {rows[-1]['case']}: {rate:.3g} collisions/s, mass-weighted drift "
                f"{u:.3f} m/s")
    return rows


def harddisk_table(rows: list[dict]) -> dict:
    """The table of a :func:`bench_harddisk` result and its notes."""
    body = [[r["case"], float(r["rate"]), r["collisions"], f"{r['model_time']:.4g}",
             f"{r['crossings_per_collision']:.2f}", r["repairs"]] for r in rows]
    notes = [f"Herman (2011) set-up after {r['spin_up'] + r['model_time']:.0f} s: mass-weighted "
             f"mean along-wind velocity {r['mean_drift']:.3f} m/s (paper: about 0.23)"
             for r in rows if "mean_drift" in r]
    return harness.table("Hard-disc engine, one core",
                         ["case", "collisions/s", "collisions timed", "model time [s]",
                          "cell crossings per collision", "repairs"], body, "\n\n".join(notes))


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    p.add_argument("--seed", type=int, default=1)
    args, argv = harness.parse(p, argv)
    sizes = QUICK if args.quick else FULL
    t0 = time.perf_counter()
    rows = bench_harddisk(args.seed, args.quiet, **sizes)
    record = harness.make_record(
        SUITE, TITLE, DESCRIPTION, harness.command_line(SUITE, argv), [harddisk_table(rows)],
        dict(seed=args.seed, rounds=REPEATS, quick=args.quick, sizes=sizes, rows=rows),
        time.perf_counter() - t0)
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
