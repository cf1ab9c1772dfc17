"""The planners' demonstrations as Minari datasets (agents.datasets)."""
import json

import numpy as np
import pytest

pytest.importorskip("minari")

from agents import datasets  # noqa: E402
from agents.pretrain import collect  # noqa: E402
from small_envs import SMALL  # noqa: E402

NAV = "iceenvs/ShipNavigation-v1"
KWARGS = {**SMALL[NAV], "length": 300.0, "goal_distance": 150.0}


def test_a_dataset_holds_the_teachers_episodes_and_loads_back(tmp_path):
    summary = datasets.main(["--env", NAV, "--teacher", "lattice", "--episodes", "2",
                             "--seed", "5", "--root", str(tmp_path), "--no-progress",
                             "--env-kwargs", *(f"{k}={v}" for k, v in KWARGS.items())])
    assert summary["dataset_id"] == "seaice-gym/ShipNavigation-v1/lattice-v0"
    assert json.loads((tmp_path / "lattice-v0.json").read_text())["steps"] == summary["steps"]
    dataset = datasets.load(tmp_path, summary["dataset_id"])
    assert dataset.total_episodes == 2
    # the same episodes as the warm start's demonstrations of the same seeds
    demos = datasets.demonstrations(dataset)
    teacher = collect(NAV, KWARGS, "lattice", 2, seed=5)
    np.testing.assert_array_equal(demos.obs, teacher.obs)
    np.testing.assert_array_equal(demos.actions, teacher.actions)
    np.testing.assert_array_equal(demos.episode_starts, teacher.episode_starts)
    assert demos.rewards.sum() == pytest.approx(teacher.rewards.sum(), rel=1e-12)
    assert summary["steps"] == len(teacher)
    # the environment comes back from the dataset, with its keywords
    env = dataset.recover_environment()
    assert env.unwrapped.goal_distance == 150.0
    env.close()
    # a dataset is never overwritten
    with pytest.raises(FileExistsError, match="exists"):
        datasets.write_dataset(NAV, KWARGS, "lattice", 1, 5, tmp_path, "lattice-v0")


def test_refused_arguments(tmp_path, capsys):
    with pytest.raises(ValueError, match="one part"):
        datasets.dataset_id(NAV, "a/b")
    with pytest.raises(SystemExit):
        datasets.main(["--env", NAV, "--teacher", "lattice", "--episodes", "0",
                       "--root", str(tmp_path)])
    assert "episodes must be an integer >= 1" in capsys.readouterr().err
