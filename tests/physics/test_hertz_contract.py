"""The Hertz engine keeps the engine contract (physics.engine): read-only
snapshots (also of its forces and torques), checked assignment,
SimulationError with its reason, and the set-up from a preset."""
from __future__ import annotations

import numpy as np
import pytest

from physics import (HERMAN2013, DeformingPeriodicBox, FloeField, Forcing, HertzSimulation,
                     PeriodicBox, make_floe_field)
from physics.engine import FailureReason, FloeEngine, SimulationError


@pytest.fixture(scope="module")
def field():
    floes, box = make_floe_field(300, concentration=0.6, alpha=1.8, mean_diameter=8.0, seed=7,
                                 velocity_std=0.02)
    floes.frozen[:3] = True
    floes.velocities[:3] = 0.0
    floes.angular_velocities[:3] = 0.0
    return floes, box


def test_arrays_are_read_only_snapshots(field):
    floes, box = field
    sim = HertzSimulation(floes, box, HERMAN2013.contact, None, 0.002, parallel=False)
    assert isinstance(sim, FloeEngine)
    pos, vel, omega = sim.positions, sim.velocities, sim.angular_velocities
    for a in (pos, vel, omega):
        with pytest.raises(ValueError):
            a[0] = 1.0
    sim.step(20)
    assert not np.array_equal(sim.positions, pos)     # the snapshot stayed as it was
    assert sim.positions is not sim.positions
    np.testing.assert_array_equal(floes.velocities, field[0].velocities)   # input untouched


def test_force_and_torque_are_read_only_snapshots():
    """``force`` and ``torque``, the totals of the last step, are read-only
    snapshots. Three floes pressed together at rest, without forcing, in a
    periodic box: the forces are the pairs' only, so they add up to zero
    (Newton's third law)."""
    pos = np.array([[10.0, 10.0], [11.98, 10.0], [13.9, 10.3]])    # radius 1 m: overlaps
    floes = FloeField(pos, np.ones(3), 1.0)
    sim = HertzSimulation(floes, PeriodicBox(40.0), HERMAN2013.contact, None, 0.001,
                          allow_overlap=True, parallel=False)
    force, torque = sim.force, sim.torque
    assert force.shape == (3, 2) and torque.shape == (3,)
    for a in (force, torque):
        assert not a.flags.writeable
        with pytest.raises(ValueError):
            a[0] = 1.0
    largest = float(np.abs(force).max())
    assert largest > 0.0
    # three pair forces added with opposite signs: rounding only
    np.testing.assert_allclose(force.sum(axis=0), 0.0, rtol=0.0, atol=1e-12 * largest)
    kept = force.copy()
    sim.step(10)
    np.testing.assert_array_equal(force, kept)                 # taken at the call
    assert not np.array_equal(sim.force, kept)                 # the floes moved apart


def test_assigned_velocities_are_checked_and_copied(field):
    floes, box = field
    sim = HertzSimulation(floes, box, HERMAN2013.contact, None, 0.002, parallel=False)
    new = np.full((floes.n, 2), 0.01)
    new[:3] = 0.0
    sim.velocities = new
    new[5] = 7.0                                        # the engine took a copy
    assert np.all(sim.velocities[3:] == 0.01)
    spin = np.zeros(floes.n)
    spin[10] = 0.2
    sim.angular_velocities = spin
    assert sim.angular_velocities[10] == 0.2
    before = sim.velocities
    for bad, match in ((np.zeros((floes.n, 3)), "shape"), (np.full((floes.n, 2), np.nan), "finite"),
                       (np.full((floes.n, 2), 0.01), "frozen")):
        with pytest.raises(ValueError, match=match):
            sim.velocities = bad
    with pytest.raises(ValueError, match="frozen"):
        sim.angular_velocities = np.ones(floes.n)
    with pytest.raises(ValueError, match="shape"):
        sim.angular_velocities = np.zeros(floes.n + 1)
    np.testing.assert_array_equal(sim.velocities, before)   # nothing changed


def test_assignment_equals_a_field_with_those_velocities(field):
    """Assigning velocities before the first step gives the trajectory of a
    simulation started from a field with those velocities (the field starts
    without contacts and without forcing, so its first forces are zero
    either way)."""
    floes, box = field
    a = HertzSimulation(floes, box, HERMAN2013.contact, None, 0.002, parallel=False)
    b_field = floes.copy()
    b_field.velocities[3:] *= 2.0
    b = HertzSimulation(b_field, box, HERMAN2013.contact, None, 0.002, parallel=False)
    a.velocities = b_field.velocities
    a.step(100)
    b.step(100)
    np.testing.assert_allclose(a.positions, b.positions, rtol=0, atol=1e-9)


def test_concentration_limit_raises_simulation_error():
    floes, box = make_floe_field(200, concentration=0.6, alpha=1.8, mean_diameter=8.0, seed=3)
    deforming = DeformingPeriodicBox(box.lx, box.ly, concentration_rate=1.0,
                                     max_concentration=0.62)
    sim = HertzSimulation(floes, deforming, HERMAN2013.contact, None, 0.002)
    with pytest.raises(RuntimeError, match="concentration limit") as caught:
        sim.advance(1.0)
    assert isinstance(caught.value, SimulationError)
    assert caught.value.reason is FailureReason.CONCENTRATION_LIMIT
    assert caught.value.time == sim.time > 0.0


def test_from_preset_builds_the_preset_set_up():
    """The same floes, contact law, time step and forcing as the set-up
    written out by hand, hence the same trajectory."""
    P = HERMAN2013
    sim = HertzSimulation.from_preset(P, 300, 0.6, seed=2, velocity_std=0.01, parallel=False)
    field, box = make_floe_field(300, concentration=0.6, alpha=P.fsd_exponent,
                                 mean_diameter=P.mean_diameter, thickness=P.thickness,
                                 density=P.forcing.ice_density, seed=2, velocity_std=0.01)
    ref = HertzSimulation(field, box, P.contact, Forcing(P.forcing), P.time_step, parallel=False)
    assert (sim.dt, sim.contact, sim.box.lx) == (P.time_step, P.contact, box.lx)
    assert sim.forcing.wind.tolist() == [10.0, 0.0] and sim.forcing.coriolis == P.forcing.coriolis
    for s in (sim, ref):
        s.advance(0.5)
    np.testing.assert_array_equal(sim.positions, ref.positions)
    np.testing.assert_array_equal(sim.velocities, ref.velocities)


def test_from_preset_options():
    P = HERMAN2013
    free = HertzSimulation.from_preset(P, 200, 0.5, forcing=False, dt=0.001, skin=0.5)
    assert free.forcing is None and (free.dt, free.skin) == (0.001, 0.5)
    calm = Forcing(P.forcing, wind=(0.0, 0.0))
    assert HertzSimulation.from_preset(P, 200, 0.5, forcing=calm).forcing is calm
    assert HertzSimulation.from_preset(P, 200, 0.5, forcing=None).forcing is None
    assert HertzSimulation.from_preset(P, 200, 0.5, seed=1).n_floes == 200
    with pytest.raises(TypeError, match="PaperPreset"):
        HertzSimulation.from_preset(P.contact, 200, 0.5)
    with pytest.raises(TypeError):
        HertzSimulation.from_preset(P, 200, 0.5, no_such_option=1)
