"""``python -m iceenvs.bench`` on one fast environment with short runs (a
smoke test; the figures themselves come from the full benchmark)."""
from __future__ import annotations

import json

import pytest

from iceenvs import bench


def test_sustained_benchmark_writes_the_table_and_the_json(tmp_path, capsys):
    path = tmp_path / "bench" / "environments.json"
    argv = ["--ids", "ThicknessDistribution-v0", "--seconds", "0.5", "--runs", "2",
            "--warmup", "0", "--json", str(path)]
    assert bench.main(argv) == 0
    result = json.loads(path.read_text())
    assert set(result) >= {"command", "machine", "date", "settings", "environments"}
    assert result["command"].startswith("python -m iceenvs.bench --ids ThicknessDistribution-v0")
    assert set(result["machine"]) >= {"platform", "cpu", "numba"}
    assert result["settings"]["runs"] == 2 and result["settings"]["seconds"] == 0.5
    (row,) = result["environments"]
    assert row["id"] == "iceenvs/ThicknessDistribution-v0"
    assert len(row["rates"]) == len(row["steps"]) == len(row["seconds"]) == 2
    for rate, steps, wall in zip(row["rates"], row["steps"], row["seconds"]):
        assert wall >= 0.5 and rate == pytest.approx(steps / wall)
    assert row["min"] <= row["mean"] <= row["max"] and row["std"] >= 0.0
    assert row["resets"] >= 0 and row["errors"] == 0
    assert row["unit"] == "days" and row["interval"] > 0
    table = path.with_suffix(".md").read_text()
    assert table.startswith("`python -m iceenvs.bench --ids ThicknessDistribution-v0")
    assert f"| `iceenvs/ThicknessDistribution-v0` | {row['mean']:.0f} |" in table
    out = capsys.readouterr().out
    assert "| id | steps/s (mean) | min–max | std |" in out
    assert f"| `iceenvs/ThicknessDistribution-v0` | {row['mean']:.0f} |" in out


def test_unknown_ids_are_refused(tmp_path):
    with pytest.raises(SystemExit):
        bench.main(["--ids", "NoSuchEnv-v0", "--json", str(tmp_path / "x.json")])
