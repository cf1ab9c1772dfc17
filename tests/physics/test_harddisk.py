"""The event-driven hard-disc engine: collisions, calendar, drag, collapse, input.

Tolerances: single collisions and the drag formulas are exact to rounding
(1e-12 relative); the drift of the linearised integrator is checked against
the bound |x − x_exact| ≤ |u₀ − u_eq| Δt_max derived in the drag test; the
Herman (2011) set-up (slow) within 10 % of the paper's 0.23 m/s.
(Gas-theory checks — Enskog, Henderson, Haff — are in test_harddisk_gas.py.)
"""
import math

import numpy as np
import pytest

from physics import (HERMAN2011, HERMAN2013, ChannelBox, DeformingPeriodicBox, FloeField,
                     Forcing, HardDiskSimulation, PeriodicBox, make_floe_field)
from physics import harddisk_kernels as K
from physics.engine import FailureReason, SimulationError
from physics.event_calendar import heap_build, heap_check, heap_update, new_calendar
from physics.floes import max_overlap


def two_discs(r1=0.5, r2=1.0, gap=1.0, v1=(1.0, 0.0), v2=(0.0, 0.0), offset=0.0, **kw):
    pos = np.array([[10.0, 20.0], [10.0 + r1 + r2 + gap, 20.0 + offset]])
    field = FloeField(pos, np.array([r1, r2]), 1.0, np.array([v1, v2], dtype=float))
    kw.setdefault("restitution", 1.0)
    kw.setdefault("collision_duration", 0.0)
    return HardDiskSimulation(field, PeriodicBox(40.0), **kw), field


# -- event calendar --------------------------------------------------------------

def test_calendar_orders_events_under_updates():
    rng = np.random.default_rng(0)
    n = 200
    cal = new_calendar(n)
    cal.time[:] = rng.random(n)
    heap_build(cal)
    assert heap_check(cal)
    for _ in range(2000):
        i = int(rng.integers(n))
        heap_update(cal, i, float(rng.random()) * (1.0 if rng.random() < 0.5 else 10.0))
        assert cal.time[cal.heap[0]] == cal.time.min()
    assert heap_check(cal)


# -- single collisions -------------------------------------------------------------

@pytest.mark.parametrize("eps", [1.0, 0.85, 0.3])
def test_head_on_collision_follows_eqs_10_11(eps):
    sim, field = two_discs(restitution=eps, log_collisions=True)
    m1, m2 = field.masses
    sim.advance(2.0)                       # contact after 1 s (gap 1 m at 1 m/s)
    log = sim.collision_log
    assert len(log) == 1 and sim.collision_count == 1
    assert log.time[0] == pytest.approx(1.0, rel=1e-12)
    n = (1 + eps) / (m1 + m2) * 1.0
    v = sim.velocities
    np.testing.assert_allclose(v[0], [1.0 - m2 * n, 0.0], atol=1e-12)
    np.testing.assert_allclose(v[1], [m1 * n, 0.0], atol=1e-12)
    np.testing.assert_allclose(log.impulse[0], [m1 * m2 * n, 0.0], rtol=1e-12)
    lost = 0.5 * (1 - eps ** 2) * m1 * m2 / (m1 + m2)
    assert sim.diagnostics["energy_lost"] == pytest.approx(lost, rel=1e-12, abs=1e-12)
    assert 0.5 * m1 - sim.kinetic_energy() == pytest.approx(lost, rel=1e-9, abs=1e-9)
    np.testing.assert_allclose(sim.momentum(), [m1, 0.0], rtol=1e-12, atol=1e-12)


def test_oblique_collision_changes_only_the_normal_component():
    sim, field = two_discs(r1=1.0, r2=1.0, gap=1.0, offset=1.0, restitution=1.0)
    sim.advance(5.0)
    m = field.masses[0]
    # at contact the centre line makes 30° with x (offset 1 = 2 r sin 30°)
    nx, ny = math.cos(math.pi / 6), math.sin(math.pi / 6)
    v = sim.velocities
    np.testing.assert_allclose(v[1], [nx * nx, nx * ny], atol=1e-12)
    np.testing.assert_allclose(v[0], [1 - nx * nx, -nx * ny], atol=1e-12)
    assert sim.kinetic_energy() == pytest.approx(0.5 * m, rel=1e-12)


def test_frozen_floe_reflects_with_restitution_and_never_moves():
    pos = np.array([[10.0, 20.0], [12.5, 20.0]])
    field = FloeField(pos, np.array([0.5, 1.0]), 1.0, np.array([[1.0, 0.0], [0.0, 0.0]]),
                      frozen=np.array([False, True]))
    sim = HardDiskSimulation(field, PeriodicBox(40.0), restitution=0.5, collision_duration=0.0)
    sim.advance(3.0)
    np.testing.assert_allclose(sim.velocities[0], [-0.5, 0.0], atol=1e-12)
    np.testing.assert_array_equal(sim.positions[1], pos[1])
    np.testing.assert_array_equal(sim.velocities[1], [0.0, 0.0])


def test_collision_log_grows_and_matches_the_count():
    field, box = make_floe_field(300, concentration=0.5, alpha=1.5, mean_diameter=2.0, seed=4,
                                 velocity_std=0.5)
    sim = HardDiskSimulation(field, box, restitution=1.0, collision_duration=0.0,
                             log_collisions=True)
    sim.advance(20.0)
    log = sim.collision_log
    assert sim.collision_count > 2048            # past two doublings of the log
    assert len(log) == sim.collision_count
    assert np.all(np.diff(log.time) >= 0.0)
    assert np.all(log.i != log.j)
    sim.clear_collision_log()
    assert len(sim.collision_log) == 0
    off = HardDiskSimulation(field, box)
    with pytest.raises(ValueError, match="log_collisions=True"):
        _ = off.collision_log


# -- calendar and cells against brute force ----------------------------------------

def _pair_times(sim):
    """Brute force: time of the next contact of every pair (inf if none)."""
    x = sim.positions
    v = sim.velocities
    r = sim.radii
    L = sim.L
    dx = x[None, :, :] - x[:, None, :]
    dx -= L * np.round(dx / L)
    dv = v[None, :, :] - v[:, None, :]
    sig = r[:, None] + r[None, :]
    b = np.sum(dx * dv, axis=2)
    a = np.sum(dv * dv, axis=2)
    c = np.sum(dx * dx, axis=2) - sig ** 2
    disc = b * b - a * c
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where((b < 0) & (disc > 0), c / (-b + np.sqrt(np.maximum(disc, 0))), np.inf)
    np.fill_diagonal(t, np.inf)
    return t


@pytest.mark.parametrize("seed", [1, 2])
def test_every_coming_contact_is_in_the_calendar(seed):
    """Invariant of the one-event-per-floe calendar: for every pair, one of
    the two floes has an event no later than the pair's next contact. Checked
    with big floes (power-law sizes) at several times."""
    field, box = make_floe_field(400, concentration=0.65, alpha=1.5, mean_diameter=2.0,
                                 seed=seed, velocity_std=0.3)
    sim = HardDiskSimulation(field, box, restitution=0.85, collision_duration=0.0)
    assert sim._cover.floes.size > 0
    for _ in range(5):
        sim.advance(3.0)
        t_pair = _pair_times(sim) + sim.time
        ev = sim._calendar.time
        first = np.minimum(ev[:, None], ev[None, :])
        finite = np.isfinite(t_pair)
        assert finite.sum() > 100
        late = first[finite] - t_pair[finite]
        assert late.max() <= 1e-9, f"a contact is missing from the calendar by {late.max():.3g} s"
        assert max_overlap(sim.positions, field.radii, box) <= 1e-9
    assert sim.repairs == 0


# -- drag ---------------------------------------------------------------------------

def _lanes(diameters, u0=0.0):
    """Floes in separate rows along the wind: they never meet."""
    d = np.asarray(diameters, dtype=float)
    n = d.size
    L = max(60.0, 3.0 * n * d.max())
    pos = np.column_stack([np.full(n, 0.25 * L), (np.arange(n) + 0.5) * L / n])
    vel = np.column_stack([np.full(n, u0), np.zeros(n)])
    th = HERMAN2011.thickness
    return FloeField(pos, 0.5 * d, th, vel, density=HERMAN2011.forcing.ice_density), PeriodicBox(L)


def test_equilibrium_velocity_matches_eqs_6_to_8():
    p = HERMAN2011.forcing
    h = HERMAN2011.thickness
    d = np.array([1.0, 2.0, 10.0, 1000.0])
    field, _ = _lanes(d)
    forcing = Forcing(p)
    u_eq = forcing.equilibrium_velocity(field.radii, field.thickness, field.masses)[:, 0]
    rho, rho_w, rho_a = p.ice_density, p.water_density, p.air_density
    inv_tau = rho_w * p.water_skin_drag / (rho * h) + 4 * p.water_form_drag / (np.pi * d)
    C = (rho_a * p.air_skin_drag / (rho * h)
         + 4 * (rho_w - rho) * rho_a * p.air_form_drag / (np.pi * rho_w * rho * d)) / inv_tau
    expected = 0.01 * 10.0 + C * 10.0 * 10.0
    np.testing.assert_allclose(u_eq, expected, rtol=1e-12)
    np.testing.assert_allclose(1.0 / forcing.time_constant(field.radii, field.thickness,
                                                            field.masses), inv_tau, rtol=1e-12)
    assert u_eq[0] == pytest.approx(0.17, abs=0.005)       # d = 1 m (the Physics page: physics-drag)
    assert u_eq[-1] == pytest.approx(0.26, abs=0.005)      # large floes


@pytest.mark.parametrize("dt_max", [1.0, 10.0, 50.0])
def test_drag_relaxes_to_u_eq_within_the_derived_position_bound(dt_max):
    """Eq 13 moves a floe with its velocity at the last update, eq 14 then
    updates the velocity implicitly. With D = u₀ − u_eq, h = Δt/τ and
    r = 1/(1 + h), after n updates x − x_exact = D [Δt (1 − rⁿ) + τ (e^(−nh) − rⁿ)];
    the first term lies in [0, Δt], the second in [−Δt/(2e), 0], so
    |x − x_exact| ≤ |D| Δt_max at all times, approached as t → ∞."""
    d = np.array([1.0, 3.0, 30.0])
    field, box = _lanes(d, u0=0.0)
    forcing = Forcing(HERMAN2011.forcing)
    sim = HardDiskSimulation(field, box, restitution=0.85, forcing=forcing,
                             max_velocity_step=dt_max, collision_duration=0.1)
    tau = forcing.time_constant(field.radii, field.thickness, field.masses)
    u_eq = forcing.equilibrium_velocity(field.radii, field.thickness, field.masses)[:, 0]
    x0 = field.positions[:, 0].copy()
    travelled = np.zeros(d.size)
    last = x0.copy()
    worst = np.zeros(d.size)
    t_total = 8 * tau.max()
    n_chunks = 200
    for _ in range(n_chunks):
        sim.advance(t_total / n_chunks)
        x = sim.positions[:, 0]
        travelled += (x - last + 0.5 * box.lx) % box.lx - 0.5 * box.lx
        last = x
        t = sim.time
        exact = u_eq * t - tau * (0.0 - u_eq) * (np.exp(-t / tau) - 1.0)     # eq 12, u0 = 0
        worst = np.maximum(worst, np.abs(travelled - exact))
    bound = np.abs(0.0 - u_eq) * dt_max
    assert np.all(worst <= bound * (1 + 1e-9) + 1e-9), (worst, bound)
    assert np.all(worst >= 0.5 * bound), "the bound should be nearly reached (it is tight)"
    np.testing.assert_allclose(sim.velocities[:, 0], u_eq, rtol=1e-3)
    np.testing.assert_allclose(sim.velocities[:, 1], 0.0, atol=1e-15)
    assert sim.collision_count == 0


def test_wind_change_between_calls_takes_effect():
    field, box = _lanes([5.0, 5.0])
    forcing = Forcing(HERMAN2011.forcing)
    sim = HardDiskSimulation(field, box, forcing=forcing, max_velocity_step=5.0)
    forcing.wind = (0.0, 10.0)
    forcing.current = (0.0, 0.1)
    sim.advance(20000.0)
    assert abs(sim.velocities[:, 0]).max() < 1e-6
    assert sim.velocities[0, 1] > 0.2


# -- inelastic collapse ---------------------------------------------------------------

def _three_in_a_row(collision_duration):
    r = np.full(3, 0.5)
    pos = np.array([[5.0, 10.0], [6.3, 10.0], [7.4, 10.0]])
    vel = np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 0.0]])
    return HardDiskSimulation(FloeField(pos, r, 1.0, vel), PeriodicBox(20.0), restitution=0.05,
                              collision_duration=collision_duration)


def test_tc_model_keeps_three_disc_collapse_bounded():
    sim = _three_in_a_row(0.1)
    sim.advance(5.0)
    assert sim.time == 5.0
    assert 2 <= sim.collision_count <= 20
    assert sim.diagnostics["tc_elastic"] >= 1


def test_collapse_without_tc_model_stops_with_a_clear_error():
    sim = _three_in_a_row(0.0)
    with pytest.raises(SimulationError, match="inelastic collapse.*collision_duration") as err:
        sim.advance(5.0)
    assert err.value.reason is FailureReason.INELASTIC_COLLAPSE
    assert 0.0 < err.value.time < 5.0
    assert sim.collision_count >= K.COLLAPSE_EVENTS


# -- Herman (2011) set-up ------------------------------------------------------------------

@pytest.mark.slow
def test_herman2011_quasi_steady_drift():
    """N = 3000, Ā = 0.75, wind 10 m/s: the mass-weighted mean along-wind
    velocity approaches about 0.23 m/s (paper), and Σ m u tends to Σ m u_eq."""
    P = HERMAN2011
    field, box = make_floe_field(3000, concentration=0.75, alpha=P.fsd_exponent,
                                 mean_diameter=P.mean_diameter, thickness=P.thickness, seed=1,
                                 velocity_std=0.01)
    forcing = Forcing(P.forcing)
    sim = HardDiskSimulation(field, box, restitution=P.contact.restitution, forcing=forcing,
                             max_velocity_step=1.0, collision_duration=0.1)
    sim.advance(5000.0)
    m = sim.masses
    u = (m * sim.velocities[:, 0]).sum() / m.sum()
    u_eq = forcing.equilibrium_velocity(field.radii, field.thickness, m)[:, 0]
    assert u == pytest.approx(0.23, rel=0.10)
    assert u == pytest.approx((m * u_eq).sum() / m.sum(), rel=0.05)
    assert max_overlap(sim.positions, field.radii, box) <= 1e-9


# -- bad input ------------------------------------------------------------------------

def _field(n=100, seed=0):
    return make_floe_field(n, concentration=0.3, alpha=1.5, mean_diameter=2.0, seed=seed,
                           velocity_std=0.1)


@pytest.mark.parametrize("kw, match", [
    (dict(restitution=0.0), "restitution"),
    (dict(restitution=1.2), "restitution"),
    (dict(restitution=float("nan")), "restitution"),
    (dict(max_velocity_step=0.0), "max_velocity_step"),
    (dict(max_velocity_step=-1.0), "max_velocity_step"),
    (dict(collision_duration=-0.1), "collision_duration"),
    (dict(collision_duration=float("nan")), "collision_duration"),
])
def test_bad_parameters_raise(kw, match):
    field, box = _field()
    with pytest.raises(ValueError, match=match):
        HardDiskSimulation(field, box, **kw)


def test_bad_set_ups_raise():
    field, box = _field()
    bad = field.copy()
    bad.positions[1] = bad.positions[0] + 0.1
    with pytest.raises(ValueError, match="overlap"):
        HardDiskSimulation(bad, box)
    with pytest.raises(ValueError, match="square"):
        HardDiskSimulation(field, PeriodicBox(box.lx, 1.5 * box.lx))
    with pytest.raises(ValueError, match="non-deforming"):
        HardDiskSimulation(field, DeformingPeriodicBox(box.lx, concentration_rate=1e-5))
    with pytest.raises(ValueError, match="Coriolis"):
        HardDiskSimulation(field, box, forcing=Forcing(HERMAN2011.forcing, coriolis=1e-4))
    small_box = FloeField(np.array([[2.0, 2.0], [6.0, 6.0], [6.0, 2.0]]),
                          np.array([3.0, 0.5, 0.5]), 1.0, np.zeros((3, 2)))
    with pytest.raises(ValueError, match="too small"):
        HardDiskSimulation(small_box, PeriodicBox(8.0))
    with pytest.raises(ValueError, match="NaN|finite|nan"):
        FloeField(np.array([[0.0, np.nan], [5.0, 5.0]]), np.ones(2), 1.0, np.zeros((2, 2)))
    sim = HardDiskSimulation(field, box)
    with pytest.raises(ValueError, match="duration"):
        sim.advance(-1.0)
    with pytest.raises(ValueError, match="velocities"):
        sim.velocities = np.full((field.n, 2), np.nan)


def test_wrong_types_raise_type_error():
    field, box = _field()
    with pytest.raises(TypeError, match="FloeField"):
        HardDiskSimulation(field.positions, box)
    with pytest.raises(TypeError, match="PeriodicBox"):
        HardDiskSimulation(field, ChannelBox(box.lx, box.ly))
    with pytest.raises(TypeError, match="PeriodicBox"):
        HardDiskSimulation(field, box.lx)
    with pytest.raises(TypeError, match="forcing"):
        HardDiskSimulation(field, box, forcing=HERMAN2011.forcing)


def test_non_finite_event_time_raises_simulation_error():
    field, box = _field()
    sim = HardDiskSimulation(field, box)
    sim.advance(1.0)
    cal = sim._calendar
    cal.time[cal.heap[0]] = np.nan           # what a corrupted prediction would give
    with pytest.raises(SimulationError, match="non-finite") as err:
        sim.advance(1.0)
    assert err.value.reason is FailureReason.NON_FINITE
    assert err.value.time == pytest.approx(1.0)


# -- set-up from a preset -----------------------------------------------------------------

def test_from_preset_builds_the_preset_set_up():
    """The same floes, parameters and forcing as the set-up written out by hand,
    hence the same trajectory."""
    P = HERMAN2011
    sim = HardDiskSimulation.from_preset(P, 300, 0.6, seed=2, velocity_std=0.01,
                                         log_collisions=True)
    field, box = make_floe_field(300, concentration=0.6, alpha=P.fsd_exponent,
                                 mean_diameter=P.mean_diameter, thickness=P.thickness,
                                 density=P.forcing.ice_density, seed=2, velocity_std=0.01)
    ref = HardDiskSimulation(field, box, restitution=P.contact.restitution,
                             forcing=Forcing(P.forcing), max_velocity_step=P.max_velocity_step,
                             collision_duration=P.collision_duration)
    assert (sim.n_floes, sim.restitution, sim.max_velocity_step, sim.collision_duration) == (
        300, 0.85, 1.0, 0.1)
    assert sim.box.lx == box.lx and sim.forcing.wind.tolist() == [10.0, 0.0]
    for s in (sim, ref):
        s.advance(30.0)
    assert sim.collision_count == ref.collision_count > 0
    np.testing.assert_array_equal(sim.positions, ref.positions)
    assert len(sim.collision_log) == sim.collision_count


def test_from_preset_keywords_replace_the_presets_numerics():
    """(The options both engines share are in test_engine_protocol.py.)"""
    free = HardDiskSimulation.from_preset(HERMAN2011, 200, 0.5, forcing=False, restitution=1.0,
                                          collision_duration=0.0, max_velocity_step=2.0)
    assert free.forcing is None
    assert (free.restitution, free.collision_duration, free.max_velocity_step) == (1.0, 0.0, 2.0)
    with pytest.raises(ValueError, match="Coriolis"):
        HardDiskSimulation.from_preset(HERMAN2013, 200, 0.5)
