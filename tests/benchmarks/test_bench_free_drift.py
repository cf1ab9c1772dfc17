"""``python -m benchmarks.bench_free_drift --quick``: the equivalence test of the
ship's steps. Its statistics are checked against hand calculations (the
intervals, the choice of statistic by the control, the verdicts), and the
quick run's record and the documentation's tables and figure of it are
checked for structure (the figures come from the full benchmark)."""
from __future__ import annotations

import json
import math

import numba
import numpy as np
import pytest

from benchmarks import bench_free_drift as fd, harness
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
    for argv in (["--parts", "gpu"], ["--seeds", "4"], ["--workers", "0"],
                 ["--concentrations", "0"], ["--policies", "nope"], ["--variants", "warp"]):
        with pytest.raises(SystemExit):
            fd.main(argv + ["--no-json"])
    err = capsys.readouterr().err
    assert "unknown part" in err and "--seeds must be at least 5" in err
    assert "unknown variant" in err


def test_another_environments_record_goes_beside():
    from pathlib import Path

    docs = Path("docs/benchmarks/free_drift.json")
    assert fd.record_path(docs, fd.ENV_ID) == docs
    assert fd.record_path(docs, "iceenvs/ShipBeset-v0") == \
        Path("docs/benchmarks/free_drift-ShipBeset-v0.json")
    assert fd.record_path(Path("elsewhere.json"), "iceenvs/ShipBeset-v0") == \
        Path("elsewhere.json")
    for env_id, own in fd.ENVS.items():
        assert fd.parse_policies(",".join(own["policies"]), env_id) == own["policies"]


def test_every_step_names_its_keywords():
    """The reference is the exact step by name, whatever the environment's
    default; each candidate is a fast step."""
    assert fd.VARIANTS[fd.REFERENCE] == {"free_drift": False}
    for name in fd.CANDIDATES:
        assert fd.VARIANTS[name]["free_drift"] is True
    assert fd.env_kwargs(0.3, "soft-0.01", False) == dict(free_drift=True, stiffness_scale=0.01,
                                                         concentration=0.3)
    # each field runs every step once, rotated by its seed, and the control last
    for seed in range(4):
        order = fd.run_order(fd.CANDIDATES, seed)
        assert sorted(order[:-1]) == sorted((fd.REFERENCE, *fd.CANDIDATES))
        assert order[-1] == fd.CONTROL
    assert fd.run_order(fd.CANDIDATES, 0)[0] != fd.run_order(fd.CANDIDATES, 1)[0]


def test_the_control_nudges_every_mobile_floe_by_a_rounding_error():
    """The control's reset: the velocities of the mobile floes move by about
    NUDGE (normal variates, seeded by the reset's seed), nothing else."""
    import gymnasium as gym

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


def test_the_intervals_by_hand():
    """Student's interval of the mean and Yuen's of the 20 %-trimmed mean of
    ten differences, against the textbook formulas worked by hand: t(0.95,
    9) = 1.8331, t(0.95, 5) = 2.0150."""
    d = np.array([-3.0, -1.0, 0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 4.0, 30.0])
    centre, lo, hi = fd.mean_interval(d)
    sd = math.sqrt(sum((x - 3.75) ** 2 for x in d) / 9)
    assert centre == pytest.approx(3.75)
    assert hi - centre == pytest.approx(1.8331 * sd / math.sqrt(10), rel=1e-4)
    assert centre - lo == pytest.approx(hi - centre)
    # g = 2: the middle six, and the winsorized ten (0, 0, 0, 0.5, …, 2.5, 2.5, 2.5)
    centre, lo, hi = fd.trimmed_interval(d)
    assert centre == pytest.approx((0.0 + 0.5 + 1.0 + 1.5 + 2.0 + 2.5) / 6)
    w = np.array([0.0, 0.0, 0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 2.5, 2.5])
    se = np.std(w, ddof=1) / (0.6 * math.sqrt(10))
    assert hi - centre == pytest.approx(2.0150 * se, rel=1e-4)
    # the one large field moves the mean's interval, not the trimmed one's
    assert hi < 3.0 < fd.mean_interval(d)[2]
    assert fd.within((0.0, -4.9, 4.9), 100.0) and not fd.within((0.0, -5.1, 1.0), 100.0)


def _fields(reference, nudged, candidate):
    """Fields of one concentration and policy whose metrics all take the
    given values under each step."""
    def run(v):
        return {key: v for key, *_ in fd.METRICS}

    return [dict(concentration=0.3, policy="straight", seed=k, exact=run(e), nudged=run(n),
                 fast=run(c)) for k, (e, n, c) in enumerate(zip(reference, nudged, candidate))]


def test_the_trimmed_mean_decides_and_a_few_wild_fields_cannot_move_it():
    """The default statistic: the trimmed mean on every row. Three fields of
    forty far off in the candidate (a large floe struck in one run only)
    leave it equivalent; a shift of every field by 20 % does not."""
    st = dict(concentrations=(0.3,), policies=("straight",), variants=("fast",),
              statistic="trimmed")
    rng = np.random.default_rng(1)
    exact = 100.0 + rng.normal(0.0, 1.0, 40)
    quiet = exact + rng.normal(0.0, 0.5, 40)
    wild = exact * 1.005
    wild[:3] += 400.0
    r = fd.equivalence_rows(_fields(exact, quiet, wild), st)[0]
    assert r["statistic"] == "trimmed"
    assert r["runs"]["fast"]["verdict"] == fd.PASS
    assert not r["runs"]["fast"]["within_mean"]          # the mean could not tell
    r = fd.equivalence_rows(_fields(exact, quiet, exact * 1.2), st)[0]
    assert r["runs"]["fast"]["verdict"] == fd.FAIL


def test_the_control_chooses_the_statistic_and_the_verdicts_follow():
    st = dict(concentrations=(0.3,), policies=("straight",), variants=("fast",),
              statistic="control")
    rng = np.random.default_rng(0)
    exact = 100.0 + rng.normal(0.0, 1.0, 40)
    quiet = exact + rng.normal(0.0, 0.5, 40)
    # a quiet control: the mean; a candidate 20 % off fails, one 0.5 % off passes
    rows = fd.equivalence_rows(_fields(exact, quiet, exact * 1.2), st)
    assert [r["metric"] for r in rows] == [key for key, *_ in fd.METRICS]
    r = rows[0]
    assert r["statistic"] == "mean" and r["n"] == 40
    assert r["runs"]["nudged"]["verdict"] == fd.PASS
    assert r["runs"]["fast"]["verdict"] == fd.FAIL
    assert r["runs"]["fast"]["mean"][0] == pytest.approx(0.2, abs=0.01)
    rows = fd.equivalence_rows(_fields(exact, quiet, exact * 1.005), st)
    assert rows[0]["runs"]["fast"]["verdict"] == fd.PASS
    # three fields far off in the control: its mean cannot resolve the margin,
    # its trimmed mean can, and the candidate is judged by the trimmed mean
    wild = quiet.copy()
    wild[:3] += 400.0
    rows = fd.equivalence_rows(_fields(exact, wild, exact * 1.005), st)
    assert rows[0]["statistic"] == "trimmed"
    assert rows[0]["runs"]["fast"]["verdict"] == fd.PASS
    # a control that nothing resolves leaves the row unresolved
    rows = fd.equivalence_rows(_fields(exact, exact + rng.normal(0.0, 40.0, 40), exact), st)
    assert rows[0]["statistic"] is None
    assert rows[0]["runs"]["fast"]["verdict"] == fd.UNRESOLVED
    tally = fd.verdicts(rows, ("fast",))["fast"]
    assert tally["unresolved"] == tally["total"] == len(fd.METRICS)


def _record(verdicts, confidence=fd.CONFIDENCE, statistic="trimmed"):
    """A record of rows (A = 0.5, swath, one metric each) with the fast
    step's verdicts."""
    rows = [dict(concentration=0.5, policy="swath", metric=key,
                 statistic=None if v == fd.UNRESOLVED else "trimmed",
                 runs={"fast": dict(verdict=v), fd.CONTROL: dict(verdict=fd.PASS)})
            for key, v in zip(("impulse_per_metre", "energy_to_ice"), verdicts)]
    return dict(data=dict(settings=dict(env=fd.ENV_ID, statistic=statistic),
                          confidence=confidence, statistics=dict(rows=rows)))


def test_a_record_supports_a_step_when_every_row_passes_there_or_in_an_extension():
    assert fd.supports(_record([fd.PASS, fd.PASS]), "fast")
    assert not fd.supports(_record([fd.PASS, fd.PASS]), "soft-0.1")
    # rows the control does not resolve: allowed, up to a tenth of them
    assert not fd.supports(_record([fd.PASS, fd.UNRESOLVED]), "fast")
    many = _record([fd.PASS, fd.PASS])
    rows = many["data"]["statistics"]["rows"]
    rows += [dict(rows[0], metric=f"m{k}") for k in range(8)]
    rows.append(dict(rows[0], metric="unresolved", statistic=None,
                     runs={"fast": dict(verdict=fd.UNRESOLVED)}))
    assert fd.supports(many, "fast")
    short = _record([fd.PASS, fd.FAIL])
    assert not fd.supports(short, "fast")
    # the row sailed again on more fields, with a stricter interval, settles it ...
    again = _record([fd.FAIL, fd.PASS], confidence=0.95)
    assert fd.supports(short, "fast", [again])
    # ... but not a record at the same confidence (the pilot), nor one where it fails
    assert not fd.supports(short, "fast", [_record([fd.PASS, fd.PASS], statistic="control")])
    assert not fd.supports(short, "fast", [_record([fd.PASS, fd.FAIL], confidence=0.95)])


def _check_record(record, st):
    harness.validate_record(record)
    assert record["suite"] == fd.SUITE and record["title"] == fd.TITLE
    assert record["command"].startswith("seaice bench free_drift --quick")
    assert record["date"] and record["wall_seconds"] > 0.0
    assert record["machine"]["numba_threads"] == 1
    data = record["data"]
    assert data["quick"] is True and data["parts"] == list(fd.PARTS)
    assert data["margin"] == fd.MARGIN and data["confidence"] == fd.CONFIDENCE
    steps = [fd.REFERENCE, *st["variants"]]

    speed = data["speed"]
    assert speed["seed"] == fd.DEFAULTS["speed_seed"] and speed["floes"] > 0
    assert list(speed["rounds"]) == steps
    for step, rounds in speed["rounds"].items():
        assert len(rounds) == fd.QUICK["rounds"]
        for r in rounds:
            assert r["steps"] > fd.QUICK["late_after"] and r["rate"] > 0.0
            assert (r["tally"] is None) == (step == fd.REFERENCE)
        s = speed["summary"][step]
        assert s["rate"] == max(r["rate"] for r in rounds) >= s["slowest_rate"]
    assert set(speed["summary"]["gain"]) == set(st["variants"])

    stats = data["statistics"]
    cases = [(a, name) for a in st["concentrations"] for name in st["policies"]]
    rows = stats["rows"]
    assert [(r["concentration"], r["policy"], r["metric"]) for r in rows] == \
        [(a, name, key) for a, name in cases for key, *_ in fd.METRICS]
    for r in rows:
        assert r["n"] == st["seeds"]
        assert set(r["runs"]) == {fd.CONTROL, *st["variants"]}
        for o in r["runs"].values():
            assert o["mean"][1] <= o["mean"][0] <= o["mean"][2]
            assert o["verdict"] in (fd.PASS, fd.FAIL, fd.UNRESOLVED)
    for v in stats["verdicts"].values():
        assert v["passed"] + v["failed"] + v["unresolved"] == v["total"] == len(rows)
    for label in (*steps, fd.CONTROL):
        c = stats["conclusions"][label]
        assert c["order"][0] != "straight" or c["pooled_ratio"]["straight"] == 1.0
    assert [r["step"] for r in stats["rates"]] == steps
    assert all(r["pooled"] > 0.0 for r in stats["rates"])
    titles = [t["title"] for t in record["tables"]]
    assert titles[0].startswith("Speed on one thread")
    assert titles[1].startswith("The equivalence test")
    assert titles[2].startswith("Sustained rates")
    assert titles[3:] == ["The leaderboard's conclusions under each step",
                          "Every row: (step − exact) / exact mean, the centre and its interval"]


def test_quick_run_writes_the_record_and_the_docs_show_it(tmp_path):
    path = tmp_path / "free_drift.json"
    threads = numba.get_num_threads()
    fields = tmp_path / "fields.json"
    assert fd.main(["--quick", "--quiet", "--json", str(path), "--fields", str(fields)]) == 0
    assert numba.get_num_threads() == threads      # the work ran in other processes
    record = json.loads(path.read_text(encoding="utf-8"))
    st = record["data"]["settings"]
    own = fd.ENVS[fd.ENV_ID]
    assert st["env"] == fd.ENV_ID and st["seeds"] == fd.QUICK["seeds"]
    assert tuple(st["concentrations"]) == own["concentrations"][:1]
    assert tuple(st["policies"]) == own["policies"][:2]
    _check_record(record, st)
    runs = json.loads(fields.read_text(encoding="utf-8"))
    assert len(runs) == len(st["concentrations"]) * len(st["policies"]) * st["seeds"]
    # the same field under every step, and the record's means are the runs'
    assert all(len({f[s]["floes"] for s in (fd.REFERENCE, *st["variants"], fd.CONTROL)}) == 1
               for f in runs)
    row = record["data"]["statistics"]["rows"][0]
    mine = [f for f in runs if f["policy"] == row["policy"]]
    assert row["reference"] == pytest.approx(np.mean([f["exact"][row["metric"]] for f in mine]))
    text = harness.render_markdown(record)
    assert text.startswith(f"## {fd.TITLE}\n") and "### The equivalence test" in text

    out = tmp_path / "_generated"
    docs, page = benchmarks_page(tmp_path, out)
    figure = out / "figures" / "free_drift.png"
    assert figure.read_bytes().startswith(b"\x89PNG")
    assert "| A | policy | metric | mean, exact | statistic | nudged |" in page
    assert page.index("### Every row") < page.index("{figure}") < \
        page.index("Command: `seaice bench free_drift --quick")
    # a record without statistics has no figure
    record["data"].pop("statistics")
    assert not docs.free_drift_figure(record, tmp_path / "none.png")
    assert not (tmp_path / "none.png").exists()
