"""The constant-action baseline and the grid search for the best one."""
import json

import gymnasium as gym
import numpy as np
import pytest

import iceenvs  # noqa: F401
from agents.baselines import GENERIC, make_baseline
from agents.constant import (ConstantPolicy, action_grid, best_action, main as constant_main,
                             search_constant_actions)

ITD = "iceenvs/ThicknessDistribution-v0"
# a short ITD episode: max_episode_steps is the gymnasium.make keyword of the length
SHORT = dict(n_classes=60, max_episode_steps=4)
SHORT_ARGS = ["n_classes=60", "max_episode_steps=4"]


@pytest.fixture
def env():
    env = gym.make(ITD, **SHORT)
    yield env
    env.close()


def test_constant_policy_single_and_batched(env):
    policy = ConstantPolicy(env, action=[0.25, -1.0])
    obs, _ = env.reset(seed=0)
    action, state = policy.predict(obs)
    assert state is None and env.action_space.contains(action)
    np.testing.assert_array_equal(action, np.array([0.25, -1.0], dtype=np.float32))
    batch, _ = policy.predict(np.stack([obs, obs, obs]))
    assert batch.shape == (3, 2)
    np.testing.assert_array_equal(batch, np.tile([0.25, -1.0], (3, 1)).astype(np.float32))
    # the same action after a reset and other observations
    policy.reset(5)
    obs, *_ = env.step(action)
    np.testing.assert_array_equal(policy.predict(obs)[0], action)


@pytest.mark.parametrize("action", [[0.5], [0.1, 0.2, 0.3], [[0.0, 0.0]], 0.5, [1.5, 0.0],
                                    [0.0, -1.01], [np.nan, 0.0], ["a", 0.0]])
def test_constant_policy_rejects_bad_actions(env, action):
    with pytest.raises(ValueError):
        ConstantPolicy(env, action=action)


def test_constant_is_a_registered_baseline(env):
    assert GENERIC["constant"] is ConstantPolicy
    policy = make_baseline("constant", env, seed=3)      # the centre of the box
    np.testing.assert_array_equal(policy.action, [0.0, 0.0])
    assert ConstantPolicy.best(env, [{"action": [1.0, -1.0]}]).action.tolist() == [1.0, -1.0]


def test_action_grid_spans_the_box(env):
    grid = action_grid(env.action_space, 3)
    assert grid.shape == (9, 2)
    assert sorted(map(tuple, grid)) == [(a, b) for a in (-1, 0, 1) for b in (-1, 0, 1)]
    with pytest.raises(ValueError):
        action_grid(env.action_space, 1)


def _direct_returns(action, seeds):
    env = gym.make(ITD, **SHORT)
    out = []
    for seed in seeds:
        env.reset(seed=seed)
        total = 0.0
        while True:
            _, reward, terminated, truncated, _ = env.step(np.asarray(action, np.float32))
            total += float(reward)
            if terminated or truncated:
                break
        out.append(total)
    env.close()
    return out


def test_search_is_sorted_deterministic_and_reproducible():
    kwargs = dict(env_kwargs=SHORT, grid=3, seeds=2, seed=123, processes=1, progress=False)
    first = search_constant_actions(ITD, **kwargs)
    assert len(first) == 3 ** 2
    means = [r["mean"] for r in first]
    assert means == sorted(means, reverse=True)
    assert len({tuple(r["action"]) for r in first}) == 9
    for r in first:
        assert r["seeds"] == [123, 124] and len(r["returns"]) == 2
        assert r["mean"] == pytest.approx(np.mean(r["returns"]))
        assert r["sem"] == pytest.approx(r["std"] / np.sqrt(2))
    assert search_constant_actions(ITD, **kwargs) == first
    best = first[0]
    direct = _direct_returns(best["action"], [123, 124])
    np.testing.assert_allclose(direct, best["returns"], rtol=1e-12)
    assert np.mean(direct) == pytest.approx(best["mean"], rel=1e-12)


def test_search_rejects_bad_arguments():
    with pytest.raises(ValueError, match="n_clases"):
        search_constant_actions(ITD, env_kwargs={"n_clases": 60}, grid=3, seeds=1,
                                processes=1, progress=False)
    with pytest.raises(ValueError, match="grid"):
        search_constant_actions(ITD, env_kwargs=SHORT, grid=1, processes=1, progress=False)
    with pytest.raises(ValueError, match="seeds"):
        search_constant_actions(ITD, env_kwargs=SHORT, seeds=0, processes=1, progress=False)


def test_command_line_and_evaluation(tmp_path, capsys):
    from agents.evaluate import main as evaluate_main

    out = tmp_path / "constant.json"
    results = constant_main(["--env", ITD, "--grid", "3", "--seeds", "2", "--processes", "1",
                             "--no-progress", "--out", str(out), "--env-kwargs", *SHORT_ARGS])
    printed = capsys.readouterr().out
    assert "| rank | action |" in printed and "Grid of 3 points" in printed
    assert "9 actions" in printed
    report = json.loads(out.read_text())
    assert report["env"] == ITD and report["env_kwargs"] == SHORT and report["grid"] == 3
    assert report["results"] == results and len(results) == 9
    assert best_action(out) == results[0]["action"]

    summaries = evaluate_main(["--baseline", "constant", "--env", ITD, "--episodes", "2",
                               "--no-progress", "--constant", str(out), "--out",
                               str(tmp_path / "e"), "--env-kwargs", *SHORT_ARGS])
    assert set(summaries) == {"constant"}
    table = (tmp_path / "e" / "evaluation.md").read_text()
    a = results[0]["action"]
    assert f"| constant ({a[0]:.4g}, {a[1]:.4g}) |" in table

    # a search on another environment is refused
    with pytest.raises(SystemExit) as exc:
        evaluate_main(["--baseline", "constant", "--env", "iceenvs/Convergence-v0",
                       "--no-progress", "--constant", str(out), "--out", str(tmp_path / "f")])
    assert exc.value.code == 2
    assert ITD in capsys.readouterr().err


def test_evaluation_searches_when_no_file_is_given(tmp_path, capsys):
    from agents.evaluate import main as evaluate_main

    summaries = evaluate_main(["--baselines", "zero,constant", "--baseline", "constant",
                               "--env", ITD, "--episodes", "2", "--no-progress", "--out",
                               str(tmp_path), "--env-kwargs", *SHORT_ARGS])
    assert set(summaries) == {"constant"}
    printed = capsys.readouterr().out
    assert "searching for the best constant action" in printed
    report = json.loads((tmp_path / "evaluation.json").read_text())
    constant = report["constant"]
    assert constant["search"] and constant["grid"] == 9
    # the search episodes are not the evaluation episodes (seeded 10000 + k)
    assert not set(constant["seeds"]) & {10_000, 10_001}
