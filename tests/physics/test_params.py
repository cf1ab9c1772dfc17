"""Parameter tables of the papers and the closed-form parts of the contact
law (Herman 2011 Table I, Herman 2013 Table 1; the Physics page: physics-drag, physics-contact)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from physics import HERMAN2011, HERMAN2013, ContactParams, PaperPreset
from physics.contact import (contact_time, damping_alpha, hertz_stiffness, lammps_damping_alpha,
                             peak_overlap, restitution_of_alpha)
from physics.hertz import minimum_contact_time

from reference.dem import HERTZ_TIME_CONSTANT, disc_mass, hertz_contact_time, hertz_peak_overlap


def test_herman2013_table1():
    """Herman (2013) Table 1: densities 910/1025/1.23 kg/m^3, C_ha = C_va = 2e-3,
    C_hw = C_vw = 1e-3 m/s, wind 10 m/s, no current, f = 1.3e-4 1/s,
    h = 1.5 m, alpha = 1.8, mean radius 4 m, E = 9e9 Pa, nu = 0.33, mu = 0.7,
    N = 20000, dt = 0.002 s, 5 members; edge area pi r h_f."""
    p = HERMAN2013
    f = p.forcing
    assert (f.ice_density, f.water_density, f.air_density) == (910.0, 1025.0, 1.23)
    assert (f.air_skin_drag, f.air_form_drag) == (2.0e-3, 2.0e-3)
    assert (f.water_skin_drag, f.water_form_drag) == (1.0e-3, 1.0e-3)
    assert f.wind_speed == 10.0 and f.current_speed == 0.0 and f.coriolis == 1.3e-4
    assert f.edge_area_factor == pytest.approx(math.pi)
    assert p.thickness == 1.5 and p.fsd_exponent == 1.8 and p.mean_radius == 4.0
    c = p.contact
    assert (c.elastic_modulus, c.poisson_ratio, c.friction) == (9.0e9, 0.33, 0.7)
    assert p.n_floes == 20000 and p.time_step == 0.002 and p.ensemble_members == 5


def test_herman2011_table1():
    """Herman (2011) Table I: C_ha = C_va = 1.7e-3, C_hw = C_vw = 1.3e-3 m/s,
    wind 10 m/s, current 0.01 |u_a| along the wind, f = 0, h = 1.5 m,
    restitution 0.85, alpha = 1.5, mean diameter 2 m, N = 3000, 10^2 cells,
    dt_max = 1 s, dt_c = 0.1 s, 5 members; edge area d h_f."""
    p = HERMAN2011
    f = p.forcing
    assert (f.air_skin_drag, f.air_form_drag) == (1.7e-3, 1.7e-3)
    assert (f.water_skin_drag, f.water_form_drag) == (1.3e-3, 1.3e-3)
    assert f.wind_speed == 10.0 and f.current_speed == pytest.approx(0.01 * f.wind_speed)
    np.testing.assert_allclose(f.current_vector(), [0.1, 0.0], atol=1e-15)
    assert f.coriolis == 0.0 and f.edge_area_factor == 2.0
    assert p.thickness == 1.5 and p.contact.restitution == 0.85
    assert p.fsd_exponent == 1.5 and p.mean_diameter == 2.0 and p.n_floes == 3000
    assert p.n_cells == 10 and p.max_velocity_step == 1.0 and p.collision_duration == 0.1
    assert p.ensemble_members == 5


def test_preset_replace_validates():
    """PaperPreset.replace returns a changed copy and validates it."""
    p = HERMAN2013.replace(thickness=2.0)
    assert isinstance(p, PaperPreset) and p.thickness == 2.0 and HERMAN2013.thickness == 1.5
    with pytest.raises(ValueError, match="thickness"):
        HERMAN2013.replace(thickness=-1.0)


@pytest.mark.parametrize("e_mod, nu", [(9e9, 0.33), (1e9, 0.0), (5e9, -0.2)])
def test_effective_moduli(e_mod, nu):
    """E* = E / (2 (1 - nu^2)), G* = E / (4 (2 - nu)(1 + nu)) for two floes of
    the same ice, and E/(1 - nu^2), E/(2 (2 - nu)(1 + nu)) against a rigid
    wall (to 1e-14)."""
    c = ContactParams(elastic_modulus=e_mod, poisson_ratio=nu)
    assert c.effective_modulus == pytest.approx(e_mod / (2 * (1 - nu ** 2)), rel=1e-14)
    assert c.effective_shear_modulus == pytest.approx(e_mod / (4 * (2 - nu) * (1 + nu)), rel=1e-14)
    assert c.wall_effective_modulus == pytest.approx(e_mod / (1 - nu ** 2), rel=1e-14)
    assert c.wall_effective_shear_modulus == pytest.approx(e_mod / (2 * (2 - nu) * (1 + nu)),
                                                           rel=1e-14)


@pytest.mark.parametrize("e", [0.05, 0.1, 0.5, 0.85, 0.99])
def test_lammps_damping_alpha(e):
    """alpha = sqrt(5) |ln e| / sqrt(pi^2 + ln^2 e), and the damping
    eta = alpha sqrt(m* (4/3) E* sqrt(R* delta)) equals the LAMMPS form
    2 sqrt(5/6) |beta| sqrt(2 E* sqrt(R* delta) m*), beta = ln e / sqrt(ln^2 e + pi^2)
    (to 1e-13)."""
    ln_e = math.log(e)
    alpha = math.sqrt(5) * abs(ln_e) / math.sqrt(math.pi ** 2 + ln_e ** 2)
    assert lammps_damping_alpha(e) == pytest.approx(alpha, rel=1e-14)
    assert ContactParams(restitution=e, damping_model="lammps").damping_alpha == pytest.approx(
        alpha, rel=1e-14)
    e_star, r_eff, m_eff, delta = 4.9e9, 0.8, 3000.0, 1e-4
    beta = ln_e / math.sqrt(ln_e ** 2 + math.pi ** 2)
    eta = alpha * math.sqrt(m_eff * 4 / 3 * e_star * math.sqrt(r_eff * delta))
    eta_lammps = (2 * math.sqrt(5 / 6) * abs(beta)
                  * math.sqrt(2 * e_star * math.sqrt(r_eff * delta) * m_eff))
    assert eta == pytest.approx(eta_lammps, rel=1e-13)


def _restitution_by_integration(alpha, limit_damping):
    """Restitution of x'' = -x^(3/2) - alpha x^(1/4) x', x(0) = 0, x'(0) = 1,
    by explicit RK4 with a fine fixed step, ending at separation (x = 0) or,
    with limit_damping, when the total force first reaches zero."""
    def acc(x, v):
        xp = max(x, 0.0)
        f = xp ** 1.5 + alpha * xp ** 0.25 * v
        return -(max(f, 0.0) if limit_damping else f)

    h = 2e-4
    x, v = 0.0, 1.0
    for _ in range(200000):
        k1x, k1v = v, acc(x, v)
        k2x, k2v = v + 0.5 * h * k1v, acc(x + 0.5 * h * k1x, v + 0.5 * h * k1v)
        k3x, k3v = v + 0.5 * h * k2v, acc(x + 0.5 * h * k2x, v + 0.5 * h * k2v)
        k4x, k4v = v + h * k3v, acc(x + h * k3x, v + h * k3v)
        x_new = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        v_new = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        if x_new <= 0.0 and v_new < 0.0:
            return -v_new
        if limit_damping and v_new < 0.0 and acc(x_new, v_new) == 0.0:
            return -v_new
        x, v = x_new, v_new
    raise AssertionError("no separation")


@pytest.mark.parametrize("e", [0.1, 0.5, 0.85])
def test_exact_damping_alpha_by_independent_integration(e):
    """The "exact" alpha of ContactParams (with force clipping) gives the
    target restitution when the dimensionless damped Hertz impact is
    integrated independently (RK4): within 1e-3."""
    alpha = ContactParams(restitution=e).damping_alpha
    assert _restitution_by_integration(alpha, True) == pytest.approx(e, abs=1e-3)


@pytest.mark.parametrize("e", [0.2, 0.5, 0.85])
def test_lammps_alpha_without_clipping_by_independent_integration(e):
    """Without clipping, the LAMMPS alpha reproduces the target restitution
    of the dimensionless damped Hertz impact (RK4): within 1e-3; with
    clipping it gives a larger restitution (the attractive tail is cut)."""
    alpha = lammps_damping_alpha(e)
    assert _restitution_by_integration(alpha, False) == pytest.approx(e, abs=1e-3)
    assert _restitution_by_integration(alpha, True) > e + 1e-3


def test_restitution_of_alpha_limits():
    """restitution_of_alpha(0) = 1, and the restitution falls as alpha grows."""
    assert restitution_of_alpha(0.0) == 1.0
    values = [restitution_of_alpha(a) for a in (0.05, 0.3, 1.0, 2.0)]
    assert all(a > b for a, b in zip(values, values[1:]))
    assert damping_alpha(1.0) == 0.0


def test_closed_form_contact_helpers():
    """hertz_stiffness = (4/3) E* sqrt(R*), contact_time = 3.2181 (m*/k)^(2/5)
    v^(-1/5) and peak_overlap = (5 m* v^2/(4 k))^(2/5) (to 1e-4 for the
    rounded constant, 1e-14 otherwise); minimum_contact_time is the contact
    time of two of the smallest floes."""
    e_star, r_eff, m_eff, v = 4.9e9, 0.75, 2500.0, 0.3
    k = hertz_stiffness(e_star, r_eff)
    assert k == pytest.approx(4 / 3 * e_star * math.sqrt(r_eff), rel=1e-14)
    assert contact_time(m_eff, k, v) == pytest.approx(hertz_contact_time(m_eff, k, v), rel=1e-4)
    assert HERTZ_TIME_CONSTANT == pytest.approx(3.2181, abs=5e-5)
    assert peak_overlap(m_eff, k, v) == pytest.approx(hertz_peak_overlap(m_eff, k, v), rel=1e-14)
    c = ContactParams()
    radii = np.array([3.0, 0.7, 5.0])
    m = disc_mass(0.7, 1.2)
    want = hertz_contact_time(0.5 * m, hertz_stiffness(c.effective_modulus, 0.35), 0.1)
    assert minimum_contact_time(radii, 1.2, 910.0, c, 0.1) == pytest.approx(want, rel=1e-4)


# -- set-up written once: a preset builds its floe field and its forcing -------

@pytest.mark.parametrize("preset", [HERMAN2011, HERMAN2013], ids=lambda p: p.name)
def test_preset_floe_field_follows_preset(preset):
    from physics import make_floe_field

    field, box = preset.floe_field(150, 0.6, seed=4)
    assert field.n == 150
    assert field.concentration(box) == pytest.approx(0.6, rel=1e-9)
    assert np.all(field.thickness == preset.thickness)
    assert field.density == preset.forcing.ice_density
    # exactly the call written out by hand
    ref, ref_box = make_floe_field(150, concentration=0.6, alpha=preset.fsd_exponent,
                                   mean_diameter=preset.mean_diameter,
                                   thickness=preset.thickness,
                                   density=preset.forcing.ice_density, seed=4)
    assert (box.lx, box.ly) == (ref_box.lx, ref_box.ly)
    np.testing.assert_array_equal(field.positions, ref.positions)
    np.testing.assert_array_equal(field.radii, ref.radii)


def test_preset_floe_field_defaults_and_seed():
    small = HERMAN2011.replace(n_floes=120, concentration=0.5)
    a, box_a = small.floe_field(seed=7)
    b, box_b = small.floe_field(seed=7)
    c, _ = small.floe_field(seed=8)
    assert a.n == 120 and a.concentration(box_a) == pytest.approx(0.5, rel=1e-9)
    assert (box_a.lx, box_a.ly) == (box_b.lx, box_b.ly)
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.radii, b.radii)
    assert not np.array_equal(a.positions, c.positions)


def test_preset_floe_field_overrides():
    from physics import ChannelBox

    field, box = HERMAN2013.floe_field(100, 0.5, seed=2, aspect=0.5, box_type=ChannelBox,
                                       velocity_std=0.01, repeat=4, thickness=2.0)
    assert isinstance(box, ChannelBox)
    assert box.ly == pytest.approx(0.5 * box.lx)
    assert field.n == 400
    assert np.all(field.thickness == 2.0)
    assert np.std(field.velocities) > 0


@pytest.mark.parametrize("kwargs", [
    {"n": 0}, {"n": -5}, {"n": 10.5}, {"concentration": 0.0}, {"concentration": 1.0},
    {"concentration": float("nan")}, {"n": 10, "repeat": 0}, {"n": 10, "aspect": -1.0},
])
def test_preset_floe_field_rejects_bad_values(kwargs):
    with pytest.raises(ValueError):
        HERMAN2013.floe_field(**{"n": 10, "concentration": 0.5, **kwargs})


def test_preset_floe_field_rejects_unknown_keyword():
    with pytest.raises(TypeError):
        HERMAN2013.floe_field(10, 0.5, colour="white")


def test_preset_make_forcing():
    from physics import Forcing

    f = HERMAN2013.make_forcing()
    ref = Forcing(HERMAN2013.forcing)
    assert f.params is HERMAN2013.forcing
    np.testing.assert_array_equal(f.wind, ref.wind)
    np.testing.assert_array_equal(f.current, ref.current)
    assert f.coriolis == ref.coriolis

    calm = HERMAN2011.make_forcing(wind_speed=0.0, coriolis=0.0)
    assert calm.wind.tolist() == [0.0, 0.0] and calm.coriolis == 0.0
    assert calm.current.tolist() == list(HERMAN2011.forcing.current_vector())
    assert calm.params.water_skin_drag == HERMAN2011.forcing.water_skin_drag

    turned = HERMAN2013.make_forcing(wind=(0.0, -3.0), current=(0.1, 0.0))
    assert turned.wind.tolist() == [0.0, -3.0] and turned.current.tolist() == [0.1, 0.0]
    # a new object every call: changing one does not change another
    assert HERMAN2013.make_forcing() is not f


@pytest.mark.parametrize("kwargs, error", [
    ({"wind_speed": -1.0}, ValueError), ({"ice_density": 2000.0}, ValueError),
    ({"wind": (1.0, 2.0, 3.0)}, ValueError), ({"wind_vector": 3.0}, TypeError),
])
def test_preset_make_forcing_rejects_bad_values(kwargs, error):
    with pytest.raises(error):
        HERMAN2013.make_forcing(**kwargs)


# -- the Godlovitch et al. ITD preset ------------------------------------------

def test_godlovitch_preset_values():
    """The constants of the Godlovitch figures, environment and benchmark."""
    from physics import GODLOVITCH, ItdPreset

    g = GODLOVITCH
    assert isinstance(g, ItdPreset) and g.name == "godlovitch"
    assert (g.n_classes, g.class_width, g.year_days, g.time_step) == (200, 0.1, 360.0, 1.0)
    assert (g.days, g.tail_min, g.tail_target) == (2000, 2.0, 1.0)
    assert g.kernels == {"constant": {"r": 0.00341},
                         "exponential": {"r": 0.0141, "beta": 0.2},
                         "multiplicative": {"r": 0.000498},
                         "additive": {"r": 0.000477}}
    assert list(g.kernels) == ["constant", "exponential", "multiplicative", "additive"]
    assert g.r0 == 0.00341 and g.raft_factor == 4.0
    assert g.raft_cutoffs == (0.2, 0.5, 1.0, 2.0) and g.raft_lambda_target == 0.9
    assert g.relative_strengths == (0.5, 1.0, 2.0, 5.0, 10.0)
    assert g.scm_times == (0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0)
    assert (g.scm_kmax, g.scm_classes) == (50, 400)
    assert g.rafting_params(1.0) == {"r": 0.00341, "h_raft": 1.0, "factor": 4.0}
    with pytest.raises(AttributeError):
        g.r_constant = 1.0                         # frozen
    # the model's defaults are the preset's
    from physics.itd import YEAR_DAYS, ThorndikeModel
    m = ThorndikeModel("constant", **g.kernel_params("constant"))
    assert (m.n, m.dh, YEAR_DAYS) == (g.n_classes, g.class_width, g.year_days)


@pytest.mark.parametrize("changes", [
    {"n_classes": 1}, {"n_classes": 20.5}, {"class_width": 0.0}, {"r_constant": -1.0},
    {"r_additive": float("nan")}, {"raft_factor": 0.5}, {"raft_cutoffs": ()},
    {"raft_cutoffs": (0.5, -1.0)}, {"relative_strengths": [1.0]}, {"scm_kmax": 500},
    {"days": 0},
])
def test_godlovitch_preset_validates(changes):
    from physics import GODLOVITCH

    with pytest.raises(ValueError):
        GODLOVITCH.replace(**changes)


def test_godlovitch_kernel_params_rejects_unknown():
    from physics import GODLOVITCH

    with pytest.raises(ValueError, match="unknown kernel"):
        GODLOVITCH.kernel_params("rafting")
    with pytest.raises(ValueError):
        GODLOVITCH.rafting_params(-1.0)
    # a fresh dict every call: changing it does not change the preset
    k = GODLOVITCH.kernels
    k["constant"]["r"] = 1.0
    assert GODLOVITCH.kernels["constant"]["r"] == 0.00341
