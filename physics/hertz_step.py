"""The velocity-Verlet step of the Hertz engine, written once.

Every run of the engine (:meth:`physics.hertz.HertzSimulation.step`, the
batches of :mod:`physics.hertz_batch`) goes through one choice of the step's
form (:func:`run_steps`, or :func:`run_one`, the same function run by
Python for one simulation, so that only its form is compiled), and
every step of every run through one loop, :func:`substeps`. A step is, in
LAMMPS ``fix nve/sphere`` order:

1. the box's lengths after the step and the ship's kick–drift
   (:func:`~physics.hertz_kernels.begin_step`);
2. the floes' half kick with the last forces, their drift, the affine remap
   of a deforming box and their new drag forces (the kick–drift pass);
3. the wall forces, then the hull's contacts (:mod:`physics.hull_contact`);
4. the Verlet list's expiry test (:mod:`physics.neighbors`), and its rebuild;
5. the pair forces at t + Δt with the half-step velocities (the Hertz force
   of :mod:`physics.contact`), added to the drag, wall and hull forces; the
   next step's half kick completes the step's velocities (leapfrog).

What differs between the step's forms is which floes move and which pairs
are looked at, and that is one argument of :func:`substeps`, the *movers*.
Its type selects, when the loop is compiled, the form of each phase:

* :class:`EveryFloe`: all floes and all pairs, serial; pairs and walls that
  cannot touch yet are not looked at (their floes' paths, a rigid box);
* :class:`EveryFloeParallel`: all floes and all pairs, each phase one
  parallel region over the chunks of :mod:`physics.hertz_kernels`;
* :class:`AwakeFloes`: the floes awake and the pairs live, floes at rest
  left as they are (``skip_resting``, :mod:`physics.hertz_resting`);
* :class:`WindowFloes`: the floes engaged in a free-drift window, the free
  ones moved in closed form when they are next needed (``free_drift``,
  :mod:`physics.hertz_free_drift`).

:func:`substeps` allocates nothing (it is compiled without reference
counting) and stops when the run is done, fails, or the list expires. The
run around it (:func:`run_steps`) rebuilds the list, which allocates,
finishes the step whose list expired and goes on. The step's form is chosen
in one place, ``_run_steps``, from the simulation's mode (:data:`MODES`).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit
from numba.extending import overload

from .hertz_free_drift import (WindowPairs, all_pairs_live, awake_all, classify, drift_table,
                               engaged_pass, engaged_wide_pass, new_pairs, repair, sync_free)
from .hertz_kernels import (STATUS_NON_FINITE, STATUS_OK, STATUS_SHIP_LOG_FULL, ForceBuffers,
                            PairChunks, begin_step, end_run, first_half, first_half_parallel,
                            floe_rows, force_buffers, gather_cut, list_expired, owner_pairs,
                            pair_chunks, pair_forces_parallel, pass_status, rebuild_in_run,
                            wall_forces, wall_forces_parallel, wide_floes_pass)
from .hertz_resting import (Awake, LivePairs, add_woken, awake_wall_forces, find_awake,
                            first_half_awake, hull_wakes, live_pair_forces, live_pairs, wake)
from .hull_contact import S_FLOE_TRAVEL, hull_forces, hull_point_speed

__all__ = ["MODES", "MODE_FULL", "MODE_RESTING", "MODE_FREE", "MODE_FREE_ITERATED",
           "EveryFloe", "EveryFloeParallel", "AwakeFloes", "WindowFloes", "substeps",
           "run_steps", "run_one"]

#: the step's forms, by their number in :func:`run_steps` (``HertzSimulation._step_mode``)
MODES = ("full", "skip resting", "free drift", "free drift, stepped")
MODE_FULL, MODE_RESTING, MODE_FREE, MODE_FREE_ITERATED = range(4)


class EveryFloe(NamedTuple):
    """The serial step over all floes and pairs."""

    #: (N,) each floe's path in the run (a bound on how far it drifted)
    path: np.ndarray
    #: (M,) a pair found apart is not looked at while its floes' paths sum below this
    due: np.ndarray
    #: (N,) a floe found clear of the walls is not looked at while its path is below this
    wall_due: np.ndarray
    #: the owners of the list, in the order of the pair loop
    chunks: PairChunks
    #: whether the looks that cannot touch are skipped (a rigid box)
    skip: bool


class EveryFloeParallel(NamedTuple):
    """The parallel step over all floes and pairs."""

    #: chunks of the parallel passes (:func:`~physics.hertz_kernels.chunk_count`)
    n_chunks: int
    #: the chunks of the pair loop and the cut pairs' slots (the parallel
    #: step looks at every pair and wall: it keeps no paths)
    chunks: PairChunks


class AwakeFloes(NamedTuple):
    """The serial step over the awake floes and the live pairs."""

    awake: Awake
    pairs: LivePairs
    path: np.ndarray
    wall_due: np.ndarray


class WindowFloes(NamedTuple):
    """The serial step over the floes engaged in a free-drift window."""

    awake: Awake
    pairs: WindowPairs
    path: np.ndarray
    wall_due: np.ndarray
    #: the free floes' recurrences (:func:`~physics.hertz_free_drift.drift_table`)
    table: tuple
    #: (N, 6) each floe's straight line, budget and speed bound
    lines: np.ndarray
    #: (6,) the window's bounds (:func:`~physics.hertz_free_drift.classify`)
    bounds: np.ndarray
    #: (N,) 1 for a floe near the hull, plus 2 for one with a wide skin
    mark: np.ndarray
    #: whether the free floes are stepped one step at a time
    iterate: bool
    #: (9,) the window's counts: free floes, first step, end step, engaged
    #: floe-steps, lines renewed, floes engaged, floes that left their lines
    #: this step, whether this step ends the window, whether the hull's guard
    #: failed
    counts: np.ndarray
    #: (4,) the hull's travel in the window, the free floes' travel unseen by
    #: a hull list (already counted), the window's span [s], the first kick [s]
    clock: np.ndarray


# what WindowFloes.counts holds
(W_FREE, W_START, W_END, W_ENGAGED_STEPS, W_LINES, W_ENGAGED, W_BROKEN, W_LAST,
 W_HULL_BROKEN) = range(9)
# what WindowFloes.clock holds
W_HULL_PATH, W_UNSEEN, W_SPAN, W_KICK0 = range(4)


def _kind(movers):
    """The form of the step that a movers type stands for (at compile time)."""
    return getattr(movers, "instance_class", None)


def _form(movers, every=None, parallel=None, awake=None, window=None):
    """A phase's implementation for the form of ``movers`` (an overload's
    choice, at compile time): ``every`` for :class:`EveryFloe`, ``parallel``
    for :class:`EveryFloeParallel`, ``awake`` for :class:`AwakeFloes`,
    ``window`` for :class:`WindowFloes`; None for a form not given."""
    return {EveryFloe: every, EveryFloeParallel: parallel, AwakeFloes: awake,
            WindowFloes: window}.get(_kind(movers))


# -- the phases: each a stub whose form is compiled per movers type ----------
# (``overload(..., inline="always")``: the chosen form becomes part of the
# loop, compiled with its flags, and the other forms are never compiled in)

def travel_phase(movers, ship, dt):
    """Before the pass, in a free-drift window: the hull's travel."""
    raise NotImplementedError


def kick_phase(movers, work, floes, verlet, drive, kick, step):
    """The kick–drift pass: (worst, Σ dx, Σ dy, largest squared speed) of
    :func:`~physics.hertz_kernels.first_half`."""
    raise NotImplementedError


def window_phase(movers, run, work, verlet, step, dt, worst):
    """After the pass, a free-drift window's guards (floes that left their
    lines, the hull's travel, the window's end): (ok, worst)."""
    raise NotImplementedError


def wall_phase(movers, floes, wall_law, box, dt, fbuf, tbuf):
    """The wall forces, added to the buffers."""
    raise NotImplementedError


def hull_phase(movers, ship, floes, box, time, dt, vmax2, fbuf, tbuf):
    """The hull's contacts: False when the ship's collision log is full."""
    raise NotImplementedError


def wide_phase(movers, pos, verlet, lx, ly, px, py, kick, cx_new, cy_new, worst):
    """The expiry test of the floes with a wide skin (and, but in a window,
    the list's new displacement centre): the new worst."""
    raise NotImplementedError


def expiry_phase(movers, run, work, verlet, step, dt):
    """What an expired list needs before the run rebuilds it: False when a
    state is not finite."""
    raise NotImplementedError


def pair_phase(movers, floes, law, box, verlet, dt, fbuf, tbuf):
    """The pair forces, added to the buffers."""
    raise NotImplementedError


def ends_window(movers):
    """Whether this step ends the piece of the run (a free-drift window)."""
    raise NotImplementedError


@overload(travel_phase, inline="always")
def _travel_phase(movers, ship, dt):
    if _kind(movers) is not WindowFloes:
        return lambda movers, ship, dt: None

    def impl(movers, ship, dt):
        if ship.active:
            movers.clock[W_HULL_PATH] += dt * hull_point_speed(ship) * (1.0 + 1e-12)
    return impl


@overload(kick_phase, inline="always")
def _kick_phase(movers, work, floes, verlet, drive, kick, step):
    def every(movers, work, floes, verlet, drive, kick, step):
        return first_half(work, verlet.ref, drive, kick, movers.path)

    def parallel(movers, work, floes, verlet, drive, kick, step):
        return first_half_parallel(movers.n_chunks, floes,
                                   ForceBuffers(work.force, work.torque), movers.chunks,
                                   verlet.ref, drive, kick)

    def awake(movers, work, floes, verlet, drive, kick, step):
        return first_half_awake(work, verlet.ref, drive, kick, movers.awake, movers.path)

    def window(movers, work, floes, verlet, drive, kick, step):
        counts = movers.counts
        if counts[W_FREE] == 0:
            worst, mx, my, vmax2 = first_half(work, verlet.ref, drive, kick, movers.path)
            counts[W_BROKEN] = 0
        else:
            worst, mx, my, vmax2, n_broken = engaged_pass(
                work, verlet.ref, drive, kick, movers.awake, movers.path, movers.lines,
                (step + 1 - counts[W_START]) * kick.dt, movers.pairs.stack)
            counts[W_BROKEN] = n_broken
        counts[W_ENGAGED_STEPS] += movers.awake.count[0]
        return worst, mx, my, vmax2

    return _form(movers, every, parallel, awake, window)


@overload(window_phase, inline="always")
def _window_phase(movers, run, work, verlet, step, dt, worst):
    if _kind(movers) is not WindowFloes:
        return lambda movers, run, work, verlet, step, dt, worst: (True, worst)

    def impl(movers, run, work, verlet, step, dt, worst):
        floes, law, wall_law, drive, box, ship = run
        counts, clock, bounds = movers.counts, movers.clock, movers.bounds
        fbuf, tbuf = work.force, work.torque
        n_done = step - counts[W_START]
        last = step >= counts[W_END]
        counts[W_HULL_BROKEN] = 0
        ok = True
        if counts[W_FREE] > 0:
            reach = bounds[2] + bounds[3] * (n_done * dt)
            worst = max(worst, reach * reach)
            hull_broken = clock[W_HULL_PATH] > bounds[0]
            counts[W_HULL_BROKEN] = hull_broken
            if counts[W_BROKEN] > 0 and not hull_broken:
                # floes that left their lines: new lines, and the floes and
                # pairs they may reach engaged and live from this step on
                ok, n_new, n_renewed, unseen = repair(
                    counts[W_BROKEN], floes, fbuf, tbuf, drive, movers.table, box, verlet,
                    movers.awake, movers.pairs, movers.lines, movers.mark, movers.path, dt,
                    clock[W_KICK0], n_done, clock[W_SPAN], bounds[4], bounds[5],
                    movers.iterate)
                if not ok:
                    return False, worst
                counts[W_FREE] -= n_new
                counts[W_LINES] += n_renewed
                counts[W_ENGAGED] += n_new
                if ship.active and unseen > clock[W_UNSEEN]:
                    # a hull list built earlier in the window saw them where
                    # it began
                    ship.state[S_FLOE_TRAVEL] += unseen - clock[W_UNSEEN]
                    clock[W_UNSEEN] = unseen
                if counts[W_FREE] == 0:
                    # no free floe left: no guard either, so every pair is live
                    all_pairs_live(verlet, movers.awake, movers.pairs)
            last = last or hull_broken
            if last and counts[W_FREE] > 0:
                ok = sync_free(floes, fbuf, tbuf, drive, movers.table, box, movers.awake,
                               movers.lines, movers.path, dt, clock[W_KICK0], n_done,
                               movers.iterate, verlet.ref)
                counts[W_FREE] = 0
        counts[W_LAST] = last
        return ok, worst
    return impl


@overload(wall_phase, inline="always")
def _wall_phase(movers, floes, wall_law, box, dt, fbuf, tbuf):
    def every(movers, floes, wall_law, box, dt, fbuf, tbuf):
        if movers.skip:
            wall_forces(0, floes.pos.shape[0], floes, wall_law, box, dt, fbuf, tbuf,
                        movers.path, movers.wall_due)
        else:
            wall_forces(0, floes.pos.shape[0], floes, wall_law, box, dt, fbuf, tbuf)

    def parallel(movers, floes, wall_law, box, dt, fbuf, tbuf):
        wall_forces_parallel(floes, wall_law, box, dt, fbuf, tbuf)

    def awake(movers, floes, wall_law, box, dt, fbuf, tbuf):
        awake_wall_forces(movers.awake, floes, wall_law, box, dt, movers.path,
                          movers.wall_due, fbuf, tbuf)

    return _form(movers, every, parallel, awake, window=awake)


@overload(hull_phase, inline="always")
def _hull_phase(movers, ship, floes, box, time, dt, vmax2, fbuf, tbuf):
    def every(movers, ship, floes, box, time, dt, vmax2, fbuf, tbuf):
        return hull_forces(ship, floes, box, time, dt, math.sqrt(vmax2), fbuf, tbuf)

    def awake(movers, ship, floes, box, time, dt, vmax2, fbuf, tbuf):
        logged = hull_forces(ship, floes, box, time, dt, math.sqrt(vmax2), fbuf, tbuf)
        hull_wakes(ship, movers.awake, fbuf, tbuf)
        return logged

    def window(movers, ship, floes, box, time, dt, vmax2, fbuf, tbuf):
        floe_speed = max(math.sqrt(vmax2), movers.bounds[1])
        if movers.counts[W_FREE] > 0:
            return hull_forces(ship, floes, box, time, dt, floe_speed, fbuf, tbuf,
                               movers.awake.flag)
        return hull_forces(ship, floes, box, time, dt, floe_speed, fbuf, tbuf)

    return _form(movers, every, every, awake, window)


@overload(wide_phase, inline="always")
def _wide_phase(movers, pos, verlet, lx, ly, px, py, kick, cx_new, cy_new, worst):
    if _kind(movers) is WindowFloes:
        # the list's centre is held through a window
        def impl(movers, pos, verlet, lx, ly, px, py, kick, cx_new, cy_new, worst):
            if movers.counts[W_FREE] > 0:
                return engaged_wide_pass(pos, verlet, lx, ly, px, py, kick.cx, kick.cy, worst,
                                         movers.pairs.wide)
            if verlet.wide.shape[0] > 0:
                return wide_floes_pass(pos, verlet, lx, ly, px, py, kick.cx, kick.cy, kick.cx,
                                       kick.cy, worst)
            return worst
        return impl

    def impl(movers, pos, verlet, lx, ly, px, py, kick, cx_new, cy_new, worst):
        if verlet.wide.shape[0] > 0:
            worst = wide_floes_pass(pos, verlet, lx, ly, px, py, kick.cx, kick.cy, cx_new,
                                    cy_new, worst)
        verlet.centre[0] = cx_new
        verlet.centre[1] = cy_new
        return worst
    return impl


@overload(expiry_phase, inline="always")
def _expiry_phase(movers, run, work, verlet, step, dt):
    if _kind(movers) is not WindowFloes:
        return lambda movers, run, work, verlet, step, dt: True

    def impl(movers, run, work, verlet, step, dt):
        floes, law, wall_law, drive, box, ship = run
        counts = movers.counts
        if counts[W_FREE] == 0:
            return True
        ok = sync_free(floes, work.force, work.torque, drive, movers.table, box, movers.awake,
                       movers.lines, movers.path, dt, movers.clock[W_KICK0],
                       step - counts[W_START], movers.iterate, verlet.ref)
        counts[W_FREE] = 0
        return ok
    return impl


@overload(pair_phase, inline="always")
def _pair_phase(movers, floes, law, box, verlet, dt, fbuf, tbuf):
    def every(movers, floes, law, box, verlet, dt, fbuf, tbuf):
        owners = movers.chunks.owners
        if movers.skip:
            owner_pairs(0, owners.shape[0], owners, floes, law, box, verlet, dt, fbuf, tbuf,
                        0, 0, None, None, movers.path, movers.due)
        else:
            owner_pairs(0, owners.shape[0], owners, floes, law, box, verlet, dt, fbuf, tbuf)

    def parallel(movers, floes, law, box, verlet, dt, fbuf, tbuf):
        pair_forces_parallel(movers.chunks, floes, law, box, verlet, dt,
                             ForceBuffers(fbuf, tbuf))

    def awake(movers, floes, law, box, verlet, dt, fbuf, tbuf):
        live_pair_forces(movers.pairs, movers.awake, floes, law, box, verlet, dt,
                         movers.path, fbuf, tbuf)
        if movers.awake.count[1] > 0:
            add_woken(movers.awake, verlet, movers.pairs)

    def window(movers, floes, law, box, verlet, dt, fbuf, tbuf):
        if movers.counts[W_HULL_BROKEN]:
            # the hull's guard failed: a free floe may touch an engaged one now
            all_pairs_live(verlet, movers.awake, movers.pairs)
        live_pair_forces(movers.pairs, movers.awake, floes, law, box, verlet, dt,
                         movers.path, fbuf, tbuf)

    return _form(movers, every, parallel, awake, window)


@overload(ends_window, inline="always")
def _ends_window(movers):
    if _kind(movers) is not WindowFloes:
        return lambda movers: False

    def impl(movers):
        if movers.counts[W_LAST]:
            # a pair of this step may have woken a floe of the synced ones
            # (no matter: all are up to date and the next window sorts them)
            movers.awake.count[1] = 0
            return True
        return False
    return impl


# -- the loop ------------------------------------------------------------------
def _substeps(step, end, dt, time, run, work, verlet, movers):
    """Steps ``step`` … ``end`` − 1 of a run, until they are done, the run
    fails, or the Verlet list expires (the caller rebuilds it and finishes
    that step: its pair forces and the ship's log).

    ``run`` is (floes, law, wall law, drive, box, ship bundle), ``work`` the
    floes' rows with the run's force buffer as their forces
    (:func:`~physics.hertz_kernels.floe_rows`), ``verlet`` the list and
    ``movers`` the step's form (module docstring). It allocates nothing.

    Returns (next step, steps done, status, whether the list expired,
    whether the ship's log is full, the box's lengths after the last step)."""
    floes, law, wall_law, drive, box, ship = run
    px = box.periodic_x
    py = box.periodic_y
    walls = not (px and py)
    n = floes.pos.shape[0]
    fbuf, tbuf = work.force, work.torque
    done = 0
    status = STATUS_OK
    log_full = False
    expired = False
    lx = 0.0
    ly = 0.0
    while step < end:
        status, kick = begin_step(box, time, step, dt, verlet.centre, ship)
        if status != STATUS_OK:
            break
        lx, ly = kick.lx, kick.ly
        travel_phase(movers, ship, dt)
        worst, mx, my, vmax2 = kick_phase(movers, work, floes, verlet, drive, kick, step)
        done += 1
        step += 1
        status = pass_status(worst, mx, my, vmax2, dt, verlet.skin)
        if status != STATUS_OK:
            break
        ok, worst = window_phase(movers, run, work, verlet, step, dt, worst)
        if not ok:
            status = STATUS_NON_FINITE
            break
        if walls:
            wall_phase(movers, floes, wall_law, box, dt, fbuf, tbuf)
        if ship.active:
            log_full = not hull_phase(movers, ship, floes, box, time + step * dt, dt, vmax2,
                                      fbuf, tbuf)
        worst = wide_phase(movers, floes.pos, verlet, lx, ly, px, py, kick, mx / n, my / n,
                           worst)
        if list_expired(worst, lx, ly, verlet):
            if not expiry_phase(movers, run, work, verlet, step, dt):
                status = STATUS_NON_FINITE
                break
            expired = True
            break
        pair_phase(movers, floes, law, box, verlet, dt, fbuf, tbuf)
        if log_full:
            status = STATUS_SHIP_LOG_FULL
            break
        if ends_window(movers):
            break
    return step, done, status, expired, log_full, lx, ly


#: the loop of the serial forms, compiled without Numba's reference counting
#: (it allocates nothing): in a loop this short, counting every array taken
#: from a bundle in and out costs as much as the rest of a step of a ship
#: among a few floes
substeps = njit(cache=True, error_model="numpy", _nrt=False)(_substeps)
#: the same loop for the parallel form (:class:`EveryFloeParallel`), whose
#: parallel regions allocate their partial results and so need the counting
substeps_counted = njit(cache=True, error_model="numpy")(_substeps)


def loop(movers, step, end, dt, time, run, work, verlet):
    """:func:`substeps` for the movers' form (:data:`substeps_counted` for
    the parallel one)."""
    raise NotImplementedError


@overload(loop, inline="always")
def _loop(movers, step, end, dt, time, run, work, verlet):
    if _kind(movers) is EveryFloeParallel:
        def impl(movers, step, end, dt, time, run, work, verlet):
            return substeps_counted(step, end, dt, time, run, work, verlet, movers)
    else:
        def impl(movers, step, end, dt, time, run, work, verlet):
            return substeps(step, end, dt, time, run, work, verlet, movers)
    return impl


# -- the runs around the loop ----------------------------------------------------
def rebuilt(movers, run, verlet, lx, ly, dt):
    """The list rebuilt after it expired, and the movers for the new list:
    (verlet, movers)."""
    raise NotImplementedError


@overload(rebuilt, inline="always")
def _rebuilt(movers, run, verlet, lx, ly, dt):
    def every(movers, run, verlet, lx, ly, dt):
        floes, box, ship = run[0], run[4], run[5]
        verlet = rebuild_in_run(floes, verlet, lx, ly, box.periodic_x, box.periodic_y, False,
                                ship, box.deforming, dt)
        return verlet, EveryFloe(movers.path, np.full(verlet.nbr.shape[0], -np.inf),
                                 movers.wall_due, pair_chunks(verlet, 1), movers.skip)

    def parallel(movers, run, verlet, lx, ly, dt):
        floes, box, ship = run[0], run[4], run[5]
        verlet = rebuild_in_run(floes, verlet, lx, ly, box.periodic_x, box.periodic_y, True,
                                ship, box.deforming, dt)
        return verlet, EveryFloeParallel(movers.n_chunks, pair_chunks(verlet, movers.n_chunks))

    def awake(movers, run, verlet, lx, ly, dt):
        floes, box, ship = run[0], run[4], run[5]
        verlet = rebuild_in_run(floes, verlet, lx, ly, box.periodic_x, box.periodic_y, False,
                                ship, box.deforming, dt)
        awake = movers.awake
        # the new wide floes are integrated (their shadow positions must
        # be in the kick-drift pass); the pending floes' pairs are live
        for k in range(verlet.wide.shape[0]):
            wake(verlet.wide[k], awake)
        pairs = live_pairs(verlet, awake)
        add_woken(awake, verlet, pairs)
        return verlet, AwakeFloes(awake, pairs, movers.path, movers.wall_due)

    return _form(movers, every, parallel, awake)


@njit(cache=True, error_model="numpy")
def run_pieces(n_steps, dt, time, run, work, verlet, movers):
    """:func:`substeps` until the run is done or fails, the list rebuilt
    whenever it expires (and that step finished). Returns (steps done,
    status, list rebuilds, the list now, the movers now)."""
    done = 0
    n_rebuilds = 0
    status = STATUS_OK
    step = 0
    floes, law, box = run[0], run[1], run[4]
    while step < n_steps:
        step, d, status, expired, log_full, lx, ly = loop(movers, step, n_steps, dt, time, run,
                                                          work, verlet)
        done += d
        if not expired:
            break
        verlet, movers = rebuilt(movers, run, verlet, lx, ly, dt)
        n_rebuilds += 1
        pair_phase(movers, floes, law, box, verlet, dt, work.force, work.torque)
        if log_full:
            status = STATUS_SHIP_LOG_FULL
            break
    return done, status, n_rebuilds, verlet, movers


@njit(cache=True, error_model="numpy")
def start_run(run):
    """The force buffer of a run, holding the floes' last forces, and the
    floes' rows that kick with it: (buffers, work)."""
    floes = run[0]
    n = floes.pos.shape[0]
    buffers = force_buffers(n)
    buffers.force[:] = floes.force
    buffers.torque[:] = floes.torque
    return buffers, floe_rows(floes, 0, n, buffers)


@njit(cache=True, error_model="numpy")
def run_every_floe(n_steps, dt, time, run, verlet):
    """The full serial step (:class:`EveryFloe`): returns (steps done,
    status, list rebuilds, the list now)."""
    n, box = run[0].pos.shape[0], run[4]
    return run_chunked(n_steps, dt, time, run, verlet,
                       EveryFloe(np.zeros(n), np.full(verlet.nbr.shape[0], -np.inf),
                                 np.full(n, -np.inf), pair_chunks(verlet, 1), not box.deforming))


@njit(cache=True, error_model="numpy")
def run_every_floe_parallel(n_steps, dt, time, run, verlet, n_chunks):
    """The full parallel step (:class:`EveryFloeParallel`, ``n_chunks``
    chunks): returns (steps done, status, list rebuilds, the list now)."""
    return run_chunked(n_steps, dt, time, run, verlet,
                       EveryFloeParallel(n_chunks, pair_chunks(verlet, n_chunks)))


@njit(cache=True, error_model="numpy")
def run_chunked(n_steps, dt, time, run, verlet, movers):
    """A full step's run (``movers``: :class:`EveryFloe` or
    :class:`EveryFloeParallel`, whose pairs come in chunks): the pieces,
    then the forces each chunk cut gathered and the run ended. Returns
    (steps done, status, list rebuilds, the list now)."""
    floes, ship = run[0], run[5]
    buffers, work = start_run(run)
    done, status, n_rebuilds, verlet, movers = run_pieces(n_steps, dt, time, run, work, verlet,
                                                          movers)
    gather_cut(0, floes.pos.shape[0], movers.chunks, buffers.force, buffers.torque)
    end_run(floes, buffers.force, buffers.torque, done, dt, ship)
    return done, status, n_rebuilds, verlet


@njit(cache=True, error_model="numpy")
def run_awake(n_steps, dt, time, run, verlet):
    """The step over the awake floes (:class:`AwakeFloes`,
    :mod:`physics.hertz_resting`): returns (steps done, status, list
    rebuilds, the list now, floes awake at the end)."""
    floes, drive, box, ship = run[0], run[3], run[4], run[5]
    n = floes.pos.shape[0]
    buffers, work = start_run(run)
    awake = find_awake(floes, drive, box, verlet)
    movers = AwakeFloes(awake, live_pairs(verlet, awake), np.zeros(n), np.full(n, -np.inf))
    done, status, n_rebuilds, verlet, movers = run_pieces(n_steps, dt, time, run, work, verlet,
                                                          movers)
    end_run(floes, buffers.force, buffers.torque, done, dt, ship)
    return done, status, n_rebuilds, verlet, awake.count[0]


@njit(cache=True, error_model="numpy")
def run_windows(n_steps, dt, time, run, verlet, window, tally, iterate):
    """The step with free-drift windows of ``window`` steps
    (:class:`WindowFloes`, :mod:`physics.hertz_free_drift`). Adds to
    ``tally`` (:data:`~physics.hertz_free_drift.TALLY`) the windows, those
    that the hull's guard ended early, the engaged floe-steps, the steps,
    the lines renewed and the floes engaged within a window. With
    ``iterate`` the free floes are stepped one step at a time. Returns
    (steps done, status, list rebuilds, the list now, floes engaged in the
    last window)."""
    floes, law, drive, box, ship = run[0], run[1], run[3], run[4], run[5]
    n = floes.pos.shape[0]
    buffers, work = start_run(run)
    fbuf, tbuf = buffers.force, buffers.torque
    awake = Awake(np.ones(n, dtype=np.uint8), np.empty(n, dtype=np.int64),
                  np.empty(n, dtype=np.int64), np.zeros(3, dtype=np.int64))
    movers = WindowFloes(awake, new_pairs(verlet), np.zeros(n), np.full(n, -np.inf),
                         drift_table(floes, drive, dt), np.empty((n, 6)), np.zeros(6),
                         np.zeros(n, dtype=np.uint8), iterate, np.zeros(9, dtype=np.int64),
                         np.zeros(4))
    counts, clock = movers.counts, movers.clock
    n_rebuilds = 0
    done = 0
    status = STATUS_OK
    step = 0
    n_engaged = n
    while step < n_steps:
        dt_kick = 0.5 * dt if step == 0 else dt
        end = min(n_steps, step + window)
        classify(floes, fbuf, tbuf, movers.table, box, verlet, ship, dt, dt_kick, end - step,
                 awake, movers.pairs, movers.mark, movers.lines, movers.bounds)
        tally[0] += 1
        counts[:] = 0
        counts[W_FREE] = awake.count[1]
        counts[W_START] = step
        counts[W_END] = end
        clock[:] = 0.0
        clock[W_SPAN] = (end - step) * dt
        clock[W_KICK0] = dt_kick
        step, d, status, expired, log_full, lx, ly = substeps(step, end, dt, time, run, work,
                                                              verlet, movers)
        if counts[W_FREE] > 0 and d > 0:
            sync_free(floes, fbuf, tbuf, drive, movers.table, box, awake, movers.lines,
                      movers.path, dt, dt_kick, step - counts[W_START], iterate, verlet.ref)
        if ship.active:
            # a hull list built in the window saw the free floes where the
            # window began: count their travel since then as the floes' travel
            ship.state[S_FLOE_TRAVEL] += movers.bounds[1] * (step - counts[W_START]) * dt
        n_engaged = awake.count[0]
        done += d
        tally[2] += counts[W_ENGAGED_STEPS]
        tally[3] += d
        tally[4] += counts[W_LINES]
        tally[5] += counts[W_ENGAGED]
        if step < end and not expired:
            tally[1] += 1
        if status != STATUS_OK:
            break
        if not expired:
            continue
        verlet = rebuild_in_run(floes, verlet, lx, ly, box.periodic_x, box.periodic_y, False,
                                ship, box.deforming, dt)
        n_rebuilds += 1
        movers = WindowFloes(awake, new_pairs(verlet), movers.path, movers.wall_due,
                             movers.table, movers.lines, movers.bounds, movers.mark, iterate,
                             counts, clock)
        all_pairs_live(verlet, awake, movers.pairs)
        awake_all(awake, n)
        live_pair_forces(movers.pairs, awake, floes, law, box, verlet, dt, movers.path, fbuf,
                         tbuf)
        awake.count[1] = 0
        if log_full:
            status = STATUS_SHIP_LOG_FULL
            break
    end_run(floes, fbuf, tbuf, done, dt, ship)
    return done, status, n_rebuilds, verlet, n_engaged


def _run_steps(mode, n_steps, dt, time, run, verlet, window, tally):
    """Advance the floes of ``run`` (floes, law, wall law, drive, box, ship
    bundle) by ``n_steps`` serial velocity-Verlet steps in the form
    ``mode`` (:data:`MODES`): the one place where the step's form is
    chosen. ``window``, ``tally``: the free-drift windows' length and
    counts (modes 2 and 3).

    Between two steps of one call the second half kick of a step and the
    first half kick of the next are done together (leapfrog form); the
    state returned is synchronised (velocities at full steps) and
    ``floes.force``, ``floes.torque`` hold the forces of the last step.
    ``box.lengths`` is updated in place for a deforming box; the Verlet
    list is rebuilt whenever the displacement criterion of
    :mod:`physics.neighbors` could be violated. A status other than OK
    stops the run early: non-finite state, a blow-up, a deforming box at
    its concentration limit, or a full collision log of the ship.

    Returns (steps done, status (a
    :class:`~physics.hertz_kernels.HertzStatus` value), list rebuilds, the
    Verlet list now, floes awake or engaged at the end (−1 for the full
    step))."""
    if mode == MODE_RESTING:
        return run_awake(n_steps, dt, time, run, verlet)
    if mode == MODE_FREE or mode == MODE_FREE_ITERATED:
        return run_windows(n_steps, dt, time, run, verlet, window, tally,
                           mode == MODE_FREE_ITERATED)
    done, status, n_rebuilds, verlet = run_every_floe(n_steps, dt, time, run, verlet)
    return done, status, n_rebuilds, verlet, -1


#: the choice compiled, for the batches of :func:`physics.hertz_batch.run_many`
#: (every form is compiled into it)
run_steps = njit(cache=True, error_model="numpy")(_run_steps)
#: the same choice run by Python, for one simulation: only the form it runs
#: is compiled (a first step compiles about a minute less)
run_one = _run_steps
