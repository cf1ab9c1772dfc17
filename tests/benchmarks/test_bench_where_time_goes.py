"""``python -m benchmarks.bench_where_time_goes --quick``: the record of a late
ShipNavigation-v1 substep in parts, of its episode and of PPO on it, whose
parts add up and whose shares are fractions, and the documentation's tables
and figure of it (a smoke test; the figures come from the full benchmark)."""
from __future__ import annotations

import json
import math

import numba
import pytest

from benchmarks import bench_where_time_goes as wtg, harness
from docs_extension import benchmarks_page

pytest.importorskip("stable_baselines3")


def test_parts_from_the_command_line(capsys):
    assert wtg.parse_parts(None) == list(wtg.PARTS)
    assert wtg.parse_parts("ppo,substep") == ["substep", "ppo"]
    with pytest.raises(ValueError, match="unknown part"):
        wtg.parse_parts("gpu")
    for argv in (["--parts", "nope"], ["--rounds", "0"], ["--trajectory-steps", "0"]):
        with pytest.raises(SystemExit):
            wtg.main(argv + ["--no-json"])
    assert "unknown part" in capsys.readouterr().err


def test_shares_of_a_profile_are_fractions_that_add_up_to_one():
    cum = dict(collect_rollouts=6.0, vec_normalize=4.0, adapter=3.5, unbatch_info=0.2,
               vector_step=3.0, engine=2.0, policy_forward=1.0, buffer_add=0.3,
               buffer_returns=0.1, train=3.0)
    s = wtg.shares(cum, 10.0)
    assert list(s) == list(wtg.SHARES)
    assert s["engine"] == pytest.approx(0.2) and s["env_python"] == pytest.approx(0.1)
    assert s["adapter"] == pytest.approx(0.05) and s["vec_normalize"] == pytest.approx(0.05)
    assert s["buffer"] == pytest.approx(0.04) and s["train"] == pytest.approx(0.3)
    assert sum(s.values()) == pytest.approx(1.0)


def _check_record(record):
    harness.validate_record(record)
    assert record["suite"] == wtg.SUITE and record["title"] == wtg.TITLE
    assert record["command"].startswith("seaice bench where_time_goes --quick")
    assert record["date"] and record["wall_seconds"] > 0.0
    data = record["data"]
    assert data["quick"] is True and data["parts"] == list(wtg.PARTS)
    b = data["substep"]["breakdown"]
    assert b["floes"] > 0 and 0 <= b["awake"] <= b["floes"] and b["listed_pairs"] >= 0
    assert b["contacts"] >= 0 and b["n_sub"] >= 1 and b["dt"] > 0.0
    assert b["n_sub"] == round(b["control_interval"] / b["dt"])
    for key in ("whole", "kick_drift", "live_pairs", "fast_whole", "classify", "sync",
                "rebuild"):
        times = b["times"][key]
        assert len(times) == wtg.QUICK["rounds"]
        assert all(t > 0.0 and math.isfinite(t) for t in times)
    s = data["substep"]["summary"]
    best = s["best"]
    # the three parts add up to the whole, by construction
    assert best["kick_drift"] + best["live_pairs"] + best["rest"] == pytest.approx(best["whole"])
    assert sum(s["shares"].values()) == pytest.approx(1.0)
    assert all(0.0 <= v <= 1.0 for v in s["shares"].values())
    # the fast step's parts: per substep, each window-level part its time per
    # call times its calls per substep, and the four add up to the whole
    tally, fast = b["fast_tally"], s["fast"]
    assert tally["substeps"] == wtg.QUICK["rounds"] * b["n_sub"]
    assert 1 <= tally["windows"] <= tally["substeps"] and tally["rebuilds"] >= 0
    per = fast["per_substep"]
    assert per["classify"] == pytest.approx(best["classify"] * tally["windows"]
                                            / tally["substeps"])
    assert sum(per.values()) == pytest.approx(best["fast_whole"])
    assert fast["gain"] == pytest.approx(best["whole"] / best["fast_whole"])
    assert 0 <= b["free_at_window"] <= b["floes"]
    tr = data["substep"]["trajectory"]
    assert tr["rows"] and tr["tau_median"] > 0.0 and tr["tau_min"] <= tr["tau_median"]
    assert [r["step"] for r in tr["rows"]] == sorted(r["step"] for r in tr["rows"])
    for r in tr["rows"]:
        assert r["step_ms"] > 0.0 and 0 <= r["moving"] <= tr["floes"]
        assert 0 <= r["awake"] <= tr["floes"] and 0 <= r["in_contact"] <= tr["floes"]
    assert list(data["ppo"]) == list(wtg.CONFIGURATIONS)
    for configuration, both in data["ppo"].items():
        p, cores = both["one"], both["cores"]
        assert p["configuration"] == cores["configuration"] == configuration
        assert p["envs"] == wtg.QUICK["envs"] and p["rate"] > 0.0 and p["profiled_rate"] > 0.0
        assert p["steps"] >= wtg.QUICK["ppo_steps"] and cores["rate"] > 0.0
        assert list(p["shares"]) == list(wtg.SHARES)
        assert all(0.0 <= v <= 1.0 for v in p["shares"].values())
        assert sum(p["shares"].values()) == pytest.approx(1.0)
        assert p["shares"]["engine"] > 0.0 and p["shares"]["train"] > 0.0
    # the training configuration is the documented run's
    assert data["ppo"]["training"]["one"]["env_kwargs"] == wtg.training_kwargs(True)
    assert [t["columns"][0] for t in record["tables"]] == ["floes", "part", "part", "env step",
                                                           "part", "part"]


def test_quick_run_writes_the_record(tmp_path):
    import torch

    path = tmp_path / "where_time_goes.json"
    threads = (torch.get_num_threads(), numba.get_num_threads())
    assert wtg.main(["--quick", "--quiet", "--json", str(path)]) == 0
    # the quick run, in this process, leaves both thread counts as they were
    assert (torch.get_num_threads(), numba.get_num_threads()) == threads
    record = json.loads(path.read_text(encoding="utf-8"))
    _check_record(record)
    text = harness.render_markdown(record)
    assert text.startswith(f"## {wtg.TITLE}\n") and "### The fast step (the default)" in text

    out = tmp_path / "_generated"
    _, page = benchmarks_page(tmp_path, out)
    figure = out / "figures" / "where_time_goes.png"
    assert figure.read_bytes().startswith(b"\x89PNG")
    assert "| part | µs per substep | slowest round | share of the step |" in page
    assert "| env step | ms per env step |" in page
    assert page.index("### PPO on the native") < page.index("{figure}") < \
        page.index("Command: `seaice bench where_time_goes --quick")
