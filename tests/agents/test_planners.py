"""The privileged planners (agents.planners): the lattice near an edge, and the rollouts."""
import gymnasium as gym
import numpy as np
import pytest

from agents.planners import CostmapLatticePlanner, LatticePlanner
from agents.planners import RolloutPlanner
from small_envs import SMALL

NAV = "iceenvs/ShipNavigation-v1"
KWARGS = {**SMALL[NAV], "length": 300.0, "goal_distance": 150.0}


def _sail(policy_class, seed=3, **kwargs):
    env = gym.make(NAV, **KWARGS)
    policy = policy_class(env, 0, **kwargs)
    obs, _ = env.reset(seed=seed)
    policy.reset(seed)
    rewards, observations, done = [], [obs], False
    while not done:
        obs, reward, terminated, truncated, _ = env.step(policy.predict(obs)[0])
        rewards.append(reward)
        observations.append(obs)
        done = terminated or truncated
    env.close()
    return policy, np.array(rewards), np.array(observations)


def test_without_offsets_the_rollouts_leave_the_lattices_episode_as_it_was():
    """Rolled out and restored at every plan, the episode is the lattice
    planner's, bit for bit: the rollouts change nothing of it."""
    planner, rewards, observations = _sail(RolloutPlanner, offsets=(), rollout_steps=8)
    _, lattice_rewards, lattice_observations = _sail(LatticePlanner)
    np.testing.assert_array_equal(rewards, lattice_rewards)
    np.testing.assert_array_equal(observations, lattice_observations)
    assert planner.choices and all(offset == 0.0 for offset, _ in planner.choices)


def test_with_a_margin_no_rollout_beats_the_lattice_keeps_the_lattices_route():
    """A margin larger than any window's return keeps the lattice's own
    route at every plan: the episode is the lattice planner's, bit for bit,
    though other candidates were rolled out."""
    planner, rewards, _ = _sail(RolloutPlanner, offsets=(-6.0, 6.0), rollout_steps=8,
                                margin=1e9)
    _, lattice_rewards, _ = _sail(LatticePlanner)
    np.testing.assert_array_equal(rewards, lattice_rewards)
    assert all(label == 0.0 and len(returns) == 3 for label, returns in planner.choices)


def test_each_plan_keeps_the_candidate_of_the_best_rollout():
    planner, rewards, _ = _sail(RolloutPlanner, offsets=(-6.0, 6.0), rollout_steps=8)
    assert planner.offsets == (0.0, -6.0, 6.0)  # the offsets asked for, 0 first
    assert planner.candidates == planner.offsets
    for offset, returns in planner.choices:
        assert len(returns) == 3 and returns[planner.offsets.index(offset)] == max(returns)
    assert len(planner.choices) == len(planner.decision_times)


def test_a_cost_factor_tries_the_lattices_route_at_another_price_of_a_metre():
    """A factor of 1 is the lattice's own route, so it is not tried twice;
    another is the lattice planned at that price, a route the planner may
    keep; with a price that makes every metre dear the route runs straight
    down the ship's row."""
    env = gym.make(NAV, **KWARGS)
    env.reset(seed=3)
    planner = RolloutPlanner(env, 0, offsets=(), cost_factors=(1.0, 1e9, 0.5), rollout_steps=8)
    assert planner.candidates == (0.0, "metre cost × 0.5", "metre cost × 1e+09")
    np.testing.assert_array_equal(planner.lattice_plan(planner.metre_cost),
                                  LatticePlanner(env, 0).plan())
    straight = planner.lattice_plan(planner.metre_cost * 1e9)
    np.testing.assert_allclose(straight[:, 1], straight[0, 1], atol=planner.lateral_step)
    env.close()
    planner, _, _ = _sail(RolloutPlanner, offsets=(), cost_factors=(0.5, 2.0), rollout_steps=8)
    for label, returns in planner.choices:
        assert len(returns) == 3 and returns[planner.candidates.index(label)] == max(returns)


class _UniformIce(RolloutPlanner):
    """The rollout planner on a grid of one ice cost density everywhere."""
    density = 0.0

    def cost_grid(self, x, y0, nx, ny, reach):
        return np.full((nx, ny), self.density)


@pytest.mark.parametrize("density", [0.0, 2_000.0])
def test_the_value_to_go_of_a_uniform_ice_is_the_progress_left_less_its_time_and_ice(density):
    """With one ice cost density c [N s/m] everywhere, the lattice's route
    runs straight (a detour adds length and ice), so the value to go from d
    metres before the goal line is (1 − w) d / ℓ − (w / ℓ) c L₀ / metre cost,
    L₀ the route's extent: the progress left less the ice the reward charges
    for it (its time is the progress's w)."""
    env = gym.make(NAV, **KWARGS)
    env.reset(seed=3)
    u = env.unwrapped
    planner = _UniformIce(env, 0, cost_to_go=True)
    planner.density = density
    route = planner.lattice_plan(u.metre_cost)
    np.testing.assert_allclose(route[:, 1], route[0, 1], atol=1e-9)
    extent = route[-1, 0] - route[0, 0]
    step, w = u.max_speed * u.control_interval, u.reward_params["time_weight"]
    left = u.goal_x - float(u.sim.ship.position[0])
    expected = (1 - w) * left / step - w / step * density * extent / u.metre_cost
    assert planner.value_to_go() == pytest.approx(expected, rel=1e-9)
    env.close()


def test_with_cost_to_go_a_rollout_adds_the_value_to_go_from_where_it_ends():
    env = gym.make(NAV, **KWARGS)
    obs, _ = env.reset(seed=3)
    u = env.unwrapped
    plain = RolloutPlanner(env, 0, rollout_steps=8)
    togo = RolloutPlanner(env, 0, rollout_steps=8, cost_to_go=True)
    for planner in (plain, togo):
        planner.predict(obs)              # the first plan, and its rollouts restored
    route, snap = plain.route, u.snapshot()
    window = plain._rollout(route)
    tail = plain.value_to_go()           # from where the window left the ship
    u.restore(snap)
    assert togo._rollout(route) == pytest.approx(window + tail, rel=1e-12)
    env.close()


@pytest.mark.parametrize("kwargs, message", [
    ({"offsets": (float("nan"),)}, "offsets must be finite"),
    ({"cost_factors": (0.0,)}, "cost_factors must be positive"),
    ({"cost_factors": (float("inf"),)}, "cost_factors must be positive"),
    ({"margin": -1.0}, "margin must be a number >= 0"),
    ({"margin": float("nan")}, "margin must be a number >= 0"),
    ({"rollout_steps": 4}, "rollout_steps must be an integer >= replan_steps"),
    ({"rollout_steps": 7.5}, "rollout_steps must be an integer >= replan_steps"),
    ({"noise": -0.1}, "noise must be a standard deviation"),
    ({"noise": float("nan")}, "noise must be a standard deviation"),
    ({"noise": True}, "noise must be a standard deviation"),
    ({"blur": -1.0}, "blur must be a distance"),
    ({"blur": float("inf")}, "blur must be a distance"),
    ({"fade": 0.0}, "fade must be a distance"),
    ({"fade": float("nan")}, "fade must be a distance"),
    ({"fade": True}, "fade must be a distance"),
])
def test_refused_arguments(kwargs, message):
    env = gym.make(NAV, **KWARGS)
    with pytest.raises(ValueError, match=message):
        RolloutPlanner(env, 0, **kwargs)


def test_cost_to_go_needs_a_flag_and_a_reward_that_prices_time_and_ice():
    env = gym.make(NAV, **KWARGS)
    with pytest.raises(TypeError, match="cost_to_go must be True or False"):
        RolloutPlanner(env, 0, cost_to_go="yes")
    env = gym.make(NAV, **KWARGS, reward_params={"time_weight": 0.0})
    with pytest.raises(ValueError, match="cost_to_go needs a reward that prices"):
        RolloutPlanner(env, 0, cost_to_go=True)


@pytest.mark.parametrize("planner", [CostmapLatticePlanner, RolloutPlanner])
def test_a_noisy_planner_follows_its_routes_shifted_by_seeded_errors(monkeypatch, planner):
    """``noise`` σ: each route planned is followed with its first stage's
    end shifted by e₁ · max_slope · 30 m and the points beyond by
    e₂ · max_slope · 60 m, e normal of σ from a generator seeded by the
    episode (a waypoint decision's error of σ); the rollouts' lattice
    after the window plans without it; the same seed sails the same
    episode."""
    planned, followed = [], []
    plan = planner.plan
    erred = LatticePlanner._erred

    def kept_plan(self):
        planned.append(plan(self))
        return planned[-1]

    def kept_erred(self, route):
        out = erred(self, route)
        if self.noise:          # the planner's, not its rollouts' lattice's
            followed.append(out)
        return out

    monkeypatch.setattr(planner, "plan", kept_plan)
    monkeypatch.setattr(LatticePlanner, "_erred", kept_erred)
    sigma = 0.1
    kwargs = {"noise": sigma, "offsets": (-5.0, 5.0)} if planner is RolloutPlanner \
        else {"noise": sigma}
    policy, rewards, _ = _sail(planner, seed=3, **kwargs)
    rng = np.random.default_rng(3)
    half = 0.5 * policy.unwrapped.channel_width - policy.edge_margin
    low, high = policy.unwrapped.centre_y - half, policy.unwrapped.centre_y + half
    assert len(planned) == len(followed) > 3
    for route, sailed in zip(planned, followed):
        e = rng.normal(0.0, sigma, 2) * 0.5 * 30.0
        expected = route.copy()
        expected[1:2, 1] += e[0]
        expected[2:, 1] += 2.0 * e[1]
        expected[1:, 1] = np.clip(expected[1:, 1], low, high)
        np.testing.assert_allclose(sailed, expected, rtol=0, atol=1e-9)
    if planner is RolloutPlanner:
        assert policy._base_kwargs["noise"] == 0.0
    planned.clear()
    followed.clear()
    _, again, _ = _sail(planner, seed=3, **kwargs)
    np.testing.assert_array_equal(again, rewards)


def test_a_blur_spreads_the_cost_across_the_channel_by_its_variance():
    """``blur`` b: each column of the cost grid is convolved across the
    channel with a normal kernel of b: away from the edges its total is
    kept, its centre stays and its variance grows by (b / cell)² cells²
    (the moments of a convolution); without a blur the grid is itself."""
    env = gym.make(NAV, **KWARGS)
    planner = LatticePlanner(env, 0, blur=3.0)
    cost = np.zeros((4, 101))
    cost[:, 50] = 1.0
    cost[1, 40:61] = np.linspace(0.0, 2.0, 21)
    smooth = planner.blurred(cost)
    y = np.arange(101.0)
    for before, after in zip(cost, smooth):
        assert after.sum() == pytest.approx(before.sum(), rel=1e-9)
        mean_b, mean_a = (y @ before) / before.sum(), (y @ after) / after.sum()
        assert mean_a == pytest.approx(mean_b, abs=1e-9)
        var_b = ((y - mean_b) ** 2 @ before) / before.sum()
        var_a = ((y - mean_a) ** 2 @ after) / after.sum()
        # the kernel is cut at 4 standard deviations and sampled on cells: its variance
        # is (b / cell)² to within 0.5 % at b / cell = 2
        assert var_a - var_b == pytest.approx((3.0 / 1.5) ** 2, rel=5e-3)
    assert LatticePlanner(env, 0).blurred(cost) is cost
    env.close()


def test_a_fade_weighs_the_cost_down_by_its_distance_ahead():
    """``fade`` f: the cost of the column whose centre lies s ahead of the
    ship is multiplied by e^(−s/f), so that the ratio of two columns a
    distance d apart is e^(−d/f) and a column f further ahead counts 1/e
    as much; with a blur as well, each column is faded then blurred
    (the blur keeps a column's total)."""
    env = gym.make(NAV, **KWARGS)
    planner = LatticePlanner(env, 0, fade=60.0)
    cell = planner.lateral_step
    cost = np.ones((81, 7))
    faded = planner.blurred(cost)
    np.testing.assert_allclose(faded[:, 3], np.exp(-(np.arange(81) + 0.5) * cell / 60.0),
                               rtol=1e-12)
    assert faded[40, 0] / faded[0, 0] == pytest.approx(np.exp(-40 * cell / 60.0), rel=1e-12)
    both = LatticePlanner(env, 0, fade=60.0, blur=3.0).blurred(cost)
    np.testing.assert_allclose(both.sum(axis=1), faded.sum(axis=1), rtol=1e-9)
    env.close()


def test_the_lattice_plans_for_a_ship_heading_steeply_for_the_edge():
    """Steered hard to port and then straight (as a rollout's candidate may
    leave it), the ship heads for the edge too steeply for the lattice's
    slope steps: the route from its heading does not exist (infinite cost),
    and the planner plans from a straight heading instead of failing."""
    import math

    from agents.planners import lattice_route

    env = gym.make(NAV, **SMALL[NAV])
    env.reset(seed=0)
    u = env.unwrapped
    for k in range(60):
        env.step(np.array([1.0 if k < 10 else 0.0], dtype=np.float32))
        if u.sim.ship.position[1] > u.centre_y + 0.5 * u.channel_width - 28.0:
            break
    planner = LatticePlanner(env, 0)
    cell = planner.lateral_step
    stage_cells = int(round(planner.stage_length / cell))
    max_slope = int(round(planner.max_slope * stage_cells))
    steep = min(int(round(math.tan(u.sim.ship.heading) * stage_cells)), max_slope)
    # the lattice's own grid about the ship: rows up to the edge margin
    room = int((u.centre_y + 0.5 * u.channel_width - planner.edge_margin
                - u.sim.ship.position[1]) / cell)
    cost = np.zeros((10 * stage_cells, room + 41))
    _, total = lattice_route(cost, cell, stage_cells, 10, 40, steep, max_slope, 0, 40 + room, 0.0)
    assert math.isinf(total)
    route = planner.plan()
    assert np.isfinite(route).all()
    assert route[:, 1].max() <= u.centre_y + 0.5 * u.channel_width - planner.edge_margin
    env.close()


def test_the_rollout_planner_is_played_only_when_named():
    from agents import benchmark, leaderboard
    from agents.baselines import baseline_names

    assert "rollout" in baseline_names(NAV)
    assert "rollout" not in leaderboard.default_policies(NAV)
    assert "lattice" in leaderboard.default_policies(NAV)
    assert "rollout" not in benchmark._baseline_recipes(NAV)


def test_the_lattice_plans_for_a_ship_within_the_edge_margin():
    """A ship that another controller (a learner in DAgger) took within
    ``edge_margin`` of the edge still gets a route from where it is, never
    farther out."""
    env = gym.make(NAV, **SMALL[NAV])
    env.reset(seed=0)
    u = env.unwrapped
    planner = LatticePlanner(env, 0)
    edge = u.centre_y + 0.5 * u.channel_width
    for k in range(80):
        env.step(np.array([1.0 if k < 10 else 0.0], dtype=np.float32))
        if u.sim.ship.position[1] > edge - 0.5 * planner.edge_margin:
            break
    y = u.sim.ship.position[1]
    assert edge - planner.edge_margin < y < edge
    route = planner.plan()
    assert np.isfinite(route).all() and route[0, 1] == pytest.approx(y, abs=1e-9)
    assert route[:, 1].max() <= y + 1e-9
    env.close()


def test_the_costmap_lattice_costs_the_ice_the_floes_give_in_blocks_of_the_map():
    """The lattice's cost grid read from the costmap (5 m cells) against the
    one built from the floes (1.5 m cells) on a field at A = 0.4: summed
    over blocks of 30 m × 15 m (20 × 10 cells), each the integral of the
    same cone-spread impulse over the block, the two differ by less than 5%
    of the ice's total (the cells' sampling and their edges' misalignment:
    0.5% on this field; the map read mirrored misses by 36%), and
    beyond the map's 300 m the costmap lattice sees no ice."""
    env = gym.make(NAV, **{**KWARGS, "concentration": 0.4, "length": 600.0,
                           "goal_distance": 450.0})
    env.reset(seed=5)
    u = env.unwrapped
    lattice, seen = LatticePlanner(env, 0, show=False), CostmapLatticePlanner(env, 0, show=False)
    x, y = (float(v) for v in u.sim.ship.position)
    nx, ny = 240, 60                     # 360 m ahead, 90 m across about the ship
    y0 = y - 45.0
    truth = lattice.cost_grid(x, y0, nx, ny, 400.0)
    read = seen.cost_grid(x, y0, nx, ny, 400.0)
    assert read[200:].max() == 0.0 and truth[:200].sum() > 0.0
    blocks = lambda c: c[:200].reshape(10, 20, 6, 10).sum(axis=(1, 3))  # noqa: E731
    miss = np.abs(blocks(read) - blocks(truth)).sum() / blocks(truth).sum()
    assert miss < 0.05, miss
    mirrored = np.abs(blocks(read[:, ::-1]) - blocks(truth)).sum() / blocks(truth).sum()
    assert mirrored > 2 * miss
    env.close()
