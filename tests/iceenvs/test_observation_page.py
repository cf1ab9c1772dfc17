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
