"""The hull–floe contact and the ship's step, as compiled kernels (:ref:`physics-ship`).

A ship is one rigid convex polygon (:class:`~physics.hull.Hull`) among the
floe discs. :func:`physics.hull.disc_hull_contact` finds where a disc
touches it; this module turns that into forces and moves the ship.

**Contact law.** The floe–hull contact uses the Hertz–Mindlin law of the floe–floe contacts
(:func:`physics.contact.hertz_mindlin_force`) with

* the effective moduli of a floe against a rigid body (those of the walls),
* R* = r, the floe's radius, on edges *and* corners. A flat edge has no
  curvature of its own; a corner would need a rounding radius that a polygon
  does not have. With R* = r everywhere the force depends on the overlap
  alone, which is continuous where the nearest feature changes from an edge
  to a corner, so the contact stays conservative without damping.
* m*, the effective mass of the floe and the hull at the contact point
  along the normal: 1/m* = 1/m_f + n_xb²/M_x + n_yb²/M_y + (p × n)²/I_z,
  with the ship's masses including added mass (n_b: the normal in the ship
  frame, p: the contact point from the ship's centroid). A prescribed ship
  has infinite mass: m* = m_f. With this m* the damping calibration of the
  floe–floe contacts gives the set restitution.
* its own Coulomb coefficient (ice on hull, default 0.05).

The floe is body i of the pair law and the hull body j: n points from the
floe's centre to the hull, the contact point p lies halfway through the
overlap, and the tangential slip is that of the floe's material point at p
relative to the hull's (floe lever r − δ/2), so that friction only ever
removes energy. Forces on the floe and on the hull are equal and opposite
and act at p: the step conserves linear and angular momentum exactly.

**Neighbour search.** The hull is 10–40 floe diameters long, so it does not go into the cell
lists of the floes. It keeps a list of its own: the floes whose discs come
within a skin s of the polygon, found by one linear pass (bounding circle,
then the polygon distance). The list is valid while the hull's points and
the floes together have moved less than s since the build: the kernel adds
up |V| Δt + R_c |r| Δt for the hull (R_c: its reach from the centroid) and
the largest floe speed × Δt, and builds the list again when the sum reaches
s. The cost per step is the contacts with the few floes along the hull.

**The floes' own list.** A floe the hull pushes moves at the ship's speed,
ten to a hundred times the drift of the pack, and with one skin for all
floes it would expire the floes' Verlet list every few dozen steps. With a
ship the list is built with a skin per floe (:func:`ship_floe_skins`): a
floe moving at u relative to the mean drift gets 2 u T, and a floe within
the hull's skin of the hull (one it may hit) 4 V T, with V the speed of the
hull's fastest point (a floe leaves an impact at up to (1 + e) V ≤ 2 V);
T is :data:`SKIN_HORIZON_STEPS` steps, every skin is at most the hull's,
and one under twice the floes' own stays at theirs. The list then lasts
until a floe has moved half its own skin (:mod:`physics.neighbors`); the
few wide-skinned floes are checked in a pass of their own
(:func:`physics.hertz_kernels.wide_floes_pass`).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .contact import hertz_mindlin_force
from .domain import minimum_image
from .hull import FEATURE_NONE, disc_hull_contact

__all__ = ["ShipBundle", "RECORD_COLUMNS", "LOG_COLUMNS", "ship_kick_drift", "hull_forces",
           "ship_closing_kick", "hull_contact_list"]

#: columns of a step record (one row per step, :attr:`ShipBundle.record`);
#: ``normal_force`` and ``force_magnitude_sum`` are Σ_c F_n,c and Σ_c |F_c|
#: over the hull's contacts [N]
RECORD_COLUMNS = ("time", "x", "y", "heading", "surge", "sway", "yaw_rate", "ice_surge",
                  "ice_sway", "ice_moment", "ice_power", "contacts", "normal_force",
                  "force_magnitude_sum")
#: columns of the collision log (one row per finished collision)
LOG_COLUMNS = ("start", "end", "floe", "impulse_surge", "impulse_sway", "point_x", "point_y",
               "floe_mass", "peak_force")

# indices into ShipBundle.state
(S_X, S_Y, S_PSI, S_VX, S_VY, S_R, S_AX, S_AY, S_AR, S_HULL_TRAVEL, S_FLOE_TRAVEL, S_FX, S_FY,
 S_N) = range(14)
STATE_SIZE = 14
# indices into ShipBundle.counts
C_CAND, C_LOG, C_REBUILDS, C_LOG_FULL, C_RECORD = range(5)
# ShipBundle.contact columns
K_START, K_JX, K_JY, K_PX, K_PY, K_PEAK = range(6)


class ShipBundle(NamedTuple):
    """A ship as the compiled step sees it; :class:`physics.ship.ShipState`
    builds it. Without a ship the bundle is inactive and has empty arrays."""

    #: whether there is a ship
    active: bool
    #: dynamic (True) or prescribed (False) motion
    dynamic: bool
    #: (K,) hull corners in the ship frame [m] (x forward, counter-clockwise)
    hull_x: np.ndarray
    hull_y: np.ndarray
    #: (K,) scratch: corners in the world frame, relative to the centroid [m]
    world_x: np.ndarray
    world_y: np.ndarray
    #: largest distance of a corner from the centroid [m]
    reach: float
    #: skin of the hull's floe list [m]
    skin: float
    #: (STATE_SIZE,) x, y, heading, Vx, Vy, yaw rate, the three
    #: accelerations of the last force evaluation, the hull's and the
    #: floes' travel since the list build, the last ice force (x, y; world
    #: frame) and moment
    state: np.ndarray
    #: mass in surge and sway and yaw inertia, each with added mass [kg, kg m²]
    mass_x: float
    mass_y: float
    inertia: float
    #: (6,) linear damping ``X_u, Y_v, N_r`` and quadratic ``X_uu, Y_vv, N_rr``
    damping: np.ndarray
    #: (3,) commands: prescribed (surge speed, sway speed, yaw rate),
    #: dynamic (thrust, side force, yaw moment)
    command: np.ndarray
    #: (2,) water velocity the hydrodynamic damping is relative to [m/s]
    current: np.ndarray
    #: the floe–hull contact law
    law: object
    #: (N, 2) Mindlin history of each floe's contact with the hull
    hist: np.ndarray
    #: (N, 6) open collision of each floe: start time (−1: none), impulse
    #: on the hull (ship frame), first contact point (ship frame), peak force
    contact: np.ndarray
    #: (N,) floes in the hull's list
    cand: np.ndarray
    #: counts: list length, log rows, list builds, log full, record rows
    counts: np.ndarray
    #: (capacity, len(LOG_COLUMNS)) finished collisions
    log: np.ndarray
    #: (steps, len(RECORD_COLUMNS)) one row per step
    record: np.ndarray


def inactive_bundle(law) -> ShipBundle:
    """The bundle of a simulation without a ship (typed like a real one)."""
    z1 = np.zeros(1)
    return ShipBundle(False, False, z1, z1, np.zeros(1), np.zeros(1), 0.0, 0.0,
                      np.zeros(STATE_SIZE), 1.0, 1.0, 1.0, np.zeros(6), np.zeros(3), np.zeros(2),
                      law, np.zeros((0, 2)), np.zeros((0, 6)), np.zeros(0, dtype=np.int64),
                      np.zeros(5, dtype=np.int64), np.zeros((0, len(LOG_COLUMNS))),
                      np.zeros((0, len(RECORD_COLUMNS))))


# ---------------------------------------------------------------------------
# The ship's motion
# ---------------------------------------------------------------------------

@njit(cache=True, inline="always", error_model="numpy")
def hull_point_speed(ship):
    """The speed of the hull's fastest point [m/s]: the centroid's speed
    plus the yaw rate times the reach (a bound, for any corner)."""
    s = ship.state
    return math.sqrt(s[S_VX] * s[S_VX] + s[S_VY] * s[S_VY]) + ship.reach * abs(s[S_R])


@njit(cache=True, error_model="numpy", _nrt=False)
def ship_kick_drift(ship, dt_kick, dt):
    """First half of the ship's step: kick by ``dt_kick`` with the last
    accelerations (dynamic), or take the commanded velocities (prescribed),
    then drift by Δt. Adds the hull's travel to ``state``."""
    s = ship.state
    if ship.dynamic:
        s[S_VX] += dt_kick * s[S_AX]
        s[S_VY] += dt_kick * s[S_AY]
        s[S_R] += dt_kick * s[S_AR]
        s[S_PSI] += dt * s[S_R]
    else:
        # surge and sway along the heading at mid-step
        r = ship.command[2]
        psi_mid = s[S_PSI] + 0.5 * dt * r
        c = math.cos(psi_mid)
        sn = math.sin(psi_mid)
        s[S_VX] = c * ship.command[0] - sn * ship.command[1]
        s[S_VY] = sn * ship.command[0] + c * ship.command[1]
        s[S_R] = r
        s[S_PSI] += dt * r
    s[S_X] += dt * s[S_VX]
    s[S_Y] += dt * s[S_VY]
    s[S_HULL_TRAVEL] += dt * hull_point_speed(ship)


@njit(cache=True, error_model="numpy", _nrt=False)
def ship_accelerations(ship, fx, fy, moment):
    """The accelerations of a dynamic ship under the ice force (fx, fy)
    (world frame) and ``moment``, its commands and its hydrodynamic
    damping, at its current (half-step) velocities, into ``state``.

    Surge, sway and yaw of a body with added mass (Kirchhoff's equations in
    the ship frame): ``M_x u̇ − M_y v r = X``, ``M_y v̇ + M_x u r = Y``,
    ``I ṙ + (M_y − M_x) u v = N``."""
    s = ship.state
    c = math.cos(s[S_PSI])
    sn = math.sin(s[S_PSI])
    u = c * s[S_VX] + sn * s[S_VY]
    v = -sn * s[S_VX] + c * s[S_VY]
    r = s[S_R]
    # damping acts on the velocity through the water
    ur = u - (c * ship.current[0] + sn * ship.current[1])
    vr = v - (-sn * ship.current[0] + c * ship.current[1])
    d = ship.damping
    fx_b = c * fx + sn * fy
    fy_b = -sn * fx + c * fy
    big_x = fx_b + ship.command[0] - (d[0] + d[3] * abs(ur)) * ur
    big_y = fy_b + ship.command[1] - (d[1] + d[4] * abs(vr)) * vr
    big_n = moment + ship.command[2] - (d[2] + d[5] * abs(r)) * r
    mx, my = ship.mass_x, ship.mass_y
    du = (big_x + my * v * r) / mx
    dv = (big_y - mx * u * r) / my
    # the acceleration of the world-frame velocity: R(ψ)(u̇ − v r, v̇ + u r)
    au = du - v * r
    av = dv + u * r
    s[S_AX] = c * au - sn * av
    s[S_AY] = sn * au + c * av
    s[S_AR] = (big_n - (my - mx) * u * v) / ship.inertia


@njit(cache=True, error_model="numpy", _nrt=False)
def ship_closing_kick(ship, dt):
    """The last half kick of a run (dynamic ship only)."""
    if ship.dynamic:
        s = ship.state
        h = 0.5 * dt
        s[S_VX] += h * s[S_AX]
        s[S_VY] += h * s[S_AY]
        s[S_R] += h * s[S_AR]


# ---------------------------------------------------------------------------
# The hull's floe list and the contact loop
# ---------------------------------------------------------------------------

@njit(cache=True, inline="always", error_model="numpy")
def set_world_hull(ship):
    """Corners of the hull in the world frame, relative to the centroid."""
    c = math.cos(ship.state[S_PSI])
    s = math.sin(ship.state[S_PSI])
    for k in range(ship.hull_x.shape[0]):
        ship.world_x[k] = c * ship.hull_x[k] - s * ship.hull_y[k]
        ship.world_y[k] = s * ship.hull_x[k] + c * ship.hull_y[k]


@njit(cache=True, error_model="numpy", _nrt=False)
def build_hull_list(ship, pos, radius, lx, ly, px, py):
    """The floes whose discs come within the skin of the hull (one linear
    pass); resets the travel counters."""
    set_world_hull(ship)
    s = ship.state
    x0, y0 = s[S_X], s[S_Y]
    skin = ship.skin
    n_cand = 0
    for i in range(radius.shape[0]):
        dx = minimum_image(pos[i, 0] - x0, lx, px)
        dy = minimum_image(pos[i, 1] - y0, ly, py)
        reach = ship.reach + radius[i] + skin
        if dx * dx + dy * dy >= reach * reach:
            continue
        overlap = disc_hull_contact(dx, dy, radius[i] + skin, ship.world_x, ship.world_y)[0]
        if overlap > 0.0:
            ship.cand[n_cand] = i
            n_cand += 1
    ship.counts[C_CAND] = n_cand
    ship.counts[C_REBUILDS] += 1
    s[S_HULL_TRAVEL] = 0.0
    s[S_FLOE_TRAVEL] = 0.0


#: time a floe's skin is sized to last with a ship, in steps (the floes'
#: list is rebuilt about this often while the ship pushes floes)
SKIN_HORIZON_STEPS = 3000


@njit(cache=True, error_model="numpy")
def ship_floe_skins(ship, floes, skin, dt, lx, ly, px, py):
    """The skin of each floe for a list build with a ship: 2 u T for a floe
    moving at u relative to the mean velocity, at least 4 V T for a floe
    within the hull's skin of the hull (V: the speed of the hull's fastest
    point), T = :data:`SKIN_HORIZON_STEPS` Δt; at most the hull's skin and
    what the periodic sides allow (2 r_max + s_i under half a side). A floe
    whose skin would be less than twice ``skin`` (the floes' own), and a
    frozen floe, keeps ``skin``."""
    pos, vel, radius, inv_mass = floes.pos, floes.vel, floes.radius, floes.inv_mass
    n = radius.shape[0]
    out = np.full(n, skin)
    if n == 0:
        return out
    cap = ship.skin
    r_max = radius.max()
    if px:
        cap = min(cap, 0.49 * lx - 2.0 * r_max)
    if py:
        cap = min(cap, 0.49 * ly - 2.0 * r_max)
    if cap <= skin:
        return out
    mvx = 0.0
    mvy = 0.0
    for i in range(n):
        mvx += vel[i, 0]
        mvy += vel[i, 1]
    mvx /= n
    mvy /= n
    horizon = SKIN_HORIZON_STEPS * dt
    set_world_hull(ship)
    s = ship.state
    x0, y0 = s[S_X], s[S_Y]
    hull_speed = hull_point_speed(ship)
    near_skin = 4.0 * hull_speed * horizon
    for i in range(n):
        if inv_mass[i] == 0.0:
            continue
        ux = vel[i, 0] - mvx
        uy = vel[i, 1] - mvy
        si = 2.0 * math.sqrt(ux * ux + uy * uy) * horizon
        if si < near_skin:
            dx = minimum_image(pos[i, 0] - x0, lx, px)
            dy = minimum_image(pos[i, 1] - y0, ly, py)
            reach = ship.reach + radius[i] + ship.skin
            if dx * dx + dy * dy < reach * reach:
                if disc_hull_contact(dx, dy, radius[i] + ship.skin, ship.world_x,
                                     ship.world_y)[0] > 0.0:
                    si = near_skin
        # a skin less than twice the floes' own is not worth the floe's
        # place in the pass over the wide floes (wide_floes_pass)
        out[i] = min(cap, si) if si >= 2.0 * skin else skin
    return out


@njit(cache=True, inline="always", error_model="numpy")
def floe_hull_contact(ship, dx, dy, vx, vy, w, r, inv_mass, spring, a_last, dt_history):
    """The contact of one floe (centre (dx, dy) relative to the ship's
    centroid, minimum image) with the hull.

    Returns (touching, fx, fy, torque_floe, moment_hull, spring, a_last,
    f_normal, f_tangential, px, py, delta, power): (fx, fy) acts on the
    floe and −(fx, fy) on the hull at the contact point (px, py) (relative
    to the centroid, world frame); ``power`` is the rate of work of the hull
    on the floe, (fx, fy) · (velocity of the hull at p)."""
    overlap, nhx, nhy, px, py, feature, _ = disc_hull_contact(dx, dy, r, ship.world_x,
                                                              ship.world_y)
    s = ship.state
    inv_ship = 0.0
    if ship.dynamic:
        c = math.cos(s[S_PSI])
        sn = math.sin(s[S_PSI])
        nbx = c * nhx + sn * nhy
        nby = -sn * nhx + c * nhy
        arm = px * nhy - py * nhx
        inv_ship = nbx * nbx / ship.mass_x + nby * nby / ship.mass_y + arm * arm / ship.inertia
    inv_sum = inv_mass + inv_ship
    if feature == FEATURE_NONE or inv_sum == 0.0:
        return (False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, px, py, 0.0, 0.0)
    # pair law with the floe as body i, the hull as body j: n from floe to hull
    nx = -nhx
    ny = -nhy
    hvx = s[S_VX] - s[S_R] * py
    hvy = s[S_VY] + s[S_R] * px
    rvx = vx - hvx
    rvy = vy - hvy
    lever = r - 0.5 * overlap
    v_normal = rvx * nx + rvy * ny
    v_slip = -rvx * ny + rvy * nx + lever * w
    law = ship.law
    fn, ft, spring, a_last = hertz_mindlin_force(overlap, r, 1.0 / inv_sum, v_normal, v_slip,
                                                 spring, a_last, dt_history, law)
    tt = law.tangential_translation
    fx = -fn * nx - tt * ft * ny
    fy = -fn * ny + tt * ft * nx
    moment = -(px * fy - py * fx)
    return (True, fx, fy, ft * lever, moment, spring, a_last, fn, ft, px, py, overlap,
            fx * hvx + fy * hvy)


@njit(cache=True, error_model="numpy", _nrt=False)
def hull_forces(ship, floes, box, time, dt, floe_speed, force, torque, looked=None):
    """The hull's step after the floes' drift: the list check (and build),
    the contacts (their forces added to ``force``, ``torque`` of the floes),
    the collision log, the step record and the ship's new accelerations.

    ``floe_speed`` is the largest floe speed of the drift (for the list's
    validity), ``time`` the time after the step. With ``looked`` (N,), the
    floes of the list with ``looked[i] == 0`` are passed over: the caller
    has shown that they cannot touch the hull in this step
    (:mod:`physics.hertz_free_drift`). Returns False when the log is full
    (the caller stops the run after this step and empties it)."""
    s = ship.state
    s[S_FLOE_TRAVEL] += dt * floe_speed
    pos, vel, omega, radius, inv_mass = (floes.pos, floes.vel, floes.omega, floes.radius,
                                         floes.inv_mass)
    lx, ly = box.lengths[0], box.lengths[1]
    px_, py_ = box.periodic_x, box.periodic_y
    if s[S_HULL_TRAVEL] + s[S_FLOE_TRAVEL] >= ship.skin:
        build_hull_list(ship, pos, radius, lx, ly, px_, py_)
    else:
        set_world_hull(ship)
    c = math.cos(s[S_PSI])
    sn = math.sin(s[S_PSI])
    hist, contact, log, counts = ship.hist, ship.contact, ship.log, ship.counts
    fsx = 0.0
    fsy = 0.0
    ns = 0.0
    power = 0.0
    normal = 0.0
    magnitude = 0.0
    n_touch = 0
    room = True
    for k in range(counts[C_CAND]):
        i = ship.cand[k]
        if looked is not None and looked[i] == 0:
            continue
        res = floe_hull_contact(ship, minimum_image(pos[i, 0] - s[S_X], lx, px_),
                                minimum_image(pos[i, 1] - s[S_Y], ly, py_), vel[i, 0], vel[i, 1],
                                omega[i], radius[i], inv_mass[i], hist[i, 0], hist[i, 1], dt)
        hist[i, 0] = res[5]
        hist[i, 1] = res[6]
        if res[0]:
            fx, fy = res[1], res[2]
            force[i, 0] += fx
            force[i, 1] += fy
            torque[i] += res[3]
            fsx -= fx
            fsy -= fy
            ns += res[4]
            power += res[12]
            normal += res[7]
            n_touch += 1
            # the impulse on the hull, in the ship frame
            jx = -(c * fx + sn * fy) * dt
            jy = -(-sn * fx + c * fy) * dt
            f_abs = math.sqrt(fx * fx + fy * fy)
            magnitude += f_abs
            if contact[i, K_START] < 0.0:
                contact[i, K_START] = time
                contact[i, K_JX] = jx
                contact[i, K_JY] = jy
                contact[i, K_PX] = c * res[9] + sn * res[10]
                contact[i, K_PY] = -sn * res[9] + c * res[10]
                contact[i, K_PEAK] = f_abs
            else:
                contact[i, K_JX] += jx
                contact[i, K_JY] += jy
                contact[i, K_PEAK] = max(contact[i, K_PEAK], f_abs)
        elif contact[i, K_START] >= 0.0:
            # the collision ended: log it
            row = counts[C_LOG]
            log[row, 0] = contact[i, K_START]
            log[row, 1] = time
            log[row, 2] = i
            log[row, 3] = contact[i, K_JX]
            log[row, 4] = contact[i, K_JY]
            log[row, 5] = contact[i, K_PX]
            log[row, 6] = contact[i, K_PY]
            log[row, 7] = 1.0 / inv_mass[i] if inv_mass[i] > 0.0 else math.inf
            log[row, 8] = contact[i, K_PEAK]
            counts[C_LOG] = row + 1
            contact[i, K_START] = -1.0
            if row + 1 >= log.shape[0]:
                room = False
    s[S_FX] = fsx
    s[S_FY] = fsy
    s[S_N] = ns
    if ship.dynamic:
        ship_accelerations(ship, fsx, fsy, ns)
    # the step record: pose, velocities in the ship frame, ice load in the ship frame
    row = counts[C_RECORD]
    rec = ship.record
    if row < rec.shape[0]:
        rec[row, 0] = time
        rec[row, 1] = s[S_X]
        rec[row, 2] = s[S_Y]
        rec[row, 3] = s[S_PSI]
        rec[row, 4] = c * s[S_VX] + sn * s[S_VY]
        rec[row, 5] = -sn * s[S_VX] + c * s[S_VY]
        rec[row, 6] = s[S_R]
        rec[row, 7] = c * fsx + sn * fsy
        rec[row, 8] = -sn * fsx + c * fsy
        rec[row, 9] = ns
        rec[row, 10] = power
        rec[row, 11] = n_touch
        rec[row, 12] = normal
        rec[row, 13] = magnitude
        counts[C_RECORD] = row + 1
    # a log with fewer free rows than the list has floes could overflow next step
    if log.shape[0] - counts[C_LOG] <= counts[C_CAND]:
        room = False
    return room


@njit(cache=True, error_model="numpy")
def hull_contact_list(ship, floes, box):
    """Every floe touching the hull now, without changing the history.

    Returns (floes (K,), data (K, 9): fx, fy on the floe, torque on the
    floe, moment on the hull, normal force, tangential force, contact point
    x, y relative to the centroid (world frame), overlap)."""
    s = ship.state
    pos, vel, omega, radius, inv_mass = (floes.pos, floes.vel, floes.omega, floes.radius,
                                         floes.inv_mass)
    lx, ly = box.lengths[0], box.lengths[1]
    set_world_hull(ship)
    m = ship.counts[C_CAND]
    idx = np.empty(m, dtype=np.int64)
    data = np.empty((m, 9))
    k = 0
    for q in range(m):
        i = ship.cand[q]
        res = floe_hull_contact(ship, minimum_image(pos[i, 0] - s[S_X], lx, box.periodic_x),
                                minimum_image(pos[i, 1] - s[S_Y], ly, box.periodic_y),
                                vel[i, 0], vel[i, 1], omega[i], radius[i], inv_mass[i],
                                ship.hist[i, 0], ship.hist[i, 1], 0.0)
        if res[0]:
            idx[k] = i
            data[k, 0] = res[1]
            data[k, 1] = res[2]
            data[k, 2] = res[3]
            data[k, 3] = res[4]
            data[k, 4] = res[7]
            data[k, 5] = res[8]
            data[k, 6] = res[9]
            data[k, 7] = res[10]
            data[k, 8] = res[11]
            k += 1
    return idx[:k], data[:k]
