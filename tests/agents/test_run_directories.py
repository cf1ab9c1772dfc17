"""What a run directory offers beyond its final model: the evaluation's best
model with the statistics it was evaluated with (``RUN_DIR@best``), a
fine-tuned or resumed run (``--init-from``), and the verdicts of the paired
comparisons."""
import pickle

import numpy as np
import pytest
import yaml

pytest.importorskip("stable_baselines3")

from agents import train
from agents.rollouts import TrainedPolicy, compare, trained_argument, verdict
from test_agents import ITD, TINY_PPO, env_kwargs_args, observations


def _train(out, *extra, hyperparams=()):
    train.main(["--env", ITD, "--algo", "ppo", "--timesteps", "128", "--n-envs", "1",
                "--seed", "2", "--out", str(out), "--save-freq", "0", "--no-progress",
                "--hyperparams", *TINY_PPO, *env_kwargs_args(ITD), *hyperparams, *extra])
    return out


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """A tiny run evaluated every 64 steps (so that it has a best model)."""
    return _train(tmp_path_factory.mktemp("runs") / "base", "--eval-freq", "64",
                  "--eval-episodes", "1")


def test_the_best_model_is_saved_with_its_statistics_and_loads_as_at_best(run):
    assert (run / "eval" / "best_model.zip").is_file()
    assert (run / "eval" / train.BEST_STATS).is_file()
    name, path, checkpoint = trained_argument(f"agent={run}@best", ITD)
    assert (name, checkpoint) == ("agent", "best")
    best = TrainedPolicy(path, checkpoint)
    action, _ = best.predict(observations(ITD))
    assert np.all(np.isfinite(action))
    with pytest.raises(ValueError, match="NAME=RUN_DIR@best"):
        trained_argument(f"agent={run}@better")


def test_init_from_starts_with_the_sources_network_and_statistics(run, tmp_path):
    """A run of zero learning rate started from another keeps its network
    bit for bit, and its statistics start from the source's."""
    from stable_baselines3 import PPO

    out = _train(tmp_path / "tuned", "--eval-freq", "0", "--init-from", str(run),
                 hyperparams=["learning_rate=0.0"])
    source = PPO.load(run / "model.zip", device="cpu").policy.state_dict()
    tuned = PPO.load(out / "model.zip", device="cpu").policy.state_dict()
    # log_std is a parameter too; with a zero learning rate nothing moves
    for key, value in source.items():
        np.testing.assert_array_equal(value.numpy(), tuned[key].numpy(), err_msg=key)
    with open(run / "vecnormalize.pkl", "rb") as fh:
        before = pickle.load(fh).obs_rms.count
    with open(out / "vecnormalize.pkl", "rb") as fh:
        after = pickle.load(fh).obs_rms.count
    assert after > before          # the source's counts, then 128 steps more
    summary = yaml.safe_load((out / "training.yaml").read_text())
    assert summary["init_from"]["source"] == str(run)


def test_init_from_a_network_of_another_shape_is_refused(run, tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        _train(tmp_path / "other", "--eval-freq", "0", "--init-from", str(run),
               hyperparams=["policy_kwargs={net_arch: [8]}"])
    assert exit_info.value.code == 2
    assert "its network does not fit this run's" in capsys.readouterr().err
    assert not (tmp_path / "other").exists()
    with pytest.raises(SystemExit):
        _train(tmp_path / "missing", "--init-from", f"{run}@64000")
    assert "no checkpoint at 64000 steps" in capsys.readouterr().err


@pytest.mark.parametrize("diffs, expected", [
    ([1.0, 1.1, 0.9, 1.0], "beats"), ([-1.0, -1.1, -0.9, -1.0], "loses"),
    ([1.0, -1.0, 0.5, -0.4], "neither")])
def test_a_comparison_says_whether_the_policy_beats_or_loses(diffs, expected):
    policy = [dict(ret=d) for d in diffs]
    zero = [dict(ret=0.0) for _ in diffs]
    assert verdict(compare(policy, zero)) == expected
    # lower is better turns the verdict round
    flipped = {"beats": "loses", "loses": "beats", "neither": "neither"}[expected]
    metric = compare([dict(final={"x": d}) for d in diffs], [dict(final={"x": 0.0})] * 4,
                     metric="x", lower_is_better=True)
    assert verdict(metric) == flipped
