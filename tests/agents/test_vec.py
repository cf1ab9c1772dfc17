"""A Gymnasium vector environment seen through agents.vec.GymnasiumVecEnv
gives SB3 what DummyVecEnv gives for the same sub-environments, step for
step, across episode ends."""
import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from gymnasium.vector import AutoresetMode, SyncVectorEnv
from stable_baselines3.common.vec_env import DummyVecEnv

import iceenvs  # noqa: F401  (registers the ids)
from agents.vec import GymnasiumVecEnv, unbatch_info
from small_envs import SMALL

ITD = "iceenvs/ThicknessDistribution-v0"
CONVERGENCE = "iceenvs/Convergence-v0"
SHIP = "iceenvs/ShipNavigation-v0"


def _assert_same(a: dict, b: dict):
    # the same code on the same seeds (a native vector environment runs the
    # single environment's arithmetic in the same order): the tolerance only
    # absorbs a compiler's freedom between two compiled call sites
    assert a.keys() == b.keys()
    for key in a:
        np.testing.assert_allclose(a[key], b[key], rtol=1e-12, atol=1e-12, err_msg=key)


def _factories(env_id, n):
    kwargs = {**SMALL[env_id], "max_episode_steps": 3}
    return [lambda: gym.make(env_id, **kwargs) for _ in range(n)]


def _vector(how, env_id, n):
    """A Gymnasium vector environment of ``n`` small ``env_id`` with episodes
    of 3 steps: Gymnasium's SyncVectorEnv or the environment's native one."""
    if how == "native":
        return gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point",
                            max_episode_steps=3, **SMALL[env_id])
    return SyncVectorEnv(_factories(env_id, n), autoreset_mode=AutoresetMode.SAME_STEP)


@pytest.mark.parametrize("how, env_id", [("sync", ITD), ("sync", CONVERGENCE), ("native", SHIP)])
def test_steps_match_dummy_vec_env_across_episode_ends(how, env_id):
    n, steps = 2, 8
    ours = GymnasiumVecEnv(_vector(how, env_id, n))
    theirs = DummyVecEnv(_factories(env_id, n))
    rng = np.random.default_rng(7)
    space = theirs.action_space
    actions = rng.uniform(space.low, space.high, (steps, n) + space.shape).astype(space.dtype)
    try:
        ours.seed(11)
        theirs.seed(11)
        # the same code on the same seeds: exactly the same numbers
        _assert_same({"obs": ours.reset()}, {"obs": theirs.reset()})
        ends = 0
        for a in actions:
            o1, r1, d1, i1 = ours.step(a)
            o2, r2, d2, i2 = theirs.step(a)
            _assert_same({"obs": o1, "reward": r1}, {"obs": o2, "reward": r2})
            np.testing.assert_array_equal(d1, d2)
            for k in range(n):
                _assert_same(i1[k]["physics"], i2[k]["physics"])
                if d2[k]:
                    ends += 1
                    _assert_same({"last": i1[k]["terminal_observation"]},
                                 {"last": i2[k]["terminal_observation"]})
                    assert i1[k]["TimeLimit.truncated"] == i2[k]["TimeLimit.truncated"]
            assert ours.reset_infos[0].keys() == theirs.reset_infos[0].keys()
        assert ends == 2 * n          # episodes of 3 steps end at steps 3 and 6
    finally:
        ours.close()
        theirs.close()


@pytest.mark.parametrize("how, env_id", [("sync", ITD), ("native", SHIP)])
def test_ppo_trains_on_it(how, env_id):
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_checker import check_env
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    venv = GymnasiumVecEnv(_vector(how, env_id, 2))
    # SB3's own checks of the environment the sub-environments are (spaces, reset
    # and step values); a native vector environment's sub-environments step
    # only together
    check_env(gym.make(env_id, **SMALL[env_id]).unwrapped, warn=False)
    venv.seed(0)
    env = VecNormalize(VecMonitor(venv))
    model = PPO("MlpPolicy", env, n_steps=8, batch_size=8, n_epochs=1, seed=0, device="cpu")
    model.learn(32)
    assert model.num_timesteps == 32
    assert env.get_attr("render_mode") == [None, None]
    env.close()


def test_another_autoreset_mode_is_refused_with_its_name():
    venv = SyncVectorEnv(_factories(ITD, 1), autoreset_mode=AutoresetMode.NEXT_STEP)
    with pytest.raises(ValueError, match="SAME_STEP.*NEXT_STEP"):
        GymnasiumVecEnv(venv)
    venv.close()


def test_unbatch_info_keeps_only_the_entries_each_environment_set():
    info = {"a": np.array([1.0, 2.0]), "_a": np.array([True, False]),
            "nested": {"b": np.array([3, 4]), "_b": np.array([False, True])},
            "_nested": np.array([True, True])}
    assert unbatch_info(info, 2) == [{"a": 1.0, "nested": {}}, {"nested": {"b": 4}}]


def _sync_itd(num_envs, **kwargs):
    """A vector entry point: the thickness environment in a SyncVectorEnv
    that resets in the step that ends an episode."""
    return SyncVectorEnv([lambda: gym.make(ITD, **kwargs) for _ in range(num_envs)],
                         autoreset_mode=AutoresetMode.SAME_STEP)


@pytest.fixture
def vectorised_id():
    env_id = "vectest/Thickness-v0"
    gym.register(id=env_id, entry_point="iceenvs.thickness_distribution:ThicknessDistributionEnv",
                 vector_entry_point=_sync_itd)
    try:
        yield env_id
    finally:
        del gym.registry[env_id]


def test_make_vec_env_takes_the_native_vector_env_where_there_is_one(vectorised_id):
    from agents.envs import make_vec_env

    for how in ("auto", "native"):
        env = make_vec_env(vectorised_id, n_envs=2, seed=3, env_kwargs=SMALL[ITD],
                           vectorization=how)
        assert isinstance(env.unwrapped, GymnasiumVecEnv), how
        assert env.reset().shape == (2,) + env.observation_space.shape
        env.close()
    for n, how in ((2, "dummy"), (1, "auto")):     # auto steps one environment alone
        env = make_vec_env(vectorised_id, n_envs=n, seed=3, env_kwargs=SMALL[ITD],
                           vectorization=how)
        assert not isinstance(env.unwrapped, GymnasiumVecEnv), (n, how)
        env.close()


def test_native_is_refused_without_a_vector_entry_point():
    from agents.envs import make_vec_env

    env_id = "tests/NoVectorITD-v0"
    gym.register(id=env_id, entry_point="iceenvs.thickness_distribution:ThicknessDistributionEnv")
    try:
        with pytest.raises(ValueError, match="no native vector environment"):
            make_vec_env(env_id, n_envs=2, seed=0, env_kwargs=SMALL[ITD],
                         vectorization="native")
    finally:
        del gym.registry[env_id]
    with pytest.raises(ValueError, match="unknown vectorization 'threads'"):
        make_vec_env(ITD, n_envs=2, seed=0, vectorization="threads")
