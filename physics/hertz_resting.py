"""The serial Hertz step that skips floes at rest (``HertzSimulation(skip_resting=True)``).

A floe with v = 0, ω = 0 and zero total force stays exactly where it is
under velocity Verlet (x += Δt · 0, v += Δt/2 · 0). At the start of a run
(:func:`physics.hertz_step.run_awake`) a floe is *resting* when

* its velocity, angular velocity, force and torque (those of the last
  step, with which the run's first half kick is done) are all zero,
* its external forcing at rest is zero (wind and current times its drag
  coefficients; Coriolis and the water and rotational drag vanish at rest),
* it touches no floe (one pass over the Verlet list), no wall and, in a
  deforming box, the box does not move it (there no floe rests),
* it has not moved since the Verlet list was built (so that its
  displacement in the list's expiry test is exactly zero) and its skin is
  the list's own (a wide-skinned floe, :func:`~physics.hertz_kernels.wide_floes_pass`,
  is checked with a shadow position that the kick–drift pass must see).

The kick–drift pass, the walls and the drag then run over the awake floes
only, and the pair loop over the listed pairs with at least one awake floe
(the live pairs, in the order of the full loop, so that every floe's forces
are added up in the same order). A resting floe wakes when a listed pair
with an awake floe touches it or the hull pushes it (a non-zero hull force
in its force buffer); it cannot touch a wall without moving. From the next
step on it is integrated as any other and stays awake to the end of the
run. Everything else is the step of
:func:`physics.hertz_step.run_every_floe` (serial path): the per-floe
arithmetic is the same, and a resting floe would have come out of it
unchanged. Only the sums of the displacements in the list's expiry test
are added in another order (the resting floes add zeros): they can differ
in rounding, which could move a list rebuild by a step in a rare case.

A live pair found apart is not looked at again until its floes could have
closed its gap: each awake floe's *path* (the sum of |v| Δt over its drifts
in the run, plus a bound on their rounding) only grows, and two floes whose
paths together grew by less than the gap cannot have met
(:func:`~physics.hertz_kernels.apart_until`). Looking at such a pair gives
no force and leaves its history at zero, so skipping it changes nothing;
touching pairs and pairs whose gap is used up are looked at every step, as
before. The walls are skipped the same way: a floe found clear of every
wall is looked at again once its path could have closed the smallest gap.
The full serial step of :func:`~physics.hertz_step.run_every_floe` skips the
same looks.

The cost of a step is that of the awake floes and of their pairs that are
touching or close; a run adds one pass over all floes and the list at its
start, and the list rebuilds (which are over all floes in any case) rebuild
the live pairs.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from .domain import minimum_image
from .neighbors import bucket_sort
from .hertz_kernels import (KICK_FASTMATH, apart_until, first_half, floe_drag, kick_drift_pass,
                            floe_walls, floe_walls_skipping, listed_pair, max_keep_nan,
                            wall_overlap)
from .hull_contact import C_CAND

__all__ = ["Awake", "LivePairs", "find_awake", "live_pairs", "first_half_awake",
           "live_pair_forces"]


class Awake(NamedTuple):
    """The awake floes of a run."""

    #: (N,) 1 for an awake floe, 0 for a resting one
    flag: np.ndarray
    #: (N,) the awake floes in ``order[:count[0]]`` (in the order they woke)
    order: np.ndarray
    #: (N,) floes woken in this step, ``pending[:count[1]]``
    pending: np.ndarray
    #: (3,) number of awake floes, of pending floes, of live pairs
    count: np.ndarray


class LivePairs(NamedTuple):
    """The pairs of a Verlet list with at least one awake floe."""

    #: (M,) owner of each listed pair
    owner: np.ndarray
    #: (N + 1,) slice bounds of each floe's pairs as a partner in ``as_partner``
    partner_start: np.ndarray
    #: (M,) the pairs of each floe as a partner, in CSR form
    as_partner: np.ndarray
    #: (M,) the live pairs in ``live[:count[2]]`` of :class:`Awake`, in increasing order
    live: np.ndarray
    #: (M,) 1 for a live pair
    mark: np.ndarray
    #: (M,) scratch for the pairs of newly woken floes
    scratch: np.ndarray
    #: (M,) a pair found apart is not looked at again while the sum of its
    #: floes' paths (:func:`first_half_awake`) stays below this (−∞: every step)
    due: np.ndarray


@njit(cache=True, error_model="numpy")
def find_awake(floes, drive, box, verlet):
    """The :class:`Awake` floes at the start of a run: every floe but the
    resting ones (see the module docstring). ``floes.force``, ``torque``
    are the forces the run's first half kick uses."""
    pos, vel, omega, radius, inv_mass = (floes.pos, floes.vel, floes.omega, floes.radius,
                                         floes.inv_mass)
    force, torque, ref, coef = floes.force, floes.torque, verlet.ref, drive.coefficients
    n = pos.shape[0]
    flag = np.zeros(n, dtype=np.uint8)
    lx, ly = box.lengths[0], box.lengths[1]
    px, py = box.periodic_x, box.periodic_y
    for i in range(n):
        still = (vel[i, 0] == 0.0 and vel[i, 1] == 0.0 and omega[i] == 0.0
                 and force[i, 0] == 0.0 and force[i, 1] == 0.0 and torque[i] == 0.0
                 and pos[i, 0] == ref[i, 0] and pos[i, 1] == ref[i, 1] and not box.deforming)
        if still and drive.active:
            fx, fy, _ = floe_drag(0.0, 0.0, 0.0, coef[i, 0], coef[i, 1], coef[i, 2], coef[i, 3],
                                  drive.wind_x, drive.wind_y, drive.current_x, drive.current_y,
                                  drive.wind_speed)
            still = fx == 0.0 and fy == 0.0
        for side in range(4):
            if (side < 2 and px) or (side >= 2 and py) or inv_mass[i] == 0.0:
                continue
            still = still and wall_overlap(side, pos[i, 0], pos[i, 1], radius[i], lx, ly)[0] <= 0.0
        flag[i] = 0 if still else 1
    for k in range(verlet.wide.shape[0]):
        flag[verlet.wide[k]] = 1
    start, nbr = verlet.start, verlet.nbr
    for i in range(n):
        for p in range(start[i], start[i + 1]):
            j = nbr[p]
            if inv_mass[i] + inv_mass[j] == 0.0:
                continue                    # two frozen floes never touch (pair_contact)
            dx = minimum_image(pos[j, 0] - pos[i, 0], lx, px)
            dy = minimum_image(pos[j, 1] - pos[i, 1], ly, py)
            rsum = radius[i] + radius[j]
            if dx * dx + dy * dy < rsum * rsum:
                flag[i] = 1
                flag[j] = 1
    order = np.nonzero(flag)[0]
    count = np.zeros(3, dtype=np.int64)
    count[0] = order.shape[0]
    full = np.empty(n, dtype=np.int64)
    full[:order.shape[0]] = order
    return Awake(flag, full, np.empty(n, dtype=np.int64), count)


@njit(cache=True, error_model="numpy")
def pair_index(verlet):
    """(owner of each listed pair, and each floe's pairs as a partner in CSR
    form: slice bounds and pairs) of the Verlet list ``verlet``."""
    start, nbr = verlet.start, verlet.nbr
    n = start.shape[0] - 1
    owner = np.empty(nbr.shape[0], dtype=np.int64)
    for i in range(n):
        for p in range(start[i], start[i + 1]):
            owner[p] = i
    partner_start, as_partner = bucket_sort(nbr, n)
    return owner, partner_start, as_partner


@njit(cache=True, error_model="numpy")
def live_pairs(verlet, awake):
    """The :class:`LivePairs` of ``verlet`` (after a build) for the floes
    awake now; their number goes to ``awake.count[2]``."""
    nbr, flag = verlet.nbr, awake.flag
    m = nbr.shape[0]
    owner, partner_start, as_partner = pair_index(verlet)
    live = np.empty(m, dtype=np.int64)
    mark = np.zeros(m, dtype=np.uint8)
    n_live = 0
    for p in range(m):
        j = nbr[p]
        if flag[owner[p]] or flag[j]:
            mark[p] = 1
            live[n_live] = p
            n_live += 1
    awake.count[2] = n_live
    return LivePairs(owner, partner_start, as_partner, live, mark, np.empty(m, dtype=np.int64),
                     np.full(m, -np.inf))


@njit(cache=True, inline="always", error_model="numpy")
def wake(i, awake):
    """Floe i is pushed: wake it (it is integrated from the next step on)."""
    if awake.flag[i] == 0:
        awake.flag[i] = 1
        awake.pending[awake.count[1]] = i
        awake.count[1] += 1


@njit(cache=True, error_model="numpy", _nrt=False)
def add_woken(awake, verlet, pairs):
    """The floes woken in this step join the awake ones, and their listed
    pairs the live ones (merged in, in increasing order)."""
    count, start = awake.count, verlet.start
    live, mark, scratch = pairs.live, pairs.mark, pairs.scratch
    n_new = 0
    for q in range(count[1]):
        i = awake.pending[q]
        awake.order[count[0]] = i
        count[0] += 1
        for p in range(start[i], start[i + 1]):
            if mark[p] == 0:
                mark[p] = 1
                scratch[n_new] = p
                n_new += 1
        for k in range(pairs.partner_start[i], pairs.partner_start[i + 1]):
            p = pairs.as_partner[k]
            if mark[p] == 0:
                mark[p] = 1
                scratch[n_new] = p
                n_new += 1
    count[1] = 0
    if n_new == 0:
        return
    # insertion sort of the few new pairs, then a merge from the back
    for a in range(1, n_new):
        x = scratch[a]
        b = a - 1
        while b >= 0 and scratch[b] > x:
            scratch[b + 1] = scratch[b]
            b -= 1
        scratch[b + 1] = x
    a = count[2] - 1
    b = n_new - 1
    w = count[2] + n_new - 1
    while b >= 0:
        if a >= 0 and live[a] > scratch[b]:
            live[w] = live[a]
            a -= 1
        else:
            live[w] = scratch[b]
            b -= 1
        w -= 1
    count[2] += n_new


@njit(cache=True, fastmath=KICK_FASTMATH, error_model="numpy", _nrt=False)
def first_half_awake(floes, ref, drive, kick, awake, path):
    """:func:`~physics.hertz_kernels.first_half` over the awake floes
    (:func:`~physics.hertz_kernels.kick_drift_floe`, the same arithmetic).
    The largest squared distance from the centre includes that of the
    resting floes (displacement 0: |centre|²) when there are any.

    Each awake floe's ``path`` grows by a bound on the length of its drift,
    |v| Δt and the rounding of the new position
    (:func:`~physics.hertz_kernels.drift_bound`).

    With half the floes or more awake, the pass runs over all of them
    instead, in :func:`~physics.hertz_kernels.first_half`, whose loop
    vectorises (about 4 ns a floe against 9 for the awake ones one by one):
    a resting floe comes out of it as it went in (no velocity, force or
    drag; the displacement from its list position is zero), so the new state
    is the same."""
    order, n_awake = awake.order, awake.count[0]
    n = floes.inv_mass.shape[0]
    if 2 * n_awake >= n:
        return first_half(floes, ref, drive, kick, path)
    e2_max, sdx, sdy, vmax2, _ = kick_drift_pass(floes, ref, drive, kick, path, order, n_awake)
    if n_awake < n:
        e2_max = max_keep_nan(e2_max, kick.cx * kick.cx + kick.cy * kick.cy)
    return e2_max, sdx, sdy, vmax2


@njit(cache=True, error_model="numpy", _nrt=False)
def live_pair_forces(pairs, awake, floes, law, box, verlet, dt_history, path, force, torque):
    """The forces of the live pairs (the loop of
    :func:`~physics.hertz_kernels.owner_pairs` over them: each owner's
    pairs in list order, its sum added at the end), waking the resting
    floes they touch.

    A pair found apart is not looked at again until the paths of its two
    floes have grown by its gap (``pairs.due``,
    :func:`~physics.hertz_kernels.apart_until`): until then it cannot touch,
    and looking would give no force and leave its (zero) history as it is.
    Not in a deforming box, whose remap moves the floes by more than they
    drift."""
    pos, vel, omega, radius, inv_mass = (floes.pos, floes.vel, floes.omega, floes.radius,
                                         floes.inv_mass)
    live, owner, nbr, hist, due = pairs.live, pairs.owner, verlet.nbr, verlet.hist, pairs.due
    lx, ly = box.lengths[0], box.lengths[1]
    px, py = box.periodic_x, box.periodic_y
    skip = not box.deforming
    n_live = awake.count[2]
    q = 0
    while q < n_live:
        i = owner[live[q]]
        xi_, yi_ = pos[i, 0], pos[i, 1]
        vxi, vyi, wi, ri, imi = vel[i, 0], vel[i, 1], omega[i], radius[i], inv_mass[i]
        path_i = path[i]
        fxi = 0.0
        fyi = 0.0
        tqi = 0.0
        touched = False
        while q < n_live and owner[live[q]] == i:
            p = live[q]
            q += 1
            j = nbr[p]
            paths = 0.0
            if skip:
                paths = path_i + path[j]
                if paths < due[p]:
                    continue
            dx = minimum_image(pos[j, 0] - xi_, lx, px)
            dy = minimum_image(pos[j, 1] - yi_, ly, py)
            res = listed_pair(p, j, dx, dy, vxi, vyi, wi, ri, imi, floes, law, hist, dt_history)
            if res[0]:
                fxi += res[1]
                fyi += res[2]
                tqi += res[3]
                force[j, 0] -= res[1]
                force[j, 1] -= res[2]
                torque[j] += res[4]
                touched = True
                wake(j, awake)
            elif skip:
                due[p] = apart_until(dx, dy, ri + radius[j], paths)
        if fxi != 0.0 or fyi != 0.0 or tqi != 0.0:
            force[i, 0] += fxi
            force[i, 1] += fyi
            torque[i] += tqi
        if touched:
            wake(i, awake)


@njit(cache=True, error_model="numpy", _nrt=False)
def awake_wall_forces(awake, floes, wall_law, box, dt_history, path, wall_due, force, torque):
    """:func:`~physics.hertz_kernels.wall_forces` of the awake floes (a
    resting floe touches no wall). As with the pairs, a floe found clear of
    every wall is not looked at again until its path passes ``wall_due``
    (:func:`~physics.hertz_kernels.walls_apart_until`); not in a deforming
    box, whose walls move."""
    skip = not box.deforming
    for q in range(awake.count[0]):
        i = awake.order[q]
        if skip:
            floe_walls_skipping(i, floes, wall_law, box, dt_history, force, torque, path,
                                wall_due)
        else:
            floe_walls(i, floes, wall_law, box, dt_history, force, torque)


@njit(cache=True, error_model="numpy", _nrt=False)
def hull_wakes(ship, awake, force, torque):
    """Wake the resting floes of the hull's list that the hull pushed in
    this step (their force buffer, zero while they rest, is not)."""
    for k in range(ship.counts[C_CAND]):
        i = ship.cand[k]
        if force[i, 0] != 0.0 or force[i, 1] != 0.0 or torque[i] != 0.0:
            wake(i, awake)


