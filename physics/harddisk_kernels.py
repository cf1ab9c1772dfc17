"""Compiled kernels of the event-driven hard-disc engine (Herman 2011, "SFC").

Floes move on straight lines between events. Each floe keeps its position
``pos[i]`` at its own last update time ``t_loc[i]`` ("delayed states"), so
an event touches only the floes it involves. Every floe has one pending
event in the calendar (:mod:`physics.event_calendar`): its earliest
predicted collision, or the next crossing of a cell boundary (a
"virtual wall"). A prediction stores the partner's count of course
changes; when the partner has changed course since, the event is stale and
is simply predicted again (no search over all pairs).

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
with :attr:`HardDiskStatus.COLLAPSE` instead of hanging.

The kernels take their arrays in named bundles (module-level named tuples,
which Numba compiles as structures): :class:`Discs` (the floes' state),
:class:`Cells` (the cell list), :class:`Cover` (the big floes and the cover
lists), :class:`~physics.event_calendar.Calendar` (the pending events),
:class:`CollisionLaw`, :class:`Drag` and :class:`LogBuffer` (the collision
log). Event counts and running sums live in two arrays indexed by the
:class:`Counter` and :class:`Acc` enumerations.

The kernels allocate no arrays, so they are compiled without Numba's
reference counting (``_nrt=False``): every array taken from a bundle would
otherwise be counted in and out with atomic operations, which in the event
loop cost more than the events themselves. A kernel that needs to allocate
must not be added to this module.
"""
from __future__ import annotations

import math
from enum import IntEnum
from typing import NamedTuple

import numpy as np
from numba import njit

from .event_calendar import heap_build, heap_update

# event partner codes (Calendar.partner >= 0: collision with that floe)
EV_CELL = -1        # virtual wall: cell crossing (small) or bounding-box change (big)
EV_NONE = -2        # nothing can happen (floe at rest, alone)
COLLAPSE_INTERVAL = 1e-9   # [s] collisions of one floe closer than this count as rapid
COLLAPSE_EVENTS = 20       # rapid collisions of one floe in a row that mean inelastic collapse


class HardDiskStatus(IntEnum):
    """Why :func:`run_events` returned."""

    #: the end time was reached; every floe is at it
    DONE = 0
    #: the event budget of the call is spent; call again
    EVENTS = 1
    #: the collision log is full; grow it and call again
    LOG_FULL = 2
    #: inelastic collapse (see the module docstring)
    COLLAPSE = 3
    #: an event time is not finite
    NONFINITE = 4
    #: a cover list is full; grow the lists, rebuild them and predict again
    COVER_FULL = 5


class Counter(IntEnum):
    """Slots of the int64 event-count array."""

    COLLISIONS = 0
    CROSSINGS = 1
    STALE = 2
    REPAIR_OVERLAP = 3
    REPAIR_TIME = 4
    SYNCS = 5
    TC = 6
    #: set (to 1) when a cover list overflows
    COVER_FULL = 7


class Acc(IntEnum):
    """Slots of the float accumulator array: the kinetic tensor Σ m u⊗u
    (KXX, KXY, KYY), its time integral (IKXX, IKXY, IKYY), the collision
    virial Σ r_ij ⊗ J_ij (WXX, WXY, WYX, WYY), the time of the last
    accumulation, the start of the averaging window and the energy lost in
    collisions."""

    KXX = 0
    KXY = 1
    KYY = 2
    IKXX = 3
    IKXY = 4
    IKYY = 5
    WXX = 6
    WXY = 7
    WYX = 8
    WYY = 9
    TLAST = 10
    T0 = 11
    LOST = 12


N_COUNTERS = len(Counter)
N_ACC = len(Acc)


class Discs(NamedTuple):
    """The floes' state, in delayed form (each floe at its own time).

    Attributes
    ----------
    pos : (N, 2) float
        Centre at time ``t_loc`` [m] (a big floe's may leave [0, L) while
        its bounding box is consistent with it).
    vel : (N, 2) float
        Velocity [m/s].
    t_loc : (N,) float
        Time of the floe's last update [s].
    radius : (N,) float
    inv_mass : (N,) float
        1/m, zero for frozen floes.
    changes : (N,) int64
        Course changes so far (collisions, drag updates, new predictions);
        a prediction naming a partner whose count has changed is stale.
    last_collision : (N,) float
        Time of the last collision [s] (TC model).
    rapid_time : (N,) float
        Time of the last collision event [s] (collapse detection).
    rapid_run : (N,) int64
        Collision events in a row, each within ``COLLAPSE_INTERVAL`` of the last.
    """

    pos: np.ndarray
    vel: np.ndarray
    t_loc: np.ndarray
    radius: np.ndarray
    inv_mass: np.ndarray
    changes: np.ndarray
    last_collision: np.ndarray
    rapid_time: np.ndarray
    rapid_run: np.ndarray


class Cells(NamedTuple):
    """Cell list of the small floes (doubly linked lists per cell).

    Attributes
    ----------
    side : float
        Cell side [m].
    n : int
        Cells per side of the box (nc; cell ``cy * nc + cx``).
    length : float
        Side L of the periodic square box [m].
    head : (nc², ) int64
        First floe of each cell (−1: empty).
    nxt, prv : (N,) int64
        Next and previous floe in the same cell (−1: none).
    cell_of : (N,) int64
        Cell of each small floe (−1 for big floes).
    cix, ciy : (N,) int64
        Cell column and row of each small floe.
    """

    side: float
    n: int
    length: float
    head: np.ndarray
    nxt: np.ndarray
    prv: np.ndarray
    cell_of: np.ndarray
    cix: np.ndarray
    ciy: np.ndarray


class Cover(NamedTuple):
    """The big floes and the cells their bounding boxes cover.

    Attributes
    ----------
    rank : (N,) int64
        Rank b of each big floe among the big ones, −1 for small floes.
    floes : (B,) int64
        Index of big floe b.
    bbox : (max(B, 1), 4) int64
        Cell range ``ix0, ix1, iy0, iy1`` of the bounding box of big floe b
        (unwrapped, consistent with its centre).
    lists : (nc², capacity) int64
        Cover list of each cell: the ranks b of the big floes whose bounding
        box grown by one cell holds the cell.
    sizes : (nc²,) int64
        Length of each cover list.
    """

    rank: np.ndarray
    floes: np.ndarray
    bbox: np.ndarray
    lists: np.ndarray
    sizes: np.ndarray


class CollisionLaw(NamedTuple):
    """Restitution ε in (0, 1] and the TC model's collision duration Δt_c [s]
    (0: off)."""

    restitution: float
    duration: float


class Drag(NamedTuple):
    """Stokes drag towards each floe's free-drift velocity.

    Attributes
    ----------
    on : bool
        False: free flight (no velocity updates).
    step : float
        Δt_max [s] between velocity updates.
    inv_tau : (N,) float
        1/τ_i [1/s], zero for frozen floes.
    u_eq : (N, 2) float
        Free-drift velocity u_eq,i [m/s].
    """

    on: bool
    step: float
    inv_tau: np.ndarray
    u_eq: np.ndarray


class LogBuffer(NamedTuple):
    """The collision log's storage.

    Attributes
    ----------
    on : bool
        Record collisions.
    used : (1,) int64
        Entries written.
    time : (K,) float
        Time of each collision [s].
    pair : (K, 2) int64
        The floes i, j.
    impulse : (K, 2) float
        Impulse on j [N s].
    """

    on: bool
    used: np.ndarray
    time: np.ndarray
    pair: np.ndarray
    impulse: np.ndarray


# ---------------------------------------------------------------------------
# Pointwise geometry
# ---------------------------------------------------------------------------

@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def wrap_delta(d, length):
    """Minimum image of a displacement (periodic side of ``length``)."""
    if d > 0.5 * length:
        d -= length * math.floor(d / length + 0.5)
    elif d < -0.5 * length:
        d -= length * math.floor(d / length + 0.5)
    return d


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
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


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def line_crossing(x, v, lo, hi):
    """Time for a coordinate x moving at v to leave [lo, hi]; returns
    (t, +1 or −1 for the side, 0 if never)."""
    if v > 0.0:
        return max(0.0, (hi - x) / v), 1
    if v < 0.0:
        return max(0.0, (lo - x) / v), -1
    return math.inf, 0


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def in_range(c, lo, hi, nc):
    """Is cell index c (0..nc−1) in the periodic range lo..hi (lo may be
    negative or hi ≥ nc; hi − lo < nc)?"""
    return (c - lo) % nc <= hi - lo


# ---------------------------------------------------------------------------
# Cell lists (doubly linked, small floes only)
# ---------------------------------------------------------------------------

@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def cell_insert(i, c, cells):
    head = cells.head
    h = head[c]
    cells.nxt[i] = h
    cells.prv[i] = -1
    if h >= 0:
        cells.prv[h] = i
    head[c] = i
    cells.cell_of[i] = c


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def cell_remove(i, cells):
    nxt = cells.nxt
    prv = cells.prv
    c = cells.cell_of[i]
    p = prv[i]
    q = nxt[i]
    if p >= 0:
        nxt[p] = q
    else:
        cells.head[c] = q
    if q >= 0:
        prv[q] = p
    nxt[i] = -1
    prv[i] = -1


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def wrap_cell(c, nc):
    """Cell index c (at most one box length off) into 0..nc−1."""
    if c >= nc:
        return c - nc
    if c < 0:
        return c + nc
    return c


@njit(cache=True, error_model="numpy", _nrt=False)
def cover_line(b, kx0, kx1, ky0, ky1, add, nc, cover, counters):
    """Add big floe b to (or remove it from) the cover lists of the cells
    kx0..kx1 × ky0..ky1 (unwrapped indices). A full list sets the
    ``Counter.COVER_FULL`` counter (the caller grows the lists and rebuilds them)."""
    lists = cover.lists
    sizes = cover.sizes
    cap = lists.shape[1]
    for ky in range(ky0, ky1 + 1):
        row = (ky % nc) * nc
        for kx in range(kx0, kx1 + 1):
            c = row + kx % nc
            m = sizes[c]
            if add:
                if m < cap:
                    lists[c, m] = b
                    sizes[c] = m + 1
                else:
                    counters[Counter.COVER_FULL] = 1
            else:
                for q in range(m):
                    if lists[c, q] == b:
                        lists[c, q] = lists[c, m - 1]
                        sizes[c] = m - 1
                        break


@njit(cache=True, error_model="numpy", _nrt=False)
def build_cover(cover, nc, counters):
    """Cover lists from scratch: every big floe in the cells of its bounding
    box grown by one cell."""
    bbox = cover.bbox
    cover.sizes[:] = 0
    for b in range(cover.floes.shape[0]):
        cover_line(b, bbox[b, 0] - 1, bbox[b, 1] + 1, bbox[b, 2] - 1, bbox[b, 3] + 1, True, nc,
                   cover, counters)


@njit(cache=True, error_model="numpy", _nrt=False)
def build_cells(d, cells, cover):
    """Put small floes into cells by their centres and set the bounding-box
    cell ranges of big floes (``bbox[b] = ix0, ix1, iy0, iy1``, unwrapped,
    consistent with pos of the big floe)."""
    pos = d.pos
    cell = cells.side
    nc = cells.n
    bbox = cover.bbox
    cells.head[:] = -1
    cells.nxt[:] = -1
    cells.prv[:] = -1
    for i in range(pos.shape[0]):
        b = cover.rank[i]
        if b < 0:
            cx = min(int(pos[i, 0] / cell), nc - 1)
            cy = min(int(pos[i, 1] / cell), nc - 1)
            cells.cix[i] = cx
            cells.ciy[i] = cy
            cell_insert(i, cy * nc + cx, cells)
        else:
            cells.cell_of[i] = -1
            r = d.radius[i]
            bbox[b, 0] = int(math.floor((pos[i, 0] - r) / cell))
            bbox[b, 1] = int(math.floor((pos[i, 0] + r) / cell))
            bbox[b, 2] = int(math.floor((pos[i, 1] - r) / cell))
            bbox[b, 3] = int(math.floor((pos[i, 1] + r) / cell))


# ---------------------------------------------------------------------------
# Prediction
# ---------------------------------------------------------------------------

@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _try_pair(i, j, t, xi, yi, vxi, vyi, ri, d, L, best, best_j):
    """Collision time of i (at (xi, yi) at time t) with j; keeps the earliest."""
    inv_mass = d.inv_mass
    if inv_mass[i] == 0.0 and inv_mass[j] == 0.0:
        return best, best_j, 0
    pos = d.pos
    vel = d.vel
    dtj = t - d.t_loc[j]
    dx = wrap_delta(pos[j, 0] + vel[j, 0] * dtj - xi, L)
    dy = wrap_delta(pos[j, 1] + vel[j, 1] * dtj - yi, L)
    tc, rep = collision_time(dx, dy, vel[j, 0] - vxi, vel[j, 1] - vyi, ri + d.radius[j])
    if tc < best:
        return tc, j, rep
    return best, best_j, rep


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def predict(i, t, d, cells, cover):
    """Earliest event of floe i from time t: (time offset, partner or EV_CELL /
    EV_NONE, repair flag). ``t`` must not precede t_loc[i]."""
    cell = cells.side
    nc = cells.n
    L = cells.length
    head = cells.head
    nxt = cells.nxt
    bigs = cover.floes
    bbox = cover.bbox
    dti = t - d.t_loc[i]
    vxi = d.vel[i, 0]
    vyi = d.vel[i, 1]
    xi = d.pos[i, 0] + vxi * dti
    yi = d.pos[i, 1] + vyi * dti
    ri = d.radius[i]
    best = math.inf
    best_j = EV_NONE
    repair = 0
    nb = bigs.shape[0]
    b_i = cover.rank[i]
    if b_i < 0:
        cx = cells.cix[i]
        cy = cells.ciy[i]
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
                        best, best_j, rep = _try_pair(i, j, t, xi, yi, vxi, vyi, ri, d, L,
                                                      best, best_j)
                        repair |= rep
                    j = nxt[j]
        c = cy * nc + cx
        for q in range(cover.sizes[c]):
            best, best_j, rep = _try_pair(i, bigs[cover.lists[c, q]], t, xi, yi, vxi, vyi, ri,
                                          d, L, best, best_j)
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
                    best, best_j, rep = _try_pair(i, j, t, xi, yi, vxi, vyi, ri, d, L,
                                                  best, best_j)
                    repair |= rep
                    j = nxt[j]
        for b in range(nb):
            # other big floes whose grown rectangle meets this one's
            if b != b_i and (in_range(x0 % nc, bbox[b, 0] - x1 + x0 - 2, bbox[b, 1] + 2, nc)
                             and in_range(y0 % nc, bbox[b, 2] - y1 + y0 - 2, bbox[b, 3] + 2, nc)):
                best, best_j, rep = _try_pair(i, bigs[b], t, xi, yi, vxi, vyi, ri, d, L,
                                              best, best_j)
                repair |= rep
    return best, best_j, repair


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def predict_event(i, t, d, cells, cover, cal, counters):
    """Predict the next event of floe i from time t, store its partner and
    the partner's count of course changes, and return its time."""
    dt, j, rep = predict(i, t, d, cells, cover)
    if rep:
        counters[Counter.REPAIR_OVERLAP] += 1
    cal.partner[i] = j
    cal.partner_changes[i] = d.changes[j] if j >= 0 else 0
    return t + dt


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def schedule(i, t, d, cells, cover, cal, counters):
    """Predict the next event of floe i from time t and put it in the calendar."""
    heap_update(cal, i, predict_event(i, t, d, cells, cover, cal, counters))


@njit(cache=True, error_model="numpy", _nrt=False)
def schedule_all(t, d, cells, cover, cal, counters):
    """Predict every floe's next event from time t and rebuild the calendar."""
    for i in range(d.pos.shape[0]):
        cal.time[i] = predict_event(i, t, d, cells, cover, cal, counters)
    heap_build(cal)


# ---------------------------------------------------------------------------
# Event handlers
# ---------------------------------------------------------------------------

@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def move_to(i, t, d):
    dt = t - d.t_loc[i]
    d.pos[i, 0] += d.vel[i, 0] * dt
    d.pos[i, 1] += d.vel[i, 1] * dt
    d.t_loc[i] = t


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def kinetic_of(m, vx, vy):
    return m * vx * vx, m * vx * vy, m * vy * vy


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def accumulate(t, acc):
    """Advance the time integral of the kinetic tensor to time t."""
    dt = t - acc[Acc.TLAST]
    acc[Acc.IKXX] += acc[Acc.KXX] * dt
    acc[Acc.IKXY] += acc[Acc.KXY] * dt
    acc[Acc.IKYY] += acc[Acc.KYY] * dt
    acc[Acc.TLAST] = t


@njit(cache=True, error_model="numpy", _nrt=False)
def kinetic_tensor(d, acc):
    """Recompute Σ m v⊗v of the mobile floes into acc."""
    vel = d.vel
    inv_mass = d.inv_mass
    kxx = 0.0
    kxy = 0.0
    kyy = 0.0
    for i in range(vel.shape[0]):
        if inv_mass[i] > 0.0:
            a, b, c = kinetic_of(1.0 / inv_mass[i], vel[i, 0], vel[i, 1])
            kxx += a
            kxy += b
            kyy += c
    acc[Acc.KXX] = kxx
    acc[Acc.KXY] = kxy
    acc[Acc.KYY] = kyy


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def collide(i, j, t, d, L, law, acc, counters):
    """Instantaneous collision of i and j at time t (both moved to t).
    Returns (collided, Jx, Jy) with (Jx, Jy) the impulse on j; a pair that
    is not approaching (round-off) is left alone."""
    pos = d.pos
    vel = d.vel
    inv_mass = d.inv_mass
    last_coll = d.last_collision
    dx = wrap_delta(pos[j, 0] - pos[i, 0], L)
    dy = wrap_delta(pos[j, 1] - pos[i, 1], L)
    dist = math.sqrt(dx * dx + dy * dy)
    nx = dx / dist
    ny = dy / dist
    approach = nx * (vel[i, 0] - vel[j, 0]) + ny * (vel[i, 1] - vel[j, 1])
    if approach <= 0.0:
        return False, 0.0, 0.0
    eps = law.restitution
    if t - last_coll[i] < law.duration or t - last_coll[j] < law.duration:
        eps = 1.0
        counters[Counter.TC] += 1
    last_coll[i] = t
    last_coll[j] = t
    imi = inv_mass[i]
    imj = inv_mass[j]
    J = (1.0 + eps) * approach / (imi + imj)
    # energy lost: (1 − ε²)/2 · μ · approach²
    acc[Acc.LOST] += 0.5 * (1.0 - eps * eps) * approach * approach / (imi + imj)
    # kinetic tensor: remove the old contributions, add the new ones
    for q in range(2):
        k = i if q == 0 else j
        if inv_mass[k] > 0.0:
            a, b, c = kinetic_of(1.0 / inv_mass[k], vel[k, 0], vel[k, 1])
            acc[Acc.KXX] -= a
            acc[Acc.KXY] -= b
            acc[Acc.KYY] -= c
    vel[i, 0] -= J * imi * nx
    vel[i, 1] -= J * imi * ny
    vel[j, 0] += J * imj * nx
    vel[j, 1] += J * imj * ny
    for q in range(2):
        k = i if q == 0 else j
        if inv_mass[k] > 0.0:
            a, b, c = kinetic_of(1.0 / inv_mass[k], vel[k, 0], vel[k, 1])
            acc[Acc.KXX] += a
            acc[Acc.KXY] += b
            acc[Acc.KYY] += c
    # collision virial: branch vector i→j (length r_i + r_j) ⊗ impulse on j
    acc[Acc.WXX] += dx * J * nx
    acc[Acc.WXY] += dx * J * ny
    acc[Acc.WYX] += dy * J * nx
    acc[Acc.WYY] += dy * J * ny
    return True, J * nx, J * ny


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def step_cell(c, s, nc, L):
    """Cell index after a step s = ±1 along one axis, and the shift of the
    coordinate that wraps with it at the periodic boundary."""
    c += s
    if c == nc:
        return 0, -L
    if c < 0:
        return nc - 1, L
    return c, 0.0


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def cross(i, t, d, cells, cover, counters):
    """Virtual-wall event of floe i at time t: move it into the next cell (a
    small floe) or shift its bounding-box range (a big floe), wrapping at
    the periodic boundary."""
    cell = cells.side
    nc = cells.n
    L = cells.length
    pos = d.pos
    vel = d.vel
    move_to(i, t, d)
    b = cover.rank[i]
    x = pos[i, 0]
    y = pos[i, 1]
    if b < 0:
        cx = cells.cix[i]
        cy = cells.ciy[i]
        tx, sx = line_crossing(x, vel[i, 0], cx * cell, (cx + 1) * cell)
        ty, sy = line_crossing(y, vel[i, 1], cy * cell, (cy + 1) * cell)
        if tx <= ty:
            cx, shift = step_cell(cx, sx, nc, L)
            pos[i, 0] += shift
        else:
            cy, shift = step_cell(cy, sy, nc, L)
            pos[i, 1] += shift
        cell_remove(i, cells)
        cells.cix[i] = cx
        cells.ciy[i] = cy
        cell_insert(i, cy * nc + cx, cells)
    else:
        bbox = cover.bbox
        r = d.radius[i]
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
            cover_line(b, kx, kx, y0 - 1, y1 + 1, s1 < 0, nc, cover, counters)
        elif t2 == tm:
            bbox[b, 1] += s2
            kx = x1 + 2 if s2 > 0 else x1 + 1
            cover_line(b, kx, kx, y0 - 1, y1 + 1, s2 > 0, nc, cover, counters)
        elif t3 == tm:
            bbox[b, 2] += s3
            ky = y0 - 1 if s3 > 0 else y0 - 2
            cover_line(b, x0 - 1, x1 + 1, ky, ky, s3 < 0, nc, cover, counters)
        else:
            bbox[b, 3] += s4
            ky = y1 + 2 if s4 > 0 else y1 + 1
            cover_line(b, x0 - 1, x1 + 1, ky, ky, s4 > 0, nc, cover, counters)
        # keep the centre in [0, L) and the ranges consistent with it
        for ax in range(2):
            shift = -1 if pos[i, ax] >= L else (1 if pos[i, ax] < 0.0 else 0)
            if shift != 0:
                pos[i, ax] += shift * L
                bbox[b, 2 * ax] += shift * nc
                bbox[b, 2 * ax + 1] += shift * nc


@njit(cache=True, error_model="numpy", _nrt=False)
def sync_all(t, d):
    """Move every floe to time t (positions stay in their cells: every
    crossing before t has been processed)."""
    for i in range(d.pos.shape[0]):
        move_to(i, t, d)


@njit(cache=True, error_model="numpy", _nrt=False)
def drag_update(dt, d, drag):
    """Linearly implicit Stokes relaxation over dt (eqs 13–14):
    u ← (u + (dt/τ) u_eq) / (1 + dt/τ). Frozen floes have inv_tau = 0 and
    stay at rest."""
    vel = d.vel
    inv_tau = drag.inv_tau
    u_eq = drag.u_eq
    for i in range(vel.shape[0]):
        h = dt * inv_tau[i]
        if h > 0.0:
            vel[i, 0] = (vel[i, 0] + h * u_eq[i, 0]) / (1.0 + h)
            vel[i, 1] = (vel[i, 1] + h * u_eq[i, 1]) / (1.0 + h)


# ---------------------------------------------------------------------------
# Main loop
# ---------------------------------------------------------------------------

@njit(cache=True, error_model="numpy", _nrt=False)
def run_events(t_now, t_end, next_sync, t_drag, max_events, d, cells, cover, cal, law, drag,
               log, acc, counters):
    """Process events from t_now until t_end (then every floe is moved to
    t_end), or until ``max_events`` events, or until the collision log is
    full. With drag, velocities are relaxed at every multiple of Δt_max
    (``next_sync``; ``t_drag`` is the time of the last relaxation) and all
    events predicted again.

    Returns (status, time reached, next_sync, t_drag), status a
    :class:`HardDiskStatus`. On ``EVENTS`` / ``LOG_FULL`` the call can
    simply be repeated.
    """
    t = t_now
    n_events = 0
    status = HardDiskStatus.DONE
    changes = d.changes
    while True:
        i = cal.heap[0]
        te = cal.time[i]
        stop = min(t_end, next_sync) if drag.on else t_end
        if te >= stop:
            if drag.on and next_sync <= t_end:
                # velocity update of every floe at the sync time
                t = next_sync
                accumulate(t, acc)
                sync_all(t, d)
                drag_update(t - t_drag, d, drag)
                t_drag = t
                for k in range(changes.shape[0]):
                    changes[k] += 1
                kinetic_tensor(d, acc)
                next_sync += drag.step
                counters[Counter.SYNCS] += 1
                schedule_all(t, d, cells, cover, cal, counters)
                continue
            t = t_end
            accumulate(t, acc)
            sync_all(t, d)
            return HardDiskStatus.DONE, t, next_sync, t_drag
        if n_events >= max_events:
            return HardDiskStatus.EVENTS, t, next_sync, t_drag
        if log.on and log.used[0] >= log.time.shape[0]:
            return HardDiskStatus.LOG_FULL, t, next_sync, t_drag
        if not math.isfinite(te):
            return HardDiskStatus.NONFINITE, t, next_sync, t_drag
        if te < t:
            counters[Counter.REPAIR_TIME] += 1
            te = t
        t = te
        n_events += 1
        j = cal.partner[i]
        n_sched = 1
        if j >= 0:
            if changes[j] != cal.partner_changes[i]:
                # stale: the partner changed course since the prediction
                counters[Counter.STALE] += 1
            else:
                accumulate(t, acc)
                move_to(i, t, d)
                move_to(j, t, d)
                hit, jx, jy = collide(i, j, t, d, cells.length, law, acc, counters)
                counters[Counter.COLLISIONS] += hit
                changes[i] += 1
                changes[j] += 1
                n_sched = 2
                for k in range(2):
                    q = i if k == 0 else j
                    if t - d.rapid_time[q] < COLLAPSE_INTERVAL:
                        d.rapid_run[q] += 1
                    else:
                        d.rapid_run[q] = 0
                    d.rapid_time[q] = t
                    if d.rapid_run[q] >= COLLAPSE_EVENTS:
                        status = HardDiskStatus.COLLAPSE
                if log.on and hit:
                    slot = log.used[0]
                    log.time[slot] = t
                    log.pair[slot, 0] = i
                    log.pair[slot, 1] = j
                    log.impulse[slot, 0] = jx
                    log.impulse[slot, 1] = jy
                    log.used[0] = slot + 1
        elif j == EV_CELL:
            cross(i, t, d, cells, cover, counters)
            counters[Counter.CROSSINGS] += 1
            if counters[Counter.COVER_FULL] != 0:
                status = HardDiskStatus.COVER_FULL
        for k in range(n_sched):
            q = i if k == 0 else j
            schedule(q, t, d, cells, cover, cal, counters)
        if status != HardDiskStatus.DONE:
            return status, t, next_sync, t_drag
