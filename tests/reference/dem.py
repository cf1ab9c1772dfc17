"""Reference formulas and the binary-impact set-up shared by the tests of
the Hertzian floe engine.

The analytic quantities here are written out from the contact law
(Herman 2013; the Physics page: physics-contact) rather than taken from the engine, so
that the tests compare the engine against the physics and not against itself.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.special import beta as beta_function

from physics import ContactParams, FloeField, HertzSimulation, PeriodicBox


# ---------------------------------------------------------------------------
# Analytic two-body Hertz results
# ---------------------------------------------------------------------------

def effective_modulus(contact: ContactParams) -> float:
    """E* = E / (2 (1 - nu^2)) [Pa] for two floes of the same ice."""
    return contact.elastic_modulus / (2.0 * (1.0 - contact.poisson_ratio ** 2))


def effective_shear_modulus(contact: ContactParams) -> float:
    """G* = E / (4 (2 - nu)(1 + nu)) [Pa]."""
    nu = contact.poisson_ratio
    return contact.elastic_modulus / (4.0 * (2.0 - nu) * (1.0 + nu))


def hertz_k(contact: ContactParams, r_eff) -> np.ndarray:
    """Hertz stiffness k = (4/3) E* sqrt(R*) [N m^-3/2], F = k delta^3/2."""
    return 4.0 / 3.0 * effective_modulus(contact) * np.sqrt(r_eff)


#: t_c = C (m*/k)^(2/5) v^(-1/5): C = 2 (5/4)^(2/5) * int_0^1 (1 - x^(5/2))^(-1/2) dx,
#: the integral being B(2/5, 1/2) / (5/2).
HERTZ_TIME_CONSTANT = 2.0 * 1.25 ** 0.4 * beta_function(0.4, 0.5) / 2.5


def hertz_peak_overlap(m_eff, k, speed):
    """Largest overlap of an undamped Hertz impact, (5 m* v^2 / (4 k))^(2/5) [m]."""
    return (5.0 * m_eff * speed ** 2 / (4.0 * k)) ** 0.4


def hertz_contact_time(m_eff, k, speed):
    """Duration of an undamped Hertz impact, 3.2181 (m*/k)^(2/5) v^(-1/5) [s]."""
    return HERTZ_TIME_CONSTANT * (m_eff / k) ** 0.4 * speed ** (-0.2)


def disc_mass(radius, thickness, density=910.0):
    """m = rho h pi r^2 [kg]."""
    return density * thickness * math.pi * np.asarray(radius, dtype=float) ** 2


# ---------------------------------------------------------------------------
# Binary impacts
# ---------------------------------------------------------------------------

@dataclass
class Impact:
    """Outcome of a binary impact of floes i (index 0) and j (index 1).

    ``normal`` is the unit vector from i to j at the start, ``tangent`` =
    k x normal; ``u_rel`` = u_i - u_j. Step records (when asked for) are
    taken after every step.
    """

    radii: np.ndarray
    masses: np.ndarray
    inertia: np.ndarray
    m_eff: float
    r_eff: float
    k: float
    normal: np.ndarray
    tangent: np.ndarray
    u_rel_before: np.ndarray
    u_rel_after: np.ndarray
    spin_before: np.ndarray
    spin_after: np.ndarray
    positions_before: np.ndarray
    positions_after: np.ndarray
    velocities_before: np.ndarray
    velocities_after: np.ndarray
    t_c: float
    dt: float
    overlaps: np.ndarray = field(default_factory=lambda: np.zeros(0))
    energies: np.ndarray = field(default_factory=lambda: np.zeros(0))
    n_steps: int = 0

    @property
    def normal_speed_before(self) -> float:
        """Approach speed (u_i - u_j) . n before the impact (> 0) [m/s]."""
        return float(self.u_rel_before @ self.normal)

    @property
    def restitution(self) -> float:
        """Measured normal restitution -u_n' / u_n."""
        return float(-(self.u_rel_after @ self.normal) / self.normal_speed_before)

    @property
    def contact_steps(self) -> np.ndarray:
        return np.nonzero(self.overlaps > 0.0)[0]

    def angular_momentum(self, after: bool) -> float:
        """Total angular momentum sum m x cross u + sum I omega about the
        origin [kg m^2/s] (the total momentum is zero, so any origin gives
        the same value)."""
        x = self.positions_after if after else self.positions_before
        u = self.velocities_after if after else self.velocities_before
        w = self.spin_after if after else self.spin_before
        m = self.masses
        return float((m * (x[:, 0] * u[:, 1] - x[:, 1] * u[:, 0])).sum() + self.inertia @ w)


def run_impact(radii, speed, contact: ContactParams, *, angle_deg=0.0, thickness=1.0,
               steps_per_contact=1000, record=False, tangential_energy=False,
               normal_angle=0.3) -> Impact:
    """Binary impact of two floes at relative speed ``speed`` [m/s] arriving at
    ``angle_deg`` from the line of centres, without external forcing, in the
    centre-of-mass frame of a large periodic box.

    The time step is the undamped Hertz contact time at the normal approach
    speed divided by ``steps_per_contact``. With ``record`` the overlap and the
    mechanical energy (kinetic + Hertz potential (2/5) k delta^(5/2), plus the
    Mindlin spring energy F_t^2 / (2 k_t) with ``tangential_energy``) are
    stored after every step; otherwise the run advances in chunks until the
    floes have separated.
    """
    r = np.asarray(radii, dtype=float)
    h = np.broadcast_to(np.asarray(thickness, dtype=float), (2,)).copy()
    m = disc_mass(r, h)
    inertia = 0.5 * m * r ** 2
    m_eff = m[0] * m[1] / (m[0] + m[1])
    r_eff = r[0] * r[1] / (r[0] + r[1])
    k = float(hertz_k(contact, r_eff))
    angle = math.radians(angle_deg)
    u_n = speed * math.cos(angle)
    u_t = speed * math.sin(angle)
    t_c = float(hertz_contact_time(m_eff, k, u_n))
    dt = t_c / steps_per_contact

    n = np.array([math.cos(normal_angle), math.sin(normal_angle)])
    t = np.array([-n[1], n[0]])
    length = 20.0 * (r[0] + r[1])
    centre = np.full(2, 0.5 * length)
    gap = 0.5 * dt * u_n              # touch within the first steps
    pos = np.array([centre - (r[0] + 0.5 * gap) * n, centre + (r[1] + 0.5 * gap) * n])
    u_rel = u_n * n + u_t * t
    vel = np.array([u_rel * m[1] / m.sum(), -u_rel * m[0] / m.sum()])
    floes = FloeField(pos, r, h, vel)
    sim = HertzSimulation(floes, PeriodicBox(length), contact, None, dt, impact_speed=speed)

    kt_coef = 8.0 * effective_shear_modulus(contact) * contact.tangential_stiffness

    def overlap():
        d = sim.positions[1] - sim.positions[0]
        return r[0] + r[1] - float(np.hypot(*d))

    def energy():
        e = sim.kinetic_energy()
        c = sim.contacts()
        if len(c):
            delta = c.overlap[0]
            e += 0.4 * k * delta ** 2.5
            if tangential_energy:
                e += c.tangential_force[0] ** 2 / (2.0 * kt_coef * math.sqrt(r_eff * delta))
        return e

    overlaps = [overlap()]
    energies = [energy()] if record else []
    touched = False
    max_steps = 20 * steps_per_contact
    chunk = 1 if record else max(1, steps_per_contact // 20)
    while sim.n_steps < max_steps:
        sim.step(chunk)
        d = overlap()
        if record:
            overlaps.append(d)
            energies.append(energy())
        if d > 0.0:
            touched = True
        elif touched or (sim.velocities[0] - sim.velocities[1]) @ n < 0.0:
            break
    else:
        raise AssertionError("the impact did not end")
    assert touched or not record
    return Impact(radii=r, masses=m, inertia=inertia, m_eff=m_eff, r_eff=r_eff, k=k,
                  normal=n, tangent=t, u_rel_before=u_rel,
                  u_rel_after=sim.velocities[0] - sim.velocities[1],
                  spin_before=np.zeros(2), spin_after=sim.angular_velocities.copy(),
                  positions_before=pos, positions_after=sim.positions.copy(),
                  velocities_before=vel, velocities_after=sim.velocities.copy(),
                  t_c=t_c, dt=dt, overlaps=np.array(overlaps), energies=np.array(energies),
                  n_steps=sim.n_steps)
