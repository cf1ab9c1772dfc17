"""A new environment added by the documented steps alone: the Python block
of the Contributing page defines a throwaway environment (a module's class
with its facts and controller, and one ``register`` call) and runs the
shared checks on it. This test runs that block, then takes the environment
through the agents' evaluation and the warm-up, which no file names its id
for."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import gymnasium as gym
import pytest

from doc_blocks import ROOT, parse_page
from iceenvs.facts import env_facts, registered_ids

ENV_ID = "mytasks/Calm-v0"


def example_code() -> str:
    """The Contributing page's block that defines and registers the example."""
    page = parse_page((ROOT / "docs" / "contributing.md").read_text(encoding="utf-8"),
                      "contributing.md")
    blocks = [b for b in page.blocks if b.kind == "python" and "gym.register(" in b.code]
    assert len(blocks) == 1, "the Contributing page has one block that registers its example"
    return blocks[0].code


@pytest.fixture(scope="module")
def calm():
    """The environment of the Contributing page, registered by its block
    (which also runs the shared checks), removed afterwards."""
    namespace: dict = {"__name__": "contributing_example"}
    exec(compile(example_code(), "contributing.md", "exec"), namespace)
    try:
        yield namespace
    finally:
        del gym.registry[ENV_ID]


def test_its_facts_are_found_from_the_id(calm):
    assert env_facts(ENV_ID) is calm["CalmEnv"].facts
    assert registered_ids("mytasks") == (ENV_ID,)
    assert ENV_ID not in registered_ids()       # the package's own ids are apart


def test_the_agents_evaluate_it_against_its_heuristic(calm, tmp_path):
    pytest.importorskip("stable_baselines3")
    from agents.evaluate import main

    summaries = main(["--baseline", "heuristic", "--env", ENV_ID, "--episodes", "2",
                      "--env-kwargs", "n_floes=30", "max_episode_steps=6", "--out",
                      str(tmp_path), "--no-progress"])
    stats = summaries["heuristic"]
    assert stats["return"]["n"] == 2 and stats["length"]["mean"] == 6
    # six rewards in (0, 1]
    assert 0.0 < stats["return"]["mean"] <= 6.0
    report = json.loads((tmp_path / "evaluation.json").read_text())
    assert report["main_metric"] == "u_x" and "u_x" in stats


def test_the_warm_up_builds_it_small(calm):
    from iceenvs.warmup import warm_env

    assert warm_env(ENV_ID, steps=3) == ""        # no fall-back to the default size


def test_an_environment_without_facts_is_named_in_the_error(calm):
    class Bare(calm["CalmEnv"]):
        facts = None

    gym.register(id="mytasks/Bare-v0", entry_point=Bare)
    try:
        with pytest.raises(ValueError, match="mytasks/Bare-v0 declares no facts"):
            env_facts("mytasks/Bare-v0")
    finally:
        del gym.registry["mytasks/Bare-v0"]


def test_the_commands_of_the_page_train_and_evaluate_it(tmp_path):
    """``module:id`` on the command line: the example saved as calm.py, as
    the page says, then evaluated and trained for a few steps in new
    processes that import it themselves."""
    pytest.importorskip("stable_baselines3")
    (tmp_path / "calm.py").write_text(example_code())
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), str(ROOT)]),
               SEAICE_QUIET="1")
    evaluate = subprocess.run(
        [sys.executable, "-m", "agents.evaluate", "--baseline", "heuristic", "--env",
         f"calm:{ENV_ID}", "--episodes", "1", "--env-kwargs", "n_floes=30",
         "max_episode_steps=4", "--out", str(tmp_path / "eval"), "--no-progress"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert evaluate.returncode == 0, evaluate.stderr[-3000:]
    assert json.loads((tmp_path / "eval" / "evaluation.json").read_text())["episodes"] == 1
    train = subprocess.run(
        [sys.executable, "-m", "agents.train", "--env", f"calm:{ENV_ID}", "--algo", "ppo",
         "--timesteps", "64", "--n-envs", "2", "--eval-freq", "0", "--save-freq", "0",
         "--hyperparams", "n_steps=32", "batch_size=32", "n_epochs=1",
         "--env-kwargs", "n_floes=30", "max_episode_steps=8",
         "--out", str(tmp_path / "run"), "--no-progress"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert train.returncode == 0, train.stderr[-3000:]
    assert (tmp_path / "run" / "model.zip").is_file()
    header = (tmp_path / "run" / "metrics.csv").read_text().splitlines()[0]
    assert "final_u_x" in header          # its facts' metrics are logged
