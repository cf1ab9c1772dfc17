"""Training, saving, reloading and evaluating agents, the baselines and the
command-line errors, on tiny budgets and short episodes."""
import json
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import yaml

from iceenvs import ENV_IDS

pytest.importorskip("stable_baselines3")

from agents import train
from agents.callbacks import TimeBudgetCallback
from agents.baselines import baseline_names, make_baseline
from cli_checks import assert_refused
from iceenvs.facts import env_facts
from small_envs import SMALL as ALL_SMALL

ROOT = Path(__file__).resolve().parents[2]
CONVERGENCE = "iceenvs/Convergence-v0"
ITD = "iceenvs/ThicknessDistribution-v0"

# small instances (each environment's facts) with episodes of a few steps
# (max_episode_steps is the gymnasium.make keyword of the episode length);
# the thickness model takes 5-day steps so that 16 steps see a season change
SMALL = {env_id: {**kwargs, **({"days_per_step": 5.0} if env_id == ITD else {}),
                  "max_episode_steps": 16} for env_id, kwargs in ALL_SMALL.items()}
TINY_PPO = ["n_steps=64", "batch_size=64", "n_epochs=2", "pretrain=null",
            "policy_kwargs={net_arch: [16, 16]}"]


def env_kwargs_args(env_id):
    return [f"env_kwargs={json.dumps(SMALL[env_id])}"]


def run_train(args, **kwargs):
    return subprocess.run([sys.executable, "-m", "agents.train", *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=300, **kwargs)


def observations(env_id, n_seeds=3, steps=4):
    """A batch of raw observations from a few seeded episodes."""
    env = gym.make(env_id, **SMALL[env_id])
    space = gym.spaces.Box(env.action_space.low, env.action_space.high, seed=0)
    out = []
    for seed in range(n_seeds):
        obs, _ = env.reset(seed=seed)
        out.append(obs)
        for _ in range(steps):
            obs, *_ = env.step(space.sample())
            out.append(obs)
    env.close()
    return np.array(out)


@pytest.fixture(scope="module")
def ppo_runs(tmp_path_factory):
    """One tiny PPO run per env id, each in its own process."""
    base = tmp_path_factory.mktemp("runs")
    runs = {}
    for env_id in ENV_IDS:
        out = base / env_id.split("/")[1]
        proc = run_train(["--env", env_id, "--algo", "ppo", "--timesteps", "256",
                          "--n-envs", "1", "--seed", "3", "--out", str(out),
                          "--eval-freq", "128", "--eval-episodes", "1", "--save-freq", "128",
                          "--no-progress", "--hyperparams", *TINY_PPO,
                          *env_kwargs_args(env_id)])
        assert proc.returncode == 0, proc.stderr[-3000:]
        runs[env_id] = out
    return runs


def test_package_import_is_light():
    code = "import sys, agents; assert 'torch' not in sys.modules and " \
           "'stable_baselines3' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True)


def test_hyperparams_cover_every_env():
    for algo in train.ALGOS:
        table = yaml.safe_load((train.HYPERPARAMS_DIR / f"{algo}.yaml").read_text())
        # a default entry, and per-id entries only for registered ids
        assert "default" in table and set(table) - {"default"} <= set(ENV_IDS)
        for env_id in ENV_IDS:
            hp = train.read_hyperparams(algo, env_id)
            assert set(hp) <= set(train.valid_keys(algo))
            assert hp["n_timesteps"] >= 10_000 and hp["n_envs"] >= 1


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_ppo_run_saves_reloads_and_evaluates(ppo_runs, env_id, tmp_path):
    from agents.evaluate import TrainedPolicy, main as evaluate_main

    run = ppo_runs[env_id]
    for name in ("model.zip", "vecnormalize.pkl", "hyperparams.yaml", "args.yaml",
                 "command.txt", "metrics.csv"):
        assert (run / name).is_file(), name
    assert list((run / "checkpoints").glob("model_*_steps.zip"))
    assert (run / "eval" / "evaluations.npz").is_file()
    hp = yaml.safe_load((run / "hyperparams.yaml").read_text())
    assert hp["n_timesteps"] == 256 and hp["n_envs"] == 1 and hp["n_steps"] == 64
    assert hp["env_kwargs"] == SMALL[env_id]
    args = yaml.safe_load((run / "args.yaml").read_text())
    assert args["env"] == env_id and args["algo"] == "ppo" and args["seed"] == 3
    command = (run / "command.txt").read_text()
    assert command.startswith(f"{sys.executable} -m agents.train") and env_id in command

    # one row per finished training episode, with the task's physics metrics
    lines = (run / "metrics.csv").read_text().splitlines()
    header = lines[0].split(",")
    assert len(lines) - 1 >= 256 // 16 - 1
    for name in env_facts(env_id).metrics.values():
        assert f"final_{name}" in header and f"mean_{name}" in header
    progress = (run / "logs" / "progress.csv").read_text().splitlines()[0].split(",")
    assert "rollout/ep_rew_mean" in progress
    assert any(col.startswith("physics/final_") for col in progress)
    # TensorBoard events next to the CSV (tensorboard is in the rl extra)
    assert list((run / "logs").glob("events.out.tfevents.*"))

    # reloading gives the same deterministic actions on a batch of observations
    obs = observations(env_id)
    first = TrainedPolicy(run)
    a1, _ = first.predict(obs)
    a2, _ = TrainedPolicy(run).predict(obs)
    space = gym.make(env_id, **SMALL[env_id]).action_space
    assert a1.shape == (len(obs),) + space.shape
    np.testing.assert_array_equal(a1, a2)
    # the frozen statistics are applied: raw and normalised inputs differ
    assert not np.allclose(first.normalization.normalize_obs(obs), obs)

    summaries = evaluate_main([str(run), "--episodes", "2", "--no-progress",
                               "--out", str(tmp_path), "--seed", "7"])
    assert set(summaries) == {"ppo policy", "random", "zero", "heuristic"}
    detail = json.loads((tmp_path / "episodes.json").read_text())
    for episodes in detail.values():
        assert [e["seed"] for e in episodes] == [7, 8]
    # the two seeds are two different episodes
    zero = detail["zero"]
    assert zero[0]["final"] != zero[1]["final"]
    table = (tmp_path / "evaluation.md").read_text()
    assert "the policy (by > 2 standard errors)" in table and "| heuristic |" in table
    # each baseline's row says beats, loses or neither, as its paired difference does
    verdicts = [line.rsplit("|", 2)[-2].strip() for line in table.splitlines()
                if line.startswith("| heuristic |")]
    assert verdicts[-1] in ("beats", "loses", "neither")
    assert (tmp_path / "evaluation.png").stat().st_size > 1000


def test_evaluation_in_worker_processes_gives_the_same_episodes(ppo_runs, tmp_path):
    from agents.evaluate import main as evaluate_main

    for processes in ("1", "2"):
        evaluate_main([str(ppo_runs[CONVERGENCE]), "--episodes", "2", "--no-progress",
                       "--processes", processes, "--out", str(tmp_path / processes)])
    one, two = (json.loads((tmp_path / p / "episodes.json").read_text())
                for p in ("1", "2"))
    assert set(one) == {"ppo policy", "random", "zero", "heuristic"}
    # the same code on the same seeded episodes, only in other processes: bit for bit
    assert one == two


def test_sac_smoke(tmp_path):
    out = tmp_path / "sac"
    proc = run_train(["--env", ITD, "--algo", "sac", "--timesteps", "256", "--n-envs", "1",
                      "--out", str(out), "--eval-freq", "0", "--no-progress", "--hyperparams",
                      "learning_starts=64", "batch_size=32",
                      "policy_kwargs={net_arch: [16, 16]}", *env_kwargs_args(ITD)])
    assert proc.returncode == 0, proc.stderr[-3000:]
    from stable_baselines3 import SAC

    model = SAC.load(out / "model.zip", device="cpu")
    assert model.num_timesteps == 256
    assert (out / "vecnormalize.pkl").is_file()


def _train_in_process(tmp_path, name, seed):
    out = tmp_path / name
    train.main(["--env", ITD, "--algo", "ppo", "--timesteps", "128", "--n-envs", "2",
                "--seed", str(seed), "--out", str(out), "--eval-freq", "0", "--save-freq", "0",
                "--no-progress", "--hyperparams", *TINY_PPO, *env_kwargs_args(ITD)])
    from stable_baselines3 import PPO

    params = PPO.load(out / "model.zip", device="cpu").policy.state_dict()
    return np.concatenate([v.numpy().ravel() for v in params.values()])


def test_time_budget_stops_training_and_saves_the_model(tmp_path, capsys):
    out = tmp_path / "budget"
    train.main(["--env", ITD, "--algo", "ppo", "--timesteps", "100000", "--n-envs", "2",
                "--out", str(out), "--eval-freq", "0", "--save-freq", "0", "--no-progress",
                "--minutes", "1e-9", "--hyperparams", *TINY_PPO, *env_kwargs_args(ITD)])
    said = capsys.readouterr().out
    from stable_baselines3 import PPO

    # the budget is checked every step: the run stops within its first rollout
    steps = PPO.load(out / "model.zip", device="cpu").num_timesteps
    assert steps < 100000
    # said after the progress bar has closed, with how far the run got
    assert f"training stopped by its budget of 1e-09 minutes at {steps} of 100000 steps" in said
    summary = yaml.safe_load((out / "training.yaml").read_text())
    assert summary["stopped_by"] == "its budget of 1e-09 minutes"
    assert summary["steps"] == steps and summary["planned_steps"] == 100000
    # the wall time is kept to 0.1 s: a run stopped in its first rollout may keep 0.0
    assert summary["host"]["torch_threads"] == 1 and summary["wall_seconds"] >= 0.0
    with pytest.raises(ValueError, match="minutes"):
        TimeBudgetCallback(0.0)


def test_an_error_during_training_keeps_the_model_so_far(tmp_path, monkeypatch, capsys):
    from stable_baselines3 import PPO

    real_learn = PPO.learn

    def learn_then_fail(self, *args, **kwargs):
        real_learn(self, *args, **kwargs)
        raise RuntimeError("an environment failed")

    monkeypatch.setattr(PPO, "learn", learn_then_fail)
    out = tmp_path / "failing"
    with pytest.raises(RuntimeError, match="an environment failed"):
        train.main(["--env", ITD, "--algo", "ppo", "--timesteps", "128", "--n-envs", "2",
                    "--out", str(out), "--eval-freq", "0", "--save-freq", "0", "--no-progress",
                    "--hyperparams", *TINY_PPO, *env_kwargs_args(ITD)])
    steps = PPO.load(out / "checkpoints" / "model_128_steps.zip", device="cpu").num_timesteps
    assert steps == 128 and not (out / "model.zip").exists()
    assert (out / "checkpoints" / "model_vecnormalize_128_steps.pkl").is_file()
    assert f"{out}@128" in capsys.readouterr().err


def test_same_seed_same_training(tmp_path):
    a = _train_in_process(tmp_path, "a", seed=5)
    b = _train_in_process(tmp_path, "b", seed=5)
    c = _train_in_process(tmp_path, "c", seed=6)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


def test_a_controller_of_another_environment_is_refused_with_the_valid_names():
    env = gym.make(CONVERGENCE, **SMALL[CONVERGENCE])
    with pytest.raises(ValueError, match="unknown baseline 'reactive' for "
                                         "iceenvs/Convergence-v0; valid baselines: "
                                         "random, zero, constant, heuristic"):
        make_baseline("reactive", env)
    env.close()


@pytest.mark.parametrize("env_id,name", [(env_id, name) for env_id in ENV_IDS
                                         for name in baseline_names(env_id)])
def test_baselines_stay_in_action_space(env_id, name):
    env = gym.make(env_id, **SMALL[env_id])
    policy = make_baseline(name, env, seed=1)
    obs, _ = env.reset(seed=1)
    policy.reset(1)
    actions = []
    for _ in range(6):
        action, state = policy.predict(obs)
        assert state is None and env.action_space.contains(action)
        actions.append(action)
        obs, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            break
    if getattr(policy, "reads_environment", None):   # it steers its one environment
        with pytest.raises(ValueError, match="one environment"):
            policy.predict(np.stack([obs, obs]))
    else:
        batch, _ = policy.predict(np.stack([obs, obs]))
        assert batch.shape == (2,) + env.action_space.shape
    if name == "zero":
        assert not np.any(actions)
    elif name == "heuristic":
        assert np.any(actions)      # a controller that acts
    env.close()


def test_random_baseline_is_seeded():
    env = gym.make(ITD, **SMALL[ITD])
    obs, _ = env.reset(seed=0)
    draws = []
    for seed in (4, 4, 5):
        policy = make_baseline("random", env, seed=0)
        policy.reset(seed)
        draws.append(np.array([policy.predict(obs)[0] for _ in range(3)]))
    np.testing.assert_array_equal(draws[0], draws[1])
    assert not np.array_equal(draws[0], draws[2])


def test_unknown_baseline_lists_valid_ones():
    env = gym.make(ITD, **SMALL[ITD])
    with pytest.raises(ValueError, match="random, zero, constant, heuristic"):
        make_baseline("greedy", env)


def _episode(env, policy, seed):
    obs, _ = env.reset(seed=seed)
    policy.reset(seed)
    total = 0.0
    while True:
        obs, reward, terminated, truncated, info = env.step(policy.predict(obs)[0])
        total += reward
        if terminated or truncated:
            return total, info["physics"]


def test_convergence_heuristic_beats_zero_action():
    # a target 0.06 above the start: the zero action leaves A at the start
    # and earns about 0.4 a step (1 − 0.06/0.1); the controller converges to
    # the target within about 55 s and then holds it (about 1 a step)
    env = gym.make(CONVERGENCE, max_episode_steps=60, concentration=0.74, target=0.80)
    heuristic = make_baseline("heuristic", env)
    zero = make_baseline("zero", env)
    for seed in (0, 1, 2):
        r_h, p_h = _episode(env, heuristic, seed)
        r_z, p_z = _episode(env, zero, seed)
        assert r_h > r_z + 20.0
        assert abs(p_h["concentration"] - 0.8) < 0.01
        assert abs(p_z["concentration"] - 0.74) < 1e-9


def test_thickness_heuristic_beats_zero_action_through_the_evaluator(tmp_path):
    # one seasonal cycle: the zero action (kernel scale 1) ends near
    # W1 = 0.73 m with a return near -205; the receding-horizon controller
    # keeps g(h) closer (about -180). Run through agents.evaluate, whose
    # baselines must act on the env it steps (they read its model).
    from agents.evaluate import main as evaluate_main

    summaries = evaluate_main(["--baseline", "heuristic", "--env", ITD, "--episodes", "1",
                               "--no-progress", "--out", str(tmp_path / "h")])
    zero = evaluate_main(["--baseline", "zero", "--env", ITD, "--episodes", "1",
                          "--no-progress", "--out", str(tmp_path / "z")])
    r_h = summaries["heuristic"]["return"]["mean"]
    r_z = zero["zero"]["return"]["mean"]
    assert r_h > r_z + 10.0, (r_h, r_z)


def test_baseline_alone_from_the_command_line(tmp_path):
    from agents.evaluate import main as evaluate_main

    summaries = evaluate_main(["--baseline", "heuristic", "--env", ITD, "--episodes", "2",
                               "--no-progress", "--out", str(tmp_path), "--env-kwargs",
                               *[f"{k}={v}" for k, v in SMALL[ITD].items()]])
    assert set(summaries) == {"heuristic"}
    assert summaries["heuristic"]["length"]["mean"] == 16
    assert (tmp_path / "evaluation.md").is_file()


@pytest.mark.parametrize("argv, expected", [
    (["--env", "iceenvs/Nope-v0", "--algo", "ppo"], ENV_IDS),
    (["--env", CONVERGENCE, "--algo", "dqn"], ("ppo", "sac")),
    (["--env", CONVERGENCE, "--algo", "ppo", "--hyperparams", "n_stepz=3"],
     ("n_steps", "batch_size", "env_kwargs")),
    (["--env", CONVERGENCE, "--algo", "ppo", "--minutes", "-1"], ("--minutes",)),
])
def test_bad_input_lists_valid_choices(argv, expected, capsys, tmp_path):
    assert_refused(train.main, argv, expected, tmp_path / "run", capsys)


def test_existing_run_directory_needs_force(tmp_path):
    out = tmp_path / "run"
    out.mkdir()
    (out / "model.zip").write_text("earlier run")
    proc = run_train(["--env", CONVERGENCE, "--algo", "ppo", "--out", str(out)])
    assert proc.returncode == 2
    assert "--force" in proc.stderr
    assert (out / "model.zip").read_text() == "earlier run"


def test_learning_curve_from_progress_csv(tmp_path):
    from agents.curves import main as curves_main, read_progress

    run = tmp_path / "run"
    (run / "logs").mkdir(parents=True)
    (run / "logs" / "progress.csv").write_text(
        "time/total_timesteps,rollout/ep_rew_mean,eval/mean_reward,time/time_elapsed\n"
        "1000,-5.0,,10\n2000,-4.0,-3.5,20\n3000,-3.0,,30\n")
    (run / "evaluation.json").write_text(json.dumps({"summaries": {
        "ppo policy": {"return": {"mean": -3.0}}, "zero": {"return": {"mean": -6.0}}}}))
    progress = read_progress(run)
    assert progress["train"] == [(1000, -5.0), (2000, -4.0), (3000, -3.0)]
    assert progress["eval"] == [(2000, -3.5)]
    assert curves_main([str(run)]) == run / "learning_curve.png"
    assert (run / "learning_curve.png").stat().st_size > 1000
    with pytest.raises(SystemExit):
        curves_main([str(tmp_path / "missing")])
    # the seeds of a recipe on one figure, with their DAgger rounds
    from agents.curves import dagger_rounds

    other = tmp_path / "other"
    (other / "logs").mkdir(parents=True)
    (other / "logs" / "progress.csv").write_text((run / "logs" / "progress.csv").read_text())
    (other / "pretrain.yaml").write_text(
        "dagger:\n- {round: 1, beta: 0.5, mean_return: 10.0}\n"
        "- {round: 2, beta: 0.25, mean_return: 12.0}\n")
    assert dagger_rounds(other) == [(1, 0.5, 10.0), (2, 0.25, 12.0)] and dagger_rounds(run) == []
    with pytest.raises(SystemExit):
        curves_main([str(run), str(other)])              # several need --out
    figure = tmp_path / "seeds.png"
    assert curves_main([str(run), str(other), "--out", str(figure)]) == figure
    assert figure.stat().st_size > 1000


def test_a_checkpoint_is_evaluated_on_its_own(ppo_runs, tmp_path, capsys):
    from agents.evaluate import TrainedPolicy, main as evaluate_main

    run = ppo_runs[CONVERGENCE]
    # the run of 256 steps saves checkpoints every 128 steps
    early = TrainedPolicy(run, checkpoint=128)
    final = TrainedPolicy(run)
    obs = observations(CONVERGENCE)
    assert not np.array_equal(early.predict(obs)[0], final.predict(obs)[0])
    evaluate_main([str(run), "--checkpoint", "128", "--episodes", "1", "--baselines", "zero",
                   "--no-progress"])
    assert (run / "checkpoint_128" / "evaluation.json").is_file()
    with pytest.raises(SystemExit):
        evaluate_main([str(run), "--checkpoint", "100", "--no-progress"])
    assert "no checkpoint at 100 steps; its checkpoints: 128, 256, best" in capsys.readouterr().err
