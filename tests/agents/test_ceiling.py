"""The rate-limited ceiling of Convergence-v0 (agents.ceiling): its values, and
that no policy passes it."""
import gymnasium as gym
import numpy as np
import pytest

import iceenvs  # noqa: F401
from agents.baselines import make_baseline
from agents.ceiling import analyse, main, rate_limited_ceiling, step_change


def test_ceiling_values():
    # at the target from the start: every step can earn 1
    np.testing.assert_array_equal(rate_limited_ceiling(0.8, 0.8, steps=5, step_change=0.01,
                                                       scale=0.1), np.ones(5))
    # 0.05 away, 0.01 a step: 0.04 left after step 1 (reward 0.6), none after step 5
    c = rate_limited_ceiling(0.75, 0.80, steps=6, step_change=0.01, scale=0.1)
    np.testing.assert_allclose(c, [0.6, 0.7, 0.8, 0.9, 1.0, 1.0], rtol=0, atol=1e-12)
    # the direction does not matter, and a gap beyond the scale earns 0 until it closes
    np.testing.assert_allclose(rate_limited_ceiling(0.9, 0.7, steps=3, step_change=0.05,
                                                     scale=0.1), [0.0, 0.0, 0.5], atol=1e-12)
    with pytest.raises(ValueError, match="scale"):
        rate_limited_ceiling(0.7, 0.8, steps=3, step_change=0.01, scale=0.0)


@pytest.mark.parametrize("policy", ["heuristic", "random", "full"])
def test_no_policy_passes_the_ceiling(policy):
    """The bound is a theorem of the task: the concentration moves at most
    max_rate × the seconds of a step, and the pressure factor is at most 1.
    (The step is the control interval rounded to whole time steps: 1.99925 s
    with 60 floes, 2.00067 s with the default 200, so the nominal 2 s would
    not bound the default's change.)"""
    for seed, task in ((3, {}), (4, dict(concentration=0.72, target=0.76))):
        env = gym.make("iceenvs/Convergence-v0", n_floes=60, max_episode_steps=40, **task)
        u = env.unwrapped
        obs, info = env.reset(seed=seed)
        chooser = (make_baseline(policy, env, seed=seed) if policy != "full" else None)
        if chooser is not None:
            chooser.reset(seed)
        ceiling = rate_limited_ceiling(u.episode["concentration"], u.episode["target"],
                                       steps=40, step_change=step_change(env),
                                       scale=u.reward_params["concentration_scale"])
        rewards = []
        while True:
            action = (np.sign(u.episode["target"] - u.episode["concentration"]) * np.ones(1)
                      if chooser is None else chooser.predict(obs, deterministic=True)[0])
            obs, r, terminated, truncated, _ = env.step(action)
            rewards.append(r)
            if terminated or truncated:
                break
        assert np.all(np.array(rewards) <= ceiling[:len(rewards)] + 1e-9)
        if policy == "full":
            # full rate towards the target earns the ceiling while it approaches
            # (no pressure at these concentrations): the bound is tight. 1e-9
            # covers the float sums of the box area over the steps
            approach = ceiling[:len(rewards)] < 1.0
            assert approach.sum() >= (30 if task else 1)
            np.testing.assert_allclose(np.array(rewards)[approach], ceiling[approach],
                                       rtol=0, atol=1e-9)
        env.close()


def test_refuses_the_benchmark_episodes(tmp_path):
    with pytest.raises(ValueError, match="benchmark"):
        analyse(episodes=5, seed=39998, progress=False, root=tmp_path)
    with pytest.raises(SystemExit):
        main(["--episodes", "1", "--out", str(tmp_path), "--no-progress"])
