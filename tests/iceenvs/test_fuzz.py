"""Property tests of the floe environments: any seed, any valid reset
options and any action entries (NaN, ±inf, huge, tiny, in range) give a
finite observation inside the observation space, a finite reward and finite
physical values; invalid reset options raise ValueError.

One small env per id is built once and reused across examples.
"""
import math

import gymnasium as gym
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import iceenvs  # noqa: F401  (registers the ids)
from small_envs import SMALL as ALL_SMALL

WIND = "iceenvs/WindDrift-v0"
CONVERGENCE = "iceenvs/Convergence-v0"
MIZ = "iceenvs/MarginalIceZone-v0"
CLUSTERING = "iceenvs/FloeClustering-v0"
ITD = "iceenvs/ThicknessDistribution-v0"

SMALL = {env_id: ALL_SMALL[env_id] for env_id in (WIND, CONVERGENCE, MIZ, CLUSTERING)}

ENVS = {env_id: gym.make(env_id, **kwargs).unwrapped for env_id, kwargs in SMALL.items()}

FUZZ = settings(max_examples=20, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow])

seeds = st.integers(min_value=0, max_value=2 ** 32 - 1)
wild = st.floats(allow_nan=True, allow_infinity=True, width=32)
in_range = st.floats(min_value=-1.0, max_value=1.0, width=32)
entries = st.one_of(wild, in_range)

# valid reset options per env: (a strategy of dicts)
OPTIONS = {
    WIND: st.fixed_dictionaries({}, optional={
        "heading": st.floats(allow_nan=False, allow_infinity=False)}),
    # start concentrations up to 0.8: random placement of 60 floes jams near 0.85
    CONVERGENCE: st.fixed_dictionaries({}, optional={
        "target": st.floats(min_value=0.0, max_value=1.0, exclude_min=True, exclude_max=True),
        "concentration": st.floats(min_value=0.05, max_value=0.8)}),
    MIZ: st.fixed_dictionaries({}, optional={
        "target_speed": st.floats(min_value=-0.5, max_value=0.5)}),
    CLUSTERING: st.fixed_dictionaries({}, optional={
        "target": st.floats(min_value=0.0, max_value=1.0)}),
}


def action_lists(n):
    return st.lists(st.lists(entries, min_size=n, max_size=n), min_size=1, max_size=3)


def check_step(env, obs, reward, info):
    assert obs.dtype == np.float32
    assert np.all(np.isfinite(obs)), obs
    assert env.observation_space.contains(obs), obs
    assert math.isfinite(reward), reward
    low, high = env.unwrapped.reward_bounds
    assert low <= reward <= high, reward
    for name, value in info["physics"].items():
        if not np.isscalar(value):
            continue
        if name == "cluster_alpha" and math.isnan(value):
            # NaN marks an undefined exponent (see
            # test_cluster_exponent_in_info_is_finite_when_undefined)
            continue
        assert math.isfinite(float(value)), (name, value)


def run(env_id, seed, options, acts):
    env = ENVS[env_id]
    obs, info = env.reset(seed=seed, options=options)
    assert np.all(np.isfinite(obs)) and env.observation_space.contains(obs)
    for a in acts:
        obs, reward, terminated, truncated, info = env.step(np.array(a, dtype=np.float32))
        # every action is sanitised into range, so the physics must not fail
        assert "error" not in info, info.get("error")
        assert not terminated or env_id == CONVERGENCE
        check_step(env, obs, reward, info)
        # the last action is observed sanitised: NaN as 0, ±inf as the bounds,
        # clipped into [-1, 1]; info counts the entries that were not finite
        last = obs[-env.action_space.shape[0]:]
        raw = np.array(a, dtype=np.float32).astype(np.float64)
        expected = np.clip(np.nan_to_num(raw, nan=0.0, posinf=1.0, neginf=-1.0), -1.0, 1.0)
        assert np.array_equal(last, expected.astype(np.float32))
        assert info["nonfinite_action"] == int(np.sum(~np.isfinite(raw)))
        if terminated or truncated:
            break


@FUZZ
@given(seed=seeds, options=OPTIONS[WIND], acts=action_lists(2))
def test_wind_drift_fuzz(seed, options, acts):
    run(WIND, seed, options, acts)


@FUZZ
@given(seed=seeds, options=OPTIONS[CONVERGENCE], acts=action_lists(1))
def test_convergence_fuzz(seed, options, acts):
    run(CONVERGENCE, seed, options, acts)


@FUZZ
@given(seed=seeds, options=OPTIONS[MIZ], acts=action_lists(2))
def test_marginal_ice_zone_fuzz(seed, options, acts):
    run(MIZ, seed, options, acts)


@FUZZ
@given(seed=seeds, options=OPTIONS[CLUSTERING], acts=action_lists(2))
def test_floe_clustering_fuzz(seed, options, acts):
    run(CLUSTERING, seed, options, acts)


# -- invalid reset options ----------------------------------------------------------------

INVALID = [
    (WIND, {"no_such_option": 1}),
    (CONVERGENCE, {"no_such_option": 1}),
    (MIZ, {"no_such_option": 1}),
    (CLUSTERING, {"no_such_option": 1}),
    (ITD, {"no_such_option": 1}),
    (WIND, {"heading": float("nan")}),
    (WIND, {"heading": float("inf")}),
    (CONVERGENCE, {"target": 1.5}),
    (CONVERGENCE, {"target": float("nan")}),
    (CONVERGENCE, {"concentration": float("nan")}),
    (CONVERGENCE, {"concentration": 0.95}),
    (CONVERGENCE, {"target_range": (0.9, 0.8)}),
    (CONVERGENCE, {"max_rate": 0.0}),
    (CLUSTERING, {"target": 1.5}),
    (CLUSTERING, {"target": -0.1}),
    (CLUSTERING, {"target": True}),
    (MIZ, {"target_speed": "fast"}),
    (ITD, {"target": [1.0, 2.0]}),
    ("iceenvs/ShipNavigation-v0", {"concentration": 0.95}),
    ("iceenvs/ShipNavigation-v0", {"floe_sizes": "huge"}),
    ("iceenvs/ShipNavigation-v0", {"channel_exit": "ignore"}),
    ("iceenvs/ShipNavigation-v0", {"wind_speed": float("nan")}),
    ("iceenvs/ShipBeset-v0", {"concentration": 0.85}),
    ("iceenvs/ShipBeset-v0", {"ship_offset": 10.0}),
    ("iceenvs/ShipBeset-v0", {"pressure_limit": 0.0}),
]


@pytest.mark.parametrize("env_id, options", INVALID,
                         ids=[f"{e.split('/')[1]}-{sorted(o.items())}" for e, o in INVALID])
def test_invalid_reset_options_raise_value_error(env_id, options):
    if env_id in ENVS:
        env = ENVS[env_id]
    elif env_id == ITD:
        env = gym.make(env_id, n_classes=20).unwrapped
    else:
        env = gym.make(env_id).unwrapped
    with pytest.raises(ValueError):
        env.reset(seed=0, options=options)
    # the env is still usable afterwards
    obs, _ = env.reset(seed=0)
    assert env.observation_space.contains(obs)


def test_cluster_exponent_in_info_is_finite_when_undefined():
    """An undefined cluster exponent (one cluster) is 0 in the observation and
    in ``info["physics"]``."""
    env = gym.make(CLUSTERING, concentration=0.85, cluster_gap=0.5).unwrapped
    try:
        obs, info = env.reset(seed=0)
    finally:
        env.close()
    # preconditions (a broken one is an error, not the expected failure): a single
    # cluster, whose exponent is undefined and observed as 0
    if info["physics"]["largest_cluster"] != pytest.approx(1.0):
        raise RuntimeError(f"expected one cluster, got {info['physics']['largest_cluster']}")
    if obs[[f.name for f in env.features].index("cluster_alpha")] != 0.0:
        raise RuntimeError("an undefined exponent should be observed as 0")
    assert info["physics"]["cluster_alpha"] == 0.0


def test_convergence_start_concentration_option_is_limited_to_what_placement_reaches():
    """Random placement of the Herman (2013) FSD jams near 0.86: a start
    concentration above 0.85 is refused, 0.85 itself is built."""
    env = gym.make(CONVERGENCE).unwrapped
    try:
        with pytest.raises(ValueError, match="concentration"):
            env.reset(seed=0, options={"concentration": 0.9})
        obs, info = env.reset(seed=0, options={"concentration": 0.85})
    finally:
        env.close()
    assert info["physics"]["concentration"] == pytest.approx(0.85)
