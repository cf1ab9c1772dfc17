"""The parallel Hertz step: the same trajectory as the serial step to
rounding, the same state bit for bit on any number of threads (its chunks
depend on N alone), with and without a ship, and a run with more threads
than cores finishes in about the time of one on the cores.
"""
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numba
import numpy as np
import pytest

import physics.hertz
from physics import (DeformingPeriodicBox, FloeField, Forcing, HertzSimulation, PeriodicBox,
                     make_floe_field)
from physics import hertz_kernels as K
from physics.domain import Box
from physics.floes import place_floes
from physics.hertz import hull_contact_time
from physics.hull import Hull
from physics.params import HERMAN2013
from physics.ship import Ship

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def threads(monkeypatch):
    """Set Numba's threads for a test (the step may then use them all, even
    more than the cores: for the tests of thread counts); restored after."""
    old = numba.get_num_threads()
    monkeypatch.setattr(physics.hertz, "usable_cores", lambda: numba.config.NUMBA_NUM_THREADS)
    yield numba.set_num_threads
    numba.set_num_threads(old)


@pytest.mark.parametrize("n", [1, 2, 3, 1000, 1023, 1024, 2047, 2048, 5000, 200_000, 10**9])
def test_chunk_count_is_a_power_of_two_from_n_alone(n):
    """About FLOES_PER_CHUNK floes per chunk, rounded down to a power of
    two, at least 1 and at most MAX_CHUNKS."""
    c = K.chunk_count(n)
    assert c & (c - 1) == 0 and 1 <= c <= K.MAX_CHUNKS
    assert c == K.MAX_CHUNKS or c * K.FLOES_PER_CHUNK <= max(n, K.FLOES_PER_CHUNK) < 2 * c * K.FLOES_PER_CHUNK


def run(floes, box, steps, parallel, n_chunks=None, forcing=True):
    """``steps`` steps in four calls; ``n_chunks`` replaces the chunk count
    of the parallel step (the 400 floes would have one chunk)."""
    sim = HertzSimulation(floes, box, HERMAN2013.contact,
                          Forcing(HERMAN2013.forcing) if forcing else None, 5e-4,
                          impact_speed=1.0, allow_overlap=True, parallel=parallel)
    if n_chunks is not None:
        sim.n_chunks = n_chunks
    for _ in range(4):
        sim.step(steps // 4)
    return sim


def compressed(n=400, seed=3):
    floes, box = make_floe_field(n, concentration=0.8, alpha=1.8, mean_diameter=8.0, seed=seed,
                                 velocity_std=0.3)
    s = 0.9985
    rng = np.random.default_rng(4)
    field = FloeField(floes.positions * s, floes.radii, floes.thickness, floes.velocities,
                      rng.normal(0.0, 0.01, n))
    return field, box.lx * s, box.ly * s


@pytest.mark.parametrize("n_chunks", [2, 3, 4])
def test_parallel_step_equals_serial_step_on_any_number_of_threads(n_chunks, threads):
    """400 fast, overlapping floes (0.3 m/s) in a periodic box for 400
    steps, with list rebuilds: the parallel step in ``n_chunks`` chunks
    gives the serial step's trajectory to 1e-9 of the largest magnitude
    (it adds the forces of the cut pairs and the floes' displacements in
    another order: rounding of 1e-16 that the overlaps amplify), the same
    number of rebuilds, and the same state bit for bit on 1, 2 and 4
    threads."""
    floes, lx, ly = compressed()
    serial = run(floes, PeriodicBox(lx, ly), 400, parallel=False)
    assert serial.n_rebuilds >= 2
    runs = []
    for t in (1, 2, 4):
        threads(min(t, numba.config.NUMBA_NUM_THREADS))
        runs.append(run(floes, PeriodicBox(lx, ly), 400, True, n_chunks))
    par = runs[0]
    assert par.n_rebuilds == serial.n_rebuilds
    for a, b in ((par.positions, serial.positions), (par.velocities, serial.velocities),
                 (par.angular_velocities, serial.angular_velocities)):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-9 * np.abs(b).max())
    for other in runs[1:]:
        for a, b in ((par.positions, other.positions), (par.velocities, other.velocities),
                     (par.angular_velocities, other.angular_velocities), (par.force, other.force)):
            np.testing.assert_array_equal(a, b)


def test_parallel_step_in_a_deforming_box_equals_serial_step():
    """Convergence at dA/dt = 0.05 per second (A from 0.802 to 0.812 in
    0.2 s) in two chunks: the parallel step follows the box lengths and
    gives the serial step's trajectory."""
    floes, lx, ly = compressed(seed=5)

    def box():
        return DeformingPeriodicBox(lx, ly, concentration_rate=0.05)
    serial = run(floes, box(), 400, parallel=False, forcing=False)
    par = run(floes, box(), 400, True, 2, forcing=False)
    assert par.box.lx == serial.box.lx < lx
    np.testing.assert_allclose(par.positions, serial.positions, rtol=0,
                               atol=1e-9 * serial.positions.max())


def ship_run(parallel, mode, steps=15_000, n_chunks=2):
    """A 30 m ship (prescribed at 2 m/s, or dynamic from 2 m/s under a
    thrust of 50 kN) sailing into 550 floes (Ā ≈ 0.6 where they lie) with
    wind and drag in a periodic box, Δt a tenth of the contact time of a
    floe hitting the hull at 2 m/s, its collision log 16 rows long (the
    least allowed: it fills every few collisions), on the serial or the
    parallel step (in ``n_chunks`` chunks)."""
    rng = np.random.default_rng(5)
    lx, ly = 200.0, 120.0
    radii = rng.uniform(1.5, 3.0, 550)
    pos = place_floes(radii, Box(130.0, ly - 2.0, periodic=(False, False)), rng) + [65.0, 1.0]
    field = FloeField(pos, radii, 1.0, rng.normal(0.0, 0.05, (radii.size, 2)))
    params = HERMAN2013.contact
    ship = Ship(Hull.pointed(30.0, 8.0), 5e5, position=(48.0, 60.0), speed=2.0, mode=mode,
                log_capacity=16)
    t_c = hull_contact_time(radii, 1.0, field.density, params, 2.0)
    sim = HertzSimulation(field, PeriodicBox(lx, ly), params, Forcing(HERMAN2013.forcing),
                          0.1 * t_c, impact_speed=2.0, ship=ship, parallel=parallel)
    sim.n_chunks = n_chunks
    if mode == "dynamic":
        sim.ship.command(thrust=5e4)
    sim.step(steps)
    return sim


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
def test_parallel_step_with_a_ship_equals_serial_step(mode, threads):
    """A ship pushing through ice for 15000 steps (some 15 collisions,
    floes with wider skins, list rebuilds, the collision log full many
    times over) on two threads in two chunks: the state, step records and
    collision log of the serial step to 1e-9 of the largest magnitude of
    each quantity. The serial step adds the pair forces of the cut pairs
    and the floes' displacements in another order (so its list may expire
    at another step): rounding of 1e-16 that the impacts amplify over the
    run; 1e-9 leaves a wide margin."""
    threads(min(2, numba.config.NUMBA_NUM_THREADS))
    par = ship_run(True, mode)
    serial = ship_run(False, mode)
    assert par.n_rebuilds >= 2
    assert par._verlet.wide.size > 0                    # floes with a wider skin
    assert par.ship.records()["contacts"].max() > 0
    assert len(par.ship.collision_rows()) >= 10
    assert_same_run(par, serial, 1e-9)


def test_parallel_step_with_a_ship_is_the_same_on_one_two_and_four_threads(threads):
    """The dynamic ship's run in four chunks: the same floes, ship and
    records bit for bit on 1, 2 and 4 threads (the hull's contacts are
    added by one thread between the kick and the pair phase, and every
    sum is taken in the chunks' order)."""
    runs = []
    for t in (1, 2, 4):
        threads(min(t, numba.config.NUMBA_NUM_THREADS))
        runs.append(ship_run(True, "dynamic", 3000, n_chunks=4))
    for other in runs[1:]:
        np.testing.assert_array_equal(runs[0].positions, other.positions)
        np.testing.assert_array_equal(runs[0].velocities, other.velocities)
        np.testing.assert_array_equal(runs[0].ship.records()["surge"],
                                      other.ship.records()["surge"])


OVERSUBSCRIBED = textwrap.dedent("""
    import time, numba, numpy as np
    import physics.hertz
    from physics import HERMAN2013, HertzSimulation
    from physics.hertz import threads_within_cores, usable_cores
    with threads_within_cores():
        capped = numba.get_num_threads()
    sims = {}
    for t in (1, 8):
        numba.set_num_threads(t)
        sims[t] = HertzSimulation.from_preset(HERMAN2013, 8000, 0.7, seed=1, velocity_std=0.03,
                                              forcing=False, parallel=True)
        sims[t].step(5)
    best = {1: np.inf, 8: np.inf}
    for _ in range(5):
        for t, sim in sims.items():
            numba.set_num_threads(t)
            t0 = time.perf_counter()
            sim.step(100)
            best[t] = min(best[t], time.perf_counter() - t0)
    # and eight threads on the cores there are, not capped: the same state
    physics.hertz.usable_cores = lambda: 8
    numba.set_num_threads(8)
    free = HertzSimulation.from_preset(HERMAN2013, 8000, 0.7, seed=1, velocity_std=0.03,
                                       forcing=False, parallel=True)
    free.step(5)
    for _ in range(5):
        free.step(100)
    same = all(np.array_equal(sims[1].positions, s.positions) for s in (sims[8], free))
    print(capped, usable_cores(), same, best[8] / best[1])
""")


def test_more_threads_than_cores_finish_in_about_the_time_of_one():
    """Numba's pool of 8 threads on a host with fewer cores (as on shared CI
    hosts): the step runs on as many threads as there are cores
    (``threads_within_cores``), gives the same state as one thread, and
    takes at most 2.5 times as long as one thread per step (best of five
    segments of 100 steps of 8000 floes each, taking turns, in one of at
    most two measurements; uncapped, 8 threads on 2 cores take 2.3 times
    as long as one, and the cap brings it to about the time of two
    threads). Eight threads not capped give the same state too."""
    env = dict(os.environ, NUMBA_NUM_THREADS="8", PYTHONPATH=str(ROOT))
    ratios = []
    # a second measurement only where the first passes the bound: on shared cores a
    # neighbour's burst can slow the threaded segments of one run (2.9 seen once)
    while len(ratios) < 2 and (not ratios or ratios[-1] >= 2.5):
        out = subprocess.run([sys.executable, "-c", OVERSUBSCRIBED], env=env,
                             capture_output=True, text=True, timeout=600, cwd=ROOT)
        assert out.returncode == 0, out.stderr
        capped, cores, same, ratio = out.stdout.split()[-4:]
        assert int(capped) == min(8, int(cores))
        assert same == "True"
        ratios.append(float(ratio))
    assert min(ratios) < 2.5, ratios
