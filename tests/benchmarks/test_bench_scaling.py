"""``python -m benchmarks.bench_scaling --quick``: every workload is timed on every
thread count asked, in every round, its speed-ups are over one thread, and
the documentation draws the record's figure (a smoke test; the figures come
from the full benchmark)."""
from __future__ import annotations

import json
import math

import numba
import pytest

from benchmarks import bench_scaling, harness
from docs_extension import docs_extension

pytest.importorskip("stable_baselines3")


def test_thread_counts_and_workloads_from_the_command_line():
    assert bench_scaling.default_threads(1) == [1]
    assert bench_scaling.default_threads(2) == [1, 2]
    assert bench_scaling.default_threads(16) == [1, 2, 4, 8, 16]
    assert bench_scaling.default_threads(12) == [1, 2, 4, 8, 12]     # the top one, not a power of 2
    assert bench_scaling.parse_threads("4,2") == [1, 2, 4]            # one thread is always timed
    for bad in ("0", "two", ""):
        with pytest.raises(ValueError, match="--threads"):
            bench_scaling.parse_threads(bad)
    assert bench_scaling.parse_workloads(None) == list(bench_scaling.WORKLOADS)
    assert bench_scaling.parse_workloads("ppo,hertz-jammed,ceiling") == \
        ["ceiling", "hertz-jammed", "ppo-v0"]
    assert bench_scaling.parse_workloads("vector") == ["vector-v0", "vector-v1"]
    with pytest.raises(ValueError, match="unknown workload"):
        bench_scaling.parse_workloads("hertz,gpu")


def test_bad_options_are_refused(capsys):
    for argv in (["--workloads", "nope"], ["--threads", "0"], ["--rounds", "0"]):
        with pytest.raises(SystemExit):
            bench_scaling.main(argv + ["--no-json"])
    assert "unknown workload" in capsys.readouterr().err


def test_quick_run_times_every_workload_on_every_thread_count(tmp_path):
    import torch

    threads = [1, 2] if numba.config.NUMBA_NUM_THREADS >= 2 else [1]
    path = tmp_path / "scaling.json"
    torch_threads, numba_threads = torch.get_num_threads(), numba.get_num_threads()
    assert bench_scaling.main(["--quick", "--quiet", "--threads", ",".join(map(str, threads)),
                         "--cache-dir", str(tmp_path), "--json", str(path)]) == 0
    # the quick run, in this process, leaves both thread counts as they were
    assert (torch.get_num_threads(), numba.get_num_threads()) == (torch_threads, numba_threads)
    record = json.loads(path.read_text(encoding="utf-8"))
    harness.validate_record(record)
    assert record["suite"] == bench_scaling.SUITE and record["title"] == bench_scaling.TITLE
    assert record["command"].startswith("seaice bench scaling --quick")
    for key in ("cpu", "logical_cpus", "numpy", "numba", "python"):
        assert record["machine"][key], key
    assert record["date"] and record["wall_seconds"] > 0.0
    data = record["data"]
    rounds = bench_scaling.QUICK["rounds"]
    assert data["quick"] is True and data["threads"] == threads
    assert data["workloads"] == list(bench_scaling.WORKLOADS)
    assert [r["workload"] for r in data["results"]] == list(bench_scaling.WORKLOADS)
    for res in data["results"]:
        assert "failed" not in res, res
        assert res["unit"] and res["label"] and res["n"] > 0
        assert [r["threads"] for r in res["rows"]] == threads
        one = res["rows"][0]
        assert one["speedup"] == 1.0 and one["paired"] == [1.0] * rounds
        for r in res["rows"]:
            assert len(r["rates"]) == len(r["paired"]) == rounds
            assert all(x > 0.0 and math.isfinite(x) for x in r["rates"])
            assert r["rate"] == max(r["rates"]) and r["spread"] == [min(r["rates"]),
                                                                    max(r["rates"])]
            assert r["speedup"] == pytest.approx(r["rate"] / one["rate"])
    ppo = next(r for r in data["results"] if r["workload"] == "ppo-v0")
    assert ppo["torch_threads"] == 1
    hertz = [r for r in data["results"] if r["workload"].startswith("hertz")]
    assert all(r["contacts_per_floe"] >= 0.0 and r["rebuilds"] >= 0.0 for r in hertz)
    vector = [r for r in data["results"] if r["workload"].startswith("vector")]
    # the Python around the parallel calls is a share of the step, neither none nor all
    assert all(0.0 < r["serial_share"] < 1.0 and r["serial_ms"] > 0.0 for r in vector)
    columns = ["1 thread"] + [f"{k} threads" for k in threads[1:]]
    rates, speedups, serial = record["tables"]
    assert [row[0] for row in serial["rows"]] == [r["label"] for r in vector]
    for row, res in zip(serial["rows"], vector):
        s = res["serial_share"]   # Amdahl: between 1 and 1/s, and at most p
        assert 1.0 <= float(row[3]) <= min(16.0, 1.0 / s) + 0.05
    assert rates["columns"] == ["workload", "unit"] + columns
    assert speedups["columns"] == ["workload"] + columns
    assert len(rates["rows"]) == len(speedups["rows"]) == len(bench_scaling.WORKLOADS)
    assert all(row[1] == "1.00" for row in speedups["rows"])
    assert speedups["rows"][0][0].startswith("ceiling")
    text = harness.render_markdown(record)
    assert text.startswith(f"## {bench_scaling.TITLE}\n") and "### Speed-up over one thread" in text


def _synthetic_record(workloads=("ceiling", "hertz-loose", "ppo-v0")):
    threads = [1, 2, 4]
    results = []
    for k, key in enumerate(workloads):
        rows = [dict(threads=t, rate=1e6 * t ** (1 - 0.1 * k), speedup=t ** (1 - 0.1 * k),
                     spread=[9e5, 1e6], rates=[1e6], paired=[0.9 * t ** (1 - 0.1 * k),
                                                             t ** (1 - 0.1 * k)])
                for t in threads]
        results.append(dict(workload=key, label=f"workload {key}", unit="floe-steps/s", n=100,
                            rows=rows))
    results.append(dict(workload="vector-v1", label="broken", unit="env steps/s", n=2,
                        failed="exit 1"))
    tables = [bench_scaling.rates_table(results, threads, 1),
              bench_scaling.speedup_table(results, threads, 1, cores=2)]
    return harness.make_record("scaling", bench_scaling.TITLE, bench_scaling.DESCRIPTION,
                               "seaice bench scaling", tables,
                               dict(threads=threads, results=results, quick=False), 1.0)


def test_docs_show_the_scaling_tables_and_figure(tmp_path):
    docs = docs_extension()
    records = tmp_path / "records"
    record = _synthetic_record()
    harness.write_record(record, records / "scaling.json")
    out = tmp_path / "_generated"
    docs.generate_benchmarks(out, records)
    text = (out / "include" / "benchmarks.md").read_text(encoding="utf-8")
    figure = out / "figures" / "scaling.png"
    assert figure.read_bytes().startswith(b"\x89PNG") and figure.stat().st_size > 5000
    assert "```{figure} /_generated/figures/scaling.png" in text
    # the figure sits after the tables, before the line with the command and machine
    assert text.index("### Speed-up over one thread") < text.index("{figure}") < \
        text.index("Command: `seaice bench scaling`")
    assert "| workload | unit | 1 thread | 2 threads | 4 threads |" in text
    assert "failed: exit 1" in text
    # on 4 threads of 2 cores the engine runs on 2: the notes say so
    assert "on 4 threads the Hertz step and the vector environments run on 2" in text
    # an unchanged record leaves the figure as it is
    before = figure.stat().st_mtime_ns
    docs.generate_benchmarks(out, records)
    assert figure.stat().st_mtime_ns == before
    # a record with only the ceiling loop timed has no figure
    only = _synthetic_record(("ceiling",))
    assert not docs.scaling_figure(only, tmp_path / "none.png")
    assert not (tmp_path / "none.png").exists()
