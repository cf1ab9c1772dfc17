"""The benchmarks' shared harness and records: fresh processes, the JSON
layout, its Markdown, the README's headline block, and quick runs of the
hard-disc, observables and ITD suites."""
from __future__ import annotations

import importlib.util
import json
import os
from pathlib import Path

import pytest

import benchmarks
from benchmarks import bench_harddisk, bench_itd, bench_observables, bench_sensors, harness, headline


def _record(suite="hertz", **changes):
    record = harness.make_record(
        suite, "Title", "What is *measured*.", f"seaice bench {suite}",
        [harness.table("A table", ["case", "rate"], [["a", 1.5e8], ["b", 12]], "a note")],
        dict(quick=False), 3.2)
    record.update(changes)
    return record


def test_record_layout_and_markdown():
    record = _record()
    assert list(record) == list(harness.RECORD_KEYS)
    assert set(record["machine"]) >= set(harness.MACHINE_KEYS)
    assert record["date"].endswith("+00:00")
    text = harness.render_markdown(record)
    assert text.startswith("## Title\n\nWhat is *measured*.\n\n### A table\n")
    assert "| case | rate |\n|---|---|\n| a | 1.5e+08 |\n| b | 12 |\n\na note" in text
    last = text.strip().splitlines()[-1]
    assert "`seaice bench hertz`" in last and record["date"] in last
    assert record["machine"]["cpu"] in last


def test_tables_must_be_rectangular_and_records_complete():
    with pytest.raises(ValueError, match="2 columns"):
        harness.table("t", ["a", "b"], [["x"]])
    record = _record()
    del record["machine"]
    with pytest.raises(ValueError, match="machine"):
        harness.render_markdown(record)
    with pytest.raises(TypeError):
        harness.validate_record([])


def test_json_has_no_nan_and_records_load_in_suite_order(tmp_path):
    for suite in ("environments", "itd", "hertz", "compare"):
        harness.write_record(_record(suite, data=dict(x=float("nan"))), tmp_path / f"{suite}.json")
    (tmp_path / "notes.json").write_text("{}")
    records = harness.load_records(tmp_path)
    assert [r["suite"] for r in records] == ["hertz", "itd", "environments", "compare"]
    assert records[0]["data"]["x"] is None
    assert "NaN" not in (tmp_path / "hertz.json").read_text()


def test_format_number():
    assert [harness.format_number(v) for v in (3.15e8, 8389.4, 44.23, 0.146, 7, None, "x")] == \
        ["3.15e+08", "8389", "44.2", "0.146", "7", "–", "x"]


def test_child_runs_a_plain_function_with_its_own_threads_and_module_path(tmp_path):
    fake = tmp_path / "tree" / "physics"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("")
    child = harness.Child(harness.module_file, ("physics",), source=tmp_path / "tree")
    assert child.result() == str(fake / "__init__.py")
    assert child.loaded_from == {"physics": str(fake / "__init__.py")}
    assert harness.spawn_call(harness.module_file, "physics") != str(fake / "__init__.py")
    assert harness.spawn_call(os.getenv, "NUMBA_NUM_THREADS", threads=1) == "1"


def test_child_errors_carry_the_traceback():
    with pytest.raises(harness.ChildError, match="No module named 'no_such_module'"):
        harness.spawn_call(harness.module_file, "no_such_module")
    with pytest.raises(TypeError):
        harness.spawn_call(lambda: 1)


def test_control_loops_give_one_ratio_per_round():
    out = harness.spawn_call(harness.control_child, "scalar", 0.01, threads=2)
    assert len(out["ratios"]) == harness.REPEATS and all(r > 0 for r in out["ratios"])
    with pytest.raises(ValueError):
        harness.control_child("vector")


def test_suite_dispatch(tmp_path):
    with pytest.raises(ValueError, match="unknown benchmark suite"):
        benchmarks.main("nope")
    with pytest.raises(TypeError, match="suite must be a string"):
        benchmarks.main(None)
    path = tmp_path / "itd.json"
    assert benchmarks.main("itd", ["--quick", "--quiet", "--json", str(path)]) == 0
    assert json.loads(path.read_text())["suite"] == "itd"


def test_no_module_of_the_benchmarks_shares_a_name_with_one_of_the_library():
    """A suite's module is benchmarks.bench_SUITE, so that ``hertz`` in a
    traceback or an import is the engine's module, never its benchmark's."""
    root = Path(benchmarks.__file__).parent
    library = {p.stem for package in ("physics", "iceenvs", "agents", "seaice_gym")
               for p in (root.parent / package).rglob("*.py")} - {"__init__", "__main__"}
    ours = {p.stem for p in root.glob("*.py")} - {"__init__"}
    assert not ours & library
    for suite in benchmarks.SUITES:
        assert importlib.util.find_spec(benchmarks.suite_module(suite)), suite


@pytest.mark.parametrize("module", [bench_harddisk, bench_observables, bench_itd, bench_sensors])
def test_quick_run_writes_a_valid_record(module, tmp_path):
    path = tmp_path / f"{module.SUITE}.json"
    assert module.main(["--quick", "--quiet", "--json", str(path)]) == 0
    record = json.loads(path.read_text(encoding="utf-8"))
    harness.validate_record(record)
    assert record["suite"] == module.SUITE and record["data"]["quick"] is True
    assert record["command"] == f"seaice bench {module.SUITE} --quick --quiet --json {path}"
    for t in record["tables"]:
        assert t["rows"] and all(len(r) == len(t["columns"]) for r in t["rows"])
    text = harness.render_markdown(record)
    assert text.startswith(f"## {module.TITLE}\n")
    assert not module.main(["--quick", "--quiet", "--no-json"])


def _hertz_rows(contacts=(0.0005, 3.89)):
    loose, dense = contacts
    return [dict(case="Ā = 0.70", kernel="serial", threads=1, rate=3.15e8,
                 contacts_per_floe=loose),
            dict(case="Ā = 0.70", kernel="parallel", threads=2, rate=6.0e8,
                 contacts_per_floe=loose),
            dict(case="jammed, Ā = 0.95", kernel="serial", threads=1, rate=2.0e7,
                 contacts_per_floe=dense),
            dict(case="jammed, Ā = 0.95", kernel="parallel", threads=2, rate=4.0e7,
                 contacts_per_floe=dense),
            dict(case="control", kernel="scalar", threads=2, rate=1.9)]


def test_headline_block_is_rewritten_from_the_records(tmp_path):
    hertz = _record("hertz", data=dict(n=20000, rows=_hertz_rows()))
    envs = _record("environments", data=dict(environments=[
        dict(id="iceenvs/WindDrift-v0", mean=162.3), dict(id="iceenvs/X-v0", failed="exit 1")]))
    quick = _record("harddisk", data=dict(quick=True, rows=[dict(case="elastic", rate=1.0)]))
    ship = "iceenvs/ShipNavigation-v0"
    vector = _record("vector", data=dict(
        settings=dict(ids=[ship]),
        stepping=[dict(mode="single", id=ship, n=1, mean=380.0),
                  dict(mode="native", id=ship, n=8, mean=700.0),
                  dict(mode="native", id=ship, n=16, mean=900.4),
                  dict(mode="sync", id=ship, n=16, mean=390.0)],
        training=[dict(mode="native", id=ship, n=16, mean=640.0),
                  dict(mode="subproc", id=ship, n=16, failed="exit 1")]))
    for r in (hertz, envs, quick, vector):
        harness.write_record(r, tmp_path / f"{r['suite']}.json")
    readme = tmp_path / "README.md"
    readme.write_text("# x\n\nbefore\n<!-- headline:start -->\nold\n<!-- headline:end -->\nafter\n")
    assert headline.main(["--readme", str(readme), "--records", str(tmp_path)]) == 0
    text = readme.read_text()
    assert text.startswith("# x\n\nbefore\n<!-- headline:start -->\n| benchmark |")
    assert text.endswith("<!-- headline:end -->\nafter\n") and "old" not in text
    # each Hertz figure names its regime, concentration and contacts per
    # floe, and the dense-ice row follows the loose-ice one
    loose = "| Hertz engine, N = 20000, Ā = 0.70, 0.0005 contacts per floe | 6e+08 floe-steps/s " \
            "on 2 threads (3.15e+08 on one, serial kernels) |"
    dense = "| Hertz engine, N = 20000, jammed, Ā = 0.95, 3.89 contacts per floe | 4e+07 " \
            "floe-steps/s on 2 threads (2e+07 on one, serial kernels) |"
    assert f"{loose} {hertz['date'][:10]} |\n{dense}" in text
    # the note under the table: 6e8 / 4e7 = 15 at the same 2 threads
    assert "the Ā = 0.70 field has 0.0005 contacts per floe (nearly all its floes in free " \
           "flight); in the jammed, Ā = 0.95 field, with 3.89 contacts per floe, a floe-step " \
           "costs 15 times as much on 2 threads." in text
    assert "| `iceenvs/WindDrift-v0` | 162 steps/s, one core |" in text
    # the vector environment's fastest N beside the single environment of its run
    threads = vector["machine"]["numba_threads"]
    assert (f"| `{ship}`, native vector environment, N = 16 | 900 steps/s on {threads} threads "
            f"(380 single, one core) |") in text
    assert f"| PPO on `{ship}`, native vector environment, N = 16 | 640 training steps/s end " \
           "to end |" in text
    assert "control" not in text and "X-v0" not in text and "elastic" not in text
    once = text
    assert headline.main(["--readme", str(readme), "--records", str(tmp_path)]) == 0
    assert readme.read_text() == once


def test_headline_takes_the_sustained_ship_rates_from_the_main_equivalence_record():
    """The pilot (its own rule), an extension over fewer concentrations and
    another environment's record give no headline row; the main record of
    ShipNavigation-v1 gives one, at its concentrations."""
    def record(rate, statistic="trimmed", concentrations=(0.2, 0.3, 0.4, 0.5),
               env="iceenvs/ShipNavigation-v1"):
        rates = [dict(step="exact", pooled=rate / 2), dict(step="fast", pooled=rate)]
        return _record("free_drift", data=dict(
            settings=dict(env=env, statistic=statistic, concentrations=list(concentrations)),
            statistics=dict(rates=rates)))
    main, pilot = record(240.0), record(111.0, statistic="control")
    extension, other = record(122.0, concentrations=(0.5,)), record(133.0, env="iceenvs/ShipBeset-v0")
    text = headline.headline_table([main, pilot, extension, other])
    assert ("| `iceenvs/ShipNavigation-v1`, sustained over whole transits, A = 0.2–0.5 | 240 "
            "steps/s with the default (fast) step, 120 with the exact step;") in text
    assert text.count("sustained over whole transits") == 1


def test_headline_says_free_flight_only_of_a_field_whose_floes_barely_touch():
    record = _record("hertz", data=dict(n=20000, rows=_hertz_rows((0.5, 3.89))))
    text = headline.headline_table([record])
    assert "0.5 contacts per floe;" in text and "free flight" not in text


def test_headline_refuses_a_hertz_figure_without_its_contacts(tmp_path, capsys):
    rows = _hertz_rows()
    del rows[2]["contacts_per_floe"]
    harness.write_record(_record("hertz", data=dict(n=20000, rows=rows)), tmp_path / "hertz.json")
    readme = tmp_path / "README.md"
    readme.write_text("<!-- headline:start -->\n<!-- headline:end -->\n")
    assert headline.main(["--readme", str(readme), "--records", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert "no contacts per floe" in err and "'jammed, Ā = 0.95'" in err
    assert readme.read_text() == "<!-- headline:start -->\n<!-- headline:end -->\n"


def test_headline_without_markers_is_an_error(tmp_path, capsys):
    readme = tmp_path / "README.md"
    readme.write_text("# no markers\n")
    assert headline.main(["--readme", str(readme), "--records", str(tmp_path)]) == 1
    assert "<!-- headline:start -->" in capsys.readouterr().err
    assert readme.read_text() == "# no markers\n"
    with pytest.raises(ValueError):
        headline.rewrite("<!-- headline:end -->\n<!-- headline:start -->", [])


def test_stored_records_are_valid():
    """Every record kept in the documentation's folder renders."""
    root = Path(__file__).resolve().parents[2]
    for record in harness.load_records(root / "docs" / "benchmarks"):
        harness.validate_record(record)
        assert harness.render_markdown(record).startswith(f"## {record['title']}")
