"""The committed observation page is what the environments' feature lists
give, and the signs it states are the signs the environments measure."""
from pathlib import Path

import gymnasium as gym
import numpy as np

import iceenvs  # noqa: F401
from iceenvs.observation_page import PAGE, observations_page

ROOT = Path(__file__).resolve().parents[2]


def test_the_committed_page_matches_the_code():
    committed = (ROOT / PAGE).read_text(encoding="utf-8")
    assert committed == observations_page(), (
        "docs/observations.md is out of date: run python -m iceenvs.observation_page")
    for env_id in iceenvs.ENV_IDS:
        assert f"## {env_id}\n" in committed


def test_turning_to_port_makes_goal_sin_and_channel_offset_positive():
    """A positive yaw rate turns the ship anticlockwise, to port: the goal
    (ahead along +x) then lies to starboard, goal_sin < 0, and the ship
    drifts to port of the centre line, channel_offset > 0."""
    env = gym.make("iceenvs/ShipNavigation-v0", concentration=0.2)
    names = [f.name for f in env.unwrapped.features]
    obs, _ = env.reset(seed=0)
    assert abs(obs[names.index("channel_offset")]) < 1e-6
    for _ in range(5):
        obs, *_ = env.step(np.ones(1, np.float32))
    now = env.unwrapped.last_measurement
    assert now["goal_sin"] < 0.0 and now["channel_offset"] > 0.0
    assert env.unwrapped.sim.ship.position[1] > env.unwrapped.centre_y
    env.close()


def test_the_costmaps_cost_is_read_from_the_sensors_record(tmp_path):
    """The page states the costmap's share of a step from the sensors
    benchmark's record (its least and greatest over the concentrations),
    and points to the command where the record lacks it."""
    import json

    from iceenvs.observation_page import costmap_cost

    rows = [dict(concentration=0.2, step=2.0e-3, costmap=1.0e-4, costmap_far=2.0e-4),
            dict(concentration=0.5, step=4.0e-3, costmap=1.2e-4, costmap_far=1.6e-4)]
    record = tmp_path / "sensors.json"
    record.write_text(json.dumps({"data": {"rows": rows}, "machine": {"cpu": "a CPU"},
                                  "date": "2026-01-02T03:04:05+00:00"}))
    text = costmap_cost(record)
    assert "costs 0.03–0.05 of a step" in text and "(A = 0.2–0.5)" in text
    assert "0.04–0.10 with it reaching 500 m" in text and "a CPU, 2026-01-02" in text
    record.write_text(json.dumps({"data": {"rows": [dict(concentration=0.2, step=1.0)]},
                                  "machine": {}, "date": "2026-01-02"}))
    assert "timed by `seaice bench sensors`" in costmap_cost(record)
    assert "timed by `seaice bench sensors`" in costmap_cost(tmp_path / "none.json")
