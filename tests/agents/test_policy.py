"""A policy of one's own, named module:Class or file.py:Class: ranked by the
leaderboard and scored by agents.evaluate in worker processes, beside the
baselines on the same fields; bad references refused clearly."""
import textwrap

import gymnasium as gym
import numpy as np
import pytest

import iceenvs  # noqa: F401
from agents import evaluate, leaderboard
from agents.baselines import make_baseline
from agents.policy import Policy, make_policy, parse_reference, policy_class, split_policies
from cli_checks import assert_refused

SHORT = ["--env-kwargs", "goal_distance=200.0", "length=500.0"]

#: a policy that reads its observation entries by name: yaw towards the
#: goal direction, with a gain
STEER = textwrap.dedent('''
    import numpy as np


    class Steer:
        def __init__(self, env, seed=0, gain=1.0):
            names = [f.name for f in env.unwrapped.features]
            self.sin = names.index("goal_sin")
            self.gain = float(gain)
            self.episodes = []

        def reset(self, seed=None):
            self.episodes.append(seed)

        def predict(self, obs, deterministic=True):
            turn = np.clip(self.gain * obs[self.sin], -1.0, 1.0)
            return np.array([turn], dtype=np.float32), None


    class NoPredict:
        def __init__(self, env, seed=0):
            pass

        def reset(self, seed=None):
            pass
''')


@pytest.fixture
def steer_module(tmp_path, monkeypatch):
    """The module ``steer_policy`` in a directory of its own, on the path."""
    (tmp_path / "steer_policy.py").write_text(STEER)
    monkeypatch.syspath_prepend(str(tmp_path))
    return tmp_path / "steer_policy.py"


def test_a_reference_is_a_module_or_a_file_and_its_arguments():
    assert parse_reference("pkg.mod:Steer") == ("pkg.mod", "Steer", {})
    assert parse_reference("a/b/steer.py:Steer?gain=0.5&name=x&on=true") == (
        "a/b/steer.py", "Steer", {"gain": 0.5, "name": "x", "on": True})


def test_a_list_value_keeps_its_commas_in_a_list_of_policies(tmp_path, capsys):
    text = "lattice, wide=agents.planners:RolloutPlanner?offsets=[-16,4]&x={a: 1, b: 2},swath"
    assert split_policies(text) == [
        "lattice", "wide=agents.planners:RolloutPlanner?offsets=[-16,4]&x={a: 1, b: 2}", "swath"]
    assert parse_reference(split_policies(text)[1].partition("=")[2])[2] == {
        "offsets": [-16, 4], "x": {"a": 1, "b": 2}}
    for bad, words in (("a?x=[1,2", ["not closed"]), ("a?x=1],b", ["never opened"])):
        with pytest.raises(ValueError, match=words[0]):
            split_policies(bad)
        assert_refused(leaderboard.main, ["--policies", bad], words, tmp_path / "none", capsys)
        assert_refused(evaluate.main, ["--baselines", bad, "--env", "iceenvs/ShipNavigation-v0"],
                       words, tmp_path / "none", capsys)


def test_own_policy_is_made_for_its_environment(steer_module):
    env = gym.make("iceenvs/ShipNavigation-v0")
    for ref in ("steer_policy:Steer?gain=2", f"{steer_module}:Steer?gain=2"):
        policy = make_baseline(ref, env, seed=3)
        assert isinstance(policy, Policy) and policy.gain == 2.0
        obs, _ = env.reset(seed=0)
        action, state = policy.predict(obs)
        assert env.action_space.contains(action) and state is None
    env.close()


def test_own_policy_joins_the_leaderboard_in_worker_processes(steer_module, tmp_path):
    out = tmp_path / "board"
    ref = "steer_policy:Steer?gain=0.5"
    report = leaderboard.main(["--concentrations", "0.2", "--episodes", "2", "--processes", "2",
                               "--out", str(out), "--policies",
                               f"straight,{ref},steer-half={ref}"] + SHORT)
    assert list(report["summary"]["0.2"]) == ["straight", ref, "steer-half"]
    assert report["own_policies"] == [ref, "steer-half"]
    # a policy of one's own shown under a name of its own is the same policy
    assert ([e["ret"] for e in report["episodes_detail"]["0.2"]["steer-half"]]
            == [e["ret"] for e in report["episodes_detail"]["0.2"][ref]])
    # paired with the straight line on the same fields
    mine = report["episodes_detail"]["0.2"][ref]
    straight = report["episodes_detail"]["0.2"]["straight"]
    assert [e["seed"] for e in mine] == [e["seed"] for e in straight] == [10_000, 10_001]
    assert "ratio_impulse_per_metre" in report["summary"]["0.2"][ref]
    assert f"| {ref} |" in (out / "leaderboard.md").read_text()


def test_own_policy_is_scored_by_evaluate_in_worker_processes(steer_module, tmp_path):
    ref = f"{steer_module}:Steer?gain=0.5"
    summaries = evaluate.main(["--baseline", ref, "--env", "iceenvs/ShipNavigation-v0",
                               "--episodes", "2", "--processes", "2", "--no-progress",
                               "--out", str(tmp_path / "eval"), "--env-kwargs",
                               "goal_distance=200.0", "length=500.0"])
    assert list(summaries) == [ref]
    assert np.isfinite(summaries[ref]["return"]["mean"])


@pytest.mark.parametrize("ref, words", [
    ("no_such_module_xyz:Steer", ["no module 'no_such_module_xyz'"]),
    ("missing_dir/steer.py:Steer", ["no file"]),
    ("steer_policy:Nope", ["has no 'Nope'"]),
    ("steer_policy:NoPredict", ["NoPredict has no predict"]),
    (":Steer", ["module:Class"]),
    ("steer_policy:Steer?gain", ["key=value"]),
])
def test_bad_references_are_refused_clearly(steer_module, tmp_path, capsys, ref, words):
    with pytest.raises(ValueError) as err:
        policy_class(ref)
    assert all(w in str(err.value) for w in words), str(err.value)
    assert_refused(leaderboard.main, ["--policies", f"straight,{ref}"], words,
                   tmp_path / "none", capsys)
    assert_refused(evaluate.main, ["--baseline", ref, "--env", "iceenvs/ShipNavigation-v0"],
                   words, tmp_path / "none", capsys)


def test_a_class_made_otherwise_is_refused(steer_module):
    env = gym.make("iceenvs/ShipNavigation-v0")
    with pytest.raises(ValueError, match=r"Steer\(env, seed=seed, \*\*kwargs\)"):
        make_policy("steer_policy:Steer?speed=3", env)
    env.close()


def test_one_check_of_policy_names_for_every_command():
    from agents.baselines import check_policy_names

    check_policy_names(["straight", "lattice", "my_policy.py:Mine", "pkg.mod:Cls"],
                       "iceenvs/ShipNavigation-v1")
    with pytest.raises(ValueError, match=r"unknown policies 'swerve', 'zig' for "
                                         r"iceenvs/ShipNavigation-v1; valid: .*lattice.*"
                                         r"module:Class or path/to/file.py:Class, or a run"):
        check_policy_names(["straight", "swerve", "zig"], "iceenvs/ShipNavigation-v1",
                           also=", or a run")
    with pytest.raises(ValueError, match="unknown policy 'lattice' for iceenvs/Convergence-v0"):
        check_policy_names(["lattice"], "iceenvs/Convergence-v0")
