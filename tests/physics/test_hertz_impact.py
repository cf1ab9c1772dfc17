"""Binary Hertz impacts against the analytic two-body solution (Herman 2013;
the Physics page: physics-contact): peak overlap, contact time, normal restitution and
Coulomb sliding in oblique impacts."""
from __future__ import annotations

import numpy as np
import pytest

from physics import ContactParams

from reference.dem import hertz_contact_time, hertz_peak_overlap, run_impact

ELASTIC = ContactParams(restitution=1.0, friction=0.0)


# ---------------------------------------------------------------------------
# 1. Undamped head-on impact
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("radii, thickness, speed", [
    ((1.0, 1.0), 1.0, 0.1),          # equal floes
    ((1.0, 3.0), 1.0, 0.1),          # unequal radii
    ((0.5, 2.0), (1.5, 0.8), 1.0),   # unequal radii and thickness, fast
    ((2.0, 2.0), (1.0, 2.0), 1e-3),  # equal radii, unequal masses, slow
])
def test_undamped_impact_peak_overlap_and_contact_time(radii, thickness, speed):
    """Undamped, frictionless head-on impact: the largest overlap is
    (5 m* v^2 / (4 k))^(2/5) and the contact lasts 3.2181 (m*/k)^(2/5) v^(-1/5),
    k = (4/3) E* sqrt(R*), both within 1 % (dt = t_c / 1000, so the contact
    time is resolved to 0.2 %). The floes leave with their approach speed
    (restitution 1 within 1e-3)."""
    res = run_impact(radii, speed, ELASTIC, thickness=thickness, record=True)
    delta_max = hertz_peak_overlap(res.m_eff, res.k, speed)
    t_c = hertz_contact_time(res.m_eff, res.k, speed)
    steps = res.contact_steps
    measured_time = (steps[-1] - steps[0] + 1) * res.dt
    assert np.all(np.diff(steps) == 1), "the contact is not one continuous interval"
    assert res.overlaps.max() == pytest.approx(delta_max, rel=0.01)
    assert measured_time == pytest.approx(t_c, rel=0.01)
    assert res.restitution == pytest.approx(1.0, abs=1e-3)


# ---------------------------------------------------------------------------
# 2. Damped head-on impact: restitution independent of impact speed
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("restitution", [0.1, 0.5, 0.85])
@pytest.mark.parametrize("speed", [1e-3, 1e-2, 1e-1, 1.0])
def test_restitution_is_target_at_all_speeds(restitution, speed):
    """Frictionless damped impact of equal floes: the measured normal
    restitution equals the target within 1e-3 for impact speeds over three
    decades (dt = t_c / 1000 of each speed; velocities measured after
    separation)."""
    res = run_impact((1.0, 1.0), speed, ContactParams(restitution=restitution, friction=0.0))
    assert res.restitution == pytest.approx(restitution, abs=1e-3)


@pytest.mark.parametrize("restitution", [0.1, 0.5, 0.85])
def test_restitution_unequal_floes(restitution):
    """Restitution does not depend on the mass or size ratio: floes of radii
    0.6 and 2.5 m and thicknesses 2 and 1 m rebound with the target
    restitution within 1e-3."""
    res = run_impact((0.6, 2.5), 0.2, ContactParams(restitution=restitution, friction=0.0),
                     thickness=(2.0, 1.0))
    assert res.restitution == pytest.approx(restitution, abs=1e-3)


@pytest.mark.parametrize("restitution", [0.1, 0.5, 0.85])
@pytest.mark.parametrize("speed", [1e-3, 1.0])
def test_lammps_damping_without_clipping_gives_target(restitution, speed):
    """damping_model="lammps" (alpha = sqrt(5) |ln e| / sqrt(pi^2 + ln^2 e)) with
    limit_damping=False: the measured restitution equals the target within
    1e-3 at 1e-3 and 1 m/s."""
    contact = ContactParams(restitution=restitution, friction=0.0, damping_model="lammps",
                            limit_damping=False)
    res = run_impact((1.0, 1.0), speed, contact)
    assert res.restitution == pytest.approx(restitution, abs=1e-3)


@pytest.mark.parametrize("restitution", [0.1, 0.3, 0.5])
def test_exact_damping_without_clipping_gives_target(restitution):
    """damping_model="exact" with limit_damping=False (attractive damping
    force allowed at the end of the contact): restitution equals the target
    within 1e-3."""
    contact = ContactParams(restitution=restitution, friction=0.0, limit_damping=False)
    res = run_impact((1.0, 1.0), 0.1, contact)
    assert res.restitution == pytest.approx(restitution, abs=1e-3)


# ---------------------------------------------------------------------------
# 3. Oblique impact with friction: Coulomb sliding
# ---------------------------------------------------------------------------

def coulomb_sliding_changes(res, restitution, friction):
    """Rigid-body changes of an impact that slides throughout.

    J_n = m* (1 + e) u_n; the tangential impulse on i is
    J_t = -mu J_n sign(v_s) (v_s the initial slip, here u_t > 0); then
    Delta (u_i - u_j) . t = J_t / m*, Delta omega_i = J_t r_i / I_i,
    Delta omega_j = J_t r_j / I_j, and the slip changes by
    J_t (1/m_i + 1/m_j + r_i^2/I_i + r_j^2/I_j).
    """
    u_n = res.normal_speed_before
    j_n = res.m_eff * (1.0 + restitution) * u_n
    j_t = -friction * j_n
    d_ut = j_t / res.m_eff
    d_spin = j_t * res.radii / res.inertia
    slip_change = j_t * (1.0 / res.masses + res.radii ** 2 / res.inertia).sum()
    return d_ut, d_spin, slip_change


SLIDING_CASES = [
    # radii, restitution, friction, angle from the line of centres [deg]
    ((1.0, 1.0), 0.5, 0.7, 80.0),
    ((1.0, 1.0), 0.85, 0.3, 70.0),
    ((0.7, 1.5), 0.5, 0.4, 78.0),
]


def _sliding_id(case):
    radii, e, mu, angle = case
    return f"r{radii[0]:g}-{radii[1]:g}_e{e:g}_mu{mu:g}_{angle:g}deg"


def _sliding_params():
    """Every sliding case without and with tangential damping."""
    return [pytest.param(case, gamma_t, id=f"{_sliding_id(case)}-gt{gamma_t:g}")
            for case in SLIDING_CASES for gamma_t in (0.0, 1.0)]


@pytest.mark.parametrize("case, tangential_damping", _sliding_params())
def test_oblique_sliding_impact_follows_coulomb(case, tangential_damping):
    """Oblique impact at an angle where the contact slides from start to end
    (the rigid-body slip change is below the initial slip): the tangential
    impulse is mu times the normal impulse, so the relative tangential
    velocity changes by J_t / m* and the spins by J_t r / I with
    J_t = -mu m* (1 + e) u_n; for equal discs |Delta u_t| = mu (1 + e) u_n and
    Delta omega = -mu (1 + e) u_n / r. Tolerance 3 % (the Mindlin spring needs
    a short loading phase before it reaches the Coulomb limit, which costs up
    to 2 % of the impulse at e = 0.5); dt = t_c/1000. The normal restitution
    is unchanged by friction (within 0.01)."""
    radii, e, mu, angle = case
    contact = ContactParams(restitution=e, friction=mu, tangential_damping=tangential_damping)
    res = run_impact(radii, 0.1, contact, angle_deg=angle)
    d_ut, d_spin, slip_change = coulomb_sliding_changes(res, e, mu)
    slip0 = res.u_rel_before @ res.tangent
    assert abs(slip_change) < slip0, "set-up error: the impact would stop sliding"
    measured_dut = (res.u_rel_after - res.u_rel_before) @ res.tangent
    assert measured_dut == pytest.approx(d_ut, rel=0.03)
    assert res.spin_after == pytest.approx(d_spin, rel=0.03)
    if radii[0] == radii[1]:
        u_n = res.normal_speed_before
        assert measured_dut == pytest.approx(-mu * (1 + e) * u_n, rel=0.03)
        assert res.spin_after == pytest.approx(np.full(2, -mu * (1 + e) * u_n / radii[0]),
                                               rel=0.03)
    assert res.restitution == pytest.approx(e, abs=0.01)


def test_sticking_impact_conserves_angular_momentum():
    """Oblique impact in the sticking/rolling regime (30 degrees, mu = 0.7,
    e = 0.5): the contact forces on the two floes are equal and opposite and
    act at the same point, so the total angular momentum
    sum(m x cross u) + sum(I omega) is unchanged by the impact, within 1e-9 of
    m* |x_i - x_j| |u_i - u_j|, while the spins change (both floes the same,
    equal radii)."""
    contact = ContactParams(restitution=0.5, friction=0.7)
    res = run_impact((1.0, 1.0), 0.1, contact, angle_deg=30.0)
    scale = res.m_eff * res.radii.sum() * np.hypot(*res.u_rel_before)
    change = res.angular_momentum(after=True) - res.angular_momentum(after=False)
    assert abs(change) <= 1e-9 * scale
    assert res.spin_after[0] == pytest.approx(res.spin_after[1], rel=1e-12)
    assert abs(float(res.inertia @ res.spin_after)) > 1e-3 * scale


# ---------------------------------------------------------------------------
# Energy in damped and frictional contacts
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("restitution", [0.1, 0.5, 0.85])
@pytest.mark.parametrize("speed", [1e-3, 1.0])
def test_damped_contact_energy_never_increases(restitution, speed):
    """Frictionless damped impact: the mechanical energy, kinetic
    (translational + rotational) plus the Hertz potential (2/5) k delta^(5/2),
    never increases from one step to the next (allowing 1e-12 of the initial
    energy for round-off), and the kinetic energy after the impact is
    e^2 of the kinetic energy of the relative motion before, within 2e-3."""
    res = run_impact((1.0, 1.0), speed, ContactParams(restitution=restitution, friction=0.0),
                     record=True)
    e0 = res.energies[0]
    assert np.diff(res.energies).max() <= 1e-12 * e0
    lost = e0 - res.energies[-1]
    assert lost / e0 == pytest.approx(1.0 - restitution ** 2, abs=2e-3)


@pytest.mark.parametrize("tangential_damping", [0.0, 1.0])
@pytest.mark.parametrize("case", SLIDING_CASES[:2], ids=_sliding_id)
def test_sliding_contact_energy_never_increases(case, tangential_damping):
    """Oblique impact sliding throughout: friction only removes energy, so
    kinetic (translational + rotational) plus Hertz potential energy never
    increases from one step to the next (1e-12 of the initial energy allowed
    for round-off)."""
    radii, e, mu, angle = case
    contact = ContactParams(restitution=e, friction=mu, tangential_damping=tangential_damping)
    res = run_impact(radii, 0.1, contact, angle_deg=angle, record=True)
    assert np.diff(res.energies).max() <= 1e-12 * res.energies[0]


@pytest.mark.parametrize("restitution, angle, allowed", [(1.0, 30.0, 1e-6), (0.5, 50.0, 1e-12)])
def test_sticking_contact_energy_never_increases(restitution, angle, allowed):
    """Oblique frictional impact (mu = 0.7) that sticks for part of the
    contact (tangential_damping 0, so F_t is the incremental Mindlin spring
    force, k_t = 8 G* sqrt(R* delta)): kinetic plus Hertz potential plus
    Mindlin spring energy F_t^2 / (2 k_t) never increases from one step to
    the next. Allowed per step: 1e-12 of the initial energy (round-off) for
    a damped contact; 1e-6 for the undamped one (e = 1), whose only
    dissipation is friction, so that the O(dt^2) energy error of the
    integrator at t_c/1000 is not masked. (The total form F_t = -k_t xi
    created 4.4 % of the energy in the e = 1 case, at any dt.)"""
    contact = ContactParams(restitution=restitution, friction=0.7, tangential_damping=0.0)
    res = run_impact((1.0, 1.0), 0.1, contact, angle_deg=angle, record=True,
                     tangential_energy=True)
    assert np.diff(res.energies).max() <= allowed * res.energies[0]
    assert res.energies[-1] < res.energies[0]


def test_tangential_stiffness_scales_the_sticking_tangential_force():
    """Two floes held at an overlap of 0.1 mm slide past each other at 1 mm/s
    for 20 steps, far below the Coulomb limit: the tangential force is the
    Mindlin spring k_t √(R* δ) Δs, so ``tangential_stiffness`` = 0.25 gives
    a quarter of the force (to 1 %: the force itself nudges the floes), and
    the normal force does not change. A non-positive factor is refused."""
    from physics import FloeField, HertzSimulation, PeriodicBox

    r = np.array([5.0, 5.0])
    delta, v_t, dt, steps = 1e-4, 1e-3, 1e-4, 20
    pos = np.array([[50.0, 50.0], [50.0 + 2 * 5.0 - delta, 50.0]])
    vel = np.array([[0.0, -0.5 * v_t], [0.0, 0.5 * v_t]])
    forces = {}
    for factor in (1.0, 0.25):
        contact = ContactParams(restitution=0.5, friction=0.7, tangential_stiffness=factor)
        sim = HertzSimulation(FloeField(pos, r, np.full(2, 1.5), vel), PeriodicBox(100.0),
                              contact, None, dt, impact_speed=0.01, allow_overlap=True)
        sim.step(steps)
        c = sim.contacts()
        assert len(c.i) == 1
        forces[factor] = (abs(float(c.tangential_force[0])), float(c.normal_force[0]))
    f_t, f_n = forces[1.0]
    k_t = 8.0 * ContactParams().effective_shear_modulus * np.sqrt(2.5 * delta)   # R* = 2.5 m
    expected = k_t * v_t * steps * dt
    assert f_t == pytest.approx(expected, rel=0.05)
    assert f_t < 0.1 * 0.7 * f_n                      # sticking, far from the Coulomb limit
    assert forces[0.25][0] == pytest.approx(0.25 * f_t, rel=0.01)
    assert forces[0.25][1] == pytest.approx(f_n, rel=1e-6)
    with pytest.raises(ValueError, match="tangential_stiffness"):
        ContactParams(tangential_stiffness=0.0)


@pytest.mark.parametrize("case", SLIDING_CASES, ids=_sliding_id)
def test_friction_that_only_turns_floes(case):
    """``tangential_translation=False`` (Herman 2013, eqs 6-7 as written:
    the tangential force enters only the angular momentum equation). In an
    oblique impact that slides throughout, the floes' centres move exactly
    as in the same impact without friction (relative velocity after the
    impact within 1e-12 of the impact speed: only the normal force moves
    them), while the spins change by the Coulomb impulse,
    Delta omega = J_t r / I with J_t = -mu m* (1 + e) u_n (3 %, as in the
    sliding test above), and the normal restitution is unchanged (0.01)."""
    radii, e, mu, angle = case
    contact = ContactParams(restitution=e, friction=mu, tangential_translation=False)
    res = run_impact(radii, 0.1, contact, angle_deg=angle)
    smooth = run_impact(radii, 0.1, ContactParams(restitution=e, friction=0.0),
                        angle_deg=angle)
    _, d_spin, _ = coulomb_sliding_changes(res, e, mu)
    assert np.abs(res.u_rel_after - smooth.u_rel_after).max() < 1e-12 * 0.1
    assert np.abs(smooth.spin_after).max() == 0.0
    assert res.spin_after == pytest.approx(d_spin, rel=0.03)
    assert res.restitution == pytest.approx(e, abs=0.01)


@pytest.mark.parametrize("name", ["tangential_translation", "limit_damping"])
def test_contact_switches_must_be_booleans(name):
    """A switch given as a number or a string is refused, naming the field."""
    with pytest.raises(ValueError, match=name):
        ContactParams(**{name: "no"})
    with pytest.raises(ValueError, match=name):
        ContactParams(**{name: 0})
