"""The feature extractors for map observations (agents.extractors), their
choice from a hyperparameter file, the normalisation of maps, and a PPO run
of the costmap recipe (agents/hyperparams/ppo-costmap.yaml) on the small
instance of its environment, warm start included."""
import io

import gymnasium as gym
import numpy as np
import pytest
import yaml

pytest.importorskip("stable_baselines3")

import torch
from stable_baselines3 import PPO, SAC
from stable_baselines3.common.preprocessing import preprocess_obs

from agents import train
from agents.envs import normalize_for_space
from agents.extractors import (DEFAULT_LAYERS, CostmapCNN, CostmapCombined, conv_output_shape,
                               extractor_class)
from agents.observations import as_float32, length, stack, take
from small_envs import SMALL

CONF = train.HYPERPARAMS_DIR / "ppo-costmap.yaml"
#: the environment of the costmap recipe: the one entry of its file
ENV_ID = next(iter(yaml.safe_load(CONF.read_text())))
MAP = gym.spaces.Box(0.0, 5.0, (3, 64, 40), dtype=np.float32)     # ShipNavigation-v1's default
VECTOR = gym.spaces.Box(-1.0, 1.0, (7,), dtype=np.float32)
TWO_MB = 2_000_000


def conv_params(channels_in, layers):
    """Weights and biases of the convolutions of ``layers``."""
    total = 0
    for out, k, _ in layers:
        total += channels_in * out * k * k + out
        channels_in = out
    return total


def linear_params(n_in, n_out):
    return n_in * n_out + n_out


def test_costmap_cnn_shrinks_the_map_to_8_by_5_cells_and_counts_its_parameters():
    cnn = CostmapCNN(MAP, features_dim=128)
    x = torch.as_tensor(np.random.default_rng(0).uniform(0, 5, (4, 3, 64, 40)),
                        dtype=torch.float32)
    # the convolutions alone: 64 × 40 halved three times keeps the proportions
    assert tuple(cnn.cnn[:-1](x).shape) == (4, 16, 8, 5) == (4, *conv_output_shape((3, 64, 40),
                                                                                   DEFAULT_LAYERS))
    out = cnn(x)
    assert tuple(out.shape) == (4, 128) and cnn.features_dim == 128
    assert bool((out >= 0).all())                                   # after a ReLU
    expected = conv_params(3, DEFAULT_LAYERS) + linear_params(16 * 8 * 5, 128)
    assert expected == 97_680
    assert sum(p.numel() for p in cnn.parameters()) == expected
    # an odd size rounds up at each halving
    assert conv_output_shape((2, 65, 41), DEFAULT_LAYERS) == (16, 9, 6)
    small = CostmapCNN(gym.spaces.Box(0.0, 5.0, (2, 65, 41), dtype=np.float32), 32)
    assert tuple(small(torch.zeros(1, 2, 65, 41)).shape) == (1, 32)


def test_costmap_combined_concatenates_the_map_features_and_the_vector():
    space = gym.spaces.Dict({"costmap": MAP, "vector": VECTOR})
    rng = np.random.default_rng(1)
    obs = {"costmap": torch.as_tensor(rng.uniform(0, 5, (3, 3, 64, 40)), dtype=torch.float32),
           "vector": torch.as_tensor(rng.uniform(-1, 1, (3, 7)), dtype=torch.float32)}
    flat = CostmapCombined(space, cnn_dim=32)
    out = flat(obs)
    assert flat.features_dim == 32 + 7 and tuple(out.shape) == (3, 39)
    # the vector passes as it is; the map's part is its CNN's features
    map_part = flat.extractors["costmap"](obs["costmap"])
    assert torch.equal(out, torch.cat([map_part, obs["vector"]], dim=1))
    mlp = CostmapCombined(space, cnn_dim=32, vector_dim=16)
    assert mlp.features_dim == 48 and tuple(mlp(obs).shape) == (3, 48)
    assert sum(p.numel() for p in mlp.parameters()) == (
        conv_params(3, DEFAULT_LAYERS) + linear_params(640, 32) + linear_params(7, 16))


@pytest.mark.parametrize("make,match", [
    (lambda: CostmapCNN(VECTOR), "channels, rows, columns"),
    (lambda: CostmapCNN(gym.spaces.Box(0, 255, (3, 64, 40), dtype=np.uint8)), "uint8"),
    (lambda: CostmapCNN(gym.spaces.Dict({"costmap": MAP})), "channels, rows, columns"),
    (lambda: CostmapCNN(MAP, features_dim=0), "features_dim"),
    (lambda: CostmapCNN(MAP, layers=[(16, 4, 2)]), "odd kernels"),
    (lambda: CostmapCNN(MAP, layers=[(16, 3)]), "triples"),
    (lambda: CostmapCNN(MAP, layers=[]), "triples"),
    (lambda: CostmapCNN(MAP, layers="abc"), "triples"),
    (lambda: CostmapCombined(MAP), "Dict"),
    (lambda: CostmapCombined(gym.spaces.Dict({"vector": VECTOR})), "needs a map"),
    (lambda: CostmapCombined(gym.spaces.Dict({"costmap": MAP, "n": gym.spaces.Discrete(3)})),
     "not a Box"),
    (lambda: CostmapCombined(gym.spaces.Dict({"costmap": MAP, "vector": VECTOR}),
                             vector_dim=-1), "vector_dim"),
])
def test_bad_spaces_and_arguments_are_refused(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_the_map_reaches_the_network_unscaled():
    """SB3 divides by 255 only an image space (uint8, bounds 0 and 255): a
    float map goes to the extractor as it is."""
    x = torch.as_tensor(np.random.default_rng(2).uniform(0, 5, (2, 3, 64, 40)),
                        dtype=torch.float32)
    assert torch.equal(preprocess_obs(x, MAP, normalize_images=True), x)
    space = gym.spaces.Dict({"costmap": MAP, "vector": VECTOR})
    both = preprocess_obs({"costmap": x, "vector": torch.zeros(2, 7)}, space,
                          normalize_images=True)
    assert torch.equal(both["costmap"], x)


def test_maps_are_left_out_of_the_observation_statistics():
    assert normalize_for_space({"norm_obs": True, "norm_reward": True}, MAP) == \
        {"norm_obs": False, "norm_reward": True}
    space = gym.spaces.Dict({"costmap": MAP, "vector": VECTOR})
    assert normalize_for_space({"norm_reward": True}, space) == \
        {"norm_reward": True, "norm_obs_keys": ["vector"]}
    # keys named are kept; no observation normalisation stays none
    assert normalize_for_space({"norm_obs_keys": ["costmap", "vector"]}, space) == \
        {"norm_obs_keys": ["costmap", "vector"]}
    assert normalize_for_space({"norm_obs": False}, space) == {"norm_obs": False}
    assert normalize_for_space({}, gym.spaces.Dict({"costmap": MAP})) == {"norm_obs": False}
    assert normalize_for_space({"norm_obs": True}, VECTOR) == {"norm_obs": True}


def test_extractors_are_named_in_the_hyperparameters():
    assert extractor_class("CostmapCombined") is CostmapCombined
    assert extractor_class(CostmapCNN) is CostmapCNN
    with pytest.raises(ValueError, match="unknown features_extractor_class 'os.system'"):
        extractor_class("os.system")
    hp = train.read_hyperparams("ppo", ENV_ID, conf=CONF)
    assert hp["policy"] == "MultiInputPolicy"
    kw = train.algo_kwargs(hp)
    assert kw["policy_kwargs"]["features_extractor_class"] is CostmapCombined
    assert hp["policy_kwargs"]["features_extractor_class"] == "CostmapCombined"   # as written
    with pytest.raises(ValueError, match="unknown features_extractor_class 'Nope'"):
        train.read_hyperparams("ppo", ENV_ID, ["policy_kwargs.features_extractor_class=Nope"],
                               conf=CONF)


def test_observation_batches_of_dicts():
    rows = [{"costmap": np.full((3, 2, 2), i), "vector": np.arange(3) + i} for i in range(5)]
    batch = stack(rows)
    assert batch["costmap"].dtype == np.float32 and batch["costmap"].shape == (5, 3, 2, 2)
    assert length(batch) == 5
    assert np.array_equal(take(batch, [1, 3])["vector"], [[1, 2, 3], [3, 4, 5]])
    assert np.array_equal(take(stack([r["vector"] for r in rows]), [4]), [[4, 5, 6]])
    buffer = np.zeros(2)
    assert as_float32(buffer, copy=True) is not buffer


def default_recipe_model():
    """PPO of the recipe on the environment's default costmap (no learning)."""
    hp = train.read_hyperparams("ppo", ENV_ID, conf=CONF)
    env = gym.make(ENV_ID, **hp["env_kwargs"])
    model = PPO(hp["policy"], env, seed=0, device="cpu", **train.algo_kwargs(hp))
    return model, env


def test_the_recipe_policy_counts_its_parameters_and_saves_under_2_mb():
    model, env = default_recipe_model()
    space = env.observation_space
    assert space["costmap"].shape == MAP.shape and space["costmap"].dtype == np.float32
    n_vector, n_action = space["vector"].shape[0], env.action_space.shape[0]
    features = 128 + n_vector
    heads = 2 * (linear_params(features, 64) + linear_params(64, 64))
    expected = (conv_params(3, DEFAULT_LAYERS) + linear_params(640, 128) + heads
                + linear_params(64, n_action) + linear_params(64, 1) + n_action)   # + log std
    assert sum(p.numel() for p in model.policy.parameters()) == expected
    # one step of the optimiser gives Adam its two moments per parameter, as
    # a trained model saves them: 3 × 4 bytes a parameter, stored uncompressed
    optimizer = model.policy.optimizer
    optimizer.zero_grad()
    sum((p ** 2).sum() for p in model.policy.parameters()).backward()
    optimizer.step()
    assert len(optimizer.state) == len(list(model.policy.parameters()))
    buffer = io.BytesIO()
    model.save(buffer)
    assert 12 * expected < len(buffer.getvalue()) < TWO_MB
    env.close()


def test_the_costmap_recipe_trains_with_its_warm_start(tmp_path):
    """agents.train --conf ppo-costmap.yaml on the small instance: the clone
    of the swath planner from one episode, then 256 steps of PPO; the run
    keeps the map out of its statistics, saves under 2 MB and plays."""
    from agents.rollouts import TrainedPolicy

    out = tmp_path / "run"
    env_kwargs = [f"{k}={v}" for k, v in SMALL[ENV_ID].items()]
    train.main(["--env", ENV_ID, "--algo", "ppo", "--conf", CONF.name, "--timesteps", "256",
                "--n-envs", "1", "--seed", "0", "--out", str(out), "--no-progress",
                "--eval-freq", "0", "--save-freq", "0",
                "--hyperparams", "n_steps=128", "batch_size=64", "n_epochs=2",
                "pretrain.episodes=1", "pretrain.epochs=20", "--env-kwargs", *env_kwargs])
    summary = yaml.safe_load((out / "training.yaml").read_text())
    assert summary["steps"] == 256 and summary["stopped_by"] == "steps"
    report = yaml.safe_load((out / "pretrain.yaml").read_text())
    assert report["episodes_sailed"] == 1 and report["decisions"] > 0
    # the clone, fitted through the CNN, follows the planner: its error is
    # well below the spread of the planner's actions (0.12 of it here)
    assert report["action_mse"] < 0.5 * report["action_variance"]
    # the anchor kept the demonstrations (dicts of maps and vectors) in PPO's loss
    progress = (out / "logs" / "progress.csv").read_text().splitlines()
    column = progress[0].split(",").index("train/anchor_mse")
    assert any(row.split(",")[column] not in ("", "nan") for row in progress[1:])
    assert (out / "model.zip").stat().st_size < TWO_MB
    policy = TrainedPolicy(out)
    assert policy.normalization.norm_obs_keys == ["vector"]
    assert set(policy.normalization.obs_rms) == {"vector"}
    env = gym.make(ENV_ID, **policy.env_kwargs)
    obs, _ = env.reset(seed=5)
    action, _ = policy.predict(obs)
    assert env.action_space.contains(np.asarray(action, dtype=np.float32))
    env.close()


def test_sac_trains_with_the_costmap_cnn():
    """SAC on the map alone (obs_type="costmap"): actor and critics each
    with their own CNN; a replay buffer of a few hundred maps."""
    env = gym.make(ENV_ID, obs_type="costmap", **SMALL[ENV_ID])
    model = SAC("MlpPolicy", env, seed=0, device="cpu", buffer_size=300, learning_starts=100,
                batch_size=32, policy_kwargs=dict(features_extractor_class=CostmapCNN,
                                                  features_extractor_kwargs=dict(
                                                      features_dim=64),
                                                  net_arch=[32, 32]))
    before = [p.detach().clone() for p in model.actor.features_extractor.parameters()]
    model.learn(200)
    assert model.num_timesteps == 200
    after = list(model.actor.features_extractor.parameters())
    assert any(not torch.equal(a, b) for a, b in zip(before, after))    # the CNN learnt
    env.close()


def test_a_tuning_trial_keeps_the_extractor_of_its_entry():
    from agents.tune import trial_hyperparams

    base = train.read_hyperparams("ppo", ENV_ID, conf=CONF)
    drawn = dict(gamma=0.95, policy_kwargs=dict(net_arch=dict(pi=[128, 128], vf=[128, 128]),
                                                 log_std_init=-1.0))
    hp = trial_hyperparams(base, drawn)
    assert hp["gamma"] == 0.95 and hp["policy_kwargs"]["log_std_init"] == -1.0
    assert hp["policy_kwargs"]["net_arch"] == drawn["policy_kwargs"]["net_arch"]
    assert hp["policy_kwargs"]["features_extractor_class"] == "CostmapCombined"
    assert hp["policy_kwargs"]["features_extractor_kwargs"] == {"cnn_dim": 128, "vector_dim": 0}
