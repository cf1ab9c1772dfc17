"""Validation report of the Hertz engine against theory: ``python -m physics.validate``.

Prints, for small systems, the measured errors that the test suite bounds:

* undamped head-on impact: peak overlap (5 m* v²/(4k))^{2/5} and contact
  time 3.2181 (m*/k)^{2/5} v^{−1/5};
* damped impacts: restitution against its target over impact speeds from
  1 mm/s to 1 m/s;
* oblique sliding impact: tangential impulse against μ times the normal
  impulse (Coulomb gross sliding);
* an undamped, frictionless gas: momentum and energy drift;
* a lone floe under wind, current and Coriolis: drift against eq 6;
* a ship: restitution of a floe hitting the hull on an edge and on a
  corner, and the resistance of a flat bow in dilute ice against the
  momentum flux (1 + e) ρ h A W v², with every floe in a lane of its own
  (what the tests bound) and in random fields (where floes pushed ahead
  meet others first; reported, not bounded).
"""
from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

from .contact import contact_time, hertz_stiffness, peak_overlap
from .domain import PeriodicBox
from .floes import FloeField, make_floe_field
from .forcing import steady_drift
from .hertz import HertzSimulation
from .params import HERMAN2013, ContactParams

RADIUS = 2.0
THICKNESS, DENSITY = HERMAN2013.thickness, HERMAN2013.forcing.ice_density


def binary_impact(contact: ContactParams, speed: float, angle_deg: float = 0.0,
                  steps_per_contact: int = 1000):
    """Two equal floes meeting at relative speed ``speed``; the relative
    velocity makes ``angle_deg`` with the line of centres. Returns the
    simulation after separation and a record (peak overlap, contact time,
    relative velocity before)."""
    m = DENSITY * THICKNESS * math.pi * RADIUS ** 2
    m_eff, r_eff = 0.5 * m, 0.5 * RADIUS
    k = hertz_stiffness(contact.effective_modulus, r_eff)
    t_c = contact_time(m_eff, k, speed)
    dt = t_c / steps_per_contact
    a = math.radians(angle_deg)
    u_rel = speed * np.array([math.cos(a), math.sin(a)])
    gap = 1e-3 * RADIUS
    pos = np.array([[50.0, 50.0], [50.0 + 2 * RADIUS + gap, 50.0]])
    field = FloeField(pos, [RADIUS, RADIUS], THICKNESS, np.array([0.5 * u_rel, -0.5 * u_rel]),
                      density=DENSITY)
    sim = HertzSimulation(field, PeriodicBox(100.0), contact, None, dt=dt,
                          impact_speed=2 * speed)
    sim.step(int(gap / (speed * math.cos(a)) / dt))
    peak, steps_in, touching, n = 0.0, 0, False, 0
    while n < 20 * steps_per_contact:
        sim.step(1)
        n += 1
        delta = 2 * RADIUS - np.hypot(*(sim.positions[1] - sim.positions[0]))
        if delta > 0:
            touching = True
            steps_in += 1
            peak = max(peak, delta)
        elif touching:
            break
    return sim, dict(peak=peak, contact_time=steps_in * dt, t_c=t_c, k=k, m_eff=m_eff,
                     u_rel=u_rel, dt=dt)


def lane_floes(concentration: float, width: float, x0: float, rng) -> tuple:
    """Floes of radii 1–3 m (thickness 1 m) at rest, each in a lane of its
    own across a channel of ``width`` (no two overlap in y), at random
    places along a band starting at ``x0`` whose length gives the
    concentration. Returns (field, band length)."""
    radii, lanes, y = [], [], 0.0
    while True:
        r = rng.uniform(1.0, 3.0)
        gap = rng.uniform(0.0, 0.5)
        if y + gap + 2 * r > width:
            break
        radii.append(r)
        lanes.append(y + gap + r)
        y += gap + 2 * r
    radii = np.array(radii)
    band = math.pi * np.sum(radii ** 2) / (concentration * width)
    xs = x0 + radii + rng.uniform(0.0, 1.0, radii.size) * (band - 2 * radii)
    return FloeField(np.column_stack([xs, lanes]), radii, 1.0, np.zeros((radii.size, 2))), band


def random_floes(concentration: float, width: float, x0: float, band: float, rng) -> FloeField:
    """Floes of radii 1–3 m at rest placed at random in a band of length
    ``band`` across a channel of ``width``, covering ``concentration`` of it."""
    from .domain import Box
    from .floes import place_floes

    radii = []
    while math.pi * np.sum(np.square(radii)) < concentration * band * width:
        radii.append(rng.uniform(1.0, 3.0))
    radii = np.array(radii)
    pos = place_floes(radii, Box(band, width, periodic=(False, False)), rng)
    pos[:, 0] += x0
    return FloeField(pos, radii, 1.0, np.zeros((radii.size, 2)))


def flat_bow_resistance(concentration: float, seed: int, lanes: bool = True,
                        restitution: float = 0.5, speed: float = 2.0, width: float = 50.0):
    """A flat bow as wide as its channel (W = 50 m, walls at its sides, so
    the bow meets every floe and no corner does) at constant speed through
    floes at rest, no drag. Returns (measured mean resistance over the
    bow's crossing of the band / (1 + e) ρ h A W v², its standard error in
    the same unit, floes the hull touched, floes)."""
    from .domain import ChannelBox
    from .hertz import hull_contact_time
    from .hull import Hull
    from .ship import Ship

    rng = np.random.default_rng(seed)
    x0 = 60.0
    if lanes:
        field, band = lane_floes(concentration, width, x0, rng)
    else:
        band = 400.0
        field = random_floes(concentration, width, x0, band, rng)
    params = ContactParams(elastic_modulus=1e8, restitution=restitution, friction=0.7)
    ship = Ship(Hull.box(20.0, width), 1e9, position=(30.0, 0.5 * width), speed=speed)
    t_c = hull_contact_time(field.radii, 1.0, field.density, params, 2 * speed)
    sim = HertzSimulation(field, ChannelBox(x0 + band + 200.0, width), params, None, t_c / 20,
                          impact_speed=2 * speed, ship=ship)
    bow = 40.0
    t_in, t_out = (x0 - bow) / speed, (x0 + band - bow) / speed
    sim.advance(t_out + 2.0)
    loads = sim.ship_loads(start=t_in, end=t_out)
    area = math.pi * np.sum(field.radii ** 2) / (band * width)
    expected = (1 + restitution) * field.density * 1.0 * area * width * speed ** 2
    return (loads.resistance / expected, loads.resistance_error / expected,
            loads.collided_floes, field.n)


def hull_impact_restitution(feature: str, restitution: float, speed: float = 0.5) -> float:
    """A floe (radius 1 m) hits a fixed hull head-on on the middle of a
    flat bow ("edge") or on the stem of a pointed bow ("vertex");
    returns its rebound speed / approach speed."""
    from .hertz import hull_contact_time
    from .hull import Hull
    from .ship import Ship

    hull = Hull.box(10.0, 4.0) if feature == "edge" else Hull.pointed(10.0, 4.0)
    bow = hull.vertices[:, 0].max()
    one = FloeField(np.array([[30.0 + bow + 1.05, 30.0]]), [1.0], 1.0,
                    np.array([[-speed, 0.0]]))
    params = ContactParams(elastic_modulus=1e8, restitution=restitution, friction=0.0)
    t_c = hull_contact_time(one.radii, 1.0, one.density, params, speed)
    sim = HertzSimulation(one, PeriodicBox(60.0), params, None, t_c / 1000, impact_speed=speed,
                          ship=Ship(hull, 1e6, position=(30.0, 30.0)))
    sim.advance(0.05 / speed + 3.0 * t_c)
    return float(sim.velocities[0, 0] / speed)


def report() -> list[tuple[str, str, str]]:
    rows = []
    # 1. undamped head-on impact
    c = ContactParams(restitution=1.0, friction=0.0)
    worst_peak = worst_tc = 0.0
    for v in (0.01, 0.1, 1.0):
        _, r = binary_impact(c, v)
        worst_peak = max(worst_peak, abs(r["peak"] / peak_overlap(r["m_eff"], r["k"], v) - 1))
        worst_tc = max(worst_tc, abs(r["contact_time"] / r["t_c"] - 1))
    rows.append(("undamped impact, peak overlap", "< 1 %", f"{worst_peak:.1e}"))
    rows.append(("undamped impact, contact time", "< 1 %", f"{worst_tc:.1e} (1 step = 1e-3)"))
    # 2. restitution over three decades of speed
    for e in (0.1, 0.5, 0.85):
        c = ContactParams(restitution=e, friction=0.0)
        errs = []
        for v in (1e-3, 1e-2, 1e-1, 1.0):
            sim, r = binary_impact(c, v)
            u_after = sim.velocities[0] - sim.velocities[1]
            errs.append(abs(-u_after[0] / r["u_rel"][0] - e))
        rows.append((f"restitution e = {e}, 1 mm/s to 1 m/s", "< 1e-3", f"{max(errs):.1e}"))
    # 3. Coulomb sliding: tangential impulse = mu * normal impulse
    mu, e = 0.4, 0.5
    sim, r = binary_impact(ContactParams(restitution=e, friction=mu), 0.1, angle_deg=75.0)
    m = sim.masses[0]
    du = (sim.velocities[0] - sim.velocities[1]) - r["u_rel"]
    j_n, j_t = 0.5 * m * abs(du[0]), 0.5 * m * abs(du[1])
    rows.append(("oblique sliding impact, J_t / (μ J_n) − 1", "< 3 %", f"{j_t / (mu * j_n) - 1:+.1e}"))
    spin = sim.angular_velocities[0]
    spin_expected = -j_t * RADIUS / (0.5 * m * RADIUS ** 2)
    rows.append(("oblique sliding impact, spin error", "< 3 %", f"{spin / spin_expected - 1:+.1e}"))
    # 4. elastic gas
    field, box = make_floe_field(100, concentration=0.45, alpha=1.8, mean_diameter=4.0, seed=3,
                                 velocity_std=0.2)
    c = ContactParams(restitution=1.0, friction=0.0)
    m = field.masses
    r_small = field.radii.min()
    k = hertz_stiffness(c.effective_modulus, 0.5 * r_small)
    t_c = contact_time(0.5 * m.min(), k, 1.0)
    sim = HertzSimulation(field, box, c, None, dt=t_c / 20, impact_speed=1.0)

    def energy():
        cs = sim.contacts()
        r_eff = sim.radii[cs.i] * sim.radii[cs.j] / (sim.radii[cs.i] + sim.radii[cs.j])
        pot = 0.4 * hertz_stiffness(c.effective_modulus, r_eff) * cs.overlap ** 2.5
        return sim.kinetic_energy() + pot.sum()

    p0, e0, scale = sim.momentum(), energy(), np.abs(m[:, None] * field.velocities).sum()
    energies = []
    for _ in range(100):
        sim.step(200)
        energies.append(energy())
    rows.append(("elastic gas, momentum drift / Σ|m u|", "< 1e-12",
                 f"{np.abs(sim.momentum() - p0).max() / scale:.1e}"))
    rows.append(("elastic gas, energy drift (Δt = t_c/20, 2e4 steps)", "< 1e-3",
                 f"{np.max(np.abs(np.array(energies) / e0 - 1)):.1e}"))
    # 5. lone floe drift
    forcing = HERMAN2013.make_forcing(current=(0.05, 0.02))
    one = FloeField(np.array([[50.0, 50.0]]), [5.0], 1.5, density=HERMAN2013.forcing.ice_density)
    sim = HertzSimulation(one, PeriodicBox(100.0), HERMAN2013.contact, forcing, dt=0.003)
    sim.advance(20000.0)                    # about 20 relaxation times m/b
    u_eq = steady_drift(forcing, one.radii, one.thickness, one.masses)[0]
    rows.append(("lone floe drift, wind + current + Coriolis (eq 6)", "< 0.1 %",
                 f"{np.hypot(*(sim.velocities[0] - u_eq)) / np.hypot(*u_eq):.1e}"))
    # 6. the ship
    for feature in ("edge", "vertex"):
        worst = max(abs(hull_impact_restitution(feature, e) - e) for e in (0.3, 0.5, 0.9))
        rows.append((f"hull impact on {'an edge' if feature == 'edge' else 'a corner'}, "
                     f"restitution e = 0.3, 0.5, 0.9", "< 1e-3", f"{worst:.1e}"))
    for a in (0.02, 0.05):
        ratio, err, touched, n = flat_bow_resistance(a, 11, lanes=True)
        rows.append((f"flat bow, A = {a}, floes in lanes: R / (1+e)ρhAWv² − 1", "< 5 %",
                     f"{ratio - 1:+.1e} ({touched}/{n} floes met)"))
    for a in (0.02, 0.05):
        out = [flat_bow_resistance(a, seed, lanes=False) for seed in (1, 2, 3)]
        ratios = ", ".join(f"{r - 1:+.2f} ± {e:.2f}" for r, e, _, _ in out)
        met = ", ".join(f"{t}/{n}" for _, _, t, n in out)
        rows.append((f"flat bow, A = {a}, random floes (3 seeds): R / (1+e)ρhAWv² − 1",
                     "reported", f"{ratios} (floes met {met})"))
    return rows


def main(argv=None, prog: str = "python -m physics.validate") -> int:
    argparse.ArgumentParser(prog=prog, description=__doc__,
                            formatter_class=argparse.RawDescriptionHelpFormatter).parse_args(argv)
    t0 = time.perf_counter()
    rows = report()
    print("| check | tolerance | measured |")
    print("|---|---|---|")
    for name, tol, val in rows:
        print(f"| {name} | {tol} | {val} |")
    print(f"\n({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
