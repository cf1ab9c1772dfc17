"""The thread team of the parallel Hertz step (physics.thread_team): every
task of every phase done exactly once, whatever the runtime does with the
iterations of the parallel loop, and the same trajectory as the serial path,
with and without a ship.
"""
from types import SimpleNamespace

import numba
import numpy as np
import pytest
from numba import njit, prange

import physics.hertz
from physics import (DeformingPeriodicBox, FloeField, Forcing, HertzSimulation, PeriodicBox,
                     make_floe_field)
from physics import hertz_kernels as K
from physics.domain import Box
from physics.floes import place_floes
from physics.hertz import HertzStatus, hull_contact_time
from physics.hull import Hull
from physics.params import HERMAN2013
from physics.ship import Ship
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


class _Kernels:
    """physics.hertz_kernels as the simulation sees it, with run_steps told
    whether the parallel step may use the thread team, and the (steps done,
    status) of each kernel run kept."""

    def __init__(self, with_team):
        self.with_team = with_team
        self.runs = []

    def __getattr__(self, name):
        return getattr(K, name)

    def run_steps(self, *args):
        out = K.run_steps(*args, self.with_team)
        self.runs.append((int(out[0]), HertzStatus(out[1])))
        return out


def ship_run(path, mode, steps=15_000, n_tasks=2, monkeypatch=None):
    """A 30 m ship (prescribed at 2 m/s, or dynamic from 2 m/s under a
    thrust of 50 kN) sailing into 550 floes (Ā ≈ 0.6 where they lie) with
    wind and drag in a periodic box, Δt a tenth of the contact time of a
    floe hitting the hull at 2 m/s, its collision log 16 rows long (the
    least allowed: it fills every few collisions). ``path``: "serial",
    "team" (the parallel step with the thread team, ``n_tasks`` tasks) or
    "regions" (the parallel step with one parallel region per phase).
    Returns the simulation and the runs of the kernel."""
    rng = np.random.default_rng(5)
    lx, ly = 200.0, 120.0
    radii = rng.uniform(1.5, 3.0, 550)
    pos = place_floes(radii, Box(130.0, ly - 2.0, periodic=(False, False)), rng) + [65.0, 1.0]
    field = FloeField(pos, radii, 1.0, rng.normal(0.0, 0.05, (radii.size, 2)))
    params = HERMAN2013.contact
    ship = Ship(Hull.pointed(30.0, 8.0), 5e5, position=(48.0, 60.0), speed=2.0, mode=mode,
                log_capacity=16)
    t_c = hull_contact_time(radii, 1.0, field.density, params, 2.0)
    kernels = _Kernels(path == "team")
    if path != "serial":
        monkeypatch.setattr(physics.hertz, "K", kernels)
        monkeypatch.setattr(physics.hertz, "numba", SimpleNamespace(get_num_threads=lambda: n_tasks))
    sim = HertzSimulation(field, PeriodicBox(lx, ly), params, Forcing(HERMAN2013.forcing),
                          0.1 * t_c, impact_speed=2.0, ship=ship, parallel=path != "serial")
    if mode == "dynamic":
        sim.ship.command(thrust=5e4)
    sim.step(steps)
    if monkeypatch is not None:
        monkeypatch.undo()
    return sim, kernels.runs


def assert_same_run(a, b, tol):
    """Floes, ship, step records and collision log of two runs agree to
    ``tol`` times the largest magnitude of each quantity."""
    pairs = [(a.positions, b.positions), (a.velocities, b.velocities),
             (a.angular_velocities, b.angular_velocities),
             (a.ship.position, b.ship.position), ([a.ship.surge, a.ship.sway, a.ship.heading],
                                                  [b.ship.surge, b.ship.sway, b.ship.heading])]
    for ra, rb in ((a.ship.records(), b.ship.records()),
                   (a.ship.collisions(), b.ship.collisions())):
        assert ra.keys() == rb.keys()
        pairs += [(ra[k], rb[k]) for k in ra]
    for x, y in pairs:
        y = np.asarray(y)
        np.testing.assert_allclose(x, y, rtol=0, atol=tol * max(np.abs(y).max(), 1e-300))


@pytest.mark.parametrize("mode", ["prescribed", "dynamic"])
def test_team_step_with_a_ship_equals_regions_and_serial(mode, monkeypatch):
    """A ship pushing through ice for 15000 steps (some 15 collisions,
    floes with wider skins, list rebuilds, the collision log full inside a
    run of the team), on two threads with two tasks: the team
    path gives the state, step records and collision log of the parallel
    path with one region per phase to 1e-12, and those of the serial path
    to 1e-9, of the largest magnitude of each quantity.

    The team does the arithmetic of the regions in the same order (the
    hull's contacts by one thread between the kick and the pair phase), so
    the two agree bit for bit; the tolerance is there only so that the test
    compares floats of two code paths with a margin (a few thousand ulps).
    The serial path adds the pair forces of floes along the chunks' cuts
    in another order and sums the floes' displacements in another order
    (so its list may expire at another step): rounding of 1e-16 that the
    impacts amplify over the run; 1e-9 leaves a wide margin (runs of 10000
    steps differ by about 1e-17)."""
    old = numba.get_num_threads()
    numba.set_num_threads(2)
    try:
        team, runs = ship_run("team", mode, monkeypatch=monkeypatch)
        regions, _ = ship_run("regions", mode, monkeypatch=monkeypatch)
    finally:
        numba.set_num_threads(old)
    serial, _ = ship_run("serial", mode)
    assert team.n_rebuilds == regions.n_rebuilds >= 2
    assert team._verlet.wide.size > 0                    # floes with a wider skin
    assert team.ship.records()["contacts"].max() > 0
    # the log filled in a run of the team after more than one step of it
    assert any(status is HertzStatus.SHIP_LOG_FULL and done > 1 for done, status in runs)
    assert_same_run(team, regions, 1e-12)
    assert_same_run(team, serial, 1e-9)


def test_team_step_with_a_ship_on_one_thread_equals_two(monkeypatch):
    """Two tasks on one thread (one iteration of the team's parallel loop
    does every task of every phase, the other finds itself overtaken and
    leaves): the same state bit for bit as on two threads (the team's new
    state does not depend on which thread did which task)."""
    old = numba.get_num_threads()
    try:
        numba.set_num_threads(2)
        two, _ = ship_run("team", "dynamic", 3000, monkeypatch=monkeypatch)
        numba.set_num_threads(1)
        one, _ = ship_run("team", "dynamic", 3000, monkeypatch=monkeypatch)
    finally:
        numba.set_num_threads(old)
    np.testing.assert_array_equal(one.positions, two.positions)
    np.testing.assert_array_equal(one.velocities, two.velocities)
    np.testing.assert_array_equal(one.ship.records()["surge"], two.ship.records()["surge"])
