"""The ship of the Hertz engine against a kinematic hull in pymunk.

Tolerances: a head-on impact of a floe at rest by the flat bow or the stem
gives the impulse (1 + e) m v in pymunk to rounding (1e-12) and in the Hertz
engine within 2e-4 at dt = t_c/1000 (largest at e = 0.3), so the engines are
compared within the issue's 1e-3. The dilute transit (five fields of the
reduced channel, 50-65 floes each, about 30 hull collisions per field) is
compared with the report's acceptance: the mean per-seed difference within
TRANSIT_TOLERANCE standard errors of the difference. Over 40 other fields of
this channel the mean relative difference of the resistance was +0.7 % with a
standard error of 1.0 %, and of the collisions -0.5 +- 0.6 out of 29; giving
pymunk the restitution e^2 (the shapes' elasticity e instead of sqrt(e))
lowers its resistance by a fifth and fails the check.
"""
from __future__ import annotations

import math

import numpy as np
import pymunk
import pytest

from physics import FloeField, WalledBox
from physics.crosscheck.pymunk_ship import (HULL, TRANSIT_QUICK, TRANSIT_TOLERANCE,
                                            PymunkShipSimulation, dilute_transit,
                                            hertz_hull_impact, hertz_transit, pymunk_hull_impact,
                                            pymunk_transit, seed_comparison, single_impacts,
                                            transit_fields)
from physics.crosscheck.report import GROUPS
from physics.hull import Hull


def test_hull_is_a_kinematic_polygon_with_the_hulls_corners():
    hull = Hull.pointed(40.0, 10.0)
    field = FloeField(np.array([[60.0, 20.0], [80.0, 30.0]]), np.array([1.0, 2.5]), 1.0)
    sim = PymunkShipSimulation(field, WalledBox(100.0, 40.0), hull, (25.0, 20.0), 2.0,
                               restitution=0.49, friction=0.16, dt=0.01)
    assert sim.body.body_type == pymunk.Body.KINEMATIC
    assert sim.shape.collision_type == HULL
    corners = np.array([tuple(v) for v in sim.shape.get_vertices()])
    # pymunk keeps the convex polygon; compare as sets of corners
    assert sorted(map(tuple, np.round(corners, 12))) == sorted(map(tuple, np.round(
        hull.vertices, 12)))
    assert sim.shape.elasticity == pytest.approx(0.7, rel=1e-15)
    assert sim.shape.friction == pytest.approx(0.4, rel=1e-15)
    np.testing.assert_allclose(sim.floes.masses, field.masses, rtol=1e-15)
    np.testing.assert_allclose(sim.floes.moments, 0.5 * field.masses * field.radii ** 2,
                               rtol=1e-15)
    sim.step(100)
    assert sim.hull_position == pytest.approx([27.0, 20.0], abs=1e-9)
    assert sim.time == pytest.approx(1.0)


@pytest.mark.parametrize("restitution", [0.3, 0.5, 0.9])
@pytest.mark.parametrize("feature", ["edge", "vertex"])
def test_head_on_impulse_agrees_with_pymunk(feature, restitution):
    """A floe at rest hit head-on at 2 m/s by the flat bow (edge) or the
    stem (vertex): the impulse on the hull agrees within 1e-3 (Hertz
    collision log against pymunk's momentum change of the floe, both
    negative: the floe pushes the hull back); pymunk gives (1 + e) m v and
    its post-solve sum equals the momentum change to rounding, with the pair
    values e and mu of the product rule."""
    mu, v = 0.1, 2.0
    hz = hertz_hull_impact(feature, restitution, mu, v)
    pm = pymunk_hull_impact(feature, restitution, mu, v)
    law = -(1.0 + restitution) * pm["mass"] * v
    assert hz["collisions"] == 1 and pm["collisions"] == 1
    assert pm["impulse"][0] == pytest.approx(law, rel=1e-12)
    np.testing.assert_allclose(pm["arbiter_impulse"], pm["impulse"], rtol=0.0,
                               atol=1e-12 * abs(law))
    ((e_pair, mu_pair),) = pm["pair"]
    assert (e_pair, mu_pair) == pytest.approx((restitution, mu), rel=1e-12)
    assert hz["impulse"][0] / pm["impulse"][0] == pytest.approx(1.0, abs=1e-3)
    assert abs(hz["impulse"][1]) < 1e-9 * abs(law)


def test_single_impact_rows():
    rows = {r.name: r for r in single_impacts(None, progress=False, restitutions=(0.5,))}
    assert set(rows) == {"ship/impact/edge/hertz-vs-pymunk", "ship/impact/vertex/hertz-vs-pymunk"}
    for row in rows.values():
        assert row.tolerance == 1e-3 and row.passed, row.detail


def test_seed_comparison_is_paired():
    c = seed_comparison([1.0, 2.0, 3.0], [1.0, 1.0, 1.0])
    assert c["difference"] == pytest.approx(1.0)
    assert c["paired_error"] == pytest.approx(1.0 / math.sqrt(3.0))
    assert c["t"] == pytest.approx(math.sqrt(3.0))
    assert c["combined_error"] == pytest.approx(1.0 / math.sqrt(3.0))
    with pytest.raises(ValueError):
        seed_comparison([1.0], [1.0])


@pytest.fixture(scope="module")
def quick_runs():
    p = dict(TRANSIT_QUICK)
    fields = transit_fields(p, seed=0)
    return p, fields, [hertz_transit(f, p) for f in fields]


def test_dilute_transit_agrees_over_five_seeds(quick_runs):
    """Five fields of the reduced channel: collisions and mean resistance of
    the two engines agree within TRANSIT_TOLERANCE standard errors of the
    paired difference, and the seed means within 10 %."""
    rows = {r.name: r for r in dilute_transit(None, quick=True, seed=0, progress=False)}
    assert set(rows) == {"ship/transit/collisions", "ship/transit/resistance"}
    for row in rows.values():
        assert row.tolerance == TRANSIT_TOLERANCE
        assert row.measured <= TRANSIT_TOLERANCE, row.detail
    p, fields, hz = quick_runs
    pm = [pymunk_transit(f, p) for f in fields]
    for key in ("collisions", "resistance"):
        a = np.array([r[key] for r in hz])
        b = np.array([r[key] for r in pm])
        assert a.mean() == pytest.approx(b.mean(), rel=0.1), key
    assert min(r["collisions"] for r in pm) >= 15


def test_dilute_transit_sees_a_wrong_restitution(quick_runs):
    """pymunk with the pair restitution e^2 instead of e (the shapes'
    elasticity e instead of sqrt(e)): its mean resistance is lower than
    ours by 10-21 % over the field sets of seeds 0-13, while with the right
    restitution the two differ by at most 8 %; 5 % is asserted.

    The seed comparison's t of this difference ranged over 1.5-9.1 on those
    field sets (6.5 on these): five fields detect a bias of this size at the
    tolerance of 4.6 for only about half of them, so the check's verdict is
    not what this test asserts."""
    p, fields, hz = quick_runs
    pm = [pymunk_transit(f, p, restitution=0.25) for f in fields]
    c = seed_comparison([r["resistance"] for r in hz], [r["resistance"] for r in pm])
    assert c["difference"] > 0.05 * c["mean_a"], c


def test_ship_group_is_in_the_report():
    module, what = GROUPS["ship"]
    assert module == "physics.crosscheck.pymunk_ship" and "kinematic" in what
