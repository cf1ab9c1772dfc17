"""The atomic fetch-and-add behind the dynamically scheduled parallel
loops, and the loop that uses it: every chunk is claimed exactly once, and
the results do not depend on which thread claimed what."""
from __future__ import annotations

import math

import numba
import numpy as np
from numba import njit, prange

from physics import HERMAN2013, Forcing, HertzSimulation, make_floe_field
from physics import hertz_kernels as K
from physics.atomics import fetch_add


@njit
def _claim_serially(counter, steps):
    old = np.empty(steps.shape[0], dtype=np.int64)
    for k in range(steps.shape[0]):
        old[k] = fetch_add(counter, 1, steps[k])
    return old


@njit(parallel=True)
def _claim_all(n_threads, n_chunks, hits, owner, work):
    claimed = np.zeros(1, dtype=np.int64)
    for w in prange(n_threads):
        while True:
            c = fetch_add(claimed, 0, 1)
            if c >= n_chunks:
                break
            hits[c] += 1
            owner[c] = w
            for k in range(2000):          # some work, so that all threads get chunks
                work[c] += math.sqrt(k + work[c])


def test_fetch_add_returns_the_old_value_and_adds():
    counter = np.array([7, 100, 7], dtype=np.int64)
    old = _claim_serially(counter, np.array([5, -3, 1], dtype=np.int64))
    assert old.tolist() == [100, 105, 102]
    assert counter.tolist() == [7, 103, 7]       # only the indexed element changes


def test_every_chunk_is_claimed_exactly_once_by_competing_threads():
    """2000 chunks claimed by all threads at once, 100 times: each chunk is
    claimed once per round (a lost update would give 0 or 2). With more than
    one thread, the chunks are shared between them."""
    hits = np.zeros(2000, dtype=np.int64)
    owner = np.zeros(2000, dtype=np.int64)
    work = np.zeros(2000)
    workers = set()
    for _ in range(100):
        _claim_all(numba.get_num_threads(), 2000, hits, owner, work)
        workers.update(np.unique(owner).tolist())
    assert hits.min() == hits.max() == 100
    if numba.get_num_threads() > 1:
        assert len(workers) > 1


def test_dynamic_kick_pass_is_bitwise_repeatable_and_equals_the_serial_pass():
    """The parallel kick–drift pass over 3000 floes with forcing, called 30
    times on the same input: the new state and the reduced results (largest
    displacement, summed displacements, largest speed) are identical bit for
    bit every time, whatever thread claimed which chunk, and equal the serial
    pass to rounding."""
    floes, box = make_floe_field(3000, concentration=0.7, alpha=1.8, mean_diameter=8.0, seed=2,
                                 velocity_std=0.05)
    sim = HertzSimulation(floes, box, HERMAN2013.contact, Forcing(HERMAN2013.forcing,
                          wind=(6.0, -3.0)), 0.002, parallel=False)
    sim.step(3)
    n = floes.n
    rng = np.random.default_rng(1)
    fbuf = rng.normal(0.0, 1e3, (2, n, 2))
    tbuf = rng.normal(0.0, 1e3, (2, n))
    shared = (rng.random(n) < 0.3).astype(np.uint8)
    fv = np.array([6.0, -3.0, 0.0, 0.0])
    ref = sim.positions + rng.normal(0.0, 0.05, (n, 2))

    def run(kernel, *lead):
        state = [sim.positions.copy(), sim.velocities.copy(), sim.angular_velocities.copy(),
                 fbuf.copy(), tbuf.copy()]
        out = kernel(*lead, 0.002, 0.002, *state, shared, sim.inv_mass, sim.inv_inertia,
                     box.lx, box.ly, True, True, 1.0, 1.0, ref.copy(), 0.01, -0.02, sim._drag,
                     fv, True)
        return np.array(out), state

    threads = numba.get_num_threads()
    first, first_state = run(K.first_half_parallel, threads)
    for _ in range(30):
        out, state = run(K.first_half_parallel, threads)
        assert np.array_equal(out, first)
        for a, b in zip(state, first_state):
            assert np.array_equal(a, b)
    serial, serial_state = run(K.first_half, 0, n)
    np.testing.assert_allclose(first, serial, rtol=1e-12, atol=0)
    for a, b in zip(first_state, serial_state):
        assert np.array_equal(a, b)        # per-floe updates do not depend on the chunking
