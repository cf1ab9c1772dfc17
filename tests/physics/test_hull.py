"""Hull geometry (physics/hull.py): validation, plan-form properties against
closed forms, and the disc–polygon contact against analytic cases and a
brute-force distance."""
from __future__ import annotations

import math

import numpy as np
import pytest

from physics.hull import (FEATURE_EDGE, FEATURE_NONE, FEATURE_VERTEX, MODEL_HULL, PSV_HULL, Hull,
                          disc_hull_contact)


# -- validation -------------------------------------------------------------

@pytest.mark.parametrize("vertices, message", [
    ([(0, 0), (1, 0)], "at least 3"),
    ([(0, 0), (1, 0), (math.nan, 1)], "finite"),
    ([(0, 0), (0, 1), (1, 0)], "clockwise"),
    ([(0, 0), (2, 0), (1, 0.2), (2, 2), (0, 2)], "not strictly convex"),
    ([(0, 0), (1, 0), (2, 0), (2, 2)], "not strictly convex"),
    ([(0, 0), (1, 0), (2, 0)], "no area"),
    ([1, 2, 3], r"\(K, 2\)"),
])
def test_bad_hulls_are_refused_with_the_reason(vertices, message):
    with pytest.raises(ValueError, match=message):
        Hull(vertices)


@pytest.mark.parametrize("kwargs", [dict(length=-1.0, beam=1.0), dict(length=1.0, beam=math.inf),
                                    dict(length=1.0, beam=1.0, knuckle_beam=0.3),
                                    dict(length=1.0, beam=1.0, shoulder=0.9, knuckle=0.8)])
def test_bad_pointed_dimensions_are_refused(kwargs):
    with pytest.raises(ValueError):
        Hull.pointed(**kwargs)


def test_vertices_are_read_only_and_centred():
    h = Hull([(0, 0), (4, 0), (4, 2), (0, 2)])
    np.testing.assert_allclose(h.vertices.mean(axis=0), 0.0, atol=1e-15)
    with pytest.raises(ValueError):
        h.vertices[0, 0] = 1.0


# -- plan form ----------------------------------------------------------------

def test_box_area_and_yaw_inertia_match_the_rectangle():
    h = Hull.box(76.2, 18.0)
    assert h.area == pytest.approx(76.2 * 18.0, rel=1e-14)
    assert h.yaw_inertia(6.0e6) == pytest.approx(6.0e6 * (76.2**2 + 18.0**2) / 12.0, rel=1e-12)
    assert (h.length, h.beam) == pytest.approx((76.2, 18.0), rel=1e-14)


def test_triangle_inertia_matches_the_closed_form():
    """Polar moment of a uniform triangle about its centroid: m (a² + b² + c²) / 36."""
    p = np.array([(0.0, 0.0), (3.0, 0.0), (1.0, 2.0)])
    h = Hull(p)
    sides2 = sum(float(np.sum((p[i] - p[(i + 1) % 3]) ** 2)) for i in range(3))
    assert h.yaw_inertia(2.0) == pytest.approx(2.0 * sides2 / 36.0, rel=1e-12)
    assert h.area == pytest.approx(3.0, rel=1e-14)


def test_presets_have_the_stated_dimensions_and_a_single_stem():
    for hull, length, beam in ((PSV_HULL, 76.2, 18.0), (MODEL_HULL, 1.84, 0.38)):
        assert hull.length == pytest.approx(length, rel=1e-12)
        assert hull.beam == pytest.approx(beam, rel=1e-12)
        front = hull.vertices[:, 0] == hull.vertices[:, 0].max()
        assert front.sum() == 1 and hull.vertices[front, 1][0] == pytest.approx(0.0, abs=1e-12)
    # the model is the same plan form, scaled (its beam-to-length ratio differs)
    assert PSV_HULL.n_vertices == MODEL_HULL.n_vertices == 7


def test_world_vertices_turn_the_bow_to_the_heading():
    h = Hull.box(4.0, 2.0)
    w = h.world_vertices(10.0, -5.0, math.pi / 2)
    np.testing.assert_allclose(w[1], (10.0 + 1.0, -5.0 + 2.0), atol=1e-12)   # (2, -1) turned by 90°
    np.testing.assert_allclose(w.mean(axis=0), (10.0, -5.0), atol=1e-12)


# -- disc–hull contact ----------------------------------------------------------

def _contact(hull, centre, radius, pose=(0.0, 0.0, 0.0)):
    w = hull.world_vertices(*pose)
    return disc_hull_contact(centre[0], centre[1], radius, np.ascontiguousarray(w[:, 0]),
                             np.ascontiguousarray(w[:, 1]))


def test_disc_against_an_edge():
    h = Hull.box(10.0, 4.0)                      # bow face at x = 5
    delta, nx, ny, px, py, feature, index = _contact(h, (5.0 + 0.9, 0.3), 1.0)
    assert feature == FEATURE_EDGE and index == 1
    assert delta == pytest.approx(0.1, abs=1e-14)
    assert (nx, ny) == pytest.approx((1.0, 0.0), abs=1e-14)
    assert (px, py) == pytest.approx((5.0 - 0.05, 0.3), abs=1e-14)


def test_disc_against_a_vertex_and_no_contact():
    h = Hull.box(10.0, 4.0)                      # corner at (5, 2)
    s = 0.8 / math.sqrt(2.0)
    delta, nx, ny, px, py, feature, index = _contact(h, (5.0 + s, 2.0 + s), 1.0)
    assert feature == FEATURE_VERTEX and index == 2
    assert delta == pytest.approx(0.2, abs=1e-14)
    assert (nx, ny) == pytest.approx((1 / math.sqrt(2), 1 / math.sqrt(2)), abs=1e-14)
    delta, *_, feature, _ = _contact(h, (5.0 + 2 * s, 2.0 + 2 * s), 1.0)
    assert feature == FEATURE_NONE and delta == pytest.approx(1.0 - 1.6, abs=1e-14)


def test_centre_inside_the_hull_is_pushed_out_through_the_nearest_edge():
    h = Hull.box(10.0, 4.0)
    delta, nx, ny, px, py, feature, index = _contact(h, (1.0, 1.7), 0.5)   # 0.3 below the port side
    assert feature == FEATURE_EDGE and (nx, ny) == pytest.approx((0.0, 1.0), abs=1e-14)
    assert delta == pytest.approx(0.5 + 0.3, abs=1e-14)


def test_overlap_and_normal_agree_with_a_brute_force_distance():
    """Random discs around the rotated, shifted PSV hull: the distance from
    the centre to the boundary (sampled about every 2 cm) gives the overlap,
    and stepping back from the centre along the normal by that distance
    lands on the boundary."""
    rng = np.random.default_rng(5)
    pose = (120.0, -40.0, 0.7)
    w = PSV_HULL.world_vertices(*pose)
    samples = np.concatenate([np.linspace(w[i], w[(i + 1) % len(w)], 4000, endpoint=False)
                              for i in range(len(w))])
    for _ in range(200):
        c = np.array(pose[:2]) + rng.uniform(-50.0, 50.0, 2)
        r = rng.uniform(1.0, 3.0)
        delta, nx, ny, px, py, feature, index = _contact(PSV_HULL, c, r, pose)
        d = np.hypot(*(samples - c).T)
        dist = d.min()
        # signed distance: negative inside the convex polygon
        edges = np.roll(w, -1, axis=0) - w
        signed = ((c - w)[:, 0] * edges[:, 1] - (c - w)[:, 1] * edges[:, 0]) / np.hypot(*edges.T)
        if np.all(signed <= 0):
            dist = -dist
        assert delta == pytest.approx(r - dist, abs=0.02)
        # the centre minus the normal times the distance lands on the boundary
        foot = c - np.array([nx, ny]) * (r - delta)
        assert np.hypot(*(samples - foot).T).min() < 0.02
        assert (feature != FEATURE_NONE) == (delta > 0)
        assert math.hypot(nx, ny) == pytest.approx(1.0, abs=1e-12)
