"""The reference agents kept in the repository (docs/agents/reference): each
loads, plays a seeded episode the same way twice, and replays through
agents.evaluate the first episodes of the benchmark's record."""
import json
from pathlib import Path

import gymnasium as gym
import pytest

pytest.importorskip("stable_baselines3")

import iceenvs  # noqa: F401
from agents import reference
from agents.benchmark import AGENT, DEFAULT_OUT

ROOT = Path(__file__).resolve().parents[2]
AGENTS = sorted(p.name for p in reference.REFERENCE_DIR.glob("*") if (p / "model.zip").is_file())
RECORD = ROOT / DEFAULT_OUT / "benchmark.json"


def _episode(agent, seed):
    env = gym.make(agent.env_id, **agent.agent_kwargs)
    obs, _ = env.reset(seed=seed)
    total, actions, done = 0.0, [], False
    while not done:
        action, _ = agent.predict(obs, deterministic=True)
        actions.append(action.tolist())
        obs, reward, terminated, truncated, _ = env.step(action)
        total += float(reward)
        done = terminated or truncated
    env.close()
    return total, actions


def test_there_are_reference_agents():
    assert AGENTS, "no reference agent under docs/agents/reference"


@pytest.mark.parametrize("name", AGENTS)
def test_a_reference_agent_loads_and_plays_a_seeded_episode_deterministically(name):
    agent = reference.load_reference(name)
    assert agent.env_id == f"iceenvs/{name}"
    first = _episode(agent, reference.EVAL_SEED)
    again = _episode(reference.load_reference(f"iceenvs/{name}"), reference.EVAL_SEED)
    assert first[1] == again[1] and first[0] == again[0]
    # it names the command that made it and how long that took
    assert "agents.train" in (reference.reference_dir(name) / "command.txt").read_text()
    assert (reference.reference_dir(name) / "training.yaml").is_file()


def test_an_id_without_an_agent_is_refused_with_those_that_have_one(tmp_path):
    with pytest.raises(FileNotFoundError, match="the reference agents: none"):
        reference.load_reference("Convergence-v0", root=tmp_path)


@pytest.mark.parametrize("name", AGENTS)
def test_evaluating_a_reference_agent_gives_the_records_first_episodes(name, tmp_path):
    from agents.evaluate import main as evaluate_main
    from agents.leaderboard import host_signature

    record = json.loads(RECORD.read_text())
    if record.get("host") != host_signature():
        pytest.skip("the record was made on another host: a DEM trajectory depends on how "
                    "its sums are rounded")
    row = next(r for r in record["rows"] if r["id"] == f"iceenvs/{name}")
    evaluate_main([str(reference.reference_dir(name)), "--seed", str(record["seed"]),
                   "--episodes", "2", "--baselines", "zero", "--out", str(tmp_path),
                   "--default-config", "--no-progress"])
    episodes = json.loads((tmp_path / "episodes.json").read_text())
    returns = [e["ret"] for e in next(v for k, v in episodes.items() if k != "zero")]
    assert returns == pytest.approx(row["first_returns"][AGENT], rel=1e-9, abs=1e-9)


def test_dropping_the_optimiser_moments_keeps_the_policy(tmp_path):
    """A kept SAC model without Adam's moments is smaller and acts exactly
    as before (the networks are untouched)."""
    import numpy as np
    from stable_baselines3 import SAC

    model = SAC("MlpPolicy", "Pendulum-v1", learning_starts=64, batch_size=32, seed=3,
                device="cpu", policy_kwargs=dict(net_arch=[32, 32]))
    model.learn(128)
    path = tmp_path / "model.zip"
    model.save(path)
    obs = np.random.default_rng(0).uniform(-1.0, 1.0, (16, 3)).astype(np.float32)
    before, _ = model.predict(obs, deterministic=True)
    assert reference.drop_optimizer_states(path, "sac") > 0
    after, _ = SAC.load(path, device="cpu").predict(obs, deterministic=True)
    np.testing.assert_array_equal(after, before)
