"""``python -m agents.tasks``: the constant-action search and the baselines
of an environment, as a table (one fast environment, tiny grids)."""
import json

import pytest

from agents import tasks

ARGS = ["--ids", "ThicknessDistribution-v0", "--episodes", "2", "--grid", "2", "--seeds", "1",
        "--processes", "1", "--no-progress"]


def test_table_json_and_search_are_written(tmp_path):
    (row,) = tasks.main(ARGS + ["--out", str(tmp_path)])
    assert row["id"] == "iceenvs/ThicknessDistribution-v0"
    assert row["n_actions"] == 4 and len(row["best_action"]) == 2
    assert set(row["returns"]) == {"random", "zero", "heuristic", "constant"}
    # every reward is in [0, 1]: returns lie between 0 and the episode length
    for r in row["returns"].values():
        assert 0.0 <= r["mean"] <= row["steps"]
    c = row["heuristic_minus_constant"]
    assert c["diff"] == pytest.approx(row["returns"]["heuristic"]["mean"]
                                      - row["returns"]["constant"]["mean"])
    table = (tmp_path / "tasks.md").read_text()
    assert "`python -m agents.tasks --ids ThicknessDistribution-v0" in table
    assert "| `iceenvs/ThicknessDistribution-v0` | 360 |" in table
    (tmp_path / "tasks.md").unlink()
    assert tasks.main(["--render", "--out", str(tmp_path)])[0]["id"] == row["id"]
    assert (tmp_path / "tasks.md").read_text() == table
    saved = json.loads((tmp_path / "tasks.json").read_text())
    assert saved["rows"][0]["best_action"] == row["best_action"]
    assert (tmp_path / "constant_ThicknessDistribution-v0.json").is_file()


def test_reuse_skips_the_search(tmp_path, monkeypatch):
    (first,) = tasks.main(ARGS + ["--out", str(tmp_path)])

    def no_search(*args, **kwargs):
        raise AssertionError("searched again")

    monkeypatch.setattr("agents.constant.search_constant_actions", no_search)
    (again,) = tasks.main(ARGS + ["--out", str(tmp_path), "--reuse"])
    assert again["best_action"] == first["best_action"]
    assert again["returns"] == first["returns"]


def test_bad_arguments_exit(tmp_path):
    with pytest.raises(SystemExit):
        tasks.main(["--ids", "NoSuchEnv-v0", "--out", str(tmp_path)])
    with pytest.raises(SystemExit):
        tasks.main(ARGS[:2] + ["--grid", "1", "--out", str(tmp_path)])


def test_ship_row_adds_the_straight_line_and_the_planner_and_keep_merges(tmp_path):
    tasks.main(ARGS + ["--out", str(tmp_path)])
    ship = ["--ids", "ShipNavigation-v0", "--episodes", "2", "--grid", "2", "--seeds", "1",
            "--processes", "1", "--no-progress", "--out", str(tmp_path), "--keep"]
    kept, row = tasks.main(ship)                    # every row of tasks.json
    assert kept["id"] == "iceenvs/ThicknessDistribution-v0"
    assert row["planners"] == ["straight", "lattice"] and row["trained"] == []
    assert set(row["over_constant"]) == {"heuristic", "straight", "lattice"}
    for name, c in row["over_constant"].items():
        assert c["diff"] == pytest.approx(row["returns"][name]["mean"]
                                          - row["returns"]["constant"]["mean"])
    saved = json.loads((tmp_path / "tasks.json").read_text())
    assert [r["id"] for r in saved["rows"]] == ["iceenvs/ThicknessDistribution-v0",
                                                 "iceenvs/ShipNavigation-v0"]
    assert "` then `python -m agents.tasks --ids ShipNavigation-v0" in saved["command"]
    table = (tmp_path / "tasks.md").read_text()
    assert "straight: " in table and "lattice: " in table


def test_trained_and_keep_arguments_are_checked(tmp_path):
    base = ARGS + ["--out", str(tmp_path)]
    with pytest.raises(SystemExit):                       # nothing to keep yet
        tasks.main(base + ["--keep"])
    with pytest.raises(SystemExit):                       # not a run directory
        tasks.main(base + ["--trained", f"ppo={tmp_path}"])
    run = tmp_path / "run"
    run.mkdir()
    (run / "args.yaml").write_text("env: iceenvs/WindDrift-v0\n")
    with pytest.raises(SystemExit):                       # a run of another environment
        tasks.main(base + ["--trained", f"ppo={run}"])
    with pytest.raises(SystemExit):
        tasks.main(base + ["--trained", f"ppo={run}@latest"])


OWN_POLICY = """
import numpy as np

class Still:
    '''The all-zero action, written as a policy of one's own.'''
    def __init__(self, env, seed=0, scale=1.0):
        self.shape, self.scale = env.action_space.shape, float(scale)

    def reset(self, seed=None):
        pass

    def predict(self, obs, deterministic=True):
        return self.scale * np.zeros(self.shape, dtype=np.float32), None
"""


def test_a_policy_of_ones_own_joins_the_row(tmp_path):
    """--policies plays a class of a file beside the baselines, on the same
    episodes: written as the zero action, it returns what ``zero`` does,
    episode by episode, and its difference from the best constant action is
    in the row and the table."""
    path = tmp_path / "still.py"
    path.write_text(OWN_POLICY)
    ref = f"{path}:Still?scale=1"
    row, = tasks.main(ARGS + ["--out", str(tmp_path / "out"), "--policies", f"{ref},zero"])
    assert row["own"] == [ref]                        # zero is already in the row
    assert row["returns"][ref]["mean"] == pytest.approx(row["returns"]["zero"]["mean"],
                                                        rel=1e-12)
    assert row["over_constant"][ref]["diff"] == pytest.approx(
        row["returns"][ref]["mean"] - row["returns"]["constant"]["mean"])
    assert f"{ref}: " in (tmp_path / "out" / "tasks.md").read_text()


@pytest.mark.parametrize("policies, words", [
    ("no_such_module:Policy", "no_such_module"),
    ("agents.baselines:NoSuchClass", "NoSuchClass"),
    ("lattice", "unknown policy 'lattice' for iceenvs/ThicknessDistribution-v0"),
])
def test_bad_policies_are_refused_before_anything_runs(tmp_path, capsys, policies, words):
    with pytest.raises(SystemExit) as exit_info:
        tasks.main(ARGS + ["--out", str(tmp_path / "out"), "--policies", policies])
    assert exit_info.value.code == 2
    assert words in capsys.readouterr().err
    assert not (tmp_path / "out").exists()
