"""A new environment added by the documented steps alone: the Python block
of the Contributing page defines a throwaway environment (a module's class
with its facts and controller, and one ``register`` call) and runs the
shared checks on it. This test runs that block, then takes the environment
through the agents' evaluation and the warm-up, which no file names its id
for."""
from __future__ import annotations

import json

import gymnasium as gym
import pytest

from doc_blocks import ROOT, parse_page
from iceenvs.facts import env_facts, registered_ids

ENV_ID = "mytasks/Calm-v0"


@pytest.fixture(scope="module")
def calm():
    """The environment of the Contributing page, registered by its block
    (which also runs the shared checks), removed afterwards."""
    page = parse_page((ROOT / "docs" / "contributing.md").read_text(encoding="utf-8"),
                      "contributing.md")
    blocks = [b for b in page.blocks if b.kind == "python" and "gym.register(" in b.code]
    assert len(blocks) == 1, "the Contributing page has one block that registers its example"
    namespace: dict = {"__name__": "contributing_example"}
    exec(compile(blocks[0].code, blocks[0].id, "exec"), namespace)
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
