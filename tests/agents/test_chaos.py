"""A policy against its perturbed twin (agents.chaos): the twin's actions stay
within a few epsilon of the policy's, repeat for a seed, and the command
refuses the benchmark's episodes."""
import gymnasium as gym
import numpy as np
import pytest

import iceenvs  # noqa: F401
from agents.baselines import make_baseline
from agents.chaos import Twin, main, resolvable, twins


def test_the_twin_acts_as_its_policy_within_epsilon():
    env = gym.make("iceenvs/Convergence-v0", n_floes=60)
    obs, _ = env.reset(seed=2)
    inner = make_baseline("heuristic", env, seed=2)
    twin = Twin(env, seed=2, inner="heuristic", epsilon=1e-6)
    twin.reset(11)
    first = [twin.predict(obs)[0] for _ in range(50)]
    twin.reset(11)
    again = [twin.predict(obs)[0] for _ in range(50)]
    np.testing.assert_array_equal(first, again)          # seeded per episode
    exact = inner.predict(obs, deterministic=True)[0]
    moved = np.abs(np.array(first, dtype=float) - exact)
    # a normal draw passes 6 sigma once in 5e8; float32 actions add 6e-8
    assert moved.max() < 6e-6 + 1e-7
    assert moved.max() > 0                               # it does perturb
    with pytest.raises(ValueError, match="epsilon"):
        Twin(env, epsilon=0.0)
    env.close()


def test_twins_on_a_smooth_task_and_bad_input(tmp_path):
    record = twins("iceenvs/Convergence-v0", episodes=2, progress=False)
    assert set(record["differences"]) == {"twin", "zero"}
    assert record["twin_std"] >= 0 and resolvable(record, 40) >= 0
    with pytest.raises(ValueError, match="benchmark"):
        twins("iceenvs/Convergence-v0", episodes=3, seed=39999, progress=False)
    with pytest.raises(SystemExit):
        main(["--env", "iceenvs/NoSuch-v0", "--out", str(tmp_path), "--no-progress"])
