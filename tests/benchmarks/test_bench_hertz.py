"""The Hertz benchmarks (``benchmarks.bench_hertz``, ``benchmarks.bench_hertz_phases``)
on small fields: every configuration is timed in every round, the tables
report what was measured, and a ``--quick`` run writes a valid record (a
smoke test; the figures themselves come from the full benchmark)."""
from __future__ import annotations

import json
import math
import os

import numba
import pytest

from benchmarks import harness
from benchmarks import bench_hertz as bench
from benchmarks import bench_hertz_phases as phases
from benchmarks.harness import render_table


def test_timing_child_times_every_configuration_in_every_round(tmp_path):
    path = bench.loose_state(400, 1, tmp_path)
    out = bench._timed_steps(path, 0.002, 20, threads=2)
    configs = bench.kernel_configs(2)
    assert [label for label, _, _ in configs] == ["serial", "parallel", "parallel"]
    assert len(out["rates"]) == len(configs)
    for rates in out["rates"]:
        assert len(rates) == bench.REPEATS
        assert all(r > 0.0 and math.isfinite(r) for r in rates)
    assert out["contacts_per_floe"] >= 0.0


def test_table_reports_rows_ratios_and_ceilings():
    rows = [dict(case="Ā = 0.70", kernel="serial", threads=1, rate=1.0e8, spread=[9e7, 1e8],
                 contacts_per_floe=0.0, dt=0.002, rebuilds=3),
            dict(case="Ā = 0.70", kernel="parallel", threads=1, rate=8.0e7, spread=[7e7, 8e7],
                 contacts_per_floe=0.0, dt=0.002, rebuilds=3),
            dict(case="Ā = 0.70", kernel="parallel", threads=2, rate=1.2e8, spread=[1e8, 1.2e8],
                 contacts_per_floe=0.0005, dt=0.002, rebuilds=3, paired=[1.5, 1.6, 1.9]),
            dict(case="cores", kernel="serial", threads=2, rate=1.5, alone=1e8,
                 together=[8e7, 7e7], contacts_per_floe=math.nan, dt=0.002, rebuilds=0),
            dict(case="control", kernel="scalar", threads=2, rate=1.4, paired=[1.3, 1.4, 2.0],
                 contacts_per_floe=math.nan, dt=0.0, rebuilds=0)]
    text = render_table(bench.hertz_table(rows, 20000), heading=None)
    # a field whose floes barely touch shows its contacts, not 0.00
    assert "| Ā = 0.70 | parallel | 2 | 1.2e+08 | 1e+08–1.2e+08 | 0.0005 |" in text
    assert "best / best = 1.50, same round: median 1.60, best 1.90" in text
    assert "all threads / serial kernels = 1.20" in text
    assert "give 1.50x one core" in text and "8e+07 + 7e+07" in text
    assert "runs 1.40x faster on 2 threads than on one (median of 3 rounds; range 1.30–2.00)" in text


def test_phase_benchmark_times_every_phase_and_configuration(tmp_path):
    """``python -m benchmarks.bench_hertz_phases`` on 400 floes: one row per phase
    and kernel configuration, positive times, the serial kernels' speed-up
    over themselves exactly 1, and a table that shows them."""
    result = phases.bench_phases(n=400, seed=1, passes=5, cache_dir=tmp_path, quiet=True)
    configs = bench.kernel_configs(numba.config.NUMBA_NUM_THREADS)
    timed = result["rows"]
    assert len(timed) == len(phases.PHASES) * len(configs)
    assert [r["phase"] for r in timed[::len(configs)]] == [name for name, _, _ in phases.PHASES]
    for r in timed:
        assert r["seconds"] > 0.0 and math.isfinite(r["seconds"])
        if r["kernel"] == "serial":
            assert r["speedup"] == r["speedup_best"] == 1.0
    assert result["n"] == 400 and result["n_pairs"] >= 0
    text = render_table(phases.phases_table(result), heading=None)
    assert "| list rebuild | serial | 1 |" in text and "Ā = 0.70" in text


def _check_record(path, suite):
    record = json.loads(path.read_text(encoding="utf-8"))
    harness.validate_record(record)
    assert record["suite"] == suite and record["data"]["quick"] is True
    assert record["command"].startswith(f"seaice bench {suite} --quick")
    assert record["wall_seconds"] > 0.0
    for t in record["tables"]:
        assert t["rows"] and all(len(r) == len(t["columns"]) for r in t["rows"])
    text = harness.render_markdown(record)
    assert text.startswith(f"## {record['title']}\n")
    assert f"`{record['command']}`" in text
    return record, text


def test_quick_phases_run_writes_a_valid_record(tmp_path):
    path = tmp_path / "hertz_phases.json"
    assert phases.main(["--quick", "--quiet", "--cache-dir", str(tmp_path),
                        "--json", str(path)]) == 0
    record, text = _check_record(path, "hertz_phases")
    assert len(record["tables"][0]["rows"]) == len(record["data"]["rows"])
    assert "| kick–drift pass | serial | 1 |" in text


def test_quick_hertz_run_writes_a_valid_record(tmp_path):
    path = tmp_path / "hertz.json"
    assert bench.main(["--quick", "--quiet", "--cache-dir", str(tmp_path),
                       "--json", str(path)]) == 0
    record, text = _check_record(path, "hertz")
    cases = {r["case"] for r in record["data"]["rows"]}
    assert "Ā = 0.70" in cases and any(c.startswith("jammed") for c in cases)
    assert record["data"]["n"] == bench.QUICK["floes"]
    assert "| Ā = 0.70 | serial | 1 |" in text


@pytest.mark.slow
def test_ceilings_and_memory_are_measured(tmp_path):
    """The host ceiling (one pinned process per core), a control loop and
    the peak memory, each in fresh processes (about 20 s)."""
    path = bench.loose_state(400, 1, tmp_path)
    speeds = bench.core_speeds(path, 0.002, 5)
    assert speeds["alone"] > 0.0
    assert len(speeds["together"]) == len(os.sched_getaffinity(0))
    assert harness.machine_scaling(2, "stream", processes=1, scale=0.01)
    assert bench.peak_memory(400) > 2 ** 20
