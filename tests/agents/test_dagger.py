"""DAgger (agents.dagger): who drives, who labels, a round that runs, and the
student against its teacher on fields it was not fitted on (agents.held_out)."""
import numpy as np
import pytest

from agents.dagger import aggregate, dagger, student_rollouts
from agents.pretrain import Demonstrations, collect
from small_envs import SMALL

NAV = "iceenvs/ShipNavigation-v1"
# a short transit: about 60 steps of the small field
KWARGS = {**SMALL[NAV], "length": 300.0, "goal_distance": 150.0}


def train_with_a_round(out, *, timesteps: int, save_freq: int):
    """agents.train with the costmap recipe on a short field: the lattice's
    clone from one episode, one DAgger round (beta 0.5), then PPO."""
    from agents import train

    train.main(["--env", NAV, "--algo", "ppo", "--conf", "ppo-costmap.yaml",
                "--timesteps", str(timesteps), "--n-envs", "1", "--seed", "0", "--out", str(out),
                "--no-progress", "--eval-freq", "0", "--save-freq", str(save_freq),
                "--hyperparams", "n_steps=64", "batch_size=64", "n_epochs=1",
                "pretrain={teacher: lattice, episodes: 1, epochs: 2, rounds: 1, beta: 0.5}",
                "--env-kwargs", *(f"{k}={v}" for k, v in KWARGS.items())])
    return out


class Constant:
    """A student that always commands ``value``."""

    def __init__(self, value):
        self.value = np.array([value], dtype=np.float32)

    def predict(self, obs, deterministic=True):
        return self.value, None


def test_with_beta_one_the_round_is_the_teachers_demonstrations():
    demos, returns, share = student_rollouts(Constant(0.9), None, NAV, KWARGS, "lattice", 2,
                                             seed=7, beta=1.0)
    teacher = collect(NAV, KWARGS, "lattice", 2, seed=7)
    assert share == 1.0 and demos.episodes == 2 == len(returns)
    np.testing.assert_array_equal(demos.obs, teacher.obs)
    np.testing.assert_array_equal(demos.actions, teacher.actions)
    np.testing.assert_array_equal(demos.rewards, teacher.rewards)
    assert sum(returns) == pytest.approx(teacher.rewards.sum(), rel=1e-12)


def test_with_beta_zero_the_student_drives_and_the_teacher_labels_every_state():
    import gymnasium as gym

    from agents.baselines import make_baseline

    demos, _, share = student_rollouts(Constant(0.3), None, NAV, KWARGS, "lattice", 1,
                                       seed=11, beta=0.0)
    assert share == 0.0
    # the same episode replayed with the student's constant command, the teacher
    # asked at every step: the same states and the same labels
    env = gym.make(NAV, **KWARGS)
    planner = make_baseline("lattice", env, seed=11)
    obs, _ = env.reset(seed=11)
    planner.reset(11)
    for t in range(len(demos)):
        np.testing.assert_array_equal(demos.obs[t], np.asarray(obs, dtype=np.float32))
        np.testing.assert_array_equal(demos.actions[t], planner.predict(obs)[0])
        obs, *_ = env.step(np.array([0.3], dtype=np.float32))
    env.close()
    # the labels are the planner's steering, not the command played
    assert np.ptp(demos.actions) > 0


def test_aggregate_keeps_the_episodes_in_order():
    a = Demonstrations(np.zeros((3, 2)), np.zeros((3, 1)), [1, 2, 3], [True, False, False])
    b = Demonstrations(np.ones((2, 2)), np.ones((2, 1)), [4, 5], [True, False])
    both = aggregate(a, b)
    assert len(both) == 5 and both.episodes == 2
    np.testing.assert_array_equal(both.rewards, [1, 2, 3, 4, 5])
    np.testing.assert_array_equal(both.obs[3:], 1.0)


def test_refused_beta():
    with pytest.raises(ValueError, match=r"beta must lie in \[0, 1\]"):
        student_rollouts(Constant(0.0), None, NAV, KWARGS, "lattice", 1, seed=0, beta=1.5)


def test_a_dagger_round_runs_on_a_ppo_student():
    import gymnasium as gym
    from stable_baselines3 import PPO

    env = gym.make(NAV, **KWARGS)
    model = PPO("MlpPolicy", env, n_steps=64, batch_size=32, seed=0, device="cpu")
    demos = collect(NAV, KWARGS, "lattice", 1, seed=3)
    settings = {"teacher": "lattice", "episodes": 1, "rounds": 2, "beta": 0.5, "seed": 3,
                "epochs": 2, "batch_size": 64, "learning_rate": 1e-3}
    both, records = dagger(model, None, NAV, KWARGS, demos, settings, gamma=0.99)
    assert [r["round"] for r in records] == [1, 2]
    assert [r["beta"] for r in records] == [0.5, 0.25]
    assert len(both) == len(demos) + sum(r["decisions"] for r in records)
    assert both.episodes == 3
    for r in records:
        assert 0.0 <= r["teacher_share"] <= 1.0 and np.isfinite(r["action_mse"])
    env.close()


def test_agents_train_runs_dagger_rounds_in_its_warm_start(tmp_path):
    """The pretrain hyperparameter with rounds: the clone of the lattice
    planner on the costmap, one DAgger round, then PPO; pretrain.yaml
    records the round."""
    import yaml

    out = train_with_a_round(tmp_path / "run", timesteps=128, save_freq=0)
    report = yaml.safe_load((out / "pretrain.yaml").read_text())
    assert report["rounds"] == 1 and len(report["dagger"]) == 1
    round_1 = report["dagger"][0]
    assert round_1["beta"] == 0.5 and round_1["decisions"] > 0


@pytest.mark.parametrize("value, message", [
    ({"teacher": "lattice", "rounds": -1}, "rounds .* must be an integer >= 0"),
    ({"teacher": "lattice", "rounds": 1.5}, "rounds .* must be an integer >= 0"),
    ({"teacher": "lattice", "beta": 2.0}, r"beta must be a number in \[0, 1\]"),
])
def test_bad_dagger_settings_are_refused(value, message):
    from agents.pretrain import pretrain_settings

    with pytest.raises(ValueError, match=message):
        pretrain_settings(value)



def test_the_students_error_on_fields_it_never_saw(tmp_path):
    """A student trained by agents.train (one round) is held against its
    teacher on new fields; with the teacher's own run as its data the
    held-out error is a mean of squares, never negative, and the command
    writes its table."""
    import json

    from agents.held_out import main as held_out_main

    out = train_with_a_round(tmp_path / "run", timesteps=64, save_freq=64)
    table = tmp_path / "held-out.md"
    rows = held_out_main([str(out), "--checkpoint", "0", "--episodes", "1", "--seed", "7",
                               "--env-kwargs", *(f"{k}={v}" for k, v in KWARGS.items()),
                               "--out", str(table)])
    row = rows[0]
    assert row["teacher"] == "lattice" and row["decisions"] > 0
    assert row["held_out_mse"] >= 0 and row["variance"] > 0
    assert "| run | held-out error |" in table.read_text()
    assert json.loads(table.with_suffix(".json").read_text())["rows"][0]["seed"] == 7
    with pytest.raises(SystemExit):
        held_out_main([str(tmp_path / "missing")])
