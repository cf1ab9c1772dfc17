"""The resting-floes benchmark (``benchmarks.bench_resting``): one reference
transit with the option on and off gives the same statistics, and a
``--quick`` run writes a valid record (a smoke test; the figures come from
the full benchmark)."""
from __future__ import annotations

import json

import pytest

from benchmarks import harness
from benchmarks import bench_resting as bench


@pytest.mark.parametrize("concentration, dynamic", [(0.3, False), (0.6, True)],
                         ids=["prescribed at A = 0.3", "dynamic at A = 0.6"])
def test_transit_statistics_agree_on_and_off(concentration, dynamic):
    """The two paths differ by rounding only: every statistic of a whole
    reference transit agrees to 1e-9 relative (rounding of sums over ~1e5
    steps), far inside the 2 % the comparison of the means allows, for a
    prescribed and a dynamic ship."""
    on = bench.transit(concentration, dynamic, 0, True)
    off = bench.transit(concentration, dynamic, 0, False)
    assert off["collisions"] > 0, "the ship hit nothing: the test tests nothing"
    for key in bench.METRICS:
        assert on[key] == pytest.approx(off[key], rel=1e-9, abs=1e-12), key


def test_quick_run_writes_a_record(tmp_path):
    path = tmp_path / "resting.json"
    assert bench.main(["--quick", "--seeds", "2", "--env-steps", "1", "--quiet",
                       "--json", str(path)]) == 0
    record = json.loads(path.read_text())
    harness.validate_record(record)
    assert record["suite"] == "resting" and len(record["tables"]) == 2
    assert record["data"]["speed"]["steps"] == 1


def test_bad_counts_are_refused():
    with pytest.raises(SystemExit):
        bench.main(["--seeds", "1", "--no-json"])
