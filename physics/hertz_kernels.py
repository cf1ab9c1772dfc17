"""Compiled kernels of the Hertz engine: contact loops and the velocity-Verlet step.

Pointwise functions do the physics of one contact or one floe; thin loop
kernels run them over all pairs or floes, each in a serial and a parallel
(``prange``) form:

* serial pair loop: one pass over the Verlet list, the force of a pair is
  added to i and subtracted from j at once (a scatter);
* parallel pair loop: two passes, race-free. Pass 1 (prange over owners)
  writes each pair's force into that pair's own slot of a buffer; pass 2
  (prange over floes) gathers, for every floe, the slots it owns and the
  slots where it is the partner (the reverse incidence list). No thread ever
  writes a slot of another floe.

Step (LAMMPS ``fix nve/sphere`` order): half kick with F(t) → drift →
affine remap of a deforming box → Verlet-list check (and rebuild) →
forces at t + Δt with the half-step velocities → half kick.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .contact import hertz_mindlin_force
from .domain import BOX_DEFORM, BOX_LX, BOX_LY, BOX_PX, BOX_PY, box_lengths_at, minimum_image, wrap_coordinate
from .neighbors import build_pair_list, build_pair_list_serial, reverse_incidence, transfer_history

# contact parameter vector layout
CP_KN, CP_KT, CP_ALPHA, CP_GT, CP_MU, CP_LIMIT, CP_KN_WALL, CP_KT_WALL = range(8)
CP_SIZE = 8
# forcing vector layout: wind (x, y), current (x, y)
FV_UAX, FV_UAY, FV_UWX, FV_UWY = range(4)
# status codes of run_steps
STATUS_OK, STATUS_NONFINITE, STATUS_CONCENTRATION, STATUS_UNSTABLE = 0, 1, 2, 3
N_CHUNKS = 64   # chunks of the parallel per-floe reductions


# ---------------------------------------------------------------------------
# Pointwise physics (scalars in, scalars out: no array crosses a call, so no
# reference counting in the hot loops)
# ---------------------------------------------------------------------------

@njit(cache=True, inline="always", error_model="numpy")
def pair_contact(dx, dy, ri, rj, vrx, vry, wi, wj, inv_mass_sum, spring, a_last, dt_history,
                 kn, kt, alpha, gamma_t, mu, limit_damping):
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
    fx = -fn * nx - ft * ny
    fy = -fn * ny + ft * nx
    return (True, fx, fy, ft * (ri - 0.5 * delta), ft * (rj - 0.5 * delta), spring, a_last,
            fn, ft, nx, ny, delta)


@njit(cache=True, inline="always", error_model="numpy")
def wall_contact(side, x, y, vx, vy, w, r, inv_mass, lx, ly, spring, a_last, dt_history,
                 kn, kt, alpha, gamma_t, mu, limit_damping):
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
    return -fn * nx - ft * ny, -fn * ny + ft * nx, ft * (r - delta), spring, a_last


@njit(cache=True, inline="always", error_model="numpy")
def floe_drag(vx, vy, w, a, b, c, g, uax, uay, uwx, uwy, wind_speed):
    """Eq 6–7 forcing of one floe: wind a|u_a|u_a, water b(u_w − u),
    Coriolis −g k×u (g = m f) and rotational drag −c ω. Returns (fx, fy, torque)."""
    fx = a * wind_speed * uax + b * (uwx - vx) + g * vy
    fy = a * wind_speed * uay + b * (uwy - vy) - g * vx
    return fx, fy, -c * w


@njit(cache=True, inline="always", error_model="numpy")
def wrap_step(x, length, periodic):
    """Wrap a coordinate that moved by less than one box length in a step
    (two compares instead of a division); falls back to the general wrap."""
    if periodic:
        if x >= length:
            x -= length
        elif x < 0.0:
            x += length
        if x < 0.0 or x >= length:
            x = wrap_coordinate(x, length, True)
    return x


@njit(cache=True, inline="always", error_model="numpy")
def kick_drift(x, y, vx, vy, w, fx, fy, tq, inv_m, inv_i, dt_kick, dt, lx, ly, px, py, sx, sy):
    """Kick by ``dt_kick`` with the last forces, drift by Δt, affine remap by
    (sx, sy) and periodic wrap of one mobile floe. Returns (x, y, vx, vy, w)."""
    vx += dt_kick * fx * inv_m
    vy += dt_kick * fy * inv_m
    w += dt_kick * tq * inv_i
    x = wrap_step((x + dt * vx) * sx, lx, px)
    y = wrap_step((y + dt * vy) * sy, ly, py)
    return x, y, vx, vy, w


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
    for i in range(i_lo, i_hi):
        for side in range(4):
            if (side < 2 and not walls_x) or (side >= 2 and not walls_y):
                continue
            wfx, wfy, wtq, sp, al = wall_contact(side, pos[i, 0], pos[i, 1], vel[i, 0],
                                                 vel[i, 1], omega[i], radius[i], inv_mass[i],
                                                 lx, ly, wall_hist[i, side, 0],
                                                 wall_hist[i, side, 1], dt_history, kn, kt,
                                                 alpha, gt, mu, limit)
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
                dt_history, scatter, force, torque, pair_buf):
    """Forces of the pairs owned by floes owners[k_lo:k_hi].

    ``scatter`` (serial path): each force is added to both floes at once.
    Otherwise (parallel path) it is written into the pair's own slot of
    ``pair_buf`` (fx, fy, torque_i, torque_j) for :func:`gather`.
    """
    lx, ly = box[BOX_LX], box[BOX_LY]
    px, py = box[BOX_PX] != 0.0, box[BOX_PY] != 0.0
    kn, kt, alpha, gt, mu = cp[CP_KN], cp[CP_KT], cp[CP_ALPHA], cp[CP_GT], cp[CP_MU]
    limit = cp[CP_LIMIT] != 0.0
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
                               hist[p, 0], hist[p, 1], dt_history, kn, kt, alpha, gt, mu, limit)
            hist[p, 0] = res[5]
            hist[p, 1] = res[6]
            if not scatter:
                pair_buf[p, 0] = res[1]
                pair_buf[p, 1] = res[2]
                pair_buf[p, 2] = res[3]
                pair_buf[p, 3] = res[4]
            elif res[0]:
                fxi += res[1]
                fyi += res[2]
                tqi += res[3]
                force[j, 0] -= res[1]
                force[j, 1] -= res[2]
                torque[j] += res[4]
        if scatter:
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
                hist, dt_history, True, force, torque, force)


@njit(cache=True, error_model="numpy")
def gather(k_lo, k_hi, active, start, rev_start, rev_pair, pair_buf, force, torque):
    """Add to floes active[k_lo:k_hi] the pair forces of the slots they own
    (+) and of the slots where they are the partner (−, and their own torque)."""
    for k in range(k_lo, k_hi):
        i = active[k]
        fx = force[i, 0]
        fy = force[i, 1]
        tq = torque[i]
        for p in range(start[i], start[i + 1]):
            fx += pair_buf[p, 0]
            fy += pair_buf[p, 1]
            tq += pair_buf[p, 2]
        for q in range(rev_start[i], rev_start[i + 1]):
            p = rev_pair[q]
            fx -= pair_buf[p, 0]
            fy -= pair_buf[p, 1]
            tq += pair_buf[p, 3]
        force[i, 0] = fx
        force[i, 1] = fy
        torque[i] = tq


@njit(cache=True, parallel=True, error_model="numpy")
def contact_forces_parallel(pos, vel, omega, radius, inv_mass, cp, box, start, nbr, hist,
                            wall_hist, dt_history, force, torque, pair_buf, rev_start, rev_pair,
                            owners, active):
    """Add pair and wall forces, race-free in parallel: per-pair slots, then a
    per-floe gather (see the module docstring). Only floes with list entries
    take part (``owners``: own a pair; ``active``: own or partner one); work
    is split in chunks of them."""
    n = radius.shape[0]
    m = active.shape[0]
    mo = owners.shape[0]
    for c in prange(N_CHUNKS):
        owner_pairs(c * mo // N_CHUNKS, (c + 1) * mo // N_CHUNKS, owners, pos, vel, omega, radius,
                    inv_mass, cp, box, start, nbr, hist, dt_history, False, force, torque,
                    pair_buf)
    if box[BOX_PX] == 0.0 or box[BOX_PY] == 0.0:
        for c in prange(N_CHUNKS):
            wall_forces(c * n // N_CHUNKS, (c + 1) * n // N_CHUNKS, pos, vel, omega, radius,
                        inv_mass, cp, box, wall_hist, dt_history, force, torque)
    for c in prange(N_CHUNKS):
        gather(c * m // N_CHUNKS, (c + 1) * m // N_CHUNKS, active, start, rev_start, rev_pair,
               pair_buf, force, torque)


@njit(cache=True, error_model="numpy")
def first_half(i_lo, i_hi, dt_kick, dt, pos, vel, omega, force, torque, inv_mass, inv_inertia,
               lx, ly, px, py, sx, sy, ref, cx, cy, drag, fv):
    """Kick–drift of floes i_lo..i_hi−1, their displacement since the list
    build, and their new drag forces (which need only the new half-step
    velocities; done here to save a pass over memory). ``ref`` (the
    positions at the build) is remapped with the box. Returns (largest
    squared distance of a displacement from (cx, cy), sum of the
    displacements along x, along y, largest squared speed)."""
    uax, uay, uwx, uwy = fv[FV_UAX], fv[FV_UAY], fv[FV_UWX], fv[FV_UWY]
    wind_speed = math.sqrt(uax * uax + uay * uay)
    vmax2 = 0.0
    worst = 0.0
    sdx = 0.0
    sdy = 0.0
    remap = sx != 1.0 or sy != 1.0
    for i in range(i_lo, i_hi):
        im = inv_mass[i]
        x = pos[i, 0]
        y = pos[i, 1]
        if im != 0.0:
            x, y, vx, vy, w = kick_drift(x, y, vel[i, 0], vel[i, 1], omega[i], force[i, 0],
                                         force[i, 1], torque[i], im, inv_inertia[i], dt_kick, dt,
                                         lx, ly, px, py, sx, sy)
            pos[i, 0] = x
            pos[i, 1] = y
            vel[i, 0] = vx
            vel[i, 1] = vy
            omega[i] = w
            vmax2 = max(vmax2, vx * vx + vy * vy)
            fx, fy, tq = floe_drag(vx, vy, w, drag[i, 0], drag[i, 1], drag[i, 2], drag[i, 3],
                                   uax, uay, uwx, uwy, wind_speed)
            force[i, 0] = fx
            force[i, 1] = fy
            torque[i] = tq
        if remap:
            ref[i, 0] *= sx
            ref[i, 1] *= sy
        dx = min_image_step(x - ref[i, 0], lx, px)
        dy = min_image_step(y - ref[i, 1], ly, py)
        ex = dx - cx
        ey = dy - cy
        worst = max(worst, ex * ex + ey * ey)
        sdx += dx
        sdy += dy
    return worst, sdx, sdy, vmax2


@njit(cache=True, parallel=True, error_model="numpy")
def first_half_parallel(dt_kick, dt, pos, vel, omega, force, torque, inv_mass, inv_inertia, lx, ly,
                        px, py, sx, sy, ref, cx, cy, drag, fv):
    """:func:`first_half` over all floes in parallel chunks (no race)."""
    n = pos.shape[0]
    part = np.zeros((N_CHUNKS, 4))
    for c in prange(N_CHUNKS):
        w, sx_, sy_, v2 = first_half(c * n // N_CHUNKS, (c + 1) * n // N_CHUNKS, dt_kick, dt, pos, vel,
                                 omega, force, torque, inv_mass, inv_inertia, lx, ly, px, py,
                                 sx, sy, ref, cx, cy, drag, fv)
        part[c, 0] = w
        part[c, 1] = sx_
        part[c, 2] = sy_
        part[c, 3] = v2
    return part[:, 0].max(), part[:, 1].sum(), part[:, 2].sum(), part[:, 3].max()


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

    Returns (start, nbr, hist, rev_start, rev_pair, ref) where ``ref`` is a
    copy of the positions at the build.
    """
    if parallel:
        new_start, new_nbr = build_pair_list(pos, radius, rank, lx, ly, px, py, skin, cell_size)
    else:
        new_start, new_nbr = build_pair_list_serial(pos, radius, rank, lx, ly, px, py, skin,
                                                    cell_size)
    new_hist = transfer_history(start, nbr, hist, new_start, new_nbr, 2)
    rev_start, rev_pair = reverse_incidence(new_start, new_nbr, radius.shape[0])
    return new_start, new_nbr, new_hist, rev_start, rev_pair, pos.copy()


@njit(cache=True, error_model="numpy")
def list_members(start, rev_start):
    """(owners, active): floes that own a pair of the list, and floes that
    own or partner one."""
    own = start[1:] > start[:-1]
    return np.nonzero(own)[0], np.nonzero(own | (rev_start[1:] > rev_start[:-1]))[0]


@njit(cache=True, error_model="numpy")
def run_steps(n_steps, dt, time, pos, vel, omega, force, torque, radius, rank, inv_mass,
              inv_inertia, drag, fv, cp, box, max_concentration,
              skin, cell_size, max_cut, start, nbr, hist, rev_start, rev_pair, ref, ref_lengths,
              centre, wall_hist, parallel):
    """Advance the floes by ``n_steps`` velocity-Verlet steps.

    Between two steps of one call the second half kick of a step and the
    first half kick of the next are done together (leapfrog form); the state
    returned is synchronised (velocities at full steps). ``box`` is updated
    in place for a deforming box; the Verlet list is rebuilt whenever the
    displacement criterion of :mod:`physics.neighbors` could be violated.

    Returns (steps done, status, n_rebuilds, start, nbr, hist, rev_start,
    rev_pair, ref). A non-zero status stops the run early: non-finite state,
    or a deforming box at its concentration limit.
    """
    px = box[BOX_PX] != 0.0
    py = box[BOX_PY] != 0.0
    walls = not (px and py)
    n = pos.shape[0]
    n_rebuilds = 0
    pair_buf = np.empty((nbr.shape[0], 4))
    owners, active = list_members(start, rev_start)
    done = 0
    status = STATUS_OK
    for step in range(n_steps):
        t_new = time + (step + 1) * dt
        lx_old, ly_old = box[BOX_LX], box[BOX_LY]
        lx, ly, conc = box_lengths_at(box, t_new)
        if box[BOX_DEFORM] != 0.0 and (conc >= max_concentration or conc <= 0.0):
            status = STATUS_CONCENTRATION
            break
        box[BOX_LX] = lx
        box[BOX_LY] = ly
        dt_kick = 0.5 * dt if step == 0 else dt
        if parallel:
            worst, mx, my, vmax2 = first_half_parallel(dt_kick, dt, pos, vel, omega, force, torque,
                                                inv_mass, inv_inertia, lx, ly, px, py,
                                                lx / lx_old, ly / ly_old, ref, centre[0],
                                                centre[1], drag, fv)
        else:
            worst, mx, my, vmax2 = first_half(0, n, dt_kick, dt, pos, vel, omega, force, torque,
                                       inv_mass, inv_inertia, lx, ly, px, py, lx / lx_old,
                                       ly / ly_old, ref, centre[0], centre[1], drag, fv)
        if not math.isfinite(worst + mx + my + vmax2):
            status = STATUS_NONFINITE
            done += 1
            break
        if vmax2 * dt * dt > 0.25 * skin * skin:
            # a floe crossed half the skin in one step: the dynamics blew up
            status = STATUS_UNSTABLE
            done += 1
            break
        centre[0] = mx / n
        centre[1] = my / n
        shrink = max(0.0, 1.0 - min(lx / ref_lengths[0], ly / ref_lengths[1]))
        if 2.0 * math.sqrt(worst) + shrink * max_cut >= skin:
            start, nbr, hist, rev_start, rev_pair, ref = rebuild(
                pos, radius, rank, lx, ly, px, py, skin, cell_size, start, nbr, hist, parallel)
            ref_lengths[0] = lx
            ref_lengths[1] = ly
            centre[0] = 0.0
            centre[1] = 0.0
            pair_buf = np.empty((nbr.shape[0], 4))
            owners, active = list_members(start, rev_start)
            n_rebuilds += 1
        # drag forces are already in force/torque (first half); add contacts
        if parallel:
            contact_forces_parallel(pos, vel, omega, radius, inv_mass, cp, box, start, nbr, hist,
                                    wall_hist, dt, force, torque, pair_buf, rev_start, rev_pair,
                                    owners, active)
        else:
            if walls:
                wall_forces(0, n, pos, vel, omega, radius, inv_mass, cp, box, wall_hist, dt,
                            force, torque)
            owner_pairs(0, owners.shape[0], owners, pos, vel, omega, radius, inv_mass, cp, box,
                        start, nbr, hist, dt, True, force, torque, pair_buf)
        done += 1
    if done > 0:
        half_kick(vel, omega, force, torque, inv_mass, inv_inertia, dt)
    return done, status, n_rebuilds, start, nbr, hist, rev_start, rev_pair, ref


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
                               alpha, gt, mu, limit)
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
