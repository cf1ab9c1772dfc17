"""A short end-to-end run of the Hertz engine: ``python -m physics.demo``.

Herman (2013) set-up at reduced size: floes with a power-law size
distribution (α = 1.8, mean radius 4 m) at Ā = 0.8 in a periodic box, driven
by a 10 m/s wind along x with Coriolis, contacts by the Hertz–Mindlin law.
It prints what it did and how fast, compares the mean drift with the
analytic free drift of eq 6, and draws the floes and the contact-force
network to a PNG.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from .forcing import steady_drift
from .hertz import HertzSimulation
from .params import HERMAN2013


def draw(sim: HertzSimulation, path: Path, title: str) -> None:
    """Floes coloured by speed, contact forces as lines between centres
    (width proportional to the normal force)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection, PatchCollection
    from matplotlib.patches import Circle

    speed = np.hypot(*sim.velocities.T)
    fig, ax = plt.subplots(figsize=(7.5, 7))
    patches = [Circle(xy, r) for xy, r in zip(sim.positions, sim.radius)]
    coll = PatchCollection(patches, cmap="viridis", linewidths=0.2, edgecolors="k")
    coll.set_array(speed)
    ax.add_collection(coll)
    c = sim.contacts()
    if len(c):
        a = sim.positions[c.i]
        b = a + c.branch_i - c.branch_j           # the image of j touching i
        fn = c.normal_force
        lines = LineCollection(np.stack([a, b], axis=1), colors="crimson",
                               linewidths=0.3 + 3.0 * fn / fn.max())
        ax.add_collection(lines)
    ax.set_xlim(0, sim.box.lx)
    ax.set_ylim(0, sim.box.ly)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title, fontsize=10)
    fig.colorbar(coll, ax=ax, label="floe speed [m/s]", shrink=0.8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main(argv=None, prog: str = "python -m physics.demo") -> int:
    p = argparse.ArgumentParser(prog=prog, description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--floes", type=int, default=2000)
    p.add_argument("--concentration", type=float, default=0.8)
    p.add_argument("--duration", type=float, default=1200.0,
                   help="model seconds (the largest floes relax to free drift in about 1300 s)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--out", type=Path, default=Path("runs/demo"))
    args = p.parse_args(argv)
    if args.floes < 10:
        p.error("--floes must be at least 10")
    if args.duration <= 0:
        p.error("--duration must be positive")

    preset = HERMAN2013
    print(f"Hertz engine demo: Herman (2013) set-up, {args.floes} floes, Ā = {args.concentration}")
    t0 = time.perf_counter()
    field, box = preset.floe_field(args.floes, args.concentration, seed=args.seed,
                                   velocity_std=0.01)
    t_place = time.perf_counter() - t0
    print(f"  floe field: box {box.lx:.0f} m × {box.ly:.0f} m, radii {field.radii.min():.2f}–"
          f"{field.radii.max():.1f} m, placed without overlap in {t_place:.2f} s")
    forcing = preset.make_forcing()
    sim = HertzSimulation(field, box, preset.contact, forcing, dt=preset.time_step)
    sim.step(1)                                         # compile (or load the cache)
    t0 = time.perf_counter()
    sim.advance(args.duration, progress=sys.stderr.isatty())
    wall = time.perf_counter() - t0
    steps = sim.n_steps - 1
    m = sim.mass
    u_mean = (m[:, None] * sim.velocities).sum(0) / m.sum()
    u_free = steady_drift(forcing, field.radii, field.thickness, m)
    u_free_mean = (m[:, None] * u_free).sum(0) / m.sum()
    c = sim.contacts()
    in_contact = np.zeros(sim.n_floes, dtype=bool)
    in_contact[c.i] = True
    in_contact[c.j] = True
    print(f"  ran {args.duration:g} model s = {steps} steps of {sim.dt} s in {wall:.2f} s "
          f"({sim.n_floes * steps / wall:.3g} floe-steps/s, {sim.n_rebuilds} neighbour-list rebuilds)")
    print(f"  mass-weighted mean velocity: ({u_mean[0]:+.4f}, {u_mean[1]:+.4f}) m/s; "
          f"free drift of eq 6: ({u_free_mean[0]:+.4f}, {u_free_mean[1]:+.4f}) m/s")
    print(f"  contacts: {len(c)} ({2 * len(c) / sim.n_floes:.2f} per floe), "
          f"{in_contact.mean():.1%} of floes touching; largest overlap "
          f"{(c.overlap / np.minimum(sim.radius[c.i], sim.radius[c.j])).max() if len(c) else 0:.2e} "
          f"of a radius")
    print(f"  kinetic energy {sim.kinetic_energy():.4g} J")
    png = args.out / "hertz_demo.png"
    draw(sim, png, f"{sim.n_floes} floes, Ā = {sim.concentration:.2f}, wind 10 m/s along x, "
                   f"t = {sim.time:.0f} s; red: contact forces")
    print(f"  picture: {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
