"""The costmap observation (:mod:`iceenvs.costmap`): the map against a slow
reference built floe by floe and cell by cell, its masks on a known
geometry, its range, its spaces in the environments and the checks of its
arguments."""
import math

import gymnasium as gym
import numpy as np
import pytest

import iceenvs
from iceenvs.costmap import (COSTMAP_CAP, COSTMAP_CHANNELS, COSTMAP_SCALE, costmap_density,
                             costmap_samples, costmap_shape, ice_costmap, impulse_costmap)
from iceenvs.facts import env_spec
from iceenvs.ship_env import ShipEnv
from small_envs import SMALL

HALF_BEAM = 9.0


def cone(impulse, reach, dx, dy):
    """The cone density [N s/m] of one floe at displacement (dx, dy) from
    its centre (the planner's cost, written out)."""
    rho = math.hypot(dx, dy)
    return impulse * (1.0 - rho / reach) / reach if rho <= reach else 0.0


def reference_density(ship, positions, radii, impulses, *, cell, behind, ahead, width,
                      box=None, periodic=(False, False)):
    """The density per cell, cell by cell, sample by sample, floe by floe and
    image by image (images k = −2 … 2 along a periodic axis: enough for the
    maps here, which are no wider than two boxes)."""
    rows = math.ceil((behind + ahead) / cell - 1e-9)
    cols = math.ceil(width / cell - 1e-9)
    sub = costmap_samples(cell)
    out = np.zeros((rows, cols))
    shifts = [[k * box[a] for k in range(-2, 3)] if periodic[a] else [0.0] for a in range(2)]
    for i in range(rows):
        for j in range(cols):
            total = 0.0
            for s in range(sub):
                for t in range(sub):
                    # the sample: rows run back from the far edge, columns to starboard
                    x = ship[0] + ahead - i * cell - (s + 0.5) * cell / sub
                    y = ship[1] + 0.5 * cols * cell - j * cell - (t + 0.5) * cell / sub
                    for (px, py), r, w in zip(positions, radii, impulses):
                        for sx in shifts[0]:
                            for sy in shifts[1]:
                                total += cone(w, r + HALF_BEAM, x - px - sx, y - py - sy)
            out[i, j] = total / sub ** 2
    return out


def few_floes(seed):
    """Five floes about a ship at (100, 60) in a box 400 m × 120 m: two by
    the box's edges y = 0 and y = 120 (seen through their images across a
    periodic y), one behind the ship, one ahead, one large."""
    rng = np.random.default_rng(seed)
    positions = np.array([[150.0, 3.0], [190.0, 117.0], [95.0, 50.0], [230.0, 70.0],
                          [170.0, 40.0]]) + rng.uniform(-2.0, 2.0, (5, 2))
    radii = np.array([4.0, 6.0, 3.0, 5.0, 20.0]) * rng.uniform(0.9, 1.1, 5)
    impulses = rng.uniform(1e5, 1e6, 5)
    return positions, radii, impulses


GEOMETRY = {"cell": 5.0, "behind": 10.0, "ahead": 150.0, "width": 120.0}


@pytest.mark.parametrize("periodic", [(False, True), (False, False)])
def test_the_density_equals_a_slow_reference_floe_by_floe(periodic):
    """On a field of five floes, periodic across or not, the density per
    cell equals the reference's sum of the same terms (in another order)."""
    ship = (100.0, 60.0)
    positions, radii, impulses = few_floes(1)
    box = (400.0, 120.0)
    g = GEOMETRY
    rows, cols = costmap_shape(g["cell"], g["behind"], g["ahead"], g["width"])
    got = costmap_density(ship[0], ship[1], positions, radii, impulses, HALF_BEAM, g["ahead"],
                          g["cell"], rows, cols, costmap_samples(g["cell"]), box[0], box[1],
                          periodic[0], periodic[1])
    want = reference_density(ship, positions, radii, impulses, box=box, periodic=periodic, **g)
    assert got.shape == want.shape == (32, 24)
    assert np.count_nonzero(want) > 100
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * want.max())
    # the images matter: the floe by y = 0 reaches the map's port edge (y = 120 m) only
    # through its image across a periodic y
    solo = reference_density(ship, positions[:1], radii[:1], impulses[:1], box=box,
                             periodic=periodic, **g)
    assert (solo[:, 0].max() > 0.0) == periodic[1] and solo[:, -1].max() > 0.0
    # and the observation's channel is the scaled density
    obs = ice_costmap(ship, positions, radii, impulses, half_beam=HALF_BEAM, goal_x=1e3,
                      centre_y=60.0, channel_width=g["width"], cell=g["cell"],
                      behind=g["behind"], ahead=g["ahead"], box_lengths=box, periodic=periodic)
    assert obs.dtype == np.float32 and obs.shape == (3, 32, 24)
    np.testing.assert_allclose(obs[0], np.minimum(np.log1p(want / COSTMAP_SCALE), COSTMAP_CAP),
                               rtol=1e-6, atol=1e-7)


@pytest.mark.parametrize("cone_spread", [True, False])
def test_the_planners_cost_grid_is_the_cone_or_the_chord_density(cone_spread):
    """:func:`impulse_costmap`, the lattice planner's cost grid, samples the
    density at the cell centres (x index first), as the reference does."""
    positions, radii, impulses = few_floes(2)
    reach = radii + HALF_BEAM
    x0, y0, cell, nx, ny = 80.0, 0.0, 1.5, 120, 80
    got = impulse_costmap(x0, y0, nx, ny, cell, positions[:, 0], positions[:, 1], reach,
                          impulses, cone_spread)
    want = np.zeros((nx, ny))
    for a in range(nx):
        for b in range(ny):
            x, y = x0 + (a + 0.5) * cell, y0 + (b + 0.5) * cell
            for (px, py), r, w in zip(positions, reach, impulses):
                if not cone_spread:
                    want[a, b] += w / (2.0 * r) if math.hypot(x - px, y - py) <= r else 0.0
                else:
                    want[a, b] += cone(w, r, x - px, y - py)
    assert np.count_nonzero(want) > 500
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * want.max())


def test_the_line_integral_through_a_floe_is_its_impulse():
    """A route through a floe's centre meets its impulse: the sum of the
    densities of the cells along the map's centre column, times the cell,
    is the impulse (to the sampling error of 5 m cells)."""
    impulse, r = 4e5, 6.0
    obs = ice_costmap((0.0, 0.0), [[100.0, -2.5]], [r], [impulse], half_beam=HALF_BEAM,
                      goal_x=1e3, centre_y=0.0, channel_width=100.0)
    density = COSTMAP_SCALE * np.expm1(obs[0].astype(float))
    line = density[:, 10].sum() * 5.0           # column 10: centres y = −2.5
    assert line == pytest.approx(impulse, rel=0.03)


def test_the_masks_on_a_known_geometry():
    """Ship 50 m to port of the centre line of a 200 m channel, goal line
    100 m ahead: the 10 port columns lie outside the channel (their centres
    147.5 … 102.5 m to port of the centre line), the 40 rows more than 100 m
    ahead lie past the goal line; and the ice channel is empty without
    floes."""
    obs = ice_costmap((500.0, 150.0), np.empty((0, 2)), np.empty(0), np.empty(0),
                      half_beam=HALF_BEAM, goal_x=600.0, centre_y=100.0, channel_width=200.0)
    assert obs.shape == (len(COSTMAP_CHANNELS), 64, 40)
    outside = np.zeros((64, 40))
    outside[:, :10] = 1.0
    beyond = np.zeros((64, 40))
    beyond[:40] = 1.0
    np.testing.assert_array_equal(obs[1], outside)
    np.testing.assert_array_equal(obs[2], beyond)
    np.testing.assert_array_equal(obs[0], 0.0)


def test_floes_beyond_the_map_are_not_seen():
    """A floe whose enlarged disc ends just beyond the map (ahead, behind,
    to either side) leaves it as it is; one just inside the far edge does
    not."""
    base_p, base_r, base_w = few_floes(3)
    kw = {"half_beam": HALF_BEAM, "goal_x": 1e3, "centre_y": 60.0, "channel_width": 120.0,
          "behind": 10.0, "ahead": 150.0}
    ship = (100.0, 60.0)
    base = ice_costmap(ship, base_p, base_r, base_w, **kw)
    r = 5.0
    reach = r + HALF_BEAM
    for where in ([250.0 + reach + 0.01, 60.0], [90.0 - reach - 0.01, 60.0],
                  [150.0, 120.0 + reach + 0.01], [150.0, -reach - 0.01]):
        more = ice_costmap(ship, np.vstack([base_p, where]), np.append(base_r, r),
                           np.append(base_w, 1e9), **kw)
        np.testing.assert_array_equal(more, base)
    inside = ice_costmap(ship, np.vstack([base_p, [250.0 + reach - 2.5, 60.0]]),
                         np.append(base_r, r), np.append(base_w, 1e9), **kw)
    assert inside[0, 0].max() > base[0, 0].max()


def ship_ids():
    out = []
    for env_id in iceenvs.ENV_IDS:
        env = gym.make(env_id, **SMALL[env_id])
        if isinstance(env.unwrapped, ShipEnv):
            out.append(env_id)
        env.close()
    return out


SHIP_IDS = ship_ids()


@pytest.mark.parametrize("env_id", SHIP_IDS)
def test_the_observation_lies_in_its_space(env_id):
    """Every ship environment gives the costmap and the costmap with the
    vector in their spaces, the costmap the environment's :meth:`costmap`,
    which is :func:`ice_costmap` of its floes."""
    env = gym.make(env_id, obs_type="costmap", **SMALL[env_id])
    both = gym.make(env_id, obs_type="costmap_dict", **SMALL[env_id])
    plain = gym.make(env_id, **SMALL[env_id])
    u = env.unwrapped
    rows, cols = u.costmap_size
    assert env.observation_space.shape == (3, rows, cols)
    assert rows == 64 and cols == math.ceil(u.channel_width / 5.0 - 1e-9)
    assert both.observation_space["vector"] == plain.observation_space
    obs, _ = env.reset(seed=4)
    pair, _ = both.reset(seed=4)
    for _ in range(3):
        obs = env.step(np.zeros(env.action_space.shape, dtype=np.float32))[0]
        pair = both.step(np.zeros(both.action_space.shape, dtype=np.float32))[0]
    assert env.observation_space.contains(obs) and both.observation_space.contains(pair)
    np.testing.assert_array_equal(pair["costmap"], obs)
    sim = u.sim
    np.testing.assert_array_equal(obs, ice_costmap(
        sim.ship.position, sim.positions, sim.radii, u.expected_impulses(sim.masses),
        half_beam=0.5 * u.ship.hull.beam, goal_x=u.goal_x, centre_y=u.centre_y,
        channel_width=u.channel_width, box_lengths=(sim.box.lx, sim.box.ly),
        periodic=sim.box.periodic))
    for e in (env, both, plain):
        e.close()


@pytest.mark.parametrize("env_id", [i for i in SHIP_IDS if env_spec(i).vector_entry_point])
@pytest.mark.parametrize("obs_type", ["costmap", "costmap_dict"])
def test_the_native_vector_env_gives_the_costmap(env_id, obs_type):
    """The native vector environment batches the observation in its space,
    each row the costmap of its sub-environment."""
    envs = gym.make_vec(env_id, num_envs=2, vectorization_mode="vector_entry_point",
                        obs_type=obs_type, **SMALL[env_id])
    obs, _ = envs.reset(seed=5)
    assert envs.observation_space.contains(obs)
    for _ in range(3):
        obs = envs.step(np.zeros(envs.action_space.shape, dtype=np.float32))[0]
    assert envs.observation_space.contains(obs)
    maps = obs if obs_type == "costmap" else obs["costmap"]
    assert maps.shape == (2, *envs.single_observation_space.shape) if obs_type == "costmap" \
        else maps.shape == (2, *envs.single_observation_space["costmap"].shape)
    for k, sub in enumerate(envs.envs):
        np.testing.assert_array_equal(maps[k], sub.costmap())
    envs.close()


@pytest.mark.parametrize("kwargs, message", [
    ({"costmap_cell": 0.0}, "costmap_cell"),
    ({"costmap_cell": float("nan")}, "costmap_cell"),
    ({"costmap_ahead": 0.0}, "costmap_ahead"),
    ({"costmap_behind": -1.0}, "costmap_behind"),
    ({"costmap_cell": 0.01}, "more than"),
    ({"obs_type": "costmaps"}, "costmaps"),
])
def test_bad_arguments_raise(kwargs, message):
    env_id = SHIP_IDS[0]
    with pytest.raises(ValueError, match=message):
        gym.make(env_id, **SMALL[env_id], **kwargs)


def test_bad_sensor_arguments_raise():
    kw = {"half_beam": HALF_BEAM, "goal_x": 1e3, "centre_y": 0.0, "channel_width": 100.0}
    with pytest.raises(ValueError, match="impulses"):
        ice_costmap((0.0, 0.0), [[1.0, 2.0]], [1.0], [1.0, 2.0], **kw)
    with pytest.raises(ValueError, match="impulses"):
        ice_costmap((0.0, 0.0), [[1.0, 2.0]], [1.0], [-1.0], **kw)
    with pytest.raises(ValueError, match="half_beam"):
        ice_costmap((0.0, 0.0), [[1.0, 2.0]], [1.0], [1.0], **{**kw, "half_beam": 0.0})
    with pytest.raises(ValueError, match="box_lengths"):
        ice_costmap((0.0, 0.0), [[1.0, 2.0]], [1.0], [1.0], periodic=(False, True), **kw)
