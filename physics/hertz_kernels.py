"""Compiled kernels of the Hertz engine: contact loops and the velocity-Verlet step.

Pointwise functions do the physics of one contact or one floe; thin loop
kernels run them over all pairs or floes, each in a serial and a parallel
(``prange``) form:

* serial pair loop: one pass over the Verlet list, the force of a pair is
  added to i and subtracted from j at once (a scatter);
* parallel pair loop: the owners of the list are split into chunks with
  equal numbers of pairs (:func:`pair_chunks`). The owners of chunk c lie
  in a range of floe numbers of their own (:func:`chunk_range`; the ranges
  of the chunks cut 0 … N−1 into consecutive pieces): a chunk adds the
  forces of floes in its range straight to the force buffer, which no
  other chunk writes there. A pair whose partner lies outside the range (a
  *cut* pair) writes the partner's share to a slot of its own instead, and
  the slots are added to their floes, in the order of the chunks, at the
  start of the next step, just before the kick and drift of the same floes
  (:func:`gather_cut`). So no two chunks ever write the same memory. When
  the floes are numbered in space (:func:`physics.floes.spatial_order`),
  partners are mostly in the same range and only the pairs along the cuts
  between the chunks' patches have slots.

The number of chunks is a function of N alone (:func:`chunk_count`), not of
the number of threads: every sum is taken in the same order whatever thread
runs which chunk, and the new state is the same bit for bit on any number of
threads. The parallel step runs each phase (the kick–drift pass, the wall
forces, the pair loop) as one parallel region (``prange``) over the chunks,
which the threading layer hands out in the same consecutive blocks every
step.

Step (LAMMPS ``fix nve/sphere`` order): half kick with F(t) → drift →
affine remap of a deforming box → drag and wall forces (they need only the
floe itself) → Verlet-list check (and rebuild) → pair forces at t + Δt with
the half-step velocities → half kick.

Arguments travel as named bundles (named tuples, which Numba compiles to
plain structures: reading a field costs nothing): the floes
(:class:`Floes`), their forcing (:class:`Drive`), the contact law
(:class:`~physics.contact.ContactLaw`), the box
(:class:`~physics.domain.KernelBox`), the Verlet list (:class:`VerletList`)
and, inside a run, the one kick–drift pass (:class:`Kick`), the chunks of
the parallel pair loop (:class:`PairChunks`) and the force buffer
(:class:`ForceBuffers`). The arrays of
a bundle are shared, not copied: a kernel that writes into them changes the
caller's state.

The kernels called once per step that allocate nothing (the kick–drift
pass, the drag, wall and pair forces, the closing half kick) are compiled
without Numba's reference counting (``_nrt=False``): every array taken from
a bundle would otherwise be counted in and out with atomic operations at
each call, which costs about 4 % of a step of the environments' 200-floe
fields. Such a kernel must not allocate.
"""
from __future__ import annotations

import math
from enum import IntEnum
from typing import NamedTuple

import numpy as np
from numba import njit, prange, types
from numba.extending import intrinsic

from .contact import hertz_mindlin_force
from .domain import box_lengths_at, minimum_image
from .hull_contact import (ship_closing_kick, ship_floe_skins,
                           ship_kick_drift)
from .neighbors import build_pair_list, build_pair_list_serial, transfer_history


class HertzStatus(IntEnum):
    """How a run (:func:`physics.hertz_step.run_steps`) ended."""

    #: every step done
    OK = 0
    #: a position or velocity became NaN or infinite
    NON_FINITE = 1
    #: a deforming box reached its concentration limit
    CONCENTRATION_LIMIT = 2
    #: a floe moved more than half the Verlet skin in one step
    UNSTABLE = 3
    #: the ship's collision log is full (the caller empties it and goes on)
    SHIP_LOG_FULL = 4


# the statuses as plain integers for the compiled code
STATUS_OK = int(HertzStatus.OK)
STATUS_NON_FINITE = int(HertzStatus.NON_FINITE)
STATUS_CONCENTRATION_LIMIT = int(HertzStatus.CONCENTRATION_LIMIT)
STATUS_UNSTABLE = int(HertzStatus.UNSTABLE)
STATUS_SHIP_LOG_FULL = int(HertzStatus.SHIP_LOG_FULL)


class Floes(NamedTuple):
    """The state and constants of N floes. Frozen floes have zero inverse
    mass and inertia."""

    #: (N, 2) centres [m]
    pos: np.ndarray
    #: (N, 2) velocities [m/s]
    vel: np.ndarray
    #: (N,) angular velocities [1/s]
    omega: np.ndarray
    #: (N,) radii [m]
    radius: np.ndarray
    #: (N,) 1/m [1/kg], 0 for frozen floes
    inv_mass: np.ndarray
    #: (N,) 1/I [1/(kg m²)], 0 for frozen floes
    inv_inertia: np.ndarray
    #: (N,) rank by radius (:func:`physics.neighbors.radius_rank`)
    rank: np.ndarray
    #: (N, 2) total force of the last step [N]
    force: np.ndarray
    #: (N,) total torque of the last step [N m]
    torque: np.ndarray
    #: (N, 4, 2) Mindlin history (spring, a_last) of the contact with each wall
    wall_hist: np.ndarray


class Drive(NamedTuple):
    """The external forcing (Herman 2013, eqs 6–7)."""

    #: (N, 4) per floe: wind a, water b, rotational drag c, Coriolis m f
    #: (all zero for frozen floes)
    coefficients: np.ndarray
    #: wind (x, y) [m/s]
    wind_x: float
    wind_y: float
    #: ocean current (x, y) [m/s]
    current_x: float
    current_y: float
    #: |wind| [m/s]
    wind_speed: float
    #: whether any coefficient is non-zero
    active: bool


def make_drive(coefficients: np.ndarray, wind=(0.0, 0.0), current=(0.0, 0.0)) -> Drive:
    """A :class:`Drive` with the drag ``coefficients`` (N, 4), the wind and
    the current (2-vectors [m/s])."""
    uax, uay = float(wind[0]), float(wind[1])
    uwx, uwy = float(current[0]), float(current[1])
    return Drive(coefficients, uax, uay, uwx, uwy, math.sqrt(uax * uax + uay * uay),
                 bool(np.any(coefficients != 0.0)))


class VerletList(NamedTuple):
    """A Verlet list in CSR form (:mod:`physics.neighbors`) with the
    contact history of its pairs and what decides when it expires."""

    #: (N + 1,) slice bounds of each owner's partners in ``nbr``
    start: np.ndarray
    #: (M,) partners
    nbr: np.ndarray
    #: (M, 2) Mindlin history (spring, a_last) of each pair
    hist: np.ndarray
    #: (N, 2) positions at the build (remapped with a deforming box)
    ref: np.ndarray
    #: (2,) box lengths at the build
    ref_lengths: np.ndarray
    #: (2,) mean displacement of the floes since the build [m]
    centre: np.ndarray
    #: skin [m]
    skin: float
    #: cell width of the build [m]
    cell_size: float
    #: longest cut-off 2 r_max + skin [m]
    max_cut: float
    #: (N,) skin of each floe [m]: ``skin`` for all, but wider for the
    #: floes a ship sets moving (:func:`physics.hull_contact.ship_floe_skins`)
    skins: np.ndarray
    #: largest of ``skins`` [m]
    skin_max: float
    #: (K,) the floes whose skin is wider than ``skin`` (:func:`wide_floes_pass`)
    wide: np.ndarray
    #: (K, 2) their positions at the build
    wide_ref: np.ndarray
    #: (K,) (skin / s_i)² of each
    wide_weight: np.ndarray


class Kick(NamedTuple):
    """The constants of one kick–drift pass (:func:`first_half`)."""

    #: kick time step (Δt/2 in the first step of a run, else Δt) [s]
    dt_kick: float
    #: drift time step Δt [s]
    dt: float
    #: box lengths after the step [m]
    lx: float
    ly: float
    periodic_x: bool
    periodic_y: bool
    #: affine remap factors of a deforming box (new length / old length)
    sx: float
    sy: float
    #: mean displacement since the build, subtracted before the largest is taken [m]
    cx: float
    cy: float


class PairChunks(NamedTuple):
    """The chunks of the parallel pair loop (:func:`pair_chunks`) and the
    cut pairs' slots (see the module docstring)."""

    #: floes that own pairs
    owners: np.ndarray
    #: chunk c is owners[bounds[c]:bounds[c + 1]]
    bounds: np.ndarray
    #: (M,) the slot (row of ``cut``) of each pair of the list whose partner
    #: lies outside its chunk's range, −1 for the others
    slot: np.ndarray
    #: (S, 3) the partner's force (x, y) and torque of each cut pair, written
    #: by the pair loop and added to the partner (then zeroed) by :func:`gather_cut`
    cut: np.ndarray
    #: the floes that are partners of cut pairs, in increasing order
    shared: np.ndarray
    #: (len(shared) + 1,) the slots of floe shared[k] are gather[first[k]:first[k + 1]]
    first: np.ndarray
    #: slots per shared floe, each floe's in increasing order (= chunk order)
    gather: np.ndarray


class ForceBuffers(NamedTuple):
    """The force buffer of a run (:func:`force_buffers`): the pair loop
    adds to it, the kick–drift pass kicks with it."""

    #: (N, 2) forces [N]
    force: np.ndarray
    #: (N,) torques [N m]
    torque: np.ndarray


N_CHUNKS = 64   # chunks of the parallel wall-force loop
#: floes per chunk of the parallel step (:func:`chunk_count`)
FLOES_PER_CHUNK = 1024
#: most chunks of the parallel step
MAX_CHUNKS = 1024


# ---------------------------------------------------------------------------
# Pointwise physics (scalars in, scalars out: no array crosses a call, so no
# reference counting in the hot loops)
# ---------------------------------------------------------------------------

@njit(cache=True, inline="always", error_model="numpy")
def pair_contact(dx, dy, ri, rj, vrx, vry, wi, wj, inv_mass_sum, spring, a_last, dt_history, law):
    """Force of floe j on floe i, given their minimum-image separation
    (dx, dy) = x_j − x_i and relative velocity (vrx, vry) = u_i − u_j.

    Returns (touching, fx, fy, torque_i, torque_j, spring, a_last, f_normal,
    f_tangential, nx, ny, delta): (fx, fy) acts on i and −(fx, fy) on j;
    n = (nx, ny) is the unit vector from i to j; (spring, a_last) is the
    updated Mindlin history; ``law`` is a
    :class:`~physics.contact.ContactLaw`. A pair that does not touch, or
    of two frozen floes, returns zeros (and a reset history).
    """
    rsum = ri + rj
    d2 = dx * dx + dy * dy
    if d2 >= rsum * rsum or inv_mass_sum == 0.0:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    d = math.sqrt(d2)
    nx = dx / d
    ny = dy / d
    delta = rsum - d
    v_normal = vrx * nx + vry * ny
    v_slip = -vrx * ny + vry * nx + ri * wi + rj * wj
    fn, ft, spring, a_last = hertz_mindlin_force(delta, ri * rj / rsum, 1.0 / inv_mass_sum,
                                                 v_normal, v_slip, spring, a_last, dt_history,
                                                 law)
    tt = law.tangential_translation
    fx = -fn * nx - tt * ft * ny
    fy = -fn * ny + tt * ft * nx
    return (True, fx, fy, ft * (ri - 0.5 * delta), ft * (rj - 0.5 * delta), spring, a_last,
            fn, ft, nx, ny, delta)


@njit(cache=True, inline="always", error_model="numpy")
def wall_overlap(side, x, y, r, lx, ly):
    """(overlap, nx, ny) of a disc of radius r at (x, y) with wall ``side``
    (0..3 = wall at x=0, x=lx, y=0, y=ly; n points from the floe to the
    wall); the disc touches it when the overlap is positive."""
    if side == 0:
        return r - x, -1.0, 0.0
    if side == 1:
        return r - (lx - x), 1.0, 0.0
    if side == 2:
        return r - y, 0.0, -1.0
    return r - (ly - y), 0.0, 1.0


@njit(cache=True, inline="always", error_model="numpy")
def wall_contact(side, x, y, vx, vy, w, r, inv_mass, lx, ly, spring, a_last, dt_history, law):
    """Force of a rigid wall on a floe; ``side`` 0..3 = wall at x=0, x=lx,
    y=0, y=ly. Returns (fx, fy, torque, spring, a_last)."""
    delta, nx, ny = wall_overlap(side, x, y, r, lx, ly)
    if delta <= 0.0 or inv_mass == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    v_normal = vx * nx + vy * ny
    v_slip = -vx * ny + vy * nx + r * w
    fn, ft, spring, a_last = hertz_mindlin_force(delta, r, 1.0 / inv_mass, v_normal, v_slip,
                                                 spring, a_last, dt_history, law)
    tt = law.tangential_translation
    return -fn * nx - tt * ft * ny, -fn * ny + tt * ft * nx, ft * (r - delta), spring, a_last


@njit(cache=True, inline="always", error_model="numpy")
def floe_drag(vx, vy, w, a, b, c, g, uax, uay, uwx, uwy, wind_speed):
    """Eq 6–7 forcing of one floe: wind a|u_a|u_a, water b(u_w − u),
    Coriolis −g k×u (g = m f) and rotational drag −c ω. Returns (fx, fy, torque)."""
    fx = a * wind_speed * uax + b * (uwx - vx) + g * vy
    fy = a * wind_speed * uay + b * (uwy - vy) - g * vx
    return fx, fy, -c * w


@njit(cache=True, inline="always", error_model="numpy")
def path_slack(lx, ly):
    """A bound on the rounding error of one drift of a floe's position in a
    box of lengths (lx, ly) (a few units in the last place of the largest
    coordinate)."""
    return 2e-15 * (lx + ly)


@njit(cache=True, inline="always", error_model="numpy")
def drift_bound(kick):
    """(length per unit speed, constant) of the bound on one drift that a
    floe's path grows by: Δt (1 + 1e-12) and :func:`path_slack`; zeros for
    a deforming box, which remaps the floes by more than they drift (there
    the paths are not used)."""
    if kick.sx != 1.0 or kick.sy != 1.0:
        return 0.0, 0.0
    return rigid_drift_bound(kick.dt, kick.lx, kick.ly)


@njit(cache=True, inline="always", error_model="numpy")
def rigid_drift_bound(dt, lx, ly):
    """:func:`drift_bound` of a step Δt = ``dt`` in a rigid box of lengths
    (lx, ly)."""
    return dt * (1.0 + 1e-12), path_slack(lx, ly)


@njit(cache=True, inline="always", error_model="numpy")
def apart_until(dx, dy, rsum, paths):
    """For a pair apart by (dx, dy) with radii summing to ``rsum``, whose
    floes' paths sum to ``paths``: the sum of their paths below which they
    cannot touch. Neither floe can have come closer by more than the length
    it drifted, so while the sum grows by less than the gap they stay apart;
    a nanometre and a relative 1e-12 are kept back for rounding."""
    d = math.sqrt(dx * dx + dy * dy)
    return paths + (d - rsum) - 1e-9 - 1e-12 * (d + rsum)


@njit(cache=True, inline="always", error_model="numpy")
def walls_apart_until(i, floes, box, path_i):
    """For floe i, whose path is ``path_i``: the path below which it cannot
    touch a wall of the box (−∞ when it touches one now)."""
    pos, radius = floes.pos, floes.radius
    lx, ly = box.lengths[0], box.lengths[1]
    gap = math.inf
    for side in range(4):
        if (side < 2 and box.periodic_x) or (side >= 2 and box.periodic_y):
            continue
        gap = min(gap, -wall_overlap(side, pos[i, 0], pos[i, 1], radius[i], lx, ly)[0])
    if gap > 0.0:
        return path_i + gap - 1e-9 - 1e-12 * (lx + ly)
    return -math.inf


@njit(cache=True, inline="always", error_model="numpy")
def wrap_once(x, length, periodic):
    """Wrap a coordinate that moved by less than one box length in a step
    into [0, length) (compares and selects only: no branch, no division,
    so that a loop over floes vectorises). Coordinates of a non-periodic
    side are returned as they are."""
    x = x - length if periodic and x >= length else x
    return x + length if periodic and x < 0.0 else x


@intrinsic
def order_key(typingctx, x):
    """The bits of a float64 as a uint64. For non-negative floats (and
    +inf) the keys are in the order of the floats, and every NaN, whatever
    its sign bit, has a larger key than +inf: the largest key of a set of
    squares is their maximum, or a NaN if there is one. Integer maxima
    vectorise; floating-point maxima do not without assuming no NaNs."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], context.get_value_type(types.uint64))
    return types.uint64(types.float64), codegen


@intrinsic
def from_order_key(typingctx, k):
    """The float64 whose bits are ``k`` (inverse of :func:`order_key`)."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], context.get_value_type(types.float64))
    return types.float64(types.uint64), codegen


@njit(cache=True, inline="always", error_model="numpy")
def min_image_step(d, length, periodic):
    """Minimum image of a displacement known to be within (−L, L)."""
    if periodic:
        if d > 0.5 * length:
            d -= length
        elif d < -0.5 * length:
            d += length
    return d


# ---------------------------------------------------------------------------
# Loop kernels
# ---------------------------------------------------------------------------

@njit(cache=True, error_model="numpy", _nrt=False)
def wall_forces(i_lo, i_hi, floes, wall_law, box, dt_history, force, torque, path=None,
                wall_due=None):
    """Add the forces of the rigid walls of non-periodic sides to floes
    i_lo..i_hi−1 (and advance their history ``floes.wall_hist``). With the
    floes' ``path`` and ``wall_due`` (the serial step in a rigid box), a
    floe found clear of the walls is not looked at again until its path
    passes :func:`walls_apart_until`: such a look gives no force and leaves
    the (zero) history as it is."""
    for i in range(i_lo, i_hi):
        if wall_due is None:
            floe_walls(i, floes, wall_law, box, dt_history, force, torque)
        else:
            floe_walls_skipping(i, floes, wall_law, box, dt_history, force, torque, path,
                                wall_due)


@njit(cache=True, inline="always", error_model="numpy")
def floe_walls_skipping(i, floes, wall_law, box, dt_history, force, torque, path, wall_due):
    """:func:`floe_walls` of floe i once its path has passed ``wall_due[i]``
    (then the next threshold, :func:`walls_apart_until`); nothing before."""
    if path[i] >= wall_due[i]:
        floe_walls(i, floes, wall_law, box, dt_history, force, torque)
        wall_due[i] = walls_apart_until(i, floes, box, path[i])


@njit(cache=True, inline="always", error_model="numpy")
def floe_walls(i, floes, wall_law, box, dt_history, force, torque):
    """Add the forces of the rigid walls of non-periodic sides to floe i
    (and advance its history ``floes.wall_hist``)."""
    pos, vel, omega, radius = floes.pos, floes.vel, floes.omega, floes.radius
    inv_mass, wall_hist = floes.inv_mass, floes.wall_hist
    lx, ly = box.lengths[0], box.lengths[1]
    for side in range(4):
        if (side < 2 and box.periodic_x) or (side >= 2 and box.periodic_y):
            continue
        wfx, wfy, wtq, sp, al = wall_contact(side, pos[i, 0], pos[i, 1], vel[i, 0], vel[i, 1],
                                             omega[i], radius[i], inv_mass[i], lx, ly,
                                             wall_hist[i, side, 0], wall_hist[i, side, 1],
                                             dt_history, wall_law)
        wall_hist[i, side, 0] = sp
        wall_hist[i, side, 1] = al
        force[i, 0] += wfx
        force[i, 1] += wfy
        torque[i] += wtq


@njit(cache=True, error_model="numpy", _nrt=False)
def drag_forces(i_lo, i_hi, floes, drive, force, torque):
    """Assign the eq 6–7 forcing of ``drive`` to floes i_lo..i_hi−1."""
    vel, omega, drag = floes.vel, floes.omega, drive.coefficients
    uax, uay, uwx, uwy = drive.wind_x, drive.wind_y, drive.current_x, drive.current_y
    wind_speed = drive.wind_speed
    for i in range(i_lo, i_hi):
        fx, fy, tq = floe_drag(vel[i, 0], vel[i, 1], omega[i], drag[i, 0], drag[i, 1], drag[i, 2],
                               drag[i, 3], uax, uay, uwx, uwy, wind_speed)
        force[i, 0] = fx
        force[i, 1] = fy
        torque[i] = tq


@njit(cache=True, inline="always", error_model="numpy")
def listed_pair(p, j, dx, dy, vxi, vyi, wi, ri, imi, floes, law, hist, dt_history):
    """:func:`pair_contact` of pair p of a Verlet list, owner i (its
    velocity, angular velocity, radius and inverse mass given) and partner
    j, their minimum-image separation (dx, dy) = x_j − x_i given, with the
    pair's history ``hist[p]`` advanced."""
    vel, omega, radius, inv_mass = floes.vel, floes.omega, floes.radius, floes.inv_mass
    res = pair_contact(dx, dy, ri, radius[j], vxi - vel[j, 0], vyi - vel[j, 1], wi, omega[j],
                       imi + inv_mass[j], hist[p, 0], hist[p, 1], dt_history, law)
    hist[p, 0] = res[5]
    hist[p, 1] = res[6]
    return res


@njit(cache=True, error_model="numpy", _nrt=False)
def owner_pairs(k_lo, k_hi, owners, floes, law, box, verlet, dt_history, force, torque,
                j_lo=0, j_hi=0, slot=None, cut=None, path=None, due=None):
    """Forces of the pairs owned by floes owners[k_lo:k_hi], each added to
    both floes of its pair at once (a scatter into ``force``, ``torque``).
    With the ``slot`` of each pair (:class:`PairChunks`), the partner's
    share of a pair whose partner j lies outside j_lo ≤ j < j_hi (its
    chunk's :func:`chunk_range`) goes to row slot[p] of ``cut`` instead.

    Only floes that touch are written: in loose ice most listed pairs are
    apart, and a write of zero would still claim the cache line for this
    thread, so that the thread doing the kick of that floe would have to
    fetch it back (see :func:`first_half_parallel`).

    With the floes' ``path`` and the pairs' ``due`` (the serial step in a
    rigid box), a pair found apart is not looked at again until the paths
    of its floes pass :func:`apart_until` (as in
    :func:`physics.hertz_resting.live_pair_forces`)."""
    pos, vel, omega, radius, inv_mass = (floes.pos, floes.vel, floes.omega, floes.radius,
                                         floes.inv_mass)
    start, nbr, hist = verlet.start, verlet.nbr, verlet.hist
    lx, ly = box.lengths[0], box.lengths[1]
    px, py = box.periodic_x, box.periodic_y
    for k in range(k_lo, k_hi):
        i = owners[k]
        xi_, yi_ = pos[i, 0], pos[i, 1]
        vxi, vyi, wi, ri, imi = vel[i, 0], vel[i, 1], omega[i], radius[i], inv_mass[i]
        fxi = 0.0
        fyi = 0.0
        tqi = 0.0
        for p in range(start[i], start[i + 1]):
            j = nbr[p]
            paths = 0.0
            if due is not None:
                paths = path[i] + path[j]
                if paths < due[p]:
                    continue
            dx = minimum_image(pos[j, 0] - xi_, lx, px)
            dy = minimum_image(pos[j, 1] - yi_, ly, py)
            res = listed_pair(p, j, dx, dy, vxi, vyi, wi, ri, imi, floes, law, hist, dt_history)
            if due is not None and not res[0]:
                due[p] = apart_until(dx, dy, ri + radius[j], paths)
            if res[0]:
                fxi += res[1]
                fyi += res[2]
                tqi += res[3]
                if slot is None or j_lo <= j < j_hi:
                    force[j, 0] -= res[1]
                    force[j, 1] -= res[2]
                    torque[j] += res[4]
                else:
                    q = slot[p]
                    cut[q, 0] = -res[1]
                    cut[q, 1] = -res[2]
                    cut[q, 2] = res[4]
        if fxi != 0.0 or fyi != 0.0 or tqi != 0.0:
            force[i, 0] += fxi
            force[i, 1] += fyi
            torque[i] += tqi


@njit(cache=True, error_model="numpy")
def forces_serial(floes, law, wall_law, drive, box, verlet, dt_history, force, torque):
    """All forces and torques at the current state into ``force``,
    ``torque`` (serial)."""
    n = floes.radius.shape[0]
    drag_forces(0, n, floes, drive, force, torque)
    if not (box.periodic_x and box.periodic_y):
        wall_forces(0, n, floes, wall_law, box, dt_history, force, torque)
    start = verlet.start
    owners = np.nonzero(start[1:] > start[:-1])[0]
    owner_pairs(0, owners.shape[0], owners, floes, law, box, verlet, dt_history, force, torque)


@njit(cache=True, error_model="numpy")
def owner_chunks(start, n_chunks):
    """(owners, bounds): the floes that own pairs of the list, split into
    ``n_chunks`` runs owners[bounds[c]:bounds[c+1]] with about equal numbers
    of pairs (a giant floe owning many pairs gets a short run)."""
    owners = np.nonzero(start[1:] > start[:-1])[0]
    first = start[owners]
    total = start[-1]
    bounds = np.empty(n_chunks + 1, dtype=np.int64)
    for c in range(n_chunks + 1):
        bounds[c] = np.searchsorted(first, c * total / n_chunks)
    bounds[0] = 0
    bounds[n_chunks] = owners.shape[0]
    return owners, bounds


@njit(cache=True, inline="always", error_model="numpy")
def chunk_range(c, owners, bounds, n):
    """(lo, hi): the floe numbers lo ≤ i < hi whose forces chunk c of
    :func:`owner_chunks` writes to the shared buffer, from its first owner
    to the first owner of the next chunk (0 for the first chunk, N for the
    last): consecutive pieces of 0 … N−1 that hold every owner of the
    chunk."""
    n_owners = owners.shape[0]
    lo = 0 if c == 0 else (owners[bounds[c]] if bounds[c] < n_owners else n)
    last = bounds.shape[0] - 2
    hi = n if c == last else (owners[bounds[c + 1]] if bounds[c + 1] < n_owners else n)
    return lo, hi


@njit(cache=True, error_model="numpy")
def chunk_count(n):
    """Chunks of the parallel step of N floes: the largest power of two
    not above N / :data:`FLOES_PER_CHUNK`, at least 1 and at most
    :data:`MAX_CHUNKS`. A function of N alone, so that the order of every
    sum, and so the new state bit for bit, does not depend on the number
    of threads; a power of two, so that 2, 4, 8, ... threads share the
    chunks evenly."""
    c = 1
    while 2 * c * FLOES_PER_CHUNK <= n and 2 * c <= MAX_CHUNKS:
        c *= 2
    return c


@njit(cache=True, error_model="numpy")
def pair_chunks(verlet, n_chunks):
    """The list's owners cut into ``n_chunks`` chunks of the parallel pair
    loop (:func:`owner_chunks`) and a slot for each pair whose partner lies
    outside its chunk's :func:`chunk_range` (a cut pair), numbered in the
    order of the list. ``first`` and ``gather`` list each partner's slots
    in that order, which is the order of the chunks: :func:`gather_cut`
    adds them up in the same order whatever thread ran which chunk. With
    the floes numbered in space only the pairs across the boundaries
    between the chunks' patches are cut."""
    start, nbr = verlet.start, verlet.nbr
    n = start.shape[0] - 1
    owners, bounds = owner_chunks(start, n_chunks)
    slot = np.full(nbr.shape[0], -1, dtype=np.int64)
    count = np.zeros(n, dtype=np.int64)
    n_slots = 0
    for c in range(n_chunks):
        lo, hi = chunk_range(c, owners, bounds, n)
        for k in range(bounds[c], bounds[c + 1]):
            i = owners[k]
            for p in range(start[i], start[i + 1]):
                j = nbr[p]
                if j < lo or j >= hi:
                    slot[p] = n_slots
                    n_slots += 1
                    count[j] += 1
    shared = np.nonzero(count)[0]
    first = np.zeros(shared.shape[0] + 1, dtype=np.int64)
    at = np.zeros(n, dtype=np.int64)
    for k in range(shared.shape[0]):
        first[k + 1] = first[k] + count[shared[k]]
        at[shared[k]] = first[k]
    gather = np.empty(n_slots, dtype=np.int64)
    for p in range(nbr.shape[0]):           # slots increase with p
        if slot[p] >= 0:
            j = nbr[p]
            gather[at[j]] = slot[p]
            at[j] += 1
    return PairChunks(owners, bounds, slot, np.zeros((n_slots, 3)), shared, first, gather)


@njit(cache=True, error_model="numpy")
def pair_task(k, chunks, floes, law, box, verlet, dt_history, buffers):
    """Chunk k of the parallel pair loop (:func:`pair_forces_parallel`):
    :func:`owner_pairs` over the k-th run of owners of
    :func:`owner_chunks`, into the force buffer for the floes of its
    :func:`chunk_range` and into the slots of its cut pairs for the
    others."""
    lo, hi = chunk_range(k, chunks.owners, chunks.bounds, floes.pos.shape[0])
    owner_pairs(chunks.bounds[k], chunks.bounds[k + 1], chunks.owners, floes, law, box, verlet,
                dt_history, buffers.force, buffers.torque, lo, hi, chunks.slot, chunks.cut)


@njit(cache=True, error_model="numpy")
def force_buffers(n):
    """A zeroed :class:`ForceBuffers` of N floes."""
    return ForceBuffers(np.zeros((n, 2)), np.zeros(n))


# Parallel kernels that other compiled kernels call are never cached on disk
# (cache=False): when a caller is compiled in a process that loaded such a
# callee from Numba's cache, the caller's own cache entry crashes every later
# process that loads it (seen with numba 0.68). Compiled in the same process
# as its caller, the callee is embedded in the caller's (cached) code.
@njit(cache=False, parallel=True, error_model="numpy")
def pair_forces_parallel(chunks, floes, law, box, verlet, dt_history, buffers):
    """:func:`owner_pairs` over the chunks of :func:`owner_chunks` in
    parallel (:func:`pair_task`): race-free (see the module docstring)."""
    for c in prange(chunks.bounds.shape[0] - 1):
        pair_task(c, chunks, floes, law, box, verlet, dt_history, buffers)


@njit(cache=False, parallel=True, error_model="numpy")
def wall_forces_parallel(floes, wall_law, box, dt_history, force, torque):
    """:func:`wall_forces` over all floes in parallel chunks (each floe only
    touches its own rows: no race)."""
    n = floes.radius.shape[0]
    for c in prange(N_CHUNKS):
        wall_forces(c * n // N_CHUNKS, (c + 1) * n // N_CHUNKS, floes, wall_law, box, dt_history,
                    force, torque)


@njit(cache=True, error_model="numpy")
def gather_cut(i_lo, i_hi, chunks, force, torque):
    """Add the slots of the cut pairs of floes i_lo..i_hi−1
    (:func:`pair_chunks`) to their force and torque, in the order of the
    chunks, and clear them. Only non-zero slots (pairs in contact) are
    added and reset: a line left clean stays in the cache of the pair-loop
    thread that writes it next."""
    shared, first, gather, cut = chunks.shared, chunks.first, chunks.gather, chunks.cut
    for k in range(np.searchsorted(shared, i_lo), np.searchsorted(shared, i_hi)):
        i = shared[k]
        for m in range(first[k], first[k + 1]):
            q = gather[m]
            gx = cut[q, 0]
            gy = cut[q, 1]
            gt = cut[q, 2]
            if gx != 0.0 or gy != 0.0 or gt != 0.0:
                force[i, 0] += gx
                force[i, 1] += gy
                torque[i] += gt
                cut[q, 0] = 0.0
                cut[q, 1] = 0.0
                cut[q, 2] = 0.0


# The kick–drift pass may reassociate floating-point sums (``reassoc``): with
# this, and only this, fast-math flag its loop vectorises. Infinities, NaNs
# and signed zeros keep their IEEE meaning, so that a blow-up still shows in
# the results the step checks.
KICK_FASTMATH = {"reassoc"}


@njit(cache=True, fastmath=KICK_FASTMATH, error_model="numpy", _nrt=False)
def first_half(floes, ref, drive, kick, path=None):
    """Kick–drift of the floes ``floes`` (all of them, or the views of a
    run of them) with their forces ``floes.force``, ``floes.torque``, their
    displacement since the list build, and their new drag forces.

    Kick by ``kick.dt_kick`` with the last forces, drift by Δt, affine remap
    by (sx, sy) of a deforming box and periodic wrap (:class:`Kick`);
    frozen floes (inverse mass 0) keep their state. Afterwards the forces
    hold the drag force of ``drive`` (it needs only the new half-step
    velocities; done here to save a pass over memory; zero when
    ``drive.active`` is false, i.e. without forcing), ready for the pair
    loop to add to. ``ref`` (the floes' positions at the build) is remapped
    with the box. Returns (largest squared distance of a displacement from
    (cx, cy), sum of the displacements along x, along y, largest squared
    speed); a NaN anywhere in the new positions or velocities makes the
    sums or the maxima NaN.

    The loop body has no branch and no call (selects for the frozen floes,
    the wrap and the minimum image; maxima over the bits of non-negative
    floats, :func:`order_key`), and the (N, k) arrays are read as flat
    arrays: so it vectorises (AVX2/AVX-512), about 2.7 times as fast as the
    scalar loop (34 against 94 µs for 20000 floes on one thread,
    ``python -m benchmarks.bench_hertz_phases``). Its per-floe arithmetic is the
    same in the vector body and in the scalar remainder, so the new state
    does not depend on how the floes are cut into chunks; only the sums are
    reassociated.

    With ``path`` (the serial step), each floe's path grows by a bound on
    the length of its drift, |v| Δt and the rounding of the new position
    (:func:`path_slack`), in a rigid box (a deforming one remaps the floes
    by more than they drift)."""
    worst, sdx, sdy, vmax2, _ = kick_drift_pass(floes, ref, drive, kick, path)
    return worst, sdx, sdy, vmax2


@njit(cache=True, fastmath=KICK_FASTMATH, error_model="numpy", _nrt=False)
def kick_drift_pass(floes, ref, drive, kick, path=None, order=None, count=0, lines=None,
                    elapsed=0.0, broken=None):
    """The kick–drift pass, written once: :func:`first_half` over all floes
    (``order`` None: the loop vectorises), or over the floes
    ``order[:count]`` alone (the awake floes of
    :func:`physics.hertz_resting.first_half_awake`, the engaged floes of
    :func:`physics.hertz_free_drift.engaged_pass`), with the same per-floe
    arithmetic (:func:`kick_drift_floe`).

    With ``lines`` (a free-drift window's straight lines and budgets, at
    time ``elapsed`` into the window), the floes that left their lines by
    more than their budgets are written to ``broken``. Returns (largest
    squared distance from (cx, cy), Σ dx, Σ dy, largest squared speed,
    the number of floes written to ``broken``)."""
    omega, torque = floes.omega, floes.torque
    inv_mass, inv_inertia = floes.inv_mass, floes.inv_inertia
    sx, sy = kick.sx, kick.sy
    n = inv_mass.shape[0] if order is None else count
    if sx != 1.0 or sy != 1.0:
        for q in range(n):
            i = q if order is None else order[q]
            ref[i, 0] *= sx
            ref[i, 1] *= sy
    p = floes.pos.reshape(-1)
    v = floes.vel.reshape(-1)
    f = floes.force.reshape(-1)
    r = ref.reshape(-1)
    k = drive.coefficients.reshape(-1)
    vmax2 = np.uint64(0)
    worst = np.uint64(0)
    n_broken = 0
    sdx = 0.0
    sdy = 0.0
    step_length, slack = drift_bound(kick)
    for q in range(n):
        i = q if order is None else order[q]
        v2, e2, dx, dy = kick_drift_floe(i, p, v, f, omega, torque, inv_mass, inv_inertia, r, k,
                                         drive, kick)
        if path is not None:
            path[i] += math.sqrt(v2) * step_length + slack
        if lines is not None:
            mx = min_image_step(p[2 * i] - lines[i, 0], kick.lx, kick.periodic_x) \
                - elapsed * lines[i, 2]
            my = min_image_step(p[2 * i + 1] - lines[i, 1], kick.ly, kick.periodic_y) \
                - elapsed * lines[i, 3]
            if mx * mx + my * my > lines[i, 4] * lines[i, 4]:
                broken[n_broken] = i
                n_broken += 1
        key = order_key(v2)
        vmax2 = key if key > vmax2 else vmax2
        key = order_key(e2)
        worst = key if key > worst else worst
        sdx += dx
        sdy += dy
    return from_order_key(worst), sdx, sdy, from_order_key(vmax2), n_broken


@njit(cache=True, inline="always", error_model="numpy")
def kick_drift_floe(i, p, v, f, omega, torque, inv_mass, inv_inertia, r, k, drive, kick):
    """The kick–drift of floe i of :func:`first_half` (``p``, ``v``, ``f``,
    ``r``, ``k``: the positions, velocities, forces, positions at the build
    and drag coefficients as flat arrays): its new state and drag force
    written. Returns (squared speed, 0 for a frozen floe; squared distance
    of its displacement since the build from (kick.cx, kick.cy); the
    displacement along x, along y)."""
    dt_kick, dt = kick.dt_kick, kick.dt
    lx, ly, px, py = kick.lx, kick.ly, kick.periodic_x, kick.periodic_y
    on = 1.0 if drive.active else 0.0
    im = inv_mass[i]
    mobile = im != 0.0
    x0 = p[2 * i]
    y0 = p[2 * i + 1]
    vx0 = v[2 * i]
    vy0 = v[2 * i + 1]
    w0 = omega[i]
    vx = vx0 + dt_kick * f[2 * i] * im
    vy = vy0 + dt_kick * f[2 * i + 1] * im
    w = w0 + dt_kick * torque[i] * inv_inertia[i]
    # one wrap is enough: a floe that crossed more than a box length
    # also crossed half the skin, and the step stops as unstable
    x = wrap_once((x0 + dt * vx) * kick.sx, lx, px)
    y = wrap_once((y0 + dt * vy) * kick.sy, ly, py)
    x = x if mobile else x0
    y = y if mobile else y0
    vx = vx if mobile else vx0
    vy = vy if mobile else vy0
    w = w if mobile else w0
    p[2 * i] = x
    p[2 * i + 1] = y
    v[2 * i] = vx
    v[2 * i + 1] = vy
    omega[i] = w
    # frozen floes have zero drag coefficients: their force is cleared
    fx, fy, tq = floe_drag(vx, vy, w, on * k[4 * i], on * k[4 * i + 1], on * k[4 * i + 2],
                           on * k[4 * i + 3], drive.wind_x, drive.wind_y, drive.current_x,
                           drive.current_y, drive.wind_speed)
    f[2 * i] = fx
    f[2 * i + 1] = fy
    torque[i] = tq
    dx = min_image_step(x - r[2 * i], lx, px)
    dy = min_image_step(y - r[2 * i + 1], ly, py)
    ex = dx - kick.cx
    ey = dy - kick.cy
    return vx * vx + vy * vy if mobile else 0.0, ex * ex + ey * ey, dx, dy


@njit(cache=True, inline="always", error_model="numpy")
def max_keep_nan(a, b):
    """The larger of a and b, NaN if either is NaN."""
    return b if b > a or b != b else a


@njit(cache=True, error_model="numpy")
def combine_chunks(part):
    """The results of :func:`first_half` for the whole pass from those of its
    chunks (rows of ``part``), in chunk order: largest squared distance, the
    two sums, largest squared speed (a NaN in any row makes the maxima
    NaN). A plain loop in a function of its own: inside a ``parallel=True``
    function, ``part[:, 0].max()`` and the like each become a parallel
    region of their own, about 1 µs each."""
    worst = part[0, 0]
    sx = part[0, 1]
    sy = part[0, 2]
    vmax2 = part[0, 3]
    for c in range(1, part.shape[0]):
        worst = max_keep_nan(worst, part[c, 0])
        sx += part[c, 1]
        sy += part[c, 2]
        vmax2 = max_keep_nan(vmax2, part[c, 3])
    return worst, sx, sy, vmax2


@njit(cache=True, inline="always", error_model="numpy")
def floe_rows(floes, lo, hi, buffers):
    """Floes lo..hi−1 of ``floes`` (views) with their rows of the force
    buffer ``buffers`` as their forces."""
    f = floes
    return Floes(f.pos[lo:hi], f.vel[lo:hi], f.omega[lo:hi], f.radius[lo:hi], f.inv_mass[lo:hi],
                 f.inv_inertia[lo:hi], f.rank[lo:hi], buffers.force[lo:hi],
                 buffers.torque[lo:hi], f.wall_hist[lo:hi])


@njit(cache=True, inline="always", error_model="numpy")
def drive_rows(drive, lo, hi):
    """``drive`` with the coefficients of floes lo..hi−1 only (a view)."""
    d = drive
    return Drive(d.coefficients[lo:hi], d.wind_x, d.wind_y, d.current_x, d.current_y,
                 d.wind_speed, d.active)


@njit(cache=True, error_model="numpy")
def kick_task(k, n_tasks, floes, buffers, chunks, ref, drive, kick, part):
    """Part k of a parallel kick–drift pass (:func:`first_half_parallel`):
    :func:`gather_cut` and :func:`first_half` over the k-th of
    ``n_tasks`` equal runs of floes, its results in part[k]."""
    n = floes.pos.shape[0]
    lo = k * n // n_tasks
    hi = (k + 1) * n // n_tasks
    gather_cut(lo, hi, chunks, buffers.force, buffers.torque)
    w, sx_, sy_, v2 = first_half(floe_rows(floes, lo, hi, buffers), ref[lo:hi],
                                 drive_rows(drive, lo, hi), kick)
    part[k, 0] = w
    part[k, 1] = sx_
    part[k, 2] = sy_
    part[k, 3] = v2


@njit(cache=False, parallel=True, error_model="numpy")
def first_half_parallel(n_tasks, floes, buffers, chunks, ref, drive, kick):
    """:func:`first_half` over all floes in parallel (no race), kicking
    with the force buffer ``buffers`` (``floes.force`` is not used), each
    task first adding the slots of its floes' cut pairs
    (:func:`gather_cut`); ``ref`` are the positions at the list build.

    The floes are cut into ``n_tasks`` consecutive runs (as many as the
    pair loop has chunks); the runtime gives each thread the same
    consecutive block of runs every step, so each core keeps its floes in
    its own caches. The chunks of the pair loop (:func:`owner_chunks`)
    hold equal numbers of pairs; when the floes are numbered in space
    (:func:`physics.floes.spatial_order`, as
    :func:`physics.floes.make_floe_field` does) both splits cut the box into
    about the same patches, and a thread mostly reads and writes its own
    floes in both loops. Each task writes only its own floes and its own
    row of the partial results, which are reduced in task order: the new
    state is the same bit for bit whatever thread did which task.

    Each run gets views of its floes (:func:`kick_task`) and loops from a
    start index known at compile time to be 0: with a start known only at
    run time the compiler cannot rule out negative indices, and the loop
    does not vectorise (2.5 times as slow)."""
    part = np.empty((n_tasks, 4))
    for t in prange(n_tasks):
        kick_task(t, n_tasks, floes, buffers, chunks, ref, drive, kick, part)
    return combine_chunks(part)


@njit(cache=True, inline="always", error_model="numpy")
def pass_status(worst, mx, my, vmax2, dt, skin):
    """Status after a kick–drift pass with results (worst, mx, my, vmax2)
    (:func:`first_half`): non-finite state, or a floe that crossed half the
    skin in one step (the dynamics blew up), or OK."""
    if not math.isfinite(worst + mx + my + vmax2):
        return STATUS_NON_FINITE
    if vmax2 * dt * dt > 0.25 * skin * skin:
        return STATUS_UNSTABLE
    return STATUS_OK


@njit(cache=True, inline="always", error_model="numpy")
def list_expired(worst, lx, ly, verlet):
    """Whether the Verlet list may miss a pair: twice the largest
    displacement since the build, plus what a shrinking box takes off the
    distances (up to the longest cut-off), reaches the skin.

    With per-floe skins s_i ≥ s, ``worst`` is the largest |e_i|² (s/s_i)²
    (:func:`wide_floes_pass`):
    2 |e_i| s/s_i + shrink · cut_max < s gives
    2 |e_i| + shrink · cut_max < s_i for every floe, so the pairs' cut-offs
    r_i + r_j + (s_i + s_j)/2 still hold every contact."""
    ref_lengths = verlet.ref_lengths
    shrink = max(0.0, 1.0 - min(lx / ref_lengths[0], ly / ref_lengths[1]))
    max_cut = verlet.max_cut + (verlet.skin_max - verlet.skin)
    return 2.0 * math.sqrt(worst) + shrink * max_cut >= verlet.skin


@njit(cache=True, error_model="numpy", _nrt=False)
def wide_floes_pass(pos, verlet, lx, ly, px, py, cx, cy, cx_new, cy_new, worst):
    """The expiry test of the floes with a skin s_i wider than the list's s
    (:func:`physics.hull_contact.ship_floe_skins`), after a kick–drift pass
    that returned ``worst`` with the centre (cx, cy).

    The list holds while every floe has moved less than s_i / 2 relative to
    a common centre (:mod:`physics.neighbors`). The kick–drift pass finds
    the largest displacement of all floes against s / 2; for a wide floe
    it would be the wrong measure, so its entry in ``verlet.ref`` is a
    shadow that moves with it: set here to x_i − (cx_new, cy_new) each step,
    so that the next pass sees only its motion over one step (it cannot
    decide the expiry). Its true displacement is measured here from
    ``wide_ref``, weighted by (s / s_i)², and merged into the largest.
    Returns the new largest squared (weighted) distance from the centre."""
    for k in range(verlet.wide.shape[0]):
        worst = max_keep_nan(worst, wide_floe_test(k, pos, verlet, lx, ly, px, py, cx, cy,
                                                   cx_new, cy_new))
    return worst


@njit(cache=True, inline="always", error_model="numpy")
def wide_floe_test(k, pos, verlet, lx, ly, px, py, cx, cy, cx_new, cy_new):
    """Wide floe k of :func:`wide_floes_pass`: its weighted squared
    displacement from the centre (cx, cy), and its shadow reference set
    from the new centre."""
    i = verlet.wide[k]
    x = pos[i, 0]
    y = pos[i, 1]
    ex = min_image_step(x - verlet.wide_ref[k, 0], lx, px) - cx
    ey = min_image_step(y - verlet.wide_ref[k, 1], ly, py) - cy
    verlet.ref[i, 0] = x - cx_new
    verlet.ref[i, 1] = y - cy_new
    return (ex * ex + ey * ey) * verlet.wide_weight[k]


@njit(cache=True, error_model="numpy", _nrt=False)
def half_kick(floes, dt):
    """v += Δt/2 F/m, ω += Δt/2 T/I with the floes' forces (the last half
    kick of a run)."""
    vel, omega, force, torque = floes.vel, floes.omega, floes.force, floes.torque
    inv_mass, inv_inertia = floes.inv_mass, floes.inv_inertia
    h = 0.5 * dt
    for i in range(vel.shape[0]):
        vel[i, 0] += h * force[i, 0] * inv_mass[i]
        vel[i, 1] += h * force[i, 1] * inv_mass[i]
        omega[i] += h * torque[i] * inv_inertia[i]


@njit(cache=True, error_model="numpy")
def end_run(floes, force, torque, done, dt, ship):
    """The end of a run of ``done`` steps: the total force of its last step
    (``force``, ``torque``) kept as the floes' forces, and the closing half
    kick of the floes and the ship."""
    floes.force[:] = force
    floes.torque[:] = torque
    if done > 0:
        half_kick(floes, dt)
        if ship.active:
            ship_closing_kick(ship, dt)


@njit(cache=True, error_model="numpy")
def rebuild(floes, verlet, lx, ly, px, py, parallel, skins=None):
    """A new Verlet list at the floes' positions in a box of lengths
    (lx, ly), with the contact history of ``verlet`` carried over, the
    positions at the build copied and the displacement centre reset.
    ``skins``: the skin of each floe (default: ``verlet.skin`` for all)."""
    pos, radius, rank = floes.pos, floes.radius, floes.rank
    skin, cell_size = verlet.skin, verlet.cell_size
    n = pos.shape[0]
    if skins is None:
        sk = np.full(n, skin)
    else:
        sk = skins
    skin_max = sk.max() if n > 0 else skin
    n_wide = 0
    for i in range(n):
        n_wide += sk[i] > skin
    wide = np.empty(n_wide, dtype=np.int64)
    wide_ref = np.empty((n_wide, 2))
    wide_weight = np.empty(n_wide)
    k = 0
    for i in range(n):
        if sk[i] > skin:
            wide[k] = i
            wide_ref[k, 0] = pos[i, 0]
            wide_ref[k, 1] = pos[i, 1]
            q = skin / sk[i]
            wide_weight[k] = q * q
            k += 1
    expected = verlet.nbr.shape[0]
    if parallel:
        new_start, new_nbr = build_pair_list(pos, radius, rank, lx, ly, px, py, sk, cell_size,
                                             expected)
    else:
        new_start, new_nbr = build_pair_list_serial(pos, radius, rank, lx, ly, px, py, sk,
                                                    cell_size, expected)
    new_hist = transfer_history(verlet.start, verlet.nbr, verlet.hist, new_start, new_nbr, 2)
    ref_lengths = np.empty(2)
    ref_lengths[0] = lx
    ref_lengths[1] = ly
    return VerletList(new_start, new_nbr, new_hist, pos.copy(), ref_lengths, np.zeros(2), skin,
                      cell_size, verlet.max_cut, sk, skin_max, wide, wide_ref, wide_weight)


@njit(cache=True, inline="always", error_model="numpy")
def begin_step(box, time, step, dt, centre, ship):
    """The start of step ``step`` of a run: the box's lengths after it
    (written to ``box.lengths``), the :class:`Kick` of the floes' pass
    (centre: the list's displacement centre) and the ship's kick–drift.
    Returns (status, kick): CONCENTRATION_LIMIT, with nothing changed, when
    a deforming box reached its limit, else OK."""
    lengths = box.lengths
    lx_old, ly_old = lengths[0], lengths[1]
    lx, ly, conc = box_lengths_at(box, time + (step + 1) * dt)
    dt_kick = 0.5 * dt if step == 0 else dt
    kick = Kick(dt_kick, dt, lx, ly, box.periodic_x, box.periodic_y, lx / lx_old, ly / ly_old,
                centre[0], centre[1])
    if box.deforming and (conc >= box.max_concentration or conc <= 0.0):
        return STATUS_CONCENTRATION_LIMIT, kick
    lengths[0] = lx
    lengths[1] = ly
    if ship.active:
        ship_kick_drift(ship, dt_kick, dt)
    return STATUS_OK, kick


@njit(cache=True, error_model="numpy")
def rebuild_in_run(floes, verlet, lx, ly, px, py, parallel, ship, deforming, dt):
    """The list rebuild of a run (:func:`rebuild`): with a ship in a rigid
    box, with the floes' skins of :func:`physics.hull_contact.ship_floe_skins`."""
    if ship.active and not deforming:
        return rebuild(floes, verlet, lx, ly, px, py, parallel,
                       ship_floe_skins(ship, floes, verlet.skin, dt, lx, ly, px, py))
    return rebuild(floes, verlet, lx, ly, px, py, parallel)


@njit(cache=True, inline="always", error_model="numpy")
def listed_contact(pos, vel, omega, radius, inv_mass, nbr, hist, law, lx, ly, px, py, i, p):
    """The contact of floe i with its Verlet-list partner ``nbr[p]`` at the
    current state, without changing the history (the tuple of
    :func:`pair_contact`); the arrays of :class:`Floes` and
    :class:`VerletList`, the box's side lengths and periodicity."""
    j = nbr[p]
    return pair_contact(minimum_image(pos[j, 0] - pos[i, 0], lx, px),
                        minimum_image(pos[j, 1] - pos[i, 1], ly, py), radius[i], radius[j],
                        vel[i, 0] - vel[j, 0], vel[i, 1] - vel[j, 1], omega[i], omega[j],
                        inv_mass[i] + inv_mass[j], hist[p, 0], hist[p, 1], 0.0, law)


@njit(cache=True, error_model="numpy")
def ice_energy(vel, omega, radius, inv_mass):
    """Kinetic energy [J] of the mobile floes, translation and rotation:
    Σ ½ m |v|² + ½ I ω² with I = ½ m r² (a disc) and m = 1 / ``inv_mass``;
    a frozen floe (``inv_mass`` 0) counts nothing."""
    e = 0.0
    for i in range(radius.shape[0]):
        if inv_mass[i] > 0.0:
            w = radius[i] * omega[i]
            e += (0.5 * (vel[i, 0] * vel[i, 0] + vel[i, 1] * vel[i, 1]) + 0.25 * w * w) \
                / inv_mass[i]
    return e


@njit(cache=True, error_model="numpy")
def state_finite(pos, vel):
    """Whether every floe's position and velocity is finite."""
    for i in range(pos.shape[0]):
        if not (math.isfinite(pos[i, 0]) and math.isfinite(pos[i, 1])
                and math.isfinite(vel[i, 0]) and math.isfinite(vel[i, 1])):
            return False
    return True


@njit(cache=True, error_model="numpy")
def ice_within(pos, vel, omega, radius, inv_mass, start, nbr, hist, law, lx, ly, px, py, cx, cy,
               reach):
    """The ice within ``reach`` of the point (cx, cy) (minimum-image
    distances), without changing the history: the number of floes whose
    centre lies there and the sum of their r²; the number of touching pairs
    whose contact point (the middle of the overlap) lies there and the sum
    of l ⊗ F over them as (xx, xy, yx, yy), l = x_j − x_i the branch vector
    (from the centre of i through the contact point to the centre of j) and
    F the contact force on i.

    The arguments are the arrays of :class:`Floes` and :class:`VerletList`
    and the box's side lengths and periodicity rather than the bundles:
    unpacking a bundle costs a call several microseconds, more than the
    loop over a few hundred pairs."""
    n_floes, n_contacts = 0, 0
    r2 = sxx = sxy = syx = syy = 0.0
    for i in range(radius.shape[0]):
        if math.hypot(minimum_image(pos[i, 0] - cx, lx, px),
                      minimum_image(pos[i, 1] - cy, ly, py)) < reach:
            n_floes += 1
            r2 += radius[i] * radius[i]
        for p in range(start[i], start[i + 1]):
            res = listed_contact(pos, vel, omega, radius, inv_mass, nbr, hist, law, lx, ly, px,
                                 py, i, p)
            if not res[0]:
                continue
            nx, ny, half_delta = res[9], res[10], 0.5 * res[11]
            arm_i = radius[i] - half_delta
            ix, iy = arm_i * nx, arm_i * ny
            if math.hypot(minimum_image(pos[i, 0] + ix - cx, lx, px),
                          minimum_image(pos[i, 1] + iy - cy, ly, py)) >= reach:
                continue
            arm_j = -(radius[nbr[p]] - half_delta)
            bx, by = ix - arm_j * nx, iy - arm_j * ny
            n_contacts += 1
            sxx += bx * res[1]
            sxy += bx * res[2]
            syx += by * res[1]
            syy += by * res[2]
    return n_floes, r2, n_contacts, sxx, sxy, syx, syy


@njit(cache=True, error_model="numpy")
def contact_list(floes, law, box, verlet):
    """All touching pairs at the current state, without changing the history.

    Returns arrays: i, j (int), and per contact (nx, ny, delta, f_normal,
    f_tangential, fx, fy, torque_i, torque_j) as a (K, 9) float array.
    """
    pos, vel, omega, radius, inv_mass = (floes.pos, floes.vel, floes.omega, floes.radius,
                                         floes.inv_mass)
    start, nbr, hist = verlet.start, verlet.nbr, verlet.hist
    lx, ly = box.lengths[0], box.lengths[1]
    px, py = box.periodic_x, box.periodic_y
    n = radius.shape[0]
    m = nbr.shape[0]
    ii = np.empty(m, dtype=np.int64)
    jj = np.empty(m, dtype=np.int64)
    data = np.empty((m, 9))
    k = 0
    for i in range(n):
        for p in range(start[i], start[i + 1]):
            res = listed_contact(pos, vel, omega, radius, inv_mass, nbr, hist, law, lx, ly, px,
                                 py, i, p)
            if res[0]:
                ii[k] = i
                jj[k] = nbr[p]
                data[k, 0] = res[9]
                data[k, 1] = res[10]
                data[k, 2] = res[11]
                data[k, 3] = res[7]
                data[k, 4] = res[8]
                data[k, 5] = res[1]
                data[k, 6] = res[2]
                data[k, 7] = res[3]
                data[k, 8] = res[4]
                k += 1
    return ii[:k], jj[:k], data[:k]
