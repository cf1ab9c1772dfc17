"""``python -m benchmarks.vector --quick``: every way of stepping and of
training runs and lands in the record (a smoke test; the figures come from
the full benchmark)."""
from __future__ import annotations

import json

import pytest

from benchmarks import harness, vector

pytest.importorskip("stable_baselines3")


def test_quick_run_writes_every_configuration(tmp_path, capsys):
    path = tmp_path / "vector.json"
    assert vector.main(["--quick", "--quiet", "--ids", "ShipNavigation-v0", "--json",
                        str(path)]) == 0
    record = json.loads(path.read_text())
    harness.validate_record(record)
    data = record["data"]
    assert data["settings"]["sizes"] == [2] and data["settings"]["small"]
    modes = {(r["mode"], r["n"]) for r in data["stepping"]}
    assert modes == {("single", 1), ("sync", 2), ("subproc", 2), ("native", 2)}
    for r in data["stepping"] + data["training"]:
        assert r["min"] <= r["mean"] <= r["max"] and r["min"] > 0
    # the quick run trains without worker processes
    assert {r["mode"] for r in data["training"]} == {"sync", "native"}
    phases = data["phases"]
    for case in ("single", "empty", "native"):
        assert phases[case]["engine_ms"] > 0 and phases[case]["rest_ms"] > 0
    text = harness.render_markdown(record)
    assert "| N | single (1 core) | SyncVectorEnv (1 core) |" in text
    assert "where the time of a step goes" in text


def test_an_environment_without_a_native_vector_env_is_refused(capsys):
    with pytest.raises(SystemExit):
        vector.main(["--ids", "ThicknessDistribution-v0", "--no-json"])
    assert "has no native vector environment" in capsys.readouterr().err
