"""The thread team of the parallel Hertz step (physics.thread_team): every
task of every phase done exactly once, whatever the runtime does with the
iterations of the parallel loop, and the same trajectory as the serial path.
"""
from types import SimpleNamespace

import numba
import numpy as np
import pytest
from numba import njit, prange

import physics.hertz
from physics import (DeformingPeriodicBox, FloeField, Forcing, HertzSimulation, PeriodicBox,
                     make_floe_field)
from physics.params import HERMAN2013
from physics.thread_team import claim, sync_size, task_done, task_order, wait_generation


@njit(parallel=True)
def count_tasks(n_tasks, n_generations, sync, counts, doer):
    for t in prange(n_tasks):
        for g in range(1, n_generations + 1):
            for m in range(n_tasks):
                k = (t + m) % n_tasks
                if claim(sync, k, g):
                    counts[g, k] += 1
                    doer[g, k] = t
                    task_done(sync, n_tasks)
            wait_generation(sync, n_tasks, g)
            # a phase may only start when the previous one is complete
            for k in range(n_tasks):
                if counts[g, k] != 1:
                    counts[0, 0] = -1


@pytest.mark.parametrize("threads,n_tasks", [(1, 1), (1, 2), (1, 3), (2, 2), (2, 3)])
def test_every_task_is_done_once_and_phases_do_not_overlap(threads, n_tasks):
    """20000 generations: each task done exactly once per generation, and no
    thread passes a generation before all its tasks are done. With more
    tasks than threads the runtime runs some iterations one after the other
    (with one thread, all of them): a thread then does the tasks of the
    missing ones, and the team must not hang."""
    old = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        n_gen = 20000
        sync = np.zeros(sync_size(n_tasks), dtype=np.int64)
        counts = np.zeros((n_gen + 1, n_tasks), dtype=np.int64)
        doer = np.full((n_gen + 1, n_tasks), -1, dtype=np.int64)
        count_tasks(n_tasks, n_gen, sync, counts, doer)
    finally:
        numba.set_num_threads(old)
    assert counts[0, 0] == 0, "a phase started before the previous one was complete"
    assert (counts[1:] == 1).all()
    assert sync[n_tasks] == n_gen * n_tasks
    assert (sync[:n_tasks] == n_gen).all()
    if threads == 1 and n_tasks > 1:
        assert (doer[1:] == 0).all()      # the first iteration did everything


@pytest.mark.parametrize("n_threads,n_tasks", [(1, 1), (1, 4), (2, 2), (2, 4), (2, 5), (3, 6),
                                               (3, 7)])
def test_task_order_visits_every_task_once_own_block_first(n_threads, n_tasks):
    """Each thread tries every task of a phase exactly once, its own
    consecutive block first and in order; the blocks of the threads cut the
    tasks into consecutive pieces; the first task a thread would take from
    others is the last of the block before its own."""
    blocks = []
    for t in range(n_threads):
        order = [task_order(t, m, n_threads, n_tasks) for m in range(n_tasks)]
        assert sorted(order) == list(range(n_tasks))
        lo, hi = t * n_tasks // n_threads, (t + 1) * n_tasks // n_threads
        assert order[:hi - lo] == list(range(lo, hi))
        if hi - lo < n_tasks:
            assert order[hi - lo] == (lo - 1) % n_tasks
        blocks.extend(order[:hi - lo])
    assert blocks == list(range(n_tasks))


def run(floes, box, steps, parallel, n_tasks=None, monkeypatch=None, forcing=True):
    if n_tasks is not None:
        # the step asks physics.hertz for the number of threads: pretend
        monkeypatch.setattr(physics.hertz, "numba", SimpleNamespace(get_num_threads=lambda: n_tasks))
    sim = HertzSimulation(floes, box, HERMAN2013.contact,
                          Forcing(HERMAN2013.forcing) if forcing else None, 5e-4,
                          impact_speed=1.0, allow_overlap=True, parallel=parallel)
    for _ in range(4):
        sim.step(steps // 4)
    if n_tasks is not None:
        monkeypatch.undo()
    return sim


def compressed(n=400, seed=3):
    floes, box = make_floe_field(n, concentration=0.8, alpha=1.8, mean_diameter=8.0, seed=seed,
                                 velocity_std=0.3)
    s = 0.9985
    rng = np.random.default_rng(4)
    field = FloeField(floes.positions * s, floes.radii, floes.thickness, floes.velocities,
                      rng.normal(0.0, 0.01, n))
    return field, box.lx * s, box.ly * s


@pytest.mark.parametrize("threads,n_tasks", [(1, 2), (1, 3), (2, 2), (2, 3)])
def test_team_step_equals_serial_step(threads, n_tasks, monkeypatch):
    """400 fast, overlapping floes (0.3 m/s) in a periodic box for 400
    steps, with list rebuilds (the team leaves its parallel region for
    them): the team path with n_tasks tasks on ``threads`` threads gives
    the serial path's trajectory to 1e-9 of the largest magnitude, the same
    number of rebuilds, and the same state bit for bit on 1 and 2 threads
    for the same number of tasks."""
    floes, lx, ly = compressed()
    serial = run(floes, PeriodicBox(lx, ly), 400, parallel=False)
    assert serial.n_rebuilds >= 2
    old = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        team = run(floes, PeriodicBox(lx, ly), 400, True, n_tasks, monkeypatch)
        numba.set_num_threads(1)
        team1 = run(floes, PeriodicBox(lx, ly), 400, True, n_tasks, monkeypatch)
    finally:
        numba.set_num_threads(old)
    assert team.n_rebuilds == serial.n_rebuilds
    for a, b in ((team.positions, serial.positions), (team.velocities, serial.velocities),
                 (team.angular_velocities, serial.angular_velocities)):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-9 * np.abs(b).max())
    np.testing.assert_array_equal(team.positions, team1.positions)
    np.testing.assert_array_equal(team.velocities, team1.velocities)


def test_team_step_in_a_deforming_box_equals_serial_step(monkeypatch):
    """Convergence at dA/dt = 0.05 per second (A from 0.802 to 0.812 in
    0.2 s) with two tasks: the team path follows the box lengths and gives
    the serial path's trajectory."""
    floes, lx, ly = compressed(seed=5)

    def box():
        return DeformingPeriodicBox(lx, ly, concentration_rate=0.05)
    serial = run(floes, box(), 400, parallel=False, forcing=False)
    team = run(floes, box(), 400, True, 2, monkeypatch, forcing=False)
    assert team.box.lx == serial.box.lx < lx
    np.testing.assert_allclose(team.positions, serial.positions, rtol=0,
                               atol=1e-9 * serial.positions.max())
