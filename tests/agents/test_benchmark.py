"""Shipping a reference agent and benchmarking it (agents.benchmark), on
tiny runs: the best seed by its selection episodes is kept with what
playing it needs, it replays the record's episodes, and an oversized
reference is refused."""
import json

import pytest
import yaml

pytest.importorskip("stable_baselines3")

from agents import benchmark, reference, train
from agents.rollouts import TrainedPolicy
from test_agents import ITD, TINY_PPO


@pytest.fixture(scope="module")
def seeds(tmp_path_factory):
    """Two tiny training seeds of ThicknessDistribution-v0 (the default
    configuration: the benchmark plays it)."""
    base = tmp_path_factory.mktemp("seeds")
    runs = []
    for seed in (1, 2):
        out = base / f"seed_{seed}"
        train.main(["--env", ITD, "--algo", "ppo", "--timesteps", "128", "--n-envs", "1",
                    "--seed", str(seed), "--out", str(out), "--eval-freq", "64",
                    "--eval-episodes", "1", "--save-freq", "0", "--no-progress",
                    "--hyperparams", *TINY_PPO])
        runs.append(out)
    return runs


@pytest.fixture(scope="module")
def shipped(seeds, tmp_path_factory):
    root = tmp_path_factory.mktemp("reference")
    target = benchmark.ship(seeds, episodes=2, evaluation_episodes=2, progress=False,
                            out=reference.reference_dir(ITD, root))
    return root, target


def test_the_best_seed_by_its_selection_episodes_is_kept(seeds, shipped):
    _, target = shipped
    record = json.loads((target / "seeds.json").read_text())
    scores = {s["seed"]: s["selection"]["mean"] for s in record["seeds"]}
    assert record["chosen_seed"] == max(scores, key=scores.get)
    kept = yaml.safe_load((target / "args.yaml").read_text())
    assert kept["seed"] == record["chosen_seed"]
    assert {p.name for p in target.iterdir()} <= set(reference.KEPT_FILES) | {"seeds.json"}
    assert (target / "model.zip").is_file() and (target / "training.yaml").is_file()
    # the command as anyone runs it, not with the training machine's interpreter path
    assert (target / "command.txt").read_text().startswith("python -m agents.train --env")
    # each seed's learning curve and its returns on the benchmark's episodes
    for s in record["seeds"]:
        assert s["curve"]["eval"] and len(s["returns"]) == 2


@pytest.fixture(scope="module")
def row(shipped):
    root, _ = shipped
    return benchmark.benchmark_id(ITD, episodes=2, processes=1, progress=False, root=root)


def test_a_reference_agent_plays_deterministically_and_replays_the_record(shipped, row):
    import gymnasium as gym

    root, target = shipped
    assert row["agent"]["seed"] in (1, 2)
    assert set(row["differences"]) >= {"zero", "random", "heuristic"}
    env = gym.make(ITD)
    policy = TrainedPolicy(target)
    returns = []
    for _ in range(2):
        obs, _ = env.reset(seed=reference.EVAL_SEED)
        total, done = 0.0, False
        while not done:
            action, _ = policy.predict(obs)
            obs, reward, terminated, truncated, _ = env.step(action)
            total += float(reward)
            done = terminated or truncated
        returns.append(total)
    assert returns[0] == returns[1]
    # the record's first episode, played again in this process
    assert returns[0] == pytest.approx(row["first_returns"][benchmark.AGENT][0], rel=1e-9)


def test_the_page_says_beats_or_loses_and_names_ids_without_an_agent(shipped, row, tmp_path):
    root, _ = shipped
    without = {**row, "agent": None}
    without.pop("differences")
    rows = [row, without]
    text = benchmark.markdown(dict(command="c", commit="x", date="d", episodes=2,
                                   seed=reference.EVAL_SEED, rows=rows))
    assert "no reference agent" in text
    assert any(word in text for word in ("| beats", "| loses", "| neither"))
    details = benchmark.details_markdown(dict(rows=rows))
    assert details.count("### ThicknessDistribution-v0") == 1 and "| heuristic |" in details
    benchmark.plot_curves(dict(rows=rows), tmp_path / "curves.png", root)
    assert (tmp_path / "curves.png").stat().st_size > 0


def test_a_reference_over_the_size_limit_is_refused(seeds, tmp_path, monkeypatch):
    monkeypatch.setattr(reference, "MAX_BYTES", 1000)
    with pytest.raises(ValueError, match="more than the 1000"):
        benchmark.ship(seeds[:1], episodes=2, evaluation_episodes=2, progress=False,
                       out=tmp_path / "big")


def test_records_of_other_ids_merge_in_the_order_of_the_ids(row):
    other = {**row, "id": "iceenvs/WindDrift-v0"}
    a = dict(command="a", commit="x", date="d", episodes=2, seed=reference.EVAL_SEED, rows=[row])
    b = dict(command="b", commit="y", date="e", episodes=2, seed=reference.EVAL_SEED,
             rows=[other])
    merged = benchmark.merge([a, b])
    assert [r["id"] for r in merged["rows"]] == ["iceenvs/WindDrift-v0", ITD]
    assert merged["command"] == "a` then `b" and merged["commit"] == "y"
    with pytest.raises(ValueError, match="episodes"):
        benchmark.merge([a, {**b, "episodes": 3}])


def test_a_ceiling_record_notes_the_row(tmp_path, monkeypatch):
    """A ceiling record (agents.ceiling) puts the controller's distance from
    it into the id's row; an id without one gets no note."""
    folder = tmp_path / "Convergence-v0-ceiling"
    folder.mkdir()
    (folder / "ceiling.json").write_text(json.dumps(
        {"summary": {"heuristic": {"below_ceiling": {"mean": 0.0832, "sem": 0.0024}}}}))
    monkeypatch.setattr(benchmark, "DIAGNOSTICS_DIR", tmp_path)
    note = benchmark.ceiling_note("iceenvs/Convergence-v0")
    assert "within 0.0832 ± 0.0024" in note
    assert "#why-an-agent-cannot-win-convergence-v0" in note
    assert benchmark.ceiling_note("iceenvs/WindDrift-v0") == ""


def test_an_oracle_record_notes_the_row(tmp_path, monkeypatch):
    """An oracle record (agents.oracle) puts what the true model buys beyond
    foresight of the chaos into the row, with the chaos record's resolvable
    gain where there is one."""
    folder = tmp_path / "MarginalIceZone-v0-oracle"
    folder.mkdir()
    (folder / "oracle.json").write_text(json.dumps(
        {"differences": {"oracle − chaos oracle": {"diff": 7.18, "sem": 3.0}}}))
    monkeypatch.setattr(benchmark, "DIAGNOSTICS_DIR", tmp_path)
    note = benchmark.oracle_note("iceenvs/MarginalIceZone-v0")
    assert "gains 7.18 ± 3.0 over the controller" in note and "resolve" not in note
    assert "#what-a-policy-could-gain-marginalicezone-v0" in note
    (tmp_path / "MarginalIceZone-v0-chaos").mkdir()
    (tmp_path / "MarginalIceZone-v0-chaos" / "chaos.json").write_text(
        json.dumps({"twin_std": 10.0}))
    # two standard errors of a spread of 10 over the benchmark's 40 episodes
    assert "40 episodes resolve gains of 3.2 or more" in benchmark.oracle_note(
        "iceenvs/MarginalIceZone-v0")
    assert benchmark.oracle_note("iceenvs/WindDrift-v0") == ""
