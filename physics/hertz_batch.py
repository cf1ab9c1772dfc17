"""Several Hertz simulations in one compiled call: :func:`run_many`, which
:func:`physics.hertz.advance_together` calls (and through it the native
vector environments of :mod:`iceenvs.vector`).

The simulations share no array, so one ``prange`` over them runs each one's
serial step (:func:`physics.hertz_kernels.run_steps`, or
:func:`physics.hertz_resting.run_steps_resting` for one that skips the floes
at rest, or :func:`physics.hertz_free_drift.run_steps_free` for one whose
free floes drift in closed form) on its own thread, with no two iterations writing the same memory.
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange

from .hertz_free_drift import run_steps_free
from .hertz_kernels import run_steps
from .hertz_resting import run_steps_resting

__all__ = ["run_many"]


@njit(cache=True, parallel=True, error_model="numpy")
def run_many(n_steps, dt, time, mode, window, tally, runs, verlets, done, status, n_rebuilds,
             n_awake):
    """The serial step of several independent simulations, parallel over them.

    ``runs[k]`` is (floes, law, wall law, drive, box, ship bundle) of
    simulation k and ``verlets[k]`` its Verlet list (replaced by the list
    after the run); ``n_steps``, ``dt`` and ``time`` hold the arguments of
    the step per simulation, ``mode[k]`` its step (0 full, 1 skipping the
    floes at rest, 2 free drift with windows of ``window[k]`` steps and
    its counts in row k of ``tally``, 3 the same with the free floes stepped
    one step at a time);
    ``done``, ``status``, ``n_rebuilds`` and ``n_awake`` (the floes awake or
    engaged at the end, for modes 1 and 2) receive the results."""
    for m in prange(len(runs)):
        k = np.int64(m)                     # typed lists take signed indices
        floes, law, wall_law, drive, box, ship = runs[k]
        if mode[k] == 1:
            d, s, r, verlet, a = run_steps_resting(n_steps[k], dt[k], time[k], floes, law,
                                                   wall_law, drive, box, verlets[k], ship)
            n_awake[k] = a
        elif mode[k] >= 2:
            d, s, r, verlet, a = run_steps_free(n_steps[k], dt[k], time[k], floes, law,
                                                wall_law, drive, box, verlets[k], ship, window[k],
                                                tally[k], mode[k] == 3)
            n_awake[k] = a
        else:
            d, s, r, verlet = run_steps(n_steps[k], dt[k], time[k], floes, law, wall_law, drive,
                                        box, verlets[k], False, 1, ship)
        done[k] = d
        status[k] = s
        n_rebuilds[k] = r
        verlets[k] = verlet
