"""External forcing of a lone floe: free drift of Herman (2013) eq 6 with
Coriolis, rotational drag of eq 7, inertial oscillations, and the drift
speeds of Herman (2011) (the Physics page: physics-drag)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from physics import (HERMAN2011, HERMAN2013, FloeField, Forcing, ForcingParams,
                     HertzSimulation, PeriodicBox, steady_drift)


def drag_coefficients(params: ForcingParams, radius, thickness):
    """a = rho_a (pi r^2 C_ha + e r h_f C_va), b = rho_w (pi r^2 C_hw + e r (h - h_f) C_vw)
    with the freeboard h_f = h (rho_w - rho) / rho_w and edge factor e."""
    r = np.asarray(radius, dtype=float)
    h_f = thickness * (params.water_density - params.ice_density) / params.water_density
    e = params.edge_area_factor
    a = params.air_density * (math.pi * r ** 2 * params.air_skin_drag
                              + e * r * h_f * params.air_form_drag)
    b = params.water_density * (math.pi * r ** 2 * params.water_skin_drag
                                + e * r * (thickness - h_f) * params.water_form_drag)
    return a, b


def free_drift(params, wind, current, coriolis, radius, thickness, density=910.0):
    """Steady solution of m du/dt = -m f k x u + a |u_a| u_a + b (u_w - u) = 0,
    solved as a 2x2 linear system [kg/s] u = force."""
    a, b = drag_coefficients(params, radius, thickness)
    m = density * thickness * math.pi * radius ** 2
    wind = np.asarray(wind, dtype=float)
    force = a * np.hypot(*wind) * wind + b * np.asarray(current, dtype=float)
    g = m * coriolis
    # -g k x u - b u = -force, k x u = (-u_y, u_x)
    matrix = np.array([[b, -g], [g, b]])
    return np.linalg.solve(matrix, force)


def lone_floe(radius, thickness, forcing, dt, velocity=(0.0, 0.0), spin=0.0):
    """One floe in a periodic box; it never meets another floe, so the
    time-step check is passed with a vanishing impact speed."""
    side = 100.0 * radius
    floes = FloeField(np.array([[0.5 * side, 0.5 * side]]), [radius], thickness,
                      np.array([velocity]), np.array([spin]))
    return HertzSimulation(floes, PeriodicBox(side), None, forcing, dt, impact_speed=1e-20,
                           skin=radius)


@pytest.mark.parametrize("radius, thickness", [(2.0, 1.5), (10.0, 0.8)])
def test_lone_floe_converges_to_steady_drift(radius, thickness):
    """A lone floe at rest under wind 10 m/s, current (0.05, 0.02) m/s and
    Coriolis f = 1.3e-4 1/s (Herman 2013, Table 1) reaches the analytic steady
    drift of eq 6 within 0.1 % after 12 relaxation times m/b (dt = 0.5 s)."""
    params = HERMAN2013.forcing
    forcing = Forcing(params, current=(0.05, 0.02))
    expected = free_drift(params, forcing.wind, forcing.current, forcing.coriolis, radius,
                          thickness)
    a, b = drag_coefficients(params, radius, thickness)
    tau = 910.0 * thickness * math.pi * radius ** 2 / b
    sim = lone_floe(radius, thickness, forcing, 0.5)
    sim.advance(12.0 * tau)
    u = sim.velocities[0]
    assert np.hypot(*(u - expected)) <= 1e-3 * np.hypot(*expected)
    # the drift turns to the right of the wind for f > 0
    assert expected[1] < 0.0


def test_steady_drift_function_matches_eq6():
    """steady_drift() equals the solution of eq 6 written out from the drag
    laws, to 1e-12, for several floe sizes, a rotated wind and f > 0 and f < 0."""
    params = HERMAN2013.forcing
    radii = np.array([0.5, 2.0, 8.0, 40.0])
    thickness = np.array([0.5, 1.5, 1.5, 3.0])
    masses = 910.0 * thickness * math.pi * radii ** 2
    for coriolis in (1.3e-4, -1.0e-4):
        forcing = Forcing(params, wind=(6.0, -8.0), current=(0.03, 0.04), coriolis=coriolis)
        got = steady_drift(forcing, radii, thickness, masses)
        for k in range(len(radii)):
            want = free_drift(params, forcing.wind, forcing.current, coriolis, radii[k],
                              thickness[k])
            assert got[k] == pytest.approx(want, rel=1e-12, abs=1e-15)


def test_spin_decays_with_water_drag():
    """Eq 7 without contacts: (m r^2/2) d omega/dt = -(pi r^3/2) rho_w
    (r C_hw + (h - h_f) C_vw) omega, so omega decays as exp(-t b/m); after one
    e-folding time omega/omega_0 = 1/e within 1e-4 (dt = 0.05 s; drag acts
    through half-step velocities, a first-order error of about
    (b dt / 2m)(b t / m) = 3e-5 here)."""
    radius, thickness, dt = 3.0, 1.5, 0.05
    forcing = Forcing(HERMAN2013.forcing, wind=(0.0, 0.0))
    a, b = drag_coefficients(HERMAN2013.forcing, radius, thickness)
    tau = 910.0 * thickness * math.pi * radius ** 2 / b
    sim = lone_floe(radius, thickness, forcing, dt, spin=0.02)
    n = int(round(tau / dt))
    sim.step(n)
    assert np.all(sim.velocities == 0.0)
    assert sim.angular_velocities[0] / 0.02 == pytest.approx(math.exp(-n * dt / tau), rel=1e-4)


def test_inertial_oscillation_without_drag():
    """With all drag coefficients zero only Coriolis acts: over a quarter of
    the inertial period 2 pi / f the velocity keeps its speed and turns
    clockwise (f > 0) by f t, both within 1e-5 (dt = 0.05 s; the Coriolis
    force acts through half-step velocities, which lets the speed grow by
    about (f t)(f dt)/2 = 5e-6)."""
    params = ForcingParams(air_skin_drag=0.0, air_form_drag=0.0, water_skin_drag=0.0,
                           water_form_drag=0.0, coriolis=1.3e-4)
    forcing = Forcing(params)
    u0 = np.array([0.3, 0.1])
    dt = 0.05
    sim = lone_floe(10.0, 1.5, forcing, dt, velocity=u0)
    n = int(round(0.5 * math.pi / 1.3e-4 / dt))
    sim.step(n)
    u = sim.velocities[0]
    assert np.hypot(*u) == pytest.approx(np.hypot(*u0), rel=1e-5)
    turned = math.atan2(u[1], u[0]) - math.atan2(u0[1], u0[0])
    assert turned == pytest.approx(-1.3e-4 * n * dt, abs=1e-5)


def test_herman2011_drift_speeds():
    """Herman (2011) Table I (f = 0, current 0.01 |u_a| along the wind):
    u_eq = u_w + (a/b) |u_a| u_a is about 0.26 m/s for large floes and about
    0.17 m/s for a 1 m floe (the Physics page: physics-drag), to the two digits quoted."""
    params = HERMAN2011.forcing
    forcing = Forcing(params)
    radii = np.array([0.5, 500.0])
    thickness = np.full(2, HERMAN2011.thickness)
    masses = 910.0 * thickness * math.pi * radii ** 2
    u_eq = forcing.equilibrium_velocity(radii, thickness, masses)
    drift = steady_drift(forcing, radii, thickness, masses)
    assert drift == pytest.approx(u_eq, abs=1e-12)
    assert u_eq[:, 1] == pytest.approx([0.0, 0.0], abs=1e-12)
    assert u_eq[0, 0] == pytest.approx(0.17, abs=0.005)
    assert u_eq[1, 0] == pytest.approx(0.26, abs=0.005)
    # Stokes time constant tau = m / b (Herman 2011, eq 7)
    a, b = drag_coefficients(params, radii, thickness)
    assert forcing.time_constant(radii, thickness, masses) == pytest.approx(masses / b, rel=1e-12)


def test_wind_can_change_between_runs():
    """Changing forcing.wind between calls changes the drift: after the wind
    turns from +x to +y the floe converges to the new eq 6 drift within 0.1 %."""
    params = HERMAN2013.forcing
    forcing = Forcing(params)
    radius, thickness = 2.0, 1.5
    a, b = drag_coefficients(params, radius, thickness)
    tau = 910.0 * thickness * math.pi * radius ** 2 / b
    sim = lone_floe(radius, thickness, forcing, 0.5)
    sim.advance(3.0 * tau)
    forcing.wind = (0.0, 10.0)
    sim.advance(12.0 * tau)
    expected = free_drift(params, (0.0, 10.0), (0.0, 0.0), params.coriolis, radius, thickness)
    assert np.hypot(*(sim.velocities[0] - expected)) <= 1e-3 * np.hypot(*expected)
