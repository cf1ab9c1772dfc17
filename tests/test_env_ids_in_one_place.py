"""Each environment id is named in code only where it belongs: its own
module, the registration (``iceenvs/__init__.py``) and the rewards. Every
other piece of code reads ids from the registry and facts from
:class:`iceenvs.facts.EnvFacts`, so that adding an environment touches no
table elsewhere. Prose (docstrings, help texts that give an example) is not
code: the check looks for string constants that *are* an id."""
from __future__ import annotations

import ast
from pathlib import Path

import gymnasium as gym
import pytest

from iceenvs import ENV_IDS

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("physics", "iceenvs", "agents", "seaice_gym", "benchmarks")
#: besides an id's own module: the registration and the reward functions
SHARED = {"iceenvs/__init__.py", "iceenvs/rewards.py"}
#: benchmark experiments about given environments by design: the timing
#: against BenchNPIN's ship-ice-v0 (ShipNavigation-v0) and the study of the
#: stiffness_scale option (WindDrift-v0, Convergence-v0); the vector
#: environments timed on a ship task, the pressured ship task and a
#: wind-driven one; the long ship channel of the resting-floe benchmark; the
#: ship tasks whose vector environments and training the scaling suite times;
#: the ship task whose step and training the where_time_goes suite breaks down; the ship
#: tasks whose episodes the free_drift suite runs under each engine step;
#: the ceiling of Convergence-v0's return, which its rate limit sets
EXPERIMENTS = {"agents/ceiling.py": {"iceenvs/Convergence-v0"},
               "benchmarks/bench_environments.py": {"iceenvs/ShipNavigation-v0",
                                             "iceenvs/ShipNavigation-v1",
                                             "iceenvs/WindDrift-v0", "iceenvs/Convergence-v0"},
               "benchmarks/bench_vector.py": {"iceenvs/ShipNavigation-v0", "iceenvs/ShipNavigation-v1",
                                        "iceenvs/ShipBeset-v0", "iceenvs/WindDrift-v0"},
               "benchmarks/bench_resting.py": {"iceenvs/ShipNavigation-v0"},
               "benchmarks/bench_sensors.py": {"iceenvs/ShipNavigation-v1"},
               "benchmarks/bench_scaling.py": {"iceenvs/ShipNavigation-v0", "iceenvs/ShipNavigation-v1"},
               "benchmarks/bench_where_time_goes.py": {"iceenvs/ShipNavigation-v1"},
               "benchmarks/bench_free_drift.py": {"iceenvs/ShipNavigation-v0", "iceenvs/ShipNavigation-v1",
                                            "iceenvs/ShipBeset-v0"},
               "agents/leaderboard.py": {"iceenvs/ShipNavigation-v1"}}


def _names() -> dict[str, str]:
    """Every spelling of an id in code → the id."""
    names = {env_id: env_id for env_id in ENV_IDS}
    names.update({env_id.split("/")[1]: env_id for env_id in ENV_IDS})
    return names


def _id_constants(path: Path, names: dict) -> set[str]:
    """The ids whose full id or name (``"WindDrift-v0"``) is a string
    constant of the module."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return {names[node.value] for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str)
            and node.value in names}


def test_no_code_outside_its_module_names_an_environment_id():
    names = _names()
    own = {env_id: gym.spec(env_id).entry_point.split(":")[0].replace(".", "/") + ".py"
           for env_id in ENV_IDS}
    misplaced = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            rel = path.relative_to(ROOT).as_posix()
            for env_id in _id_constants(path, names):
                if rel in SHARED or rel == own[env_id] or env_id in EXPERIMENTS.get(rel, ()):
                    continue
                misplaced.append(f"{rel} names {env_id}")
    assert not misplaced, ("environment ids named outside their module, the registration "
                           "and the rewards (read them from the registry and the facts):\n"
                           + "\n".join(misplaced))


@pytest.mark.parametrize("snippet,expected", [
    ('TABLE = {"WindDrift-v0": 1}', {"iceenvs/WindDrift-v0"}),
    ('gym.make("iceenvs/ShipBeset-v0")', {"iceenvs/ShipBeset-v0"}),
    ('"""Docstring naming WindDrift-v0 in prose."""', set()),
])
def test_the_scan_finds_ids_in_code_not_in_prose(tmp_path, snippet, expected):
    path = tmp_path / "module.py"
    path.write_text(snippet + "\n")
    assert _id_constants(path, _names()) == expected
