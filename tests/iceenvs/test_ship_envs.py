"""The ship environments: kinematics of the prescribed ship, the episode
metrics against the engine's own records, rewards against their formula,
termination, task parameters, observation types and fuzzing."""
import math

import gymnasium as gym
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import iceenvs  # noqa: F401  (registers the ids)
from agents.metrics import physics_metrics
from iceenvs.facts import env_facts
from iceenvs.ship_env import METRICS
from iceenvs.ship_measures import SUM_COLUMNS

NAV = "iceenvs/ShipNavigation-v0"
BESET = "iceenvs/ShipBeset-v0"


def _straight(env, obs, steps=400):
    """Sail the straight-line baseline from ``obs`` to the end of the
    episode; returns the rewards, the last info and whether it terminated."""
    from iceenvs.ship_controllers import StraightLineController

    policy = StraightLineController(env)
    rewards = []
    for _ in range(steps):
        action, _ = policy.predict(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        rewards.append(reward)
        if terminated or truncated:
            break
    return rewards, info, terminated


# -- kinematics and metrics -------------------------------------------------------------------

def test_open_water_transit_reward_and_metrics_are_exact():
    """A ship alone (a concentration so low that no floe lies on the line):
    every step gains exactly the distance sailed at full speed, reward
    1 − time_weight, and the goal step adds the bonus; path length = goal
    distance to the last step's overshoot, efficiency 300/path."""
    env = gym.make(NAV, concentration=0.01)
    try:
        obs, _ = env.reset(seed=0)
        u = env.unwrapped
        rewards, info, terminated = _straight(env, obs)
    finally:
        env.close()
    assert terminated and info["success"]
    assert info["collisions"] == 0 and info["energy_to_ice"] == 0.0
    steps = len(rewards)
    assert steps == math.ceil(300.0 / (2.0 * 2.0))           # 2 m/s, 2 s steps
    np.testing.assert_allclose(rewards[:-1], 1.0 - 0.05, atol=1e-9)
    assert rewards[-1] == pytest.approx(1.0 - 0.05 + 10.0, abs=1e-9)
    assert info["path_length"] == pytest.approx(2.0 * 2.0 * steps, rel=1e-6)
    assert info["efficiency"] == pytest.approx(300.0 / info["path_length"], rel=1e-9)
    assert info["time"] == pytest.approx(2.0 * steps, rel=1e-9)
    # effort of the prescribed ship in open water: the surge damping's work
    h = u._ship.hydrodynamics
    power = (h.linear_damping[0] * 2.0 + h.quadratic_damping[0] * 4.0) * 2.0
    assert info["effort"] == pytest.approx(power * info["time"], rel=1e-3)


def test_yaw_rate_action_turns_the_prescribed_ship_at_that_rate():
    """Heading after k steps of a constant yaw action a: a × max_yaw_rate × t."""
    env = gym.make(NAV, concentration=0.01)
    try:
        env.reset(seed=0)
        for _ in range(5):
            env.step(np.array([0.5], np.float32))
        ship = env.unwrapped.sim.ship
        assert ship.heading == pytest.approx(0.5 * 0.04 * 10.0, rel=1e-6)
        assert ship.surge == pytest.approx(2.0, rel=1e-9)
    finally:
        env.close()


def test_course_action_is_followed_with_the_autopilots_time_constant():
    """control="course": the autopilot turns at (course − heading) /
    course_time (20 s), so over 2 s steps the heading error shrinks by
    1 − 2/20 a step: after k steps of a full course (π/4 = 45°, within the
    yaw limit: 0.785 rad / 20 s < 0.04 rad/s) the heading is
    π/4 (1 − 0.9^k). Larger errors turn at max_yaw_rate, the short way
    round; a course_time below the control interval counts as the
    interval."""
    env = gym.make(NAV, concentration=0.01, control="course")
    try:
        env.reset(seed=0)
        ship = env.unwrapped.sim.ship
        headings = []
        for _ in range(12):
            env.step(np.array([1.0], np.float32))
            headings.append(ship.heading)
        np.testing.assert_allclose(headings, math.pi / 4 * (1.0 - 0.9 ** np.arange(1, 13)),
                                   rtol=1e-9)
        assert ship.surge == pytest.approx(2.0, rel=1e-9)
        u = env.unwrapped
        # heading 3 rad, course −0.9 π/4 = −0.71 rad: the short way is anticlockwise,
        # through π (an error of 2π − 3.71 = +2.58 rad), at the full rate
        assert u.course_yaw_rate(-0.9, 3.0) == pytest.approx(0.04)
        assert u.course_yaw_rate(0.0, 0.05) == pytest.approx(-0.0025, rel=1e-12)
    finally:
        env.close()
    env = gym.make(NAV, concentration=0.01, control="course", course_time=0.5)
    try:
        env.reset(seed=0)
        assert env.unwrapped.course_yaw_rate(0.0, 0.05) == pytest.approx(-0.025, rel=1e-12)
    finally:
        env.close()
    with pytest.raises(ValueError, match="course_time"):
        gym.make(NAV, control="course", course_time=0.0)


@pytest.mark.parametrize("planner", ["reactive", "lattice"])
def test_planners_steer_by_course(planner):
    """The planners command courses with control="course" (actions within
    the box, not all equal) and reach the goal line."""
    from agents.baselines import make_baseline

    env = gym.make(NAV, concentration=0.3, control="course")
    try:
        obs, _ = env.reset(seed=1)
        policy = make_baseline(planner, env, seed=1)
        actions = []
        for _ in range(300):
            action, _ = policy.predict(obs)
            actions.append(float(action[0]))
            obs, _, terminated, truncated, info = env.step(action)
            if terminated or truncated:
                break
    finally:
        env.close()
    assert info["success"]
    assert min(actions) >= -1.0 and max(actions) <= 1.0
    assert len(set(actions)) > 1                   # it steered


def test_the_ship_controllers_old_names_are_the_same_classes():
    """User code and saved ``module:Class`` references may name the ship
    controllers by their names before this release; those import the same
    classes, and a reference by an old name builds the controller."""
    from agents.policy import policy_class
    from iceenvs import ship_controllers as sc

    pairs = {"StraightLinePolicy": sc.StraightLineController,
             "ReactivePlanner": sc.ReactiveController, "SwathPlanner": sc.SwathController}
    for old, new in pairs.items():
        assert getattr(sc, old) is new
        assert policy_class(f"iceenvs.ship_controllers:{old}") is new
    assert env_facts(NAV).controllers["straight"] is sc.StraightLineController


def test_the_straight_line_is_the_same_path_with_either_steering_action():
    """The straight line commands zero yaw rate with control="yaw" and the
    goal direction's course with control="course": the same episode."""
    runs = []
    for control in ("yaw", "course"):
        env = gym.make(NAV, concentration=0.3, control=control)
        try:
            obs, _ = env.reset(seed=2)
            rewards, info, _ = _straight(env, obs)
        finally:
            env.close()
        runs.append((len(rewards), sum(rewards), info["impulse_per_metre"]))
    assert runs[0][0] == runs[1][0]
    np.testing.assert_allclose(runs[0][1:], runs[1][1:], rtol=1e-12)
    assert runs[0][2] > 0.0                                  # the line met ice


def test_collision_impulses_are_bounded_by_the_contact_impulses():
    """Over an episode, Σ_c |J_c| of the logged collisions ≤ Σ_c ∫ |F_c| dt
    (``step_contact_impulse``): each J_c is the integral of its contact's
    force (triangle inequality; turning it into the ship frame keeps its
    length) and collisions still open at the end are not logged. And
    ∫ |Σ_c F_c| dt (``step_impulse``) ≤ Σ_c ∫ |F_c| dt at every step. Neither
    log total nor resultant bounds the other: floes pressing on opposite
    sides cancel in the resultant, not in the log."""
    env = gym.make(NAV, concentration=0.5)
    try:
        obs, _ = env.reset(seed=3)
        u = env.unwrapped
        resultant = contact = 0.0
        from iceenvs.ship_controllers import StraightLineController

        policy = StraightLineController(env)
        while True:
            action, _ = policy.predict(obs)
            obs, _, terminated, truncated, info = env.step(action)
            loads = info["physics"]
            # at every step; 1e-12: sums of ~2e3 engine steps of a few dozen contacts,
            # each rounding to ~1e-16 relative
            assert loads["step_impulse"] <= loads["step_contact_impulse"] * (1.0 + 1e-12)
            resultant += loads["step_impulse"]
            contact += loads["step_contact_impulse"]
            if terminated or truncated:
                break
        impulses = u._sums[SUM_COLUMNS.index("impulse_total")]
    finally:
        env.close()
    assert info["collisions"] >= 5 and u.n_floes > 50
    assert impulses > 0.0 and resultant > 0.0
    # 1e-9: the two totals sum the same ~1e5 contact-step terms in different
    # orders, each rounding to ~1e-16 relative
    assert impulses <= contact * (1.0 + 1e-9), (impulses, contact)
    assert resultant <= contact * (1.0 + 1e-9), (resultant, contact)
    # the mean mass of the floes hit, each once, from the engine's masses
    hit = sorted(u.floes_hit)
    assert info["collided_floes"] == len(hit) > 1
    np.testing.assert_allclose(info["mean_mass_hit"], np.mean(u.sim.masses[hit]), rtol=1e-12)


@pytest.mark.parametrize("dynamic", [False, True])
def test_step_sums_match_column_by_column_numpy(dynamic):
    """The compiled sums behind the step loads equal NumPy over the record
    columns: means, maxima, |resultant|, the effort's power (|T u| + |M r|,
    or the ice power plus Σ (b v + a |v| v) v) and the path from (x0, y0)."""
    from physics.hull_contact import RECORD_COLUMNS
    from iceenvs.ship_measures import step_sums

    rng = np.random.default_rng(4)
    rows = rng.normal(0.0, 1.0, (300, len(RECORD_COLUMNS))) * rng.uniform(0.1, 1e6,
                                                                           len(RECORD_COLUMNS))
    col = {name: rows[:, k] for k, name in enumerate(RECORD_COLUMNS)}
    x0, y0, thrust, moment = 3.0, -2.0, 4e5, -2e6
    b, a = (2e4, 5e4, 3e6), (1e3, 8e3, 1e7)
    got = step_sums(rows, x0, y0, dynamic, thrust, moment, b, a)
    vel = np.column_stack([col["surge"], col["sway"], col["yaw_rate"]])
    if dynamic:
        power = np.abs(thrust * col["surge"]) + np.abs(moment * col["yaw_rate"])
    else:
        power = col["ice_power"] + np.sum((np.array(b) * vel + np.array(a) * np.abs(vel) * vel)
                                          * vel, axis=1)
    path = np.diff(np.vstack([[x0, y0], np.column_stack([col["x"], col["y"]])]), axis=0)
    terms = (col["ice_surge"], col["ice_sway"], col["ice_moment"], col["normal_force"], None,
             np.hypot(col["ice_surge"], col["ice_sway"]), col["force_magnitude_sum"],
             col["ice_power"], power, np.hypot(path[:, 0], path[:, 1]))
    assert got[4] == col["normal_force"].max()          # the largest value, no arithmetic
    for g, t, name in zip(got, terms, ("surge", "sway", "moment", "normal", "peak", "resultant",
                                       "magnitudes", "ice power", "effort", "path")):
        if t is not None:
            # 1e-12 of the sum of magnitudes: 300 terms summed in another
            # order, each addition rounding to ~1e-16 of the running sum
            assert abs(g - t.sum()) <= 1e-12 * np.abs(t).sum(), name


def test_episode_metrics_are_the_ones_agents_log():
    env = gym.make(NAV, concentration=0.3)
    try:
        _, info = env.reset(seed=0)
        assert set(METRICS) <= set(info)
        _, _, _, _, info = env.step(np.zeros(1, np.float32))
        assert set(METRICS) <= set(info)
    finally:
        env.close()
    logged = physics_metrics(NAV, info)
    assert set(env_facts("iceenvs/ShipNavigation-v0").episode_metrics) <= set(logged)
    assert all(logged[k] == float(info[k]) for k in METRICS)


# -- termination and rewards -----------------------------------------------------------------

def _turn_out(exit_rule, max_yaw_rate=0.04):
    """Turn to port at the full rate from the centre line until the ship
    leaves the channel or the episode ends: (rewards, info, terminated)."""
    env = gym.make(NAV, concentration=0.01, channel_exit=exit_rule, max_yaw_rate=max_yaw_rate)
    try:
        env.reset(seed=0)
        rewards = []
        for _ in range(200):
            _, reward, terminated, truncated, info = env.step(np.array([1.0], np.float32))
            rewards.append(reward)
            if terminated or truncated or abs(info["physics"]["channel_offset"]) > 1.0:
                break
    finally:
        env.close()
    return rewards, info, terminated


def test_leaving_the_channel_is_penalised_or_ends_the_episode():
    # a turn at 0.5 rad/s (a circle of radius 4 m) never leaves the channel
    _, info, _ = _turn_out("terminate", max_yaw_rate=0.5)
    assert abs(info["physics"]["channel_offset"]) <= 1.0
    # at 0.04 rad/s (radius 50 m) from the centre line it leaves the 75 m half-channel
    rewards, info, terminated = _turn_out("terminate")
    assert terminated and not info["success"] and rewards[-1] == -10.0
    assert abs(info["physics"]["channel_offset"]) > 1.0
    rewards, info, terminated = _turn_out("penalty")
    assert not terminated and abs(info["physics"]["channel_offset"]) > 1.0
    # outside: progress − time cost − exit weight
    assert rewards[-1] <= 1.0 - 0.05 - 1.0 + 1e-9


def test_a_weak_ship_is_beset_and_the_episode_fails():
    """The dynamic ship with a thousandth of its thrust in the pack along
    the coast cannot hold 5 cm/s: after beset_time it is beset."""
    env = gym.make(BESET, concentration=0.7, thrust_fraction=0.001, speed=0.0, beset_time=20.0)
    try:
        env.reset(seed=0)
        for k in range(100):  # noqa: B007  (k counts the steps after the loop)
            _, reward, terminated, truncated, info = env.step(np.array([1.0, 0.0], np.float32))
            if terminated or truncated:
                break
        assert terminated and not info["success"] and reward == -10.0
        assert k + 1 == 10                 # 20 s of 2 s steps
    finally:
        env.close()


def test_beset_reward_penalises_hull_pressure_above_the_limit():
    from iceenvs.rewards import ship_beset_reward

    prev = {"goal_distance": 100.0}
    now = {"goal_distance": 95.0, "hull_pressure": 1.5e4, "reached": 0.0}
    r = ship_beset_reward(prev, None, now, step_length=10.0, pressure_limit=1e4)
    assert r == pytest.approx(0.5 - 0.5 - 0.05)
    now["hull_pressure"] = 5e4
    r = ship_beset_reward(prev, None, now, step_length=10.0, pressure_limit=1e4)
    assert r == pytest.approx(0.5 - 1.0 - 0.05)


# -- task parameters and observation types -----------------------------------------------------

def test_concentration_drawn_per_episode_keyword_and_option():
    env = gym.make(NAV)
    try:
        drawn = {env.reset(seed=s)[1]["task"]["concentration"] for s in range(4)}
        assert len(drawn) == 4 and all(0.2 <= c <= 0.6 for c in drawn)
    finally:
        env.close()
    env = gym.make(NAV, concentration=0.25)
    try:
        _, info = env.reset(seed=0)
        assert info["task"]["concentration"] == 0.25
        assert info["physics"]["concentration"] == pytest.approx(0.25, abs=0.01)
        _, info = env.reset(seed=1, options={"concentration": 0.5})
        assert info["physics"]["concentration"] == pytest.approx(0.5, abs=0.01)
        _, info = env.reset(seed=2)
        assert info["task"]["concentration"] == 0.25
    finally:
        env.close()


def test_wind_sets_the_ice_drifting_at_its_free_drift():
    env = gym.make(NAV, concentration=0.3, wind_speed=15.0, wind_direction=0.5)
    try:
        env.reset(seed=0)
        v = env.unwrapped.sim.velocities
        speed = np.hypot(v[:, 0], v[:, 1])
        # free drift of 1.5 m ice at 15 m/s of wind: a few per cent of it
        assert 0.1 < np.median(speed) < 0.8
    finally:
        env.close()


@pytest.mark.parametrize("control, n", [("yaw", 1), ("speed_yaw", 2), ("thrust", 2),
                                        ("course", 1)])
def test_controls_have_their_action_spaces(control, n):
    env = gym.make(NAV, concentration=0.3, control=control)
    try:
        assert env.action_space.shape == (n,)
        env.reset(seed=0)
        _, _, _, _, info = env.step(np.ones(n, np.float32))
        assert "error" not in info
        ship = env.unwrapped.sim.ship
        assert ship.mode == ("dynamic" if control == "thrust" else "prescribed")
    finally:
        env.close()
    with pytest.raises(ValueError, match="control"):
        gym.make(NAV, control="rudder")


@pytest.mark.parametrize("obs_type", ["image", "dict"])
def test_image_and_dict_observations(obs_type):
    env = gym.make(NAV, concentration=0.4, obs_type=obs_type, image_size=48)
    try:
        obs, _ = env.reset(seed=0)
        assert env.observation_space.contains(obs)
        obs, *_ = env.step(np.zeros(1, np.float32))
        assert env.observation_space.contains(obs)
        image = obs if obs_type == "image" else obs["image"]
        assert image.shape == (4, 48, 48) and image.dtype == np.uint8
        assert image[1].max() == 255          # the hull is in the picture
    finally:
        env.close()


def test_reset_at_concentration_06_takes_under_a_second():
    import time

    env = gym.make(NAV, concentration=0.6)
    try:
        env.reset(seed=0)
        times = []
        for seed in range(1, 6):
            t0 = time.perf_counter()
            env.reset(seed=seed)
            times.append(time.perf_counter() - t0)
    finally:
        env.close()
    assert max(times) < 1.0, times


def test_cnn_policy_trains_on_images():
    sb3 = pytest.importorskip("stable_baselines3")
    env = gym.make(NAV, concentration=0.3, obs_type="image", image_size=36,
                   max_episode_steps=20)
    try:
        model = sb3.PPO("CnnPolicy", env, n_steps=32, batch_size=16, n_epochs=1, seed=0,
                        device="cpu", policy_kwargs=dict(normalize_images=True,
                                                         features_extractor_kwargs=dict(
                                                             features_dim=32)))
        model.learn(total_timesteps=64)
        action, _ = model.predict(env.reset(seed=1)[0], deterministic=True)
        assert env.action_space.contains(action)
    finally:
        env.close()


# -- fuzzing ------------------------------------------------------------------------------------

ENVS = {NAV: gym.make(NAV, concentration=0.4).unwrapped,
        BESET: gym.make(BESET, concentration=0.6).unwrapped}
FUZZ = settings(max_examples=10, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow])
entries = st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=32),
                    st.floats(min_value=-1.0, max_value=1.0, width=32))
OPTIONS = {
    NAV: st.fixed_dictionaries({}, optional={
        "concentration": st.floats(min_value=0.05, max_value=0.7),
        "wind_speed": st.floats(min_value=0.0, max_value=30.0),
        "current_speed": st.floats(min_value=0.0, max_value=0.5),
        "floe_sizes": st.sampled_from(["pack", "brash"])}),
    BESET: st.fixed_dictionaries({}, optional={
        "concentration": st.floats(min_value=0.3, max_value=0.75),
        "wind_speed": st.floats(min_value=0.0, max_value=30.0),
        "pressure_limit": st.floats(min_value=1.0, max_value=1e6)}),
}


def _fuzz(env_id, seed, options, acts):
    env = ENVS[env_id]
    low, high = env.reward_bounds
    obs, _ = env.reset(seed=seed, options=options)
    assert env.observation_space.contains(obs)
    for a in acts:
        obs, reward, terminated, truncated, info = env.step(np.array(a, dtype=np.float32))
        assert "error" not in info, info.get("error")
        assert env.observation_space.contains(obs) and np.all(np.isfinite(obs))
        assert low <= reward <= high, reward
        for key in METRICS:
            assert math.isfinite(float(info[key])), key
        if terminated or truncated:
            break


@FUZZ
@given(seed=st.integers(0, 2 ** 32 - 1), options=OPTIONS[NAV],
       acts=st.lists(st.lists(entries, min_size=1, max_size=1), min_size=1, max_size=3))
def test_ship_navigation_fuzz(seed, options, acts):
    _fuzz(NAV, seed, options, acts)


@FUZZ
@given(seed=st.integers(0, 2 ** 32 - 1), options=OPTIONS[BESET],
       acts=st.lists(st.lists(entries, min_size=2, max_size=2), min_size=1, max_size=3))
def test_ship_beset_fuzz(seed, options, acts):
    _fuzz(BESET, seed, options, acts)


def test_draw_ship_paints_the_hull_and_rejects_bad_input():
    pytest.importorskip("pygame")
    from iceenvs.rendering import HULL, draw_floes, draw_ship

    pic = draw_floes(np.array([[10.0, 10.0]]), np.array([1.0]), (200.0, 100.0),
                     np.array([0.0]), size=400)
    hull = np.array([[90.0, 45.0], [110.0, 45.0], [110.0, 55.0], [90.0, 55.0]])
    out = draw_ship(pic, (200.0, 100.0), hull, np.array([[20.0, 50.0], [100.0, 50.0]]),
                    goal_x=150.0)
    assert tuple(out[100, 200]) == HULL                   # centre of the hull, y up
    with pytest.raises(ValueError, match="hull_vertices"):
        draw_ship(pic, (200.0, 100.0), hull[:2])
    with pytest.raises(ValueError, match="picture"):
        draw_ship(pic[..., 0], (200.0, 100.0), hull)


@pytest.mark.parametrize("env_id", ["iceenvs/ShipNavigation-v0", "iceenvs/ShipNavigation-v1"])
def test_the_resistance_records_task_row_covers_the_tasks(env_id):
    """The ship-resistance summary's row for the ShipNavigation tasks
    (physics.scenarios.ship_resistance.TASK_FROUDE, TASK_CONCENTRATIONS)
    holds each task's default speed on its floes' thickness, as a Froude
    number, and its range of drawn concentrations: the tasks' docs point to
    that row to say how far their loads are from the laws."""
    from physics.scenarios.ship_resistance import TASK_CONCENTRATIONS, TASK_FROUDE

    env = gym.make(env_id, concentration=0.3)
    try:
        env.reset(seed=0)
        u = env.unwrapped
        thickness = float(np.median(u.sim.field.thickness))
        froude = u.episode["speed"] / math.sqrt(9.81 * thickness)
        assert TASK_FROUDE[0] <= froude <= TASK_FROUDE[1], froude
        low, high = u.episode["concentration_range"]
        assert TASK_CONCENTRATIONS[0] <= low and high <= TASK_CONCENTRATIONS[1]
    finally:
        env.close()


@pytest.mark.parametrize("env_id", [NAV, BESET, "iceenvs/ShipNavigation-v1"])
def test_the_default_engine_step_is_the_one_the_equivalence_test_supports(env_id):
    """A ship environment's default engine step is the fast one exactly when
    its equivalence record (``seaice bench free_drift``, docs/benchmarks)
    supports it: no row fails the margin and the control resolves nearly
    every row. Without a record the exact step stays the default. The exact
    step is one keyword away."""
    import json
    from pathlib import Path

    from benchmarks import bench_free_drift as fd

    docs = Path(__file__).resolve().parents[2] / "docs" / "benchmarks"
    path = fd.record_path(docs / f"{fd.SUITE}.json", env_id)
    record = json.loads(path.read_text(encoding="utf-8")) if path.is_file() else None
    others = [json.loads(p.read_text(encoding="utf-8")) for p in docs.glob(f"{fd.SUITE}-*.json")]
    supported = (record is not None and not record["data"]["quick"]
                 and fd.supports(record, "fast", [r for r in others if not r["data"]["quick"]]))
    for kwargs, fast in (({}, supported), ({"free_drift": False}, False)):
        env = gym.make(env_id, **kwargs)
        try:
            assert env.unwrapped.free_drift is fast, (env_id, kwargs)
        finally:
            env.close()
