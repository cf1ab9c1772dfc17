"""Two short runs of the Hertz engine, with a figure each: ``python -m physics.demo``.

1. Force chains. 200 floes of the Herman (2013) power-law sizes (α = 1.8)
   at Ā = 0.85 fill a square channel with rigid walls at x = 0 and x = L
   (periodic in y), at rest; a steady wind of 20 m/s along +x (no
   Coriolis, no current) drives them against the wall at x = L. Within a
   few model minutes the pack
   jams and comes to rest, and the wind's push reaches the wall through
   chains of floes that carry most of the force, while the floes beside
   them carry little. The demo prints the contacts per floe and checks the
   force balance of the pack at rest: the sum of all contact forces (the
   floe–floe forces cancel pairwise, so it is the push of the walls) must
   cancel the wind force on the ice, Σ a |u_a| u_a. It draws the floes,
   the walls, the wind and the contact-force network (line width ∝ normal
   force, with a legend of the widths of a few forces; wall contacts
   included).
2. A ship transit. The platform supply vessel of :func:`physics.ship.psv_ship`
   (76 m × 18 m) sails at a prescribed 2 m/s through a 200 m band of
   floes at Ā = 0.5 in a 500 m × 150 m transit channel (the README's
   example). The demo prints the ice loads (:meth:`HertzSimulation.ship_loads`
   after the bow has reached the ice; the ± of the mean resistance is its
   standard error, from the means of 20 consecutive blocks of time) and
   draws the floes, the hull and its track beside the ice resistance
   against time.

Both runs take seconds once the kernels are compiled (``python -m
iceenvs.warmup``).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from .engine import FloeEngine
from .floes import PlacementError
from .hertz import HertzSimulation, hertz_time_step
from .params import HERMAN2013
from .ice_fields import TransitBox, transit_field
from .ship import psv_ship

__all__ = ["force_chains", "wall_force", "wind_force", "draw", "chain_width", "chain_samples",
           "ship_transit", "draw_transit", "error_meaning", "main"]

#: the transit of the README: channel, ice band, concentration, ship start and speed
TRANSIT = dict(length=500.0, width=150.0, band=(150.0, 350.0), concentration=0.5,
               position=(50.0, 75.0), speed=2.0, dt=0.001)
#: the ship's loads are averaged from this time on [s] (its bow reaches the ice at ~31 s)
LOADS_START = 50.0


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path: Path) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    _pyplot().close(fig)


def _frame(ax, box, title: str) -> None:
    """The box as the limits of a map in metres, to scale."""
    ax.set_xlim(0, box.lx)
    ax.set_ylim(0, box.ly)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title, fontsize=9)


def _advance(sim: FloeEngine, duration: float, progress: bool) -> float:
    """Advance and return the wall time [s]."""
    t0 = time.perf_counter()
    sim.advance(duration, progress=progress)
    return time.perf_counter() - t0


# -- 1. force chains ----------------------------------------------------------------------
def force_chains(n_floes: int = 200, concentration: float = 0.85, wind: float = 20.0,
                 seed: int | None = 1) -> HertzSimulation:
    """``n_floes`` floes of the Herman (2013) sizes at rest in a square
    channel with walls at x = 0 and x = L (periodic in y), and a wind of
    ``wind`` m/s along +x without Coriolis or current (advance it to press
    them on the wall)."""
    preset = HERMAN2013
    field, box = preset.floe_field(n_floes, concentration, seed=seed, box_type=TransitBox)
    forcing = preset.make_forcing(wind=(wind, 0.0), current=(0.0, 0.0), coriolis=0.0)
    # the stiffer wall contact is shorter than the preset's time step allows
    # for; the pack is dense, and no floe of the default run passes 0.09 m/s,
    # so the engine's default impact speed of 0.1 m/s holds
    dt = hertz_time_step(field, box, preset.contact, 0.1, preset.time_step, 1.0)
    return HertzSimulation(field, box, preset.contact, forcing, dt=dt)


def wind_force(sim: HertzSimulation) -> np.ndarray:
    """Total air drag on the floes, Σ a |u_a| u_a (2,) [N] (Herman 2011,
    eq 6; the ice's own speed is neglected against the wind's, as there)."""
    k = sim.forcing.coefficients(sim.radii, sim.field.thickness, sim.masses)
    u_a = np.asarray(sim.forcing.wind, dtype=float)
    return float(np.sum(k.wind)) * float(np.hypot(*u_a)) * u_a


def _wall_forces(sim: HertzSimulation) -> np.ndarray:
    """(N, 2) force of the walls on every floe [N]: all contact forces
    minus the floe–floe ones."""
    total, _ = sim.contact_forces()
    c = sim.contacts()
    pair = np.zeros_like(total)
    np.add.at(pair, c.i, c.force)
    np.add.at(pair, c.j, -c.force)
    return total - pair


def wall_force(sim: HertzSimulation) -> np.ndarray:
    """Total force of the walls on the ice (2,) [N]: the sum of all contact
    forces, in which the floe–floe forces cancel pairwise."""
    total, _ = sim.contact_forces()
    return total.sum(axis=0)


def _force_text(f: float) -> str:
    """A force [N] in N, kN or MN."""
    for unit, scale in (("MN", 1e6), ("kN", 1e3)):
        if abs(f) >= scale:
            return f"{f / scale:g} {unit}"
    return f"{f:g} N"


def _round_down(x: float) -> float:
    """The largest of 1, 2 and 5 times a power of ten not above ``x`` (> 0)."""
    power = 10.0 ** np.floor(np.log10(x))
    return max(m * power for m in (1.0, 2.0, 5.0) if m * power <= x * (1 + 1e-9))


#: a chain line's width [pt] at zero force and its growth up to the largest force
CHAIN_WIDTH = (0.3, 3.0)


def chain_width(force, largest: float) -> np.ndarray:
    """Width [pt] of the line of a contact carrying ``force`` [N] in a
    picture whose largest contact force is ``largest`` [N]: proportional
    to the force, from 0.3 pt at none to 3.3 pt at the largest."""
    return CHAIN_WIDTH[0] + CHAIN_WIDTH[1] * np.asarray(force, dtype=float) / largest


def chain_samples(largest: float) -> list[float]:
    """Two or three round forces [N] up to ``largest`` whose line widths
    the legend of :func:`draw` shows."""
    samples = []
    for part in (1.0, 0.3, 0.05):
        f = _round_down(part * largest)
        if not samples or f < 0.6 * samples[-1]:
            samples.append(f)
    return samples


def draw(sim: HertzSimulation, path: Path, title: str) -> None:
    """Floes coloured by speed, contact forces as lines between centres
    and, in a box with walls, from the centre to the wall (width
    proportional to the normal force; the legend shows the widths of a few
    round forces), the walls (hatched beyond them) and the wind (an arrow
    with its speed)."""
    plt = _pyplot()
    from matplotlib.collections import LineCollection, PatchCollection
    from matplotlib.lines import Line2D
    from matplotlib.patches import Circle, FancyBboxPatch, Patch, Rectangle

    speed = np.hypot(*sim.velocities.T)
    fig, ax = plt.subplots(figsize=(7.5, 7.2))
    patches = [Circle(xy, r) for xy, r in zip(sim.positions, sim.radii)]
    coll = PatchCollection(patches, cmap="viridis", linewidths=0.2, edgecolors="k")
    coll.set_array(speed)
    ax.add_collection(coll)
    c = sim.contacts()
    segments = [np.zeros((0, 2, 2))]
    forces = [np.zeros(0)]
    if len(c):
        a = sim.positions[c.i]
        segments.append(np.stack([a, a + c.branch_i - c.branch_j], axis=1))  # j's image touching i
        forces.append(c.normal_force)
    if not all(sim.box.periodic):
        wall = _wall_forces(sim)
        f = np.hypot(*wall.T)
        on = f > 1e-9 * max(f.max(), 1.0)
        a = sim.positions[on]
        tip = a - sim.radii[on, None] * wall[on] / f[on, None]     # the point on the wall
        segments.append(np.stack([a, tip], axis=1))
        forces.append(f[on])
    segments, forces = np.concatenate(segments), np.concatenate(forces)
    handles = []
    if forces.size and forces.max() > 0:
        largest = float(forces.max())
        ax.add_collection(LineCollection(segments, colors="crimson",
                                         linewidths=chain_width(forces, largest)))
        handles += [Line2D([], [], color="crimson", lw=float(chain_width(f, largest)),
                           label=f"contact force {_force_text(f)}")
                    for f in chain_samples(largest)]
    _frame(ax, sim.box, title)
    box = sim.box
    margin = 0.04 * max(box.lx, box.ly)
    walls = [(axis, at) for axis, periodic in enumerate(box.periodic) if not periodic
             for at in (0.0, (box.lx, box.ly)[axis])]
    for axis, at in walls:
        beyond = -margin if at == 0.0 else at
        if axis == 0:
            ax.add_patch(Rectangle((beyond, 0.0), margin, box.ly, fc="0.85", ec="0.4",
                                   hatch="//", lw=0))
            ax.axvline(at, color="0.15", lw=3)
        else:
            ax.add_patch(Rectangle((0.0, beyond), box.lx, margin, fc="0.85", ec="0.4",
                                   hatch="//", lw=0))
            ax.axhline(at, color="0.15", lw=3)
    if walls:
        ax.set_xlim(-margin if not box.periodic[0] else 0.0,
                    box.lx + (margin if not box.periodic[0] else 0.0))
        ax.set_ylim(-margin if not box.periodic[1] else 0.0,
                    box.ly + (margin if not box.periodic[1] else 0.0))
        handles.append(Patch(fc="0.85", ec="0.15", hatch="//", label="rigid wall"))
    wind = np.asarray(sim.forcing.wind, dtype=float)
    wind_speed = float(np.hypot(*wind))
    if wind_speed > 0:
        u = wind / wind_speed
        centre = np.array([0.1, 0.93])                      # axes fraction, upper left
        ax.add_patch(FancyBboxPatch((0.02, 0.825), 0.16, 0.165, boxstyle="round,pad=0.005",
                                    transform=ax.transAxes, fc="white", ec="navy", lw=0.8,
                                    alpha=0.9, zorder=4))
        ax.annotate("", xy=centre + 0.06 * u, xytext=centre - 0.06 * u, xycoords="axes fraction",
                    arrowprops=dict(arrowstyle="-|>,head_width=0.5,head_length=0.9",
                                    color="navy", lw=2.5), zorder=5)
        ax.text(centre[0], centre[1] - 0.07, f"wind {wind_speed:g} m/s", ha="center", va="top",
                transform=ax.transAxes, fontsize=9, color="navy", zorder=5)
    if handles:
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.09),
                  ncol=len(handles), fontsize=8, frameon=False,
                  title="line width ∝ normal force", title_fontsize=8)
    from mpl_toolkits.axes_grid1 import make_axes_locatable

    bar = make_axes_locatable(ax).append_axes("right", size="4%", pad=0.15)
    fig.colorbar(coll, cax=bar, label="floe speed [m/s]")
    fig.tight_layout()
    _save(fig, path)


# -- 2. ship transit --------------------------------------------------------------------------
def ship_transit(seed: int | None = 1) -> HertzSimulation:
    """The transit of :data:`TRANSIT`: the PSV at its start, the ice band at rest."""
    t = TRANSIT
    field, box = transit_field(HERMAN2013, concentration=t["concentration"], band=t["band"],
                               length=t["length"], width=t["width"], seed=seed)
    ship = psv_ship(position=t["position"], speed=t["speed"])
    return HertzSimulation(field, box, HERMAN2013.contact, dt=t["dt"], ship=ship)


def error_meaning(samples: int) -> str:
    """What the ± of a mean ice resistance of :meth:`HertzSimulation.ship_loads`
    over ``samples`` engine steps is (:meth:`physics.ship.ShipState.statistics`):
    the standard error of the mean, from the means of consecutive blocks."""
    return f"standard error of the mean, from {min(20, samples)} consecutive time blocks"


def draw_transit(sim: HertzSimulation, path: Path, title: str, *,
                 loads_start: float = LOADS_START, every: float = 50.0) -> None:
    """Left: the floes (orange: those the hull hit), the ice band, the
    track of the ship's centroid and its hull now and every ``every``
    seconds before. Right: the ice resistance (ice force against surge)
    and the sum of the normal forces on the hull against time, in means
    over 1 s, with the mean resistance after ``loads_start``."""
    plt = _pyplot()
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle, Polygon, Rectangle

    rec = sim.ship.records()
    hit = np.zeros(sim.n_floes, dtype=bool)
    hit[np.unique(sim.ship.collisions()["floe"])] = True
    hull = sim.ship.ship.hull
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(13, 4.6),
                                  gridspec_kw=dict(width_ratios=[1.6, 1]))
    band = getattr(sim.box, "band", None)
    if band is not None:
        ax.add_patch(Rectangle((band[0], 0.0), band[1] - band[0], sim.box.ly, color="lightblue",
                               alpha=0.3, lw=0, label="ice band at the start"))
    ax.add_collection(PatchCollection([Circle(xy, r) for xy, r in zip(sim.positions, sim.radii)],
                                      facecolors=np.where(hit, "tab:orange", "lightsteelblue"),
                                      edgecolors="k", linewidths=0.3))
    t = rec["time"]
    if t.size:
        ax.plot(rec["x"], rec["y"], color="k", lw=1, ls="--", label="track of the centroid")
        for when in np.arange(0.0, t[-1] - 0.5 * every, every):
            k = min(int(np.searchsorted(t, when)), t.size - 1)
            ax.add_patch(Polygon(hull.world_vertices(rec["x"][k], rec["y"][k], rec["heading"][k]),
                                 closed=True, fc="none", ec="crimson", lw=0.6, alpha=0.6))
    ax.add_patch(Polygon(sim.ship.vertices, closed=True, fc="crimson", ec="k", lw=0.8,
                         label=f"hull at t = {sim.time:.0f} s (outlines every {every:g} s)"))
    _frame(ax, sim.box, title)
    ax.legend(loc="upper left", fontsize=7)

    if t.size:
        per = max(1, int(round(1.0 / float(np.median(np.diff(t)))))) if t.size > 1 else 1
        per = min(per, t.size)                  # samples per bin: 1 s, or all of a shorter run
        n = t.size - t.size % per

        def binned(x):
            return x[:n].reshape(-1, per).mean(axis=1)

        tb = binned(t)
        ax2.plot(tb, binned(rec["normal_force"]) / 1e3, color="0.6", lw=1,
                 label="sum of the normal forces on the hull")
        ax2.plot(tb, -binned(rec["ice_surge"]) / 1e3, color="crimson", lw=1.2,
                 label="ice resistance (ice force against surge)")
        if t[-1] > loads_start:
            loads = sim.ship_loads(start=loads_start)
            ax2.axhline(loads.resistance / 1e3, color="crimson", ls=":", lw=1,
                        label=f"mean resistance after {loads_start:g} s: "
                              f"{loads.resistance / 1e3:.1f} ± "
                              f"{loads.resistance_error / 1e3:.1f} kN\n"
                              f"(± {error_meaning(int(np.sum(t > loads_start)))})")
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel("force, means over 1 s [kN]")
    ax2.legend(fontsize=7, loc="upper left")
    ax2.set_title("ice loads on the hull", fontsize=9)
    fig.tight_layout()
    _save(fig, path)


# -- the command ---------------------------------------------------------------------------
def build_parser(prog: str) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog=prog, description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    g = p.add_argument_group("force chains")
    g.add_argument("--floes", type=int, default=200, help="number of floes (default 200)")
    g.add_argument("--concentration", type=float, default=0.85,
                   help="ice concentration at the start, in (0, 0.9] (default 0.85)")
    g.add_argument("--wind", type=float, default=20.0, help="wind speed [m/s] (default 20)")
    g.add_argument("--duration", type=float, default=300.0,
                   help="model seconds (default 300: the pack is at rest by then)")
    g = p.add_argument_group("ship transit")
    g.add_argument("--ship-duration", type=float, default=150.0,
                   help="model seconds of the transit (default 150: through the band; "
                        "0 skips the transit)")
    p.add_argument("--seed", type=int, default=1, help="seed of the floe fields (default 1)")
    p.add_argument("--out", type=Path, default=Path("runs/demo"),
                   help="directory of the figures (default runs/demo)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bars")
    return p


def main(argv=None, prog: str = "python -m physics.demo") -> int:
    p = build_parser(prog)
    args = p.parse_args(sys.argv[1:] if argv is None else argv)
    if args.floes < 10:
        p.error(f"--floes must be at least 10, got {args.floes}")
    for name in ("wind", "duration"):
        if not getattr(args, name) > 0:
            p.error(f"--{name} must be positive, got {getattr(args, name)}")
    if not 0.0 < args.concentration <= 0.9:
        p.error(f"--concentration must lie in (0, 0.9], got {args.concentration}")
    if not args.ship_duration >= 0:
        p.error(f"--ship-duration must be >= 0, got {args.ship_duration}")
    progress = not args.no_progress and sys.stderr.isatty()
    t_start = time.perf_counter()

    print(f"1. Force chains: wind {args.wind:g} m/s along +x presses floes of the Herman (2013) "
          f"sizes against a wall", flush=True)
    t0 = time.perf_counter()
    try:
        sim = force_chains(args.floes, args.concentration, args.wind, args.seed)
    except PlacementError as err:
        p.error(f"--floes {args.floes} --concentration {args.concentration}: {err}; try a "
                f"lower --concentration or more --floes")
    print(f"   {sim.n_floes} floes at Ā = {sim.concentration:.2f} in a channel "
          f"{sim.box.lx:.0f} m × {sim.box.ly:.0f} m (walls at x = 0 and {sim.box.lx:.0f} m, "
          f"periodic in y), placed in {time.perf_counter() - t0:.1f} s", flush=True)
    sim.step(1)                                         # compile (or load the cache)
    seconds = _advance(sim, args.duration, progress)
    steps = sim.n_steps - 1
    c = sim.contacts()
    touching = np.zeros(sim.n_floes, dtype=bool)
    touching[c.i] = touching[c.j] = True
    largest = (c.overlap / np.minimum(sim.radii[c.i], sim.radii[c.j])).max() if len(c) else 0.0
    push, back = wind_force(sim)[0], wall_force(sim)[0]
    print(f"   ran {args.duration:g} model s = {steps} steps of {sim.dt:g} s in {seconds:.1f} s "
          f"({sim.n_floes * steps / seconds:.3g} floe-steps/s); fastest floe now "
          f"{np.hypot(*sim.velocities.T).max():.2g} m/s")
    print(f"   contacts: {len(c)} floe pairs, {2 * len(c) / sim.n_floes:.2f} per floe, "
          f"{touching.mean():.0%} of floes touching another; largest overlap {largest:.1e} of "
          f"a radius")
    print(f"   force balance along x: the wind pushes the ice with {push / 1e3:.1f} kN, the walls "
          f"push back with {-back / 1e3:.1f} kN ({abs(push + back) / abs(push):.1%} apart: the "
          f"drag and inertia of floes still moving)")
    png = args.out / "force_chains.png"
    draw(sim, png, f"{sim.n_floes} floes, wind {args.wind:g} m/s along +x, t = {sim.time:.0f} s; "
                   f"red lines: contact forces")
    print(f"   picture: {png}", flush=True)

    if args.ship_duration > 0:
        print(f"2. Ship transit: a 76 m supply vessel at {TRANSIT['speed']:g} m/s through a band "
              f"of ice at Ā = {TRANSIT['concentration']:g}", flush=True)
        sim = ship_transit(args.seed)
        sim.step(1)
        seconds = _advance(sim, args.ship_duration, progress)
        steps = sim.n_steps - 1
        print(f"   {sim.n_floes} floes in a channel {sim.box.lx:g} m × {sim.box.ly:g} m; ran "
              f"{args.ship_duration:g} model s = {steps} steps of {sim.dt:g} s in {seconds:.1f} s")
        if sim.time > LOADS_START:
            loads = sim.ship_loads(start=LOADS_START)
            samples = int(np.sum(sim.ship.records()["time"] > LOADS_START))
            print(f"   after {LOADS_START:g} s: {loads.distance:.0f} m sailed, mean ice resistance "
                  f"{loads.resistance / 1e3:.1f} ± {loads.resistance_error / 1e3:.1f} kN "
                  f"(± {error_meaning(samples)}), "
                  f"{loads.collisions} collisions with {loads.collided_floes} floes, largest "
                  f"impulse {loads.max_impulse / 1e3:.0f} kN s, {loads.energy_to_ice / 1e6:.2f} MJ "
                  f"given to the ice")
        png = args.out / "ship_transit.png"
        draw_transit(sim, png, f"PSV 76 m × 18 m at {TRANSIT['speed']:g} m/s through "
                               f"{sim.n_floes} floes (Ā = {TRANSIT['concentration']:g} in the "
                               f"band); orange: floes it hit")
        print(f"   picture: {png}", flush=True)
    print(f"engine demo done in {time.perf_counter() - t_start:.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
