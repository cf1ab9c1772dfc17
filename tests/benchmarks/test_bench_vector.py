"""``python -m benchmarks.bench_vector --quick``: every way of stepping and of
training runs and lands in the record (a smoke test; the figures come from
the full benchmark)."""
from __future__ import annotations

import json

import pytest

from benchmarks import bench_vector, harness

pytest.importorskip("stable_baselines3")


def test_quick_run_writes_every_configuration(tmp_path, capsys):
    path = tmp_path / "vector.json"
    assert bench_vector.main(["--quick", "--quiet", "--ids", "ShipNavigation-v0", "--json",
                        str(path)]) == 0
    record = json.loads(path.read_text())
    harness.validate_record(record)
    data = record["data"]
    assert data["settings"]["sizes"] == [2] and data["settings"]["small"]
    assert data["settings"]["ppo_rollout"] == bench_vector.QUICK["ppo_rollout"]
    modes = {(r["mode"], r["n"]) for r in data["stepping"]}
    assert modes == {("single", 1), ("sync", 2), ("subproc", 2), ("native", 2)}
    for r in data["stepping"] + data["training"]:
        assert r["min"] <= r["mean"] <= r["max"] and r["min"] > 0
    # stepping is timed over whole episodes: every sub-environment ended one
    for r in data["stepping"]:
        assert all(e >= r["n"] for e in r["episodes"]), r
    # the quick run trains without worker processes
    assert {r["mode"] for r in data["training"]} == {"sync", "native"}
    phases = data["phases"]
    for case in ("single", "empty", "native"):
        assert phases[case]["engine_ms"] > 0 and phases[case]["rest_ms"] > 0
    text = harness.render_markdown(record)
    assert "| N | single (1 core) | SyncVectorEnv (1 core) |" in text
    assert "where the time of a step goes" in text


def test_an_environment_whose_engines_do_not_advance_together_is_refused(capsys):
    with pytest.raises(SystemExit):
        bench_vector.main(["--ids", "ThicknessDistribution-v0", "--no-json"])
    assert "advances no engines together" in capsys.readouterr().err


def test_engine_clock_times_the_engine_calls_and_puts_them_back():
    """The phase timing counts each engine call of a real step (the single
    environment's ``advance`` and the vector environment's
    ``advance_together``) and leaves both as they were."""
    import gymnasium as gym

    import iceenvs.step
    from physics.hertz import HertzSimulation

    advance, together = HertzSimulation.advance, iceenvs.step.advance_together
    env = gym.make("iceenvs/ShipNavigation-v0", concentration=0.05)
    env.reset(seed=0)
    envs = gym.make_vec("iceenvs/ShipNavigation-v0", num_envs=2,
                        vectorization_mode="vector_entry_point", concentration=0.05)
    envs.reset(seed=0)
    with bench_vector._EngineClock() as clock:
        env.step(env.action_space.sample())
        envs.step(envs.action_space.sample())
    sim = env.unwrapped.sim
    per_step = round(env.unwrapped.control_interval / sim.dt)
    assert clock.sims == 3
    assert clock.substeps == per_step + sum(
        round(e.control_interval / e.sim.dt) for e in envs.unwrapped.envs)
    assert clock.seconds > 0.0 and clock.floes >= sim.n_floes
    assert HertzSimulation.advance is advance
    assert iceenvs.step.advance_together is together
