"""Environment arguments on the command lines (``--env-kwargs``): parsed
once, checked on one environment before anything starts, saved with the
run; and a failed start leaves no half-written run directory."""
import json

import pytest
import yaml

pytest.importorskip("stable_baselines3")

from agents import train
from agents.envs import check_env_kwargs, parse_key_values

CONVERGENCE = "iceenvs/Convergence-v0"
ITD = "iceenvs/ThicknessDistribution-v0"
TINY_PPO = ["n_steps=64", "batch_size=64", "n_epochs=2",
            "policy_kwargs={net_arch: [16, 16]}"]
ITD_SMALL = ["env_kwargs={n_classes: 60, days_per_step: 5.0, max_episode_steps: 16}"]


def test_parse_key_values():
    base = {"n_floes": 60, "kernel_params": {"r": 1.0, "s": 2.0}}
    out = parse_key_values(["n_floes=40", "target=0.85", "name=abc", "kernel_params.r=0.5",
                            "grid=[1, 2]", "nested={a: 1}"], into=base)
    assert out == {"n_floes": 40, "target": 0.85, "name": "abc", "grid": [1, 2],
                   "nested": {"a": 1}, "kernel_params": {"r": 0.5, "s": 2.0}}
    assert base == {"n_floes": 60, "kernel_params": {"r": 1.0, "s": 2.0}}   # not modified
    for bad in (["n_floes"], ["=3"], ["a..b=1"], ["x=[1"]):
        with pytest.raises(ValueError, match="--env-kwargs"):
            parse_key_values(bad)


def test_check_env_kwargs_carries_the_environment_message():
    check_env_kwargs(CONVERGENCE, {"n_floes": 40}, seed=0)
    with pytest.raises(ValueError, match="n_flos"):
        check_env_kwargs(CONVERGENCE, {"n_flos": 50})


@pytest.mark.parametrize("option", [["--env-kwargs", "n_flos=50"],
                                    ["--hyperparams", "env_kwargs.n_flos=50"]])
def test_train_rejects_a_bad_env_kwarg_before_the_run_directory(option, tmp_path, capsys):
    out = tmp_path / "runs" / "run"
    with pytest.raises(SystemExit) as exc:
        train.main(["--env", CONVERGENCE, "--algo", "ppo", "--out", str(out), *option])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "n_flos" in err and CONVERGENCE in err
    assert not (tmp_path / "runs").exists()


def test_train_saves_env_kwargs_and_evaluates_with_them(tmp_path, capsys):
    from agents.constant import main as constant_main
    from agents.evaluate import main as evaluate_main

    out = tmp_path / "run"
    train.main(["--env", CONVERGENCE, "--algo", "ppo", "--timesteps", "64", "--n-envs", "1",
                "--out", str(out), "--eval-freq", "0", "--save-freq", "0", "--no-progress",
                "--hyperparams", *TINY_PPO,
                "env_kwargs={n_floes: 60, max_episode_steps: 16}",
                "--env-kwargs", "n_floes=40"])
    hp = yaml.safe_load((out / "hyperparams.yaml").read_text())
    # --env-kwargs over --hyperparams env_kwargs, key by key
    assert hp["env_kwargs"] == {"n_floes": 40, "max_episode_steps": 16}
    assert yaml.safe_load((out / "args.yaml").read_text())["env_kwargs"] == ["n_floes=40"]
    assert (out / "model.zip").is_file()

    # the best constant action of a small search, then the run against it
    search = tmp_path / "constant.json"
    constant_main(["--env", CONVERGENCE, "--grid", "3", "--seeds", "2", "--processes", "1",
                   "--no-progress", "--out", str(search), "--env-kwargs", "n_floes=40",
                   "max_episode_steps=16"])
    report = json.loads(search.read_text())
    best = report["results"][0]["action"]
    capsys.readouterr()
    summaries = evaluate_main([str(out), "--episodes", "2", "--no-progress", "--baselines",
                               "zero", "--constant", str(search), "--out", str(tmp_path / "e")])
    assert set(summaries) == {"ppo policy", "zero", "constant"}
    table = (tmp_path / "e" / "evaluation.md").read_text()
    label = f"constant ({best[0]:.4g})"
    assert f"| {label} |" in table and table.count(label) == 2   # summary and comparison
    evaluation = json.loads((tmp_path / "e" / "evaluation.json").read_text())
    assert evaluation["constant"]["action"] == best
    assert evaluation["env_kwargs"] == {"n_floes": 40, "max_episode_steps": 16}
    assert set(evaluation["comparisons"]) == {"zero", "constant"}

    # a bad keyword for the evaluation of the run is refused the same way
    with pytest.raises(SystemExit) as exc:
        evaluate_main([str(out), "--no-progress", "--env-kwargs", "n_flos=3"])
    assert exc.value.code == 2
    assert "n_flos" in capsys.readouterr().err


def test_evaluate_baseline_rejects_a_bad_env_kwarg(tmp_path, capsys):
    from agents.evaluate import main as evaluate_main

    with pytest.raises(SystemExit) as exc:
        evaluate_main(["--baseline", "zero", "--env", CONVERGENCE, "--no-progress",
                       "--out", str(tmp_path / "e"), "--env-kwargs", "n_flos=50"])
    assert exc.value.code == 2
    assert "n_flos" in capsys.readouterr().err
    assert not (tmp_path / "e").exists()


def _fail(*args, **kwargs):
    raise RuntimeError("failing on purpose")


@pytest.mark.parametrize("step", ["make_envs", "make_model", "make_callbacks"])
def test_failed_start_removes_a_new_run_directory(step, tmp_path, monkeypatch):
    monkeypatch.setattr(train, step, _fail)
    out = tmp_path / "new" / "run"
    with pytest.raises(RuntimeError, match="on purpose"):
        train.main(["--env", ITD, "--algo", "ppo", "--timesteps", "64", "--n-envs", "1",
                    "--out", str(out), "--eval-freq", "64", "--save-freq", "0",
                    "--no-progress", "--hyperparams", *TINY_PPO, *ITD_SMALL])
    assert not (tmp_path / "new").exists()
    assert list(tmp_path.iterdir()) == []


def test_failed_forced_start_removes_only_its_artefacts(tmp_path, monkeypatch):
    monkeypatch.setattr(train, "make_callbacks", _fail)
    out = tmp_path / "run"
    out.mkdir()
    (out / "model.zip").write_text("earlier run")
    (out / "notes.txt").write_text("mine")
    with pytest.raises(RuntimeError, match="on purpose"):
        train.main(["--env", ITD, "--algo", "ppo", "--timesteps", "64", "--n-envs", "1",
                    "--out", str(out), "--force", "--eval-freq", "0", "--save-freq", "0",
                    "--no-progress", "--hyperparams", *TINY_PPO, *ITD_SMALL])
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


def test_a_run_on_soft_ice_is_evaluated_on_the_default_ice():
    """Soft ice is a training configuration: ``agents.evaluate`` leaves the
    run's ``stiffness_scale`` out unless ``--env-kwargs`` sets it again,
    and keeps everything else of the run's (how it acts and sees)."""
    from agents.evaluate import TRAINING_ONLY_KWARGS, evaluation_kwargs

    run = {"control": "course", "swath_edge": True, "stiffness_scale": 0.01}
    assert evaluation_kwargs(run) == {"control": "course", "swath_edge": True}
    assert TRAINING_ONLY_KWARGS == ("stiffness_scale",)
    # the leaderboard plays a trained run with how it acts and sees alone
    from agents.rollouts import AGENT_KWARGS

    assert not set(TRAINING_ONLY_KWARGS) & set(AGENT_KWARGS)
