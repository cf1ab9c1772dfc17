"""The rollout oracle (agents.oracle): with rollouts that reach the end of the
episode it never returns less than its baseline (the rollout theorem, exact
copies of a deterministic environment), the chaos oracle's candidates stay
within a few epsilon of the baseline's action, and the command writes its
record and refuses bad input and the benchmark's episodes."""
import json

import gymnasium as gym
import numpy as np
import pytest

import iceenvs  # noqa: F401
from agents.baselines import make_baseline
from agents.oracle import RolloutOracle, main, oracles
from agents.rollouts import run_episode

STEPS = 16


@pytest.fixture(scope="module")
def small_miz():
    env = gym.make("iceenvs/MarginalIceZone-v0", n_floes=60, max_episode_steps=STEPS)
    yield env
    env.close()


class Ramp:
    """A baseline with a state: the wind command cycles with its calls."""

    def reset(self, seed=None):
        self.calls = 0

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        self.calls += 1
        return np.array([np.sin(0.7 * self.calls), 0.3 * np.cos(0.3 * self.calls)],
                        dtype=np.float32), state


@pytest.mark.parametrize("base, chaos", [("heuristic", False), ("ramp", False), ("ramp", True)])
def test_rollouts_to_the_end_never_return_less_than_the_baseline(small_miz, base, chaos):
    """Rollout theorem: the baseline's continuation is a candidate at every
    decision and the copies are exact, so the planned return (rewards so
    far plus the best rollout's) never falls and the last plan is what the
    episode earns. It fails if a copy is not exact or the baseline's state
    is not copied with the environment."""
    extra = dict(epsilon=1e-6) if chaos else {}
    for seed in (50000, 50001):
        oracle = RolloutOracle(small_miz, every=4, horizon=STEPS, **extra)
        if base == "ramp":
            oracle.base = Ramp()
        policy = Ramp() if base == "ramp" else make_baseline("heuristic", small_miz)
        base_return = run_episode(small_miz, policy, seed, None)["ret"]
        episode = run_episode(small_miz, oracle, seed, None)
        ret = episode["ret"]
        assert oracle.decisions == STEPS // 4
        planned = [sum(episode["rewards"][:4 * j]) + plan for j, plan in enumerate(oracle.plans)]
        tol = 1e-9 * max(1.0, abs(base_return))
        assert all(b >= a - tol for a, b in zip(planned, planned[1:]))
        assert abs(ret - planned[-1]) <= tol
        assert ret >= base_return - tol
        again = run_episode(small_miz, oracle, seed, None)["ret"]
        assert again == ret                               # the same seed, the same episode


def test_candidates_of_the_oracle_and_of_its_chaos_control(small_miz):
    oracle = RolloutOracle(small_miz, delta=0.5)
    offsets = np.array(oracle.offsets)
    assert offsets.shape == (5, 2)                       # none, then +- delta on each entry
    np.testing.assert_array_equal(np.abs(offsets).sum(axis=1), [0.0, 0.5, 0.5, 0.5, 0.5])
    chaos = RolloutOracle(small_miz, epsilon=1e-6)
    chaos.reset(3)
    drawn = np.array(chaos._candidates())
    assert drawn.shape == (5, 2) and not drawn[0].any()
    # a normal draw passes 6 sigma once in 5e8
    assert 0 < np.abs(drawn[1:]).max() < 6e-6
    chaos.reset(3)
    np.testing.assert_array_equal(chaos._candidates(), drawn)   # seeded per episode
    for bad in (dict(every=0), dict(every=5, horizon=4), dict(delta=0.0), dict(epsilon=-1.0)):
        with pytest.raises(ValueError):
            RolloutOracle(small_miz, **bad)


def test_the_command_writes_its_record(tmp_path):
    out = tmp_path / "oracle"
    record = main(["--env", "iceenvs/ThicknessDistribution-v0", "--base", "zero", "--every",
                   "60", "--horizon", "60", "--episodes", "2", "--out", str(out),
                   "--no-progress"])
    assert set(record["returns"]) == {"zero", "oracle", "chaos oracle"}
    assert json.loads((out / "oracle.json").read_text())["episodes"] == 2
    assert (out / "oracle.png").stat().st_size > 0
    assert "oracle − chaos oracle" in (out / "oracle.md").read_text()
    with pytest.raises(ValueError, match="benchmark"):
        oracles("iceenvs/ThicknessDistribution-v0", episodes=3, seed=39999, progress=False)
    for argv in (["--env", "iceenvs/NoSuch-v0"],
                 ["--env", "iceenvs/ThicknessDistribution-v0", "--horizon", "2"]):
        with pytest.raises(SystemExit):
            main([*argv, "--out", str(tmp_path / "bad"), "--no-progress"])
