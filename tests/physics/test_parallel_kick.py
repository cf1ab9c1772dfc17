"""The parallel kick–drift pass of the Hertz engine: race-free,
deterministic and equal to the serial pass."""
from __future__ import annotations

import numba
import numpy as np

from physics import HERMAN2013, Forcing, HertzSimulation, make_floe_field
from physics import hertz_kernels as K


def test_kick_pass_is_bitwise_repeatable_and_equals_the_serial_pass():
    """The parallel kick–drift pass over 3000 floes with forcing, called 30
    times on the same input: the new state and the reduced results (largest
    displacement, summed displacements, largest speed) are identical bit for
    bit every time and for one thread and all threads (the chunks do not
    depend on the thread count), and equal the serial pass to rounding (the
    per-floe updates bit for bit)."""
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

    def fresh_state():
        return [sim.positions.copy(), sim.velocities.copy(), sim.angular_velocities.copy(),
                fbuf.copy(), tbuf.copy()]

    def run(kernel, *lead):
        state = fresh_state()
        out = kernel(*lead, 0.002, 0.002, *state, shared, sim.inv_mass, sim.inv_inertia,
                     box.lx, box.ly, True, True, 1.0, 1.0, ref.copy(), 0.01, -0.02, sim._drag,
                     fv, True)
        return np.array(out), state

    def serial_pass():
        """The serial path: the buffers added up, then the kick of buffer 0."""
        state = fresh_state()
        K.gather_buffers(0, n, state[3], state[4], shared)
        out = K.first_half(0, n, 0.002, 0.002, *state[:3], state[3][0], state[4][0],
                           sim.inv_mass, sim.inv_inertia, box.lx, box.ly, True, True, 1.0, 1.0,
                           ref.copy(), 0.01, -0.02, sim._drag, fv, True)
        return np.array(out), state

    threads = numba.get_num_threads()
    first, first_state = run(K.first_half_parallel, threads)
    for k in range(30):
        nt = 1 if k % 2 else threads
        numba.set_num_threads(nt)
        try:
            out, state = run(K.first_half_parallel, nt)
        finally:
            numba.set_num_threads(threads)
        assert np.array_equal(out, first)
        for a, b in zip(state, first_state):
            assert np.array_equal(a, b)
    serial, serial_state = serial_pass()
    np.testing.assert_allclose(first, serial, rtol=1e-12, atol=0)
    for a, b in zip(first_state, serial_state):
        assert np.array_equal(a, b)        # per-floe updates do not depend on the chunking
    # the pass did something: every mobile floe moved and the buffers were reset
    assert np.all(first_state[0] != sim.positions)
    assert np.all(first_state[3][1:][:, shared == 1] == 0.0)
