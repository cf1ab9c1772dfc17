"""The pymunk runner and the pymunk cross-checks, on small samples.

Tolerances: single impacts and the drag updates are exact to rounding
(1e-12 relative) where both sides compute the same closed form; the
engines against the binary-impact laws use the tolerances of the full
cross-check (1e-6 for the restitution law and the rigid Coulomb law in
pymunk and the hard-disc engine; 1e-3 for the Hertz engine in gross sliding
at e >= 0.85 and 3e-2 at e = 0.5, where the Mindlin spring's loading phase
costs up to 2 % of the tangential impulse). The small cooling gas (N = 500,
three seeds) is compared within 10 %: over twelve base seeds its largest
relative difference of KE/KE0 between the engines was 3.3 % on average
(standard deviation 1.2 %, largest 5.6 %), and against Haff's law 2.8 %
(largest 5.5 %); a wrong restitution mapping (e instead of sqrt(e) per
shape) would double pymunk's cooling rate.
"""
from __future__ import annotations

import math

import numpy as np
import pymunk
import pytest

from physics import (HERMAN2011, HERMAN2013, FloeField, Forcing, HardDiskSimulation,
                     PeriodicBox, WalledBox)
from physics.crosscheck.pymunk_checks import (binary_friction, binary_frictionless,
                                              drag_relaxation, gas_cooling, hertz_pair_impact,
                                              pymunk_oblique_impact, rigid_coulomb_impact)
from physics.crosscheck.pymunk_runner import PymunkSimulation
from physics.forcing import steady_drift


def _field(n=3, frozen=None, velocities=None):
    pos = np.array([[10.0, 10.0], [20.0, 12.0], [30.0, 30.0]])[:n]
    radii = np.array([1.0, 2.5, 0.7])[:n]
    thick = np.array([1.0, 2.0, 0.5])[:n]
    vel = np.zeros((n, 2)) if velocities is None else velocities
    return FloeField(pos, radii, thick, vel, frozen=frozen)


# ---------------------------------------------------------------------------
# Runner basics
# ---------------------------------------------------------------------------

def test_bodies_have_the_floes_masses_moments_and_pair_values():
    field = _field(frozen=np.array([False, False, True]))
    sim = PymunkSimulation(field, WalledBox(40.0), restitution=0.49, friction=0.36, dt=0.01)
    np.testing.assert_allclose(sim.masses[:2], field.masses[:2], rtol=1e-15)
    np.testing.assert_allclose(sim.moments[:2], 0.5 * field.masses[:2] * field.radii[:2] ** 2,
                               rtol=1e-15)
    assert sim.bodies[2].body_type == pymunk.Body.STATIC
    assert math.isinf(sim.masses[2])
    for s in sim.shapes:
        assert s.elasticity == pytest.approx(0.7, rel=1e-15)
        assert s.friction == pytest.approx(0.6, rel=1e-15)
        # Chipmunk multiplies the two shapes' values
        assert s.elasticity * s.elasticity == pytest.approx(0.49, rel=1e-15)
        assert s.friction * s.friction == pytest.approx(0.36, rel=1e-15)
    sp = sim.space
    assert tuple(sp.gravity) == (0.0, 0.0) and sp.damping == 1.0
    assert math.isinf(sp.sleep_time_threshold)
    assert len(sim.walls) == 4


def test_head_on_impact_follows_restitution_and_counts_one_collision():
    """Equal floes, head on, e = 0.64: the striker keeps (1 - e)/2 of its
    velocity and the target gets (1 + e)/2, exactly (one solver pass)."""
    field = FloeField(np.array([[10.0, 20.0], [14.0, 20.0]]), np.array([1.0, 1.0]), 1.0,
                      np.array([[1.0, 0.0], [0.0, 0.0]]))
    sim = PymunkSimulation(field, WalledBox(40.0), restitution=0.64, dt=0.5)
    sim.step(8)                               # contact at t = 2 s, detected at its end
    np.testing.assert_allclose(sim.velocities, [[0.18, 0.0], [0.82, 0.0]], atol=1e-14)
    assert sim.collision_count == 1 and sim.wall_collision_count == 0
    assert sim.time == pytest.approx(4.0)


def test_walls_are_elastic_frictionless_and_not_counted_as_collisions():
    """A spinning floe hits the wall at x = 0 obliquely with floe restitution
    0.25 and friction 0.81: the wall contact has its own e = 1, mu = 0, so
    the normal velocity is reversed exactly and the tangential velocity and
    the spin are unchanged."""
    field = FloeField(np.array([[3.0, 20.0]]), np.array([1.0]), 1.0, np.array([[-1.0, 0.5]]),
                      np.array([0.3]))
    sim = PymunkSimulation(field, WalledBox(40.0), restitution=0.25, friction=0.81, dt=0.01)
    sim.advance(4.0)
    np.testing.assert_allclose(sim.velocities[0], [1.0, 0.5], atol=1e-12)
    assert sim.angular_velocities[0] == pytest.approx(0.3, abs=1e-12)
    assert sim.collision_count == 0 and sim.wall_collision_count == 1
    assert sim.kinetic_energy() == pytest.approx(
        0.5 * field.masses[0] * 1.25 + 0.5 * field.inertia[0] * 0.09, rel=1e-12)


def test_frozen_floe_is_an_immovable_obstacle():
    field = FloeField(np.array([[10.0, 20.0], [14.0, 20.0]]), np.array([1.0, 1.0]), 1.0,
                      np.array([[1.0, 0.0], [0.0, 0.0]]), frozen=np.array([False, True]))
    sim = PymunkSimulation(field, WalledBox(40.0), restitution=0.5, dt=0.5)
    sim.step(8)
    np.testing.assert_allclose(sim.velocities, [[-0.5, 0.0], [0.0, 0.0]], atol=1e-14)
    np.testing.assert_allclose(sim.positions[1], [14.0, 20.0], atol=0.0)
    assert sim.collision_count == 1


@pytest.mark.parametrize("kwargs, match", [
    (dict(dt=0.0), "dt"),
    (dict(dt=-1.0), "dt"),
    (dict(restitution=0.0), "restitution"),
    (dict(restitution=1.5), "restitution"),
    (dict(friction=-0.1), "friction"),
    (dict(iterations=0), "iterations"),
    (dict(forcing=Forcing(HERMAN2011.forcing), drag="quadratic"), "drag"),
    (dict(forcing=Forcing(HERMAN2011.forcing), drag=None), "drag"),
    (dict(forcing=Forcing(HERMAN2013.forcing), drag="stokes"), "Coriolis"),
    (dict(wall_restitution=1.2), "wall_restitution"),
])
def test_bad_input_raises(kwargs, match):
    args = dict(restitution=0.5, dt=0.01)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        PymunkSimulation(_field(), WalledBox(40.0), **args)


def test_bad_field_and_box_raise():
    with pytest.raises(ValueError, match="FloeField"):
        PymunkSimulation(np.zeros((3, 2)), WalledBox(40.0), restitution=0.5)
    with pytest.raises(ValueError, match="Box"):
        PymunkSimulation(_field(), 40.0, restitution=0.5)
    crossing = FloeField(np.array([[0.5, 10.0], [20.0, 20.0]]), np.array([1.0, 1.0]), 1.0)
    with pytest.raises(ValueError, match="crosses a side"):
        PymunkSimulation(crossing, PeriodicBox(40.0), restitution=0.5)
    sim = PymunkSimulation(_field(), WalledBox(40.0), restitution=0.5)
    with pytest.raises(ValueError, match="dt"):
        sim.dt = 0.0


# ---------------------------------------------------------------------------
# Drag through the velocity functions
# ---------------------------------------------------------------------------

def _far_apart(n=2, shift=0.0):
    pos = np.array([[20.0, 20.0], [80.0, 80.0]])[:n] + shift
    return FloeField(pos, np.array([1.0, 3.0])[:n], np.array([1.0, 2.0])[:n],
                     np.array([[0.3, -0.2], [-0.1, 0.05]])[:n], np.array([0.2, -0.1])[:n])


def test_stokes_implicit_update_equals_the_hard_disc_engine():
    """Two floes that never meet, Stokes drag of Herman (2011) with the
    linearly implicit update at Δt = Δt_max = 1 s: velocities and positions
    equal the hard-disc engine's after 50 s within 1e-12."""
    field = _far_apart()
    forcing = Forcing(HERMAN2011.forcing)
    hd = HardDiskSimulation(field, PeriodicBox(100.0), restitution=0.5, forcing=forcing,
                            max_velocity_step=1.0, collision_duration=0.0)
    pm = PymunkSimulation(field, WalledBox(100.0), restitution=0.5, forcing=forcing,
                          drag="stokes", dt=1.0, stokes_scheme="implicit")
    hd.advance(50.0)
    pm.step(50)
    np.testing.assert_allclose(pm.velocities, hd.velocities, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(pm.positions, hd.positions, rtol=1e-12)


def test_stokes_exponential_update_is_exact():
    """The exponential Stokes update gives u(t) = u_eq + (u_0 − u_eq) e^(−t/τ)
    at any step (1e-12); spins are untouched (no rotational drag in 2011)."""
    field = _far_apart(shift=1000.0)
    forcing = Forcing(HERMAN2011.forcing)
    pm = PymunkSimulation(field, WalledBox(2000.0), restitution=0.5, forcing=forcing,
                          drag="stokes", dt=0.7)
    pm.step(300)
    tau = forcing.time_constant(field.radii, field.thickness, field.masses)
    u_eq = forcing.equilibrium_velocity(field.radii, field.thickness, field.masses)
    expected = u_eq + (field.velocities - u_eq) * np.exp(-pm.time / tau)[:, None]
    np.testing.assert_allclose(pm.velocities, expected, rtol=1e-12)
    np.testing.assert_allclose(pm.angular_velocities, field.angular_velocities, rtol=0.0)


def test_herman2013_drag_reaches_the_coriolis_free_drift():
    """Quadratic-air/linear-water drag with Coriolis (Herman 2013): after
    40 time constants the velocity equals the analytic steady drift of
    physics.forcing.steady_drift (turned to the right of the wind for
    f > 0) within 1e-9, and the spin has decayed as exp(−(c/I) t)."""
    field = _far_apart(shift=5e4)
    forcing = Forcing(HERMAN2013.forcing, wind=(0.0, 8.0))
    pm = PymunkSimulation(field, WalledBox(1e5), restitution=0.5, forcing=forcing,
                          drag="herman2013", dt=5.0)
    k = forcing.coefficients(field.radii, field.thickness, field.masses)
    tau = float(np.max(field.masses / k.water))
    pm.advance(40.0 * tau)
    drift = steady_drift(forcing, field.radii, field.thickness, field.masses)
    np.testing.assert_allclose(pm.velocities, drift, rtol=1e-9)
    assert np.all(drift[:, 0] > 0.0)        # to the right of a wind towards +y
    np.testing.assert_allclose(
        pm.angular_velocities,
        field.angular_velocities * np.exp(-k.rotation / field.inertia * pm.time), rtol=1e-9)


# ---------------------------------------------------------------------------
# Binary impacts
# ---------------------------------------------------------------------------

def test_binary_frictionless_both_engines_follow_the_restitution_law():
    rows = {r.name: r for r in binary_frictionless(None, seed=11, progress=False,
                                                   n_impacts=300)}
    for name in ("harddisk-vs-law", "pymunk-vs-law", "harddisk-vs-pymunk"):
        row = rows[f"binary/frictionless/{name}"]
        assert row.measured <= 1e-6, f"{name}: {row.measured:.3g}"


def test_rigid_coulomb_law_for_equal_discs():
    """Equal discs: gross sliding gives β = −1 + 3/ψ and
    Δω = −μ(1 + e) v_n / r for v_s > 0; below ψ = 3 the slip is stopped
    (β = 0) with Δω = −v_s / (3 r)."""
    m = np.array([2.0, 2.0])
    r = np.array([0.5, 0.5])
    e, mu, vn = 0.5, 0.4, 0.1
    slide = rigid_coulomb_impact(m, r, vn, 6.0 * mu * (1 + e) * vn, e, mu)
    assert slide["sliding"] and slide["psi"] == pytest.approx(6.0)
    assert slide["beta"] == pytest.approx(-0.5, rel=1e-12)
    np.testing.assert_allclose(slide["spin_change"], -mu * (1 + e) * vn / r[0], rtol=1e-12)
    vs = 2.0 * mu * (1 + e) * vn
    stick = rigid_coulomb_impact(m, r, vn, vs, e, mu)
    assert not stick["sliding"]
    assert stick["beta"] == pytest.approx(0.0, abs=1e-15)
    np.testing.assert_allclose(stick["spin_change"], -vs / (3 * r[0]), rtol=1e-12)


def test_binary_friction_rows_meet_their_tolerances():
    rows = {r.name: r for r in binary_friction(None, quick=True, seed=5, progress=False,
                                               n_pairs=90)}
    assert rows["binary/friction/pymunk-vs-rigid-law"].measured <= 1e-6
    assert rows["binary/friction/hertz-vs-gross-sliding"].measured <= 1e-3
    assert rows["binary/friction/hertz-vs-pymunk-sliding"].measured <= 1e-3
    assert rows["binary/friction/hertz-vs-gross-sliding-e0.5"].measured <= 3e-2


@pytest.mark.parametrize("psi", [1.0, 1.5, 2.0])
def test_sticking_pymunk_stops_the_slip_hertz_rebounds(psi):
    """Equal floes, e = 0.5, μ = 0.7 (Herman 2013), ψ < 3 where the rigid
    law sticks: pymunk brings the contact-point slip to zero (|β| < 1e-6),
    the Mindlin spring of the Hertz engine reverses it (β > 0.2)."""
    e, mu, vn = 0.5, 0.7, 1e-4
    slip = psi * mu * (1 + e) * vn
    pm = pymunk_oblique_impact((1.0, 1.0), 1.0, e, mu, vn, slip, 0.3)
    hz = hertz_pair_impact((1.0, 1.0), 1.0, e, mu, vn, slip)
    assert abs(pm["beta"]) < 1e-6
    assert hz["beta"] > 0.2
    assert hz["normal_restitution"] == pytest.approx(e, abs=0.01)


# ---------------------------------------------------------------------------
# Gases
# ---------------------------------------------------------------------------

def test_small_cooling_gas_engines_agree_and_follow_haff():
    rows = {r.name: r for r in gas_cooling(None, seed=7, progress=False, n_floes=500,
                                           n_seeds=3, samples=20)}
    for name in ("harddisk-vs-pymunk", "harddisk-vs-haff", "pymunk-vs-haff"):
        row = rows[f"gas/cooling/{name}"]
        assert row.measured <= 0.10, f"{name}: {row.measured:.3g} ({row.detail})"


def test_drag_relaxation_to_the_mean_drift():
    """Equal floes: the mean velocity follows ū_eq (1 − e^(−t/τ)) exactly
    (momentum-conserving collisions, no floe at a wall): pymunk with the
    exponential update within 1e-9 of |ū_eq|, the hard-disc engine (implicit
    update every second) within 1e-3, and the engines within 1 %."""
    rows = {r.name: r for r in drag_relaxation(None, seed=2, progress=False, n_floes=300,
                                               samples=10)}
    assert rows["gas/drag/pymunk-vs-analytic"].measured <= 1e-9
    assert rows["gas/drag/harddisk-vs-analytic"].measured <= 1e-3
    assert rows["gas/drag/harddisk-vs-pymunk"].measured <= 1e-2
    assert "wall contacts 0" in rows["gas/drag/harddisk-vs-pymunk"].detail
