"""Boxes: prescribed convergence of a deforming periodic box, frozen floes
and rigid walls (Herman 2013 experiments 1 and 3; the Physics page: physics-contact)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from physics import (HERMAN2013, ChannelBox, ContactParams, DeformingPeriodicBox, FloeField,
                     Forcing, HertzSimulation, PeriodicBox, WalledBox, make_floe_field)

from reference.dem import disc_mass, hertz_contact_time, hertz_k, hertz_peak_overlap


# ---------------------------------------------------------------------------
# Deforming periodic box
# ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def loose_field():
    """60 floes at A = 0.5 (alpha = 1.8, mean diameter 8 m), at rest."""
    return make_floe_field(60, concentration=0.5, alpha=1.8, mean_diameter=8.0, seed=21)


@pytest.mark.parametrize("axes", ["xy", "x", "y"])
@pytest.mark.parametrize("rate", [2e-3, -2e-3])
def test_deforming_box_concentration_is_linear_in_time(loose_field, axes, rate):
    """DeformingPeriodicBox with dA/dt = r: the concentration follows
    A(t) = A0 + r t within 1e-9 at every check, whatever the mix of step()
    and advance() calls; "xy" keeps the aspect ratio, "x" and "y" change one
    side only."""
    floes, box0 = loose_field
    box = DeformingPeriodicBox(box0.lx, box0.ly, concentration_rate=rate, axes=axes)
    sim = HertzSimulation(floes, box, ContactParams(), None, dt=0.002)
    a0 = sim.concentration
    assert a0 == pytest.approx(0.5, abs=1e-12)
    for k in (1, 7, 250, 1000):
        sim.step(k)
        assert abs(sim.concentration - (a0 + rate * sim.time)) < 1e-9
        assert box.concentration == pytest.approx(sim.concentration, abs=1e-15)
    sim.advance(3.0)
    assert abs(sim.concentration - (a0 + rate * sim.time)) < 1e-9
    if axes == "xy":
        assert box.lx / box.ly == pytest.approx(box0.lx / box0.ly, rel=1e-12)
    elif axes == "x":
        assert box.ly == box0.ly and box.lx != box0.lx
    else:
        assert box.lx == box0.lx and box.ly != box0.ly


def test_deforming_box_remaps_positions_affinely():
    """Floes at rest and out of contact move with the box: after the area
    changes from S0 to S, a floe at x0 is at x0 sqrt(S/S0) ("xy"), to 1e-9
    relative."""
    pos = np.array([[20.0, 30.0], [60.0, 75.0], [85.0, 15.0]])
    floes = FloeField(pos, [2.0, 3.0, 1.5], 1.0)
    box = DeformingPeriodicBox(100.0, 100.0, concentration_rate=-1e-4)
    sim = HertzSimulation(floes, box, ContactParams(), None, dt=0.001)
    s0 = box.area
    sim.advance(10.0)
    scale = math.sqrt(box.area / s0)
    assert scale > 1.01
    np.testing.assert_allclose(sim.positions, pos * scale, rtol=1e-9)
    assert np.all(sim.velocities == 0.0)


def test_deforming_box_stops_at_max_concentration(loose_field):
    """Converging beyond max_concentration stops the run with an error."""
    floes, box0 = loose_field
    box = DeformingPeriodicBox(box0.lx, box0.ly, concentration_rate=0.01, max_concentration=0.52)
    sim = HertzSimulation(floes, box, ContactParams(), None, dt=0.002)
    with pytest.raises(RuntimeError, match="concentration"):
        sim.advance(5.0)
    assert sim.concentration <= 0.52 + 1e-12
    assert sim.concentration > 0.52 - 0.01 * 0.002 - 1e-12


# ---------------------------------------------------------------------------
# Frozen floes
# ---------------------------------------------------------------------------

def test_frozen_floe_is_an_immovable_partner():
    """A floe hitting a frozen floe head-on (e = 0.5, frictionless) rebounds
    as from an infinite mass: restitution 0.5 within 1e-3 (m* = m of the
    mobile floe); with e = 1 the peak overlap is (5 m v^2 / (4 k))^(2/5)
    within 1 %. The frozen floe's position stays bitwise identical and its
    velocity and spin zero."""
    radii = np.array([1.0, 1.5])
    speed = 0.2
    m = disc_mass(radii[0], 1.0)
    for restitution in (0.5, 1.0):
        contact = ContactParams(restitution=restitution, friction=0.0)
        k = hertz_k(contact, radii.prod() / radii.sum())
        t_c = hertz_contact_time(m, k, speed)
        pos = np.array([[20.0, 20.0], [20.0 + radii.sum() + 1e-6, 20.0]])
        floes = FloeField(pos, radii, 1.0, np.array([[speed, 0.0], [0.0, 0.0]]),
                          frozen=np.array([False, True]))
        sim = HertzSimulation(floes, PeriodicBox(50.0), contact, None, t_c / 1000,
                              impact_speed=speed)
        frozen_start = sim.positions[1].copy()
        peak = 0.0
        for _ in range(3000):
            sim.step(1)
            peak = max(peak, radii.sum() - (sim.positions[1, 0] - sim.positions[0, 0]))
            assert np.array_equal(sim.positions[1], frozen_start)
        assert sim.velocities[0, 0] < 0.0
        assert -sim.velocities[0, 0] / speed == pytest.approx(restitution, abs=1e-3)
        if restitution == 1.0:
            assert peak == pytest.approx(hertz_peak_overlap(m, k, speed), rel=0.01)
        assert np.all(sim.velocities[1] == 0.0) and sim.angular_velocities[1] == 0.0


def test_frozen_floes_never_move_under_wind_and_impacts():
    """Wind-driven floes (Herman 2013 forcing, wind 10 m/s towards -y, with
    Coriolis and friction) pile up against a row of frozen floes: the frozen
    floes' positions stay bitwise identical and their velocities and spins
    exactly zero, while the mobile floes do move."""
    rng = np.random.default_rng(31)
    n_frozen, n_mobile = 12, 24
    frozen_pos = np.column_stack([np.arange(n_frozen) * 5.0 + 2.5, np.full(n_frozen, 3.0)])
    mobile_pos = np.column_stack([(np.arange(n_mobile) % 12) * 5.0 + 2.5,
                                  8.0 + 4.5 * (np.arange(n_mobile) // 12)])
    pos = np.vstack([frozen_pos, mobile_pos])
    radii = np.concatenate([np.full(n_frozen, 2.4), rng.uniform(1.5, 2.0, n_mobile)])
    vel = np.vstack([rng.normal(0, 0.1, (n_frozen, 2)), rng.normal(0, 0.1, (n_mobile, 2))])
    vel[n_frozen:, 1] -= 0.5
    frozen = np.arange(n_frozen + n_mobile) < n_frozen
    floes = FloeField(pos, radii, 1.5, vel, rng.normal(0, 0.05, len(radii)), frozen=frozen)
    forcing = Forcing(HERMAN2013.forcing, wind=(0.0, -10.0))
    sim = HertzSimulation(floes, PeriodicBox(60.0, 40.0), HERMAN2013.contact, forcing, 0.001,
                          impact_speed=1.0)
    start = sim.positions.copy()
    touched = 0
    for _ in range(1000):
        sim.step(10)
        c = sim.contacts()
        touched += np.count_nonzero(frozen[c.i] | frozen[c.j])
        assert np.array_equal(sim.positions[frozen], start[frozen])
        assert np.all(sim.velocities[frozen] == 0.0)
        assert np.all(sim.angular_velocities[frozen] == 0.0)
    assert touched > 0
    assert np.abs(sim.positions[~frozen] - start[~frozen]).max() > 0.5


def test_frozen_floes_stay_put_in_a_deforming_box(loose_field):
    """In a converging box the mobile floes are remapped with the box while
    frozen floes keep their positions bitwise."""
    floes, box0 = loose_field
    frozen = np.zeros(floes.n, dtype=bool)
    frozen[::5] = True
    field = FloeField(floes.positions, floes.radii, floes.thickness, frozen=frozen)
    box = DeformingPeriodicBox(box0.lx, box0.ly, concentration_rate=2e-3)
    sim = HertzSimulation(field, box, ContactParams(), None, dt=0.002)
    start = sim.positions.copy()
    sim.advance(5.0)
    assert np.array_equal(sim.positions[frozen], start[frozen])
    assert not np.array_equal(sim.positions[~frozen], start[~frozen])


# ---------------------------------------------------------------------------
# Rigid walls
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("restitution", [0.5, 1.0])
def test_floe_rebounds_from_channel_wall(restitution):
    """A floe moving at 0.3 m/s into the wall y = 0 of a ChannelBox (no
    forcing, frictionless) rebounds with the target restitution within 1e-3
    (the wall is an infinite mass: m* = m, R* = r, E*_w = E / (1 - nu^2)),
    and with e = 1 the peak overlap is (5 m v^2 / (4 k_w))^(2/5) within 1 %."""
    r, speed = 1.0, 0.3
    m = disc_mass(r, 1.0)
    contact = ContactParams(restitution=restitution, friction=0.0)
    k_wall = 4.0 / 3.0 * contact.elastic_modulus / (1.0 - contact.poisson_ratio ** 2) * math.sqrt(r)
    t_c = hertz_contact_time(m, k_wall, speed)
    floes = FloeField(np.array([[10.0, r + 1e-7]]), [r], 1.0, np.array([[0.0, -speed]]))
    sim = HertzSimulation(floes, ChannelBox(30.0, 20.0), contact, None, t_c / 1000,
                          impact_speed=speed)
    lowest = r
    for _ in range(3000):
        sim.step(1)
        lowest = min(lowest, sim.positions[0, 1])
    assert sim.velocities[0, 1] / speed == pytest.approx(restitution, abs=1e-3)
    assert sim.velocities[0, 0] == 0.0
    if restitution == 1.0:
        assert r - lowest == pytest.approx(hertz_peak_overlap(m, k_wall, speed), rel=0.01)


def test_wind_presses_floe_against_wall_at_equilibrium_overlap():
    """A floe at rest against the wall y = 0 under wind 10 m/s towards -y
    (Herman 2013 drag, Coriolis on) settles where the wall's Hertz force
    balances the wind drag, k_w delta^(3/2) = a |u_a|^2 with
    a = rho_a pi r (r C_ha + h_f C_va): overlap within 1e-3, and it stays at
    rest (speed below 1e-9 m/s) inside the channel."""
    r, h = 1.0, 1.0
    params = HERMAN2013.forcing
    forcing = Forcing(params, wind=(0.0, -10.0))
    contact = ContactParams(restitution=0.5, friction=0.7)
    h_f = h * (params.water_density - params.ice_density) / params.water_density
    a = params.air_density * math.pi * r * (r * params.air_skin_drag + h_f * params.air_form_drag)
    k_wall = 4.0 / 3.0 * contact.elastic_modulus / (1.0 - contact.poisson_ratio ** 2) * math.sqrt(r)
    delta_eq = (a * 100.0 / k_wall) ** (2.0 / 3.0)
    floes = FloeField(np.array([[10.0, r]]), [r], h)
    sim = HertzSimulation(floes, ChannelBox(30.0, 20.0), contact, forcing, 0.001)
    sim.advance(8.0)
    assert r - sim.positions[0, 1] == pytest.approx(delta_eq, rel=1e-3)
    assert np.hypot(*sim.velocities[0]) < 1e-9


@pytest.mark.parametrize("box_type", [ChannelBox, WalledBox])
def test_walls_keep_floes_in(box_type):
    """40 floes blown at 10 m/s towards a corner (Herman 2013 forcing and
    contacts), thrown at it at about 1 m/s, stay inside the box: no
    centre leaves it and no floe overlaps a wall by more than 1 % of its
    radius, at any of 20 checks over 10 s; floes do reach the bottom wall
    (within 2 cm at a check)."""
    rng = np.random.default_rng(41)
    n = 40
    box = box_type(60.0, 40.0)
    radii = rng.uniform(1.0, 2.5, n)
    grid = np.array([(x, y) for x in np.arange(4.0, 57.0, 6.5) for y in np.arange(4.0, 37.0, 6.5)])
    pos = grid[rng.choice(len(grid), n, replace=False)]
    vel = rng.normal(0.0, 0.5, (n, 2)) - 0.8
    floes = FloeField(pos, radii, 1.5, vel)
    forcing = Forcing(HERMAN2013.forcing, wind=(-7.0, -7.0))
    sim = HertzSimulation(floes, box, HERMAN2013.contact, forcing, 7e-4, impact_speed=2.0)
    closest = np.inf
    for _ in range(20):
        sim.advance(0.5)
        x, y = sim.positions.T
        closest = min(closest, float(np.min(y - radii)))
        assert np.all(box.contains(sim.positions))
        assert np.all(y - radii > -0.01 * radii) and np.all(box.ly - y - radii > -0.01 * radii)
        if box_type is WalledBox:
            assert np.all(x - radii > -0.01 * radii) and np.all(box.lx - x - radii > -0.01 * radii)
    assert closest < 0.02
