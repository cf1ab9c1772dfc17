"""Conservation laws of the Hertz engine for a gas of elastic, frictionless
floes in a periodic box (velocity-Verlet; the Physics page: physics-contact)."""
from __future__ import annotations

import numpy as np
import pytest

from physics import ContactParams, FloeField, HertzSimulation, PeriodicBox, place_floes

from reference.dem import disc_mass, hertz_contact_time, hertz_k

N_FLOES = 100
CONCENTRATION = 0.45
VELOCITY_STD = 0.5          # m/s per component
STEPS_PER_CONTACT = 20
CONTACT_TIMES = 1000
SAMPLE_EVERY = 4            # steps; a contact lasts about 20 steps


@pytest.fixture(scope="module")
def elastic_gas():
    """Run the gas once and record energy, momentum and collisions."""
    rng = np.random.default_rng(20130)
    radii = rng.uniform(0.5, 1.0, N_FLOES)
    thickness = rng.uniform(0.8, 1.6, N_FLOES)
    side = np.sqrt(np.pi * np.sum(radii ** 2) / CONCENTRATION)
    box = PeriodicBox(side)
    positions = place_floes(radii, box, rng)
    velocities = rng.normal(0.0, VELOCITY_STD, (N_FLOES, 2)) + np.array([0.2, -0.1])
    floes = FloeField(positions, radii, thickness, velocities)
    contact = ContactParams(restitution=1.0, friction=0.0)

    # shortest contact time of two equal floes at a fast relative speed (4 sigma)
    m = disc_mass(radii, thickness)
    v_ref = 4.0 * VELOCITY_STD
    t_c = float(np.min(hertz_contact_time(0.5 * m, hertz_k(contact, 0.5 * radii), v_ref)))
    dt = float(t_c / STEPS_PER_CONTACT)
    sim = HertzSimulation(floes, box, contact, None, dt, impact_speed=v_ref)

    def energy(c):
        r_eff = radii[c.i] * radii[c.j] / (radii[c.i] + radii[c.j])
        potential = 0.4 * hertz_k(contact, r_eff) * c.overlap ** 2.5
        return sim.kinetic_energy() + float(np.sum(potential))

    n_samples = CONTACT_TIMES * STEPS_PER_CONTACT // SAMPLE_EVERY
    times, energies, momenta = [0.0], [energy(sim.contacts())], [sim.momentum()]
    spins = 0.0
    pairs_before = set()
    collisions = 0
    for _ in range(n_samples):
        sim.step(SAMPLE_EVERY)
        c = sim.contacts()
        pairs = set(zip(c.i.tolist(), c.j.tolist()))
        collisions += len(pairs - pairs_before)
        pairs_before = pairs
        times.append(sim.time)
        energies.append(energy(c))
        momenta.append(sim.momentum())
        spins = max(spins, float(np.abs(sim.angular_velocities).max()))
    return dict(t_c=t_c, times=np.array(times), energies=np.array(energies),
                momenta=np.array(momenta), collisions=collisions, spins=spins,
                momentum_scale=float(np.sum(m * np.hypot(*velocities.T))))


def test_gas_has_many_collisions(elastic_gas):
    """The run covers 1000 contact times (dt = t_c / 20, t_c the shortest
    equal-pair contact time at 4 sigma) and contains at least 100 binary
    collisions."""
    assert elastic_gas["times"][-1] == pytest.approx(CONTACT_TIMES * elastic_gas["t_c"], rel=1e-9)
    assert elastic_gas["collisions"] >= 100


def test_gas_momentum_conserved(elastic_gas):
    """Total momentum is conserved to 1e-12 of sum |m v| (pair forces are
    equal and opposite, no external force)."""
    p = elastic_gas["momenta"]
    assert np.abs(p - p[0]).max() <= 1e-12 * elastic_gas["momentum_scale"]


def test_gas_energy_conserved_without_trend(elastic_gas):
    """Kinetic plus Hertz potential energy (2/5) k delta^(5/2) of an elastic,
    frictionless gas at dt = t_c / 20: every sample within 1e-3 of the initial
    energy, the drift of a straight-line fit over the run below 1e-3, and the
    means of the first and second halves within 1e-3 of each other."""
    t = elastic_gas["times"]
    e = elastic_gas["energies"] / elastic_gas["energies"][0]
    assert np.abs(e - 1.0).max() < 1e-3
    slope = np.polyfit(t, e, 1)[0]
    assert abs(slope * t[-1]) < 1e-3
    half = len(e) // 2
    assert abs(e[half:].mean() - e[:half].mean()) < 1e-3


def test_frictionless_gas_does_not_spin(elastic_gas):
    """Without friction no torque acts: angular velocities stay exactly zero."""
    assert elastic_gas["spins"] == 0.0
