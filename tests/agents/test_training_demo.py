"""The training demo (``python -m agents.demo``, the end of ``make demo``):
its configuration is valid for ``agents.train``, its verdicts say what the
paired comparison says, the command trains, evaluates, prints and records
on a tiny budget, and (slow) the demo budget beats random and zero actions."""
import json

import pytest
import yaml

pytest.importorskip("stable_baselines3")

from agents import demo
from agents.train import read_hyperparams
from cli_checks import assert_refused


def report(**changes):
    """An evaluation report of one seed, as ``run_seed`` returns it."""
    summaries = {name: {"return": dict(mean=mean, sem=sem), "length": dict(mean=150.0)}
                 for name, mean, sem in (("ppo policy", 129.0, 4.0), ("random", 79.8, 9.0),
                                         ("zero", 128.0, 8.9), ("heuristic", 136.9, 3.4))}
    out = dict(env="iceenvs/Convergence-v0", episodes=20, seed=10_000, timesteps=40_000,
               training_seed=0, train_seconds=91.4, evaluate_seconds=25.2, summaries=summaries,
               comparisons={"random": dict(diff=49.2, sem=6.0, beats=True),
                            "zero": dict(diff=1.0, sem=2.0, beats=False),
                            "heuristic": dict(diff=-7.9, sem=1.5, beats=False)})
    out.update(changes)
    return out


def test_configuration_resolves_to_the_demo_hyperparameters():
    config = demo.load_config()
    hp = read_hyperparams(config["algo"], config["env"], demo.overrides(config))
    for key, value in config["hyperparams"].items():
        assert hp[key] == value
    # the rest comes from the environment's entry of ppo.yaml
    assert hp["gamma"] == 0.95 and hp["policy_kwargs"]["log_std_init"] == -1.0
    assert set(config["notes"]) <= set(demo.BASELINES)


def test_verdicts_follow_the_paired_comparison():
    notes = {"heuristic": "{timesteps} steps, about {episodes} episodes."}
    beats, ties, loses = demo.verdicts(report(), notes)
    assert beats.startswith("PPO beats random actions by +49.2 per episode (8.2 standard errors")
    assert "does not beat the zero action by more than two standard errors" in ties
    assert "scores 7.9 less per episode" in loses and "40 000 steps, about 267 episodes." in loses
    row = demo.summary_row(report())
    assert row.startswith("| 0 | 129.0 ± 4.0 | 79.8 ± 9.0 |")
    assert "+49.2 [6] ✓" in row and "+1.0 [2] ✗" in row and row.endswith("| 91 | 25 |")


def test_demo_trains_evaluates_prints_and_records(tmp_path, capsys):
    summaries = demo.main(["--timesteps", "256", "--episodes", "2", "--seeds", "3",
                           "--no-progress", "--out", str(tmp_path / "demo"),
                           "--record", str(tmp_path / "record")])
    out = capsys.readouterr().out
    assert set(summaries) == {"ppo policy", "random", "zero", "heuristic"}
    assert "| PPO |" in out and "| heuristic |" in out and "PPO " in out
    run = tmp_path / "demo" / "seed_3"
    for name in ("model.zip", "evaluation.md", "evaluation.png"):
        assert (run / name).stat().st_size > 0
    hp = yaml.safe_load((run / "hyperparams.yaml").read_text())
    assert hp["n_envs"] == 2 and hp["n_steps"] == 512
    record = json.loads((tmp_path / "record" / "seeds.json").read_text())
    (only,) = record["runs"]
    assert only["training_seed"] == 3 and set(only["comparisons"]) == set(demo.BASELINES)
    assert "--hyperparams" in only["train_command"]
    rows = [line for line in (tmp_path / "record" / "seeds.md").read_text().splitlines()
            if line.startswith("| 3 |")]
    assert len(rows) == 1


@pytest.mark.parametrize("args, words", [
    (["--timesteps", "0"], ["--timesteps", "0"]),
    (["--episodes", "1"], ["--episodes", "1"]),
    (["--seeds", "1", "1"], ["--seeds", "[1, 1]"]),
    (["--seed", "0", "--seeds", "1"], ["not allowed with"]),
])
def test_bad_arguments_are_refused_before_training(args, words, tmp_path, capsys):
    assert_refused(demo.main, args, words, tmp_path / "run", capsys)


@pytest.mark.slow
def test_demo_budget_beats_random_and_zero_actions(tmp_path):
    """One training seed with the demo's budget (about 3 minutes on two
    cores): PPO beats random and zero actions by more than two
    standard errors of the paired difference (docs/agents/demo/seeds.md:
    by 8.3 and 8.7 standard errors)."""
    demo.main(["--seed", "0", "--no-progress", "--out", str(tmp_path / "run")])
    comparisons = json.loads((tmp_path / "run" / "evaluation.json").read_text())["comparisons"]
    assert comparisons["random"]["beats"] and comparisons["zero"]["beats"]
