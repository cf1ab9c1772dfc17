"""The warm start of PPO from a planner's decisions (agents.pretrain)."""
import gymnasium as gym
import numpy as np
import pytest
import yaml

from agents import train
from agents.pretrain import Demonstrations, fit_policy, pretrain_settings

# two episodes of 3 and 2 steps
DEMOS = Demonstrations(obs=np.zeros((5, 1)), actions=np.zeros((5, 1)),
                       rewards=[1.0, 2.0, 4.0, 1.0, 3.0],
                       episode_starts=[True, False, False, True, False])


def test_discounted_returns_of_the_demonstrations_exactly():
    # gamma 0.5: running 1, 2.5, 5.25 | 1, 3.5; to go 1 + 0.5 (2 + 0.5 4) = 3, 4, 4 | 2.5, 3
    np.testing.assert_allclose(DEMOS.running_returns(0.5), [1.0, 2.5, 5.25, 1.0, 3.5])
    np.testing.assert_allclose(DEMOS.returns_to_go(0.5), [3.0, 4.0, 4.0, 2.5, 3.0])
    np.testing.assert_allclose(DEMOS.returns_to_go(0.5, scale=2.0), [1.5, 2.0, 2.0, 1.25, 1.5])


@pytest.mark.parametrize("value, message", [
    ("swath", "must be a mapping"),
    ({"episodes": 3}, "needs a teacher"),
    ({"teacher": "swath", "epoch": 3}, r"unknown pretrain settings \['epoch'\]"),
    ({"teacher": "swath", "episodes": 0}, "episodes must be an integer >= 1"),
    ({"teacher": "swath", "learning_rate": 0}, "learning_rate must be > 0"),
    ({"teacher": "swath", "anchor": -1.0}, "anchor must be a number >= 0"),
    ({"teacher": "swath", "anchor": "strong"}, "anchor must be a number >= 0"),
])
def test_bad_settings_are_refused_with_what_is_wrong(value, message):
    with pytest.raises(ValueError, match=message):
        pretrain_settings(value)


def test_settings_get_their_defaults_and_none_means_no_warm_start():
    assert pretrain_settings(None) is None and pretrain_settings({}) is None
    settings = pretrain_settings({"teacher": "swath", "episodes": 3})
    assert settings["episodes"] == 3 and settings["seed"] == 30000 and settings["epochs"] == 50
    assert settings["anchor"] == 0.0
    hp = train.read_hyperparams("ppo", "iceenvs/ShipNavigation-v1",
                                ["pretrain={teacher: swath, episodes: 2}"])
    assert hp["pretrain"]["teacher"] == "swath" and hp["pretrain"]["episodes"] == 2
    assert "pretrain" not in train.read_hyperparams("ppo", "iceenvs/Convergence-v0")
    assert "pretrain" not in train.read_hyperparams("ppo", "iceenvs/ShipNavigation-v1",
                                                    ["pretrain=null"])
    with pytest.raises(ValueError, match="unknown teacher 'swat' for iceenvs/ShipNavigation-v1; "
                                         "valid: .*swath"):
        train.read_hyperparams("ppo", "iceenvs/ShipNavigation-v1", ["pretrain={teacher: swat}"])
    with pytest.raises(ValueError, match="made for ppo, not sac"):
        train.read_hyperparams("sac", "iceenvs/Convergence-v0", ["pretrain={teacher: zero}"])


def test_the_fit_reproduces_a_smooth_teacher_and_leaves_the_noise_alone():
    """A PPO policy fitted to actions tanh(x·w) and values x·v of 2000
    random observations: the mean squared errors fall below a tenth of the
    variances (a constant predictor's error is the variance), and the
    log standard deviation is untouched."""
    import torch
    from stable_baselines3 import PPO

    env = gym.make("Pendulum-v1")
    model = PPO("MlpPolicy", env, seed=0, device="cpu", policy_kwargs={"log_std_init": -1.0})
    rng = np.random.default_rng(0)
    x = rng.normal(size=(2000, 3)).astype(np.float32)
    actions = np.tanh(x @ np.array([[0.8], [-0.5], [0.3]]))
    values = x @ np.array([2.0, 1.0, -1.0]) + 5.0
    before = model.policy.log_std.detach().clone()
    fit = fit_policy(model.policy, x, actions, values, epochs=30, batch_size=128,
                     learning_rate=3e-3, seed=0)
    assert fit["action_mse"] < 0.1 * fit["action_variance"]
    assert fit["value_mse"] < 0.1 * fit["value_variance"]
    torch.testing.assert_close(model.policy.log_std, before, rtol=0, atol=0)
    env.close()


def test_a_policy_of_discrete_actions_is_fitted_by_the_teachers_choices():
    """A policy of three actions fitted to the choice argmax(x·W) of 2000
    random observations: it makes the teacher's choice on more than 90 %
    of them (a constant predictor: about a third), and the fit's
    negative log-likelihood falls below a constant predictor's, ln 3."""
    from stable_baselines3.common.policies import ActorCriticPolicy

    space = gym.spaces.Box(-5.0, 5.0, (3,), np.float32)
    policy = ActorCriticPolicy(space, gym.spaces.Discrete(3), lambda _: 1e-3)
    rng = np.random.default_rng(0)
    x = rng.normal(size=(2000, 3)).astype(np.float32)
    choices = np.argmax(x @ np.array([[1.0, -1.0, 0.0], [0.0, 1.0, -1.0], [0.5, 0.0, 1.0]]),
                        axis=1)
    fit = fit_policy(policy, x, choices, None, epochs=30, batch_size=128, learning_rate=3e-3,
                     seed=0)
    assert fit["action_accuracy"] > 0.9
    assert fit["action_nll"] < np.log(3.0)
    assert "action_mse" not in fit


def _anchor_run(coef: float | None):
    """PPO on Pendulum (learning rate 1e-2, 4 updates of 10 steps) with or
    without an anchor to the teacher a = 0.5; returns the policy's mean
    squared distance to the teacher before and after, and the model."""
    import torch
    from stable_baselines3 import PPO

    from agents.pretrain import BehaviourAnchor

    env = gym.make("Pendulum-v1")
    model = PPO("MlpPolicy", env, seed=0, device="cpu", n_steps=64, batch_size=64,
                learning_rate=1e-2)
    rng = np.random.default_rng(1)
    obs = np.column_stack([np.cos(th := rng.uniform(-np.pi, np.pi, 500)), np.sin(th),
                           rng.uniform(-8, 8, 500)]).astype(np.float32)
    demos = Demonstrations(obs, np.full((500, 1), 0.5), np.zeros(500), np.zeros(500, bool))

    def distance():
        with torch.no_grad():
            mean = model.policy.get_distribution(torch.as_tensor(obs)).distribution.mean
        return float(((mean - 0.5) ** 2).mean())

    before = distance()
    anchor = None if coef is None else BehaviourAnchor(model, demos, None, coef, 128, seed=0)
    model.learn(256)
    env.close()
    return before, distance(), model, anchor


def test_an_anchor_holds_ppo_to_the_teacher():
    """With a strong anchor (coefficient 100) every PPO step also pulls the
    mean action towards the teacher's: after 40 steps it is within a fifth
    of the starting squared distance; PPO alone (the same seed) is not.
    The term is logged, and once removed it no longer acts."""
    start, free, _, _ = _anchor_run(None)
    start_anchored, anchored, model, anchor = _anchor_run(100.0)
    assert start_anchored == pytest.approx(start, rel=1e-6)       # the same initial policy
    assert anchored < 0.2 * start < free
    assert 0 <= anchor.mse < start
    assert model.logger.name_to_value["train/anchor_mse"] == anchor.mse
    anchor.remove()
    params = [p.detach().clone() for p in model.policy.action_net.parameters()]
    model.policy.optimizer.zero_grad()
    for p in model.policy.parameters():
        p.grad = None
    model.policy.optimizer.step()          # no gradient and no anchor: nothing moves
    for p, q in zip(model.policy.action_net.parameters(), params):
        assert bool((p.detach() == q).all())
    with pytest.raises(ValueError, match="must be > 0"):
        type(anchor)(model, anchor.demos, None, 0.0, 128, seed=0)


def test_a_warm_started_run_starts_from_the_planner(tmp_path):
    """Two episodes of the swath planner on a short field: the run writes
    pretrain.yaml and its clone before PPO (RUN@0), whose deterministic
    actions on the planner's own observations are closer to the planner's
    than the planner's mean action is; the normalisation has seen every
    decision. PPO trains on with the anchor (one update)."""
    import pickle

    from agents.pretrain import collect
    from agents.rollouts import TrainedPolicy

    run = tmp_path / "run"
    env_kwargs = {"control": "course", "swath_frame": "goal", "swath_edge": True,
                  "course_guard": 150, "goal_distance": 200.0, "length": 500.0}
    train.main(["--env", "iceenvs/ShipNavigation-v1", "--algo", "ppo", "--timesteps", "32",
                "--n-envs", "1", "--seed", "1", "--out", str(run), "--eval-freq", "0",
                "--save-freq", "1000", "--no-progress", "--hyperparams", "n_steps=32",
                "batch_size=32", "pretrain={teacher: swath, episodes: 2, epochs: 40, anchor: 1.0}",
                "--env-kwargs", *(f"{k}={v}" for k, v in env_kwargs.items())])
    report = yaml.safe_load((run / "pretrain.yaml").read_text())
    assert report["teacher"] == "swath" and report["decisions"] > 50 and report["anchor"] == 1.0
    assert report["action_mse"] < report["action_variance"]
    with open(run / "checkpoints" / "model_vecnormalize_0_steps.pkl", "rb") as fh:
        assert pickle.load(fh).obs_rms.count >= report["decisions"]
    demos = collect("iceenvs/ShipNavigation-v1", env_kwargs, "swath", 2, 30000)
    assert len(demos) == report["decisions"]              # the same episodes again
    clone = TrainedPolicy(f"{run}", checkpoint=0).predict(demos.obs)[0]
    error = np.mean((clone - demos.actions) ** 2)
    assert error < np.mean((demos.actions - demos.actions.mean()) ** 2)


SHORT_FIELD = {"control": "course", "swath_frame": "goal", "swath_edge": True,
               "course_guard": 150, "goal_distance": 200.0, "length": 500.0, "leads": 0}


def _budgeted_run(tmp_path, minutes: float, episodes: int):
    return ["--env", "iceenvs/ShipNavigation-v1", "--algo", "ppo", "--n-envs", "1",
            "--seed", "1", "--out", str(tmp_path / "run"), "--eval-freq", "0",
            "--save-freq", "0", "--no-progress", "--minutes", f"{minutes:g}",
            "--hyperparams", "n_steps=32", "batch_size=32",
            f"pretrain={{teacher: swath, episodes: {episodes}, epochs: 2000}}",
            "--env-kwargs", *(f"{k}={v}" for k, v in SHORT_FIELD.items())]


def test_a_minutes_budget_holds_the_warm_start_and_the_training(tmp_path, capsys):
    """A warm start asked for 10 000 episodes and 2000 epochs under a
    12-second budget: it sails some episodes and stops the fit within its
    half of the budget, PPO trains on to the budget, and the whole run,
    from the making of the environments to the saved model, keeps it (the
    slack is for what follows the last step: saving and closing)."""
    import time

    budget = 12.0
    t0 = time.perf_counter()
    run = train.main(_budgeted_run(tmp_path, budget / 60, 10_000))
    wall = time.perf_counter() - t0
    report = yaml.safe_load((run / "pretrain.yaml").read_text())
    assert 1 <= report["episodes_sailed"] < report["episodes"] == 10_000
    assert report["actor_epochs"] < 2000 and report["critic_epochs"] < 2000
    assert report["budget_seconds"] == budget
    # the share is 6 s; an episode of this field takes well under a second
    assert report["collect_seconds"] + report["fit_seconds"] < 0.5 * budget + 2.0
    out = capsys.readouterr().out
    assert "within 6 s (50%) of the 0.2-minute budget" in out
    assert "training stopped by its budget of 0.2 minutes" in out
    assert (run / "model.zip").is_file()
    # main also checks the arguments on one environment before the budget starts
    assert wall < budget + 10.0, wall


def test_a_budget_too_short_for_the_warm_start_is_refused(tmp_path, capsys):
    """One demonstration does not fit in half of 0.03 s: exit status 2,
    the shortest budget that would do, and no run directory left."""
    with pytest.raises(SystemExit) as exit_info:
        train.main(_budgeted_run(tmp_path, 0.0005, 5))
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert "too short for the warm start" in err and "give at least --minutes" in err
    assert "pretrain=null" in err
    assert not (tmp_path / "run").exists()


def test_the_share_of_the_budget_is_checked():
    with pytest.raises(ValueError, match=r"share .* in \(0, 1\)"):
        pretrain_settings({"teacher": "swath", "share": 1.0})
    assert pretrain_settings({"teacher": "swath", "share": 0.25})["share"] == 0.25
