"""Our two engines against pymunk (Chipmunk2D) and against the laws both obey.

Each comparison runs the same floes in our engines and in
:class:`~physics.crosscheck.pymunk_runner.PymunkSimulation` and returns
:class:`~physics.crosscheck.results.Check` rows:

* :func:`binary_frictionless` — random oblique impacts of smooth discs: the
  hard-disc engine and pymunk against the restitution law (normal relative
  velocity reversed and scaled by e, tangential unchanged, momentum
  conserved), and against each other;
* :func:`binary_friction` — oblique impacts with Coulomb friction: the Hertz
  engine (Hertz–Mindlin contact) and pymunk against the rigid-body Coulomb
  law for discs; they agree in gross sliding and differ where the contact
  sticks (see below);
* :func:`gas_cooling` — a dilute inelastic gas: kinetic-energy decay in the
  hard-disc engine and in pymunk, against each other and Haff's law;
* :func:`drag_relaxation` — a dilute gas under Stokes drag: the mean
  velocity of both engines relaxes to the free drift;
* :func:`speed` — collisions per second of the hard-disc engine and of
  pymunk on one system.

:func:`run` runs them all.

Rigid-body Coulomb impact of two discs
--------------------------------------
Floes i and j with masses m, radii r, moments I = m r²/2, unit normal n from
i to j, tangent t = k × n, approach speed v_n = (u_i − u_j)·n > 0 and
contact-point slip v_s = (u_i − u_j)·t + r_i ω_i + r_j ω_j. The normal
impulse is J_n = m* (1 + e) v_n (m* = m_i m_j / (m_i + m_j)); an impulse P
along t on i (−P on j) changes the slip by P K with
K = 1/m_i + 1/m_j + r_i²/I_i + r_j²/I_j = 3/m* for discs. Coulomb's law
bounds |P| ≤ μ J_n, and a rigid contact whose slip can be stopped within the
bound is stopped:

    P = −sign(v_s) min(μ J_n, |v_s| / K),   Δω_i = P r_i / I_i,  Δω_j = P r_j / I_j.

With the impact angle parameter ψ = |v_s| / (μ (1 + e) v_n) (Maw, Barber &
Fawcett 1976), the tangential restitution β = −v_s' / v_s (−1 for a smooth
contact, 0 when the slip is stopped, > 0 for a tangential rebound) is

    β = −1 + 3/ψ  for ψ ≥ 3 (gross sliding),   β = 0  for ψ < 3 (sticking).

Why the Hertz engine and pymunk differ at small ψ
-------------------------------------------------
Chipmunk's friction is a rigid constraint: within the Coulomb bound the
solver brings the contact-point slip to exactly zero, so β = 0 for every
ψ < 3 and the floes leave rolling on each other. Our Hertz engine has a
Mindlin tangential spring: during a sticking phase the spring stores the
tangential displacement and gives it back as the contact unloads, so the
slip reverses (β > 0, up to ≈ 0.65 at ψ ≈ 1 with Herman's e = 0.5,
μ = 0.7; at very small ψ the tangential oscillation can also end with
β < 0). This is the well-known difference between rigid (impulse-based)
and compliant (Mindlin) contact laws for oblique impacts; both reduce to
the same gross-sliding law at large ψ, where the contact slides throughout
and the tangential impulse is μ J_n.

In gross sliding the Hertz engine still departs slightly from the rigid law:
(i) with normal damping, the normal force rises faster than the Mindlin
spring force at the start of the contact, which therefore stays below the
Coulomb bound for a short time (a deficit of the tangential impulse that
shrinks with ψ: at ψ = 4, ≈ 2 % for e = 0.5, 10⁻³ for e = 0.8, 4·10⁻⁴ for
e = 0.85, 6·10⁻⁵ for e = 1; at ψ = 12, 0.5 % for e = 0.5); (ii) during the
finite contact time t_c the line of centres turns by about v_s t_c /
(r_i + r_j), which tilts the impulse by an angle growing as v_n^0.8 ψ²; the
impacts are therefore run at v_n = 10⁻⁴ m/s, where (ii) stays below 5·10⁻⁴
for ψ ≤ 12.
"""
from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from ..contact import contact_time, hertz_stiffness
from ..domain import PeriodicBox, WalledBox
from ..floes import FloeField, place_floes
from ..forcing import Forcing
from ..harddisk import HardDiskSimulation
from ..hertz import HertzSimulation
from ..params import HERMAN2011, ContactParams
from .pymunk_runner import PymunkSimulation
from .results import Check, save_figure

__all__ = ["binary_frictionless", "binary_friction", "gas_cooling", "drag_relaxation", "speed",
           "run", "smooth_impact_law", "rigid_coulomb_impact", "hertz_pair_impact",
           "pymunk_pair_impact", "pymunk_oblique_impact", "harddisk_pair_impact",
           "enskog_rate", "henderson_g", "drag_forcing"]

DENSITY = HERMAN2011.forcing.ice_density   # ice density [kg/m³]
LEAD = 1e-10               # pymunk steps end this fraction of the approach time after touching


# ---------------------------------------------------------------------------
# Small helpers
# ---------------------------------------------------------------------------

def _bar(iterable, progress: bool, desc: str, total: int | None = None):
    if not progress:
        return iterable
    from tqdm.auto import tqdm

    return tqdm(iterable, desc=desc, total=total, dynamic_ncols=True, leave=False)


def new_figure(size=(6.0, 4.0), ncols=1):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size)
    FigureCanvasAgg(fig)
    axes = [fig.add_subplot(1, ncols, k + 1) for k in range(ncols)]
    return fig, axes


def _masses(radii, thickness):
    return DENSITY * np.asarray(thickness, dtype=float) * math.pi * np.asarray(radii) ** 2


def _unit(angle):
    return np.array([math.cos(angle), math.sin(angle)])


# ---------------------------------------------------------------------------
# Binary impacts: laws and the three engines
# ---------------------------------------------------------------------------

def smooth_impact_law(masses, velocities, normal, restitution) -> np.ndarray:
    """Velocities (2, 2) [m/s] after an impact of two smooth discs:
    ``normal`` (unit, from disc 0 to disc 1) component of the relative
    velocity reversed and scaled by e, tangential components unchanged,
    momentum conserved: J = m* (1 + e) (u_0 − u_1)·n."""
    m = np.asarray(masses, dtype=float)
    u = np.asarray(velocities, dtype=float)
    n = np.asarray(normal, dtype=float)
    j = (1.0 + restitution) * m[0] * m[1] / (m[0] + m[1]) * float((u[0] - u[1]) @ n)
    return np.array([u[0] - j / m[0] * n, u[1] + j / m[1] * n])


def rigid_coulomb_impact(masses, radii, normal_speed, slip, restitution, friction) -> dict:
    """Rigid-body impact of two discs with Coulomb friction (module docstring).

    Parameters: masses, radii (2,) [kg], [m]; ``normal_speed`` v_n > 0 and
    ``slip`` v_s [m/s] before the impact; e, μ.

    Returns a dict: ``jn`` and ``p`` (normal impulse on j along n and
    tangential impulse on i along t [N s]), ``beta`` (−v_s'/v_s),
    ``spin_change`` (2,) [rad/s], ``du_t`` (change of (u_i − u_j)·t [m/s]),
    ``psi`` and ``sliding`` (bool).
    """
    m = np.asarray(masses, dtype=float)
    r = np.asarray(radii, dtype=float)
    inertia = 0.5 * m * r ** 2
    m_eff = m[0] * m[1] / m.sum()
    jn = m_eff * (1.0 + restitution) * normal_speed
    k = float((1.0 / m).sum() + (r ** 2 / inertia).sum())
    stop = abs(slip) / k
    bound = friction * jn
    sliding = bound < stop
    p = -math.copysign(min(bound, stop), slip)
    slip_after = slip + p * k
    psi = abs(slip) / (friction * (1.0 + restitution) * normal_speed) if friction > 0 else math.inf
    return dict(jn=jn, p=p, beta=-slip_after / slip, spin_change=p * r / inertia,
                du_t=p * float((1.0 / m).sum()), psi=psi, sliding=bool(sliding))


def _approach(radii, velocities, normal, lead_time, centre):
    """Positions (2, 2) at time 0 of discs that touch at ``lead_time`` with
    unit normal ``normal`` (from 0 to 1), the contact point at ``centre``."""
    r = np.asarray(radii, dtype=float)
    touch = np.array([centre - r[0] * normal, centre + r[1] * normal])
    return touch - np.asarray(velocities) * lead_time


def harddisk_pair_impact(radii, thickness, velocities, normal, restitution) -> np.ndarray:
    """Velocities (2, 2) after the impact of two discs in our hard-disc
    engine (a periodic box of 10 (r_0 + r_1), no drag, no TC model); the
    discs touch with unit normal ``normal`` half a sum of radii of relative
    travel after the start."""
    r = np.asarray(radii, dtype=float)
    u = np.asarray(velocities, dtype=float)
    big = 10.0 * r.sum()
    lead = 0.5 * r.sum() / float(np.hypot(*(u[0] - u[1])))
    pos = _approach(r, u, normal, lead, np.full(2, 0.5 * big))
    sim = HardDiskSimulation(FloeField(pos, r, thickness, u), PeriodicBox(big),
                             restitution=restitution, forcing=None, collision_duration=0.0)
    sim.advance(1.5 * lead)
    if sim.collision_count != 1:
        raise RuntimeError(f"expected one collision, got {sim.collision_count}")
    return sim.velocities


def pymunk_pair_impact(radii, thickness, velocities, normal, restitution, friction=0.0, *,
                       spins=(0.0, 0.0), step_fraction: float | None = None) -> PymunkSimulation:
    """The same impact in pymunk (walled box of 10 (r_0 + r_1), pair in the
    middle); returns the simulation after the impact.

    ``step_fraction=None``: four steps of exactly a quarter of the approach
    time plus ``LEAD`` of it, so that the contact is detected at an overlap
    of ~10⁻¹⁰ of the approach distance and resolved with the normal of the
    touching instant (Chipmunk detects contacts only once circles overlap).
    A number: steps of ``step_fraction`` × r_min / |u_0 − u_1|, the contact
    falling anywhere in a step (the generic case).
    """
    r = np.asarray(radii, dtype=float)
    u = np.asarray(velocities, dtype=float)
    big = 10.0 * r.sum()
    speed = float(np.hypot(*(u[0] - u[1])))
    lead = 0.5 * r.sum() / speed
    pos = _approach(r, u, normal, lead, np.full(2, 0.5 * big))
    field = FloeField(pos, r, thickness, u, np.asarray(spins, dtype=float))
    if step_fraction is None:
        dt, n_steps = lead * (1.0 + LEAD) / 4.0, 7
    else:
        dt = step_fraction * float(r.min()) / speed
        n_steps = int(math.ceil(lead / dt)) + 4
    sim = PymunkSimulation(field, WalledBox(big), restitution=restitution, friction=friction,
                           dt=dt)
    sim.step(n_steps)
    if sim.collision_count != 1:
        raise RuntimeError(f"expected one pymunk collision, got {sim.collision_count}")
    return sim


def _oblique_velocities(masses, normal, normal_speed, slip):
    """Centre-of-mass-frame velocities (2, 2) with (u_0 − u_1) = v_n n + v_s t."""
    m = np.asarray(masses, dtype=float)
    t = np.array([-normal[1], normal[0]])
    u_rel = normal_speed * normal + slip * t
    return np.array([u_rel * m[1] / m.sum(), -u_rel * m[0] / m.sum()])


def hertz_pair_impact(radii, thickness, restitution, friction, normal_speed, slip, *,
                      steps_per_contact: int = 200, normal_angle: float = 0.3,
                      contact: ContactParams | None = None) -> dict:
    """Oblique impact of two floes in our Hertz engine (no forcing, centre-of-
    mass frame of a periodic box of 20 (r_0 + r_1)).

    The time step is the undamped Hertz contact time at the normal speed
    divided by ``steps_per_contact``; the floes start ½ Δt v_n apart and the
    run stops once they have separated. ``contact`` overrides the contact
    law (its restitution and friction are replaced by the arguments).

    Returns a dict with ``velocities`` (2, 2), ``spins`` (2,), ``beta``
    (−v_s'/v_s with the initial tangent), ``du_t`` (change of
    (u_0 − u_1)·t), ``normal_restitution`` (along the initial normal),
    ``masses``, ``dt`` and ``steps``.
    """
    r = np.asarray(radii, dtype=float)
    h = np.broadcast_to(np.asarray(thickness, dtype=float), (2,)).copy()
    m = _masses(r, h)
    base = contact if contact is not None else ContactParams()
    law = ContactParams(elastic_modulus=base.elastic_modulus, poisson_ratio=base.poisson_ratio,
                        restitution=restitution, friction=friction,
                        tangential_damping=base.tangential_damping,
                        damping_model=base.damping_model, limit_damping=base.limit_damping)
    m_eff = m[0] * m[1] / m.sum()
    r_eff = r[0] * r[1] / r.sum()
    t_c = float(contact_time(m_eff, hertz_stiffness(law.effective_modulus, r_eff), normal_speed))
    dt = t_c / steps_per_contact
    n = _unit(normal_angle)
    t = np.array([-n[1], n[0]])
    u = _oblique_velocities(m, n, normal_speed, slip)
    big = 20.0 * r.sum()
    gap = 0.5 * dt * normal_speed
    centre = np.full(2, 0.5 * big)
    pos = np.array([centre - (r[0] + 0.5 * gap) * n, centre + (r[1] + 0.5 * gap) * n])
    speed = float(np.hypot(normal_speed, slip))
    sim = HertzSimulation(FloeField(pos, r, h, u), PeriodicBox(big), law, None, dt,
                          impact_speed=min(speed, normal_speed))
    chunk = max(1, steps_per_contact // 10)
    touched = False
    for _ in range(200):
        sim.step(chunk)
        d = sim.positions[1] - sim.positions[0]
        overlap = r.sum() - float(np.hypot(*d))
        if overlap > 0.0:
            touched = True
        elif touched:
            break
    else:
        raise RuntimeError("the Hertz impact did not end")
    v = sim.velocities
    w = sim.angular_velocities
    rel = v[0] - v[1]
    slip_after = float(rel @ t + r[0] * w[0] + r[1] * w[1])
    return dict(velocities=v, spins=w, beta=-slip_after / slip, du_t=float(rel @ t) - slip,
                normal_restitution=-float(rel @ n) / normal_speed, masses=m, dt=dt,
                steps=sim.n_steps)


def pymunk_oblique_impact(radii, thickness, restitution, friction, normal_speed, slip,
                          normal_angle: float = 0.3) -> dict:
    """The oblique impact of :func:`hertz_pair_impact` in pymunk (centre-of-
    mass frame, normal at ``normal_angle`` [rad] from x, no initial spin);
    returns a dict with ``velocities``, ``spins``, ``beta``, ``du_t``,
    ``normal_restitution`` and ``masses`` as there."""
    r = np.asarray(radii, dtype=float)
    m = _masses(r, thickness)
    n = _unit(normal_angle)
    t = np.array([-n[1], n[0]])
    u = _oblique_velocities(m, n, normal_speed, slip)
    sim = pymunk_pair_impact(r, thickness, u, n, restitution, friction)
    v = sim.velocities
    w = sim.angular_velocities
    rel = v[0] - v[1]
    slip_after = float(rel @ t + r[0] * w[0] + r[1] * w[1])
    return dict(velocities=v, spins=w, beta=-slip_after / slip, du_t=float(rel @ t) - slip,
                normal_restitution=-float(rel @ n) / normal_speed, masses=m)


# ---------------------------------------------------------------------------
# 1. Binary collisions, frictionless
# ---------------------------------------------------------------------------

def binary_frictionless(out_dir: Path | None = None, quick: bool = False, seed: int = 0,
                        progress: bool = True, n_impacts: int | None = None) -> list[Check]:
    """Random oblique impacts of smooth discs in the hard-disc engine and in
    pymunk, against the restitution law and each other.

    Each impact: radii log-uniform in 0.5–20 m, thickness uniform in
    0.3–3 m, relative speed log-uniform in 10⁻³–1 m/s, centre-of-mass
    velocity up to the relative speed in a random direction, impact
    parameter b/(r_0 + r_1) uniform in [0, 0.99) (either side), e uniform in
    (0.1, 1]. The error of an engine is the largest velocity error of the two
    discs over the relative speed before the impact. pymunk's steps end just
    after the touching instant (see :func:`pymunk_pair_impact`); the error
    of the generic case, the contact anywhere in a step of 1 % of
    r_min / |u_rel|, is reported as well (first order in Δt: the contact is
    resolved with the normal of the overlapping position).
    """
    n_imp = n_impacts if n_impacts is not None else (1000 if quick else 5000)
    rng = np.random.default_rng(seed)
    rows = np.zeros((n_imp, 5))    # b, hd-law, pm-law, hd-pm, pm-generic-law
    for k in _bar(range(n_imp), progress, "binary impacts (frictionless)"):
        r = np.exp(rng.uniform(math.log(0.5), math.log(20.0), 2))
        h = rng.uniform(0.3, 3.0, 2)
        speed = 10.0 ** rng.uniform(-3.0, 0.0)
        e = 1.0 - 0.9 * rng.random()
        b = rng.uniform(0.0, 0.99)
        side = rng.choice([-1.0, 1.0])
        d = _unit(rng.uniform(0.0, 2.0 * math.pi))
        dperp = np.array([-d[1], d[0]])
        phi = math.asin(b)
        n = math.cos(phi) * d + side * math.sin(phi) * dperp
        m = _masses(r, h)
        u_rel = speed * d
        v_cm = speed * rng.random() * _unit(rng.uniform(0.0, 2.0 * math.pi))
        u = np.array([v_cm + m[1] / m.sum() * u_rel, v_cm - m[0] / m.sum() * u_rel])
        law = smooth_impact_law(m, u, n, e)
        hd = harddisk_pair_impact(r, h, u, n, e)
        pm = pymunk_pair_impact(r, h, u, n, e).velocities
        pm_generic = pymunk_pair_impact(r, h, u, n, e, step_fraction=0.01).velocities
        rows[k] = (b, np.abs(hd - law).max() / speed, np.abs(pm - law).max() / speed,
                   np.abs(hd - pm).max() / speed, np.abs(pm_generic - law).max() / speed)
    worst = rows[:, 1:].max(axis=0)
    figures = []
    if out_dir is not None:
        fig, (ax,) = new_figure((6.4, 4.2))
        floor = 1e-18
        ax.semilogy(rows[:, 0], np.maximum(rows[:, 1], floor), ".", ms=3, label="hard discs vs law")
        ax.semilogy(rows[:, 0], np.maximum(rows[:, 2], floor), ".", ms=3,
                    label="pymunk vs law (step ends at touching)")
        ax.semilogy(rows[:, 0], np.maximum(rows[:, 4], floor), ".", ms=3,
                    label="pymunk vs law (generic step, 1 % r_min/|u|)")
        ax.axhline(1e-6, color="k", lw=0.8, ls="--", label="tolerance")
        ax.set_xlabel("impact parameter b / (r_i + r_j)")
        ax.set_ylabel("|u' − u'_law| / |u_i − u_j|")
        ax.set_title(f"{n_imp} smooth oblique impacts, e in (0.1, 1]")
        ax.legend(fontsize=7)
        figures.append(save_figure(fig, out_dir, "pymunk_binary_frictionless.png"))
    common = f"{n_imp} random impacts: r 0.5–20 m, |u_rel| 1e-3–1 m/s, b/(r_i+r_j) < 0.99, e in (0.1, 1]"
    return [
        Check("binary/frictionless/harddisk-vs-law",
              "smooth oblique impacts: hard-disc engine vs the restitution law, worst velocity "
              "error / relative speed", float(worst[0]), 1e-6, detail=common, figures=figures),
        Check("binary/frictionless/pymunk-vs-law",
              "the same impacts in pymunk (steps ending 1e-10 of the approach time after "
              "touching) vs the restitution law", float(worst[1]), 1e-6,
              detail=common + "; pymunk elasticity √e per shape, 10 solver iterations",
              figures=figures),
        Check("binary/frictionless/harddisk-vs-pymunk",
              "the same impacts: hard-disc engine vs pymunk", float(worst[2]), 1e-6,
              detail=common, figures=figures),
        Check("binary/frictionless/pymunk-generic-step",
              "pymunk with steps of 1 % of r_min/|u_rel| (contact anywhere in a step) vs the "
              "law: the first-order error of detecting contacts after overlap", float(worst[3]),
              None, detail=(f"median {np.median(rows[:, 4]):.2g}; the impact is resolved with the "
                            f"normal of the overlapping position, rotated by ~ v_t Δt/(r_i+r_j)"),
              figures=figures),
    ]


# ---------------------------------------------------------------------------
# 2. Binary collisions with friction
# ---------------------------------------------------------------------------

NORMAL_SPEED = 1e-4        # [m/s] normal approach speed of the frictional impacts
PSI_SLIDING = (4.0, 12.0)  # ψ range compared with gross sliding
#: restitutions of the weakly damped set (a few values: the Hertz damping
#: coefficient of each is found by solving the impact ODE once)
WEAK_DAMPING = (0.85, 0.9, 0.95, 1.0)


def _gross_sliding_error(res, law):
    """Largest relative error of Δ(u_i − u_j)·t and of the two spins
    against the rigid law (whose tangential impulse is nonzero)."""
    err_t = abs(res["du_t"] / law["du_t"] - 1.0)
    err_w = np.abs(res["spins"] / law["spin_change"] - 1.0).max()
    return float(max(err_t, err_w))


def binary_friction(out_dir: Path | None = None, quick: bool = False, seed: int = 0,
                    progress: bool = True, n_pairs: int | None = None) -> list[Check]:
    """Oblique impacts with Coulomb friction: the Hertz engine and pymunk
    against the rigid-body Coulomb law for discs (module docstring) over
    impact-angle parameters ψ from 0.1 to 12.

    Random pairs: radii log-uniform 0.5–20 m, thickness 0.3–3 m, μ uniform
    0.1–0.8, normal speed 10⁻⁴ m/s; for the Hertz engine Herman's material
    (E = 9 GPa, ν = 0.33) with the time step of t_c/200. Three sets, taken
    in turn: e in {0.85, 0.9, 0.95, 1} (weak damping) and e = 0.5
    (Herman 2013's damping), ψ log-uniform in [4, 12] for half of the pairs
    and in [0.1, 4) for the other half; and, for pymunk only, e uniform in
    (0.1, 1] with ψ log-uniform in [0.1, 12].

    Rows: pymunk vs the rigid law at every ψ (tolerance 10⁻⁶, absolute on β
    and relative on the spins); Hertz vs gross sliding for ψ in [4, 12]
    (tangential velocity change and spins; tolerance 10⁻³ for e ≥ 0.85 and
    3·10⁻² for e = 0.5, see the module docstring); Hertz vs pymunk in gross
    sliding; and the sticking difference: the largest β_Hertz − β_pymunk
    for ψ < 3 (reported), where pymunk's β is 0 and the Mindlin spring gives
    a tangential rebound.
    """
    n = n_pairs if n_pairs is not None else (300 if quick else 1500)
    rng = np.random.default_rng(seed + 1)
    records = []        # (set, psi, e, beta_h, beta_p, beta_law, err_h_gs, err_p, err_hp)
    for k in _bar(range(n), progress, "binary impacts (friction)"):
        which = k % 3
        r = np.exp(rng.uniform(math.log(0.5), math.log(20.0), 2))
        h = rng.uniform(0.3, 3.0, 2)
        mu = rng.uniform(0.1, 0.8)
        lo, hi = ((0.1, 12.0) if which == 2 else
                  (PSI_SLIDING if (k // 3) % 2 == 0 else (0.1, PSI_SLIDING[0])))
        psi = math.exp(rng.uniform(math.log(lo), math.log(hi)))
        e = (float(rng.choice(WEAK_DAMPING)), 0.5, 1.0 - 0.9 * rng.random())[which]
        angle = rng.uniform(0.0, 2.0 * math.pi)
        slip = rng.choice([-1.0, 1.0]) * psi * mu * (1.0 + e) * NORMAL_SPEED
        m = _masses(r, h)
        law = rigid_coulomb_impact(m, r, NORMAL_SPEED, slip, e, mu)
        pm = pymunk_oblique_impact(r, h, e, mu, NORMAL_SPEED, slip, angle)
        err_p = max(abs(pm["beta"] - law["beta"]),
                    float(np.abs(pm["spins"] / law["spin_change"] - 1.0).max()),
                    abs(pm["normal_restitution"] - e))
        beta_h = err_h = err_hp = math.nan
        if which < 2:
            hz = hertz_pair_impact(r, h, e, mu, NORMAL_SPEED, slip, normal_angle=angle)
            beta_h = hz["beta"]
            if psi >= PSI_SLIDING[0]:
                err_h = _gross_sliding_error(hz, law)
                err_hp = max(abs(hz["du_t"] / pm["du_t"] - 1.0),
                             float(np.abs(hz["spins"] / pm["spins"] - 1.0).max()))
        records.append((which, psi, e, beta_h, pm["beta"], law["beta"], err_h, err_p, err_hp))
    rec = np.array(records)
    weak, damped = rec[:, 0] == 0, rec[:, 0] == 1
    sliding = rec[:, 1] >= PSI_SLIDING[0]
    sticking = rec[:, 1] < 3.0
    err_p = float(rec[:, 7].max())
    err_h_weak = float(np.nanmax(rec[weak & sliding, 6]))
    err_h_damped = float(np.nanmax(rec[damped & sliding, 6]))
    err_hp_weak = float(np.nanmax(rec[weak & sliding, 8]))
    hz_stick = rec[(weak | damped) & sticking]
    diff = hz_stick[:, 3] - hz_stick[:, 4]
    k_max = int(np.argmax(diff))
    pm_stick = float(np.abs(rec[sticking, 4]).max())

    # β(ψ) curves for two contact laws, equal floes (figure and detail)
    curves = {}
    psis = np.geomspace(0.05, 20.0, 24 if quick else 60)
    for e, mu in ((0.85, 0.5), (0.5, 0.7)):
        rows = []
        for psi in _bar(psis, progress, f"beta(psi), e={e:g}"):
            slip = psi * mu * (1.0 + e) * NORMAL_SPEED
            hz = hertz_pair_impact((1.0, 1.0), 1.0, e, mu, NORMAL_SPEED, slip)
            pm = pymunk_oblique_impact((1.0, 1.0), 1.0, e, mu, NORMAL_SPEED, slip, 0.3)
            rows.append((psi, hz["beta"], pm["beta"], hz["spins"][0] / slip,
                         pm["spins"][0] / slip))      # r = 1 m
        curves[(e, mu)] = np.array(rows)
    herman = curves[(0.5, 0.7)]
    peak = herman[np.argmax(herman[:, 1])]
    figures = []
    if out_dir is not None:
        fig, (ax, ax2) = new_figure((11.0, 4.2), ncols=2)
        grid = np.geomspace(psis[0], psis[-1], 400)
        ax.semilogx(grid, np.minimum(0.0, -1.0 + 3.0 / grid), "k-", lw=1.0,
                    label="rigid Coulomb (sticking: β = 0)")
        ax.semilogx(grid[grid >= 1.5], -1.0 + 3.0 / grid[grid >= 1.5], "k:", lw=1.0,
                    label="gross sliding −1 + 3/ψ")
        ax2.semilogx(grid, -np.minimum(1.0 / 3.0, 1.0 / grid), "k-", lw=1.0,
                     label="rigid Coulomb −min(1/3, 1/ψ)")
        for (e, mu), c in curves.items():
            ax.semilogx(c[:, 0], c[:, 1], "o-", ms=3, label=f"Hertz–Mindlin e={e:g}, μ={mu:g}")
            ax.semilogx(c[:, 0], c[:, 2], "x", ms=5, label=f"pymunk e={e:g}, μ={mu:g}")
            ax2.semilogx(c[:, 0], c[:, 3], "o-", ms=3, label=f"Hertz e={e:g}, μ={mu:g}")
            ax2.semilogx(c[:, 0], c[:, 4], "x", ms=5, label=f"pymunk e={e:g}, μ={mu:g}")
        ax.set_xlabel("ψ = |v_s| / (μ (1+e) v_n)")
        ax.set_ylabel("tangential restitution β = −v_s'/v_s")
        ax.set_ylim(-1.05, 1.05)
        ax.legend(fontsize=7)
        ax.set_title("equal discs r = 1 m, h = 1 m, v_n = 1e-4 m/s")
        ax2.set_xlabel("ψ")
        ax2.set_ylabel("spin after impact ω r / v_s")
        ax2.legend(fontsize=7)
        figures.append(save_figure(fig, out_dir, "pymunk_binary_friction.png"))

    n_w, n_d = int(np.sum(weak & sliding)), int(np.sum(damped & sliding))
    return [
        Check("binary/friction/pymunk-vs-rigid-law",
              "oblique frictional impacts in pymunk vs the rigid Coulomb law at every ψ: worst of "
              "|β − β_law|, relative spin error and |e_n − e|", err_p, 1e-6,
              detail=(f"{len(rec)} pairs, ψ 0.1–12, μ 0.1–0.8, e in (0.1, 1]; pymunk elasticity √e "
                      f"and friction √μ per shape; largest |β| where the rigid law sticks (ψ < 3): "
                      f"{pm_stick:.1g}"),
              figures=figures),
        Check("binary/friction/hertz-vs-gross-sliding",
              "Hertz engine vs the rigid gross-sliding law for ψ in [4, 12], e in [0.85, 1]: worst "
              "relative error of the tangential velocity change and the spins",
              err_h_weak, 1e-3,
              detail=(f"{n_w} pairs, v_n = 1e-4 m/s, Δt = t_c/200; the remaining error is the "
                      f"loading phase of the Mindlin spring and the turn of the line of centres "
                      f"during contact (module docstring)"),
              figures=figures),
        Check("binary/friction/hertz-vs-gross-sliding-e0.5",
              "the same for e = 0.5 (Herman 2013): worst relative error in gross sliding",
              err_h_damped, 3e-2,
              detail=(f"{n_d} pairs; the normal damping makes the normal force rise faster than the "
                      f"Mindlin spring force, which stays below the Coulomb bound at the start of "
                      f"the contact (a deficit of the tangential impulse shrinking with ψ)"),
              figures=figures),
        Check("binary/friction/hertz-vs-pymunk-sliding",
              "Hertz engine vs pymunk in gross sliding (ψ in [4, 12], e in [0.85, 1]): worst "
              "relative difference of the tangential velocity change and the spins",
              err_hp_weak, 1e-3, detail=f"{n_w} pairs", figures=figures),
        Check("binary/friction/sticking-difference",
              "where the rigid law sticks (ψ < 3): largest β_Hertz − β_pymunk (pymunk stops the "
              "slip, β = 0; the Mindlin spring gives a tangential rebound)",
              float(diff[k_max]), None,
              detail=(f"{len(hz_stick)} pairs; β_Hertz from {hz_stick[:, 3].min():+.3f} to "
                      f"{hz_stick[:, 3].max():+.3f} (largest at ψ = {hz_stick[k_max, 1]:.2f}, "
                      f"e = {hz_stick[k_max, 2]:.2f}), pymunk |β| ≤ {pm_stick:.1g}; equal floes, "
                      f"e = 0.5, μ = 0.7: β_Hertz peaks at {peak[1]:+.3f} at ψ = {peak[0]:.2f}. "
                      f"Rigid impulse friction has no tangential compliance, the Mindlin spring "
                      f"returns its stored tangential displacement"),
              figures=figures),
    ]


# ---------------------------------------------------------------------------
# 3-4. Dilute gases
# ---------------------------------------------------------------------------

def henderson_g(eta: float) -> float:
    """Contact value of the pair correlation of hard discs (Henderson 1975)."""
    return (1.0 - 7.0 * eta / 16.0) / (1.0 - eta) ** 2


def enskog_rate(number_density: float, diameter: float, eta: float, kt: float,
                mass: float) -> float:
    """Enskog collision frequency per disc, 2 n σ g(σ) √(π kT/m) [1/s]
    (kT = KE/N in 2D, equal discs)."""
    return 2.0 * number_density * diameter * henderson_g(eta) * math.sqrt(math.pi * kt / mass)


def _gas(n: int, eta: float, radius: float, thickness: float, sigma_v: float,
         rng: np.random.Generator, margin: float = 0.0):
    """Equal discs at area fraction ``eta`` (of the inner square), placed in a
    walled inner square of side L_g and shifted by ``margin`` into a box of
    side L_g + 2 margin; Gaussian velocities of ``sigma_v`` per component
    with zero mean. Returns (field, side of the box)."""
    inner = math.sqrt(n * math.pi * radius ** 2 / eta)
    radii = np.full(n, radius)
    pos = place_floes(radii, WalledBox(inner), rng) + margin
    vel = rng.normal(0.0, sigma_v, (n, 2))
    vel -= vel.mean(axis=0)
    return FloeField(pos, radii, thickness, vel), inner + 2.0 * margin


def _pymunk_adaptive(sim: PymunkSimulation, duration: float, courant: float, radius: float,
                     mass: float, floor_speed: float = 0.0, max_dt: float = math.inf):
    """Advance pymunk by ``duration`` with Δt = courant · r / v, v the rms
    peculiar speed now (or ``floor_speed``), in equal steps."""
    v = sim.velocities
    v_pec = math.sqrt(float(np.mean(np.sum((v - v.mean(axis=0)) ** 2, axis=1))))
    dt = min(courant * radius / max(v_pec, floor_speed, 1e-300), max_dt)
    k = max(1, int(math.ceil(duration / dt)))
    sim.dt = duration / k
    sim.step(k)


GAS_ETA = 0.05
GAS_RESTITUTION = 0.9
COURANT = 0.02             # pymunk: rms speed × Δt = 2 % of a radius


def gas_cooling(out_dir: Path | None = None, quick: bool = False, seed: int = 0,
                progress: bool = True, n_floes: int | None = None,
                n_seeds: int | None = None, samples: int = 40) -> list[Check]:
    """Homogeneous cooling of a dilute inelastic gas in both engines.

    Equal discs (r = 1 m, h = 1 m) at area fraction 0.05, e = 0.9,
    Gaussian velocities of 0.1 m/s per component with zero total momentum,
    no drag; our hard-disc engine in the periodic box (no TC model), pymunk
    in the walled box of the same size (elastic, frictionless walls), with
    Δt = 0.02 r / v_rms re-chosen at every sample (~10⁻³ of the mean free
    time). Run for two Haff times τ_H = 4 / ((1 − e²) ν₀), ν₀ the Enskog
    rate; KE/KE₀ at ``samples`` + 1 times, averaged over ``n_seeds`` seeds
    (N = 2000 × 6 seeds, or 1000 × 3 with ``quick``). Compared: the two
    engines (max relative difference of the mean KE/KE₀, tolerance 5 %), and
    each with Haff's law KE/KE₀ = 1/(1 + t/τ_H)² (tolerance 5 %: the
    homogeneous cooling state cools ~2 % slower than Haff's law at
    e = 0.9 — the Sonine correction and velocity correlations; see the
    hard-disc gas tests).
    """
    n = n_floes if n_floes is not None else (1000 if quick else 2000)
    seeds = n_seeds if n_seeds is not None else (3 if quick else 6)
    radius, thickness, sigma_v = 1.0, 1.0, 0.1
    x = np.linspace(0.0, 2.0, samples + 1)          # t / τ_H
    ke_hd, ke_pm, coll_hd, coll_pm, walls = [], [], 0, 0, 0
    children = np.random.SeedSequence(seed + 2).spawn(seeds)
    for child in _bar(children, progress, "gas cooling (seeds)"):
        rng = np.random.default_rng(child)
        field, side = _gas(n, GAS_ETA, radius, thickness, sigma_v, rng)
        mass = float(field.masses[0])
        kt0 = 0.5 * mass * float(np.sum(field.velocities ** 2)) / n
        nu0 = enskog_rate(n / side ** 2, 2.0 * radius, GAS_ETA, kt0, mass)
        tau_h = 4.0 / ((1.0 - GAS_RESTITUTION ** 2) * nu0)
        hd = HardDiskSimulation(field, PeriodicBox(side), restitution=GAS_RESTITUTION,
                                forcing=None, collision_duration=0.0)
        pm = PymunkSimulation(field, WalledBox(side), restitution=GAS_RESTITUTION, dt=1.0)
        a, b = [hd.kinetic_energy()], [pm.kinetic_energy(rotation=False)]
        for step in _bar(np.diff(x) * tau_h, progress, "  samples"):
            hd.advance(step)
            _pymunk_adaptive(pm, step, COURANT, radius, mass)
            a.append(hd.kinetic_energy())
            b.append(pm.kinetic_energy(rotation=False))
        ke_hd.append(np.array(a) / a[0])
        ke_pm.append(np.array(b) / b[0])
        coll_hd += hd.collision_count
        coll_pm += pm.collision_count
        walls += pm.wall_collision_count
    mean_hd, mean_pm = np.mean(ke_hd, axis=0), np.mean(ke_pm, axis=0)
    haff = 1.0 / (1.0 + x) ** 2
    diff = float(np.max(np.abs(mean_pm / mean_hd - 1.0)))
    err_hd = float(np.max(np.abs(mean_hd / haff - 1.0)))
    err_pm = float(np.max(np.abs(mean_pm / haff - 1.0)))
    figures = []
    if out_dir is not None:
        fig, (ax, ax2) = new_figure((10.5, 4.0), ncols=2)
        ax.semilogy(x, haff, "k-", lw=1.0, label="Haff 1/(1 + t/τ_H)²")
        ax.semilogy(x, mean_hd, "o", ms=4, mfc="none", label="hard discs (periodic)")
        ax.semilogy(x, mean_pm, "x", ms=5, label="pymunk (walls)")
        ax.set_xlabel("t / τ_H")
        ax.set_ylabel("KE / KE₀")
        ax.set_title(f"N = {n}, A = {GAS_ETA:g}, e = {GAS_RESTITUTION:g}, {seeds} seeds")
        ax.legend(fontsize=8)
        ax2.plot(x, mean_hd / haff - 1.0, "o-", ms=3, label="hard discs / Haff − 1")
        ax2.plot(x, mean_pm / haff - 1.0, "x-", ms=4, label="pymunk / Haff − 1")
        ax2.plot(x, mean_pm / mean_hd - 1.0, "s-", ms=3, label="pymunk / hard discs − 1")
        ax2.axhline(0.0, color="k", lw=0.6)
        ax2.set_xlabel("t / τ_H")
        ax2.set_ylabel("relative difference of KE/KE₀")
        ax2.legend(fontsize=8)
        figures.append(save_figure(fig, out_dir, "pymunk_gas_cooling.png"))
    common = (f"N = {n}, A = {GAS_ETA:g}, e = {GAS_RESTITUTION:g}, {seeds} seeds, "
              f"{samples + 1} samples over 2 τ_H")
    return [
        Check("gas/cooling/harddisk-vs-pymunk",
              "dilute inelastic gas: max relative difference of the seed-mean KE/KE₀ between the "
              "hard-disc engine (periodic) and pymunk (walled box)", diff, 0.05,
              detail=(f"{common}; collisions {coll_hd} (hard discs) vs {coll_pm} (pymunk), "
                      f"{walls} wall contacts in pymunk; pymunk Δt = {COURANT:g} r / v_rms"),
              figures=figures),
        Check("gas/cooling/harddisk-vs-haff",
              "hard-disc engine vs Haff's law 1/(1 + t/τ_H)², τ_H from the Enskog rate: max "
              "relative difference of KE/KE₀", err_hd, 0.05,
              detail=f"{common}; at 2 τ_H: {mean_hd[-1] / haff[-1] - 1.0:+.3f}", figures=figures),
        Check("gas/cooling/pymunk-vs-haff",
              "pymunk vs Haff's law: max relative difference of KE/KE₀", err_pm, 0.05,
              detail=f"{common}; at 2 τ_H: {mean_pm[-1] / haff[-1] - 1.0:+.3f}", figures=figures),
    ]


DRAG_ETA = 0.1
DRAG_WIND = (3.0 * math.cos(math.radians(30.0)), 3.0 * math.sin(math.radians(30.0)))


def drag_forcing() -> Forcing:
    """Herman (2011) drag coefficients with a constant 3 m/s wind at 30° and
    no current (a drift of ~1 cm/s, so that the gas stays clear of pymunk's
    walls over five relaxation times)."""
    return HERMAN2011.make_forcing(wind=DRAG_WIND, current=(0.0, 0.0))


def drag_relaxation(out_dir: Path | None = None, quick: bool = False, seed: int = 0,
                    progress: bool = True, n_floes: int | None = None,
                    relaxation_times: float = 5.0, samples: int = 40) -> list[Check]:
    """Relaxation of the mean velocity of a dilute gas under Stokes drag.

    Equal discs (r = 1 m, h = 1 m; all floes share τ and u_eq) at area
    fraction 0.1, e = 0.9, Gaussian velocities of 0.05 m/s per component
    with zero mean, drag of :func:`drag_forcing` (Herman 2011 form: the
    hard-disc engine's linearly implicit update every Δt_max = 1 s; pymunk's
    exact exponential every step). Collisions conserve momentum, so the mean
    velocity follows ū(t) = ū_eq (1 − exp(−t/τ)) exactly, ū_eq the mass-
    weighted mean of u_eq,i, whatever the collisions — provided no floe
    reaches pymunk's walls: the gas is placed in the middle of a box with
    margins of twice the drift plus three thermal ranges σ_v τ (wall
    contacts are counted and reported). Compared after ``relaxation_times``
    τ: both engines' mean velocities with each other and with ū(t)
    (tolerance 1 % of |ū_eq| each); the largest difference over the run is
    reported in the detail.
    """
    n = n_floes if n_floes is not None else (500 if quick else 2000)
    radius, thickness, sigma_v = 1.0, 1.0, 0.05
    forcing = drag_forcing()
    rng = np.random.default_rng(seed + 3)
    # free drift and time constant of the (equal) floes
    probe_m = _masses(radius, thickness)
    tau = float(forcing.time_constant(radius, thickness, probe_m))
    u_eq_one = forcing.equilibrium_velocity(np.array([radius]), np.array([thickness]),
                                            np.array([probe_m]))[0]
    duration = relaxation_times * tau
    margin = 2.0 * float(np.hypot(*u_eq_one)) * duration + 3.0 * sigma_v * tau
    field, side = _gas(n, DRAG_ETA, radius, thickness, sigma_v, rng, margin=margin)
    m = field.masses
    u_eq = forcing.equilibrium_velocity(field.radii, field.thickness, m)
    u_bar_eq = (m[:, None] * u_eq).sum(axis=0) / m.sum()
    hd = HardDiskSimulation(field, PeriodicBox(side), restitution=GAS_RESTITUTION,
                            forcing=forcing, max_velocity_step=1.0, collision_duration=0.0)
    pm = PymunkSimulation(field, WalledBox(side), restitution=GAS_RESTITUTION, forcing=forcing,
                          drag="stokes", dt=1.0)
    times = np.linspace(0.0, duration, samples + 1)
    mean_hd = [hd.momentum() / m.sum()]
    mean_pm = [pm.mean_velocity()]
    for step in _bar(np.diff(times), progress, "drag relaxation"):
        hd.advance(step)
        _pymunk_adaptive(pm, step, COURANT, radius, float(m[0]), floor_speed=1e-3 * sigma_v,
                         max_dt=0.02 * tau)
        mean_hd.append(hd.momentum() / m.sum())
        mean_pm.append(pm.mean_velocity())
    mean_hd, mean_pm = np.array(mean_hd), np.array(mean_pm)
    exact = u_bar_eq[None, :] * (1.0 - np.exp(-times / tau))[:, None]
    scale = float(np.hypot(*u_bar_eq))
    d_engines = float(np.hypot(*(mean_hd[-1] - mean_pm[-1]))) / scale
    d_hd = float(np.hypot(*(mean_hd[-1] - exact[-1]))) / scale
    d_pm = float(np.hypot(*(mean_pm[-1] - exact[-1]))) / scale
    run_hd = float(np.max(np.hypot(*(mean_hd - exact).T))) / scale
    run_pm = float(np.max(np.hypot(*(mean_pm - exact).T))) / scale
    figures = []
    if out_dir is not None:
        fig, (ax,) = new_figure((6.4, 4.2))
        ax.plot(times / tau, exact[:, 0], "k-", lw=1.0, label="ū_eq (1 − exp(−t/τ))")
        ax.plot(times / tau, mean_hd[:, 0], "o", ms=4, mfc="none", label="hard discs")
        ax.plot(times / tau, mean_pm[:, 0], "x", ms=5, label="pymunk")
        ax.axhline(u_bar_eq[0], color="k", lw=0.6, ls="--", label="ū_eq,x")
        ax.set_xlabel("t / τ")
        ax.set_ylabel("mean velocity ū_x [m/s]")
        ax.set_title(f"Stokes drag, N = {n}, A = {DRAG_ETA:g}, τ = {tau:.0f} s")
        ax.legend(fontsize=8)
        figures.append(save_figure(fig, out_dir, "pymunk_drag_relaxation.png"))
    common = (f"N = {n} equal floes, A = {DRAG_ETA:g} (inner square), e = {GAS_RESTITUTION:g}, "
              f"τ = {tau:.4g} s, |ū_eq| = {scale:.4g} m/s, t = {relaxation_times:g} τ; "
              f"collisions {hd.collision_count} / {pm.collision_count}, "
              f"pymunk wall contacts {pm.wall_collision_count}")
    return [
        Check("gas/drag/harddisk-vs-pymunk",
              "Stokes drag on a dilute gas: difference of the final mean velocities of the two "
              "engines over |ū_eq|", d_engines, 0.01, detail=common, figures=figures),
        Check("gas/drag/harddisk-vs-analytic",
              "hard-disc engine: final mean velocity vs ū_eq (1 − exp(−t/τ)), over |ū_eq|",
              d_hd, 0.01, detail=(f"largest over the run {run_hd:.2g} (implicit drag update at "
                                  f"multiples of Δt_max = 1 s, so a sample lags by up to 1 s)"),
              figures=figures),
        Check("gas/drag/pymunk-vs-analytic",
              "pymunk: final mean velocity vs ū_eq (1 − exp(−t/τ)), over |ū_eq|", d_pm, 0.01,
              detail=f"largest over the run {run_pm:.2g} (exact exponential drag update)",
              figures=figures),
    ]


# ---------------------------------------------------------------------------
# 5. Speed
# ---------------------------------------------------------------------------

def speed(out_dir: Path | None = None, quick: bool = False, seed: int = 0,
          progress: bool = True, n_floes: int | None = None,
          duration: float | None = None) -> list[Check]:
    """Collisions per second of the hard-disc engine and of pymunk, and
    pymunk's steps per second, on one system: equal discs (r = 1 m,
    h = 1 m) at area fraction 0.3, e = 0.9, velocities of 0.05 m/s per
    component, the Stokes drag of :func:`drag_forcing`; N = 2000 for 300
    model seconds (1000 for 150 s with ``quick``; a few collisions per
    floe). The
    hard-disc engine uses the TC model (Δt_c = 0.1 s) and Δt_max = 1 s;
    pymunk Δt = 0.02 r / v_rms (0.28 s) and its drag through per-body
    velocity functions. Wall time after a warm-up (Numba compilation
    excluded); the hard-disc run is timed three times from the same state
    and the best time is kept."""
    n = n_floes if n_floes is not None else (1000 if quick else 2000)
    duration = duration if duration is not None else (150.0 if quick else 300.0)
    radius, sigma_v, eta = 1.0, 0.05, 0.3
    rng = np.random.default_rng(seed + 4)
    field, side = _gas(n, eta, radius, 1.0, sigma_v, rng)
    forcing = drag_forcing()
    # warm-up: compile the hard-disc kernels on a small copy
    small, small_side = _gas(50, eta, radius, 1.0, sigma_v, np.random.default_rng(seed + 5))
    HardDiskSimulation(small, PeriodicBox(small_side), restitution=GAS_RESTITUTION,
                       forcing=forcing).advance(10.0)
    best, coll_hd = math.inf, 0
    for _ in _bar(range(3), progress, "speed: hard discs"):
        hd = HardDiskSimulation(field, PeriodicBox(side), restitution=GAS_RESTITUTION,
                                forcing=forcing, max_velocity_step=1.0, collision_duration=0.1)
        t0 = time.perf_counter()
        hd.advance(duration)
        best = min(best, time.perf_counter() - t0)
        coll_hd = hd.collision_count
    dt = COURANT * radius / (math.sqrt(2.0) * sigma_v)
    pm = PymunkSimulation(field, WalledBox(side), restitution=GAS_RESTITUTION, forcing=forcing,
                          drag="stokes", dt=dt)
    pm.step(2)
    c0, s0 = pm.collision_count, pm.n_steps
    t0 = time.perf_counter()
    pm.advance(duration, progress=progress)
    wall_pm = time.perf_counter() - t0
    coll_pm, steps_pm = pm.collision_count - c0, pm.n_steps - s0
    # the same without drag: the cost of the velocity functions
    free = PymunkSimulation(field, WalledBox(side), restitution=GAS_RESTITUTION, dt=dt)
    t0 = time.perf_counter()
    free.advance(duration)
    steps_free = free.n_steps / (time.perf_counter() - t0)
    rate_hd = coll_hd / best
    rate_pm = coll_pm / wall_pm
    common = f"N = {n}, A = {eta:g}, e = {GAS_RESTITUTION:g}, Stokes drag, {duration:g} model s"
    return [
        Check("speed/harddisk/collisions-per-s", "hard-disc engine: collisions per wall-clock "
              "second (one core, compile time excluded)", rate_hd, None, unit="collisions/s",
              detail=f"{common}: {coll_hd} collisions in {best:.3g} s"),
        Check("speed/pymunk/collisions-per-s", "pymunk: collisions (contacts begun) per "
              "wall-clock second", rate_pm, None, unit="collisions/s",
              detail=f"{common}: {coll_pm} collisions in {wall_pm:.3g} s, Δt = {dt:.3g} s"),
        Check("speed/pymunk/steps-per-s", "pymunk: steps per wall-clock second (drag through "
              "per-body Python velocity functions)", steps_pm / wall_pm, None, unit="steps/s",
              detail=(f"{common}: {steps_pm} steps; {steps_free:.4g} steps/s without drag "
                      f"(no velocity functions)")),
        Check("speed/harddisk-over-pymunk", "collisions per second, hard-disc engine / pymunk",
              rate_hd / rate_pm, None, unit="×", detail=common),
    ]


# ---------------------------------------------------------------------------

def run(out_dir: Path | None = None, quick: bool = False, seed: int = 0,
        progress: bool = True) -> list[Check]:
    """Every pymunk comparison. ``quick`` uses fewer impacts and smaller
    gases (same tolerances; ~1–2 minutes instead of ~5–10)."""
    out = Path(out_dir) if out_dir is not None else None
    rows: list[Check] = []
    for check in (binary_frictionless, binary_friction, gas_cooling, drag_relaxation, speed):
        rows += check(out, quick=quick, seed=seed, progress=progress)
    return rows
