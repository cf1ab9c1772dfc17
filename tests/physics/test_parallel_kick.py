"""The parallel kick–drift pass of the Hertz engine: race-free,
deterministic and equal to the serial pass."""
from __future__ import annotations

import numba
import numpy as np
import pytest

from physics import HERMAN2013, Forcing, HertzSimulation, make_floe_field
from physics import hertz_kernels as K
from physics.engine import FailureReason, SimulationError


def _floes(pos, vel, omega, force, torque, inv_mass, inv_inertia):
    """A floe bundle of the kernels around these arrays (radii, ranks and
    wall history, which the kick–drift pass does not read, are dummies)."""
    n = pos.shape[0]
    return K.Floes(pos, vel, omega, np.ones(n), inv_mass, inv_inertia, np.arange(n), force, torque,
                   np.zeros((n, 4, 2)))


def test_kick_pass_is_bitwise_repeatable_and_equals_the_serial_pass():
    """The parallel kick–drift pass over 3000 floes with forcing, with the
    slots of the cut pairs of four chunks full, called 30 times on the same
    input, alternately on one thread and on all threads: for a given number
    of tasks the new state and the reduced results (largest displacement,
    summed displacements, largest speed) are identical bit for bit
    whatever the threads; the new state is identical for any number of
    tasks and to the serial pass (the slots added up, then the kick), and
    the reduced results agree to rounding (the sums are added in another
    order)."""
    floes, box = make_floe_field(3000, concentration=0.7, alpha=1.8, mean_diameter=8.0, seed=2,
                                 velocity_std=0.05)
    sim = HertzSimulation(floes, box, HERMAN2013.contact, Forcing(HERMAN2013.forcing,
                          wind=(6.0, -3.0)), 0.002, parallel=False)
    sim.step(3)
    n = floes.n
    rng = np.random.default_rng(1)
    chunks = K.pair_chunks(sim._verlet, 4)
    assert chunks.cut.shape[0] > 0
    cut = rng.normal(0.0, 1e3, chunks.cut.shape)
    force = rng.normal(0.0, 1e3, (n, 2))
    torque = rng.normal(0.0, 1e3, n)
    drive = K.make_drive(sim._drag, (6.0, -3.0))
    kick = K.Kick(0.002, 0.002, box.lx, box.ly, True, True, 1.0, 1.0, 0.01, -0.02)
    ref = sim.positions + rng.normal(0.0, 0.05, (n, 2))

    def fresh_state():
        return [sim.positions.copy(), sim.velocities.copy(), sim.angular_velocities.copy(),
                force.copy(), torque.copy(), cut.copy()]

    def bundles(state):
        return (_floes(*state[:5], sim._floes.inv_mass, sim._floes.inv_inertia),
                K.ForceBuffers(state[3], state[4]), chunks._replace(cut=state[5]))

    def run(n_tasks):
        state = fresh_state()
        floes, buffers, ch = bundles(state)
        out = K.first_half_parallel(n_tasks, floes, buffers, ch, ref.copy(), drive, kick)
        return np.array(out), state

    def serial_pass():
        state = fresh_state()
        floes, buffers, ch = bundles(state)
        K.gather_cut(0, n, ch, state[3], state[4])
        out = K.first_half(floes, ref.copy(), drive, kick)
        return np.array(out), state

    threads = numba.get_num_threads()
    first = {}
    for k in range(30):
        nt = 1 if k % 2 else threads
        n_tasks = 4 if k % 3 else 7
        numba.set_num_threads(nt)
        try:
            out, state = run(n_tasks)
        finally:
            numba.set_num_threads(threads)
        if n_tasks not in first:
            first[n_tasks] = out, state
        assert np.array_equal(out, first[n_tasks][0])
        for a, b in zip(state, first[7][1]):
            assert np.array_equal(a, b)
    serial, serial_state = serial_pass()
    for out, _ in first.values():
        np.testing.assert_allclose(out, serial, rtol=1e-12, atol=0)
    first_state = first[7][1]
    for a, b in zip(first_state, serial_state):
        assert np.array_equal(a, b)        # per-floe updates do not depend on the chunking
    # the pass did something: every mobile floe moved and the slots were added and reset
    assert np.all(first_state[0] != sim.positions)
    assert np.all(first_state[5] == 0.0)


def _reference_pass(dt_kick, dt, pos, vel, omega, force, torque, inv_mass, inv_inertia, box,
                    ref, centre, drag, fv):
    """The kick–drift pass written plainly with NumPy (periodic box, no
    remap): new positions, velocities, spins, drag forces and torques, and
    the four reduced results."""
    lx, ly = box
    mobile = inv_mass != 0.0
    v = vel + dt_kick * force * inv_mass[:, None]
    w = omega + dt_kick * torque * inv_inertia
    x = np.mod(pos + dt * v, [lx, ly])
    v = np.where(mobile[:, None], v, vel)
    w = np.where(mobile, w, omega)
    x = np.where(mobile[:, None], x, pos)
    wind = np.hypot(fv[0], fv[1])
    a, b, c, g = drag.T
    fx = a * wind * fv[0] + b * (fv[2] - v[:, 0]) + g * v[:, 1]
    fy = a * wind * fv[1] + b * (fv[3] - v[:, 1]) - g * v[:, 0]
    d = x - ref
    d -= np.array([lx, ly]) * np.round(d / [lx, ly])
    worst = np.max(np.sum((d - centre) ** 2, axis=1))
    speed2 = np.max(np.where(mobile, np.sum(v ** 2, axis=1), 0.0))
    return x, v, w, np.column_stack([fx, fy]), -c * w, (worst, d[:, 0].sum(), d[:, 1].sum(),
                                                        speed2)


def test_kick_pass_matches_a_plain_numpy_pass_and_reports_nan():
    """The compiled (vectorised) pass against :func:`_reference_pass` on 1001
    floes (an odd count, so the scalar remainder of the vector loop runs),
    with frozen floes and floes crossing the periodic edges: the per-floe
    state to 1e-12 relative, the sums to 1e-9 and the maxima to 1e-12. A
    NaN in one floe's velocity, of either sign, makes the largest speed
    and the displacement sums NaN (the step's blow-up check)."""
    rng = np.random.default_rng(5)
    n, lx, ly = 1001, 50.0, 40.0
    pos = rng.random((n, 2)) * [lx, ly]
    pos[:20, 0] = lx - 1e-3                       # these cross the right edge
    pos[20:40, 1] = 1e-3                          # and these the bottom edge
    vel = rng.normal(0.0, 0.5, (n, 2))
    vel[:20, 0] = 1.0
    vel[20:40, 1] = -1.0
    omega = rng.normal(0.0, 0.1, n)
    force = rng.normal(0.0, 1e3, (n, 2))
    torque = rng.normal(0.0, 1e3, n)
    inv_mass = rng.uniform(1e-4, 1e-3, n)
    inv_inertia = rng.uniform(1e-4, 1e-3, n)
    drag = rng.uniform(0.0, 50.0, (n, 4))
    frozen = rng.random(n) < 0.1
    inv_mass[frozen] = inv_inertia[frozen] = 0.0
    drag[frozen] = 0.0
    ref = pos + rng.normal(0.0, 0.05, (n, 2))
    ref = np.mod(ref, [lx, ly])
    fv = np.array([7.0, -2.0, 0.1, 0.05])
    centre = np.array([0.01, -0.02])
    dt = 0.01

    def compiled(v0):
        state = [pos.copy(), v0.copy(), omega.copy(), force.copy(), torque.copy()]
        out = K.first_half(_floes(*state, inv_mass, inv_inertia), ref.copy(),
                           K.make_drive(drag, fv[:2], fv[2:]),
                           K.Kick(dt, dt, lx, ly, True, True, 1.0, 1.0, centre[0], centre[1]))
        return state, out

    state, out = compiled(vel)
    expect = _reference_pass(dt, dt, pos, vel, omega, force, torque, inv_mass, inv_inertia,
                             (lx, ly), ref, centre, drag, fv)
    for got, want in zip(state, expect[:5]):
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
    assert np.array_equal(state[0][frozen], pos[frozen])
    assert np.all((state[0] >= 0.0) & (state[0] < [lx, ly]))
    np.testing.assert_allclose(out[1:3], expect[5][1:3], rtol=1e-9)
    np.testing.assert_allclose([out[0], out[3]], [expect[5][0], expect[5][3]], rtol=1e-12)
    for nan in (np.nan, -np.nan):
        bad = vel.copy()
        bad[n // 2, 1] = nan
        _, out = compiled(bad)
        assert np.isnan(out[3]) and np.isnan(out[2])


def test_a_blow_up_stops_the_run_at_once_on_both_paths():
    """A NaN velocity (either sign) or a floe flung across the box in one
    step stops ``step`` with a SimulationError (a FloatingPointError) of
    the right reason after the first step, on the serial and the parallel
    path."""
    floes, box = make_floe_field(400, concentration=0.5, alpha=1.8, mean_diameter=8.0, seed=3,
                                 velocity_std=0.05)
    for parallel in (False, True):
        for value, kind, reason in ((np.nan, "non-finite", FailureReason.NON_FINITE),
                                    (-np.nan, "non-finite", FailureReason.NON_FINITE),
                                    (2.0 * box.lx / 0.002, "unstable", FailureReason.UNSTABLE)):
            sim = HertzSimulation(floes, box, HERMAN2013.contact, None, 0.002, parallel=parallel)
            # the velocities setter refuses a NaN: plant it in the engine's own array
            sim._vel[7, 0] = value
            with pytest.raises(FloatingPointError, match=kind) as caught:
                sim.step(50)
            assert isinstance(caught.value, SimulationError)
            assert caught.value.reason is reason and caught.value.time == sim.time
            assert sim.n_steps == 1
