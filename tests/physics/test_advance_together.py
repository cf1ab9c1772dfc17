"""physics.hertz.advance_together: several simulations advanced in one
compiled call end where each one's own advance would take it, a failure of
one leaves the others going, and bad input is refused clearly."""
from __future__ import annotations

import numpy as np
import pytest

from physics import ContactParams, HertzSimulation
from physics.domain import Box, PeriodicBox
from physics.engine import SimulationError
from physics.floes import FloeField, place_floes
from physics.hertz import KernelLists, advance_together, hull_contact_time
from physics.hull import Hull
from physics.ship import Ship

PARAMS = ContactParams(elastic_modulus=1e7, restitution=0.5, friction=0.3)
# the same compiled step on the same state, in the same order; the bound only
# absorbs a compiler's freedom between two call sites
TOL = 1e-12


def transit(seed: int, speed: float = 2.0) -> HertzSimulation:
    """A ship crossing 300 floes at rest in a periodic box."""
    rng = np.random.default_rng(seed)
    radii = rng.uniform(1.0, 2.5, 300)
    pos = place_floes(radii, Box(70.0, 80.0, periodic=(False, True)), rng) + [40.0, 0.0]
    field = FloeField(pos, radii, 1.0, np.zeros((300, 2)))
    ship = Ship(Hull.pointed(20.0, 6.0), 3e5, position=(18.0, 40.0), speed=speed)
    dt = 0.1 * hull_contact_time(radii, 1.0, field.density, PARAMS, 2.0 * speed)
    return HertzSimulation(field, PeriodicBox(140.0, 80.0), PARAMS, None, dt,
                           impact_speed=2.0 * speed, ship=ship)


def test_together_ends_where_each_alone_ends():
    alone = [transit(s) for s in (1, 2, 3)]
    together = [transit(s) for s in (1, 2, 3)]
    for _ in range(4):
        for sim in alone:
            sim.advance(2.0)
        assert advance_together(together, 2.0) == [None, None, None]
    for a, b in zip(alone, together):
        assert b.n_steps == a.n_steps and b.n_rebuilds == a.n_rebuilds
        np.testing.assert_allclose(b.positions, a.positions, rtol=0, atol=TOL)
        np.testing.assert_allclose(b.velocities, a.velocities, rtol=0, atol=TOL)
        np.testing.assert_allclose(b.ship.position, a.ship.position, rtol=0, atol=TOL)
        la, lb = a.ship_loads(), b.ship_loads()
        assert lb.collisions == la.collisions > 0
        np.testing.assert_allclose(lb.resistance, la.resistance, rtol=1e-9)


def test_kept_lists_carry_new_simulations_and_new_item_types():
    """Lists kept from call to call (a vector environment's) take the
    simulations of each call, also others than the last call's."""
    kept = KernelLists()
    alone = [transit(s) for s in (7, 8)]
    together = [transit(s) for s in (7, 8)]
    for sim in alone:
        sim.advance(2.0)
    assert advance_together(together, 2.0, lists=kept) == [None, None]
    first = kept._lists[2]
    fresh, other = transit(9), transit(9)   # a new episode in the second slot
    fresh.advance(1.0)
    assert advance_together([together[0], other], 1.0, lists=kept) == [None, None]
    alone[0].advance(1.0)
    for a, b in ((alone[0], together[0]), (fresh, other)):
        assert b.n_steps == a.n_steps
        np.testing.assert_allclose(b.positions, a.positions, rtol=0, atol=TOL)
    assert kept._lists[2] is first      # the second call refilled the first's lists


def test_a_failing_simulation_does_not_stop_the_others():
    good, bad = transit(4), transit(5)
    v = np.zeros((bad.n_floes, 2))
    v[0] = 1e6                         # a floe that crosses the box in a step
    bad.velocities = v
    errors = advance_together([good, bad], 1.0)
    assert errors[0] is None and isinstance(errors[1], SimulationError)
    assert good.time == pytest.approx(1.0, abs=good.dt)
    with pytest.raises(SimulationError):
        bad.advance(1.0)


def test_bad_input_is_refused():
    sim = transit(6)
    with pytest.raises(TypeError, match="sims\\[1\\] is a str"):
        advance_together([sim, "x"], 1.0)
    with pytest.raises(ValueError, match="the same simulation twice"):
        advance_together([sim, sim], 1.0)
    with pytest.raises(ValueError, match="duration"):
        advance_together([sim], -1.0)
    field = FloeField(np.array([[5.0, 5.0], [9.0, 5.0]]), np.array([1.0, 1.0]), 1.0,
                      np.zeros((2, 2)))
    par = HertzSimulation(field, PeriodicBox(20.0, 20.0), PARAMS, None, 1e-3, parallel=True)
    with pytest.raises(ValueError, match="sims\\[0\\] is a parallel simulation"):
        advance_together([par], 1.0)
    assert advance_together([], 1.0) == []


def test_a_simulation_whose_slot_is_refilled_gets_its_verlet_list_back():
    """A run that rebuilds a Verlet list leaves it in the batch's typed
    list; refilling that slot for another simulation first hands it back,
    so the first one goes on (alone) exactly as if it had run alone."""
    kept = KernelLists()
    alone, together, other = transit(11), transit(11), transit(12)
    partner = transit(13)
    for sim in (alone, together):       # drifting floes: the lists are rebuilt
        sim.velocities = np.random.default_rng(5).normal(0.0, 0.5, (sim.n_floes, 2))
    for _ in range(3):
        alone.advance(2.0)
        assert advance_together([together, partner], 2.0, lists=kept) == [None, None]
    assert together.n_rebuilds == alone.n_rebuilds > 0
    assert advance_together([other, partner], 1.0, lists=kept) == [None, None]
    assert kept.current([together, partner]) is None          # slot 0 is other's now
    for sim in (alone, together):
        sim.advance(2.0)
    assert together.n_steps == alone.n_steps
    np.testing.assert_allclose(together.positions, alone.positions, rtol=0, atol=TOL)
    np.testing.assert_allclose(together.velocities, alone.velocities, rtol=0, atol=TOL)
    assert len(together.contacts()) == len(alone.contacts())


def test_the_ice_near_every_ship_in_one_call_is_each_ones_own():
    """ice_near_many over the kept lists gives each simulation's local ice
    and the kinetic energy of all its floes (ice_energy: ½ m v² + ½ I ω²
    with I = ½ m r², as kinetic_energy())."""
    from physics.hertz_batch import ice_near_many

    kept = KernelLists()
    sims = [transit(s) for s in (21, 22, 23)]
    rng = np.random.default_rng(6)
    for sim in sims:                    # drifting, turning floes that meet
        sim.velocities = rng.normal(0.0, 0.5, (sim.n_floes, 2))
        sim.angular_velocities = rng.normal(0.0, 0.05, sim.n_floes)
    for _ in range(2):
        assert advance_together(sims, 2.0, lists=kept) == [None] * 3
    lists = kept.current(sims)
    assert lists is not None
    centres = np.array([sim.ship.position for sim in sims])
    out = np.empty((3, 8))
    ice_near_many(lists[0], lists[1], centres, 30.0, 140.0, 80.0, True, True, out)
    for k, sim in enumerate(sims):
        np.testing.assert_allclose(out[k], sim.ice_near_row(centres[k], 30.0), rtol=1e-12,
                                   atol=1e-9)
        ice = sim.local_ice(centres[k], 30.0)
        assert (int(out[k, 0]), int(out[k, 2])) == (ice.n_floes, ice.n_contacts)
        assert out[k, 2] > 0                                   # floes in contact
        np.testing.assert_allclose(out[k, 7], sim.kinetic_energy(), rtol=1e-12)


def test_a_non_finite_state_is_a_failure_of_that_simulation():
    good, bad = transit(31), transit(32)
    bad._vel[5] = np.nan                # past the setter's check: the batch's own test finds it
    errors = advance_together([good, bad], 0.5)
    assert errors[0] is None
    assert isinstance(errors[1], SimulationError) and "non-finite" in str(errors[1])
