"""Both engines keep the contract of :mod:`physics.engine`.

Every test runs on :class:`HertzSimulation` and on :class:`HardDiskSimulation`
with the same small field (Herman 2013 floes, N = 60, Ā = 0.4, one frozen
floe) and checks what code written against :class:`FloeEngine` relies on:
the names, the copy semantics of the input field and of the exposed
arrays, the floes' radii, masses, frozen flags and the concentration
against the field, the checks of an assignment to ``velocities``, the
exception type of each mistake, and :class:`SimulationError` when the
physics breaks down.
"""
from __future__ import annotations

import numpy as np
import pytest

from physics import (HERMAN2011, HERMAN2013, Contacts, DeformingPeriodicBox, Fabric, FloeField,
                     Forcing, HardDiskSimulation, HertzSimulation, PeriodicBox, Stress)
from physics.engine import FailureReason, FloeEngine, SimulationError

ENGINES = {"hertz": HertzSimulation, "harddisk": HardDiskSimulation}
#: the paper each engine reproduces
PRESETS = {"hertz": HERMAN2013, "harddisk": HERMAN2011}
FROZEN = 0          # the frozen floe of the test field


def small_field():
    """60 Herman (2013) floes at Ā = 0.4, moving at a few cm/s, floe 0 frozen."""
    field, box = HERMAN2013.floe_field(60, 0.4, seed=5, velocity_std=0.05)
    field.frozen[FROZEN] = True
    field.velocities[FROZEN] = 0.0
    field.angular_velocities[FROZEN] = 0.0
    return field, box


def make(kind, field=None, box=None, **kwargs):
    if field is None:
        field, box = small_field()
    if kind == "harddisk":
        kwargs.setdefault("log_collisions", True)      # for contact_stress
    return ENGINES[kind](field, box, **kwargs)


@pytest.fixture(params=list(ENGINES))
def kind(request):
    return request.param


def test_engines_are_floe_engines(kind):
    sim = make(kind)
    assert isinstance(sim, FloeEngine)
    assert sim.n_floes == 60 and sim.time == 0.0
    sim.advance(1.0)
    assert sim.time == pytest.approx(1.0)
    assert isinstance(sim.box, PeriodicBox)
    assert isinstance(sim.contacts(), Contacts)
    assert isinstance(sim.fabric(), Fabric)
    assert isinstance(sim.contact_stress(), Stress)
    assert isinstance(sim.kinetic_energy(), float) and sim.kinetic_energy() > 0.0
    assert sim.momentum().shape == (2,)
    state = sim.state()
    assert isinstance(state, FloeField) and state.n == 60
    np.testing.assert_array_equal(state.positions, sim.positions)
    np.testing.assert_array_equal(state.velocities, sim.velocities)
    state.positions[:] = 0.0                 # the state is the caller's own copy
    assert np.any(sim.positions != 0.0)


def test_input_field_is_never_modified(kind):
    field, box = small_field()
    before = field.copy()
    sim = make(kind, field, box)
    sim.advance(2.0)
    sim.velocities = 0.5 * sim.velocities
    sim.advance(1.0)
    for name in ("positions", "radii", "thickness", "velocities", "angular_velocities",
                 "frozen"):
        np.testing.assert_array_equal(getattr(field, name), getattr(before, name), err_msg=name)
    assert not np.array_equal(sim.positions, box.wrap(field.positions))


def test_exposed_arrays_are_read_only_snapshots(kind):
    sim = make(kind)
    pos, vel, omega = sim.positions, sim.velocities, sim.angular_velocities
    assert pos.shape == (60, 2) and vel.shape == (60, 2) and omega.shape == (60,)
    for a in (pos, vel, omega):
        assert not a.flags.writeable
        with pytest.raises(ValueError):
            a[0] = 1.0
    kept = pos.copy(), vel.copy(), omega.copy()
    sim.advance(2.0)
    for a, b in zip((pos, vel, omega), kept):
        np.testing.assert_array_equal(a, b)      # taken at the call: they do not follow
    assert not np.array_equal(sim.positions, pos)
    assert sim.positions is not sim.positions


def test_floe_properties_are_the_fields_and_read_only(kind):
    """``radii`` and ``frozen`` are the field's, ``masses`` are ρ h π r²,
    and none of them can be written or changes as the engine advances."""
    field, box = small_field()
    sim = make(kind, field, box)
    radii, masses, frozen = sim.radii, sim.masses, sim.frozen
    assert radii.shape == masses.shape == frozen.shape == (60,) and frozen.dtype == bool
    np.testing.assert_array_equal(radii, field.radii)          # copied, not computed
    np.testing.assert_array_equal(frozen, field.frozen)
    assert frozen.sum() == 1 and frozen[FROZEN]
    expected = field.density * field.thickness * np.pi * field.radii ** 2
    # a product of four factors: a few roundings
    np.testing.assert_allclose(masses, expected, rtol=1e-14, atol=0.0)
    for a, value in ((radii, 1.0), (masses, 1.0), (frozen, False)):
        assert not a.flags.writeable
        with pytest.raises(ValueError):
            a[FROZEN] = value
    kept = radii.copy(), masses.copy(), frozen.copy()
    pinned = sim.positions[FROZEN]
    sim.advance(2.0)
    for a, b in zip((sim.radii, sim.masses, sim.frozen), kept):
        np.testing.assert_array_equal(a, b)
    # the frozen floe is held fixed (inverse mass 0): it is exactly where it was
    np.testing.assert_array_equal(sim.positions[FROZEN], pinned)
    assert np.all(sim.velocities[FROZEN] == 0.0)


def test_masses_and_frozen_give_momentum_and_energy(kind):
    """The engine's momentum and kinetic energy are those of its ``masses``
    and ``radii`` over the floes that are not ``frozen``: Σ m u and
    Σ (m u²/2 + I ω²/2) with I = m r²/2 for discs."""
    sim = make(kind)
    sim.advance(2.0)
    mobile = ~sim.frozen
    m, r = sim.masses[mobile], sim.radii[mobile]
    u, w = sim.velocities[mobile], sim.angular_velocities[mobile]
    p = (m[:, None] * u).sum(axis=0)
    # sums of 59 terms in another order: rounding only
    scale = float(np.sum(m * np.hypot(u[:, 0], u[:, 1])))
    np.testing.assert_allclose(sim.momentum(), p, rtol=0.0, atol=1e-12 * scale)
    energy = float(np.sum(0.5 * m * (u ** 2).sum(axis=1) + 0.25 * m * r ** 2 * w ** 2))
    assert sim.kinetic_energy() == pytest.approx(energy, rel=1e-12)


def test_concentration_is_the_covered_fraction_of_the_box(kind):
    """A = Σ π r² / (Lx Ly), before and after advancing (the box is fixed)."""
    field, box = small_field()
    sim = make(kind, field, box)
    covered = float(np.sum(np.pi * field.radii ** 2)) / (box.lx * box.ly)
    # sums of 60 areas in another order, and one division: rounding only
    assert isinstance(sim.concentration, float)
    assert sim.concentration == pytest.approx(covered, rel=1e-12)
    assert covered == pytest.approx(0.4, rel=1e-9)             # the field's target
    sim.advance(1.0)
    assert sim.concentration == pytest.approx(covered, rel=1e-12)


def test_assigning_velocities_is_checked(kind):
    sim = make(kind)
    good = np.full((60, 2), 0.01)
    good[FROZEN] = 0.0
    before = sim.velocities
    bad_values = [np.zeros((59, 2)), np.zeros(120), np.where(good == 0.01, np.nan, 0.0),
                  np.full((60, 2), np.inf), np.full((60, 2), 0.01)]      # the last moves the frozen floe
    for bad in bad_values:
        with pytest.raises(ValueError):
            sim.velocities = bad
        np.testing.assert_array_equal(sim.velocities, before)      # nothing changed
    sim.velocities = good
    np.testing.assert_array_equal(sim.velocities, good)
    good[1] = 5.0                                # the engine took a copy
    assert sim.velocities[1, 0] == 0.01


@pytest.mark.parametrize("mistake, error", [
    ("field not a FloeField", TypeError),
    ("box not a Box", TypeError),
    ("forcing not a Forcing", TypeError),
    ("negative duration", ValueError),
    ("non-finite duration", ValueError),
    ("overlapping floes", ValueError),
])
def test_the_same_mistake_gives_the_same_exception(kind, mistake, error):
    field, box = small_field()
    if mistake == "field not a FloeField":
        call = lambda: make(kind, field.positions, box)          # noqa: E731
    elif mistake == "box not a Box":
        call = lambda: make(kind, field, box.lx)                 # noqa: E731
    elif mistake == "forcing not a Forcing":
        call = lambda: make(kind, field, box, forcing=HERMAN2013.forcing)     # noqa: E731
    elif mistake == "overlapping floes":
        field.positions[2] = field.positions[1]
        call = lambda: make(kind, field, box)                    # noqa: E731
    else:
        sim = make(kind, field, box)
        duration = -1.0 if mistake == "negative duration" else np.nan
        call = lambda: sim.advance(duration)                     # noqa: E731
    with pytest.raises(error):
        call()


def _breakdown(kind):
    """A simulation bound to break down within 10 s, and the expected reason."""
    if kind == "harddisk":
        # three discs in a row with ε = 0.05 and no TC model: inelastic collapse
        pos = np.array([[5.0, 10.0], [6.3, 10.0], [7.4, 10.0]])
        vel = np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 0.0]])
        field = FloeField(pos, np.full(3, 0.5), 1.0, vel)
        sim = HardDiskSimulation(field, PeriodicBox(20.0), restitution=0.05,
                                 collision_duration=0.0)
        return sim, FailureReason.INELASTIC_COLLAPSE
    # a box closing at 0.01 per second up to a limit of 0.42
    field, box = small_field()
    box = DeformingPeriodicBox(box.lx, concentration_rate=0.01, max_concentration=0.42)
    return HertzSimulation(field, box), FailureReason.CONCENTRATION_LIMIT


@pytest.mark.parametrize("catch", [SimulationError, RuntimeError, FloatingPointError])
def test_a_breakdown_raises_simulation_error(kind, catch):
    sim, reason = _breakdown(kind)
    with pytest.raises(catch) as err:
        sim.advance(10.0)
    assert isinstance(err.value, SimulationError)
    assert err.value.reason is reason
    assert 0.0 < err.value.time < 10.0
    assert err.value.time == pytest.approx(sim.time)


def test_from_preset_options(kind):
    cls, preset = ENGINES[kind], PRESETS[kind]
    sim = cls.from_preset(preset, 80, 0.5, seed=1, velocity_std=0.01)
    assert isinstance(sim, FloeEngine) and sim.n_floes == 80
    assert sim.forcing.wind.tolist() == [preset.forcing.wind_speed, 0.0]
    assert sim.field.thickness[0] == preset.thickness
    calm = Forcing(preset.forcing, wind=(0.0, 0.0))
    assert cls.from_preset(preset, 80, 0.5, forcing=calm).forcing is calm
    for off in (False, None):
        assert cls.from_preset(preset, 80, 0.5, forcing=off).forcing is None
    with pytest.raises(TypeError, match="PaperPreset"):
        cls.from_preset(preset.contact, 80, 0.5)
    with pytest.raises(TypeError):
        cls.from_preset(preset, 80, 0.5, no_such_option=1)
    with pytest.raises(ValueError):
        cls.from_preset(preset, 80, 1.5)


def test_the_lammps_engine_keeps_the_protocol():
    from physics.lammps_library import lammps_available

    ok, why = lammps_available()
    if not ok:
        pytest.skip(why)
    from physics.lammps_engine import LammpsHertzSimulation

    field, box = small_field()
    with LammpsHertzSimulation(field, box) as sim:
        assert isinstance(sim, FloeEngine)
        assert sim.n_floes == 60 and sim.time == 0.0
        sim.advance(1.0)
        assert sim.time == pytest.approx(1.0)
        assert isinstance(sim.contacts(), Contacts)
        assert isinstance(sim.fabric(), Fabric)
        assert isinstance(sim.contact_stress(), Stress)
        assert isinstance(sim.state(), FloeField) and sim.state().n == 60
        radii, masses, frozen = sim.radii, sim.masses, sim.frozen
        for a in (radii, masses, frozen):
            assert a.shape == (60,) and not a.flags.writeable
            with pytest.raises(ValueError):
                a[0] = 1
        np.testing.assert_array_equal(radii, field.radii)
        assert frozen.dtype == bool and frozen.tolist() == field.frozen.tolist()
        # rtol: the same product ρ h π r² in another order of operations
        np.testing.assert_allclose(masses, field.density * field.thickness * np.pi * radii ** 2,
                                   rtol=1e-12)
        # rtol: the same sum over the floes in another order of operations
        assert sim.concentration == pytest.approx(np.sum(np.pi * radii ** 2) / (box.lx * box.ly),
                                                  rel=1e-12)
        # the masses are those of the dynamics: momentum and kinetic energy
        # (disc inertia m r²/2) of the mobile floes, summed in another order
        # (the momentum's tolerance relative to Σ m |u|, as its sum cancels)
        v, w, m = sim.velocities[~frozen], sim.angular_velocities[~frozen], masses[~frozen]
        np.testing.assert_allclose(sim.momentum(), (m[:, None] * v).sum(axis=0), rtol=0,
                                   atol=1e-12 * np.sum(m[:, None] * np.abs(v)))
        e = 0.5 * np.sum(m * np.sum(v ** 2, axis=1)) + 0.25 * np.sum(m * radii[~frozen] ** 2
                                                                     * w ** 2)
        assert sim.kinetic_energy() == pytest.approx(e, rel=1e-12)
