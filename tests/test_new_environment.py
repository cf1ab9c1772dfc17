"""A new environment added by the documented steps alone (the Contributing
page): a module with its class and facts, and one ``register`` call. It then
passes the shared checks, the agents' evaluation and the warm-up without any
other file knowing its id."""
from __future__ import annotations

import json
import math

import gymnasium as gym
import numpy as np
import pytest

from iceenvs.base import HertzEnv, TaskParameter, number
from iceenvs.controllers import FloeController
from iceenvs.facts import EnvFacts, env_facts, registered_ids
from physics import HERMAN2013

ENV_ID = "iceenvs-test/Calm-v0"


def calm_reward(prev, action, now, *, speed_scale: float) -> float:
    """1 for ice at rest, falling as 1/(1 + |u|/speed_scale): in (0, 1]."""
    return 1.0 / (1.0 + math.hypot(now["u_x"], now["u_y"]) / speed_scale)


class CalmController(FloeController):
    """Blow against the mean drift."""

    def act(self, obs):
        u = np.array([self._get(obs, "u_x"), self._get(obs, "u_y")])
        return -np.clip(u / 0.01, -1.0, 1.0)


class CalmEnv(HertzEnv):
    """Keep the ice at rest under a wind that the agent controls.

    ## Description
    A throwaway task of the test suite.

    ## Rewards
    1/(1 + |u|/`speed_scale`) every step.

    ## Task parameters
    `concentration`, `max_wind`.
    """

    action_space = gym.spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)
    action_names = ("wind_x", "wind_y")
    extra_features = ()
    task_parameters = (
        TaskParameter("concentration", 0.5, "ice concentration of the start state",
                      number(0.0, 0.85, low_open=True)),
        TaskParameter("max_wind", 5.0, "wind speed [m/s] per component at |action| = 1",
                      number(0.0, 100.0, low_open=True)),
    )
    reward_task_keys = ()
    reward_fn = staticmethod(calm_reward)
    facts = EnvFacts(summary="keep the ice at rest", main_metric="speed",
                     metrics={"u_x": "u_x", "u_y": "u_y", "speed": "speed"},
                     controllers={"heuristic": CalmController}, small={"n_floes": 30})

    def __init__(self, n_floes: int = 60, **kwargs):
        super().__init__(n_floes=n_floes, preset=HERMAN2013, control_interval=2.0, **kwargs)

    def default_reward_params(self) -> dict:
        return dict(speed_scale=0.05)

    def _make_sim(self, rng):
        field, box = self.preset.floe_field(self.n_floes, self.episode["concentration"],
                                            seed=int(rng.integers(2 ** 63)))
        self.forcing = self.preset.make_forcing(wind=(0.0, 0.0))
        return self._hertz_sim(field, box, self.forcing)

    def _apply_action(self, action):
        self.forcing.wind = self.episode["max_wind"] * action

    def _measure(self) -> dict:
        now = self._contact_physics()
        now["speed"] = math.hypot(now["u_x"], now["u_y"])
        return now


@pytest.fixture(scope="module")
def calm():
    gym.register(id=ENV_ID, entry_point=CalmEnv, max_episode_steps=8)
    try:
        yield ENV_ID
    finally:
        del gym.registry[ENV_ID]


def test_the_facts_are_found_from_the_id(calm):
    assert env_facts(calm) is CalmEnv.facts
    assert registered_ids("iceenvs-test") == (calm,)
    assert calm not in registered_ids()       # the package's own ids are apart


@pytest.mark.parametrize("check", ["api", "determinism", "fuzz", "facts"])
def test_the_shared_checks_pass(calm, check):
    from iceenvs.checks import CHECKS

    CHECKS[check](calm)


def test_the_agents_evaluate_it_against_its_heuristic(calm, tmp_path):
    pytest.importorskip("stable_baselines3")
    from agents.evaluate import main

    summaries = main(["--baseline", "heuristic", "--env", calm, "--episodes", "2",
                      "--env-kwargs", "n_floes=30", "--out", str(tmp_path), "--no-progress"])
    stats = summaries["heuristic"]
    assert stats["return"]["n"] == 2
    # 8 steps of rewards in (0, 1]
    assert 0.0 < stats["return"]["mean"] <= 8.0
    report = json.loads((tmp_path / "evaluation.json").read_text())
    assert report["main_metric"] == "speed" and "speed" in stats


def test_the_warm_up_builds_it_small(calm):
    from iceenvs.warmup import warm_env

    assert warm_env(calm, steps=3) == ""        # no fall-back to the default size


def test_an_environment_without_facts_is_named_in_the_error():
    class Bare(CalmEnv):
        facts = None

    gym.register(id="iceenvs-test/Bare-v0", entry_point=Bare)
    try:
        with pytest.raises(ValueError, match="iceenvs-test/Bare-v0 declares no facts"):
            env_facts("iceenvs-test/Bare-v0")
    finally:
        del gym.registry["iceenvs-test/Bare-v0"]
