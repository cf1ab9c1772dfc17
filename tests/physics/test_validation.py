"""Bad input is refused with a ValueError that names the offending field,
before any work starts."""
from __future__ import annotations

import numpy as np
import pytest

from physics import (ContactParams, DeformingPeriodicBox, FloeField, Forcing, ForcingParams,
                     HertzSimulation, PeriodicBox, WalledBox, make_floe_field)

from reference.dem import disc_mass, hertz_contact_time, hertz_k

POS = np.array([[10.0, 10.0], [20.0, 10.0], [10.0, 25.0]])
RADII = np.array([2.0, 3.0, 1.5])


@pytest.mark.parametrize("kwargs, field", [
    (dict(radii=[2.0, 0.0, 1.5]), "radii"),
    (dict(radii=[2.0, -1.0, 1.5]), "radii"),
    (dict(radii=[2.0, np.nan, 1.5]), "radii"),
    (dict(radii=[2.0, np.inf, 1.5]), "radii"),
    (dict(thickness=0.0), "thickness"),
    (dict(thickness=[1.0, -0.5, 1.0]), "thickness"),
    (dict(thickness=[1.0, np.nan, 1.0]), "thickness"),
    (dict(density=0.0), "density"),
    (dict(density=-910.0), "density"),
    (dict(density=np.nan), "density"),
    (dict(positions=[[10.0, 10.0], [np.nan, 10.0], [10.0, 25.0]]), "positions"),
    (dict(positions=[[10.0, 10.0], [20.0, np.inf], [10.0, 25.0]]), "positions"),
    (dict(velocities=[[0.0, 0.0], [np.nan, 0.0], [0.0, 0.0]]), "velocities"),
    (dict(velocities=[[0.0, 0.0], [0.0, -np.inf], [0.0, 0.0]]), "velocities"),
    (dict(angular_velocities=[0.0, np.nan, 0.0]), "angular_velocities"),
    (dict(positions=np.zeros((2, 2))), "positions"),
    (dict(velocities=np.zeros((3, 3))), "velocities"),
])
def test_floe_field_rejects_bad_values(kwargs, field):
    """FloeField refuses non-positive or non-finite radii, thickness and
    density, non-finite positions and velocities and wrong shapes, with a
    ValueError naming the field."""
    args = dict(positions=POS, radii=RADII, thickness=1.0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=field):
        FloeField(**args)


@pytest.mark.parametrize("kwargs, field", [
    (dict(elastic_modulus=0.0), "elastic_modulus"),
    (dict(elastic_modulus=-9e9), "elastic_modulus"),
    (dict(elastic_modulus=np.inf), "elastic_modulus"),
    (dict(restitution=0.0), "restitution"),
    (dict(restitution=-0.5), "restitution"),
    (dict(restitution=1.0 + 1e-9), "restitution"),
    (dict(restitution=np.nan), "restitution"),
    (dict(friction=-0.1), "friction"),
    (dict(friction=np.nan), "friction"),
    (dict(poisson_ratio=0.5), "poisson_ratio"),
    (dict(poisson_ratio=-1.0), "poisson_ratio"),
    (dict(tangential_damping=-1.0), "tangential_damping"),
    (dict(damping_model="tsuji"), "damping_model"),
])
def test_contact_params_reject_bad_values(kwargs, field):
    """ContactParams refuses E <= 0, restitution outside (0, 1], friction < 0,
    Poisson ratio outside (-1, 0.5), negative tangential damping and unknown
    damping models, naming the field."""
    with pytest.raises(ValueError, match=field):
        ContactParams(**kwargs)


def test_contact_params_accept_limits():
    """restitution = 1 (elastic) and friction = 0 (frictionless) are valid."""
    ContactParams(restitution=1.0, friction=0.0)


@pytest.mark.parametrize("kwargs, field", [
    (dict(ice_density=0.0), "ice_density"),
    (dict(ice_density=1100.0), "ice_density"),
    (dict(water_density=-1.0), "water_density"),
    (dict(water_skin_drag=-1e-3), "water_skin_drag"),
    (dict(wind_speed=np.nan), "wind_speed"),
    (dict(coriolis=np.inf), "coriolis"),
])
def test_forcing_params_reject_bad_values(kwargs, field):
    """ForcingParams refuses non-positive densities, ice denser than water,
    negative drag coefficients and non-finite values, naming the field."""
    with pytest.raises(ValueError, match=field):
        ForcingParams(**kwargs)


@pytest.mark.parametrize("attribute, value", [
    ("wind", (np.nan, 0.0)),
    ("wind", (1.0, 2.0, 3.0)),
    ("current", (0.0, np.inf)),
    ("coriolis", np.nan),
])
def test_forcing_rejects_bad_vectors(attribute, value):
    """Setting a non-finite or wrongly shaped wind/current or a non-finite
    Coriolis parameter raises a ValueError naming it."""
    forcing = Forcing()
    with pytest.raises(ValueError, match=attribute):
        setattr(forcing, attribute, value)


def _max_dt(radius, thickness, contact, speed):
    """A tenth of the undamped contact time of two equal floes of this size."""
    m = disc_mass(radius, thickness)
    return 0.1 * hertz_contact_time(0.5 * m, hertz_k(contact, 0.5 * radius), speed)


@pytest.mark.parametrize("speed", [0.1, 2.0])
def test_time_step_above_tenth_of_contact_time_is_refused(speed):
    """dt above a tenth of the Hertz contact time of the smallest floes at
    impact_speed raises a ValueError naming dt; dt just below is accepted."""
    contact = ContactParams()
    floes = FloeField(POS, RADII, 1.0)
    limit = _max_dt(RADII.min(), 1.0, contact, speed)
    HertzSimulation(floes, PeriodicBox(60.0), contact, None, 0.999 * limit, impact_speed=speed)
    with pytest.raises(ValueError, match="dt"):
        HertzSimulation(floes, PeriodicBox(60.0), contact, None, 1.001 * limit,
                        impact_speed=speed)


@pytest.mark.parametrize("dt", [0.0, -1e-3, np.nan])
def test_bad_time_step_is_refused(dt):
    """A non-positive or NaN dt raises a ValueError naming dt."""
    with pytest.raises(ValueError, match="dt"):
        HertzSimulation(FloeField(POS, RADII, 1.0), PeriodicBox(60.0), dt=dt)


def test_initial_overlap_above_one_percent_is_refused():
    """Floes overlapping by more than 1 % of the smaller radius are refused
    (ValueError naming the overlap) unless allow_overlap=True; 0.9 % passes."""
    r = 2.0
    for frac, ok in ((0.009, True), (0.011, False)):
        pos = np.array([[20.0, 20.0], [20.0 + 2 * r - frac * r, 20.0]])
        floes = FloeField(pos, [r, r], 1.0)
        if ok:
            HertzSimulation(floes, PeriodicBox(60.0), dt=1e-4)
        else:
            with pytest.raises(ValueError, match="overlap"):
                HertzSimulation(floes, PeriodicBox(60.0), dt=1e-4)
            sim = HertzSimulation(floes, PeriodicBox(60.0), dt=1e-4, allow_overlap=True)
            assert sim.contacts().overlap[0] == pytest.approx(frac * r, rel=1e-9)
            sim.step(10)


def test_overlap_with_unequal_floes_is_relative_to_smaller_radius():
    """The 1 % overlap limit refers to the smaller floe: an overlap of 2 % of
    the small radius (0.2 % of the large one) is refused."""
    pos = np.array([[30.0, 30.0], [30.0 + 10.0 + 1.0 - 0.02, 30.0]])
    floes = FloeField(pos, [10.0, 1.0], 1.0)
    with pytest.raises(ValueError, match="overlap"):
        HertzSimulation(floes, PeriodicBox(100.0), dt=1e-4)


def test_periodic_box_too_small_is_refused():
    """A periodic side not exceeding 2 (2 r_max + skin) is refused, naming the axis."""
    floes = FloeField(np.array([[5.0, 5.0]]), [2.0], 1.0)
    with pytest.raises(ValueError, match="too small along x"):
        HertzSimulation(floes, PeriodicBox(8.0, 100.0), dt=1e-4)


def test_floe_outside_walled_box_is_refused():
    """A floe centre outside a walled box raises a ValueError."""
    floes = FloeField(np.array([[5.0, 5.0], [25.0, 5.0]]), [1.0, 1.0], 1.0)
    with pytest.raises(ValueError, match="outside"):
        HertzSimulation(floes, WalledBox(20.0, 20.0), dt=1e-4)


@pytest.mark.parametrize("make, field", [
    (lambda: PeriodicBox(0.0), "lx"),
    (lambda: PeriodicBox(10.0, -1.0), "ly"),
    (lambda: PeriodicBox(np.nan), "lx"),
    (lambda: DeformingPeriodicBox(50.0, concentration_rate=np.inf), "concentration_rate"),
    (lambda: DeformingPeriodicBox(50.0, max_concentration=1.5), "max_concentration"),
    (lambda: DeformingPeriodicBox(50.0, axes="z"), "axes"),
])
def test_boxes_reject_bad_values(make, field):
    """Box sides must be positive and finite; deforming-box rate finite,
    max_concentration in (0, 1], axes one of xy/x/y."""
    with pytest.raises(ValueError, match=field):
        make()


@pytest.mark.parametrize("kwargs, field", [
    (dict(concentration=1.0), "concentration"),
    (dict(concentration=0.0), "concentration"),
    (dict(alpha=0.0), "alpha"),
    (dict(mean_diameter=-2.0), "mean_diameter"),
])
def test_make_floe_field_rejects_bad_values(kwargs, field):
    """make_floe_field refuses a concentration outside (0, 1), alpha <= 0 and
    a non-positive mean diameter, naming the argument."""
    args = dict(concentration=0.5, alpha=1.5, mean_diameter=2.0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=field):
        make_floe_field(50, **args)


def test_run_never_returns_nan_silently():
    """An impact far faster than the impact_speed the time step was chosen
    for makes the integration fail loudly (FloatingPointError) or stay
    finite; it never leaves NaN in the state."""
    contact = ContactParams(restitution=1.0, friction=0.0)
    r = 1.0
    dt = _max_dt(r, 1.0, contact, 1e-3)
    pos = np.array([[10.0, 10.0], [10.0 + 2 * r + 1e-3, 10.0]])
    floes = FloeField(pos, [r, r], 1.0, np.array([[400.0, 0.0], [-400.0, 0.0]]))
    sim = HertzSimulation(floes, PeriodicBox(40.0), contact, None, dt, impact_speed=1e-3)
    try:
        sim.step(200)
    except FloatingPointError:
        return
    assert np.all(np.isfinite(sim.positions)) and np.all(np.isfinite(sim.velocities))
