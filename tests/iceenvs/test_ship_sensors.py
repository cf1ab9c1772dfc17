"""Tests of iceenvs.ship_sensors: the sector lidar, the swath sensor and the
egocentric occupancy image, and the room a course leaves in the channel,
against analytic geometry and against direct
per-ray, per-sample and per-pixel evaluation of the documented
conventions."""
import math

import numpy as np
import pytest

from iceenvs.ship_sensors import (LIDAR_RAYS, LIDAR_RINGS, channel_room, course_with_room,
                                  ice_lidar, ice_swath, lidar_scan, occupancy_image, scan_box)

TWO_PI = 2.0 * math.pi


def unit(angle):
    return np.array([math.cos(angle), math.sin(angle)])


def rectangle_hull(centre, heading, length, beam):
    """World corners, anticlockwise, of a length × beam rectangle."""
    local = np.array([[-0.5 * length, -0.5 * beam], [0.5 * length, -0.5 * beam],
                      [0.5 * length, 0.5 * beam], [-0.5 * length, 0.5 * beam]])
    c, s = math.cos(heading), math.sin(heading)
    return np.asarray(centre) + local @ np.array([[c, s], [-s, c]])


# -- direct evaluation of the documented conventions ------------------------------------------

def lidar_by_hand(ship, heading, positions, radii, sectors, fov, max_range):
    """Per-ray and per-sample evaluation, floe by floe (no periodicity)."""
    d = np.asarray(positions, float) - ship
    start = heading - 0.5 * fov
    distance = np.full(sectors, max_range)
    for k in range(sectors):
        u = unit(start + (k + 0.5) * fov / sectors)
        for (dx, dy), r in zip(d, radii):
            if dx * dx + dy * dy <= r * r:
                distance[k] = 0.0
                continue
            along = dx * u[0] + dy * u[1]
            across = dx * u[1] - dy * u[0]
            if along > 0.0 and abs(across) <= r:
                distance[k] = min(distance[k], along - math.sqrt(r * r - across * across))
    rho = max_range * np.sqrt((np.arange(LIDAR_RINGS) + 0.5) / LIDAR_RINGS)
    width = fov / sectors
    concentration = np.zeros(sectors)
    for k in range(sectors):
        phi = start + k * width + (np.arange(LIDAR_RAYS) + 0.5) * width / LIDAR_RAYS
        pts = (rho[:, None, None] * np.stack([np.cos(phi), np.sin(phi)], -1)[None]).reshape(-1, 2)
        gap = pts[:, None, :] - d[None, :, :]
        inside = np.any(np.sum(gap * gap, axis=-1) <= np.asarray(radii) ** 2, axis=1)
        concentration[k] = inside.mean()
    return distance, concentration


def pixel_world_points(ship, heading, size, extent):
    """(size, size, 2) world coordinates of the pixel centres."""
    centres = 0.5 * extent - (np.arange(size) + 0.5) * extent / size
    forward, port = unit(heading), unit(heading + 0.5 * math.pi)
    return (np.asarray(ship)[None, None, :] + centres[:, None, None] * forward
            + centres[None, :, None] * port)


# -- lidar: distance ----------------------------------------------------------------------------

def test_floe_straight_ahead_is_seen_by_the_central_sector_only():
    ship, heading = np.array([10.0, -3.0]), 1.1
    d, r = 50.0, 5.0
    distance, _ = ice_lidar(ship, heading, [ship + d * unit(heading)], [r])
    assert distance.shape == (9,) and distance.dtype == float
    assert distance[4] == pytest.approx(d - r, abs=1e-9)
    # the neighbouring rays (±20°) pass 50 sin 20° ≈ 17 m > 5 m from the centre
    assert np.all(np.delete(distance, 4) == 200.0)


def test_floe_at_port_moves_between_sectors_with_the_heading():
    # 18 sectors of 20° over the full circle, sector 0 centred on heading − 170°:
    # the ray of sector k looks towards heading − 170° + 20° k
    floe, r = np.array([[0.0, 50.0]]), np.array([2.0])
    for heading, expected in ((0.0, 13), (math.radians(20.0), 12), (math.radians(-40.0), 15)):
        distance, _ = ice_lidar((0.0, 0.0), heading, floe, r, sectors=18, fov=TWO_PI)
        assert np.flatnonzero(distance < 200.0).tolist() == [expected]
        assert distance[expected] == pytest.approx(48.0, abs=1e-9)


def test_floe_behind_or_beyond_range_is_not_seen():
    distance, _ = ice_lidar((0.0, 0.0), 0.0, [[-50.0, 0.0], [206.0, 0.0]], [5.0, 5.0])
    assert np.all(distance == 200.0)
    # a disc whose edge comes within range counts although its centre lies beyond it
    distance, _ = ice_lidar((0.0, 0.0), 0.0, [[203.0, 0.0]], [5.0])
    assert distance[4] == pytest.approx(198.0, abs=1e-9)


def test_nearest_of_two_floes_on_one_ray():
    distance, _ = ice_lidar((0.0, 0.0), 0.0, [[80.0, 0.0], [30.0, 1.0]], [10.0, 3.0])
    assert distance[4] == pytest.approx(30.0 - math.sqrt(9.0 - 1.0), abs=1e-9)


def test_ray_starting_inside_a_floe_reads_zero():
    distance, _ = ice_lidar((0.0, 0.0), 0.3, [[1.0, 0.5], [60.0, 0.0]], [4.0, 5.0])
    assert np.all(distance == 0.0)
    # with a range of 10 m the inner ring (2.5 m) lies inside the floe all round
    distance, concentration = ice_lidar((0.0, 0.0), 0.3, [[1.0, 0.5]], [4.0], max_range=10.0)
    assert np.all(distance == 0.0)
    assert np.all(concentration >= 1.0 / LIDAR_RINGS)
    # the ship at the centre of a 5 m floe, range 10 m: the rings at 10 sqrt((i + 1/2) / 8) m
    # inside it are i = 0, 1
    distance, concentration = ice_lidar((3.0, 4.0), 2.0, [[3.0, 4.0]], [5.0], max_range=10.0,
                                        sectors=4, fov=TWO_PI)
    assert np.all(distance == 0.0)
    np.testing.assert_allclose(concentration, 2.0 / LIDAR_RINGS, rtol=0.0, atol=1e-12)


def test_periodic_wrap_uses_the_minimum_image():
    box = (1000.0, 800.0)
    # across the right edge (x): the floe at x = 40 is 50 m ahead of the ship at x = 990
    distance, _ = ice_lidar((990.0, 400.0), 0.0, [[40.0, 400.0]], [5.0], box_lengths=box,
                            periodic=(True, False))
    assert distance[4] == pytest.approx(45.0, abs=1e-9)
    distance, _ = ice_lidar((990.0, 400.0), 0.0, [[40.0, 400.0]], [5.0])
    assert np.all(distance == 200.0)
    # across the top edge (y), the ship heading north
    distance, _ = ice_lidar((500.0, 795.0), 0.5 * math.pi, [[500.0, 30.0]], [5.0],
                            box_lengths=box, periodic=(False, True))
    assert distance[4] == pytest.approx(30.0, abs=1e-9)


def test_lidar_matches_ray_by_ray_and_sample_by_sample_evaluation():
    rng = np.random.default_rng(3)
    for sectors, fov, heading in ((9, math.pi, 0.4), (7, 2.0, -2.9), (12, TWO_PI, 3.0),
                                  (1, 0.3, 1.0), (5, TWO_PI, -0.2)):
        ship = rng.uniform(-20.0, 20.0, 2)
        positions = rng.uniform(-150.0, 150.0, (120, 2))
        radii = rng.uniform(1.0, 12.0, 120)
        keep = np.hypot(*(positions - ship).T) > radii          # the ship in open water
        positions, radii = positions[keep], radii[keep]
        got = ice_lidar(ship, heading, positions, radii, sectors=sectors, fov=fov,
                        max_range=120.0)
        want = lidar_by_hand(ship, heading, positions, radii, sectors, fov, 120.0)
        np.testing.assert_allclose(got[0], want[0], rtol=0.0, atol=1e-9)
        np.testing.assert_allclose(got[1], want[1], rtol=0.0, atol=1e-12)


def test_unchecked_lidar_matches_evaluation_of_the_nearest_images():
    """lidar_scan (what an environment calls every step, without the checks)
    in a box periodic along x, y or both equals the per-ray and per-sample
    evaluation of each floe's nearest periodic image, found by trying the
    nine images; the ship stands near a corner, so that the sensor looks
    across the edges."""
    rng = np.random.default_rng(8)
    lx, ly = 300.0, 260.0
    shifts = np.array([(i * lx, j * ly) for i in (-1, 0, 1) for j in (-1, 0, 1)])
    for periodic, ship, heading in (((True, True), (290.0, 10.0), 0.3),
                                    ((True, False), (5.0, 130.0), 3.0),
                                    ((False, True), (150.0, 250.0), 1.4)):
        positions = rng.uniform(0.0, 1.0, (80, 2)) * [lx, ly]
        radii = rng.uniform(1.0, 10.0, 80)
        allowed = shifts[[(periodic[0] or dx == 0.0) and (periodic[1] or dy == 0.0)
                          for dx, dy in shifts]]
        images = positions[:, None, :] + allowed[None, :, :]
        gap = np.hypot(*(images - np.asarray(ship)).transpose(2, 0, 1))
        nearest = images[np.arange(80), np.argmin(gap, axis=1)]
        keep = np.min(gap, axis=1) > radii + 0.5                    # the ship in open water
        got = lidar_scan(np.array([ship[0], ship[1], heading]), positions[keep], radii[keep],
                         np.array([7, 2.5, 120.0]), scan_box(lx, ly, periodic))
        want = lidar_by_hand(np.asarray(ship), heading, nearest[keep], radii[keep], 7, 2.5, 120.0)
        assert np.min(got[0]) < 120.0 and np.max(got[1]) > 0.0       # it sees ice
        # 1e-9 m: the same ray-circle root in two algebraic forms
        np.testing.assert_allclose(got[0], want[0], rtol=0.0, atol=1e-9)
        # counts of sample points: any disagreement is at least 1/32
        np.testing.assert_allclose(got[1], want[1], rtol=0.0, atol=1e-12)


# -- lidar: concentration -----------------------------------------------------------------------

def test_concentration_of_open_water_and_of_a_covering_floe():
    distance, concentration = ice_lidar((0.0, 0.0), 0.0, np.empty((0, 2)), np.empty(0))
    assert np.all(concentration == 0.0) and np.all(distance == 200.0)
    _, concentration = ice_lidar((0.0, 0.0), 0.0, [[30.0, -20.0]], [1000.0])
    assert np.all(concentration == 1.0)


def test_concentration_of_a_half_plane():
    # a disc of radius 1e6 m whose edge runs along x, 1 m to starboard of the ship
    big = 1e6
    floe, r = [[0.0, -big - 1.0]], [big]
    distance, concentration = ice_lidar((0.0, 0.0), 0.0, floe, r, sectors=2, fov=TWO_PI)
    assert concentration.tolist() == [1.0, 0.0]            # starboard half, port half
    # the starboard ray (−90°) meets the edge 1 m away, the port ray runs clear of it
    assert distance[0] == pytest.approx(1.0, abs=1e-9) and distance[1] == 200.0
    _, concentration = ice_lidar((0.0, 0.0), 0.0, floe, r, sectors=1)
    assert concentration[0] == pytest.approx(0.5, abs=1e-12)


def test_concentration_of_a_poisson_field():
    # discs of radius 1 m at density n: covered fraction 1 − exp(−n π r²)
    rng = np.random.default_rng(11)
    side, r, target = 500.0, 1.0, 0.3
    n = int(round(-math.log(1.0 - target) / (math.pi * r * r) * side * side))
    positions = rng.uniform(0.0, side, (n, 2))
    _, concentration = ice_lidar((250.0, 250.0), 0.7, positions, np.full(n, r), sectors=36,
                                 fov=TWO_PI, max_range=200.0, box_lengths=(side, side),
                                 periodic=(True, True))
    assert concentration.mean() == pytest.approx(target, abs=0.08)
    assert np.all((concentration >= 0.0) & (concentration <= 1.0))


# -- occupancy image ----------------------------------------------------------------------------

SIZE, EXTENT = 64, 100.0
PIXEL_AREA = (EXTENT / SIZE) ** 2


def image(ship, heading, positions, radii, hull=None, goal_x=1e3, **kw):
    if hull is None:
        hull = rectangle_hull(ship, heading, 20.0, 6.0)
    return occupancy_image(ship, heading, np.asarray(positions, float).reshape(-1, 2),
                           np.asarray(radii, float), hull, goal_x, **kw)


def centroid(mask):
    rows, cols = np.nonzero(mask)
    return rows.mean(), cols.mean()


def test_image_shape_and_dtype():
    img = image((5.0, 5.0), 0.2, np.empty((0, 2)), np.empty(0))
    assert img.shape == (4, SIZE, SIZE) and img.dtype == np.uint8
    assert not img[0].any()
    assert image((5.0, 5.0), 0.2, [], [], size=16).shape == (4, 16, 16)


def test_floe_ahead_is_above_the_centre_and_floe_to_port_on_the_left():
    ship, heading, r = np.array([100.0, 50.0]), 0.6, 8.0
    expected = math.pi * r * r / PIXEL_AREA
    # the centre of a floe 25 m ahead lies at row (50 − 25) / (100 / 64) − 1/2 = 15.5
    ahead = image(ship, heading, ship + 25.0 * unit(heading), [r])[0]
    assert set(np.unique(ahead)) == {0, 255}
    assert (ahead > 0).sum() == pytest.approx(expected, rel=0.15)
    row, col = centroid(ahead > 0)
    assert row == pytest.approx(15.5, abs=0.5) and col == pytest.approx(31.5, abs=0.5)
    port = image(ship, heading, ship + 25.0 * unit(heading + 0.5 * math.pi), [r])[0]
    assert (port > 0).sum() == pytest.approx(expected, rel=0.15)
    row, col = centroid(port > 0)
    assert row == pytest.approx(31.5, abs=0.5) and col == pytest.approx(15.5, abs=0.5)


def test_ice_channel_matches_pixel_by_pixel_evaluation():
    rng = np.random.default_rng(5)
    ship, heading, size, extent = np.array([3.0, -7.0]), -2.2, 32, 80.0
    positions = ship + rng.uniform(-70.0, 70.0, (150, 2))
    radii = rng.uniform(0.5, 9.0, 150)
    got = image(ship, heading, positions, radii, size=size, extent=extent)[0]
    pts = pixel_world_points(ship, heading, size, extent)
    gap = pts[:, :, None, :] - positions[None, None]
    want = np.any(np.sum(gap * gap, axis=-1) <= radii ** 2, axis=-1)
    np.testing.assert_array_equal(got == 255, want)
    assert np.all((got == 0) | (got == 255))


def test_ice_channel_of_a_covering_floe_and_through_a_periodic_edge():
    assert np.all(image((0.0, 0.0), 1.0, [[10.0, 10.0]], [500.0])[0] == 255)
    wrapped = image((995.0, 500.0), 0.0, [[20.0, 500.0]], [5.0], box_lengths=(1000.0, 1000.0),
                    periodic=(True, True))[0]
    plain = image((0.0, 500.0), 0.0, [[25.0, 500.0]], [5.0])[0]
    assert plain.any()
    np.testing.assert_array_equal(wrapped, plain)


def test_hull_channel_covers_the_hull_area():
    ship, heading = np.array([40.0, 60.0]), 0.6
    hull = rectangle_hull(ship, heading, 40.0, 10.0)
    mask = image(ship, heading, [], [], hull=hull)[1] > 0
    assert mask.sum() == pytest.approx(400.0 / PIXEL_AREA, rel=0.15)
    rows, cols = np.nonzero(mask)
    assert np.ptp(rows) > 3 * np.ptp(cols)                   # the bow points up
    assert rows.mean() == pytest.approx(31.5, abs=0.5)
    assert cols.mean() == pytest.approx(31.5, abs=0.5)
    # a hull given in the world frame stays where it is when the image turns
    off = rectangle_hull(ship + 20.0 * unit(heading), heading, 10.0, 10.0)
    row, col = centroid(image(ship, heading, [], [], hull=off)[1] > 0)
    assert row == pytest.approx(31.5 - 20.0 * SIZE / EXTENT, abs=0.5)
    assert col == pytest.approx(31.5, abs=0.5)


def test_goal_channel_is_a_ramp_of_the_distance_to_the_goal_line():
    ship, goal_x = np.array([0.0, 10.0]), 30.0
    goal = image(ship, 0.0, [], [], goal_x=goal_x)[2].astype(int)
    # heading +x: every row is one distance; the row nearest x = 30 is row 12 (x = 30.47)
    assert np.all(goal == goal[:, :1])
    assert int(np.argmax(goal[:, 0])) == 12
    assert goal[12, 0] >= 255 * (1.0 - 0.5 * EXTENT / SIZE / EXTENT) - 1
    assert np.all(np.diff(goal[:13, 0]) >= 0) and np.all(np.diff(goal[12:, 0]) <= 0)
    # the bottom row (x = −49.2 m) lies 79.2 m from the line
    assert goal[-1, 0] == round(255 * (1.0 - 79.21875 / EXTENT))
    assert not image(ship, 0.0, [], [], goal_x=150.0)[2].any()   # ≥ 100 m everywhere
    for heading, periodic, box in ((0.0, (False, False), None), (1.3, (False, False), None),
                                   (-2.0, (True, False), (70.0, 50.0))):
        got = image(ship, heading, [], [], goal_x=goal_x, box_lengths=box,
                    periodic=periodic)[2].astype(int)
        gap = pixel_world_points(ship, heading, SIZE, EXTENT)[..., 0] - goal_x
        if box is not None:
            gap -= box[0] * np.round(gap / box[0])
        want = np.clip(255.0 * (1.0 - np.abs(gap) / EXTENT), 0.0, 255.0)
        assert np.max(np.abs(got - want)) <= 1.0


def test_heading_channel_encodes_the_heading():
    for heading in (0.0, 1.0, -1.0, 7.0, math.pi, -12.5):
        channel = image((0.0, 0.0), heading, [], [])[3].astype(int)
        assert np.all(channel == channel[0, 0])
        assert abs(channel[0, 0] - round(255 * (heading % TWO_PI) / TWO_PI)) <= 1


# -- validation ---------------------------------------------------------------------------------

FLOE = dict(positions=[[1.0, 2.0]], radii=[1.0])


@pytest.mark.parametrize("kwargs, name", [
    (dict(sectors=0), "sectors"),
    (dict(sectors=2.5), "sectors"),
    (dict(sectors=True), "sectors"),
    (dict(fov=0.0), "fov"),
    (dict(fov=7.0), "fov"),
    (dict(max_range=0.0), "max_range"),
    (dict(max_range=float("nan")), "max_range"),
    (dict(positions=[[1.0, 2.0, 3.0]]), "positions"),
    (dict(positions=[[1.0, float("inf")]]), "positions"),
    (dict(radii=[1.0, 2.0]), "radii"),
    (dict(radii=[-1.0]), "radii"),
    (dict(radii=[0.0]), "radii"),
    (dict(ship_xy=(0.0, float("nan"))), "ship_xy"),
    (dict(ship_xy=(0.0, 1.0, 2.0)), "ship_xy"),
    (dict(heading=float("inf")), "heading"),
    (dict(periodic=(True, False)), "box_lengths"),
    (dict(box_lengths=(10.0, -1.0), periodic=(True, True)), "box_lengths"),
    (dict(periodic=True), "periodic"),
])
def test_lidar_rejects_bad_input(kwargs, name):
    args = dict(ship_xy=(0.0, 0.0), heading=0.0, **FLOE)
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        ice_lidar(args.pop("ship_xy"), args.pop("heading"), args.pop("positions"),
                  args.pop("radii"), **args)


@pytest.mark.parametrize("kwargs, name", [
    (dict(size=4), "size"),
    (dict(size=64.0), "size"),
    (dict(extent=0.0), "extent"),
    (dict(extent=-5.0), "extent"),
    (dict(goal_x=float("nan")), "goal_x"),
    (dict(hull_vertices=[[0.0, 0.0], [1.0, 0.0]]), "hull_vertices"),
    (dict(hull_vertices=[[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]]), "hull_vertices"),   # clockwise
    (dict(hull_vertices=[[0.0, 0.0], [2.0, 0.0], [1.0, 0.2], [1.0, 1.0]]), "hull_vertices"),
    (dict(radii=[-1.0]), "radii"),
    (dict(heading=float("nan")), "heading"),
    (dict(periodic=(False, True)), "box_lengths"),
])
def test_image_rejects_bad_input(kwargs, name):
    args = dict(ship_xy=(0.0, 0.0), heading=0.0,
                hull_vertices=[[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]],
                goal_x=10.0, **FLOE)
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        occupancy_image(args.pop("ship_xy"), args.pop("heading"), args.pop("positions"),
                        args.pop("radii"), args.pop("hull_vertices"), args.pop("goal_x"),
                        **args)


# -- swath sensor -------------------------------------------------------------------------------

def swath_by_hand(ship, heading, positions, radii, weights, rays, fan, half_beam, bands):
    """Course by course and floe by floe, as the module docstring states it."""
    d = np.asarray(positions, float) - ship
    out = np.zeros((rays, len(bands) - 1))
    for k in range(rays):
        u = unit(heading - 0.5 * fan + (k + 0.5) * fan / rays)
        for (dx, dy), r, w in zip(d, radii, weights):
            along = dx * u[0] + dy * u[1]
            across = abs(dx * u[1] - dy * u[0])
            reach = r + half_beam
            for b in range(len(bands) - 1):
                if across < reach and bands[b] <= along < bands[b + 1]:
                    out[k, b] += w * (1.0 - across / reach)
    return out


def test_swath_weighs_a_floe_by_how_centrally_a_course_meets_it():
    # one floe 60 m dead ahead, 4 m to port of the ship's axis; half beam 6 m, radius 4 m:
    # the straight course meets it 4 m off its centre, 4/10 of the reach
    s = ice_swath((0.0, 0.0), 0.0, np.array([[60.0, 4.0]]), np.array([4.0]),
                  np.array([3.0]), rays=3, fan=0.5, half_beam=6.0, bands=(0.0, 50.0, 100.0))
    assert s.shape == (3, 2)
    assert s[1, 0] == 0.0                               # not in the near band
    assert s[1, 1] == pytest.approx(3.0 * (1.0 - 0.4), rel=1e-12)
    # the port course (1/6 rad to port) passes 60 sin(1/6) − 4 cos(1/6) ≈ 6.0 m from its centre
    across = abs(4.0 * math.cos(1 / 6) - 60.0 * math.sin(1 / 6))
    assert s[2, 1] == pytest.approx(3.0 * (1.0 - across / 10.0), rel=1e-12)
    assert s[0, 1] == 0.0                               # starboard: 14 m off, beyond the reach


def test_swath_of_a_field_matches_evaluation_by_hand():
    rng = np.random.default_rng(4)
    positions = rng.uniform(-150.0, 250.0, (300, 2))
    radii = rng.uniform(1.0, 25.0, 300)
    weights = rng.uniform(0.0, 5.0, 300)
    for heading in (0.0, 0.7, -2.5):
        got = ice_swath((10.0, -5.0), heading, positions, radii, weights, rays=7, fan=1.2,
                        half_beam=9.0, bands=(0.0, 40.0, 120.0, 200.0))
        want = swath_by_hand(np.array([10.0, -5.0]), heading, positions, radii, weights, 7,
                             1.2, 9.0, (0.0, 40.0, 120.0, 200.0))
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


def test_swath_ignores_floes_behind_and_beyond_and_sees_periodic_images():
    radii, weights = np.array([5.0]), np.array([1.0])
    behind = ice_swath((0.0, 0.0), 0.0, np.array([[-20.0, 0.0]]), radii, weights, rays=1)
    beyond = ice_swath((0.0, 0.0), 0.0, np.array([[260.0, 0.0]]), radii, weights, rays=1)
    assert behind.sum() == 0.0 and beyond.sum() == 0.0
    # a floe 30 m ahead through the periodic edge of a 100 m box
    wrapped = ice_swath((90.0, 50.0), 0.0, np.array([[20.0, 50.0]]), radii, weights, rays=1,
                        box_lengths=(100.0, 100.0), periodic=(True, False))
    assert wrapped[0, 0] == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize("kwargs, name", [
    (dict(rays=0), "rays"),
    (dict(rays=1.5), "rays"),
    (dict(fan=0.0), "fan"),
    (dict(fan=4.0), "fan"),
    (dict(half_beam=0.0), "half_beam"),
    (dict(weights=[1.0, 2.0]), "weights"),
    (dict(weights=[-1.0]), "weights"),
    (dict(weights=[float("nan")]), "weights"),
    (dict(bands=(0.0,)), "bands"),
    (dict(bands=(0.0, 50.0, 40.0)), "bands"),
    (dict(bands=(-10.0, 50.0)), "bands"),
    (dict(radii=[-1.0]), "radii"),
    (dict(heading=float("nan")), "heading"),
])
def test_swath_rejects_bad_input(kwargs, name):
    args = dict(ship_xy=(0.0, 0.0), heading=0.0, weights=[1.0], **FLOE)
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        ice_swath(args.pop("ship_xy"), args.pop("heading"), args.pop("positions"),
                  args.pop("radii"), args.pop("weights"), **args)


# -- room in the channel ------------------------------------------------------------------------

def test_channel_room_ends_on_the_edge_and_not_before():
    """From 200 offsets and bearings drawn in a channel of half-width 100 m,
    the point ``room`` along the course lies on the edge (to 1e-9 m) when
    the room is below the cap, and every point before it inside; a course
    whose room reaches the cap stays inside for the whole cap."""
    rng = np.random.default_rng(4)
    h, reach = 100.0, 250.0
    offsets = rng.uniform(-h, h, 200)
    bearings = rng.uniform(-math.pi, math.pi, (200, 5))
    for d, angles in zip(offsets, bearings):
        room = channel_room(d, h, angles, reach)
        lateral = d + np.linspace(0.0, 1.0, 51)[:, None] * room * np.sin(angles)
        assert np.all(np.abs(lateral) <= h + 1e-9)
        short = room < reach
        np.testing.assert_allclose(np.abs(lateral[-1, short]), h, atol=1e-9)


def test_channel_room_along_the_channel_and_from_outside():
    room = channel_room(-30.0, 100.0, [0.0, math.pi, math.pi / 2, -math.pi / 2], 250.0)
    np.testing.assert_allclose(room, [250.0, 250.0, 130.0, 70.0], rtol=1e-12)
    # 10 m beyond the port edge: 0 further out, 210 m across the channel heading in
    out = channel_room(110.0, 100.0, [math.pi / 2, -math.pi / 2], 500.0)
    np.testing.assert_allclose(out, [0.0, 210.0], rtol=1e-12)
    # the docstring's example
    np.testing.assert_allclose(channel_room(50.0, 100.0, [0.0, math.pi / 2, -math.pi / 6], 250.0),
                               [250.0, 50.0, 250.0], rtol=1e-12)


@pytest.mark.parametrize("kwargs, name", [
    (dict(offset=float("nan")), "offset"),
    (dict(half_width=0.0), "half_width"),
    (dict(reach=-1.0), "reach"),
    (dict(bearings=[0.0, float("inf")]), "bearings"),
])
def test_channel_room_rejects_bad_input(kwargs, name):
    args = dict(offset=0.0, half_width=100.0, bearings=[0.0], reach=250.0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        channel_room(**args)


def test_course_with_room_is_the_nearest_course_that_leaves_the_room():
    """Over 200 drawn offsets and courses, the course kept leaves at least
    the room asked (to 1e-6 m) and is the course asked when that one does;
    else it is the nearest that does (a course 1e-3 rad nearer the one
    asked leaves less). From 10 m outside the port edge, only starboard
    courses remain."""
    rng = np.random.default_rng(5)
    h, g = 100.0, 150.0
    for d, course in zip(rng.uniform(-h, h, 200), rng.uniform(-1.2, 1.2, 200)):
        kept = course_with_room(course, d, h, g)
        assert channel_room(d, h, [kept], 1e6)[0] >= g - 1e-6
        if channel_room(d, h, [course], 1e6)[0] >= g:
            assert kept == course
        else:
            nearer = kept + 1e-3 * np.sign(course - kept)
            assert channel_room(d, h, [nearer], 1e6)[0] < g
    assert course_with_room(0.7, 110.0, h, g) < 0.0
    assert course_with_room(-0.5, 110.0, h, g) == -0.5
