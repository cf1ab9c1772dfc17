"""Herman (2013) scenarios: the analysis functions on known curves, and small
runs that show the paper's qualitative results."""
from __future__ import annotations

import math

import numpy as np
import pytest

xr = pytest.importorskip("xarray")
pytest.importorskip("yaml")

from physics.scenarios import run_scenario
from physics.scenarios.herman2013 import first_crossing, jamming_from_pressure, shear_zone


def _run(name, out, **overrides):
    res = run_scenario(name, overrides=overrides, out=out, workers=1, progress=False,
                       plots=False, log=lambda *a: None)
    return xr.open_dataset(res.dataset).load()


def test_knee_of_a_two_slope_pressure_curve():
    """ln p with slope 100 below A = 0.9 and 1000 above: the knee within one
    output step (0.002), the slopes within 1 %."""
    rng = np.random.default_rng(0)
    a = np.arange(0.80, 0.95, 0.002)
    lnp = 2.0 + 100 * (a - 0.8) + 900 * np.maximum(0.0, a - 0.9) + rng.normal(0, 0.01, a.size)
    knee, lo, hi = jamming_from_pressure(a, np.exp(lnp))
    assert abs(knee - 0.9) <= 0.002
    assert lo == pytest.approx(100, rel=0.01) and hi == pytest.approx(1000, rel=0.01)
    # zero pressures (no contact at that instant) are skipped; too few points → NaN
    p = np.exp(lnp)
    p[::5] = 0.0
    assert abs(jamming_from_pressure(a, p)[0] - 0.9) <= 0.004
    assert math.isnan(jamming_from_pressure(a[:5], p[:5])[0])


def test_first_crossing_is_where_the_curve_stays_above():
    a = np.linspace(0.8, 0.9, 11)
    z = np.array([0, 2, 3.5, 2, 2, 3.2, 3.4, 3.6, 2.9, 3.1, 3.3])
    assert first_crossing(a, z, 3.0) == pytest.approx(0.89)
    assert math.isnan(first_crossing(a, np.zeros(11), 3.0))


def test_shear_zone_width_of_a_ramp_profile():
    """u_x rising linearly from 0 at y = 20 m to 1 m/s at y = 60 m, flat
    beyond: 10–90 % of the outer speed is 0.8 × 40 m = 32 m (± one bin)."""
    y = np.arange(0.5, 200, 1.0)
    u = np.clip((y - 20) / 40, 0, 1)
    width, outer = shear_zone(y, u, edge_width=10.0)
    assert outer == pytest.approx(1.0)
    assert abs(width - 32.0) <= 1.0


def test_convergence_jams_with_the_papers_signatures(tmp_path):
    """1000 floes from A = 0.80 to 0.90 at 1 per hour: binary collisions well
    below the knee (≤ 1.6 contacts per touching floe, f_nr < 0.1), Z_c > 3 and
    f_nr > 0.3 beyond it, a pressure rise of more than 4 decades, and the
    Z_c > 3 estimate of A_J within 0.02 of the knee.

    The size and range are what makes these hold for any trajectory: with
    300 floes from 0.82 the knee of ln p fell at 0.818-0.866 over seeds 0-11
    (below 0.84, or with no output before it, for some), and Z_c > 3 came up
    to 0.042 after it; with 1000 floes the knee lies at 0.864-0.878 and the
    Z_c estimate 0.006-0.018 after it (seeds 0-11). max_pressure is raised
    so that the run goes on past the knee (1e7 N/m stopped it within 0.01
    of the knee), leaving at least 8 outputs beyond A_J + 0.01."""
    ds = _run("herman2013-convergence", tmp_path / "c", floes=1000, start_concentration=0.80,
              end_concentration=0.90, rate=1.0, output_step=0.002, max_pressure=1e9)
    a = ds["concentration"].values[0, 0]
    aj = float(ds["a_j"].values[0, 0])
    assert 0.84 < aj < 0.89
    early = (a > 0.805) & (a < aj - 0.015)
    late = a > aj + 0.01
    assert early.sum() >= 3 and late.sum() >= 2
    assert np.mean(ds["z_touch"].values[0, 0][early]) <= 1.6
    assert np.mean(ds["f_nr"].values[0, 0][early]) < 0.1
    assert np.mean(ds["z_c"].values[0, 0][late]) > 3.0
    assert np.mean(ds["f_nr"].values[0, 0][late]) > 0.3
    p = ds["p"].values[0, 0]
    assert np.nanmax(p[late]) > 1e4 * np.nanmedian(p[early][p[early] > 0])
    # the Z_c > 3 estimate of A_J agrees with the knee within 0.02
    assert abs(float(ds["a_j_network"].values[0, 0]) - aj) < 0.02


def test_wind_anisotropy_falls_with_concentration(tmp_path):
    """Under wind, loose ice (A = 0.80) carries small and strongly
    anisotropic stresses (τ/p > 0.5); jammed ice (A = 0.90, 200 floes) has a
    nearly isotropic contact network (Z_a < 0.1), τ/p < 0.15 and orders of
    magnitude more pressure (Fig 5: τ and Z_a grow as A decreases).

    Z_a of the loose ice is not tested: there 200 floes have fewer than two
    non-rattlers on average (f_nr ≤ 0.011), and the mean Z_a of one or two
    floes ranged over 0.06-0.52 by seed. Over seeds 0-15 τ/p was 0.77-1.11
    at A = 0.80 and 0.036-0.093 at A = 0.90, Z_a at A = 0.90 at most 0.035,
    and the pressure ratio above 1e7."""
    ds = _run("herman2013-wind", tmp_path / "w", floes=200, concentrations=[0.8, 0.9],
              duration=150.0, output_interval=5.0, snapshot_times=[])
    late = ds["time"].values >= 75.0
    za = [np.nanmean(ds["z_a"].values[c][late[c]]) for c in range(2)]
    p = [np.nanmean(ds["p"].values[c][late[c]]) for c in range(2)]
    tau = [np.nanmean(ds["tau"].values[c][late[c]]) for c in range(2)]
    assert tau[0] > 0.5 * p[0] and tau[1] < 0.15 * p[1]
    assert za[1] < 0.1
    assert p[1] > 100 * p[0]
    assert list(ds.coords["concentration"].values) == [0.8, 0.9]


def test_miz_fast_ice_holds_and_ice_moves_along_the_edge(tmp_path):
    """Frozen floes never move; with onshore wind the floes next to the fast
    ice move slower along it than the outer ice."""
    ds = _run("herman2013-miz", tmp_path / "m", floes=200, wind_y=[-5.0], duration=200.0,
              output_interval=10.0, snapshot_times=[50.0], profile_bins=6)
    frozen = ds["floe_frozen"].values[0, 0, 0].astype(bool)
    assert frozen.any() and not frozen.all()
    for k in range(1, ds.sizes["snapshot"]):
        np.testing.assert_array_equal(ds["floe_x"].values[0, 0, k][frozen],
                                      ds["floe_x"].values[0, 0, 0][frozen])
        np.testing.assert_array_equal(ds["floe_u"].values[0, 0, k][frozen], 0.0)
    prof = np.nanmean(ds["u_x_profile"].values[0, 0][-5:], axis=0)
    assert np.nanmean(prof[-3:]) > 0.01
    assert prof[0] < 0.5 * np.nanmean(prof[-3:])


def test_miz_open_water_moves_the_top_wall_away(tmp_path):
    """With open_water = 1 the channel is twice as wide as the ice: at the
    start every floe lies in the lower half, and the upper half of the
    u_x(y) profile is open water (NaN) at the first output."""
    ds = _run("herman2013-miz", tmp_path / "o", floes=200, wind_y=[-5.0], duration=20.0,
              output_interval=10.0, snapshot_times=[], profile_bins=8, open_water=1.0)
    ly = float(ds["snapshot_ly"].values[0, 0, 0])
    y = ds["floe_y"].values[0, 0, 0]
    r = ds["floe_radius"].values[0, 0, 0]
    assert np.all(y + r <= 0.5 * ly + 1.0)
    assert np.all(np.isnan(ds["u_x_profile"].values[0, 0, 0, 4:]))
    assert np.all(np.isfinite(ds["u_x_profile"].values[0, 0, 0, :4]))


def test_edge_stress_of_ice_at_rest_and_in_free_drift():
    """Momentum balance of the mobile ice (herman2013-miz summary). Floes of
    many sizes at rest under a wind (8, -6) m/s: Coriolis and water drag
    vanish, so the fast ice takes the wind force alone, σ_xy/σ_yy = 8/6
    (1e-12), with σ_yy > 0 (pushed onto the edge) and σ_xy the x wind force
    over the edge length (1e-12). The same floes in their eq 6 free drift
    (with Coriolis, and with an ocean current as well) exert nothing: both
    stresses below 1e-9 of that at rest. Frozen floes and NaN padding are
    left out."""
    from physics.forcing import Forcing, steady_drift
    from physics.params import HERMAN2013
    from physics.scenarios.herman2013 import edge_stress

    h = HERMAN2013.thickness
    r = np.array([1.0, 2.5, 4.0, 30.0, 200.0, 5.0, np.nan])
    frozen = np.array([0, 0, 0, 0, 0, 1, 0])
    wind = (8.0, -6.0)
    snap = {"floe_radius": r, "floe_frozen": frozen, "floe_u": np.zeros(7),
            "floe_v": np.zeros(7), "snapshot_lx": 500.0}
    sxy, syy = edge_stress(snap, wind)
    f = Forcing(HERMAN2013.forcing, wind=wind)
    rm = r[:5]
    a = f.coefficients(rm, np.full(5, h), np.ones(5)).wind
    assert sxy == pytest.approx(float((a * 10.0 * 8.0).sum()) / 500.0, rel=1e-12)
    assert syy > 0 and sxy / syy == pytest.approx(8.0 / 6.0, rel=1e-12)
    drift = np.full((7, 2), np.nan)
    drift[:5] = steady_drift(f, rm, np.full(5, h),
                             HERMAN2013.forcing.ice_density * h * math.pi * rm ** 2)
    sxy_d, syy_d = edge_stress(dict(snap, floe_u=drift[:, 0], floe_v=drift[:, 1]), wind)
    assert abs(sxy_d) < 1e-9 * abs(sxy) and abs(syy_d) < 1e-9 * syy
    # with an ocean current too: the free drift changes, the fast ice still carries nothing
    import dataclasses
    flow = dataclasses.replace(HERMAN2013.forcing, current_speed=0.2, current_angle=1.0)
    f = Forcing(flow, wind=wind)
    drift[:5] = steady_drift(f, rm, np.full(5, h),
                             HERMAN2013.forcing.ice_density * h * math.pi * rm ** 2)
    sxy_c, syy_c = edge_stress(dict(snap, floe_u=drift[:, 0], floe_v=drift[:, 1]), wind,
                               forcing_params=flow)
    assert abs(sxy_c) < 1e-9 * abs(sxy) and abs(syy_c) < 1e-9 * syy


def test_channel_fields_are_placed_above_the_random_placement_limit():
    """A channel (walls, no periodic compression) is filled directly at
    A = 0.87: the floe area over the box area is 0.87 to 1e-9, and no two
    floes overlap by more than 1 % of the smaller radius."""
    from physics.domain import ChannelBox
    from physics.floes import max_overlap
    from physics.scenarios.herman2013 import _field

    field, box = _field(400, 0.87, 3, aspect=0.5, box_type=ChannelBox)
    assert field.total_area / (box.lx * box.ly) == pytest.approx(0.87, rel=1e-9)
    assert max_overlap(field.positions, field.radii, box) <= 0.01


@pytest.mark.parametrize("name", ["herman2013-convergence", "herman2013-wind", "herman2013-miz"])
def test_contact_parameters_reach_the_contact_law(name):
    """friction, restitution, tangential_damping, tangential_stiffness and
    friction_moves_floes of every Herman (2013) scenario end up in the
    ContactParams of its simulations (defaults: the paper's friction, our
    restitution 0.5, no tangential damping, the Mindlin stiffness, friction
    acting on translation)."""
    from physics.params import HERMAN2013
    from physics.scenarios.herman2013 import contact_law
    from physics.scenarios.runner import find_config

    defaults = find_config(name).defaults()
    def law(c):
        return (c.friction, c.restitution, c.tangential_damping, c.tangential_stiffness,
                c.tangential_translation)

    assert law(contact_law(defaults)) == (HERMAN2013.contact.friction, 0.5, 0.0, 1.0, True)
    changed = dict(defaults, friction=0.3, restitution=0.9, tangential_damping=0.5,
                   tangential_stiffness=0.24, friction_moves_floes=False)
    assert law(contact_law(changed)) == (0.3, 0.9, 0.5, 0.24, False)
