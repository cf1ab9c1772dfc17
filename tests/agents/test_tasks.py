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
