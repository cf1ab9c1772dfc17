"""Kernels loaded from Numba's on-disk cache in a later process must run.

A cached kernel that calls a parallel kernel crashed every process that
loaded it when it had been compiled in a process that took the parallel
callee from the cache itself. The sequence below did that before the
parallel callees stopped being cached: one process builds a large pair
list (caching the parallel list builder), the next compiles the Hertz step
(with the list builder inside), the third loads that step from the cache.
"""
from __future__ import annotations

import os
import subprocess
import sys

BUILD_LIST = """
from physics import make_floe_field
from physics.neighbors import choose_cell_size, pair_list, radius_rank
f, b = make_floe_field(6000, concentration=0.7, alpha=1.8, mean_diameter=8.0, seed=1)
start, nbr = pair_list(f.positions, f.radii, radius_rank(f.radii), b.lx, b.ly, True, True, 0.4,
                       choose_cell_size(f.radii, b.lx, b.ly, 0.4))
print("pairs", len(nbr))
"""

HERTZ = """
from physics import HERMAN2013, HertzSimulation, make_floe_field
f, b = make_floe_field(300, concentration=0.7, alpha=1.8, mean_diameter=8.0, seed=2,
                       velocity_std=0.05)
sim = HertzSimulation(f, b, HERMAN2013.contact, None, 0.002)
sim.step(20)
print("steps", sim.n_steps)
"""


def test_kernels_compiled_in_one_process_run_when_loaded_in_the_next(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), NUMBA_NUM_THREADS="1")
    outputs = []
    for script in (BUILD_LIST, HERTZ, HERTZ):
        run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                             env=env, timeout=600)
        assert run.returncode == 0, f"exit {run.returncode}: {run.stderr[-2000:]}"
        outputs.append(run.stdout.strip().splitlines()[-1])
    assert outputs[0].startswith("pairs ") and int(outputs[0].split()[1]) > 0
    assert outputs[1] == outputs[2] == "steps 20"
