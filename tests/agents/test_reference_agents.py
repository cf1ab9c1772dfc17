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
AGENTS = sorted(p.name for p in reference.REFERENCE_DIR.glob("*") if reference.is_reference(p))
RECORD = ROOT / DEFAULT_OUT / "benchmark.json"


def _load(name):
    """The reference agent of ``name`` and the environment it plays."""
    env = reference.reference_env(name)
    return reference.load_reference(name, environment=env), env


def _episode(agent, env, seed):
    obs, _ = env.reset(seed=seed)
    agent.reset(seed)
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
    agent, env = _load(name)
    assert agent.env_id == f"iceenvs/{name}"
    first = _episode(agent, env, reference.EVAL_SEED)
    again = _episode(*_load(f"iceenvs/{name}"), reference.EVAL_SEED)
    assert first[1] == again[1] and first[0] == again[0]
    # it names the command that made it and how long that took
    command = (reference.reference_dir(name) / "command.txt").read_text()
    assert any(f"python -m agents.{c}" in command for c in ("train", "waypoints train",
                                                             "waypoints finetune"))
    assert (reference.reference_dir(name) / "training.yaml").is_file()


def test_a_waypoint_student_is_kept_played_and_refused_without_its_environment(tmp_path):
    """A waypoint student's run ships as a reference agent (student.zip, its
    record, command.txt, training.yaml); load_reference needs the
    environment it reads, made with its costmap, and reference_env makes it."""
    from agents.benchmark import run_summary, ship
    from agents.waypoints import train_student

    run = tmp_path / "run"
    short = dict(length=300.0, goal_distance=150.0, concentration=0.2, costmap_ahead=200.0)
    train_student(run, seed=1, progress=False, quiet=True, env_kwargs=short, episodes=1,
                  rounds=0, epochs=1, held_out_episodes=1, command="python -m agents.waypoints "
                  "train --seed 1 --out run")
    summary = run_summary(run)
    assert summary["seed"] == 1 and summary["training"]["unit"] == "decisions"
    assert summary["training"]["steps"] > 0 and summary["curve"]["eval"] == []
    root = tmp_path / "reference"
    folder = reference.reference_dir("ShipNavigation-v1", root)
    ship([run], episodes=1, evaluation_episodes=1, progress=False, out=folder)
    assert reference.is_reference(folder)
    assert sorted(p.name for p in folder.iterdir()) == [
        "command.txt", "seeds.json", "student.zip", "training.yaml", "waypoints.json"]
    assert (folder / "command.txt").read_text().startswith("python -m agents.waypoints train")
    kept = json.loads((folder / "seeds.json").read_text())
    assert kept["chosen_seed"] == 1 and kept["seeds"][0]["training"]["unit"] == "decisions"
    with pytest.raises(ValueError, match="waypoint student.*reference_env"):
        reference.load_reference("ShipNavigation-v1", root=root)
    with pytest.raises(ValueError, match="costmap_ahead"):
        reference.load_reference("ShipNavigation-v1", root=root,
                                 environment=gym.make("iceenvs/ShipNavigation-v1"))
    env = reference.reference_env("ShipNavigation-v1", root=root, length=300.0,
                                  goal_distance=150.0, concentration=0.2)
    agent = reference.load_reference("ShipNavigation-v1", root=root, environment=env)
    assert agent.env_id == "iceenvs/ShipNavigation-v1"
    assert agent.agent_kwargs == {"costmap_ahead": 200.0}
    first, again = _episode(agent, env, 7), _episode(agent, env, 7)
    assert first == again and len(first[1]) > 5
    # agents.frames takes its folder as it takes a run of agents.train
    from agents.frames import main as frames_main

    episode = frames_main([str(folder), "--seed", "7", "--env-kwargs", "length=300.0",
                           "goal_distance=150.0", "--concentration", "0.2", "--every", "20",
                           "--out", str(tmp_path / "frames"), "--no-progress"])
    assert episode["summary"] and (tmp_path / "frames" / "contact_sheet.png").is_file()


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
    if reference.is_reference(reference.reference_dir(name)) and not (
            reference.reference_dir(name) / "model.zip").is_file():
        # a waypoint student: agents.evaluate takes runs of agents.train; the benchmark's
        # own player gives its episodes
        from agents.benchmark import play

        episodes = play(f"iceenvs/{name}", {AGENT: ("trained", str(
            reference.reference_dir(name)), {})}, episodes=2, seed=record["seed"],
            processes=1, progress=False)
        returns = [e["ret"] for e in episodes[AGENT]]
        assert returns == pytest.approx(row["first_returns"][AGENT], rel=1e-9, abs=1e-9)
        return
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
