"""``python -m benchmarks.free_drift --quick``: the record of the fast step
against the exact one, its statistics rows with both criteria, the route
choice under each step, the speed of each step, and the documentation's
tables and figure of it (a smoke test of the structure; the figures come
from the full benchmark)."""
from __future__ import annotations

import json
import math

import numba
import pytest

from benchmarks import free_drift as fd, harness
from docs_extension import benchmarks_page


def test_options_from_the_command_line(capsys):
    assert fd.parse_parts(None) == list(fd.PARTS)
    assert fd.parse_parts("speed,statistics") == ["statistics", "speed"]
    assert fd.parse_concentrations("0.4, 0.2") == (0.4, 0.2)
    assert fd.parse_policies("lattice,straight,lattice") == ("lattice", "straight")
    for bad in ("", "0.3,x", "1.2"):
        with pytest.raises(ValueError, match="--concentrations"):
            fd.parse_concentrations(bad)
    with pytest.raises(ValueError, match="unknown policy"):
        fd.parse_policies("straight,teleport")
    for argv in (["--parts", "gpu"], ["--seeds", "1"], ["--workers", "0"],
                 ["--concentrations", "0"], ["--policies", "nope"]):
        with pytest.raises(SystemExit):
            fd.main(argv + ["--no-json"])
    err = capsys.readouterr().err
    assert "unknown part" in err and "--seeds must be at least 2" in err


def test_the_control_nudges_every_mobile_floe_by_a_rounding_error():
    """The control's reset: the velocities of the mobile floes move by about
    NUDGE (normal variates, seeded by the reset's seed), nothing else."""
    import gymnasium as gym
    import numpy as np

    import iceenvs  # noqa: F401

    env = gym.make(fd.ENV_ID, **fd._small_kwargs(True)).unwrapped
    env.reset(seed=3)
    plain = env.sim.velocities.copy()
    nudged = fd.Nudged(env)
    nudged.reset(seed=3)
    first = env.sim.velocities - plain
    nudged.reset(seed=3)
    assert np.array_equal(env.sim.velocities - plain, first)
    assert 0.5 * fd.NUDGE < float(np.std(first)) < 2.0 * fd.NUDGE
    assert nudged.spec.id == fd.ENV_ID


def test_the_criteria_of_a_row():
    def episodes(values):
        return [dict(final=dict(impulse_per_metre=v, collisions=v, energy_to_ice=v,
                                path_length=v)) for v in values]

    st = dict(concentrations=(0.3,), policies=("straight",))
    exact = episodes([100.0, 110.0, 90.0])
    cases = {"same": ([100.0, 110.0, 90.0], (True, True)),
             "small, steady shift": ([101.0, 111.0, 91.0], (True, False)),
             "large, noisy shift": ([130.0, 100.0, 110.0], (False, True))}
    for name, (values, (within_mean, within_se)) in cases.items():
        fields = [dict(concentration=0.3, policy="straight", seed=k, exact=e, fast=f)
                  for k, (e, f) in enumerate(zip(exact, episodes(values)))]
        rows = fd.metric_rows(fields, st)
        assert [r["metric"] for r in rows] == [key for key, *_ in fd.METRICS]
        r = rows[0]
        assert (r["within_mean"], r["within_se"]) == (within_mean, within_se), name
        assert r["passed"] == (within_mean and within_se)
        assert r["difference"] == pytest.approx(r["fast"] - r["exact"])
        assert r["relative"] == pytest.approx(r["difference"] / r["exact"])


def _check_record(record, st):
    harness.validate_record(record)
    assert record["suite"] == fd.SUITE and record["title"] == fd.TITLE
    assert record["command"].startswith("seaice bench free_drift --quick")
    assert record["date"] and record["wall_seconds"] > 0.0
    assert record["machine"]["numba_threads"] == 1
    data = record["data"]
    assert data["quick"] is True and data["parts"] == list(fd.PARTS)

    speed = data["speed"]
    assert speed["seed"] == fd.DEFAULTS["speed_seed"] and speed["floes"] > 0
    assert 0.0 < speed["concentration"] < 1.0
    assert list(speed["rounds"]) == list(fd.STEPS.values())
    for step, rounds in speed["rounds"].items():
        assert len(rounds) == fd.QUICK["rounds"]
        for r in rounds:
            assert r["steps"] > fd.QUICK["late_after"] and r["rate"] > 0.0
            assert r["late_steps"] == r["steps"] - fd.QUICK["late_after"]
            assert 0.0 <= r["awake_mean"] <= speed["floes"]
            assert (r["tally"] is None) == (step == "exact")
        s = speed["summary"][step]
        assert s["rate"] == max(r["rate"] for r in rounds) >= s["slowest_rate"]
        assert s["late_ms"] == min(r["late_ms"] for r in rounds) <= s["slowest_late_ms"]
    fast = speed["summary"]["fast"]
    tally = speed["rounds"]["fast"][0]["tally"]
    assert len(tally) == 4 and tally[3] > 0 and 0 <= tally[1] <= tally[0]
    assert fast["engaged_per_step"] == pytest.approx(tally[2] / tally[3])
    assert 0.0 <= fast["engaged_per_step"] <= speed["floes"]
    assert speed["summary"]["gain"]["rate"] > 0.0

    stats = data["statistics"]
    cases = [(a, name) for a in st["concentrations"] for name in st["policies"]]
    fields = stats["fields"]
    assert len(fields) == len(cases) * st["seeds"]
    assert sorted({f["seed"] for f in fields}) == \
        list(range(fd.DEFAULTS["seed"], fd.DEFAULTS["seed"] + st["seeds"]))
    for f in fields:
        for step in (*fd.STEPS.values(), fd.CONTROL):
            e = f[step]
            assert e["wall"] > 0.0 and e["length"] > 0 and e["floes"] > 0
            assert all(math.isfinite(e[key]) for key, *_ in fd.METRICS)
            assert (e["tally"] is None) == (step != "fast")
        # the same field under both steps
        assert f["exact"]["floes"] == f["fast"]["floes"]
    rows = stats["rows"]
    assert [(r["concentration"], r["policy"], r["metric"]) for r in rows] == \
        [(a, name, key) for a, name in cases for key, *_ in fd.METRICS]
    for r in rows:
        assert r["n"] == st["seeds"] and r["sem"] >= 0.0
        assert r["passed"] == (r["within_mean"] and r["within_se"])
        assert r["within_mean"] == (abs(r["relative"]) <= fd.RELATIVE_TOLERANCE)
        assert r["within_se"] == (abs(r["difference"]) <= fd.STANDARD_ERRORS * r["sem"])
    assert stats["passed"] == sum(r["passed"] for r in rows) and stats["total"] == len(rows)
    control = stats["control"]
    assert [(r["concentration"], r["policy"], r["metric"]) for r in control] == \
        [(r["concentration"], r["policy"], r["metric"]) for r in rows]
    assert stats["control_passed"] == sum(r["passed"] for r in control)
    for r, c in zip(rows, control):
        assert c["exact"] == r["exact"]                # the same exact runs
        assert c["fast"] == pytest.approx(
            sum(f[fd.CONTROL][c["metric"]] for f in fields
                if f["concentration"] == c["concentration"] and f["policy"] == c["policy"])
            / st["seeds"])
    assert [(w["concentration"], w["policy"]) for w in stats["wall"]] == cases
    assert all(w["exact"]["mean"] > 0.0 and w["fast"]["mean"] > 0.0 for w in stats["wall"])
    routes = stats["route_choice"]
    assert [r["concentration"] for r in routes] == list(st["concentrations"])
    for r in routes:
        for step in fd.STEPS.values():
            assert r[step]["ratio_of_means"] > 0.0 and r[step]["per_field"]["n"] == st["seeds"]

    titles = [t["title"] for t in record["tables"]]
    assert titles[0].startswith("Speed: one straight-line episode")
    assert titles[1] == f"Exact and fast step: means over {st['seeds']} fields"
    assert titles[2].startswith("The control: the exact step against itself")
    assert titles[3:] == ["Does route choice pay under each step?", "Wall time of an episode"]
    statistics = record["tables"][1]
    assert len(statistics["rows"]) == len(rows)
    assert all(row[-1] in ("pass", "**fail**") for row in statistics["rows"])


def test_quick_run_writes_the_record_and_the_docs_show_it(tmp_path):
    path = tmp_path / "free_drift.json"
    threads = numba.get_num_threads()
    assert fd.main(["--quick", "--quiet", "--json", str(path)]) == 0
    assert numba.get_num_threads() == threads      # the work ran in other processes
    record = json.loads(path.read_text(encoding="utf-8"))
    st = dict(fd.DEFAULTS, **fd.QUICK)
    _check_record(record, st)
    text = harness.render_markdown(record)
    assert text.startswith(f"## {fd.TITLE}\n") and "### Does route choice pay" in text

    out = tmp_path / "_generated"
    docs, page = benchmarks_page(tmp_path, out)
    figure = out / "figures" / "free_drift.png"
    assert figure.read_bytes().startswith(b"\x89PNG")
    assert "| A | policy | metric | mean, exact | mean, fast |" in page
    assert page.index("### Wall time of an episode") < page.index("{figure}") < \
        page.index("Command: `seaice bench free_drift --quick")
    # a record without statistics has no figure
    record["data"].pop("statistics")
    assert not docs.free_drift_figure(record, tmp_path / "none.png")
    assert not (tmp_path / "none.png").exists()
