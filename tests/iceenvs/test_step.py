"""The batch of episodes (iceenvs.step.Episodes): it owns every episode's
state, a single environment is a batch of one, and bad use gets clear
errors. ThicknessDistribution-v0 keeps these tests free of engine compiles."""
import gymnasium as gym
import numpy as np
import pytest

import iceenvs  # noqa: F401  (registers the ids)
from iceenvs.step import ROW_STATE, Episodes
from small_envs import SMALL

ITD = "iceenvs/ThicknessDistribution-v0"


def make_vec(n):
    return gym.make_vec(ITD, num_envs=n, vectorization_mode="vector_entry_point", **SMALL[ITD])


def test_the_batch_holds_each_episodes_state_and_the_environments_read_their_row():
    envs = make_vec(3)
    envs.reset(seed=0)
    batch = envs.unwrapped.episodes
    actions = np.random.default_rng(1).uniform(-1, 1, (3, 2))
    obs, _, _, _, info = envs.step(actions)
    np.testing.assert_array_equal(batch.steps, [1, 1, 1])
    np.testing.assert_array_equal(info["steps"], batch.steps)
    np.testing.assert_allclose(batch.last_action, np.clip(actions, -1, 1))
    for k, env in enumerate(envs.unwrapped.envs):
        assert env.episodes is batch and env.row == k
        assert env.last_measurement is batch.prev[k]
        np.testing.assert_array_equal(obs[k], batch.obs[k])
        assert set(batch.row_state(k)) == set(ROW_STATE)
    assert not batch.failed.any() and not batch.ended.any()
    envs.close()


def test_a_single_environment_is_a_batch_of_one():
    env = gym.make(ITD, **SMALL[ITD]).unwrapped
    assert env.episodes.single and env.episodes.num_envs == 1 and env.row == 0
    env.reset(seed=0)
    env.step(np.zeros(2))
    env.step(np.zeros(2))
    assert env.episodes.steps[0] == 2 and env._steps == 2


def test_a_sub_environment_steps_only_with_its_vector_environment():
    envs = make_vec(2)
    envs.reset(seed=0)
    with pytest.raises(RuntimeError, match="step the vector environment"):
        envs.unwrapped.envs[0].step(np.zeros(2))
    envs.close()


def test_bad_batches_are_refused():
    env = gym.make(ITD, **SMALL[ITD]).unwrapped
    with pytest.raises(ValueError, match="at least one environment"):
        Episodes([])
    with pytest.raises(ValueError, match="holds one environment, not 2"):
        Episodes([env, gym.make(ITD, **SMALL[ITD]).unwrapped], single=True)
