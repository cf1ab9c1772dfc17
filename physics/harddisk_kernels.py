"""Compiled kernels of the event-driven hard-disc engine (Herman 2011, "SFC").

Floes move on straight lines between events. Each floe keeps its position
``pos[i]`` at its own last update time ``t_loc[i]`` ("delayed states"), so
an event touches only the floes it involves. Every floe has one pending
event in the calendar (:mod:`physics.event_calendar`): its earliest
predicted collision, or the next crossing of a cell boundary (a
"virtual wall"). A prediction stores the partner's collision counter; when
the partner has changed course since, the event is stale and is simply
predicted again (no search over all pairs).

Cell list for power-law sizes. The cell side is at least the diameter of
every "small" floe; the "big" floes (the largest of the field, see
:func:`physics.harddisk.choose_cells`) are not stored in cells but as the
rectangle of cells their bounding box covers, and every cell keeps a short
"cover list" of the big floes whose rectangle, grown by one cell, holds
it. A small floe looks for partners in its 3 × 3 block of cells and in the
cover list of its own cell; a big floe looks for small floes in the ring of
cells around its rim (cells entirely inside its disc cannot hold a floe
centre) and at every other big floe whose grown rectangle meets its own.
The relation is symmetric, so every pair that can touch before either floe
crosses a cell boundary is seen by both. A big floe's "virtual wall" is an
edge of its bounding box crossing a cell boundary; it updates one row or
column of cover lists.

Collisions (eqs 10–11) with restitution ε and the TC model of Luding and
McNamara: a floe that collided less than ``collision_duration`` ago
collides elastically. Drag in Stokes form is applied to all floes at fixed
times k Δt_max by the linearly implicit update (eqs 13–14), after which
every prediction is redone.

Round-off repairs (counted): a pair found overlapping while approaching is
collided at once; a negative predicted time is clamped to zero. A floe that
collides more than ``COLLAPSE_EVENTS`` times in a row, each within
``COLLAPSE_INTERVAL`` of the last, is in inelastic collapse: the run stops
with a status code instead of hanging.
"""
from __future__ import annotations

import math

from numba import njit

from .event_calendar import heap_build, heap_update

# event partner codes (ev_partner >= 0: collision with that floe)
EV_CELL = -1        # virtual wall: cell crossing (small) or bounding-box change (big)
EV_NONE = -2        # nothing can happen (floe at rest, alone)
# status codes of run_events
STATUS_DONE, STATUS_EVENTS, STATUS_LOG_FULL, STATUS_COLLAPSE, STATUS_NONFINITE, STATUS_COVER_FULL = range(6)
COLLAPSE_INTERVAL = 1e-9   # [s] collisions of one floe closer than this count as rapid
COLLAPSE_EVENTS = 20       # rapid collisions of one floe in a row that mean inelastic collapse
# counters (int64 array) layout
C_COLLISIONS, C_CROSSINGS, C_STALE, C_REPAIR_OVERLAP, C_REPAIR_TIME, C_SYNCS, C_TC, C_COVER_FULL = range(8)
N_COUNTERS = 8
# accumulators (float array): kinetic tensor Σ m v⊗v (xx, xy, yy), its time
# integral, collision virial Σ r_ij ⊗ J_ij, time of the last accumulation,
# start of the window, energy lost in collisions
A_KXX, A_KXY, A_KYY, A_IKXX, A_IKXY, A_IKYY, A_WXX, A_WXY, A_WYX, A_WYY, A_TLAST, A_T0, A_LOST = range(13)
N_ACC = 13


# ---------------------------------------------------------------------------
# Pointwise geometry
# ---------------------------------------------------------------------------

@njit(cache=True, inline="always", error_model="numpy")
def wrap_delta(d, length):
    """Minimum image of a displacement (periodic side of ``length``)."""
    if d > 0.5 * length:
        d -= length * math.floor(d / length + 0.5)
    elif d < -0.5 * length:
        d -= length * math.floor(d / length + 0.5)
    return d


@njit(cache=True, inline="always", error_model="numpy")
def collision_time(dx, dy, dvx, dvy, sigma):
    """Time until two discs at separation (dx, dy) = x_j − x_i with relative
    velocity (dvx, dvy) = u_j − u_i touch at centre distance ``sigma``.

    Returns (t, repair): t = inf if they never touch; t = 0 with repair = 1
    if they already overlap while approaching (round-off)."""
    b = dx * dvx + dy * dvy
    if b >= 0.0:
        return math.inf, 0
    c = dx * dx + dy * dy - sigma * sigma
    if c <= 0.0:
        return 0.0, 1 if c < -1e-10 * sigma * sigma else 0
    a = dvx * dvx + dvy * dvy
    disc = b * b - a * c
    if disc <= 0.0:
        return math.inf, 0
    # stable root of a t² + 2 b t + c = 0 (b < 0, c > 0): t = c / (−b + √disc)
    return c / (-b + math.sqrt(disc)), 0


@njit(cache=True, inline="always", error_model="numpy")
def line_crossing(x, v, lo, hi):
    """Time for a coordinate x moving at v to leave [lo, hi]; returns
    (t, +1 or −1 for the side, 0 if never)."""
    if v > 0.0:
        return max(0.0, (hi - x) / v), 1
    if v < 0.0:
        return max(0.0, (lo - x) / v), -1
    return math.inf, 0


@njit(cache=True, inline="always", error_model="numpy")
def in_range(c, lo, hi, nc):
    """Is cell index c (0..nc−1) in the periodic range lo..hi (lo may be
    negative or hi ≥ nc; hi − lo < nc)?"""
    return (c - lo) % nc <= hi - lo


# ---------------------------------------------------------------------------
# Cell lists (doubly linked, small floes only)
# ---------------------------------------------------------------------------

@njit(cache=True, inline="always", error_model="numpy")
def cell_insert(i, c, head, nxt, prv, cell_of):
    h = head[c]
    nxt[i] = h
    prv[i] = -1
    if h >= 0:
        prv[h] = i
    head[c] = i
    cell_of[i] = c


@njit(cache=True, inline="always", error_model="numpy")
def cell_remove(i, head, nxt, prv, cell_of):
    c = cell_of[i]
    p = prv[i]
    q = nxt[i]
    if p >= 0:
        nxt[p] = q
    else:
        head[c] = q
    if q >= 0:
        prv[q] = p
    nxt[i] = -1
    prv[i] = -1


@njit(cache=True, inline="always", error_model="numpy")
def wrap_cell(c, nc):
    """Cell index c (at most one box length off) into 0..nc−1."""
    if c >= nc:
        return c - nc
    if c < 0:
        return c + nc
    return c


@njit(cache=True, error_model="numpy")
def cover_line(b, kx0, kx1, ky0, ky1, add, nc, cover, cover_n, counters):
    """Add big floe b to (or remove it from) the cover lists of the cells
    kx0..kx1 × ky0..ky1 (unwrapped indices). A full list sets the
    C_COVER_FULL counter (the caller grows the lists and rebuilds them)."""
    cap = cover.shape[1]
    for ky in range(ky0, ky1 + 1):
        row = (ky % nc) * nc
        for kx in range(kx0, kx1 + 1):
            c = row + kx % nc
            m = cover_n[c]
            if add:
                if m < cap:
                    cover[c, m] = b
                    cover_n[c] = m + 1
                else:
                    counters[C_COVER_FULL] = 1
            else:
                for q in range(m):
                    if cover[c, q] == b:
                        cover[c, q] = cover[c, m - 1]
                        cover_n[c] = m - 1
                        break


@njit(cache=True, error_model="numpy")
def build_cover(bbox, n_big, nc, cover, cover_n, counters):
    """Cover lists from scratch: every big floe in the cells of its bounding
    box grown by one cell."""
    cover_n[:] = 0
    for b in range(n_big):
        cover_line(b, bbox[b, 0] - 1, bbox[b, 1] + 1, bbox[b, 2] - 1, bbox[b, 3] + 1, True, nc,
                   cover, cover_n, counters)


@njit(cache=True, error_model="numpy")
def build_cells(pos, big_rank, cell, nc, head, nxt, prv, cell_of, cix, ciy, bbox, radius):
    """Put small floes into cells by their centres and set the bounding-box
    cell ranges of big floes (``bbox[b] = ix0, ix1, iy0, iy1``, unwrapped,
    consistent with pos of the big floe)."""
    head[:] = -1
    nxt[:] = -1
    prv[:] = -1
    for i in range(pos.shape[0]):
        b = big_rank[i]
        if b < 0:
            cx = min(int(pos[i, 0] / cell), nc - 1)
            cy = min(int(pos[i, 1] / cell), nc - 1)
            cix[i] = cx
            ciy[i] = cy
            cell_insert(i, cy * nc + cx, head, nxt, prv, cell_of)
        else:
            cell_of[i] = -1
            r = radius[i]
            bbox[b, 0] = int(math.floor((pos[i, 0] - r) / cell))
            bbox[b, 1] = int(math.floor((pos[i, 0] + r) / cell))
            bbox[b, 2] = int(math.floor((pos[i, 1] - r) / cell))
            bbox[b, 3] = int(math.floor((pos[i, 1] + r) / cell))


# ---------------------------------------------------------------------------
# Prediction
# ---------------------------------------------------------------------------

@njit(cache=True, inline="always", error_model="numpy")
def _try_pair(i, j, t, xi, yi, vxi, vyi, ri, pos, vel, radius, t_loc, inv_mass, L, best, best_j):
    """Collision time of i (at (xi, yi) at time t) with j; keeps the earliest."""
    if inv_mass[i] == 0.0 and inv_mass[j] == 0.0:
        return best, best_j, 0
    dtj = t - t_loc[j]
    dx = wrap_delta(pos[j, 0] + vel[j, 0] * dtj - xi, L)
    dy = wrap_delta(pos[j, 1] + vel[j, 1] * dtj - yi, L)
    tc, rep = collision_time(dx, dy, vel[j, 0] - vxi, vel[j, 1] - vyi, ri + radius[j])
    if tc < best:
        return tc, j, rep
    return best, best_j, rep


@njit(cache=True, inline="always", error_model="numpy")
def predict(i, t, pos, vel, radius, t_loc, inv_mass, big_rank, bigs, bbox, cell, nc, L, head,
            nxt, cix, ciy, cover, cover_n):
    """Earliest event of floe i from time t: (time offset, partner or EV_CELL /
    EV_NONE, repair flag). ``t`` must not precede t_loc[i]."""
    dti = t - t_loc[i]
    vxi = vel[i, 0]
    vyi = vel[i, 1]
    xi = pos[i, 0] + vxi * dti
    yi = pos[i, 1] + vyi * dti
    ri = radius[i]
    best = math.inf
    best_j = EV_NONE
    repair = 0
    nb = bigs.shape[0]
    b_i = big_rank[i]
    if b_i < 0:
        cx = cix[i]
        cy = ciy[i]
        # virtual walls: the boundaries of the floe's cell
        tx, sx = line_crossing(xi, vxi, cx * cell, (cx + 1) * cell)
        ty, sy = line_crossing(yi, vyi, cy * cell, (cy + 1) * cell)
        if min(tx, ty) < best:
            best = min(tx, ty)
            best_j = EV_CELL
        for oy in range(-1, 2):
            yy = wrap_cell(cy + oy, nc) * nc
            for ox in range(-1, 2):
                j = head[yy + wrap_cell(cx + ox, nc)]
                while j >= 0:
                    if j != i:
                        best, best_j, rep = _try_pair(i, j, t, xi, yi, vxi, vyi, ri, pos, vel,
                                                      radius, t_loc, inv_mass, L, best, best_j)
                        repair |= rep
                    j = nxt[j]
        c = cy * nc + cx
        for q in range(cover_n[c]):
            best, best_j, rep = _try_pair(i, bigs[cover[c, q]], t, xi, yi, vxi, vyi, ri, pos, vel,
                                          radius, t_loc, inv_mass, L, best, best_j)
            repair |= rep
    else:
        x0, x1, y0, y1 = bbox[b_i, 0], bbox[b_i, 1], bbox[b_i, 2], bbox[b_i, 3]
        # virtual walls: an edge of the bounding box reaching a cell boundary
        # (xi is kept consistent with the unwrapped range x0..x1)
        t1, s1 = line_crossing(xi - ri, vxi, x0 * cell, (x0 + 1) * cell)
        t2, s2 = line_crossing(xi + ri, vxi, x1 * cell, (x1 + 1) * cell)
        t3, s3 = line_crossing(yi - ri, vyi, y0 * cell, (y0 + 1) * cell)
        t4, s4 = line_crossing(yi + ri, vyi, y1 * cell, (y1 + 1) * cell)
        tw = min(min(t1, t2), min(t3, t4))
        if tw < best:
            best = tw
            best_j = EV_CELL
        # small floes in the ring of cells around the rim
        r_in2 = ri * ri
        for ky in range(y0 - 1, y1 + 2):
            cy_lo = ky * cell - yi
            cy_hi = cy_lo + cell
            fy = max(cy_lo * cy_lo, cy_hi * cy_hi)
            yy = ky % nc
            for kx in range(x0 - 1, x1 + 2):
                cx_lo = kx * cell - xi
                cx_hi = cx_lo + cell
                fx = max(cx_lo * cx_lo, cx_hi * cx_hi)
                if fx + fy < r_in2:
                    continue      # the whole cell is inside the disc: no centre there
                j = head[yy * nc + kx % nc]
                while j >= 0:
                    best, best_j, rep = _try_pair(i, j, t, xi, yi, vxi, vyi, ri, pos, vel,
                                                  radius, t_loc, inv_mass, L, best, best_j)
                    repair |= rep
                    j = nxt[j]
        for b in range(nb):
            # other big floes whose grown rectangle meets this one's
            if b != b_i and (in_range(x0 % nc, bbox[b, 0] - x1 + x0 - 2, bbox[b, 1] + 2, nc)
                             and in_range(y0 % nc, bbox[b, 2] - y1 + y0 - 2, bbox[b, 3] + 2, nc)):
                best, best_j, rep = _try_pair(i, bigs[b], t, xi, yi, vxi, vyi, ri, pos, vel,
                                              radius, t_loc, inv_mass, L, best, best_j)
                repair |= rep
    return best, best_j, repair


@njit(cache=True, inline="always", error_model="numpy")
def predict_event(i, t, pos, vel, radius, t_loc, inv_mass, big_rank, bigs, bbox, cell, nc, L,
                  head, nxt, cix, ciy, cover, cover_n, count, ev_partner, ev_count, counters):
    """Predict the next event of floe i from time t, store its partner and
    the partner's collision counter, and return its time."""
    dt, j, rep = predict(i, t, pos, vel, radius, t_loc, inv_mass, big_rank, bigs, bbox, cell, nc,
                         L, head, nxt, cix, ciy, cover, cover_n)
    if rep:
        counters[C_REPAIR_OVERLAP] += 1
    ev_partner[i] = j
    ev_count[i] = count[j] if j >= 0 else 0
    return t + dt


@njit(cache=True, inline="always", error_model="numpy")
def schedule(i, t, pos, vel, radius, t_loc, inv_mass, big_rank, bigs, bbox, cell, nc, L, head,
             nxt, cix, ciy, cover, cover_n, count, ev_partner, ev_count, heap, where, key,
             counters):
    """Predict the next event of floe i from time t and put it in the calendar."""
    heap_update(heap, where, key, i,
                predict_event(i, t, pos, vel, radius, t_loc, inv_mass, big_rank, bigs, bbox,
                              cell, nc, L, head, nxt, cix, ciy, cover, cover_n, count,
                              ev_partner, ev_count, counters))


@njit(cache=True, error_model="numpy")
def schedule_all(t, pos, vel, radius, t_loc, inv_mass, big_rank, bigs, bbox, cell, nc, L, head,
                 nxt, cix, ciy, cover, cover_n, count, ev_partner, ev_count, heap, where, key,
                 counters):
    """Predict every floe's next event from time t and rebuild the calendar."""
    for i in range(pos.shape[0]):
        key[i] = predict_event(i, t, pos, vel, radius, t_loc, inv_mass, big_rank, bigs, bbox,
                               cell, nc, L, head, nxt, cix, ciy, cover, cover_n, count,
                               ev_partner, ev_count, counters)
    heap_build(heap, where, key)


# ---------------------------------------------------------------------------
# Event handlers
# ---------------------------------------------------------------------------

@njit(cache=True, inline="always", error_model="numpy")
def move_to(i, t, pos, vel, t_loc):
    dt = t - t_loc[i]
    pos[i, 0] += vel[i, 0] * dt
    pos[i, 1] += vel[i, 1] * dt
    t_loc[i] = t


@njit(cache=True, inline="always", error_model="numpy")
def kinetic_of(m, vx, vy):
    return m * vx * vx, m * vx * vy, m * vy * vy


@njit(cache=True, inline="always", error_model="numpy")
def accumulate(t, acc):
    """Advance the time integral of the kinetic tensor to time t."""
    dt = t - acc[A_TLAST]
    acc[A_IKXX] += acc[A_KXX] * dt
    acc[A_IKXY] += acc[A_KXY] * dt
    acc[A_IKYY] += acc[A_KYY] * dt
    acc[A_TLAST] = t


@njit(cache=True, error_model="numpy")
def kinetic_tensor(vel, inv_mass, acc):
    """Recompute Σ m v⊗v of the mobile floes into acc."""
    kxx = 0.0
    kxy = 0.0
    kyy = 0.0
    for i in range(vel.shape[0]):
        if inv_mass[i] > 0.0:
            a, b, c = kinetic_of(1.0 / inv_mass[i], vel[i, 0], vel[i, 1])
            kxx += a
            kxy += b
            kyy += c
    acc[A_KXX] = kxx
    acc[A_KXY] = kxy
    acc[A_KYY] = kyy


@njit(cache=True, inline="always", error_model="numpy")
def collide(i, j, t, pos, vel, inv_mass, L, restitution, last_coll, tc_duration, acc, counters):
    """Instantaneous collision of i and j at time t (both moved to t).
    Returns (collided, Jx, Jy) with (Jx, Jy) the impulse on j; a pair that
    is not approaching (round-off) is left alone."""
    dx = wrap_delta(pos[j, 0] - pos[i, 0], L)
    dy = wrap_delta(pos[j, 1] - pos[i, 1], L)
    d = math.sqrt(dx * dx + dy * dy)
    nx = dx / d
    ny = dy / d
    approach = nx * (vel[i, 0] - vel[j, 0]) + ny * (vel[i, 1] - vel[j, 1])
    if approach <= 0.0:
        return False, 0.0, 0.0
    eps = restitution
    if t - last_coll[i] < tc_duration or t - last_coll[j] < tc_duration:
        eps = 1.0
        counters[C_TC] += 1
    last_coll[i] = t
    last_coll[j] = t
    imi = inv_mass[i]
    imj = inv_mass[j]
    J = (1.0 + eps) * approach / (imi + imj)
    # energy lost: (1 − ε²)/2 · μ · approach²
    acc[A_LOST] += 0.5 * (1.0 - eps * eps) * approach * approach / (imi + imj)
    # kinetic tensor: remove the old contributions, add the new ones
    for q in range(2):
        k = i if q == 0 else j
        if inv_mass[k] > 0.0:
            a, b, c = kinetic_of(1.0 / inv_mass[k], vel[k, 0], vel[k, 1])
            acc[A_KXX] -= a
            acc[A_KXY] -= b
            acc[A_KYY] -= c
    vel[i, 0] -= J * imi * nx
    vel[i, 1] -= J * imi * ny
    vel[j, 0] += J * imj * nx
    vel[j, 1] += J * imj * ny
    for q in range(2):
        k = i if q == 0 else j
        if inv_mass[k] > 0.0:
            a, b, c = kinetic_of(1.0 / inv_mass[k], vel[k, 0], vel[k, 1])
            acc[A_KXX] += a
            acc[A_KXY] += b
            acc[A_KYY] += c
    # collision virial: branch vector i→j (length r_i + r_j) ⊗ impulse on j
    acc[A_WXX] += dx * J * nx
    acc[A_WXY] += dx * J * ny
    acc[A_WYX] += dy * J * nx
    acc[A_WYY] += dy * J * ny
    return True, J * nx, J * ny


@njit(cache=True, inline="always", error_model="numpy")
def step_cell(c, s, nc, L):
    """Cell index after a step s = ±1 along one axis, and the shift of the
    coordinate that wraps with it at the periodic boundary."""
    c += s
    if c == nc:
        return 0, -L
    if c < 0:
        return nc - 1, L
    return c, 0.0


@njit(cache=True, inline="always", error_model="numpy")
def cross(i, t, pos, vel, radius, t_loc, big_rank, bbox, cell, nc, L, head, nxt, prv, cell_of,
          cix, ciy, cover, cover_n, counters):
    """Virtual-wall event of floe i at time t: move it into the next cell (a
    small floe) or shift its bounding-box range (a big floe), wrapping at
    the periodic boundary."""
    move_to(i, t, pos, vel, t_loc)
    b = big_rank[i]
    x = pos[i, 0]
    y = pos[i, 1]
    if b < 0:
        cx = cix[i]
        cy = ciy[i]
        tx, sx = line_crossing(x, vel[i, 0], cx * cell, (cx + 1) * cell)
        ty, sy = line_crossing(y, vel[i, 1], cy * cell, (cy + 1) * cell)
        if tx <= ty:
            cx, shift = step_cell(cx, sx, nc, L)
            pos[i, 0] += shift
        else:
            cy, shift = step_cell(cy, sy, nc, L)
            pos[i, 1] += shift
        cell_remove(i, head, nxt, prv, cell_of)
        cix[i] = cx
        ciy[i] = cy
        cell_insert(i, cy * nc + cx, head, nxt, prv, cell_of)
    else:
        r = radius[i]
        x0, x1, y0, y1 = bbox[b, 0], bbox[b, 1], bbox[b, 2], bbox[b, 3]
        t1, s1 = line_crossing(x - r, vel[i, 0], x0 * cell, (x0 + 1) * cell)
        t2, s2 = line_crossing(x + r, vel[i, 0], x1 * cell, (x1 + 1) * cell)
        t3, s3 = line_crossing(y - r, vel[i, 1], y0 * cell, (y0 + 1) * cell)
        t4, s4 = line_crossing(y + r, vel[i, 1], y1 * cell, (y1 + 1) * cell)
        tm = min(min(t1, t2), min(t3, t4))
        # one edge moves by one cell: one column (or row) of cells enters or
        # leaves the grown rectangle x0−1..x1+1 × y0−1..y1+1
        if t1 == tm:
            bbox[b, 0] += s1
            kx = x0 - 1 if s1 > 0 else x0 - 2
            cover_line(b, kx, kx, y0 - 1, y1 + 1, s1 < 0, nc, cover, cover_n, counters)
        elif t2 == tm:
            bbox[b, 1] += s2
            kx = x1 + 2 if s2 > 0 else x1 + 1
            cover_line(b, kx, kx, y0 - 1, y1 + 1, s2 > 0, nc, cover, cover_n, counters)
        elif t3 == tm:
            bbox[b, 2] += s3
            ky = y0 - 1 if s3 > 0 else y0 - 2
            cover_line(b, x0 - 1, x1 + 1, ky, ky, s3 < 0, nc, cover, cover_n, counters)
        else:
            bbox[b, 3] += s4
            ky = y1 + 2 if s4 > 0 else y1 + 1
            cover_line(b, x0 - 1, x1 + 1, ky, ky, s4 > 0, nc, cover, cover_n, counters)
        # keep the centre in [0, L) and the ranges consistent with it
        for ax in range(2):
            shift = -1 if pos[i, ax] >= L else (1 if pos[i, ax] < 0.0 else 0)
            if shift != 0:
                pos[i, ax] += shift * L
                bbox[b, 2 * ax] += shift * nc
                bbox[b, 2 * ax + 1] += shift * nc


@njit(cache=True, error_model="numpy")
def sync_all(t, pos, vel, t_loc):
    """Move every floe to time t (positions stay in their cells: every
    crossing before t has been processed)."""
    for i in range(pos.shape[0]):
        move_to(i, t, pos, vel, t_loc)


@njit(cache=True, error_model="numpy")
def drag_update(dt, vel, inv_tau, u_eq):
    """Linearly implicit Stokes relaxation over dt (eqs 13–14):
    u ← (u + (dt/τ) u_eq) / (1 + dt/τ). Frozen floes have inv_tau = 0 and
    stay at rest."""
    for i in range(vel.shape[0]):
        h = dt * inv_tau[i]
        if h > 0.0:
            vel[i, 0] = (vel[i, 0] + h * u_eq[i, 0]) / (1.0 + h)
            vel[i, 1] = (vel[i, 1] + h * u_eq[i, 1]) / (1.0 + h)


# ---------------------------------------------------------------------------
# Main loop
# ---------------------------------------------------------------------------

@njit(cache=True, error_model="numpy")
def run_events(t_now, t_end, next_sync, dt_max, max_events, pos, vel, radius, t_loc, inv_mass,
               big_rank, bigs, bbox, cell, nc, L, head, nxt, prv, cell_of, cix, ciy, cover,
               cover_n, count, ev_partner, ev_count, heap, where, key, last_coll, rapid, restitution,
               tc_duration, inv_tau, u_eq, has_drag, t_drag, acc, counters, log_t, log_ij,
               log_j, log_n, log_on):
    """Process events from t_now until t_end (then every floe is moved to
    t_end), or until ``max_events`` events, or until the collision log is
    full. With drag, velocities are relaxed at every multiple of Δt_max
    (``next_sync``) and all events predicted again.

    Returns (status, time reached, next_sync, t_drag, log_n). On
    STATUS_EVENTS / STATUS_LOG_FULL the call can simply be repeated.
    """
    t = t_now
    n_events = 0
    status = STATUS_DONE
    while True:
        i = heap[0]
        te = key[i]
        stop = min(t_end, next_sync) if has_drag else t_end
        if te >= stop:
            if has_drag and next_sync <= t_end:
                # velocity update of every floe at the sync time
                t = next_sync
                accumulate(t, acc)
                sync_all(t, pos, vel, t_loc)
                drag_update(t - t_drag, vel, inv_tau, u_eq)
                t_drag = t
                for k in range(count.shape[0]):
                    count[k] += 1
                kinetic_tensor(vel, inv_mass, acc)
                next_sync += dt_max
                counters[C_SYNCS] += 1
                schedule_all(t, pos, vel, radius, t_loc, inv_mass, big_rank, bigs, bbox, cell,
                             nc, L, head, nxt, cix, ciy, cover, cover_n, count, ev_partner,
                             ev_count, heap, where, key, counters)
                continue
            t = t_end
            accumulate(t, acc)
            sync_all(t, pos, vel, t_loc)
            return STATUS_DONE, t, next_sync, t_drag, log_n
        if n_events >= max_events:
            return STATUS_EVENTS, t, next_sync, t_drag, log_n
        if log_on and log_n >= log_t.shape[0]:
            return STATUS_LOG_FULL, t, next_sync, t_drag, log_n
        if not math.isfinite(te):
            return STATUS_NONFINITE, t, next_sync, t_drag, log_n
        if te < t:
            counters[C_REPAIR_TIME] += 1
            te = t
        t = te
        n_events += 1
        j = ev_partner[i]
        n_sched = 1
        if j >= 0:
            if count[j] != ev_count[i]:
                # stale: the partner changed course since the prediction
                counters[C_STALE] += 1
            else:
                accumulate(t, acc)
                move_to(i, t, pos, vel, t_loc)
                move_to(j, t, pos, vel, t_loc)
                hit, jx, jy = collide(i, j, t, pos, vel, inv_mass, L, restitution, last_coll,
                                      tc_duration, acc, counters)
                counters[C_COLLISIONS] += hit
                count[i] += 1
                count[j] += 1
                n_sched = 2
                for k in range(2):
                    q = i if k == 0 else j
                    if t - rapid[q, 0] < COLLAPSE_INTERVAL:
                        rapid[q, 1] += 1
                    else:
                        rapid[q, 1] = 0
                    rapid[q, 0] = t
                    if rapid[q, 1] >= COLLAPSE_EVENTS:
                        status = STATUS_COLLAPSE
                if log_on and hit:
                    log_t[log_n] = t
                    log_ij[log_n, 0] = i
                    log_ij[log_n, 1] = j
                    log_j[log_n, 0] = jx
                    log_j[log_n, 1] = jy
                    log_n += 1
        elif j == EV_CELL:
            cross(i, t, pos, vel, radius, t_loc, big_rank, bbox, cell, nc, L, head, nxt, prv,
                  cell_of, cix, ciy, cover, cover_n, counters)
            counters[C_CROSSINGS] += 1
            if counters[C_COVER_FULL] != 0:
                status = STATUS_COVER_FULL
        for k in range(n_sched):
            q = i if k == 0 else j
            schedule(q, t, pos, vel, radius, t_loc, inv_mass, big_rank, bigs, bbox, cell, nc, L,
                     head, nxt, cix, ciy, cover, cover_n, count, ev_partner, ev_count, heap, where,
                     key, counters)
        if status != STATUS_DONE:
            return status, t, next_sync, t_drag, log_n
