"""The Hertz engine's step is written once (``physics/hertz_step.py``).

The forms of the step (all floes, serial or parallel; the awake floes; the
free-drift windows) must give the same physics, which the tests of each form
check bit for bit against the full step (test_hertz_resting.py,
test_free_drift.py, test_parallel_step.py). These tests hold the structure
that makes that cheap to keep: one loop, one kick–drift pass, one place that
chooses the form.
"""
import ast
from pathlib import Path

import pytest

import physics
from physics import hertz_step
from physics.hertz import HertzSimulation

PHYSICS = Path(physics.__file__).parent


def call_sites(name: str) -> list[tuple[str, str]]:
    """(module, enclosing function) of every call of ``name`` in the
    package's top-level modules."""
    sites = []
    for path in sorted(PHYSICS.glob("*.py")):
        tree = ast.parse(path.read_text())
        for func in ast.walk(tree):
            if not isinstance(func, ast.FunctionDef):
                continue
            for node in ast.walk(func):
                if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                        and node.func.id == name):
                    sites.append((path.stem, func.name))
    return sorted(set(sites))


def test_one_loop_begins_every_step():
    # begin_step starts a step (the box's lengths, the ship's kick-drift):
    # a second caller would be a second copy of the loop
    assert call_sites("begin_step") == [("hertz_step", "_substeps")]


def test_one_kick_drift_pass():
    # the per-floe kick-drift runs in the pass, and in the free-drift check
    # mode that steps free floes one at a time with the same arithmetic
    assert call_sites("kick_drift_floe") == [("hertz_free_drift", "iterate_floes"),
                                             ("hertz_kernels", "kick_drift_pass")]


def test_one_place_chooses_the_form():
    # run_steps (compiled, for batches) and run_one (by Python, for one
    # simulation) are the same function, _run_steps
    assert call_sites("run_awake") == [("hertz_step", "_run_steps")]
    assert call_sites("run_windows") == [("hertz_step", "_run_steps")]
    # the loop runs from the runs of hertz_step alone
    assert {module for module, _ in call_sites("substeps")} == {"hertz_step"}
    assert {module for module, _ in call_sites("run_steps")} == {"hertz_batch"}
    assert {module for module, _ in call_sites("run_one")} == {"hertz"}
    assert hertz_step.run_steps.py_func is hertz_step.run_one


@pytest.mark.parametrize("flags, mode", [
    ({}, hertz_step.MODE_FULL),
    ({"skip_resting": True}, hertz_step.MODE_RESTING),
    ({"free_drift": True}, hertz_step.MODE_FREE),
])
def test_the_simulation_names_its_form(flags, mode):
    sim = HertzSimulation.__new__(HertzSimulation)
    sim.skip_resting = flags.get("skip_resting", False)
    sim.free_drift = flags.get("free_drift", False)
    sim.free_iterate = False
    assert sim._step_mode == mode
    assert hertz_step.MODES[mode]
    sim.free_iterate = True
    assert sim._step_mode == (hertz_step.MODE_FREE_ITERATED if sim.free_drift else mode)
