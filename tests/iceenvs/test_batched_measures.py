"""The pieces the native ship vector environments make in batch give, row by
row, what the single environment makes of one measurement: the scaled
observation (normalise_rows) and the ship rewards evaluated on columns."""
import math

import numpy as np
import pytest

from iceenvs.observations import FLOE_FEATURES, Feature, log_stress, normalise, normalise_rows
from iceenvs.rewards import ship_beset_reward, ship_navigation_reward
from iceenvs.ship_env import ship_features

# every scaling, each feature once by name
FEATURES = tuple({f.name: f for f in FLOE_FEATURES + ship_features(3, 150.0) + (
    Feature("rate", "a rate", "1/s", "log rate", 0.0, 10.0),
    Feature("alpha", "an exponent", "-", "exponent", 0.0, 10.0))}.values())


def test_normalise_rows_is_normalise_row_by_row():
    rng = np.random.default_rng(0)
    raw = rng.lognormal(0.0, 6.0, (50, len(FEATURES))) * rng.choice([-1.0, 1.0], (50, len(FEATURES)))
    raw[0, :4] = np.nan, np.inf, -np.inf, 0.0
    rows = normalise_rows(raw, FEATURES)
    assert rows.dtype == np.float32 and rows.shape == raw.shape
    for m in range(raw.shape[0]):
        one = normalise(dict(zip((f.name for f in FEATURES), raw[m])), FEATURES)
        np.testing.assert_array_equal(rows[m], one)
    # within the bounds; a non-finite value becomes 0 (then clipped)
    low = np.array([f.low for f in FEATURES])
    high = np.array([f.high for f in FEATURES])
    assert np.all((rows >= low.astype(np.float32)) & (rows <= high.astype(np.float32)))
    assert rows[0, 0] == max(0.0, FEATURES[0].low)


def test_the_scalings_are_those_of_the_documentation():
    # sign(s) log10(1 + |s| / 1 N/m): 9 N/m ↔ 1, 10 kN/m ↔ about 4
    assert log_stress(9.0) == pytest.approx(1.0, rel=1e-15)
    assert log_stress(-9999.0) == pytest.approx(-4.0, rel=1e-15)
    names = ("surge", "yaw_rate", "goal_distance", "rate", "alpha")
    features = tuple(f for f in FEATURES if f.name in names)
    raw = {"surge": 2.5, "yaw_rate": 0.02, "goal_distance": 150.0, "rate": 0.09,
           "alpha": math.nan}
    got = normalise(raw, features).tolist()
    want = {"surge": 2.5, "yaw_rate": 0.2, "goal_distance": 1.5, "rate": 1.0, "alpha": 0.0}
    np.testing.assert_allclose(got, [want[f.name] for f in features], rtol=1e-6)


def test_normalise_rows_rejects_a_raw_array_of_the_wrong_shape():
    with pytest.raises(ValueError, match=r"raw must be an \(M, 2\) array"):
        normalise_rows(np.zeros((4, 3)), FLOE_FEATURES[:2])


@pytest.mark.parametrize("reward, params", [
    (ship_navigation_reward, dict(step_length=4.0, impulse_scale=1e6)),
    (ship_beset_reward, dict(step_length=4.0, pressure_limit=1e4)),
])
def test_a_ship_reward_of_columns_is_the_reward_of_each_row(reward, params):
    rng = np.random.default_rng(1)
    n = 200
    prev = {"goal_distance": rng.uniform(0.0, 300.0, n)}
    now = {"goal_distance": prev["goal_distance"] - rng.uniform(-6.0, 6.0, n),
           "step_impulse": rng.lognormal(12.0, 2.0, n), "channel_offset": rng.uniform(-2, 2, n),
           "hull_pressure": rng.lognormal(9.0, 1.0, n), "reached": rng.integers(0, 2, n) * 1.0}
    columns = reward(prev, None, now, **params)
    assert columns.shape == (n,)
    for m in range(n):
        one = reward({k: float(v[m]) for k, v in prev.items()}, None,
                     {k: float(v[m]) for k, v in now.items()}, **params)
        assert float(one) == columns[m]
