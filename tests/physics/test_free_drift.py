"""Free floes drift in closed form (``HertzSimulation(free_drift=True)``,
:mod:`physics.hertz_free_drift`): the same run as the full step.

A free floe follows the leapfrog recurrence of its forcing, summed in
closed form instead of step by step: the two differ by the rounding of a
few dozen operations on numbers of the size of the box, a few 1e-13 m over
thousands of steps. The engaged floes take the full step's arithmetic, but
the list's expiry test is taken in another order, and contacts amplify any
rounding (a floe pushed 1e-13 m aside meets its next floe at another angle).
Over the 10 s horizons here that growth stays far below the tolerances:
1e-9 m and m/s for lone floes, 1e-6 m and relative 1e-6 for transits with
contacts, a thousandth of a floe's skin."""
from __future__ import annotations

import copy

import gymnasium as gym
import numpy as np
import pytest

import iceenvs  # noqa: F401  (registers the environments)
from physics import ContactParams, Forcing, HertzSimulation
from physics.domain import PeriodicBox
from physics.floes import FloeField, make_floe_field
from physics.hertz import advance_together, hull_contact_time
from physics.hertz_free_drift import drift_sums
from physics.hull import Hull
from physics.params import HERMAN2013
from physics.ship import Ship

CONTACT = ContactParams(elastic_modulus=1.0e8, restitution=0.5, friction=0.5)


def test_drift_sums_are_the_sums_of_the_recurrence():
    """μ^m, T(m) = Σ_{j<m} μ^j and Q(m) = Σ_{k≤m} T(k) by doubling against
    the same sums term by term, to a relative 1e-12 (each is m terms of
    size ≤ m, added with ≤ m roundings of 1.1e-16)."""
    for mu in (complex(1.0 - 1e-3, -2e-4), complex(1.0 - 1e-6, 1e-7), complex(1.0, 0.0)):
        for m in (0, 1, 2, 3, 7, 64, 1000):
            p, t, q = drift_sums(mu, m)
            pe, te, qe = 1.0 + 0j, 0j, 0j
            for _ in range(m):
                te += pe
                pe *= mu
                qe += te
            assert abs(p - pe) <= 1e-12 * max(1.0, abs(pe))
            assert abs(t - te) <= 1e-12 * max(1.0, abs(te))
            assert abs(q - qe) <= 1e-12 * max(1.0, abs(qe))


def lone_floes(free: bool, forcing) -> HertzSimulation:
    """Twenty floes far apart in a periodic box, moving."""
    rng = np.random.default_rng(3)
    pos = np.array([[40.0 * (k % 5) + 20.0, 40.0 * (k // 5) + 20.0] for k in range(20)])
    vel = rng.normal(0.0, 0.3, (20, 2))
    pos[4] = (199.0, 20.0)                  # crosses the periodic side
    vel[4] = (1.0, 0.0)
    field = FloeField(pos, np.full(20, 5.0), np.full(20, 1.0), velocities=vel,
                      angular_velocities=rng.normal(0.0, 0.05, 20))
    box = PeriodicBox(200.0, 160.0)
    return HertzSimulation(field, box, CONTACT, forcing, dt=2e-3, free_drift=free,
                           impact_speed=1.0)


@pytest.mark.parametrize("forcing", [None, Forcing(HERMAN2013.forcing)])
def test_lone_floes_drift_as_the_full_step(forcing):
    """Floes that touch nothing, with and without wind, current and
    Coriolis, through windows, the periodic wrap and a run split in pieces:
    the full step's state to 1e-9 m, m/s and 1/s, with no floe engaged."""
    fast, full = lone_floes(True, forcing), lone_floes(False, forcing)
    for n in (1, 130, 2869):
        fast.step(n)
        full.step(n)
    assert full.positions[4, 0] < 10.0
    np.testing.assert_allclose(fast.positions, full.positions, rtol=0, atol=1e-9)
    np.testing.assert_allclose(fast.velocities, full.velocities, rtol=0, atol=1e-9)
    np.testing.assert_allclose(fast.angular_velocities, full.angular_velocities, rtol=0,
                               atol=1e-9)
    windows, _, engaged, steps, _, _ = fast.free_tally
    assert steps == 3000 and windows >= 3000 // fast.free_window
    assert engaged == 0


def transit(free: bool, forcing=None, mode: str = "prescribed", seed: int = 1):
    """A 20 m × 6 m hull at 2 m/s into a field of 300 floes (A = 0.4)."""
    field, box = make_floe_field(300, concentration=0.4, alpha=1.8, mean_diameter=4.0, seed=seed)
    start = np.array([0.2 * box.lx, 0.5 * box.ly])
    keep = np.hypot(*(field.positions - start).T) > field.radii + 12.0
    field = FloeField(field.positions[keep], field.radii[keep], field.thickness[keep],
                      density=field.density)
    impact = (1.0 + CONTACT.restitution) * 2.0
    dt = 0.1 * hull_contact_time(field.radii, field.thickness, field.density, CONTACT, impact)
    ship = Ship(Hull.pointed(20.0, 6.0), 2.0e5, mode=mode, position=tuple(start), speed=2.0)
    sim = HertzSimulation(field, box, CONTACT, forcing, dt=dt, impact_speed=impact, ship=ship,
                          free_drift=free)
    if mode == "dynamic":
        sim.ship.command(thrust=2.0e4)
    return sim


@pytest.mark.parametrize("mode, forcing", [("prescribed", None),
                                           ("dynamic", Forcing(HERMAN2013.forcing))])
def test_ship_transit_as_the_full_step(mode, forcing):
    """A ship pushing through a field for 10 s, in pieces: the floes, the
    ship's record and its collisions are the full step's to the module's
    tolerances, while most floes drifted free."""
    fast, full = transit(True, forcing, mode), transit(False, forcing, mode)
    n10 = int(round(10.0 / fast.dt))
    for n in (1, n10 // 3, n10 - n10 // 3 - 1):
        fast.step(n)
        full.step(n)
    np.testing.assert_allclose(fast.positions, full.positions, rtol=0, atol=1e-6)
    np.testing.assert_allclose(fast.velocities, full.velocities, rtol=0, atol=1e-6)
    r_fast, r_full = fast.ship.records(), full.ship.records()
    for key in ("x", "y", "surge", "ice_surge", "ice_sway", "ice_moment", "contacts"):
        scale = max(1.0, float(np.abs(r_full[key]).max()))
        np.testing.assert_allclose(r_fast[key], r_full[key], rtol=0, atol=1e-6 * scale,
                                   err_msg=key)
    c_fast, c_full = fast.ship.collisions(), full.ship.collisions()
    assert c_full["floe"].size > 0, "the ship hit nothing: the test tests nothing"
    assert c_fast["floe"].tolist() == c_full["floe"].tolist()
    _, _, engaged, steps, _, _ = fast.free_tally
    assert engaged < 0.5 * fast.n_floes * steps


def test_reference_transit_departs_as_a_rounding_error():
    """ShipNavigation-v1, seed 10001, the ship straight ahead at 2 m/s into
    the ice band 100 m ahead. The exact step is chaotic there: a floe moved
    by 3e-12 m after the first contact (32 s) is centimetres off 10 s later.
    The fast step departs from the exact one by rounding, and so no faster:
    over those 10 s its largest floe displacement from the exact run stays
    within a thousand times that of the perturbed exact run (plus 1e-9 m),
    and 2 s in, to 1e-9 m."""
    def env(free):
        e = gym.make("iceenvs/ShipNavigation-v1", free_drift=free).unwrapped
        e.reset(seed=10001)
        return e
    exact, fast, nudged = env(False), env(True), env(False)
    zero = np.zeros(1, dtype=np.float32)
    for _ in range(16):
        for e in (exact, fast, nudged):
            e.step(zero)
    moving = np.hypot(*nudged.sim.velocities.T)
    assert moving.max() > 0.1, "no floe moving at 32 s: the test tests nothing"
    nudged.sim._pos[int(np.argmax(moving)), 0] += 3e-12
    far_fast, far_nudged = [], []
    for _ in range(5):
        for e in (exact, fast, nudged):
            _, _, _, _, info = e.step(zero)
        far_fast.append(np.abs(fast.sim.positions - exact.sim.positions).max())
        far_nudged.append(np.abs(nudged.sim.positions - exact.sim.positions).max())
    assert info["collisions"] >= 1
    assert far_nudged[-1] > 1e4 * 3e-12, "no growth: the bound would be rounding alone"
    assert far_fast[0] < 1e-9
    for f, g in zip(far_fast, far_nudged):
        assert f <= 1e3 * g + 1e-9


def test_mid_episode_control_interval():
    """One control interval (2 s) from the state after 60 of seed 10001
    (the ship among floes it set moving): the fast step's floes are the
    exact step's to 1e-6 m, with fewer than half of them engaged."""
    env = gym.make("iceenvs/ShipNavigation-v1", free_drift=False).unwrapped   # the exact step
    env.reset(seed=10001)
    for _ in range(60):
        env.step(np.zeros(1, dtype=np.float32))
    sim = env.sim
    full = copy.deepcopy(sim)
    full.skip_resting = False
    assert not full.free_drift
    fast = copy.deepcopy(sim)
    fast.skip_resting, fast.free_drift = False, True
    n = int(round(2.0 / sim.dt))
    full.step(n)
    fast.step(n)
    assert np.count_nonzero(np.hypot(*full.velocities.T) > 0.01) > 50
    np.testing.assert_allclose(fast.positions, full.positions, rtol=0, atol=1e-6)
    np.testing.assert_allclose(fast.velocities, full.velocities, rtol=0, atol=1e-6)
    _, _, engaged, steps, _, _ = fast.free_tally
    assert engaged < 0.5 * fast.n_floes * steps


def assert_same_state(check, full):
    """The floes and the ship's record of two runs, bit for bit."""
    assert np.array_equal(check.positions, full.positions)
    assert np.array_equal(check.velocities, full.velocities)
    assert np.array_equal(check.angular_velocities, full.angular_velocities)
    assert np.array_equal(check.ship.records()["ice_surge"], full.ship.records()["ice_surge"])


@pytest.mark.parametrize("mode, forcing", [("prescribed", None),
                                           ("dynamic", Forcing(HERMAN2013.forcing))])
def test_stepped_windows_are_the_full_step_bit_for_bit(mode, forcing):
    """The check mode (``free_iterate``): the windows, guards and live pairs
    as in the fast step, the free floes stepped one step at a time with the
    full step's arithmetic. Every contact the full step finds must then be
    found, at the same step, in the same order: the transit's state is the
    full step's bit for bit. (So what the fast step adds is the closed
    form's rounding, nothing else.)"""
    fast, full = transit(True, forcing, mode), transit(False, forcing, mode)
    fast.free_iterate = True
    n10 = int(round(10.0 / fast.dt))
    for n in (1, n10 // 3, n10 - n10 // 3 - 1):
        fast.step(n)
        full.step(n)
    assert_same_state(fast, full)
    windows, _, engaged, steps, relined, _ = fast.free_tally
    assert relined > 0, "no engaged floe left its line: the guards were not tested"
    assert engaged < 0.5 * fast.n_floes * steps


def test_stepped_windows_reference_episode_bit_for_bit():
    """ShipNavigation-v1 at A = 0.2, seed 10004 (the ship enters the ice at
    50 s), 80 s straight ahead: the check mode's episode is the exact
    step's bit for bit."""
    def env(free):
        e = gym.make("iceenvs/ShipNavigation-v1", concentration=0.2, free_drift=free).unwrapped
        e.reset(seed=10004)
        e.sim.free_iterate = free
        return e
    exact, check = env(False), env(True)
    zero = np.zeros(1, dtype=np.float32)
    for _ in range(40):
        _, r0, _, _, i0 = exact.step(zero)
        _, r1, _, _, i1 = check.step(zero)
        assert r0 == r1
    assert i0["collisions"] > 0 and i0 == i1
    assert np.array_equal(exact.sim.positions, check.sim.positions)
    assert np.array_equal(exact.sim.velocities, check.sim.velocities)


def test_windows_carried_past_their_guards_bit_for_bit():
    """ShipNavigation-v1 at A = 0.5, seed 10001, from the state after 60
    straight-ahead steps (the ship in the pack, floes struck and turning):
    ten control intervals in the check mode are the full step's bit for
    bit after each, while engaged floes left their lines and free floes
    were engaged in the middle of windows (:func:`~physics.hertz_free_drift.repair`)."""
    env = gym.make("iceenvs/ShipNavigation-v1", concentration=0.5,
                   free_drift=False).unwrapped                              # the exact step
    env.reset(seed=10001)
    for _ in range(60):
        env.step(np.zeros(1, dtype=np.float32))
    full = copy.deepcopy(env.sim)
    full.skip_resting = False
    assert not full.free_drift
    check = copy.deepcopy(env.sim)
    check.skip_resting, check.free_drift, check.free_iterate = False, True, True
    n = int(round(2.0 / full.dt))
    for _ in range(10):
        full.step(n)
        check.step(n)
        assert_same_state(check, full)
    _, _, _, _, relined, engaged_late = check.free_tally
    assert relined > 100 and engaged_late > 10, "the windows were hardly repaired"


def test_advance_together_is_the_step_alone():
    """Free-drift simulations advanced together are, bit for bit, the same
    simulations advanced one by one."""
    alone = [transit(True, seed=s) for s in (1, 2)]
    together = [transit(True, seed=s) for s in (1, 2)]
    for sim in alone:
        sim.advance(1.0)
    assert advance_together(together, 1.0) == [None, None]
    for a, b in zip(alone, together):
        assert np.array_equal(a.positions, b.positions)
        assert np.array_equal(a.velocities, b.velocities)
        assert np.array_equal(a.free_tally, b.free_tally)
        assert a.n_awake == b.n_awake


def test_bad_arguments():
    field, box = make_floe_field(50, concentration=0.3, alpha=1.8, mean_diameter=4.0, seed=1)
    with pytest.raises(ValueError, match="serial step only"):
        HertzSimulation(field, box, CONTACT, None, 1e-3, parallel=True, free_drift=True)
    with pytest.raises(ValueError, match="choose one"):
        HertzSimulation(field, box, CONTACT, None, 1e-3, skip_resting=True, free_drift=True)
    with pytest.raises(TypeError, match="free_drift must be True or False"):
        HertzSimulation(field, box, CONTACT, None, 1e-3, free_drift=1)
    with pytest.raises(TypeError, match="free_drift must be True or False"):
        gym.make("iceenvs/ShipNavigation-v1", free_drift="yes")
    sim = HertzSimulation(field, box, CONTACT, None, 1e-3, free_drift=True)
    assert not sim.parallel and "free_drift=True" in repr(sim)
