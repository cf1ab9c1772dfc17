"""The full serial step's skipped looks (``hertz_kernels.owner_pairs`` and
``wall_forces`` with the floes' paths): a pair or wall found apart is not
looked at again until the floes' paths could have closed the gap, and is
looked at once they could. The whole-run equality with the parallel step,
which looks at every pair, is in ``test_parallel_step.py``."""
from __future__ import annotations

import numpy as np
import pytest

from physics import ContactParams, HertzSimulation
from physics import hertz_kernels as K
from physics.domain import WalledBox
from physics.floes import FloeField

CONTACT = ContactParams(elastic_modulus=1.0e8, restitution=0.5, friction=0.5)


def kernel_state(positions):
    pos = np.array(positions, dtype=float)
    field = FloeField(pos, np.ones(len(pos)), 1.0, np.zeros_like(pos))
    sim = HertzSimulation(field, WalledBox(40.0), CONTACT, None, 1e-3, impact_speed=1.0,
                          skin=1.0)
    args = sim._kernel_arguments(1)
    floes, law, wall_law, _, box = args[1:6]
    return sim, floes, law, wall_law, box


def test_a_pair_apart_is_looked_at_again_once_the_paths_allow():
    sim, floes, law, _, box = kernel_state([(10.0, 10.0), (12.5, 10.0)])
    verlet = sim._verlet
    owners = np.flatnonzero(verlet.start[1:] > verlet.start[:-1])
    assert verlet.nbr.shape[0] == 1                 # one pair, gap 0.5 m
    path, due = np.zeros(2), np.full(1, -np.inf)
    force, torque = np.zeros((2, 2)), np.zeros(2)

    def look():
        K.owner_pairs(0, owners.shape[0], owners, floes, law, box, verlet, 1e-3, force, torque,
                      0, 0, None, None, path, due)

    look()
    assert np.all(force == 0.0) and due[0] == pytest.approx(0.5, abs=1e-8)
    floes.pos[0, 0] = 10.6                          # overlapping by 0.1 m
    look()
    assert np.all(force == 0.0)                     # skipped: the paths said 0
    path[1] = 0.6                                   # the drift that took it there
    look()
    assert force[0, 0] < 0.0 < force[1, 0]


def test_a_floe_clear_of_the_walls_is_looked_at_again_once_its_path_allows():
    sim, floes, _, wall_law, box = kernel_state([(1.5, 20.0)])
    path, due = np.zeros(1), np.full(1, -np.inf)
    force, torque = np.zeros((1, 2)), np.zeros(1)
    K.wall_forces(0, 1, floes, wall_law, box, 1e-3, force, torque, path, due)
    assert force[0, 0] == 0.0 and due[0] == pytest.approx(0.5, abs=1e-8)
    floes.pos[0, 0] = 0.9                           # overlapping the wall at x = 0
    K.wall_forces(0, 1, floes, wall_law, box, 1e-3, force, torque, path, due)
    assert force[0, 0] == 0.0
    path[0] = 0.6
    K.wall_forces(0, 1, floes, wall_law, box, 1e-3, force, torque, path, due)
    assert force[0, 0] > 0.0 and due[0] == -np.inf  # touching: looked at every step
