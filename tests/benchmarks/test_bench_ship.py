"""The ship benchmark (``benchmarks.bench_ship``) on small fields: the same floe
field with and without the ship, a cleared slot, the cost table from
known figures, and a ``--quick`` run that writes a valid record (a smoke
test; the figures themselves come from the full benchmark)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from benchmarks import harness
from benchmarks import bench_ship as bench
from benchmarks.harness import render_table


def test_field_has_a_cleared_slot_and_both_runs_start_alike():
    field, side, start, removed = bench.ship_field(400, seed=1)
    full, box = bench.HERMAN2013.floe_field(400, bench.CONCENTRATION, seed=1, velocity_std=0.03)
    assert field.n == 400 - removed and box.lx == side
    assert bench._touching(field, box, *start, bench.CLEARANCE).size == 0
    dt = bench.time_step(field)
    with_ship = bench._make_sim(field, side, start, True, False, dt)      # no overlap at start
    without = bench._make_sim(field, side, start, False, False, dt)
    assert with_ship.ship is not None and without.ship is None
    np.testing.assert_array_equal(with_ship.positions, without.positions)
    assert dt <= 0.1 * with_ship.min_contact_time


def _child(rates, builds=2):
    runs = [[dict(rate=r, rebuilds=1, **(dict(hull_builds=builds, touching=3.0, candidates=40,
                                                touch_steps=0.5, collisions=4)
                                           if ship else {})) for r in rates[k]]
            for k, (_, ship, _) in enumerate(bench.CONFIGS)]
    return dict(runs=runs, n=20000, removed=12, side=2274.0, dt=1e-3,
                contacts_per_floe=[1.0, 1.2], ship_x=10.0,
                kernels=dict(hull_step=5e-6, hull_build=1e-4, floe_rebuild=4e-3, candidates=40))


def test_summary_gives_same_round_overheads_and_the_ships_share():
    rates = [[2e8, 4e8], [1e8, 3.2e8], [4e8, 8e8], [2e8, 4e8]]
    res = bench.summarise(20000, [_child(rates)], steps=1000)
    assert [r["rate"] for r in res["rows"]] == [3e8, 2.1e8, 6e8, 3e8]
    one, two = res["overhead"]
    assert one["threads"] == 1 and two["threads"] == 2
    assert one["overhead"] == pytest.approx(np.median([1.0, 0.25]))
    assert two["overhead"] == pytest.approx(1.0)
    # 5 µs per step plus 2 builds of 100 µs per 1000 steps
    assert one["hull_kernels"] == pytest.approx(5.2e-6)
    assert one["hull_share"] == pytest.approx(5.2e-6 / (20000 / 2.1e8))
    text = "\n".join(render_table(t, heading=None) for t in bench.ship_tables([res]))
    assert "| 20000 | ship | 2 | parallel | 3e+08 |" in text
    assert "| 2.00 | 50 % | 4.0 | 3.00 / 40 |" in text
    assert "| 20000 | 1 | +62.5 % | +25.0 to +100.0 % |" in text
    assert "at N = 20000: +62.5 % on 1 thread, +100.0 % on 2 threads (not met)" in text


def test_quick_ship_run_writes_a_valid_record(tmp_path):
    path = tmp_path / "ship.json"
    assert bench.main(["--quick", "--quiet", "--json", str(path)]) == 0
    record = json.loads(path.read_text(encoding="utf-8"))
    harness.validate_record(record)
    assert record["suite"] == "ship" and record["data"]["quick"] is True
    assert record["command"] == f"seaice bench ship --quick --quiet --json {path}"
    (res,) = record["data"]["results"]
    assert [(r["ship"], r["threads"]) for r in res["rows"]] == \
        [(ship, threads) for _, ship, threads in bench.CONFIGS]
    assert all(r["rate"] > 0.0 for r in res["rows"])
    assert [o["threads"] for o in res["overhead"]] == [1, 2]
    assert res["kernels"]["hull_step"] > 0.0 and res["ship_sailed"] > 0.0
    assert len(record["tables"]) == 2 and all(t["rows"] for t in record["tables"])
    assert harness.render_markdown(record).startswith(f"## {bench.TITLE}\n")
