"""The hyperparameter search (agents.tune): a two-trial study on a short
budget writes its record, draws inside its search space, keeps its seeds
apart from the benchmark's, and refuses bad input before it starts."""
import json

import pytest
import yaml

pytest.importorskip("optuna")
pytest.importorskip("stable_baselines3")

from agents import reference, tune
from agents.train import read_hyperparams
from cli_checks import assert_refused
from test_agents import ITD, SMALL


def _study(out, *extra, hyperparams=()):
    small = [f"{k}={v}" for k, v in SMALL[ITD].items()]
    return tune.main(["--env", ITD, "--algo", "ppo", "--trials", "2", "--trial-timesteps",
                      "256", "--evaluations", "2", "--eval-episodes", "1", "--out", str(out),
                      "--no-progress", "--hyperparams", "n_envs=1", *hyperparams,
                      "--env-kwargs", *small, *extra])


def test_a_two_trial_study_writes_its_record(tmp_path):
    record = _study(tmp_path / "study")
    saved = json.loads((tmp_path / "study" / "study.json").read_text())
    assert saved == json.loads(json.dumps(record))
    assert len(saved["trials"]) == 2 and saved["counts"]["COMPLETE"] == 2
    for trial in saved["trials"]:
        # scored twice on the way (the rollouts may pass the budget), on its own seed
        assert len(trial["scores"]) >= 2 and trial["value"] == trial["scores"][-1][1]
        assert trial["train_seed"] == reference.TUNE_TRAIN_SEED + trial["number"]
        assert trial["params"]["n_steps"] in (256, 512, 1024, 2048)
        assert 1e-5 <= trial["params"]["learning_rate"] <= 3e-3
    best = max(saved["trials"], key=lambda t: t["value"])
    assert saved["best"]["number"] == best["number"]
    # best.yaml is an entry of the hyperparameter file, the drawn values in it
    entry = yaml.safe_load((tmp_path / "study" / "best.yaml").read_text())[ITD]
    assert entry["learning_rate"] == pytest.approx(best["params"]["learning_rate"])
    assert entry["env_kwargs"] == {k: v for k, v in SMALL[ITD].items()}
    for name in ("study.md", "study.png"):
        assert (tmp_path / "study" / name).stat().st_size > 0
    assert "Best trial" in (tmp_path / "study" / "study.md").read_text()
    # and agents.train takes it in place of the id's entry
    hp = read_hyperparams("ppo", ITD, conf=tmp_path / "study" / "best.yaml")
    assert hp["learning_rate"] == entry["learning_rate"] and "pretrain" not in hp


def test_a_warm_started_study_clones_before_each_trial(tmp_path):
    record = _study(tmp_path / "warm", "--warm-start",
                    hyperparams=["pretrain={teacher: zero, episodes: 1}"])
    assert record["counts"]["COMPLETE"] == 2
    assert record["base_hyperparams"]["pretrain"]["teacher"] == "zero"
    assert "from a clone of the zero (1 episodes" in (tmp_path / "warm" / "study.md").read_text()
    entry = yaml.safe_load((tmp_path / "warm" / "best.yaml").read_text())[ITD]
    assert entry["pretrain"]["teacher"] == "zero"     # --conf best.yaml warm-starts too


def test_a_conf_file_without_the_id_is_refused(tmp_path):
    conf = tmp_path / "other.yaml"
    conf.write_text("iceenvs/Other-v0: {gamma: 0.9}\n")
    with pytest.raises(ValueError, match="no entry for iceenvs/ThicknessDistribution-v0"):
        read_hyperparams("ppo", ITD, conf=conf)
    with pytest.raises(ValueError, match="cannot read"):
        read_hyperparams("ppo", ITD, conf=tmp_path / "missing.yaml")


def test_tuning_episodes_are_not_the_benchmarks():
    tuned = range(reference.TUNE_EVAL_SEED, reference.TUNE_EVAL_SEED + 1000)
    benchmark = range(reference.EVAL_SEED, reference.EVAL_SEED + reference.EVAL_EPISODES)
    assert not set(tuned) & set(benchmark)
    assert not set(range(reference.TUNE_TRAIN_SEED, reference.TUNE_TRAIN_SEED + 1000)) \
        & set(benchmark)


@pytest.mark.parametrize("argv, words", [
    (["--env", ITD, "--algo", "ppo", "--trials", "0"], "--trials must be >= 1"),
    (["--env", ITD, "--algo", "ppo", "--minutes", "-1"], "--minutes must be a positive"),
    (["--env", ITD, "--algo", "ppo", "--hyperparams", "n_stepz=3"], "unknown hyperparameters"),
    (["--env", ITD, "--algo", "a2c"], "invalid choice"),
    (["--env", ITD, "--algo", "ppo", "--warm-start", "--hyperparams", "pretrain=null"],
     "no pretrain entry"),
])
def test_bad_input_is_refused_before_a_trial(argv, words, capsys, tmp_path):
    assert_refused(tune.main, argv, [words], tmp_path / "x", capsys)


def test_sac_draws_are_valid_constructor_arguments():
    """Every SAC draw builds a model: the space's corners, through FixedTrial."""
    import gymnasium as gym
    import optuna

    from agents.train import algo_class, algo_kwargs

    env = gym.make(ITD, **SMALL[ITD])
    for params in (dict(train_freq=1, net_arch="small", learning_rate=1e-5, batch_size=64,
                        buffer_size=10_000, gamma=0.95, tau=0.005, learning_starts=100,
                        log_std_init=-3.0),
                   dict(train_freq=8, net_arch="large", learning_rate=3e-3, batch_size=512,
                        buffer_size=10_000, gamma=0.999, tau=0.05, learning_starts=5000,
                        log_std_init=0.0)):
        drawn = tune.sample_sac(optuna.trial.FixedTrial(params))
        assert drawn["gradient_steps"] == drawn["train_freq"]
        model = algo_class("sac")("MlpPolicy", env, device="cpu", **algo_kwargs(drawn))
        assert model.batch_size == params["batch_size"]
    env.close()
