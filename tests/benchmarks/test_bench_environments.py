"""``python -m benchmarks.bench_environments`` on one fast environment with short
runs (a smoke test; the figures themselves come from the full benchmark)."""
from __future__ import annotations

import json

import pytest

from benchmarks import bench_environments, harness


def test_sustained_benchmark_writes_the_table_and_the_json(tmp_path, capsys):
    path = tmp_path / "bench" / "environments.json"
    argv = ["--ids", "ThicknessDistribution-v0", "--seconds", "0.5", "--runs", "2",
            "--warmup", "0", "--json", str(path)]
    assert bench_environments.main(argv) == 0
    record = json.loads(path.read_text())
    harness.validate_record(record)
    assert set(record) >= {"command", "machine", "date", "data"}
    result = record["data"]
    assert set(result) >= {"settings", "environments"}
    assert record["command"].startswith("seaice bench environments --ids "
                                        "ThicknessDistribution-v0")
    assert set(record["machine"]) >= {"platform", "cpu", "numba"}
    assert record["machine"]["numba_threads"] == 1
    assert result["settings"]["runs"] == 2 and result["settings"]["seconds"] == 0.5
    (row,) = result["environments"]
    assert row["id"] == "iceenvs/ThicknessDistribution-v0"
    assert len(row["rates"]) == len(row["steps"]) == len(row["seconds"]) == 2
    for rate, steps, wall in zip(row["rates"], row["steps"], row["seconds"]):
        assert wall >= 0.5 and rate == pytest.approx(steps / wall)
    assert row["min"] <= row["mean"] <= row["max"] and row["std"] >= 0.0
    # runs of whole episodes: each ends with an episode's end and its reset
    assert row["resets"] >= len(row["rates"]) and row["errors"] == 0
    assert row["unit"] == "days" and row["interval"] > 0
    table = harness.render_markdown(record)
    assert "`seaice bench environments --ids ThicknessDistribution-v0" in table
    assert f"| `iceenvs/ThicknessDistribution-v0` | {row['mean']:.0f} |" in table
    out = capsys.readouterr().out
    assert "| id | steps/s (mean) | min–max | std |" in out
    assert f"| `iceenvs/ThicknessDistribution-v0` | {row['mean']:.0f} |" in out


def test_unknown_ids_are_refused(tmp_path):
    with pytest.raises(SystemExit):
        bench_environments.main(["--ids", "NoSuchEnv-v0", "--json", str(tmp_path / "x.json")])


def test_quick_option_shortens_the_runs(tmp_path):
    path = tmp_path / "environments.json"
    assert bench_environments.main(["--quick", "--quiet", "--ids", "ThicknessDistribution-v0",
                              "--json", str(path)]) == 0
    record = json.loads(path.read_text())
    assert record["data"]["quick"] is True
    assert record["data"]["settings"] == dict(bench_environments.QUICK, seed=0,
                                              warmup_steps=bench_environments.WARMUP_STEPS, threads=1)
    t = record["tables"][0]
    assert len(t["rows"]) == 1 and len(t["rows"][0]) == len(t["columns"])


def test_a_failing_environment_is_reported_not_raised(monkeypatch):
    def failing(*args, **kwargs):
        raise harness.ChildError("measure_env failed in its process:\nValueError: broken")

    monkeypatch.setattr(harness, "spawn_call", failing)
    row = bench_environments._child("iceenvs/WindDrift-v0", 1.0, 1, 0, 0.0)
    assert row == dict(id="iceenvs/WindDrift-v0", failed="ValueError: broken")
    cells = bench_environments.env_row(row)
    assert len(cells) == len(bench_environments.COLUMNS) and "failed" in cells[1]


def test_peer_table_sets_v1_beside_benchnpin_and_reads_older_records():
    peer = dict(mean=5.0, min=4.0, max=6.0, interval=0.1, version="0.1.1",
                config=dict(concentration=0.5, floes_per_episode=dict(min=120, max=140)))

    def ours(rate):
        return dict(mean=rate, min=0.8 * rate, max=1.2 * rate, interval=2.0, unit="s",
                    floes=100)

    result = dict(peer=peer, default=ours(600.0), peer_like=ours(800.0), v1=ours(60.0))
    rows = bench_environments.peer_table(result)["rows"]
    assert [r[0].split("`")[1] for r in rows] == ["ship-ice-v0", "ShipNavigation-v0",
                                                  "ShipNavigation-v0", "ShipNavigation-v1"]
    # the ratio to BenchNPIN's mean, and its range from the extreme runs
    assert rows[3][-1] == "12.0 (8.0–18.0)"
    del result["v1"]
    assert len(bench_environments.peer_table(result)["rows"]) == 3
