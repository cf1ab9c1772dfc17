"""Tests of ``iceenvs/ThicknessDistribution-v0`` (ThicknessDistributionEnv)."""
import math
import warnings

import numpy as np
import pytest

from iceenvs.rewards import thickness_distribution_reward, wasserstein1
from iceenvs.thickness_distribution import (RAFT_MAX, ThicknessDistributionEnv,
                                            default_target)
from physics.params import GODLOVITCH

N_OBS = 26


@pytest.fixture
def env():
    e = ThicknessDistributionEnv()
    yield e
    e.close()


def _rollout(env, seed, actions):
    obs, _ = env.reset(seed=seed)
    observations, rewards = [obs], []
    for a in actions:
        obs, r, terminated, truncated, _ = env.step(a)
        assert not terminated
        observations.append(obs)
        rewards.append(r)
    return np.array(observations), np.array(rewards)


# -- API checkers ------------------------------------------------------------------------

def test_gymnasium_env_checker(env):
    from gymnasium.utils.env_checker import check_env

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env)
    # the checker's warnings are failures too, except the one about the
    # missing spec of an env built without gymnasium.make
    messages = [str(w.message) for w in caught if "not having a spec" not in str(w.message)]
    assert messages == []


def test_stable_baselines3_env_checker(env):
    sb3_checker = pytest.importorskip("stable_baselines3.common.env_checker")
    sb3_checker.check_env(env, warn=True)


def test_spaces_and_defaults(env):
    assert env.action_space.shape == (2,) and env.action_space.dtype == np.float32
    assert np.all(env.action_space.low == -1) and np.all(env.action_space.high == 1)
    space = env.observation_space
    assert space.shape == (N_OBS,) and space.dtype == np.float32
    assert np.all(space.low[:21] == 0) and np.all(space.high[:21] == 1)
    assert np.all(space.low[21:23] == -1) and np.all(space.high[21:23] == 1)
    assert space.low[23] == 0 and space.high[23] == 2
    assert np.all(space.low[24:] == -1) and np.all(space.high[24:] == 1)
    # constant kernel with the calibrated rate r0 of the Godlovitch figures
    assert env.kernel == "constant" and env.kernel_params == {"r": GODLOVITCH.r0}
    assert np.all(env._K == GODLOVITCH.r0)
    import gymnasium as gym

    import iceenvs  # noqa: F401
    assert gym.spec("iceenvs/ThicknessDistribution-v0").max_episode_steps == 360
    assert RAFT_MAX == 2 * GODLOVITCH.raft_factor


# -- determinism -------------------------------------------------------------------------

def test_same_seed_same_actions_identical_trajectory(env):
    rng = np.random.default_rng(12)
    actions = rng.uniform(-1, 1, size=(10, 2)).astype(np.float32)
    obs1, rew1 = _rollout(env, 7, actions)
    obs2, rew2 = _rollout(env, 7, actions)
    assert np.array_equal(obs1, obs2)
    assert np.array_equal(rew1, rew2)
    # a second env instance gives the same bits
    other = ThicknessDistributionEnv()
    obs3, rew3 = _rollout(other, 7, actions)
    assert np.array_equal(obs1, obs3) and np.array_equal(rew1, rew3)
    # another seed starts from another perturbation of the target
    obs4, rew4 = _rollout(env, 8, actions)
    assert not np.array_equal(obs1[0], obs4[0])
    assert not np.array_equal(rew1, rew4)


def test_reset_without_seed_continues_the_generator(env):
    g1 = env.reset(seed=3)[1]["physics"]["g"]
    g2 = env.reset()[1]["physics"]["g"]
    assert not np.array_equal(g1, g2)


# -- actions -----------------------------------------------------------------------------

@pytest.mark.parametrize("action", [
    [np.nan, 0.0], [np.inf, -np.inf], [-np.inf, np.nan], [1e9, -1e9], [5, -5],
    np.array([np.nan, np.nan], dtype=np.float32), (0.3, 2.0),
])
def test_bad_actions_are_sanitised(env, action):
    env.reset(seed=0)
    for _ in range(3):
        obs, reward, terminated, truncated, info = env.step(action)
        assert "error" not in info
        assert not terminated
        assert np.all(np.isfinite(obs)) and math.isfinite(reward)
        assert env.observation_space.contains(obs)
        last = obs[24:]
        assert np.all(np.isfinite(last)) and np.all(np.abs(last) <= 1.0)
    a = np.array(action, dtype=float)
    expected = np.clip(np.nan_to_num(a, nan=0.0, posinf=1.0, neginf=-1.0), -1, 1)
    np.testing.assert_allclose(obs[24:], expected, rtol=1e-6)
    assert info["nonfinite_action"] == int(np.sum(~np.isfinite(a)))


def test_action_mapping(env):
    env.reset(seed=0)
    cases = [((-1, -1), 0.1, 1.0), ((0, 0), 1.0, 1 + (RAFT_MAX - 1) / 2),
             ((1, 1), 10.0, RAFT_MAX), ((0.5, -0.5), 10 ** 0.5, 1 + (RAFT_MAX - 1) / 4)]
    for action, scale, factor in cases:
        p = env.step(np.array(action, dtype=np.float32))[4]["physics"]
        assert p["kernel_scale"] == pytest.approx(scale, rel=1e-6)
        assert p["rafting_factor"] == pytest.approx(factor, rel=1e-6)
        assert env.model.h_raft == 0.5


def test_observations_stay_in_space_over_random_episode(env):
    rng = np.random.default_rng(1)
    obs, _ = env.reset(seed=1)
    assert env.observation_space.contains(obs)
    for _ in range(360):                 # one year
        obs, reward, terminated, truncated, info = env.step(rng.uniform(-1.5, 1.5, 2))
        assert not terminated
        assert env.observation_space.contains(obs) and np.all(np.isfinite(obs))
        assert 0.0 <= reward <= 1.0


# -- observation layout -------------------------------------------------------------------

def test_observation_layout(env):
    env.reset(seed=2)
    obs, _, _, _, info = env.step([0.2, -0.4])
    p = info["physics"]
    g, h = p["g"], p["h"]
    assert g.shape == h.shape == (201,)
    assert h[0] == 0 and h[-1] == pytest.approx(20.0)
    # coarse classes: open water, 19 of 0.5 m from 0 to 9.5 m, and h >= 9.5 m
    expected = [g[0]]
    for j in range(19):
        expected.append(g[1:][(h[1:] >= 0.5 * j - 1e-9) & (h[1:] < 0.5 * (j + 1) - 1e-9)].sum())
    expected.append(g[1:][h[1:] >= 9.5 - 1e-9].sum())
    np.testing.assert_allclose(obs[:21], expected, rtol=1e-6, atol=1e-9)
    assert obs[:21].sum() == pytest.approx(1.0, abs=1e-5)
    assert obs[1] == pytest.approx(g[1:5].sum(), rel=1e-6)      # 0.1 … 0.4 m
    assert obs[2] == pytest.approx(g[5:10].sum(), rel=1e-6)     # 0.5 … 0.9 m
    # season phase of the model day
    assert p["day"] == pytest.approx(1.0)
    assert obs[21] == pytest.approx(math.cos(2 * math.pi * 1 / 360), rel=1e-6)
    assert obs[22] == pytest.approx(math.sin(2 * math.pi * 1 / 360), rel=1e-6)
    assert obs[23] == pytest.approx(p["mean_thickness"] / 10.0, rel=1e-6)
    assert p["mean_thickness"] == pytest.approx(float(np.dot(g, h)))
    assert p["open_water"] == g[0]
    np.testing.assert_allclose(obs[24:], [0.2, -0.4], rtol=1e-6)


def test_info_physics_is_a_copy(env):
    _, info = env.reset(seed=0)
    g = info["physics"]["g"]
    before = g.copy()
    env.step([1, 1])
    assert np.array_equal(g, before)
    assert set(info["physics"]) >= {"g", "h", "open_water", "mean_thickness", "day",
                                    "kernel_scale", "rafting_factor", "w1"}


# -- physics -----------------------------------------------------------------------------

def test_responds_to_the_kernel_scale_in_the_expected_direction(env):
    """Mechanical redistribution stacks two floes into one of their summed
    thickness and frees a cell of open water: from the same start, 100 daily
    steps (100 winter days) at 10× the redistribution rate (action[0] = +1) must
    end with a larger mean thickness, more ice thicker than 3 m and more
    open water than at 0.1× (action[0] = −1)."""
    results = {}
    for a0 in (1.0, -1.0):
        env.reset(seed=5)
        for _ in range(100):
            _, _, terminated, _, info = env.step([a0, 0.0])
            assert not terminated
        p = info["physics"]
        results[a0] = (p["mean_thickness"], p["g"][p["h"] >= 3.0].sum(), p["open_water"])
    (mean_hi, thick_hi, open_hi), (mean_lo, thick_lo, open_lo) = results[1.0], results[-1.0]
    assert mean_hi > mean_lo + 0.3
    assert thick_hi > 1.5 * thick_lo
    assert open_hi > 10 * open_lo


def test_area_is_conserved(env):
    env.reset(seed=4)
    for a in ([1, 1], [-1, -1], [0, 1]) * 10:
        p = env.step(a)[4]["physics"]
        assert p["g"].sum() == pytest.approx(1.0, abs=1e-9)
        assert np.all(p["g"] >= 0)


# -- rewards and targets ------------------------------------------------------------------

def test_reward_is_one_minus_w1_to_the_target(env):
    _, info0 = env.reset(seed=6)
    target = env.target
    assert info0["physics"]["w1"] == pytest.approx(wasserstein1(info0["physics"]["g"],
                                                                target, env.h))
    for a in ([1, 0], [-1, 1], [0.5, -0.5]):
        _, reward, _, _, info = env.step(a)
        p = info["physics"]
        assert reward == pytest.approx(1 - wasserstein1(p["g"], target, p["h"]), rel=1e-12)
        assert reward == pytest.approx(1 - p["w1"], rel=1e-12)
        assert 0 < reward < 1


def test_reward_function_directly():
    h = np.concatenate([[0.0], 0.1 * np.arange(1, 201)])
    target = default_target(h)
    now = {"g": target.copy()}
    assert thickness_distribution_reward(None, np.zeros(2), now, target=target, h=h) == 1.0
    # all ice of the target 0.1 m thicker: W1 = 0.1 m × ice fraction
    shifted = np.zeros_like(target)
    shifted[0] = target[0]
    shifted[2:] = target[1:-1]
    shifted[-1] += target[-1]
    r = thickness_distribution_reward(None, np.zeros(2), {"g": shifted}, target=target, h=h)
    assert r == pytest.approx(1 - 0.1 * (1 - target[0]), rel=1e-6)
    # the distance in units of distance_scale, clipped at 0
    r = thickness_distribution_reward(None, np.zeros(2), {"g": shifted}, target=target, h=h,
                                      distance_scale=0.05)
    assert r == pytest.approx(1 - 2 * (1 - target[0]) if 2 * (1 - target[0]) < 1 else 0.0)


def test_default_target():
    h = np.concatenate([[0.0], 0.1 * np.arange(1, 201)])
    t = default_target(h)
    assert t.sum() == pytest.approx(1.0)
    assert t[0] == pytest.approx(0.05)
    mean_ice = np.dot(t[1:], h[1:]) / t[1:].sum()
    assert mean_ice == pytest.approx(2.0, abs=0.05)
    assert np.argmax(t[1:]) == 9                  # mode of h exp(−h/λ) at λ = 1 m


def test_default_start_is_a_perturbed_target(env):
    _, info = env.reset(seed=9)
    g = info["physics"]["g"]
    assert info["physics"]["day"] == 0.0
    assert g.sum() == pytest.approx(1.0)
    assert not np.array_equal(g, env.target)
    ratio = (g[1:] / g.sum()) / env.target[1:]
    assert np.all(ratio > 0.5) and np.all(ratio < 2.0)


def test_target_and_g0_options(env):
    h = env.h
    target = np.where(h < 1.0, 2.0, 0.0)           # unnormalised: normalised by the env
    g0 = np.zeros(h.size)
    g0[0], g0[30] = 1.0, 3.0
    obs, info = env.reset(seed=0, options={"target": target, "g0": g0})
    np.testing.assert_allclose(env.target, target / target.sum())
    np.testing.assert_allclose(info["physics"]["g"], g0 / g0.sum())
    assert obs[0] == pytest.approx(0.25) and obs[7] == pytest.approx(0.75)   # 3.0 m → [3, 3.5)
    _, reward, *_ = env.step([0, 0])
    assert reward == pytest.approx(max(0.0, 1 - wasserstein1(env.model.g, target, h)))
    # the options hold for that episode only
    env.reset(seed=0)
    np.testing.assert_array_equal(env.target, default_target(h))
    # a start equal to the target scores ~0 until the physics moves it
    _, info = env.reset(seed=0, options={"g0": env.target})
    assert info["physics"]["w1"] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("options", [
    {"bogus": 1},
    {"target": np.ones(200)},
    {"target": np.ones((201, 1))},
    {"target": -np.ones(201)},
    {"target": np.zeros(201)},
    {"target": np.full(201, np.nan)},
    {"target": "thick"},
    {"g0": np.ones(202)},
    {"g0": np.r_[np.inf, np.ones(200)]},
    {"g0": np.r_[-1.0, np.ones(200)]},
])
def test_bad_options_raise(env, options):
    with pytest.raises(ValueError):
        env.reset(seed=0, options=options)


# -- episode end, errors ------------------------------------------------------------------

def test_truncated_after_one_year_with_defaults():
    import gymnasium as gym

    import iceenvs  # noqa: F401
    env = gym.make("iceenvs/ThicknessDistribution-v0")
    env.reset(seed=0)
    for k in range(1, 361):
        _, _, terminated, truncated, info = env.step([0, 0])
        assert not terminated
        assert truncated == (k == 360)
    assert info["physics"]["day"] == pytest.approx(360.0)


def test_episode_length_from_max_episode_steps():
    import gymnasium as gym

    import iceenvs  # noqa: F401
    e = gym.make("iceenvs/ThicknessDistribution-v0", days_per_step=30.0, max_episode_steps=3)
    e.reset(seed=0)
    flags = [e.step([0, 0])[3] for _ in range(3)]
    assert flags == [False, False, True]
    assert e.unwrapped.model.time == pytest.approx(90.0)
    # the environment never truncates on its own
    bare = ThicknessDistributionEnv(days_per_step=30.0)
    bare.reset(seed=0)
    assert not any(bare.step([0, 0])[3] for _ in range(20))


@pytest.mark.parametrize("kwargs", [
    {"n_classes": 1}, {"n_classes": 2.5}, {"n_classes": True}, {"dh": 0.0}, {"dh": -0.1},
    {"dh": float("nan")}, {"days_per_step": 0.0}, {"days_per_step": float("inf")},
    {"render_mode": "ascii"}, {"kernel": "nope"},
    {"kernel": "rafting"}, {"kernel_params": {"r": -1.0}}, {"kernel_params": {"bogus": 1.0}},
    {"kernel_params": [1.0]}, {"reward_fn": 3},
    {"kernel": lambda x, y: x + y, "kernel_params": {"r": 1.0}},
])
def test_bad_constructor_arguments_raise(kwargs):
    with pytest.raises(ValueError):
        ThicknessDistributionEnv(**kwargs)


def test_unknown_constructor_argument_lists_the_valid_ones():
    with pytest.raises(TypeError, match="episode_days.*valid arguments:.*days_per_step.*g0"):
        ThicknessDistributionEnv(episode_days=90.0)


def test_target_keyword_holds_for_every_episode():
    h = ThicknessDistributionEnv(n_classes=60).h
    target = np.where(h < 1.0, 1.0, 0.0)
    e = ThicknessDistributionEnv(n_classes=60, target=target)
    for seed in range(3):
        e.reset(seed=seed)
        np.testing.assert_allclose(e.target, target / target.sum())
    # an option replaces it for one episode
    e.reset(seed=0, options={"target": np.ones(61)})
    np.testing.assert_allclose(e.target, np.full(61, 1 / 61))
    e.reset(seed=0)
    np.testing.assert_allclose(e.target, target / target.sum())


def test_other_kernels_and_grids():
    e = ThicknessDistributionEnv(kernel="additive", n_classes=50, dh=0.3, days_per_step=10.0)
    obs, info = e.reset(seed=1)
    assert info["physics"]["g"].shape == (51,)
    assert obs.shape == (N_OBS,) and e.observation_space.contains(obs)
    assert obs[:21].sum() == pytest.approx(1.0, abs=1e-5)
    obs, *_ = e.step([1, 1])
    assert e.observation_space.contains(obs)
    matrix = np.full((200, 200), 0.002)
    e = ThicknessDistributionEnv(kernel=matrix)
    e.reset(seed=0)
    e.step([0, 0])
    assert np.all(matrix == 0.002)                 # not modified by the env


def test_custom_reward_fn_receives_target_and_h():
    calls = []

    def reward(prev, action, now, *, target, h, distance_scale):
        calls.append((prev, action, now, target, h))
        return 1.5

    e = ThicknessDistributionEnv(reward_fn=reward)
    e.reset(seed=0)
    _, r, *_ = e.step([2.0, 0.0])
    assert r == 1.5
    prev, action, now, target, h = calls[0]
    assert np.array_equal(action, [1.0, 0.0])
    assert prev["day"] == 0.0 and now["day"] == 1.0
    assert np.array_equal(target, e.target) and np.array_equal(h, e.h)


def test_physics_failure_ends_the_episode(env):
    env.reset(seed=0)
    obs0 = env.step([0, 0])[0]

    def broken(dt):
        raise FloatingPointError("overflow")

    env.model.step = broken
    obs, reward, terminated, truncated, info = env.step([0, 0])
    assert terminated and not truncated
    # the failed state is absorbing and worth nothing
    assert reward == env.failure_reward == 0.0
    assert "FloatingPointError" in info["error"]
    assert np.array_equal(obs, obs0)


def test_non_finite_custom_reward_terminates():
    e = ThicknessDistributionEnv(reward_fn=lambda prev, action, now, **p: float("nan"))
    e.reset(seed=0)
    _, reward, terminated, _, info = e.step([0, 0])
    assert terminated and "error" in info
    assert reward == e.failure_reward == 0.0


def test_step_before_reset_raises():
    with pytest.raises(RuntimeError):
        ThicknessDistributionEnv().step([0, 0])


# -- rendering ---------------------------------------------------------------------------

def test_render_without_mode_warns(env):
    env.reset(seed=0)
    with pytest.warns(UserWarning, match="render_mode"):
        assert env.render() is None


def test_render_rgb_array():
    pytest.importorskip("iceenvs.rendering")
    e = ThicknessDistributionEnv(render_mode="rgb_array")
    e.reset(seed=0)
    e.step([0, 0])
    frame = e.render()
    assert isinstance(frame, np.ndarray) and frame.dtype == np.uint8
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.shape[0] > 0
    e.close()


def test_docstring_sections():
    doc = ThicknessDistributionEnv.__doc__
    for section in ("## Description", "## Action Space", "## Observation Space", "## Rewards",
                    "## Starting State", "## Episode End", "## Arguments",
                    "## Version History", "Godlovitch", "days_per_step"):
        assert section in doc
    rows = [line for line in doc.splitlines() if line.strip().startswith("| ")]
    indices = [line.split("|")[1].strip() for line in rows]
    for k in range(24):
        assert str(k) in indices
    assert "24, 25" in indices
