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
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange, types
from numba.extending import intrinsic

from .contact import hertz_mindlin_force
from .domain import BOX_DEFORM, BOX_LX, BOX_LY, BOX_PX, BOX_PY, box_lengths_at, minimum_image
from .neighbors import build_pair_list, build_pair_list_serial, transfer_history
from .thread_team import (claim, overtaken, sync_size, take_token, task_done, task_order,
                          wait_generation)

# contact parameter vector layout
CP_KN, CP_KT, CP_ALPHA, CP_GT, CP_MU, CP_LIMIT, CP_KN_WALL, CP_KT_WALL, CP_TT = range(9)
CP_SIZE = 9
# forcing vector layout: wind (x, y), current (x, y)
FV_UAX, FV_UAY, FV_UWX, FV_UWY = range(4)
# status codes of run_steps
STATUS_OK, STATUS_NONFINITE, STATUS_CONCENTRATION, STATUS_UNSTABLE = 0, 1, 2, 3
# why a team run (team_steps) returned early: the Verlet list must be rebuilt
TEAM_ALL_DONE, TEAM_REBUILD = 0, 1
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
def pair_contact(dx, dy, ri, rj, vrx, vry, wi, wj, inv_mass_sum, spring, a_last, dt_history,
                 kn, kt, alpha, gamma_t, mu, limit_damping, tt):
    """Force of floe j on floe i, given their minimum-image separation
    (dx, dy) = x_j − x_i and relative velocity (vrx, vry) = u_i − u_j.

    Returns (touching, fx, fy, torque_i, torque_j, spring, a_last, f_normal,
    f_tangential, nx, ny, delta): (fx, fy) acts on i and −(fx, fy) on j;
    n = (nx, ny) is the unit vector from i to j; (spring, a_last) is the
    updated Mindlin history. A pair that does not touch, or of two frozen
    floes, returns zeros (and a reset history).
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
                                                 kn, kt, alpha, gamma_t, mu, limit_damping)
    fx = -fn * nx - tt * ft * ny
    fy = -fn * ny + tt * ft * nx
    return (True, fx, fy, ft * (ri - 0.5 * delta), ft * (rj - 0.5 * delta), spring, a_last,
            fn, ft, nx, ny, delta)


@njit(cache=True, inline="always", error_model="numpy")
def wall_contact(side, x, y, vx, vy, w, r, inv_mass, lx, ly, spring, a_last, dt_history,
                 kn, kt, alpha, gamma_t, mu, limit_damping, tt):
    """Force of a rigid wall on a floe; ``side`` 0..3 = wall at x=0, x=lx,
    y=0, y=ly. Returns (fx, fy, torque, spring, a_last)."""
    if side == 0:
        delta, nx, ny = r - x, -1.0, 0.0
    elif side == 1:
        delta, nx, ny = r - (lx - x), 1.0, 0.0
    elif side == 2:
        delta, nx, ny = r - y, 0.0, -1.0
    else:
        delta, nx, ny = r - (ly - y), 0.0, 1.0
    if delta <= 0.0 or inv_mass == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    v_normal = vx * nx + vy * ny
    v_slip = -vx * ny + vy * nx + r * w
    fn, ft, spring, a_last = hertz_mindlin_force(delta, r, 1.0 / inv_mass, v_normal, v_slip,
                                                 spring, a_last, dt_history, kn, kt, alpha,
                                                 gamma_t, mu, limit_damping)
    return -fn * nx - tt * ft * ny, -fn * ny + tt * ft * nx, ft * (r - delta), spring, a_last


@njit(cache=True, inline="always", error_model="numpy")
def floe_drag(vx, vy, w, a, b, c, g, uax, uay, uwx, uwy, wind_speed):
    """Eq 6–7 forcing of one floe: wind a|u_a|u_a, water b(u_w − u),
    Coriolis −g k×u (g = m f) and rotational drag −c ω. Returns (fx, fy, torque)."""
    fx = a * wind_speed * uax + b * (uwx - vx) + g * vy
    fy = a * wind_speed * uay + b * (uwy - vy) - g * vx
    return fx, fy, -c * w


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

@njit(cache=True, error_model="numpy")
def wall_forces(i_lo, i_hi, pos, vel, omega, radius, inv_mass, cp, box, wall_hist, dt_history,
                force, torque):
    """Add the forces of the rigid walls of non-periodic sides to floes
    i_lo..i_hi−1."""
    lx, ly = box[BOX_LX], box[BOX_LY]
    walls_x = box[BOX_PX] == 0.0
    walls_y = box[BOX_PY] == 0.0
    kn, kt, alpha, gt, mu = cp[CP_KN_WALL], cp[CP_KT_WALL], cp[CP_ALPHA], cp[CP_GT], cp[CP_MU]
    limit = cp[CP_LIMIT] != 0.0
    tt = cp[CP_TT]
    for i in range(i_lo, i_hi):
        for side in range(4):
            if (side < 2 and not walls_x) or (side >= 2 and not walls_y):
                continue
            wfx, wfy, wtq, sp, al = wall_contact(side, pos[i, 0], pos[i, 1], vel[i, 0],
                                                 vel[i, 1], omega[i], radius[i], inv_mass[i],
                                                 lx, ly, wall_hist[i, side, 0],
                                                 wall_hist[i, side, 1], dt_history, kn, kt,
                                                 alpha, gt, mu, limit, tt)
            wall_hist[i, side, 0] = sp
            wall_hist[i, side, 1] = al
            force[i, 0] += wfx
            force[i, 1] += wfy
            torque[i] += wtq


@njit(cache=True, error_model="numpy")
def drag_forces(i_lo, i_hi, vel, omega, drag, fv, force, torque):
    """Assign the eq 6–7 forcing to floes i_lo..i_hi−1 (``drag`` rows:
    a, b, c, m f; all zero for frozen floes)."""
    uax, uay, uwx, uwy = fv[FV_UAX], fv[FV_UAY], fv[FV_UWX], fv[FV_UWY]
    wind_speed = math.sqrt(uax * uax + uay * uay)
    for i in range(i_lo, i_hi):
        fx, fy, tq = floe_drag(vel[i, 0], vel[i, 1], omega[i], drag[i, 0], drag[i, 1], drag[i, 2],
                               drag[i, 3], uax, uay, uwx, uwy, wind_speed)
        force[i, 0] = fx
        force[i, 1] = fy
        torque[i] = tq


@njit(cache=True, error_model="numpy")
def owner_pairs(k_lo, k_hi, owners, pos, vel, omega, radius, inv_mass, cp, box, start, nbr, hist,
                dt_history, force, torque, j_lo, j_hi, force_out, torque_out):
    """Forces of the pairs owned by floes owners[k_lo:k_hi], each added to
    both floes of its pair at once (a scatter into ``force``, ``torque``;
    for a partner j outside j_lo ≤ j < j_hi into ``force_out``,
    ``torque_out`` instead).

    Only floes that touch are written: in loose ice most listed pairs are
    apart, and a write of zero would still claim the cache line for this
    thread, so that the thread doing the kick of that floe would have to
    fetch it back (see :func:`first_half_parallel`)."""
    lx, ly = box[BOX_LX], box[BOX_LY]
    px, py = box[BOX_PX] != 0.0, box[BOX_PY] != 0.0
    kn, kt, alpha, gt, mu = cp[CP_KN], cp[CP_KT], cp[CP_ALPHA], cp[CP_GT], cp[CP_MU]
    limit = cp[CP_LIMIT] != 0.0
    tt = cp[CP_TT]
    for k in range(k_lo, k_hi):
        i = owners[k]
        xi_, yi_ = pos[i, 0], pos[i, 1]
        vxi, vyi, wi, ri, imi = vel[i, 0], vel[i, 1], omega[i], radius[i], inv_mass[i]
        fxi = 0.0
        fyi = 0.0
        tqi = 0.0
        for p in range(start[i], start[i + 1]):
            j = nbr[p]
            res = pair_contact(minimum_image(pos[j, 0] - xi_, lx, px),
                               minimum_image(pos[j, 1] - yi_, ly, py), ri, radius[j],
                               vxi - vel[j, 0], vyi - vel[j, 1], wi, omega[j], imi + inv_mass[j],
                               hist[p, 0], hist[p, 1], dt_history, kn, kt, alpha, gt, mu, limit,
                               tt)
            hist[p, 0] = res[5]
            hist[p, 1] = res[6]
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
def forces_serial(pos, vel, omega, radius, inv_mass, drag, fv, cp, box, start, nbr, hist,
                  wall_hist, dt_history, force, torque):
    """All forces and torques at the current state (serial)."""
    n = radius.shape[0]
    drag_forces(0, n, vel, omega, drag, fv, force, torque)
    if box[BOX_PX] == 0.0 or box[BOX_PY] == 0.0:
        wall_forces(0, n, pos, vel, omega, radius, inv_mass, cp, box, wall_hist, dt_history,
                    force, torque)
    owners = np.nonzero(start[1:] > start[:-1])[0]
    owner_pairs(0, owners.shape[0], owners, pos, vel, omega, radius, inv_mass, cp, box, start, nbr,
                hist, dt_history, force, torque, 0, n, force, torque)


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
def pair_task(k, owners, bounds, pos, vel, omega, radius, inv_mass, cp, box, start, nbr, hist,
              dt_history, fbuf, tbuf):
    """Chunk k of the parallel pair loop (:func:`pair_forces_parallel`, a
    task of :func:`team_member`): :func:`owner_pairs` over the k-th run of
    owners of :func:`owner_chunks`, into the shared buffers fbuf[0],
    tbuf[0] for the floes of its :func:`chunk_range` and into its private
    buffers fbuf[k + 1], tbuf[k + 1] for the others (with one chunk,
    every floe is in its range)."""
    run = owners[bounds[k]:bounds[k + 1]]
    lo, hi = chunk_range(k, owners, bounds, pos.shape[0])
    b = min(k + 1, fbuf.shape[0] - 1)
    owner_pairs(0, run.shape[0], run, pos, vel, omega, radius, inv_mass, cp, box, start, nbr,
                hist, dt_history, fbuf[0], tbuf[0], lo, hi, fbuf[b], tbuf[b])


@njit(cache=True, error_model="numpy")
def force_buffers(n_chunks, n):
    """Zeroed force and torque buffers (fbuf (B, N, 2), tbuf (B, N)) for a
    pair loop in ``n_chunks`` chunks: the shared buffer 0, then a private
    buffer per chunk if there are two or more (:func:`pair_task`)."""
    n_buf = n_chunks + 1 if n_chunks > 1 else 1
    return np.zeros((n_buf, n, 2)), np.zeros((n_buf, n))


# Parallel kernels that other compiled kernels call are never cached on disk
# (cache=False): when a caller is compiled in a process that loaded such a
# callee from Numba's cache, the caller's own cache entry crashes every later
# process that loads it (seen with numba 0.68). Compiled in the same process
# as its caller, the callee is embedded in the caller's (cached) code.
@njit(cache=False, parallel=True, error_model="numpy")
def pair_forces_parallel(owners, bounds, pos, vel, omega, radius, inv_mass, cp, box, start, nbr,
                         hist, dt_history, fbuf, tbuf):
    """:func:`owner_pairs` over the chunks of :func:`owner_chunks` in
    parallel (:func:`pair_task`): race-free (see the module docstring)."""
    for c in prange(bounds.shape[0] - 1):
        pair_task(c, owners, bounds, pos, vel, omega, radius, inv_mass, cp, box, start, nbr, hist,
                  dt_history, fbuf, tbuf)


@njit(cache=False, parallel=True, error_model="numpy")
def wall_forces_parallel(pos, vel, omega, radius, inv_mass, cp, box, wall_hist, dt_history,
                         force, torque):
    """:func:`wall_forces` over all floes in parallel chunks (each floe only
    touches its own rows: no race)."""
    n = radius.shape[0]
    for c in prange(N_CHUNKS):
        wall_forces(c * n // N_CHUNKS, (c + 1) * n // N_CHUNKS, pos, vel, omega, radius,
                    inv_mass, cp, box, wall_hist, dt_history, force, torque)


@njit(cache=True, error_model="numpy")
def gather_buffers(i_lo, i_hi, fbuf, tbuf, shared):
    """Add the private force buffers b >= 1 of floes i_lo..i_hi-1 into
    buffer 0 and clear them. Only the floes listed in ``shared`` (sorted;
    :func:`scatter_floes`) can hold non-zero entries, and only non-zero
    entries are reset: a line left clean stays in the cache of the pair-loop
    thread that reads it next."""
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


@njit(cache=True, fastmath=KICK_FASTMATH, error_model="numpy")
def first_half(i_lo, i_hi, dt_kick, dt, pos, vel, omega, force, torque, inv_mass, inv_inertia,
               lx, ly, px, py, sx, sy, ref, cx, cy, drag, fv, has_drag):
    """Kick–drift of floes i_lo..i_hi−1 with their forces ``force``,
    ``torque``, their displacement since the list build, and their new drag
    forces.

    Kick by ``dt_kick`` with the last forces, drift by Δt, affine remap by
    (sx, sy) of a deforming box and periodic wrap; frozen floes (inverse
    mass 0) keep their state. Afterwards ``force``, ``torque`` hold the drag
    force (it needs only the new half-step velocities; done here to save a
    pass over memory; zero when ``has_drag`` is false, i.e. without
    forcing), ready for the pair loop to add to. ``ref`` (the positions at
    the build) is remapped with the box. Returns (largest squared distance
    of a displacement from (cx, cy), sum of the displacements along x, along
    y, largest squared speed); a NaN anywhere in the new positions or
    velocities makes the sums or the maxima NaN.

    The loop body has no branch and no call (selects for the frozen floes,
    the wrap and the minimum image; maxima over the bits of non-negative
    floats, :func:`order_key`), and the (N, k) arrays are read as flat
    arrays: so it vectorises (AVX2/AVX-512), about 2.7 times as fast as the
    scalar loop (34 against 94 µs for 20000 floes on one thread,
    ``python -m physics.bench phases``). Its per-floe arithmetic is the same in the vector body
    and in the scalar remainder, so the new state does not depend on how the
    floes are cut into chunks; only the sums are reassociated."""
    if sx != 1.0 or sy != 1.0:
        for i in range(i_lo, i_hi):
            ref[i, 0] *= sx
            ref[i, 1] *= sy
    uax, uay, uwx, uwy = fv[FV_UAX], fv[FV_UAY], fv[FV_UWX], fv[FV_UWY]
    wind_speed = math.sqrt(uax * uax + uay * uay)
    on = 1.0 if has_drag else 0.0
    p = pos.reshape(-1)
    v = vel.reshape(-1)
    f = force.reshape(-1)
    r = ref.reshape(-1)
    k = drag.reshape(-1)
    vmax2 = np.uint64(0)
    worst = np.uint64(0)
    sdx = 0.0
    sdy = 0.0
    for i in range(i_lo, i_hi):
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
        x = wrap_once((x0 + dt * vx) * sx, lx, px)
        y = wrap_once((y0 + dt * vy) * sy, ly, py)
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
        key = order_key(vx * vx + vy * vy if mobile else 0.0)
        vmax2 = key if key > vmax2 else vmax2
        # frozen floes have zero drag coefficients: their force is cleared
        fx, fy, tq = floe_drag(vx, vy, w, on * k[4 * i], on * k[4 * i + 1], on * k[4 * i + 2],
                               on * k[4 * i + 3], uax, uay, uwx, uwy, wind_speed)
        f[2 * i] = fx
        f[2 * i + 1] = fy
        torque[i] = tq
        dx = min_image_step(x - r[2 * i], lx, px)
        dy = min_image_step(y - r[2 * i + 1], ly, py)
        ex = dx - cx
        ey = dy - cy
        key = order_key(ex * ex + ey * ey)
        worst = key if key > worst else worst
        sdx += dx
        sdy += dy
    return from_order_key(worst), sdx, sdy, from_order_key(vmax2)


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


@njit(cache=True, error_model="numpy")
def kick_task(k, n_tasks, dt_kick, dt, pos, vel, omega, fbuf, tbuf, shared, inv_mass, inv_inertia,
              lx, ly, px, py, sx, sy, ref, cx, cy, drag, fv, has_drag, part):
    """Part k of a parallel kick–drift pass (:func:`first_half_parallel`, a
    task of :func:`team_member`): :func:`gather_buffers` and
    :func:`first_half` over the k-th of ``n_tasks`` equal runs of floes,
    its results in part[k]."""
    n = pos.shape[0]
    lo = k * n // n_tasks
    hi = (k + 1) * n // n_tasks
    gather_buffers(lo, hi, fbuf, tbuf, shared)
    w, sx_, sy_, v2 = first_half(0, hi - lo, dt_kick, dt, pos[lo:hi], vel[lo:hi], omega[lo:hi],
                                 fbuf[0, lo:hi], tbuf[0, lo:hi], inv_mass[lo:hi],
                                 inv_inertia[lo:hi], lx, ly, px, py, sx, sy, ref[lo:hi], cx, cy,
                                 drag[lo:hi], fv, has_drag)
    part[k, 0] = w
    part[k, 1] = sx_
    part[k, 2] = sy_
    part[k, 3] = v2


@njit(cache=False, parallel=True, error_model="numpy")
def first_half_parallel(n_tasks, dt_kick, dt, pos, vel, omega, fbuf, tbuf, shared, inv_mass,
                        inv_inertia, lx, ly, px, py, sx, sy, ref, cx, cy, drag, fv, has_drag):
    """:func:`first_half` over all floes in parallel (no race), each thread
    first adding up its floes' private pair-force buffers
    (:func:`gather_buffers`).

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
        kick_task(t, n_tasks, dt_kick, dt, pos, vel, omega, fbuf, tbuf, shared, inv_mass,
                  inv_inertia, lx, ly, px, py, sx, sy, ref, cx, cy, drag, fv, has_drag, part)
    return combine_chunks(part)


@njit(cache=True, inline="always", error_model="numpy")
def pass_status(worst, mx, my, vmax2, dt, skin):
    """Status after a kick–drift pass with results (worst, mx, my, vmax2)
    (:func:`first_half`): non-finite state, or a floe that crossed half the
    skin in one step (the dynamics blew up), or OK."""
    if not math.isfinite(worst + mx + my + vmax2):
        return STATUS_NONFINITE
    if vmax2 * dt * dt > 0.25 * skin * skin:
        return STATUS_UNSTABLE
    return STATUS_OK


@njit(cache=True, inline="always", error_model="numpy")
def list_expired(worst, lx, ly, ref_lengths, max_cut, skin):
    """Whether the Verlet list may miss a pair: twice the largest
    displacement since the build, plus what a shrinking box takes off the
    distances (up to the longest cut-off), reaches the skin."""
    shrink = max(0.0, 1.0 - min(lx / ref_lengths[0], ly / ref_lengths[1]))
    return 2.0 * math.sqrt(worst) + shrink * max_cut >= skin


@njit(cache=True, error_model="numpy")
def team_member(t, n_threads, n_kick, sync_kick, sync_pair, part, out, n_steps, step0, dt, time,
                lx0, ly0, pos, vel, omega, radius, inv_mass, inv_inertia, drag, fv, has_drag, cp,
                box, max_concentration, skin, max_cut, owners, bounds, shared, start, nbr, hist,
                ref, ref_lengths, cx, cy, fbuf, tbuf):
    """Thread t's part of :func:`team_steps`: up to ``n_steps`` steps of a
    periodic box, each a kick–drift phase of ``n_kick`` tasks and a pair
    phase of ``n_threads`` tasks (the chunks of :func:`owner_chunks`, each
    with its private force buffer), with a ``sync`` array each
    (:mod:`physics.thread_team`).

    Every thread makes the same decisions (stop, rebuild) from the same
    partial results ``part`` of the kick pass. The thread that takes the
    token writes (steps done, status, reason, centre x, centre y) to
    ``out``."""
    n = pos.shape[0]
    px = box[BOX_PX] != 0.0
    py = box[BOX_PY] != 0.0
    deform = box[BOX_DEFORM] != 0.0
    lx_old, ly_old = lx0, ly0
    status = STATUS_OK
    reason = TEAM_ALL_DONE
    done = 0
    gk = 0                                  # generation of the kick phase
    gp = 0                                  # and of the pair phase
    for s in range(n_steps):
        if deform:
            lx, ly, conc = box_lengths_at(box, time + (step0 + s + 1) * dt)
            if conc >= max_concentration or conc <= 0.0:
                status = STATUS_CONCENTRATION
                break
        else:
            lx, ly = lx_old, ly_old
        dt_kick = 0.5 * dt if step0 + s == 0 else dt
        gk += 1
        for m in range(n_kick):
            k = task_order(t, m, n_threads, n_kick)     # its own tasks first
            if claim(sync_kick, k, gk):
                if k == 0:
                    # only the pair phase reads the box lengths
                    box[BOX_LX] = lx
                    box[BOX_LY] = ly
                kick_task(k, n_kick, dt_kick, dt, pos, vel, omega, fbuf, tbuf, shared, inv_mass,
                          inv_inertia, lx, ly, px, py, lx / lx_old, ly / ly_old, ref, cx, cy,
                          drag, fv, has_drag, part)
                task_done(sync_kick, n_kick)
        wait_generation(sync_kick, n_kick, gk)
        worst, mx, my, vmax2 = combine_chunks(part)
        if overtaken(sync_kick, n_kick, gk):
            return                          # left behind: the others finish the run
        done += 1
        status = pass_status(worst, mx, my, vmax2, dt, skin)
        if status != STATUS_OK:
            break
        cx = mx / n
        cy = my / n
        if list_expired(worst, lx, ly, ref_lengths, max_cut, skin):
            reason = TEAM_REBUILD
            break
        gp += 1
        for m in range(n_threads):
            k = task_order(t, m, n_threads, n_threads)
            if claim(sync_pair, k, gp):
                pair_task(k, owners, bounds, pos, vel, omega, radius, inv_mass, cp, box, start,
                          nbr, hist, dt, fbuf, tbuf)
                task_done(sync_pair, n_threads)
        wait_generation(sync_pair, n_threads, gp)
        lx_old, ly_old = lx, ly
    if take_token(sync_pair, n_threads):
        out[0] = done
        out[1] = status
        out[2] = reason
        out[3] = cx
        out[4] = cy


@njit(cache=False, parallel=True, error_model="numpy")
def team_steps(n_threads, n_kick, sync_kick, sync_pair, part, out, n_steps, step0, dt, time, lx0,
               ly0, pos, vel, omega, radius, inv_mass, inv_inertia, drag, fv, has_drag, cp, box,
               max_concentration, skin, max_cut, owners, bounds, shared, start, nbr, hist, ref,
               ref_lengths, cx, cy, fbuf, tbuf):
    """Steps of a periodic box by a team of threads that stays in one
    parallel region (:func:`team_member`; :mod:`physics.thread_team`) until
    the run ends or the Verlet list must be rebuilt. Same arithmetic, in
    the same order, as the step of :func:`run_steps` with
    :func:`first_half_parallel` and :func:`pair_forces_parallel`: the new
    state is the same bit for bit."""
    for t in prange(n_threads):
        team_member(t, n_threads, n_kick, sync_kick, sync_pair, part, out, n_steps, step0, dt,
                    time, lx0, ly0, pos, vel, omega, radius, inv_mass, inv_inertia, drag, fv,
                    has_drag, cp, box, max_concentration, skin, max_cut, owners, bounds, shared,
                    start, nbr, hist, ref, ref_lengths, cx, cy, fbuf, tbuf)


@njit(cache=True, error_model="numpy")
def half_kick(vel, omega, force, torque, inv_mass, inv_inertia, dt):
    """v += Δt/2 F/m, ω += Δt/2 T/I (the last half kick of a run)."""
    h = 0.5 * dt
    for i in range(vel.shape[0]):
        vel[i, 0] += h * force[i, 0] * inv_mass[i]
        vel[i, 1] += h * force[i, 1] * inv_mass[i]
        omega[i] += h * torque[i] * inv_inertia[i]


@njit(cache=True, error_model="numpy")
def rebuild(pos, radius, rank, lx, ly, px, py, skin, cell_size, start, nbr, hist, parallel):
    """New Verlet list with the contact history carried over.

    Returns (start, nbr, hist, ref) where ``ref`` is a copy of the positions
    at the build.
    """
    if parallel:
        new_start, new_nbr = build_pair_list(pos, radius, rank, lx, ly, px, py, skin, cell_size,
                                             nbr.shape[0])
    else:
        new_start, new_nbr = build_pair_list_serial(pos, radius, rank, lx, ly, px, py, skin,
                                                    cell_size, nbr.shape[0])
    new_hist = transfer_history(start, nbr, hist, new_start, new_nbr, 2)
    return new_start, new_nbr, new_hist, pos.copy()


@njit(cache=True, error_model="numpy")
def run_steps(n_steps, dt, time, pos, vel, omega, force, torque, radius, rank, inv_mass,
              inv_inertia, drag, fv, cp, box, max_concentration,
              skin, cell_size, max_cut, start, nbr, hist, ref, ref_lengths, centre, wall_hist,
              parallel, n_pair):
    """Advance the floes by ``n_steps`` velocity-Verlet steps.

    Between two steps of one call the second half kick of a step and the
    first half kick of the next are done together (leapfrog form); the state
    returned is synchronised (velocities at full steps) and ``force``,
    ``torque`` hold the forces of the last step. ``box`` is updated in place
    for a deforming box; the Verlet list is rebuilt whenever the
    displacement criterion of :mod:`physics.neighbors` could be violated.

    ``n_pair`` is the number of chunks of the pair loop of the parallel
    path (the number of threads; 1 for the serial path), each with a
    private force buffer; its kick–drift pass has
    :data:`KICK_TASKS_PER_THREAD` tasks per chunk.

    Returns (steps done, status, n_rebuilds, start, nbr, hist, ref). A
    non-zero status stops the run early: non-finite state, a blow-up, or a
    deforming box at its concentration limit.
    """
    px = box[BOX_PX] != 0.0
    py = box[BOX_PY] != 0.0
    walls = not (px and py)
    n = pos.shape[0]
    has_drag = np.any(drag != 0.0)
    n_pair = n_pair if parallel else 1
    n_kick = n_pair * KICK_TASKS_PER_THREAD if parallel else 1
    fbuf, tbuf = force_buffers(n_pair, n)
    fbuf[0] = force
    tbuf[0] = torque
    n_rebuilds = 0
    owners, bounds = owner_chunks(start, n_pair)
    shared = scatter_floes(owners, bounds, start, nbr, n)
    done = 0
    status = STATUS_OK
    # parallel path in a periodic box: a team of threads that stays in one
    # parallel region between list rebuilds; the serial path and boxes with
    # walls kick one step at a time. Both end a step whose list expired with
    # the same rebuild and pair loop.
    team = parallel and not walls
    sync_kick = np.zeros(sync_size(n_kick), dtype=np.int64)
    sync_pair = np.zeros(sync_size(n_pair), dtype=np.int64)
    part = np.empty((n_kick, 4))
    out = np.empty(5)
    step = 0
    while step < n_steps:
        if team:
            sync_kick[:] = 0
            sync_pair[:] = 0
            team_steps(n_pair, n_kick, sync_kick, sync_pair, part, out, n_steps - step, step, dt,
                       time, box[BOX_LX], box[BOX_LY], pos, vel, omega, radius, inv_mass,
                       inv_inertia, drag, fv, has_drag, cp, box, max_concentration, skin, max_cut,
                       owners, bounds, shared, start, nbr, hist, ref, ref_lengths, centre[0],
                       centre[1], fbuf, tbuf)
            k = int(out[0])
            status = int(out[1])
            centre[0] = out[3]
            centre[1] = out[4]
            done += k
            step += k
            if status != STATUS_OK or int(out[2]) != TEAM_REBUILD:
                break
            # the team stopped after the kick of a step whose list expired:
            # rebuild and finish that step below
            lx, ly = box[BOX_LX], box[BOX_LY]
            expired = True
        else:
            lx_old, ly_old = box[BOX_LX], box[BOX_LY]
            lx, ly, conc = box_lengths_at(box, time + (step + 1) * dt)
            if box[BOX_DEFORM] != 0.0 and (conc >= max_concentration or conc <= 0.0):
                status = STATUS_CONCENTRATION
                break
            box[BOX_LX] = lx
            box[BOX_LY] = ly
            dt_kick = 0.5 * dt if step == 0 else dt
            if parallel:
                worst, mx, my, vmax2 = first_half_parallel(
                    n_kick, dt_kick, dt, pos, vel, omega, fbuf, tbuf, shared, inv_mass,
                    inv_inertia, lx, ly, px, py, lx / lx_old, ly / ly_old, ref, centre[0],
                    centre[1], drag, fv, has_drag)
            else:
                worst, mx, my, vmax2 = first_half(
                    0, n, dt_kick, dt, pos, vel, omega, fbuf[0], tbuf[0], inv_mass, inv_inertia,
                    lx, ly, px, py, lx / lx_old, ly / ly_old, ref, centre[0], centre[1], drag,
                    fv, has_drag)
            done += 1
            step += 1
            status = pass_status(worst, mx, my, vmax2, dt, skin)
            if status != STATUS_OK:
                break
            if walls:
                if parallel:
                    wall_forces_parallel(pos, vel, omega, radius, inv_mass, cp, box, wall_hist,
                                         dt, fbuf[0], tbuf[0])
                else:
                    wall_forces(0, n, pos, vel, omega, radius, inv_mass, cp, box, wall_hist, dt,
                                fbuf[0], tbuf[0])
            centre[0] = mx / n
            centre[1] = my / n
            expired = list_expired(worst, lx, ly, ref_lengths, max_cut, skin)
        if expired:
            start, nbr, hist, ref = rebuild(pos, radius, rank, lx, ly, px, py, skin, cell_size,
                                            start, nbr, hist, parallel)
            ref_lengths[0] = lx
            ref_lengths[1] = ly
            centre[0] = 0.0
            centre[1] = 0.0
            owners, bounds = owner_chunks(start, n_pair)
            shared = scatter_floes(owners, bounds, start, nbr, n)
            n_rebuilds += 1
        # drag and wall forces are already in buffer 0; add the pair forces
        if parallel:
            pair_forces_parallel(owners, bounds, pos, vel, omega, radius, inv_mass, cp, box,
                                 start, nbr, hist, dt, fbuf, tbuf)
        else:
            owner_pairs(0, owners.shape[0], owners, pos, vel, omega, radius, inv_mass, cp, box,
                        start, nbr, hist, dt, fbuf[0], tbuf[0], 0, n, fbuf[0], tbuf[0])
    # total force of the last step, and the closing half kick
    force[:] = fbuf.sum(axis=0)
    torque[:] = tbuf.sum(axis=0)
    if done > 0:
        half_kick(vel, omega, force, torque, inv_mass, inv_inertia, dt)
    return done, status, n_rebuilds, start, nbr, hist, ref


@njit(cache=True, error_model="numpy")
def contact_list(pos, vel, omega, radius, inv_mass, cp, box, start, nbr, hist):
    """All touching pairs at the current state, without changing the history.

    Returns arrays: i, j (int), and per contact (nx, ny, delta, f_normal,
    f_tangential, fx, fy, torque_i, torque_j) as a (K, 9) float array.
    """
    lx, ly = box[BOX_LX], box[BOX_LY]
    px, py = box[BOX_PX] != 0.0, box[BOX_PY] != 0.0
    kn, kt, alpha, gt, mu = cp[CP_KN], cp[CP_KT], cp[CP_ALPHA], cp[CP_GT], cp[CP_MU]
    limit = cp[CP_LIMIT] != 0.0
    tt = cp[CP_TT]
    n = radius.shape[0]
    m = nbr.shape[0]
    ii = np.empty(m, dtype=np.int64)
    jj = np.empty(m, dtype=np.int64)
    data = np.empty((m, 9))
    k = 0
    for i in range(n):
        for p in range(start[i], start[i + 1]):
            j = nbr[p]
            res = pair_contact(minimum_image(pos[j, 0] - pos[i, 0], lx, px),
                               minimum_image(pos[j, 1] - pos[i, 1], ly, py), radius[i], radius[j],
                               vel[i, 0] - vel[j, 0], vel[i, 1] - vel[j, 1], omega[i], omega[j],
                               inv_mass[i] + inv_mass[j], hist[p, 0], hist[p, 1], 0.0, kn, kt,
                               alpha, gt, mu, limit, tt)
            if res[0]:
                ii[k] = i
                jj[k] = j
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
