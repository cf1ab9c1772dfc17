"""Compiled kernels of the Hertz engine: contact loops and the velocity-Verlet step.

Pointwise functions do the physics of one contact or one floe; thin loop
kernels run them over all pairs or floes, each in a serial and a parallel
(``prange``) form:

* serial pair loop: one pass over the Verlet list, the force of a pair is
  added to i and subtracted from j at once (a scatter);
* parallel pair loop: the owners of the list are split into as many chunks
  as there are threads, with equal numbers of pairs. The owners of chunk c
  lie in a range of floe numbers of their own (:func:`chunk_range`; the
  ranges of the chunks cut 0 … N−1 into consecutive pieces): a chunk adds
  the forces of floes in its range straight to the shared buffer
  (``fbuf[0]``, ``tbuf[0]``), which no other chunk writes there, and those
  of partners outside it to its private buffer (``fbuf[c + 1]``,
  ``tbuf[c + 1]``). So no two chunks ever write the same memory. The
  private buffers are added per floe at the start of the next step, just
  before the kick and drift of the same floes (:func:`gather_buffers`).
  When the floes are numbered in space
  (:func:`physics.floes.spatial_order`) partners are mostly in the same
  range, the private buffers hold only the floes along the cuts, and the
  threads share little memory.

In a periodic box the parallel step runs as a team of threads
(:func:`team_steps`, :mod:`physics.thread_team`) that stays in one parallel
region from one list rebuild to the next and meets at spin barriers between
the kick–drift pass and the pair loop, instead of starting a parallel region
for each (1–2.5 µs each on two threads). Boxes with walls use the kernels
:func:`first_half_parallel`, :func:`wall_forces_parallel` and
:func:`pair_forces_parallel`, one region each.

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
the parallel pair loop (:class:`PairChunks`), the force buffers
(:class:`ForceBuffers`) and the thread team (:class:`Team`). The arrays of
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
from .hull_contact import (ShipBundle, hull_forces, ship_closing_kick, ship_floe_skins,
                           ship_kick_drift)
from .neighbors import build_pair_list, build_pair_list_serial, transfer_history
from .thread_team import (claim, overtaken, sync_size, take_token, task_done, task_order,
                          wait_generation)


class HertzStatus(IntEnum):
    """How :func:`run_steps` ended."""

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
_OK = int(HertzStatus.OK)
_NON_FINITE = int(HertzStatus.NON_FINITE)
_CONCENTRATION_LIMIT = int(HertzStatus.CONCENTRATION_LIMIT)
_UNSTABLE = int(HertzStatus.UNSTABLE)
_SHIP_LOG_FULL = int(HertzStatus.SHIP_LOG_FULL)
# why a team run (team_steps) returned early: the Verlet list must be rebuilt
TEAM_ALL_DONE, TEAM_REBUILD = 0, 1


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
    """The chunks of the parallel pair loop (:func:`pair_chunks`)."""

    #: floes that own pairs
    owners: np.ndarray
    #: chunk c is owners[bounds[c]:bounds[c + 1]]
    bounds: np.ndarray
    #: the floes the chunks can write to their private buffers (:func:`scatter_floes`)
    shared: np.ndarray


class ForceBuffers(NamedTuple):
    """Buffer 0 (shared) and one private buffer per chunk of the pair loop
    (:func:`force_buffers`)."""

    #: (B, N, 2) forces [N]
    force: np.ndarray
    #: (B, N) torques [N m]
    torque: np.ndarray


class Team(NamedTuple):
    """The thread team of :func:`team_steps` (:mod:`physics.thread_team`)."""

    n_threads: int
    #: tasks of the kick–drift phase
    n_kick: int
    #: sync arrays of the kick–drift and pair phases, and of the ship's
    #: phase between them (one task, :func:`ship_after_kick`)
    sync_kick: np.ndarray
    sync_pair: np.ndarray
    sync_ship: np.ndarray
    #: (n_kick, 4) partial results of the kick pass
    part: np.ndarray
    #: (2,) results of the ship's phase: largest squared displacement,
    #: 1 if the ship's collision log is full (else 0)
    ship_out: np.ndarray
    #: (steps done, status, reason, centre x, centre y, log full) of the run
    out: np.ndarray

N_CHUNKS = 64   # chunks of the parallel wall-force loop
# tasks per thread of the parallel kick–drift pass: in the thread team
# (team_steps) a thread that is done with its own tasks takes over the last
# ones of a slower thread
KICK_TASKS_PER_THREAD = 2


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
    return kick.dt * (1.0 + 1e-12), path_slack(kick.lx, kick.ly)


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
def owner_pairs(k_lo, k_hi, owners, floes, law, box, verlet, dt_history, force, torque, j_lo, j_hi,
                force_out, torque_out, path=None, due=None):
    """Forces of the pairs owned by floes owners[k_lo:k_hi], each added to
    both floes of its pair at once (a scatter into ``force``, ``torque``;
    for a partner j outside j_lo ≤ j < j_hi into ``force_out``,
    ``torque_out`` instead).

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
                if j_lo <= j < j_hi:
                    force[j, 0] -= res[1]
                    force[j, 1] -= res[2]
                    torque[j] += res[4]
                else:
                    force_out[j, 0] -= res[1]
                    force_out[j, 1] -= res[2]
                    torque_out[j] += res[4]
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
    owner_pairs(0, owners.shape[0], owners, floes, law, box, verlet, dt_history, force, torque, 0,
                n, force, torque)


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
def scatter_floes(owners, bounds, start, nbr, n):
    """The floes, in increasing order, that the chunks of
    :func:`owner_chunks` can write to their private buffers (partners
    outside the chunk's :func:`chunk_range`): only these floes can have
    non-zero entries in fbuf[1:], tbuf[1:] that the next kick must add up.
    With the floes numbered in space they are the few along the cuts
    between the ranges; the kick does not look at the private buffers of
    the others at all."""
    mask = np.zeros(n, dtype=np.uint8)
    for c in range(bounds.shape[0] - 1):
        lo, hi = chunk_range(c, owners, bounds, n)
        for k in range(bounds[c], bounds[c + 1]):
            i = owners[k]
            for p in range(start[i], start[i + 1]):
                j = nbr[p]
                if j < lo or j >= hi:
                    mask[j] = 1
    return np.nonzero(mask)[0]


@njit(cache=True, error_model="numpy")
def pair_chunks(verlet, n_chunks):
    """The list's owners cut into ``n_chunks`` chunks of the parallel pair
    loop (:func:`owner_chunks`) with the floes they can write to their
    private buffers (:func:`scatter_floes`)."""
    owners, bounds = owner_chunks(verlet.start, n_chunks)
    shared = scatter_floes(owners, bounds, verlet.start, verlet.nbr, verlet.start.shape[0] - 1)
    return PairChunks(owners, bounds, shared)


@njit(cache=True, error_model="numpy")
def pair_task(k, chunks, floes, law, box, verlet, dt_history, buffers):
    """Chunk k of the parallel pair loop (:func:`pair_forces_parallel`, a
    task of :func:`team_member`): :func:`owner_pairs` over the k-th run of
    owners of :func:`owner_chunks`, into the shared buffers fbuf[0],
    tbuf[0] for the floes of its :func:`chunk_range` and into its private
    buffers fbuf[k + 1], tbuf[k + 1] for the others (with one chunk,
    every floe is in its range)."""
    owners, bounds = chunks.owners, chunks.bounds
    fbuf, tbuf = buffers.force, buffers.torque
    run = owners[bounds[k]:bounds[k + 1]]
    lo, hi = chunk_range(k, owners, bounds, floes.pos.shape[0])
    b = min(k + 1, fbuf.shape[0] - 1)
    owner_pairs(0, run.shape[0], run, floes, law, box, verlet, dt_history, fbuf[0], tbuf[0], lo,
                hi, fbuf[b], tbuf[b])


@njit(cache=True, error_model="numpy")
def force_buffers(n_chunks, n):
    """Zeroed :class:`ForceBuffers` (fbuf (B, N, 2), tbuf (B, N)) for a
    pair loop in ``n_chunks`` chunks: the shared buffer 0, then a private
    buffer per chunk if there are two or more (:func:`pair_task`)."""
    n_buf = n_chunks + 1 if n_chunks > 1 else 1
    return ForceBuffers(np.zeros((n_buf, n, 2)), np.zeros((n_buf, n)))


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
def gather_buffers(i_lo, i_hi, buffers, shared):
    """Add the private force buffers b >= 1 of floes i_lo..i_hi-1 into
    buffer 0 and clear them. Only the floes listed in ``shared`` (sorted;
    :func:`scatter_floes`) can hold non-zero entries, and only non-zero
    entries are reset: a line left clean stays in the cache of the pair-loop
    thread that reads it next."""
    fbuf, tbuf = buffers.force, buffers.torque
    for k in range(np.searchsorted(shared, i_lo), np.searchsorted(shared, i_hi)):
        i = shared[k]
        for b in range(1, fbuf.shape[0]):
            gx = fbuf[b, i, 0]
            gy = fbuf[b, i, 1]
            gt = tbuf[b, i]
            if gx != 0.0 or gy != 0.0 or gt != 0.0:
                fbuf[0, i, 0] += gx
                fbuf[0, i, 1] += gy
                tbuf[0, i] += gt
                fbuf[b, i, 0] = 0.0
                fbuf[b, i, 1] = 0.0
                tbuf[b, i] = 0.0


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
    ``python -m benchmarks.hertz_phases``). Its per-floe arithmetic is the
    same in the vector body and in the scalar remainder, so the new state
    does not depend on how the floes are cut into chunks; only the sums are
    reassociated.

    With ``path`` (the serial step), each floe's path grows by a bound on
    the length of its drift, |v| Δt and the rounding of the new position
    (:func:`path_slack`), in a rigid box (a deforming one remaps the floes
    by more than they drift)."""
    omega, torque = floes.omega, floes.torque
    inv_mass, inv_inertia = floes.inv_mass, floes.inv_inertia
    sx, sy = kick.sx, kick.sy
    n = inv_mass.shape[0]
    if sx != 1.0 or sy != 1.0:
        for i in range(n):
            ref[i, 0] *= sx
            ref[i, 1] *= sy
    p = floes.pos.reshape(-1)
    v = floes.vel.reshape(-1)
    f = floes.force.reshape(-1)
    r = ref.reshape(-1)
    k = drive.coefficients.reshape(-1)
    vmax2 = np.uint64(0)
    worst = np.uint64(0)
    sdx = 0.0
    sdy = 0.0
    step_length, slack = drift_bound(kick)
    for i in range(n):
        v2, e2, dx, dy = kick_drift_floe(i, p, v, f, omega, torque, inv_mass, inv_inertia, r, k,
                                         drive, kick)
        if path is not None:
            path[i] += math.sqrt(v2) * step_length + slack
        key = order_key(v2)
        vmax2 = key if key > vmax2 else vmax2
        key = order_key(e2)
        worst = key if key > worst else worst
        sdx += dx
        sdy += dy
    return from_order_key(worst), sdx, sdy, from_order_key(vmax2)


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
    """Floes lo..hi−1 of ``floes`` (views) with their rows of the shared
    force buffer (buffer 0 of ``buffers``) as their forces."""
    f = floes
    return Floes(f.pos[lo:hi], f.vel[lo:hi], f.omega[lo:hi], f.radius[lo:hi], f.inv_mass[lo:hi],
                 f.inv_inertia[lo:hi], f.rank[lo:hi], buffers.force[0, lo:hi],
                 buffers.torque[0, lo:hi], f.wall_hist[lo:hi])


@njit(cache=True, inline="always", error_model="numpy")
def drive_rows(drive, lo, hi):
    """``drive`` with the coefficients of floes lo..hi−1 only (a view)."""
    d = drive
    return Drive(d.coefficients[lo:hi], d.wind_x, d.wind_y, d.current_x, d.current_y,
                 d.wind_speed, d.active)


@njit(cache=True, error_model="numpy")
def kick_task(k, n_tasks, floes, buffers, shared, ref, drive, kick, part):
    """Part k of a parallel kick–drift pass (:func:`first_half_parallel`, a
    task of :func:`team_member`): :func:`gather_buffers` and
    :func:`first_half` over the k-th of ``n_tasks`` equal runs of floes,
    its results in part[k]."""
    n = floes.pos.shape[0]
    lo = k * n // n_tasks
    hi = (k + 1) * n // n_tasks
    gather_buffers(lo, hi, buffers, shared)
    w, sx_, sy_, v2 = first_half(floe_rows(floes, lo, hi, buffers), ref[lo:hi],
                                 drive_rows(drive, lo, hi), kick)
    part[k, 0] = w
    part[k, 1] = sx_
    part[k, 2] = sy_
    part[k, 3] = v2


@njit(cache=False, parallel=True, error_model="numpy")
def first_half_parallel(n_tasks, floes, buffers, shared, ref, drive, kick):
    """:func:`first_half` over all floes in parallel (no race), kicking
    with the shared force buffer (buffer 0 of ``buffers``; ``floes.force``
    is not used), each thread first adding up its floes' private pair-force
    buffers (:func:`gather_buffers`). ``shared`` lists the floes that can
    have private entries (:func:`scatter_floes`); ``ref`` are the positions
    at the list build.

    The floes are cut into ``n_tasks`` consecutive runs (a few per
    thread, :data:`KICK_TASKS_PER_THREAD`); the runtime gives each thread
    the same consecutive block of runs every step, so each core keeps its
    floes in its own caches. The chunks of the pair loop
    (:func:`owner_chunks`) hold equal numbers of pairs; when the floes are
    numbered in space (:func:`physics.floes.spatial_order`, as
    :func:`physics.floes.make_floe_field` does) both splits cut the box into
    about the same patches, and a thread mostly reads and writes its own
    floes in both loops. Each task writes only its own floes and its own
    row of the partial results, which are reduced in task order: the new
    state of every floe is the same bit for bit for any number of threads
    and tasks (and equal to the serial pass), the sums of the displacements
    equal to rounding, and the outcome for a given number of tasks is
    repeatable whatever thread did which task.

    Each run gets views of its floes (:func:`kick_task`) and loops from a
    start index known at compile time to be 0: with a start known only at
    run time the compiler cannot rule out negative indices, and the loop
    does not vectorise (2.5 times as slow)."""
    part = np.empty((n_tasks, 4))
    for t in prange(n_tasks):
        kick_task(t, n_tasks, floes, buffers, shared, ref, drive, kick, part)
    return combine_chunks(part)


@njit(cache=True, inline="always", error_model="numpy")
def pass_status(worst, mx, my, vmax2, dt, skin):
    """Status after a kick–drift pass with results (worst, mx, my, vmax2)
    (:func:`first_half`): non-finite state, or a floe that crossed half the
    skin in one step (the dynamics blew up), or OK."""
    if not math.isfinite(worst + mx + my + vmax2):
        return _NON_FINITE
    if vmax2 * dt * dt > 0.25 * skin * skin:
        return _UNSTABLE
    return _OK


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


@njit(cache=True, error_model="numpy")
def ship_after_kick(ship, floes, box, verlet, time, dt, vmax2, lx, ly, cx, cy, mx, my, worst,
                    buffers):
    """What a step does between the floes' kick–drift pass and the expiry
    test of their list when there is a ship or a floe with a wider skin:
    the hull's contacts (:func:`~physics.hull_contact.hull_forces` at
    ``time``, the time after the step, with the pass's largest squared
    speed ``vmax2``; its forces added to buffer 0 of ``buffers``), then
    the pass over the wide-skinned floes (:func:`wide_floes_pass`, with the
    old centre (cx, cy) and the pass's sums of the displacements (mx, my)).
    Returns (the new largest squared displacement, whether the ship's
    collision log is full)."""
    log_full = False
    if ship.active:
        log_full = not hull_forces(ship, floes, box, time, dt, math.sqrt(vmax2), buffers.force[0],
                                   buffers.torque[0])
    if verlet.wide.shape[0] > 0:
        n = floes.pos.shape[0]
        worst = wide_floes_pass(floes.pos, verlet, lx, ly, box.periodic_x, box.periodic_y, cx, cy,
                                mx / n, my / n, worst)
    return worst, log_full


# A named tuple inside a named tuple (the ship's contact law in its bundle)
# cannot be an argument of a prange body (numba 0.68 raises "scalar type ...
# given for non scalar argument"): team_steps takes the ship's bundle as the
# fields before its law, the law and the fields after it, and each thread
# puts it together again. (The slices must be written as literals: 15 = this.)
SHIP_LAW_FIELD = ShipBundle._fields.index("law")
assert SHIP_LAW_FIELD == 15, "change the slices of the ship's bundle in run_steps"


@njit(cache=True, error_model="numpy")
def team_member(t, team, n_steps, step0, dt, time, lx0, ly0, floes, law, drive, box, verlet,
                chunks, buffers, ship_head, ship_law, ship_tail):
    """Thread t's part of :func:`team_steps`: up to ``n_steps`` steps of a
    periodic box, each a kick–drift phase of ``team.n_kick`` tasks and a
    pair phase of ``team.n_threads`` tasks (the chunks of
    :func:`owner_chunks`, each with its private force buffer), with a
    ``sync`` array each (:mod:`physics.thread_team`).

    With a ship (or floes with a wider skin, :func:`wide_floes_pass`) a
    phase of one task lies between them: :func:`ship_after_kick`, done by
    whichever thread claims it, while the others wait, since it adds the
    hull's forces to the shared force buffer that the pair tasks write
    too. Its results go to ``team.ship_out``. The ship's kick–drift is
    done by the thread that claims kick task 0 (it reads and writes only
    the ship's state, which no other task of the phase touches).

    Every thread makes the same decisions (stop, rebuild) from the same
    partial results ``team.part`` of the kick pass (and ``team.ship_out``).
    The thread that takes the token writes (steps done, status, reason,
    centre x, centre y, log full) to ``team.out``."""
    n_threads, n_kick = team.n_threads, team.n_kick
    sync_kick, sync_pair, part, out = team.sync_kick, team.sync_pair, team.part, team.out
    sync_ship, ship_out = team.sync_ship, team.ship_out
    ship = ShipBundle(*ship_head, ship_law, *ship_tail)
    ship_phase = ship.active or verlet.wide.shape[0] > 0
    n = floes.pos.shape[0]
    px = box.periodic_x
    py = box.periodic_y
    deform = box.deforming
    lx_old, ly_old = lx0, ly0
    cx = verlet.centre[0]
    cy = verlet.centre[1]
    status = _OK
    reason = TEAM_ALL_DONE
    log_full = False
    done = 0
    gk = 0                                  # generation of the kick phase,
    gp = 0                                  # of the pair phase
    gs = 0                                  # and of the ship's phase
    for s in range(n_steps):
        if deform:
            lx, ly, conc = box_lengths_at(box, time + (step0 + s + 1) * dt)
            if conc >= box.max_concentration or conc <= 0.0:
                status = _CONCENTRATION_LIMIT
                break
        else:
            lx, ly = lx_old, ly_old
        dt_kick = 0.5 * dt if step0 + s == 0 else dt
        kick = Kick(dt_kick, dt, lx, ly, px, py, lx / lx_old, ly / ly_old, cx, cy)
        gk += 1
        for m in range(n_kick):
            k = task_order(t, m, n_threads, n_kick)     # its own tasks first
            if claim(sync_kick, k, gk):
                if k == 0:
                    # only the ship's and the pair phase read the box lengths
                    box.lengths[0] = lx
                    box.lengths[1] = ly
                    if ship.active:
                        ship_kick_drift(ship, dt_kick, dt)
                kick_task(k, n_kick, floes, buffers, chunks.shared, verlet.ref, drive, kick, part)
                task_done(sync_kick, n_kick)
        wait_generation(sync_kick, n_kick, gk)
        worst, mx, my, vmax2 = combine_chunks(part)
        if overtaken(sync_kick, n_kick, gk):
            return                          # left behind: the others finish the run
        done += 1
        status = pass_status(worst, mx, my, vmax2, dt, verlet.skin)
        if status != _OK:
            break
        if ship_phase:
            gs += 1
            if claim(sync_ship, 0, gs):
                w, full = ship_after_kick(ship, floes, box, verlet, time + (step0 + s + 1) * dt,
                                          dt, vmax2, lx, ly, cx, cy, mx, my, worst, buffers)
                ship_out[0] = w
                ship_out[1] = 1.0 if full else 0.0
                task_done(sync_ship, 1)
            wait_generation(sync_ship, 1, gs)
            worst = ship_out[0]
            log_full = ship_out[1] != 0.0
            if overtaken(sync_ship, 1, gs):
                return                      # ship_out may be the next step's
        cx = mx / n
        cy = my / n
        if list_expired(worst, lx, ly, verlet):
            reason = TEAM_REBUILD
            break
        gp += 1
        for m in range(n_threads):
            k = task_order(t, m, n_threads, n_threads)
            if claim(sync_pair, k, gp):
                pair_task(k, chunks, floes, law, box, verlet, dt, buffers)
                task_done(sync_pair, n_threads)
        wait_generation(sync_pair, n_threads, gp)
        if log_full:
            # the step is finished; the caller empties the log
            status = _SHIP_LOG_FULL
            break
        lx_old, ly_old = lx, ly
    if take_token(sync_pair, n_threads):
        out[0] = done
        out[1] = status
        out[2] = reason
        out[3] = cx
        out[4] = cy
        out[5] = 1.0 if log_full else 0.0


@njit(cache=False, parallel=True, error_model="numpy")
def team_steps(team, n_steps, step0, dt, time, lx0, ly0, floes, law, drive, box, verlet, chunks,
               buffers, ship_head, ship_law, ship_tail):
    """Steps of a periodic box by a team of threads that stays in one
    parallel region (:func:`team_member`; :mod:`physics.thread_team`) until
    the run ends, the Verlet list must be rebuilt or the ship's collision
    log is full. Same arithmetic, in the same order, as the step of
    :func:`run_steps` with :func:`first_half_parallel` and
    :func:`pair_forces_parallel` (and the ship's step): the new state is
    the same bit for bit. (lx0, ly0) are the box lengths before the first
    step (the team writes the new ones into ``box.lengths``). The ship's
    bundle comes in three parts (:data:`SHIP_LAW_FIELD`)."""
    for t in prange(team.n_threads):
        team_member(t, team, n_steps, step0, dt, time, lx0, ly0, floes, law, drive, box, verlet,
                    chunks, buffers, ship_head, ship_law, ship_tail)


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
    ref, wide, wide_ref, weight = verlet.ref, verlet.wide, verlet.wide_ref, verlet.wide_weight
    for k in range(wide.shape[0]):
        i = wide[k]
        x = pos[i, 0]
        y = pos[i, 1]
        ex = min_image_step(x - wide_ref[k, 0], lx, px) - cx
        ey = min_image_step(y - wide_ref[k, 1], ly, py) - cy
        e2 = (ex * ex + ey * ey) * weight[k]
        worst = max_keep_nan(worst, e2)
        ref[i, 0] = x - cx_new
        ref[i, 1] = y - cy_new
    return worst


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
        return _CONCENTRATION_LIMIT, kick
    lengths[0] = lx
    lengths[1] = ly
    if ship.active:
        ship_kick_drift(ship, dt_kick, dt)
    return _OK, kick


@njit(cache=True, error_model="numpy")
def rebuild_in_run(floes, verlet, lx, ly, px, py, parallel, ship, deforming, dt):
    """The list rebuild of a run (:func:`rebuild`): with a ship in a rigid
    box, with the floes' skins of :func:`physics.hull_contact.ship_floe_skins`."""
    if ship.active and not deforming:
        return rebuild(floes, verlet, lx, ly, px, py, parallel,
                       ship_floe_skins(ship, floes, verlet.skin, dt, lx, ly, px, py))
    return rebuild(floes, verlet, lx, ly, px, py, parallel)


@njit(cache=True, error_model="numpy")
def run_steps(n_steps, dt, time, floes, law, wall_law, drive, box, verlet, parallel, n_pair,
              ship, with_team=True):
    """Advance the floes by ``n_steps`` velocity-Verlet steps.

    Between two steps of one call the second half kick of a step and the
    first half kick of the next are done together (leapfrog form); the state
    returned is synchronised (velocities at full steps) and
    ``floes.force``, ``floes.torque`` hold the forces of the last step.
    ``box.lengths`` is updated in place for a deforming box; the Verlet
    list is rebuilt whenever the displacement criterion of
    :mod:`physics.neighbors` could be violated.

    ``n_pair`` is the number of chunks of the pair loop of the parallel
    path (the number of threads; 1 for the serial path), each with a
    private force buffer; its kick–drift pass has
    :data:`KICK_TASKS_PER_THREAD` tasks per chunk.

    ``ship`` is a :class:`~physics.hull_contact.ShipBundle` (inactive
    without a ship). With a ship every step also moves the ship before the
    floes' kick–drift pass and adds the hull contacts after it
    (:mod:`physics.hull_contact`).

    ``with_team``: whether the parallel step of a periodic box runs as a
    thread team (:func:`team_steps`); with False it runs one parallel
    region per phase and step, as in a box with walls (the same new state
    bit for bit; for comparisons).

    Returns (steps done, status (a :class:`HertzStatus` value), number of
    list rebuilds, the Verlet list now). A status other than OK stops the
    run early: non-finite state, a blow-up, a deforming box at its
    concentration limit, or a full collision log of the ship.
    """
    px = box.periodic_x
    py = box.periodic_y
    walls = not (px and py)
    lengths = box.lengths
    n = floes.pos.shape[0]
    n_pair = n_pair if parallel else 1
    n_kick = n_pair * KICK_TASKS_PER_THREAD if parallel else 1
    buffers = force_buffers(n_pair, n)
    buffers.force[0] = floes.force
    buffers.torque[0] = floes.torque
    # the serial kick–drift pass kicks with buffer 0
    work = floe_rows(floes, 0, n, buffers)
    n_rebuilds = 0
    chunks = pair_chunks(verlet, n_pair)
    # the serial step skips the looks at pairs and walls that cannot touch
    # (the paths of owner_pairs, wall_forces); the parallel one looks at all
    path = np.zeros(n)
    due = np.full(verlet.nbr.shape[0], -np.inf)
    wall_due = np.full(n, -np.inf)
    skip = not (parallel or box.deforming)
    done = 0
    status = _OK
    # parallel path in a periodic box: a team of threads that stays in one
    # parallel region between list rebuilds; the serial path and boxes with
    # walls kick one step at a time. Both end a step whose list expired with
    # the same rebuild and pair loop.
    use_team = parallel and not walls and with_team
    log_full = False
    team = Team(n_pair, n_kick, np.zeros(sync_size(n_kick), dtype=np.int64),
                np.zeros(sync_size(n_pair), dtype=np.int64), np.zeros(sync_size(1), dtype=np.int64),
                np.empty((n_kick, 4)), np.empty(2), np.empty(6))
    step = 0
    while step < n_steps:
        if use_team:
            team.sync_kick[:] = 0
            team.sync_pair[:] = 0
            team.sync_ship[:] = 0
            team_steps(team, n_steps - step, step, dt, time, lengths[0], lengths[1], floes, law,
                       drive, box, verlet, chunks, buffers, ship[:15], ship.law, ship[16:])
            out = team.out
            k = int(out[0])
            status = int(out[1])
            verlet.centre[0] = out[3]
            verlet.centre[1] = out[4]
            log_full = out[5] != 0.0
            done += k
            step += k
            if status != _OK or int(out[2]) != TEAM_REBUILD:
                break
            # the team stopped after the kick (and the ship's phase) of a
            # step whose list expired: rebuild and finish that step below
            lx, ly = lengths[0], lengths[1]
            expired = True
        else:
            status, kick = begin_step(box, time, step, dt, verlet.centre, ship)
            if status != _OK:
                break
            lx, ly = kick.lx, kick.ly
            if parallel:
                worst, mx, my, vmax2 = first_half_parallel(n_kick, floes, buffers, chunks.shared,
                                                           verlet.ref, drive, kick)
            else:
                worst, mx, my, vmax2 = first_half(work, verlet.ref, drive, kick, path)
            done += 1
            step += 1
            status = pass_status(worst, mx, my, vmax2, dt, verlet.skin)
            if status != _OK:
                break
            if walls:
                if parallel:
                    wall_forces_parallel(floes, wall_law, box, dt, buffers.force[0],
                                         buffers.torque[0])
                elif skip:
                    wall_forces(0, n, floes, wall_law, box, dt, buffers.force[0],
                                buffers.torque[0], path, wall_due)
                else:
                    wall_forces(0, n, floes, wall_law, box, dt, buffers.force[0],
                                buffers.torque[0])
            if ship.active or verlet.wide.shape[0] > 0:
                worst, log_full = ship_after_kick(ship, floes, box, verlet, time + step * dt, dt,
                                                  vmax2, lx, ly, kick.cx, kick.cy, mx, my, worst,
                                                  buffers)
            verlet.centre[0] = mx / n
            verlet.centre[1] = my / n
            expired = list_expired(worst, lx, ly, verlet)
        if expired:
            verlet = rebuild_in_run(floes, verlet, lx, ly, px, py, parallel, ship, box.deforming,
                                    dt)
            chunks = pair_chunks(verlet, n_pair)
            due = np.full(verlet.nbr.shape[0], -np.inf)
            n_rebuilds += 1
        # drag and wall forces are already in buffer 0; add the pair forces
        if parallel:
            pair_forces_parallel(chunks, floes, law, box, verlet, dt, buffers)
        elif skip:
            owners = chunks.owners
            owner_pairs(0, owners.shape[0], owners, floes, law, box, verlet, dt,
                        buffers.force[0], buffers.torque[0], 0, n, buffers.force[0],
                        buffers.torque[0], path, due)
        else:
            owners = chunks.owners
            owner_pairs(0, owners.shape[0], owners, floes, law, box, verlet, dt,
                        buffers.force[0], buffers.torque[0], 0, n, buffers.force[0],
                        buffers.torque[0])
        if log_full:
            status = _SHIP_LOG_FULL
            break
    # total force of the last step, and the closing half kick
    floes.force[:] = buffers.force.sum(axis=0)
    floes.torque[:] = buffers.torque.sum(axis=0)
    if done > 0:
        half_kick(floes, dt)
        if ship.active:
            ship_closing_kick(ship, dt)
    return done, status, n_rebuilds, verlet


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
