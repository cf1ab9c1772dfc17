"""The Hertz benchmark's timing child and table on a small field: every
configuration is timed in every round, and the table reports what was
measured (a smoke test; the figures themselves are in the README)."""
from __future__ import annotations

import math

from physics import make_floe_field
from physics import bench


def test_timing_child_times_every_configuration_in_every_round(tmp_path):
    field, box = make_floe_field(400, concentration=0.7, alpha=1.8, mean_diameter=8.0, seed=1,
                                 velocity_std=0.03)
    path = tmp_path / "state.npz"
    bench._save_state(path, field, box)
    out = bench._timed_steps(path, 0.002, 20, threads=2)
    configs = bench._kernel_configs(2)
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
                 contacts_per_floe=0.0, dt=0.002, rebuilds=3, paired=[1.5, 1.6, 1.9]),
            dict(case="cores", kernel="serial", threads=2, rate=1.5, alone=1e8,
                 together=[8e7, 7e7], contacts_per_floe=math.nan, dt=0.002, rebuilds=0),
            dict(case="control", kernel="scalar", threads=2, rate=1.4, paired=[1.3, 1.4, 2.0],
                 contacts_per_floe=math.nan, dt=0.0, rebuilds=0)]
    text = bench.format_table(rows, 20000)
    assert "| Ā = 0.70 | parallel | 2 | 1.2e+08 | 1e+08–1.2e+08 |" in text
    assert "best / best = 1.50, same round: median 1.60, best 1.90" in text
    assert "all threads / serial kernels = 1.20" in text
    assert "give 1.50x one core" in text and "8e+07 + 7e+07" in text
    assert "runs 1.40x faster on 2 threads than on one (median of 3 rounds; range 1.30–2.00)" in text


def test_phase_benchmark_times_every_phase_and_configuration(tmp_path):
    """``python -m physics.bench phases`` on 400 floes: one row per phase
    and kernel configuration, positive times, the serial kernels' speed-up
    over themselves exactly 1, and a table that shows them."""
    result = bench.bench_phases(n=400, seed=1, passes=5, cache_dir=tmp_path, quiet=True)
    configs = bench._kernel_configs(bench.numba.config.NUMBA_NUM_THREADS)
    timed = result["rows"]
    assert len(timed) == len(bench.PHASES) * len(configs)
    assert [r["phase"] for r in timed[::len(configs)]] == [name for name, _, _ in bench.PHASES]
    for r in timed:
        assert r["seconds"] > 0.0 and math.isfinite(r["seconds"])
        if r["kernel"] == "serial":
            assert r["speedup"] == r["speedup_best"] == 1.0
    assert result["n"] == 400 and result["n_pairs"] >= 0
    text = bench.format_phases_table(result)
    assert "| list rebuild | serial | 1 |" in text and "Ā = 0.70" in text
