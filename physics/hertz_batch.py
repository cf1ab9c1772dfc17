"""Several Hertz simulations in one compiled call: :func:`run_many`, which
:func:`physics.hertz.advance_together` calls (and through it the native
vector environments of :mod:`iceenvs.vector`), and :func:`ice_near_many`,
the ice around a point of each (the ship environments' local ice).

The simulations share no array, so one ``prange`` over them runs each one's
serial step in its own form (:func:`physics.hertz_step.run_steps`) on its
own thread, with no two iterations writing the same memory.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .hertz_kernels import ice_energy, ice_within, state_finite
from .hertz_step import run_steps

__all__ = ["run_many", "ice_near_many", "ICE_NEAR"]

#: the columns of :func:`ice_near_many`'s rows: :func:`physics.hertz_kernels.ice_within`'s
#: results, then the kinetic energy of all the ice (:func:`physics.hertz_kernels.ice_energy`)
ICE_NEAR = ("n_floes", "r2", "n_contacts", "sxx", "sxy", "syx", "syy", "kinetic_energy")


@njit(cache=True, parallel=True, error_model="numpy")
def run_many(n_steps, dt, time, mode, window, tally, runs, verlets, done, status, n_rebuilds,
             n_awake, finite):
    """The serial step of several independent simulations, parallel over them.

    ``runs[k]`` is (floes, law, wall law, drive, box, ship bundle) of
    simulation k and ``verlets[k]`` its Verlet list (replaced by the list
    after the run); ``n_steps``, ``dt`` and ``time`` hold the arguments of
    the step per simulation, ``mode[k]`` its step (0 full, 1 skipping the
    floes at rest, 2 free drift with windows of ``window[k]`` steps and
    its counts in row k of ``tally``, 3 the same with the free floes stepped
    one step at a time);
    ``done``, ``status``, ``n_rebuilds``, ``n_awake`` (the floes awake or
    engaged at the end, for modes 1 and 2) and ``finite`` (every floe's
    position and velocity and the ship's state finite at the end) receive
    the results."""
    for m in prange(len(runs)):
        k = np.int64(m)                     # typed lists take signed indices
        run = runs[k]
        floes, ship = run[0], run[5]
        d, s, r, verlet, a = run_steps(mode[k], n_steps[k], dt[k], time[k], run, verlets[k],
                                       window[k], tally[k])
        n_awake[k] = a
        done[k] = d
        status[k] = s
        n_rebuilds[k] = r
        verlets[k] = verlet
        ok = state_finite(floes.pos, floes.vel)
        for j in range(ship.state.shape[0]):
            ok = ok and math.isfinite(ship.state[j])
        finite[k] = ok


@njit(cache=True, parallel=True, error_model="numpy")
def ice_near_many(runs, verlets, centres, reach, lx, ly, px, py, out):
    """The ice within ``reach`` [m] of the point ``centres[k]`` of each
    simulation k (``runs[k]``, ``verlets[k]`` as :func:`run_many` takes
    them; one box, side lengths ``lx``, ``ly`` and periodicity ``px``,
    ``py``), parallel over the simulations: row k of ``out`` receives the
    columns of :data:`ICE_NEAR`."""
    for m in prange(len(runs)):
        k = np.int64(m)
        floes, law = runs[k][0], runs[k][1]
        v = verlets[k]
        n_floes, r2, n_contacts, sxx, sxy, syx, syy = ice_within(
            floes.pos, floes.vel, floes.omega, floes.radius, floes.inv_mass, v.start, v.nbr,
            v.hist, law, lx, ly, px, py, centres[k, 0], centres[k, 1], reach)
        out[k, 0] = n_floes
        out[k, 1] = r2
        out[k, 2] = n_contacts
        out[k, 3] = sxx
        out[k, 4] = sxy
        out[k, 5] = syx
        out[k, 6] = syy
        out[k, 7] = ice_energy(floes.vel, floes.omega, floes.radius, floes.inv_mass)
