"""Floes at rest cost nothing (``HertzSimulation(skip_resting=True)``,
:mod:`physics.hertz_resting`): the same run as the full step, with the
resting floes woken by a floe, the hull and a wall, and nothing at rest
under wind.

The two paths do the same arithmetic on the awake floes; a resting floe
would come out of the full step unchanged. Only the sums of the
displacements in the Verlet list's expiry test are added in another order,
so the bound of the comparisons is rounding: 1e-12 m, 1e-12 m/s (and
relative 1e-12 for forces)."""
from __future__ import annotations

import numpy as np
import pytest

from physics import ContactParams, Forcing, HertzSimulation
from physics.domain import ChannelBox, PeriodicBox, WalledBox
from physics.floes import FloeField, make_floe_field
from physics.hertz import hull_contact_time
from physics.hull import Hull
from physics.params import HERMAN2013
from physics.ship import Ship

# rounding of the same arithmetic (see the module docstring)
TOL = 1e-12
CONTACT = ContactParams(elastic_modulus=1.0e8, restitution=0.5, friction=0.5)


def assert_same(a: HertzSimulation, b: HertzSimulation):
    """Positions, velocities, spins, forces and torques of two runs agree
    to rounding."""
    assert a.n_steps == b.n_steps
    np.testing.assert_allclose(a.positions, b.positions, rtol=0, atol=TOL)
    np.testing.assert_allclose(a.velocities, b.velocities, rtol=0, atol=TOL)
    np.testing.assert_allclose(a.angular_velocities, b.angular_velocities, rtol=0, atol=TOL)
    scale = max(1.0, float(np.abs(b.force).max()), float(np.abs(b.torque).max()))
    np.testing.assert_allclose(a.force, b.force, rtol=0, atol=TOL * scale)
    np.testing.assert_allclose(a.torque, b.torque, rtol=0, atol=TOL * scale)


def both(make, *steps):
    """The simulation of ``make(skip_resting)`` with the option on and off,
    each advanced by the numbers of steps ``steps`` (one call each)."""
    out = []
    for skip in (True, False):
        sim = make(skip)
        for n in steps:
            sim.step(n)
        out.append(sim)
    return out


def transit_field(n: int = 300, seed: int = 1):
    """A calm field of ``n`` floes (A = 0.4) with a slot cleared for a
    20 m × 6 m hull heading +x at a fifth of the box."""
    field, box = make_floe_field(n, concentration=0.4, alpha=1.8, mean_diameter=4.0, seed=seed)
    start = np.array([0.2 * box.lx, 0.5 * box.ly])
    keep = np.hypot(*(field.positions - start).T) > field.radii + 12.0
    field = FloeField(field.positions[keep], field.radii[keep], field.thickness[keep],
                      density=field.density)
    return field, box, start


def transit(skip: bool, forcing=None, seed: int = 1, mode: str = "prescribed"):
    field, box, start = transit_field(seed=seed)
    speed = 2.0
    impact = (1.0 + CONTACT.restitution) * speed
    dt = 0.1 * hull_contact_time(field.radii, field.thickness, field.density, CONTACT, impact)
    ship = Ship(Hull.pointed(20.0, 6.0), 2.0e5, mode=mode, position=tuple(start),
                speed=speed)
    sim = HertzSimulation(field, box, CONTACT, forcing, dt=dt, impact_speed=impact, ship=ship,
                          skip_resting=skip)
    if mode == "dynamic":
        sim.ship.command(thrust=2.0e4)
    return sim


@pytest.mark.parametrize("mode", ["prescribed", "dynamic"])
def test_ship_transit_same_as_full_step(mode):
    """A ship pushing through a calm field for 10 s, in pieces of different
    lengths: floes, forces and the ship's records agree with the full step
    to rounding, and most floes were never integrated."""
    pieces = []
    on, off = None, None
    for skip in (True, False):
        sim = transit(skip, mode=mode)
        n10 = int(round(10.0 / sim.dt))
        pieces = (1, n10 // 3, n10 - n10 // 3 - 1)
        for n in pieces:
            sim.step(n)
        on, off = (sim, off) if skip else (on, sim)
    assert_same(on, off)
    r_on, r_off = on.ship.records(), off.ship.records()
    assert r_on["time"].size == sum(pieces)
    for key in ("x", "y", "surge", "ice_surge", "ice_sway", "ice_moment", "ice_power",
                "contacts", "normal_force"):
        scale = max(1.0, float(np.abs(r_off[key]).max()))
        np.testing.assert_allclose(r_on[key], r_off[key], rtol=0, atol=TOL * scale, err_msg=key)
    c_on, c_off = on.ship.collisions(), off.ship.collisions()
    assert c_on["floe"].tolist() == c_off["floe"].tolist()
    assert c_off["floe"].size > 0, "the ship hit nothing: the test tests nothing"
    # the floes the ship set moving, and only they, are awake at the end
    moving = np.count_nonzero(np.any(off.velocities != 0.0, axis=1))
    assert 0 < moving <= on.n_awake < 0.5 * on.n_floes
    assert off.n_awake == off.n_floes


def test_calm_field_only_a_few_floes_awake():
    """After 10 s of a ship in calm ice few floes were integrated: the hull
    sweeps 20 m × 6 m of a box of ~100 m × 100 m, so the floes it and the
    floes it pushed can reach are a small part of the field (< 20 %)."""
    sim = transit(True)
    sim.advance(10.0)
    assert 0 < sim.n_awake < 0.2 * sim.n_floes


def pair_field(positions, velocities, radius=1.0):
    pos = np.array(positions, dtype=float)
    return FloeField(pos, np.full(len(pos), radius), 1.0, np.array(velocities, dtype=float))


def test_woken_by_a_floe_and_by_an_assigned_velocity():
    """A moving floe hits a resting one (which passes the push on to a
    third); a fourth lies in contact with a fifth at rest (touching: both
    awake from the start); between two calls the user sets a sixth moving.
    Every floe ends as in the full step."""
    positions = [(10.0, 10.0), (13.0, 10.0), (15.5, 10.0), (30.0, 30.0), (31.995, 30.0),
                 (40.0, 10.0)]
    velocities = [(0.5, 0.0)] + [(0.0, 0.0)] * 5
    field = pair_field(positions, velocities)
    dt = 1e-3

    def make(skip):
        return HertzSimulation(field, PeriodicBox(60.0), CONTACT, None, dt, impact_speed=1.0,
                               skip_resting=skip)

    on, off = both(make, 1, 4000)
    assert_same(on, off)
    assert np.all(on.velocities[:5, 0] != 0.0)
    assert on.velocities[5, 0] == 0.0 and on.n_awake == 5
    for sim in (on, off):
        v = sim.velocities.copy()
        v[5] = (0.0, 0.3)
        sim.velocities = v
        sim.step(1000)
    assert_same(on, off)
    assert on.n_awake == 6


def test_woken_by_the_hull():
    """A prescribed hull sails into a resting floe: it wakes and leaves as
    in the full step (and was not integrated before)."""
    field = pair_field([(40.0, 30.0)], [(0.0, 0.0)])
    speed = 1.0
    dt = 0.01 * hull_contact_time(field.radii, 1.0, field.density, CONTACT, 2.0 * speed)

    def make(skip):
        ship = Ship(Hull.box(10.0, 4.0), 1.0e5, position=(30.0, 30.0), speed=speed)
        return HertzSimulation(field, PeriodicBox(60.0), CONTACT, None, dt, impact_speed=2.0,
                               ship=ship, skip_resting=skip)

    on, off = both(make, 10)
    assert on.n_awake == 0
    n = int(round(6.0 / speed / dt))
    for sim in (on, off):
        sim.step(n)
    assert_same(on, off)
    assert on.n_awake == 1 and on.velocities[0, 0] > speed
    assert on.ship.collisions()["floe"].tolist() == off.ship.collisions()["floe"].tolist() == [0]


@pytest.mark.parametrize("box_type", [ChannelBox, WalledBox])
def test_walls(box_type):
    """A resting floe that overlaps a wall is not at rest (the wall pushes
    it off); a moving floe pushes a resting one into the wall ahead. Both
    as in the full step."""
    positions = [(0.995, 20.0), (20.0, 10.0), (36.0, 10.0)]
    velocities = [(0.0, 0.0), (0.8, 0.0), (0.0, 0.0)]
    if box_type is ChannelBox:          # walls at y = 0 and y = ly: turn the set-up
        positions = [(y, x) for x, y in positions]
        velocities = [(vy, vx) for vx, vy in velocities]
    field = pair_field(positions, velocities)

    def make(skip):
        return HertzSimulation(field, box_type(40.0), CONTACT, None, 1e-3, impact_speed=2.0,
                               skip_resting=skip)

    on, off = both(make, 1, 30000)
    assert_same(on, off)
    assert on.n_awake == 3
    # the first floe left the wall, the last one was pushed into it and back
    assert np.all(np.abs(on.velocities).max(axis=1) > 0.0)


def test_wind_nothing_rests():
    """With wind every floe is pushed: all are awake and the run is the
    full step's."""
    forcing = Forcing(HERMAN2013.forcing)

    def make(skip):
        return transit(skip, forcing=forcing)

    on, off = both(make, 2000)
    assert on.n_awake == on.n_floes
    assert_same(on, off)


def test_bad_arguments():
    field, box, _ = transit_field(n=50)
    with pytest.raises(ValueError, match="serial step only"):
        HertzSimulation(field, box, CONTACT, None, 1e-3, parallel=True, skip_resting=True)
    with pytest.raises(TypeError, match="skip_resting must be True or False"):
        HertzSimulation(field, box, CONTACT, None, 1e-3, skip_resting="yes")
    sim = HertzSimulation(field, box, CONTACT, None, 1e-3, skip_resting=True)
    assert not sim.parallel and "skip_resting=True" in repr(sim)


def test_apart_until_is_a_bound_on_approach():
    """The theorem the pair loops rely on (:func:`physics.hertz_kernels.apart_until`):
    two discs that each move by less than their path (sum of the paths
    below the threshold) cannot touch. Random pairs, random moves of the
    largest allowed lengths in random directions, in floating point."""
    from physics.hertz_kernels import apart_until

    rng = np.random.default_rng(3)
    checked = 0
    for _ in range(20000):
        ri, rj = rng.uniform(0.5, 30.0, 2)
        gap = rng.choice([rng.uniform(1e-8, 1e-6), rng.uniform(1e-6, 2.0)])
        angle = rng.uniform(0.0, 2.0 * np.pi)
        d = ri + rj + gap
        xi = rng.uniform(0.0, 1000.0, 2)
        xj = xi + d * np.array([np.cos(angle), np.sin(angle)])
        paths = rng.uniform(0.0, 10.0)
        limit = apart_until(xj[0] - xi[0], xj[1] - xi[1], ri + rj, paths)
        budget = limit - paths                      # what the two may drift together
        if budget <= 0.0:
            continue
        share = rng.uniform(0.0, 1.0)
        # each moves straight at the other: the closest approach its path allows
        u = (xj - xi) / d
        xi2 = xi + share * budget * u
        xj2 = xj - (1.0 - share) * budget * u
        dx, dy = xj2 - xi2
        assert dx * dx + dy * dy >= (ri + rj) ** 2
        checked += 1
    assert checked > 15000


def test_pairs_apart_are_not_looked_at_until_their_floes_drifted_their_gap():
    """After one pass every listed pair that does not touch has a finite
    threshold, and the pass skips it while the floes' paths stay below it
    (a pass with the positions moved but the paths not grown gives no force
    even where the discs now overlap: the skip is what the paths allow, so
    the paths must bound the drift, which the kick–drift pass ensures). Once
    the paths pass the threshold the pair is looked at again and pushes."""
    from physics.hertz_resting import find_awake, live_pair_forces, live_pairs

    positions = [(10.0, 10.0), (12.5, 10.0), (30.0, 30.0)]
    field = pair_field(positions, [(0.1, 0.0), (0.0, 0.0), (0.0, 0.0)])
    sim = HertzSimulation(field, PeriodicBox(60.0), CONTACT, None, 1e-3, impact_speed=1.0,
                          skin=1.0, skip_resting=True)
    args = sim._kernel_arguments(1)
    floes, law, _, drive, box = args[1:6]
    verlet = sim._verlet
    awake = find_awake(floes, drive, box, verlet)
    pairs = live_pairs(verlet, awake)
    n_live = awake.count[2]
    assert n_live == 1                              # floes 0 and 1, gap 0.5 m
    p = pairs.live[0]
    path = np.zeros(3)
    force, torque = np.zeros((3, 2)), np.zeros(3)
    live_pair_forces(pairs, awake, floes, law, box, verlet, 1e-3, path, force, torque)
    assert np.all(force == 0.0)
    assert pairs.due[p] == pytest.approx(0.5, abs=1e-8)
    floes.pos[0, 0] = 10.6                          # overlapping by 0.1 m
    live_pair_forces(pairs, awake, floes, law, box, verlet, 1e-3, path, force, torque)
    assert np.all(force == 0.0)                     # skipped: the paths said 0
    path[0] = 0.6                                   # the drift that took it there
    live_pair_forces(pairs, awake, floes, law, box, verlet, 1e-3, path, force, torque)
    assert force[0, 0] < 0.0 < force[1, 0]
    # touching: the threshold stays where it was; the paths never shrink, so
    # the pair is looked at in every step until it is apart again
    assert pairs.due[p] <= path[0] + path[1]


def test_walls_are_not_looked_at_until_a_floe_drifted_its_gap():
    """A floe 0.5 m clear of the wall gets a threshold of its path plus
    0.5 m; moved into the wall with its path not grown it is skipped (no
    force), and once its path passes the threshold the wall pushes it."""
    from physics.hertz_resting import awake_wall_forces, find_awake

    field = pair_field([(1.5, 20.0)], [(-0.1, 0.0)])
    sim = HertzSimulation(field, WalledBox(40.0), CONTACT, None, 1e-3, impact_speed=1.0,
                          skip_resting=True)
    args = sim._kernel_arguments(1)
    floes, _, wall_law, drive, box = args[1:6]
    awake = find_awake(floes, drive, box, sim._verlet)
    path, due = np.zeros(1), np.full(1, -np.inf)
    force, torque = np.zeros((1, 2)), np.zeros(1)
    awake_wall_forces(awake, floes, wall_law, box, 1e-3, path, due, force, torque)
    assert force[0, 0] == 0.0 and due[0] == pytest.approx(0.5, abs=1e-8)
    floes.pos[0, 0] = 0.9                           # overlapping the wall at x = 0
    awake_wall_forces(awake, floes, wall_law, box, 1e-3, path, due, force, torque)
    assert force[0, 0] == 0.0                       # skipped: the path said 0
    path[0] = 0.6                                   # the drift that took it there
    awake_wall_forces(awake, floes, wall_law, box, 1e-3, path, due, force, torque)
    assert force[0, 0] > 0.0
