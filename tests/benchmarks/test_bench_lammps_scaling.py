"""The LAMMPS scaling benchmark (``benchmarks.bench_lammps_scaling``) at a tiny
size: one measurement on one rank, the per-rank results of a fresh process,
and the record built from measurements (its tables, its projection) that
the documentation renders. The figures themselves come from the full run."""
from __future__ import annotations

import math

import pytest

from benchmarks import harness
from benchmarks import bench_lammps_scaling as bench
from physics.lammps_library import lammps_available

_OK, _REASON = lammps_available()
needs_lammps = pytest.mark.skipif(not _OK, reason=_REASON)

TINY = 2000

LOG = """\
Loop time of 0.0451259 on 4 procs for 100 steps with 32000 atoms

MPI task timing breakdown:
Section |  min time  |  avg time  |  max time  |%varavg| %total
---------------------------------------------------------------
Pair    | 0.02312    | 0.023875   | 0.024935   |   0.5 | 52.91
Neigh   | 0.0047685  | 0.0048664  | 0.0049412  |   0.1 | 10.78
Comm    | 0.0039881  | 0.0041343  | 0.0042858  |   0.2 |  9.16
Output  | 5.0517e-05 | 6.8193e-05 | 8.5122e-05 |   0.0 |  0.15
Modify  | 0.0088343  | 0.0089082  | 0.0089893  |   0.1 | 19.74
Other   |            | 0.003274   |            |       |  7.26
"""


def test_timing_summary_is_parsed():
    t = bench.parse_timing(LOG)
    assert t["loop_seconds"] == 0.0451259 and t["procs"] == 4 and t["steps"] == 100
    assert t["sections"]["Pair"] == dict(avg=0.023875, percent=52.91)
    assert t["sections"]["Other"] == dict(avg=0.003274, percent=7.26)
    assert bench.chute_efficiency() == pytest.approx(0.155391 / (4 * 0.0451259))


@pytest.fixture(scope="module")
def measured():
    """One tiny measurement of each engine, in this process."""
    if not _OK:
        pytest.skip(_REASON)
    return {engine: bench.measure(engine, TINY, seconds=0.2, seed=1)
            for engine in ("lammps", "numba")}


@needs_lammps
def test_one_rank_measurement(measured):
    m = measured["lammps"]
    assert m["engine"] == "lammps" and m["n"] == TINY and m["ranks"] == 1 and m["rank"] == 0
    assert m["steps"] >= 1 and len(m["rates"]) == len(m["segment_seconds"]) == 1
    assert m["rates"][0] == pytest.approx(TINY * m["steps"] / m["segment_seconds"][0])
    assert m["rates"][0] > 0 and m["nlocal"] == TINY
    assert m["peak_rss"] >= m["rss_before_engine"] > 0
    assert 0.0 < m["dt"] <= 0.002 and m["contacts_per_floe"] >= 0.0
    assert "Modify" in m["timing"]["sections"] and m["timing"]["procs"] == 1
    ours = measured["numba"]
    assert ours["rates"][0] > 0 and ours["dt"] == m["dt"] and "timing" not in ours


@needs_lammps
def test_a_fresh_process_writes_its_ranks_results(tmp_path):
    path = str(tmp_path / "field.npz")
    info = bench.save_field(TINY, 1, path)
    assert info["n"] == TINY and info["r_max"] > info["r_min"] > 0
    out = bench.launch(dict(engine="lammps", ranks=1, threads=1), path, 0.2, str(tmp_path))
    assert out["n"] == TINY and out["ranks"] == 1 and out["rates"][0] > 0
    assert out["dt"] == pytest.approx(info["dt"])
    assert out["peak_rss"] == sum(out["peak_rss_ranks"]) > 0 and out["nlocal"] == [TINY]
    assert not list(tmp_path.glob("*.json"))                # the results were collected


def _results(measured):
    """The results of a full run at the tiny size, every configuration
    (1- and 2-way alike) standing in with the one measurement of its
    engine: for the layout of the record only."""
    configs = bench.configurations(TINY, TINY, TINY // 2)
    runs = {}
    for c in configs:
        m = dict(measured[c["engine"]], n=c["n"])
        ranks = [dict(m, rank=k) for k in range(c["ranks"])]
        runs[bench.config_key(c)] = [bench.combine(ranks, c["threads"])]
    return dict(configs=configs, runs=runs, miz=bench.miz_field_info(TINY, 1),
                control=[1.4, 1.9], rounds=1, seed=1, versions=bench.versions(),
                sizes=dict(headline=TINY, strong=TINY, weak=TINY // 2, seconds=0.2,
                           scaling_seconds=0.2))


@needs_lammps
def test_record_tables_and_projection(measured):
    results = _results(measured)
    tables = bench.make_tables(results)
    record = harness.make_record(bench.SUITE, bench.TITLE, bench.DESCRIPTION,
                                 "seaice bench lammps_scaling --quick", tables,
                                 dict(quick=True, **results), 1.0)
    harness.validate_record(record)
    text = harness.render_markdown(record)
    assert text.startswith("## Beyond one machine: LAMMPS with MPI\n")
    head, scaling, proj = tables
    engines = [(r[0], r[1], r[2]) for r in head["rows"]]
    assert engines == [("LAMMPS", 1, 1), ("LAMMPS", 2, 1), ("ours (Numba)", 1, 1),
                       ("ours (Numba)", 1, 2)]
    assert all(r[4] > 0 and r[6] > 0 for r in head["rows"])       # throughput, memory
    lammps_two = head["rows"][1]
    assert lammps_two[6] == pytest.approx(2 * head["rows"][0][6], abs=1)   # two ranks' peaks
    kinds = [(r[0], r[1], r[3]) for r in scaling["rows"]]
    assert ("strong", "LAMMPS", "2 ranks") in kinds and ("weak", "LAMMPS", "2 ranks") in kinds
    assert ("strong", "ours (Numba)", "2 threads") in kinds
    assert "projection" in proj["title"].lower() and "not a measurement" in proj["notes"]
    assert "https://www.lammps.org/bench.html" in proj["notes"]
    assert "2 cores shared" in head["notes"]
    p = bench.projection(results)
    r1 = measured["lammps"]["rates"][0]
    for row in p["rows"]:
        low, high = row["efficiency"]
        want = p["floes"] * p["steps"] / (row["cores"] * r1 * high) / 3600.0
        assert row["hours"][0] == pytest.approx(want)
        assert row["hours"][1] == pytest.approx(want * high / low)
    assert p["steps"] == math.ceil(3 * 3600.0 / p["dt"])
