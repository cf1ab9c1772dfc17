"""The Hertz–Mindlin contact law between two floes (Herman 2013; :ref:`physics-contact`).

This module holds the physics of one contact, as pointwise Numba functions,
and the calibration of the normal damping from a target restitution. The
loops over contacts are in :mod:`physics.hertz_kernels`.

Conventions (one contact between floes i and j)
-----------------------------------------------
* ``n`` is the unit vector from the centre of i to the centre of j,
  ``t = k × n = (−n_y, n_x)``; overlap ``δ = r_i + r_j − |x_j − x_i| > 0``.
* Normal force (on i, along −n): ``F_n = (4/3) E* √R* δ^{3/2} + η v_n`` with
  ``v_n = (u_i − u_j)·n`` (positive while approaching) and
  ``η = α √(m* (4/3) E* √(R* δ))`` (the LAMMPS ``coeff_restitution`` form; α
  from :func:`damping_alpha`). Optionally clipped at zero (no cohesion).
* Tangential: incremental Mindlin spring. The history is the elastic
  tangential force S (a scalar along t, so it stays in the tangent plane as
  the contact rotates) and the contact radius a at its last update. With
  ``k_t = 8 G* a``, ``a = √(R* δ)`` and slip velocity
  ``v_t = (u_i − u_j)·t + r_i ω_i + r_j ω_j``: on unloading (a below its last
  value) S is scaled by a / a_last; then S ← S − k_t v_t Δt and
  ``F_t = S − η_t v_t`` (η_t = x_γt η); if ``|F_t| > μ |F_n|`` the force is
  capped (Coulomb) and S reset so that S − η_t v_t equals the capped force.
  This is LAMMPS ``tangential mindlin/rescale/force`` (except that a contact
  with no spring force yet, whose viscous force alone passes the cap, gets
  the capped force where LAMMPS gives none). Unlike the total form
  F_t = −k_t ξ (LAMMPS ``mindlin``), it stores no energy while a sticking
  contact loads at fixed tangential displacement, so a contact can never
  create energy. Tangential damping is off by default: with it, the capped
  history of the LAMMPS law can point along the slip at the start of a
  sliding contact and push the floes instead of braking them.
* Torques: ``τ_i = F_t (r_i − δ/2)``, ``τ_j = F_t (r_j − δ/2)`` (lever arms to the
  contact point).
* By default F_t also acts on the floes' translation, as Newton's third law
  at the contact point requires (and as LAMMPS does). Herman (2013) writes
  its eqs 6–7 with the normal force alone in the linear momentum equation
  and F_t only in the angular one; ``ContactParams.tangential_translation``
  = False follows that (friction turns the floes but does not resist their
  sliding). The force the kernels report for a contact, and that enters the
  stress tensor, is the one acting on translation.
"""
from __future__ import annotations

import math
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numba import njit

__all__ = [
    "ContactLaw",
    "lammps_damping_alpha",
    "damping_alpha",
    "restitution_of_alpha",
    "hertz_mindlin_force",
    "contact_time",
    "peak_overlap",
    "hertz_stiffness",
]


# ---------------------------------------------------------------------------
# Analytic two-body results (undamped Hertz), used in validation and checks
# ---------------------------------------------------------------------------

def hertz_stiffness(effective_modulus, effective_radius):
    """k = (4/3) E* √R*  [N/m^{3/2}] so that F = k δ^{3/2}."""
    return 4.0 / 3.0 * effective_modulus * np.sqrt(effective_radius)


def contact_time(effective_mass, stiffness, impact_speed):
    """Duration of an undamped Hertz impact, 3.2181 (m*/k)^{2/5} v^{−1/5} [s]."""
    return 3.2181 * (effective_mass / stiffness) ** 0.4 * impact_speed ** (-0.2)


def peak_overlap(effective_mass, stiffness, impact_speed):
    """Largest overlap of an undamped Hertz impact, (5 m* v² / (4 k))^{2/5} [m]."""
    return (5.0 * effective_mass * impact_speed ** 2 / (4.0 * stiffness)) ** 0.4


# ---------------------------------------------------------------------------
# Damping calibration
# ---------------------------------------------------------------------------

def lammps_damping_alpha(restitution: float) -> float:
    """α of LAMMPS ``damping coeff_restitution``: √5 |ln e| / √(π² + ln² e)."""
    ln_e = math.log(restitution)
    return math.sqrt(5.0) * abs(ln_e) / math.sqrt(math.pi ** 2 + ln_e ** 2)


def restitution_of_alpha(alpha: float, limit_damping: bool = True) -> float:
    """Normal restitution of a Hertz impact with damping coefficient α.

    In units where the overlap scale and time scale are removed the impact is
    ``x'' = −x^{3/2} − α x^{1/4} x'`` with ``x(0) = 0, x'(0) = 1``, so the
    restitution depends on α only. The impact ends when the floes separate
    (x = 0) or, with ``limit_damping``, when the total force reaches zero
    (it stays zero afterwards while the floes move apart).
    """
    from scipy.integrate import solve_ivp

    if alpha == 0.0:
        return 1.0

    def rhs(_, y):
        x, v = y
        xp = max(x, 0.0)
        f = xp ** 1.5 + alpha * xp ** 0.25 * v
        if limit_damping and f < 0.0:
            f = 0.0
        return (v, -f)

    def separated(_, y):
        return y[0]

    separated.terminal = True
    separated.direction = -1
    events = [separated]
    if limit_damping:
        def force_zero(_, y):
            x, v = y
            xp = max(x, 0.0)
            return xp ** 1.5 + alpha * xp ** 0.25 * v if v < 0 else 1.0

        force_zero.terminal = True
        force_zero.direction = -1
        events.append(force_zero)
    # start slightly inside contact (the x^{1/4} term is singular at 0)
    x0 = 1e-12
    sol = solve_ivp(rhs, (0.0, 50.0), [x0, 1.0], events=events, rtol=1e-11,
                    atol=1e-14, method="DOP853", max_step=0.01)
    if sol.status != 1:
        return 0.0          # over-damped: the floes come to rest in contact
    return max(-float(sol.y[1, -1]), 0.0)


@lru_cache(maxsize=256)
def _exact_alpha(restitution: float, limit_damping: bool) -> float:
    from scipy.optimize import brentq

    if restitution >= 1.0:
        return 0.0
    if not limit_damping:
        # without clipping the closed form is exact (Hertz impact with
        # η ∝ δ^{1/4} behaves as a linear oscillator in its own time scale)
        return lammps_damping_alpha(restitution)
    guess = lammps_damping_alpha(restitution)
    lo, hi = 0.0, max(2.0 * guess, 0.1)
    while restitution_of_alpha(hi, limit_damping) > restitution:
        hi *= 2.0
        if hi > 1e6:
            raise ValueError(f"restitution {restitution} is too small to reach")
    return brentq(lambda a: restitution_of_alpha(a, limit_damping) - restitution,
                  lo, hi, xtol=1e-13, rtol=1e-12)


def damping_alpha(restitution: float, model: str = "exact",
                  limit_damping: bool = True) -> float:
    """Damping coefficient α giving normal restitution ``restitution``.

    ``model="exact"`` inverts :func:`restitution_of_alpha` numerically (the
    restitution is then exact for the continuous Hertz impact at any speed);
    ``model="lammps"`` returns :func:`lammps_damping_alpha`.
    """
    if not 0.0 < restitution <= 1.0:
        raise ValueError(f"restitution must be in (0, 1], got {restitution!r}")
    if model == "lammps":
        return lammps_damping_alpha(restitution)
    if model == "exact":
        return _exact_alpha(float(restitution), bool(limit_damping))
    raise ValueError(f"damping model must be 'exact' or 'lammps', got {model!r}")


# ---------------------------------------------------------------------------
# Pointwise contact force (one contact), compiled
# ---------------------------------------------------------------------------

class ContactLaw(NamedTuple):
    """The constants of one kind of contact (floe–floe or floe–wall) as the
    compiled kernels take them; :meth:`from_params` makes them from a
    :class:`~physics.params.ContactParams`."""

    #: (4/3) E* [Pa]
    kn: float
    #: 8 G* times the tangential stiffness factor [Pa]
    kt: float
    #: normal damping coefficient α
    alpha: float
    #: tangential damping relative to the normal one
    gamma_t: float
    #: Coulomb coefficient μ
    mu: float
    #: clip the normal force at zero (no cohesion)
    limit_damping: bool
    #: 1.0 if the tangential force acts on translation, else 0.0
    tangential_translation: float

    @classmethod
    def from_params(cls, contact, wall: bool = False) -> ContactLaw:
        """The floe–floe law of ``contact`` (a
        :class:`~physics.params.ContactParams`), or with ``wall`` the law
        of a floe against a rigid wall (its stiffer E* and G*)."""
        e_eff = contact.wall_effective_modulus if wall else contact.effective_modulus
        g_eff = (contact.wall_effective_shear_modulus if wall
                 else contact.effective_shear_modulus)
        return cls(float(4.0 / 3.0 * e_eff), float(8.0 * g_eff * contact.tangential_stiffness),
                   float(contact.damping_alpha), float(contact.tangential_damping),
                   float(contact.friction), bool(contact.limit_damping),
                   float(contact.tangential_translation))


@njit(cache=True, inline="always", error_model="numpy")
def hertz_mindlin_force(delta, r_eff, m_eff, v_normal, v_slip, spring, a_last, dt_history, law):
    """Forces of one Hertz–Mindlin contact.

    Parameters
    ----------
    delta : overlap δ > 0 [m]
    r_eff, m_eff : R* [m], m* [kg]
    v_normal : approach speed (u_i − u_j)·n [m/s]
    v_slip : tangential slip velocity of the contact point of i relative to j [m/s]
    spring, a_last : history: elastic tangential force S on i along t [N] and
        the contact radius √(R* δ) when it was last updated [m] (0, 0 for a new
        contact)
    dt_history : time step to advance the history by (0 for an evaluation
        that must not change it, e.g. at set-up) [s]
    law : ContactLaw
        Stiffnesses, damping, friction and the clipping of F_n.

    Returns
    -------
    f_normal : repulsive normal force magnitude F_n (acts on i along −n) [N]
    f_tangential : tangential force on i along t [N]
    spring, a_last : updated history
    """
    a = math.sqrt(r_eff * delta)                 # contact radius scale √(R* δ)
    stiff = law.kn * a                           # F_n,c / δ
    f_elastic = stiff * delta                    # (4/3) E* √R* δ^{3/2}
    eta = law.alpha * math.sqrt(m_eff * stiff)   # α √(m* F_n,c/δ)
    f_normal = f_elastic + eta * v_normal
    if law.limit_damping and f_normal < 0.0:
        f_normal = 0.0
    # incremental Mindlin spring, LAMMPS mindlin/rescale/force order
    if a < a_last:
        spring *= a / a_last                     # unloading: shrink with the contact
    if dt_history > 0.0:
        spring -= law.kt * a * v_slip * dt_history
        a_last = a
    eta_t = law.gamma_t * eta
    f_t = spring - eta_t * v_slip
    f_crit = law.mu * abs(f_normal)
    if abs(f_t) > f_crit:
        f_cap = f_crit if f_t > 0.0 else -f_crit
        if spring != 0.0:
            spring = f_cap + eta_t * v_slip
        # (with no spring yet, only the viscous force is capped: LAMMPS
        # returns zero friction there instead)
        f_t = f_cap
    return f_normal, f_t, spring, a_last
