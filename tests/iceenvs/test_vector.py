"""The native vector environments (iceenvs.vector): sub-environment k runs the
episode of the single environment seeded the same way, episodes end and
reset in the same step (AutoresetMode.SAME_STEP) with Gymnasium's info
masks, task parameters and options reach each sub-environment, and bad input
gets the single environment's clear errors."""
import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import iceenvs  # noqa: F401  (registers the ids)
from iceenvs import ENV_IDS
from iceenvs.facts import env_facts, env_spec
from small_envs import SMALL

VECTOR_IDS = [i for i in ENV_IDS if env_spec(i).vector_entry_point is not None]
SHIP = "iceenvs/ShipNavigation-v0"
# the sub-environments' engines do the arithmetic of the single environment in
# the same order (the same compiled step, called per engine); this bound only
# absorbs a compiler's freedom between the two call sites
RTOL, ATOL = 1e-12, 1e-12


def make_vec(env_id, n, **kwargs):
    return gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point",
                        **{**SMALL[env_id], **kwargs})


def test_every_environment_has_a_native_vector_env():
    assert VECTOR_IDS == list(ENV_IDS)
    envs = make_vec(SHIP, 2)
    assert envs.metadata["autoreset_mode"] == AutoresetMode.SAME_STEP
    envs.close()


@pytest.mark.parametrize("env_id", VECTOR_IDS)
def test_sub_environment_k_runs_the_single_environment_seeded_the_same(env_id):
    n, steps, seed = 2, 5, 3
    envs = make_vec(env_id, n, max_episode_steps=3)
    singles = [gym.make(env_id, **SMALL[env_id], max_episode_steps=3) for _ in range(n)]
    obs, _ = envs.reset(seed=seed)
    for k, env in enumerate(singles):
        np.testing.assert_allclose(obs[k], env.reset(seed=seed + k)[0], rtol=RTOL, atol=ATOL)
    actions = np.random.default_rng(5).uniform(-1, 1, (steps, n) + envs.single_action_space.shape)
    ends = 0
    for a in actions:
        obs, reward, terminated, truncated, info = envs.step(a)
        for k, env in enumerate(singles):
            o, r, te, tr, inf = env.step(a[k])
            assert (terminated[k], truncated[k]) == (te, tr)
            np.testing.assert_allclose(reward[k], r, rtol=RTOL, atol=ATOL)
            if te or tr:
                ends += 1
                assert info["_final_obs"][k] and info["_final_info"][k]
                np.testing.assert_allclose(info["final_obs"][k], o, rtol=RTOL, atol=ATOL)
                o = env.reset()[0]
            else:
                assert not info.get("_final_obs", np.zeros(n, bool))[k]
            np.testing.assert_allclose(obs[k], o, rtol=RTOL, atol=ATOL)
            # the step's info; for an ended episode it is the final one, and
            # the info of the reset is in its place
            step_info = info["final_info"] if te or tr else info
            assert step_info["_physics"][k]
            for key, value in inf["physics"].items():
                np.testing.assert_allclose(step_info["physics"][key][k], value, rtol=RTOL,
                                           atol=ATOL, err_msg=key)
            # the episode metrics, of the same types
            for key in env_facts(env_id).episode_metrics:
                assert type(step_info[key][k].item()) is type(inf[key]), key
                np.testing.assert_allclose(step_info[key][k], inf[key], rtol=RTOL, atol=ATOL,
                                           err_msg=key)
    # every sub-environment was truncated after 3 steps and reset
    assert ends == n
    envs.close()


@pytest.mark.parametrize("env_id", VECTOR_IDS)
def test_a_vector_environment_of_one_gives_a_vector_info(env_id):
    """N = 1 is a vector environment like any other: its step's info is a
    vector info (columns with their masks), an ended episode included, as
    the single environment's info is its own dict."""
    envs = make_vec(env_id, 1, max_episode_steps=2)
    single = gym.make(env_id, **SMALL[env_id], max_episode_steps=2)
    envs.reset(seed=4)
    single.reset(seed=4)
    action = np.zeros((1,) + envs.single_action_space.shape, dtype=envs.single_action_space.dtype)
    for _ in range(2):
        _, _, terminated, truncated, info = envs.step(action)
        _, _, _, _, inf = single.step(action[0])
    assert truncated.all() and not terminated.any()
    final = info["final_info"]
    assert info["_final_info"][0] and final["_physics"][0]
    assert final["nonfinite_action"].shape == (1,) and final["_nonfinite_action"][0]
    for key, value in inf["physics"].items():
        np.testing.assert_allclose(final["physics"][key][0], value, rtol=RTOL, atol=ATOL,
                                   err_msg=key)
    envs.close()


def test_an_episode_that_reaches_its_goal_ends_and_resets_in_the_same_step():
    envs = make_vec(SHIP, 2, goal_distance=5.0)
    envs.reset(seed=0)
    _, _, terminated, truncated, info = envs.step(np.zeros((2, 1)))
    # 2 s at the default 2.5 m/s does not reach a line 5 m ahead
    assert not terminated.any() and "final_obs" not in info
    for _ in range(3):
        _, _, terminated, truncated, info = envs.step(np.zeros((2, 1)))
        if terminated.any():
            break
    assert terminated.all() and not truncated.any()
    assert info["final_info"]["success"].all()
    # the first observation of the new episodes: the step counter starts again
    assert (info["steps"] == 0).all()
    envs.close()


def test_task_parameters_as_keywords_and_per_sub_environment_options():
    envs = make_vec(SHIP, 2, concentration=0.25)
    _, info = envs.reset(seed=1)
    assert (info["task"]["concentration"] == 0.25).all()
    _, info = envs.reset(seed=1, options=[{"concentration": 0.2}, {"concentration": 0.35}])
    np.testing.assert_array_equal(info["task"]["concentration"], [0.2, 0.35])
    single = gym.make(SHIP, **{**SMALL[SHIP], "concentration": 0.25})
    single_obs, _ = single.reset(seed=2, options={"concentration": 0.35})
    obs, _ = envs.reset(seed=[None, 2], options={"concentration": 0.35})
    np.testing.assert_allclose(obs[1], single_obs, rtol=RTOL, atol=ATOL)
    envs.close()


def test_bad_input_gets_clear_errors():
    with pytest.raises(ValueError, match="num_envs must be an integer >= 1, got 0"):
        make_vec(SHIP, 0)
    with pytest.raises(ValueError, match="render_env must be the index of a sub-environment"):
        make_vec(SHIP, 2, render_env=2)
    with pytest.raises(TypeError, match="unknown arguments \\['bogus'\\]"):
        make_vec(SHIP, 2, bogus=1)
    with pytest.raises(ValueError, match="concentration"):
        make_vec(SHIP, 2, concentration=1.5)
    envs = make_vec(SHIP, 2)
    with pytest.raises(RuntimeError, match="call reset\\(\\) before step\\(\\)"):
        envs.step(np.zeros((2, 1)))
    envs.reset(seed=0)
    with pytest.raises(ValueError, match="actions of shape \\(3, 1\\); .* shape \\(2, 1\\)"):
        envs.step(np.zeros((3, 1)))
    with pytest.raises(ValueError, match="one entry per sub-environment"):
        envs.reset(seed=[1, 2, 3])
    with pytest.raises(ValueError, match="unknown reset options \\['bogus'\\]"):
        envs.reset(options={"bogus": 1})
    # a NaN action is a zero command, as in the single environment
    _, _, _, _, info = envs.step(np.array([[np.nan], [0.0]]))
    np.testing.assert_array_equal(info["nonfinite_action"], [1, 0])
    envs.close()


def test_render_draws_the_chosen_sub_environment():
    envs = make_vec(SHIP, 2, render_mode="rgb_array", render_env=1)
    single = gym.make(SHIP, **SMALL[SHIP], render_mode="rgb_array")
    envs.reset(seed=4)
    single.reset(seed=5)
    envs.step(np.zeros((2, 1)))
    single.step(np.zeros(1))
    frame = envs.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3
    # the same picture as the single environment seeded like sub-environment 1
    assert np.mean(frame != single.render()) < 1e-3
    envs.close()


def test_batched_infos_are_what_gymnasium_builds_one_by_one():
    from gymnasium.vector import SyncVectorEnv

    from iceenvs.vector import batch_infos

    def same(a, b):
        assert a.keys() == b.keys()
        for key in a:
            if isinstance(a[key], dict):
                same(a[key], b[key])
            else:
                assert a[key].dtype == b[key].dtype, key
                np.testing.assert_array_equal(a[key], b[key], err_msg=key)

    infos = [{"a": 1.5, "n": 2, "ok": True, "task": {"range": (0.2, 0.6), "x": 0.3},
              "v": np.arange(3.0), "error": "boom"},
             {"a": 2.5, "n": 3, "ok": False, "task": {"x": 0.4}, "v": np.ones(3)},
             {"a": 0.5, "other": "s", "task": {"range": (0.1, 0.2)}, "v": np.zeros(3)}]
    # keys that every info has: numbers of mixed types, arrays, strings
    for k, (num, flag) in enumerate(((2, 1.0), (2.7, True), (np.float32(0.5), 0))):
        infos[k].update(i=num, b=flag, m=np.full((2, 2), k, dtype=np.int32), s=str(k))
    # infos with the same keys: numbers of mixed types, arrays, strings, a
    # nested dict that two of them lack a key of
    alike = [{"i": num, "b": flag, "m": np.full((2, 2), k, dtype=np.int32),
              "s": str(k), "d": {"x": k} if k else {"x": 0, "y": 1.0}}
             for k, (num, flag) in enumerate(((2, 1.0), (2.7, True), (np.float32(0.5), 0)))]
    sync = SyncVectorEnv([lambda: gym.make("CartPole-v1")] * 3)
    for case in (infos, alike):
        expected: dict = {}
        for k, info in enumerate(case):
            expected = sync._add_info(expected, info, k)
        same(batch_infos(case), expected)
    sync.close()


def test_batched_infos_of_arrays_of_two_shapes_fail_as_gymnasiums():
    from gymnasium.vector import SyncVectorEnv

    from iceenvs.vector import batch_infos

    infos = [{"w": np.zeros(k + 1)} for k in range(3)]
    sync = SyncVectorEnv([lambda: gym.make("CartPole-v1")] * 3)
    expected: dict = {}
    with pytest.raises(ValueError):
        for k, info in enumerate(infos):
            expected = sync._add_info(expected, info, k)
    sync.close()
    with pytest.raises(ValueError):
        batch_infos(infos)




def _ship_reward(prev, action, now, **params):
    """A reward of one's own: the native vector environment calls it per
    sub-environment, with that sub-environment's measurement."""
    return float(now["surge"] - 1e-7 * now["step_impulse"])


@pytest.mark.parametrize("kwargs", [{"obs_type": "dict"}, {"reward_fn": _ship_reward},
                                    {"free_drift": False}],
                         ids=["image observations", "own reward", "exact step"])
def test_the_ship_paths_run_per_sub_environment_give_the_single_environment(kwargs):
    n = 2
    envs = make_vec(SHIP, n, **kwargs)
    singles = [gym.make(SHIP, **SMALL[SHIP], **kwargs) for _ in range(n)]
    obs, _ = envs.reset(seed=7)
    for k, env in enumerate(singles):
        env.reset(seed=7 + k)
    for a in np.random.default_rng(2).uniform(-1, 1, (3, n, 1)):
        obs, reward, _, _, _ = envs.step(a)
        for k, env in enumerate(singles):
            o, r, _, _, _ = env.step(a[k])
            np.testing.assert_allclose(reward[k], r, rtol=RTOL, atol=ATOL)
            for key in ("vector", "image") if isinstance(o, dict) else ():
                np.testing.assert_allclose(obs[key][k], o[key], rtol=RTOL, atol=ATOL)
    # the default is the fast step, which the other cases run; free_drift=False the exact one
    fast = kwargs.get("free_drift", True)
    assert all(e.sim.free_drift is fast and bool(e.sim.free_tally[3] > 0) is fast
               for e in envs.unwrapped.envs)
    envs.close()


def test_a_sub_environment_that_fails_ends_alone_and_the_others_run_on():
    """A physics failure of one sub-environment ends its episode with the
    failure reward and ``info["error"]``, as in the single environment; the
    others are measured in batch as if it were not there."""
    n = 3
    envs = make_vec(SHIP, n)
    single = gym.make(SHIP, **SMALL[SHIP])
    envs.reset(seed=11)
    single.reset(seed=11 + 2)
    broken = envs.unwrapped.envs[1]
    apply = broken.apply_action

    def fail(action):                  # once: the new episode's start applies an action too
        broken.apply_action = apply
        raise FloatingPointError("overflow in a test")

    broken.apply_action = fail
    actions = np.array([[0.3], [0.0], [-0.2]])
    obs, reward, terminated, _, info = envs.step(actions)
    o, r, te, _, inf = single.step(actions[2])
    assert terminated[1] and reward[1] == -broken.reward_params["failure_penalty"]
    assert info["final_info"]["_error"][1] and "overflow in a test" in info["final_info"]["error"][1]
    assert not info["final_info"]["_error"][[0, 2]].any()
    assert info["_final_info"].tolist() == [False, True, False]
    # sub-environment 2 is the single environment seeded alike
    assert te == terminated[2]
    np.testing.assert_allclose(obs[2], o, rtol=RTOL, atol=ATOL)
    np.testing.assert_allclose(reward[2], r, rtol=RTOL, atol=ATOL)
    np.testing.assert_allclose(info["impulse_per_metre"][2], inf["impulse_per_metre"], rtol=RTOL,
                               atol=ATOL)
    # the failed one started a new episode: its info is the new episode's first
    assert info["steps"][1] == 0 and info["_nonfinite_action"].tolist() == [True, False, True]
    envs.close()
