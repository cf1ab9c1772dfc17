"""The costmap lattice's parameters searched on the reward (agents.tuned_lattice)."""
import json
import math

import gymnasium as gym
import numpy as np
import pytest

from agents import tuned_lattice
from agents.planners import CostmapLatticePlanner
from agents.policy import make_policy
from agents.rollouts import run_episode
from agents.tuned_lattice import DEFAULTS, SEARCH_SEED, SPACE, policy_of, search
from small_envs import SMALL

NAV = "iceenvs/ShipNavigation-v1"
KWARGS = {**SMALL[NAV], "length": 300.0, "goal_distance": 150.0, "costmap_ahead": 300.0}


def test_the_first_trial_is_the_costmap_lattice_as_it_is():
    """:data:`DEFAULTS` made a policy is the planner with its own settings,
    each of them, and the search's first trial."""
    env = gym.make(NAV, **KWARGS)
    metre_cost = env.unwrapped.metre_cost
    tuned = make_policy(policy_of(DEFAULTS, metre_cost), env)
    plain = CostmapLatticePlanner(env, 0)
    for name in ("metre_cost", "blur", "fade", "max_slope", "lookahead", "replan_steps",
                 "edge_margin", "stage_length", "lateral_step", "horizon"):
        assert getattr(tuned, name) == getattr(plain, name), name
    assert math.isinf(tuned.fade)
    env.close()


def test_a_trials_parameters_reach_the_planner():
    params = dict(metre_cost=2.0, blur=1.25, fade_rate=0.004, max_slope=0.3, lookahead=20.5,
                  replan_steps=3, edge_margin=6.0)
    env = gym.make(NAV, **KWARGS)
    planner = make_policy(policy_of(params, 10_000.0), env)
    assert (planner.metre_cost, planner.blur, planner.fade, planner.max_slope,
            planner.lookahead, planner.replan_steps, planner.edge_margin) == (
        20_000.0, 1.25, 250.0, 0.3, 20.5, 3, 6.0)
    env.close()
    with pytest.raises(ValueError, match="unknown parameters"):
        policy_of({"speed": 1.0}, 1.0)


def test_a_search_scores_its_trials_on_its_own_fields_and_resumes(tmp_path):
    """Trial 0 is the planner as it is; a trial's value is the mean return
    of the planner sailed on the search's fields (seeded SEARCH_SEED +
    1000 seed + k, as here by hand); a search goes on with --resume and is
    refused without it or with other settings."""
    out = tmp_path / "s2"
    settings = dict(seed=2, episodes=2, concentrations=(0.3,), env_kwargs=KWARGS, processes=1,
                    progress=False)
    record = search(out, trials=2, **settings)
    assert [t["number"] for t in record["trials"]] == [0, 1]
    assert record["trials"][0]["params"] == DEFAULTS
    fields = SEARCH_SEED + 2000
    env = gym.make(NAV, **{**KWARGS, "concentration": 0.3})
    env.reset(seed=fields)
    planner = CostmapLatticePlanner(env, fields)
    returns = [run_episode(env, planner, fields + k, None)["ret"] for k in range(2)]
    env.close()
    assert record["trials"][0]["value"] == pytest.approx(np.mean(returns), rel=1e-9)
    for trial in record["trials"]:
        for name, (low, high, _, _) in SPACE.items():
            assert low <= trial["params"][name] <= high
    with pytest.raises(FileExistsError, match="resume"):
        search(out, trials=3, **settings)
    with pytest.raises(ValueError, match="other settings"):
        search(out, trials=3, resume=True, **{**settings, "episodes": 3})
    again = search(out, trials=3, resume=True, **settings)
    assert [t["number"] for t in again["trials"]] == [0, 1, 2]
    assert again["trials"][:2] == json.loads(json.dumps(record["trials"]))
    best = max(again["trials"], key=lambda t: t["value"])
    assert again["best"]["policy"] == best["policy"]
    assert tuned_lattice.best_policy(out) == best["policy"]
    summary = tuned_lattice.report([out], tmp_path / "report")
    assert (tmp_path / "report" / "search.png").stat().st_size > 0
    assert "| s2 | 2 | 3 |" in (tmp_path / "report" / "search.md").read_text()
    assert summary["s2"]["best"]["value"] == best["value"]


@pytest.mark.parametrize("kwargs, message", [
    ({"trials": 0}, "trials must be an integer"),
    ({"episodes": 1}, "episodes must be an integer"),
    ({"processes": 0}, "processes must be an integer"),
    ({"concentrations": (1.5,)}, "concentrations must lie"),
    ({"concentrations": ()}, "concentrations must lie"),
])
def test_bad_settings_are_refused(tmp_path, kwargs, message):
    with pytest.raises(ValueError, match=message):
        search(tmp_path / "x", **{"progress": False, **kwargs})
    assert not (tmp_path / "x").exists()


def test_a_missing_search_is_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="no search"):
        tuned_lattice.best_policy(tmp_path)


def _rewards(concentration, policy_of_env, seed=7):
    env = gym.make(NAV, **{**KWARGS, "concentration": concentration})
    rewards = run_episode(env, policy_of_env(env), seed, None)["rewards"]
    env.close()
    return np.asarray(rewards)


def test_by_concentration_sails_each_episode_with_the_settings_of_its_range():
    """Below the bound the first settings' planner sails the episode step
    for step, at or above it the second's; the two differ, so the choice
    is seen."""
    low, high = {"metre_cost": 500.0, "replan_steps": 3}, {"metre_cost": 50_000.0}
    reference = ("agents.tuned_lattice:ByConcentration?bounds=[0.35]"
                 "&settings=[{metre_cost: 500.0, replan_steps: 3}, {metre_cost: 50000.0}]")
    for a, own, other in ((0.3, low, high), (0.4, high, low)):
        joined = _rewards(a, lambda env: make_policy(reference, env))
        mine = _rewards(a, lambda env, s=own: CostmapLatticePlanner(env, 0, **s))
        theirs = _rewards(a, lambda env, s=other: CostmapLatticePlanner(env, 0, **s))
        np.testing.assert_array_equal(joined, mine)
        assert not np.array_equal(joined, theirs)


@pytest.mark.parametrize("kwargs, message", [
    ({"bounds": [0.5, 0.3], "settings": [{}, {}, {}]}, "bounds must increase"),
    ({"bounds": [1.2], "settings": [{}, {}]}, "bounds must increase"),
    ({"bounds": "0.4", "settings": [{}, {}]}, "bounds must be a list"),
    ({"bounds": [0.4], "settings": [{}]}, "settings must be 2 mappings"),
    ({"bounds": [0.4], "settings": [{}, 3]}, "settings must be 2 mappings"),
])
def test_by_concentration_refuses_bad_ranges(kwargs, message):
    env = gym.make(NAV, **KWARGS)
    with pytest.raises(ValueError, match=message):
        tuned_lattice.ByConcentration(env, 0, **kwargs)
    env.close()


def test_the_joined_policy_of_two_searches(tmp_path):
    for name, cost in (("low", 100), ("high", 200)):
        (tmp_path / name).mkdir()
        (tmp_path / name / "search.json").write_text(json.dumps({"best": {
            "policy": f"agents.planners:CostmapLatticePlanner?metre_cost={cost}&blur=1.5"}}))
    policy = tuned_lattice.by_concentration_policy([0.45], [tmp_path / "low", tmp_path / "high"])
    env = gym.make(NAV, **KWARGS)
    planner = make_policy(policy, env)
    assert planner.bounds == [0.45]
    assert [(p.metre_cost, p.blur) for p in planner.planners] == [(100.0, 1.5), (200.0, 1.5)]
    env.close()
    with pytest.raises(ValueError, match="1 bounds take 2 searches"):
        tuned_lattice.by_concentration_policy([0.45], [tmp_path / "low"])
