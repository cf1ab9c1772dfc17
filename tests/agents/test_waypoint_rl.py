"""Fine-tuning a waypoint student by PPO (agents.waypoint_rl): one action is
one decision and sails the follower's steps, the fine-tuning starts from the
student and fits the critic alone first, and bad input is refused."""
import json

import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3 import PPO
from stable_baselines3.common.policies import MultiInputActorCriticPolicy

from agents.waypoint_rl import FINETUNE_RECORD, PPO_MODEL, WaypointDecisionEnv, finetune
from agents.waypoints import (LatticeWaypoints, WaypointStudent, decision_observation, main,
                              train_student)
from test_waypoints import KWARGS, NAV, sail


def test_a_decision_sails_five_steps_of_the_followers_episode():
    # the lattice's waypoints played through the decision environment: its
    # steps are the teacher's episode five steps at a time, with their rewards
    rewards, ships, _ = sail(LatticeWaypoints, 3, 0.4)
    env = WaypointDecisionEnv(gym.make(NAV, **{**KWARGS, "concentration": 0.4}))
    teacher = LatticeWaypoints(env.env)
    obs, _ = env.reset(seed=3)
    assert env.observation_space.contains(obs)
    sums, at, steps, done = [], [], 0, False
    while not done:
        obs, reward, terminated, truncated, info = env.step(teacher.label())
        steps += info["env_steps"]
        sums.append(reward)
        at.append(np.array(env.env.unwrapped.sim.ship.position))
        done = terminated or truncated
    env.close()
    assert steps == len(rewards) and len(sums) == -(-len(rewards) // 5)
    np.testing.assert_array_equal(np.array(at), ships[np.minimum(np.arange(5, 5 * len(sums) + 1, 5),
                                                                 len(ships)) - 1])
    np.testing.assert_allclose(sums, [rewards[k:k + 5].sum() for k in range(0, len(rewards), 5)],
                               rtol=1e-12, atol=1e-12)


def test_a_paired_reward_is_the_decisions_advantage_over_the_costmap_lattice():
    """With paired_horizon the costmap lattice's own decision earns exactly
    nothing (the two rollouts are the same steps), any decision earns its
    rollout's return minus the lattice's, and the episode goes on as it does
    unpaired: the rollouts leave it, and the time limit's count, as they
    were."""
    from agents.waypoints import LatticeWaypoints as Teacher

    def play(horizon, decide):
        env = WaypointDecisionEnv(gym.make(NAV, **{**KWARGS, "concentration": 0.3}),
                                  paired_horizon=horizon)
        obs, _ = env.reset(seed=4)
        out, done = [], False
        while not done:
            obs, reward, terminated, truncated, info = env.step(decide(env, len(out)))
            out.append((reward, info, obs["costmap"].copy()))
            done = terminated or truncated
        env.close()
        return out

    def teacher(env, k):
        if k == 0:
            teacher.planner = Teacher(env.env, teacher="costmap-lattice")
        return teacher.planner.label()

    own = play(15, teacher)
    assert len(own) > 3
    assert all(abs(r) < 1e-12 and abs(i["decision_return"] - i["lattice_return"]) < 1e-12
               for r, i, _ in own)
    shifts = np.random.default_rng(5).uniform(-1.0, 1.0, (200, 2))
    paired, plain = play(15, lambda env, k: shifts[k]), play(0, lambda env, k: shifts[k])
    assert len(paired) == len(plain)
    assert any(abs(r) > 1e-3 for r, _, _ in paired)      # a decision changes what follows
    for (r, info, costmap), (r0, info0, costmap0) in zip(paired, plain):
        assert r == info["decision_return"] - info["lattice_return"]
        assert info["env_reward"] == r0 == info0["env_reward"]
        np.testing.assert_array_equal(costmap, costmap0)
    with pytest.raises(ValueError, match="paired_horizon must be"):
        WaypointDecisionEnv(gym.make(NAV, **KWARGS), paired_horizon=3)


def test_unseeded_resets_sail_the_fields_in_order():
    env = WaypointDecisionEnv(gym.make(NAV, **KWARGS), field_seed=123)
    first, _ = env.reset()
    second, _ = env.reset()
    env.close()
    again = WaypointDecisionEnv(gym.make(NAV, **KWARGS))
    np.testing.assert_array_equal(again.reset(seed=123)[0]["costmap"], first["costmap"])
    np.testing.assert_array_equal(again.reset(seed=124)[0]["costmap"], second["costmap"])
    again.close()


def assert_actor_is_students(after, before):
    """The fine-tuned policy's actor (state dict ``after``) is the student's
    (``before``), weight for weight."""
    for key in after:
        if key.startswith(("pi_features_extractor.", "mlp_extractor.policy_net.", "action_net.",
                           "log_std")):
            origin = key.replace("pi_features_extractor.", "features_extractor.")
            np.testing.assert_array_equal(after[key].numpy(), before[origin].numpy(),
                                          err_msg=key)


@pytest.fixture(scope="module")
def student(tmp_path_factory):
    run = tmp_path_factory.mktemp("student")
    train_student(run, 0, progress=False, quiet=True, env_kwargs=KWARGS, episodes=1,
                  rounds=0, epochs=2, held_out_episodes=1, teacher="costmap-lattice")
    return run


def test_the_critic_is_fitted_alone_from_the_students_actor(student, tmp_path):
    # a learning rate of 0 after the critic's phase: the actor must still be
    # the student's, weight for weight, and the critic must have moved
    record = finetune(student, tmp_path / "ft", 1, progress=False, steps=48, critic_steps=24,
                      n_steps=24, batch_size=8, n_epochs=2, learning_rate=0.0,
                      critic_learning_rate=1e-3)
    assert record["decisions"] <= 48 and record["episodes"] >= 1
    assert (tmp_path / "ft" / FINETUNE_RECORD).is_file()
    old = MultiInputActorCriticPolicy.load(str(student / "student.zip"), device="cpu")
    tuned = PPO.load(str(tmp_path / "ft" / PPO_MODEL), device="cpu").policy
    before, after = old.state_dict(), tuned.state_dict()
    assert_actor_is_students(after, before)
    assert not np.array_equal(after["value_net.weight"].numpy(), before["value_net.weight"].numpy())
    # the critic has a costmap network of its own, which started as the
    # student's and was fitted apart from it
    own = [k for k in after if k.startswith("vf_features_extractor.")]
    assert own
    assert any(not np.array_equal(after[k].numpy(),
                                  after["pi_features_extractor." + k.split(".", 1)[1]].numpy())
               for k in own)
    # it plays as the student it was
    env = gym.make(NAV, **KWARGS)
    env.reset(seed=9)
    seen = decision_observation(env)
    a = WaypointStudent(env, run=str(student)).policy.predict(seen, deterministic=True)[0]
    b = WaypointStudent(env, run=str(tmp_path / "ft")).policy.predict(seen, deterministic=True)[0]
    env.close()
    np.testing.assert_array_equal(a, b)


def test_a_finetuning_run_learns(student, tmp_path, capsys):
    record = finetune(student, tmp_path / "ft", 2, progress=False, steps=48, critic_steps=24,
                      n_steps=24, batch_size=8, n_epochs=2)
    # the report gathers it apart from the training run
    assert main(["report", str(student), str(tmp_path / "ft"), "--out", str(tmp_path / "r")]) == 0
    assert (tmp_path / "r" / "waypoints.md").is_file() and (tmp_path / "r" / "finetune.png").is_file()
    gathered = json.loads((tmp_path / "r" / FINETUNE_RECORD).read_text())
    assert list(gathered.values()) == [record]
    assert f"| {record['decisions']} (24) |" in capsys.readouterr().out
    # and its student is the fine-tuned actor, as the whole model has it
    old = MultiInputActorCriticPolicy.load(str(student / "student.zip"), device="cpu").state_dict()
    new = MultiInputActorCriticPolicy.load(str(tmp_path / "ft" / "student.zip"),
                                           device="cpu").state_dict()
    tuned = PPO.load(str(tmp_path / "ft" / PPO_MODEL), device="cpu").policy.state_dict()
    for key in ("action_net.weight", "features_extractor.extractors.costmap.cnn.0.weight"):
        assert not np.array_equal(new[key].numpy(), old[key].numpy())
        np.testing.assert_array_equal(new[key].numpy(), tuned[key.replace(
            "features_extractor.", "pi_features_extractor.")].numpy())


def test_a_paired_finetuning_keeps_the_environments_returns_apart(student, tmp_path, capsys):
    record = finetune(student, tmp_path / "ft", 2, progress=False, steps=24, critic_steps=12,
                      n_steps=12, batch_size=6, n_epochs=1, gamma=0.0, paired_horizon=10)
    assert record["reward"].startswith("paired") and record["episodes"] >= 2
    assert len(record["mean_env_return_by_window"]) == len(record["mean_return_by_window"])
    # the environment's returns are those of a ship sailing a short field; the paired sums
    # are not (an advantage per decision of order one)
    assert record["mean_env_return_by_window"] != record["mean_return_by_window"]
    assert main(["report", str(tmp_path / "ft"), "--out", str(tmp_path / "r")]) == 0
    assert "| paired: advantage over the costmap lattice in 10 steps |" in capsys.readouterr().out


def test_bad_input_is_refused(student, tmp_path, capsys):
    with pytest.raises(FileNotFoundError, match="not a run"):
        finetune(tmp_path, tmp_path / "ft", 1, progress=False)
    with pytest.raises(ValueError, match="critic_steps must be"):
        finetune(student, tmp_path / "ft", 1, progress=False, steps=10, critic_steps=10)
    with pytest.raises(ValueError, match="unknown settings"):
        finetune(student, tmp_path / "ft", 1, progress=False, epochs=3)
    with pytest.raises(ValueError, match="gamma must be 0"):
        finetune(student, tmp_path / "ft", 1, progress=False, paired_horizon=15)
    with pytest.raises(ValueError, match="form 'waypoints'"):
        WaypointDecisionEnv(gym.make(NAV, **KWARGS), form="stages")
    env = WaypointDecisionEnv(gym.make(NAV, **KWARGS))
    with pytest.raises(RuntimeError, match="before reset"):
        env.step(np.zeros(2))
    env.reset(seed=1)
    with pytest.raises(ValueError, match="finite number"):
        env.step(np.array([np.nan, 0.0]))
    env.close()
    with pytest.raises(SystemExit):
        main(["finetune", "--run", str(tmp_path), "--out", str(tmp_path / "ft")])
    assert "not a run" in capsys.readouterr().err


def test_the_privileged_signals_price_the_field_ahead():
    """The critic's privileged vector: the lattice's expected reward to the
    goal line over the whole channel's progress (at most the progress left,
    less its time, since a route is no shorter than its extent along the
    channel), and the field's concentration; the student's part of the
    observation is as without it."""
    from agents.planners import LatticePlanner
    from agents.waypoint_follower import PRIVILEGED
    from agents.waypoint_rl import privileged_observation

    env = WaypointDecisionEnv(gym.make(NAV, **{**KWARGS, "concentration": 0.4}), privileged=True)
    plain = WaypointDecisionEnv(gym.make(NAV, **{**KWARGS, "concentration": 0.4}))
    obs, _ = env.reset(seed=5)
    seen, _ = plain.reset(seed=5)
    assert env.observation_space.contains(obs) and set(obs) == {*seen, PRIVILEGED}
    np.testing.assert_array_equal(obs["costmap"], seen["costmap"])
    u = env.env.unwrapped
    step = u.max_speed * u.control_interval
    w = u.reward_params["time_weight"]
    for _ in range(3):
        left = u.goal_x - float(u.sim.ship.position[0])
        assert obs[PRIVILEGED][0] <= (1.0 - w) * left / step / (u.goal_distance / step) + 1e-6
        assert obs[PRIVILEGED][1] == np.float32(u.field_concentration)
        obs, *_ = env.step(np.zeros(2))
    np.testing.assert_array_equal(
        obs[PRIVILEGED], privileged_observation(env.env, LatticePlanner(env.env, 0, show=False)))
    env.close()
    plain.close()
    with pytest.raises(TypeError, match="privileged must be True or False"):
        WaypointDecisionEnv(gym.make(NAV, **KWARGS), privileged=1)
    with pytest.raises(ValueError, match="privileged needs a reward that prices"):
        WaypointDecisionEnv(gym.make(NAV, **KWARGS, reward_params={"time_weight": 0.0}),
                            privileged=True)


def test_a_privileged_critic_reads_what_the_actor_does_not(student, tmp_path):
    """With privileged_critic the actor is the student's, weight for weight,
    and reads no privileged key; the critic's map of the privileged signals
    starts at zero (the critic starts as the plain one) and is fitted."""
    import torch

    from agents.privileged import PrivilegedCriticPolicy, PrivilegedFeatures, public_space
    from agents.waypoint_follower import PRIVILEGED

    assert main(["finetune", "--run", str(student), "--out", str(tmp_path / "ft"),
                 "--seed", "1", "--steps", "48", "--critic-steps", "24", "--n-steps", "24",
                 "--batch-size", "8", "--n-epochs", "2", "--learning-rate", "0",
                 "--privileged-critic", "--no-progress"]) == 0
    record = json.loads((tmp_path / "ft" / FINETUNE_RECORD).read_text())
    assert record["settings"]["privileged_critic"] is True
    # one explained variance per update: one of the critic alone, one after
    assert len(record["explained_variance"]) == 2
    assert all(v is None or v <= 1.0 for v in record["explained_variance"])
    model = PPO.load(str(tmp_path / "ft" / PPO_MODEL), device="cpu")
    policy = model.policy
    assert isinstance(policy, PrivilegedCriticPolicy)
    assert isinstance(policy.vf_features_extractor, PrivilegedFeatures)
    assert PRIVILEGED not in policy.pi_features_extractor.extractors
    inject = policy.vf_features_extractor.inject
    assert torch.count_nonzero(inject.weight) > 0
    before = MultiInputActorCriticPolicy.load(str(student / "student.zip"),
                                              device="cpu").state_dict()
    assert_actor_is_students(policy.state_dict(), before)
    # the map starts at zero: with both learning rates 0 it is zero still
    idle = finetune(student, tmp_path / "idle", 1, progress=False, steps=16, critic_steps=8,
                    n_steps=8, batch_size=8, n_epochs=1, learning_rate=0.0,
                    critic_learning_rate=0.0, privileged_critic=True)
    assert idle["settings"]["privileged_critic"] is True
    start = PPO.load(str(tmp_path / "idle" / PPO_MODEL), device="cpu").policy
    assert torch.count_nonzero(start.vf_features_extractor.inject.weight) == 0
    assert torch.count_nonzero(start.vf_features_extractor.inject.bias) == 0
    # a zero map adds nothing: the critic's features are its base's
    space = model.observation_space
    obs = {k: torch.as_tensor(v[None]) for k, v in space.sample().items()}
    features = PrivilegedFeatures(space, policy.features_extractor_class,
                                  policy.features_extractor_kwargs)
    with torch.no_grad():
        features.inject.weight.zero_()
        features.inject.bias.zero_()
        torch.testing.assert_close(features(obs), features.base(obs))
    with pytest.raises(ValueError, match="privileged"):
        public_space(decision_space_of(NAV))


def decision_space_of(env_id):
    from agents.waypoint_follower import decision_space

    env = gym.make(env_id, **KWARGS)
    space = decision_space(env)
    env.close()
    return space


def test_a_zero_residual_sails_the_costmap_lattice():
    """With residual an action corrects the costmap lattice's decision: a
    zero correction is the lattice's own decision, which the paired reward
    scores exactly zero, and a correction c is sailed as the lattice's
    decision plus c (clipped), as the same decision given unpaired is."""
    env = WaypointDecisionEnv(gym.make(NAV, **{**KWARGS, "concentration": 0.3}),
                              paired_horizon=15, residual=True)
    env.reset(seed=4)
    bases, done = [], False
    while not done:
        _, reward, terminated, truncated, info = env.step(np.zeros(2))
        assert reward == 0.0 and info["decision_return"] == info["lattice_return"]
        assert np.all(np.abs(info["base"]) <= 1.0)
        bases.append(info["base"])
        done = terminated or truncated
    env.close()
    assert len(bases) > 3 and any(np.any(b != 0.0) for b in bases)
    corrected = WaypointDecisionEnv(gym.make(NAV, **{**KWARGS, "concentration": 0.3}),
                                    residual=True)
    given = WaypointDecisionEnv(gym.make(NAV, **{**KWARGS, "concentration": 0.3}))
    corrected.reset(seed=4)
    given.reset(seed=4)
    for c in (np.array([0.3, -0.2]), np.array([-0.9, 0.9])):
        _, r, *_, info = corrected.step(c)
        _, r0, *_ = given.step(np.clip(info["base"] + c, -1.0, 1.0))
        assert r == r0
        np.testing.assert_array_equal(corrected.env.unwrapped.sim.ship.position,
                                      given.env.unwrapped.sim.ship.position)
    corrected.close()
    given.close()
    with pytest.raises(TypeError, match="residual must be True or False"):
        WaypointDecisionEnv(gym.make(NAV, **KWARGS), residual="yes")


def test_a_residual_finetuning_starts_as_the_costmap_lattice(student, tmp_path):
    """The residual's policy starts at zero (its last layer zeroed), so that
    with an actor's learning rate of 0 the run plays the costmap lattice's
    decisions exactly; with a rate it learns a correction. Each player
    refuses the other's runs, and the runs' loader picks the residual's."""
    from agents.rollouts import trained_policy
    from agents.waypoints import WaypointResidual

    idle = finetune(student, tmp_path / "idle", 1, progress=False, steps=16, critic_steps=8,
                    n_steps=8, batch_size=8, n_epochs=1, learning_rate=0.0, gamma=0.0,
                    paired_horizon=10, residual=True)
    assert idle["settings"]["residual"] is True and "correction" in idle["reward"]
    env = gym.make(NAV, **{**KWARGS, "concentration": 0.3})
    env.reset(seed=6)
    residual = WaypointResidual(env, run=str(tmp_path / "idle"))
    lattice = LatticeWaypoints(env, teacher="costmap-lattice")
    for _ in range(3):
        np.testing.assert_array_equal(residual.decide(None), np.clip(lattice.label(), -1, 1))
        env.step(env.action_space.sample() * 0.0)
    assert isinstance(trained_policy(tmp_path / "idle", env), WaypointResidual)
    with pytest.raises(ValueError, match="WaypointResidual"):
        WaypointStudent(env, run=str(tmp_path / "idle"))
    with pytest.raises(ValueError, match="WaypointStudent"):
        WaypointResidual(env, run=str(student))
    with pytest.raises(ValueError, match="no teacher"):
        WaypointResidual(env, run=str(tmp_path / "idle"), teacher="lattice")
    learnt = finetune(student, tmp_path / "learnt", 1, progress=False, steps=48, critic_steps=24,
                      n_steps=24, batch_size=8, n_epochs=2, residual=True)
    seen = decision_observation(env)
    correction = WaypointResidual(env, run=str(tmp_path / "learnt")).policy.predict(
        seen, deterministic=True)[0]
    env.close()
    assert learnt["decisions"] <= 48 and np.any(correction != 0.0)
    with pytest.raises(ValueError, match="residual must be True or False"):
        finetune(student, tmp_path / "bad", 1, progress=False, residual=1)
