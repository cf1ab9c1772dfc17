"""The leaderboard command: its files, the straight line's ratios to itself,
merging a policy in, rendering again, and refused arguments."""
import json
import math

import numpy as np
import pytest

from agents import leaderboard
from cli_checks import assert_refused

SHORT = ["--env-kwargs", "goal_distance=200.0", "length=500.0"]


def test_leaderboard_writes_its_table_and_merges_a_policy(tmp_path, capsys):
    out = tmp_path / "board"
    base = ["--concentrations", "0.2", "--episodes", "2", "--processes", "1",
            "--out", str(out)] + SHORT
    report = leaderboard.main(base + ["--policies", "straight"])
    assert {p.name for p in out.iterdir()} == {"leaderboard.json", "leaderboard.md",
                                               "leaderboard.png", "episodes.json"}
    # the record holds the summaries and the recipe, the episodes lie beside it
    record = json.loads((out / "leaderboard.json").read_text())
    assert "episodes_detail" not in record and record["summary"] == json.loads(
        json.dumps(report["summary"]))
    assert list(record["recipes"]) == ["straight"]
    assert record["recipes"]["straight"].startswith("python -m agents.leaderboard")
    s = report["summary"]["0.2"]["straight"]
    # no floe hit on some field: its ratio is undefined (NaN), never another number
    ratio = s["ratio_impulse_per_metre"]["mean"]
    assert ratio == 1.0 or math.isnan(ratio)
    assert s["ratio_path_length"]["mean"] == 1.0 and s["success_rate"] == 1.0
    merged = leaderboard.main(base + ["--policies", "straight,lattice", "--merge"])
    assert list(merged["summary"]["0.2"]) == ["straight", "lattice"]
    # the straight line's episodes are kept, not run again
    assert merged["episodes_detail"]["0.2"]["straight"] == \
        json.loads(json.dumps(report["episodes_detail"]["0.2"]["straight"]))
    # --replace runs a kept policy again: the same fields, the same episodes
    again = leaderboard.main(base + ["--policies", "straight", "--merge", "--replace",
                                     "straight"])
    assert list(again["summary"]["0.2"]) == ["straight", "lattice"]
    assert [e["ret"] for e in again["episodes_detail"]["0.2"]["straight"]] == \
        [e["ret"] for e in merged["episodes_detail"]["0.2"]["straight"]]
    text = (out / "leaderboard.md").read_text()
    assert "### Does route choice pay?" in text and "| 0.2 | lattice |" in text
    # one recipe per policy: the straight line's from the last run, the lattice's from its own
    recipes = json.loads((out / "leaderboard.json").read_text())["recipes"]
    assert "--replace straight" in recipes["straight"]
    assert "--replace" not in recipes["lattice"] and "straight,lattice" in recipes["lattice"]
    assert text.count("| `python -m agents.leaderboard") == 2
    (out / "leaderboard.md").unlink()
    leaderboard.main(["--render", "--out", str(out)])
    assert (out / "leaderboard.md").read_text() == text
    # a committed record, without its episodes: rendered from its summaries alike, and
    # merged onto only by running its policies again
    committed = tmp_path / "committed"
    committed.mkdir()
    (committed / "leaderboard.json").write_bytes((out / "leaderboard.json").read_bytes())
    leaderboard.main(["--render", "--out", str(committed)])
    assert (committed / "leaderboard.md").read_text() == text
    with pytest.raises(SystemExit):
        leaderboard.main([*base[:-len(SHORT) - 1], str(committed), *SHORT, "--policies",
                          "straight", "--merge"])
    assert "are not in" in capsys.readouterr().err
    # episodes of another host start from the same fields but round otherwise, so
    # they would not pair with new ones: merging onto them is refused ...
    assert again["host"] == leaderboard.host_signature()
    (out / "leaderboard.json").write_text(json.dumps({**again, "host": "another host"}))
    with pytest.raises(SystemExit):
        leaderboard.main(base + ["--policies", "straight", "--merge"])
    assert "another host" in capsys.readouterr().err
    # ... unless every policy of them runs again
    fresh = leaderboard.main(base + ["--policies", "straight,lattice", "--merge", "--replace",
                                     "straight,lattice"])
    assert fresh["host"] == leaderboard.host_signature()
    # the board says its engine step (the ship environments' default: the fast
    # one); a board made before the default changed ran the exact step, and
    # the two are not merged
    assert fresh["step"] == "fast"
    assert "engine step: the fast step (`free_drift=True`" in (out / "leaderboard.md").read_text()
    assert "made before the fast step became" in leaderboard.step_text({})
    older = {k: v for k, v in fresh.items() if k not in ("step", "episodes_detail")}
    (out / "leaderboard.json").write_text(json.dumps(older))
    with pytest.raises(SystemExit):
        leaderboard.main(base + ["--policies", "straight", "--merge"])
    assert "would not pair" in capsys.readouterr().err


def _episode(ret, ipm, path):
    return {"ret": ret, "final": {"impulse_per_metre": ipm, "path_length": path}}


def test_all_concentrations_are_paired_field_by_field():
    """Pooled over the concentrations, each field is paired with the
    straight line's on the same field: differences of 1, 2, 3 and 6 give a
    mean of 3 and a standard error of sqrt(14 / 3) / 2; the ratios are of
    the means over every field."""
    board = {"0.2": {"straight": [_episode(10.0, 4e3, 100.0), _episode(20.0, 6e3, 100.0)],
                     "x": [_episode(11.0, 3e3, 110.0), _episode(22.0, 4e3, 100.0)]},
             "0.3": {"straight": [_episode(30.0, 10e3, 100.0), _episode(40.0, 20e3, 100.0)],
                     "x": [_episode(33.0, 5e3, 100.0), _episode(46.0, 10e3, 110.0)]}}
    c = leaderboard.pooled_comparison(board)["x"]
    assert c["fields"] == 4
    assert c["paired_return"]["diff"] == pytest.approx(3.0, rel=1e-12)
    assert c["paired_return"]["sem"] == pytest.approx(math.sqrt(14.0 / 3.0) / 2.0, rel=1e-12)
    assert c["paired_return"]["beats"]     # 3 > 2 × 1.08
    # impulse per metre: −1, −2, −5, −10 (10³); lower is better
    assert c["paired_impulse_per_metre"]["diff"] == pytest.approx(-4.5e3, rel=1e-12)
    assert c["ipm_ratio_of_means"] == pytest.approx(22.0 / 40.0, rel=1e-12)
    assert c["path_ratio_of_means"] == pytest.approx(1.05, rel=1e-12)
    assert "straight" not in leaderboard.pooled_comparison(board)
    # without the straight line on every concentration there is nothing to pair with
    del board["0.3"]["straight"]
    assert leaderboard.pooled_comparison(board) == {}


@pytest.mark.parametrize("args, message", [
    (["--policies", "straight,nonsense"], "unknown policy"),
    (["--episodes", "1"], "at least 2"),
    (["--concentrations", "0.2", "--env-kwargs", "concentration=0.3"], "concentrations"),
    (["--trained", "ppo=/no/such/run"], "existing run directory"),
    (["--merge"], "does not exist"),
    (["--render"], "does not exist"),
    (["--replace", "straight"], "needs --merge"),
    (["--policies", "noise-0.1=agents.baselines:ZeroPolicy"], "holds a '.'"),
])
def test_leaderboard_refuses_bad_arguments(tmp_path, capsys, args, message):
    assert_refused(leaderboard.main, args, [message], tmp_path / "none", capsys)


class _FullCourse:
    """A stub agent that commands a full course (action +1) and was trained
    with control="course"."""
    agent_kwargs = {"control": "course"}

    def reset(self, seed=None):
        pass

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        return np.ones(1, np.float32), None


def test_an_agent_is_evaluated_with_its_own_control():
    """An agent trained with control="course" is played with it beside the
    baselines' yaw-rate control: a full course (45°) reaches the goal line;
    read as a full yaw rate it would sail in circles."""
    import gymnasium as gym

    from agents.rollouts import evaluate

    # the task's course_time of 2 s (one step) makes the autopilot turn at its full rate
    env = gym.make("iceenvs/ShipNavigation-v0", concentration=0.01, goal_distance=200.0,
                   length=500.0, course_time=2.0)
    try:
        runs = evaluate(env, {"course": _FullCourse()}, episodes=1, seed=0, progress=False)
        assert env.unwrapped.control == "yaw"
    finally:
        env.close()
    episode = runs["course"][0]
    assert episode["final"]["success"] == 1.0
    # the turn to 45° takes 10 steps (40 m sailed, at most 40 m gained towards the
    # goal), the rest gains cos 45° a metre: at least 40 + 160 √2 m, where the
    # straight line sails 200 m
    assert episode["final"]["path_length"] >= 40.0 + 160.0 * math.sqrt(2.0)


def test_a_trained_runs_control_is_read_and_reported(tmp_path):
    """The leaderboard plays a run trained with control="course" and the
    swath sensor in the goal frame, with the courses' room in the channel
    and the course guard, with them and says so; the same episodes as the
    policy played alone in such an environment."""
    import gymnasium as gym

    from agents import train
    from agents.rollouts import TrainedPolicy, run_agent_kwargs, run_episode

    run = tmp_path / "run"
    train.main(["--env", "iceenvs/ShipNavigation-v1", "--algo", "ppo", "--timesteps", "64",
                "--n-envs", "1", "--seed", "1", "--out", str(run), "--eval-freq", "0",
                "--no-progress", "--hyperparams", "n_steps=32", "batch_size=32", "pretrain=null",
                "--env-kwargs", "control=course", "swath_frame=goal", "swath_edge=true",
                "goal_distance=200.0", "length=500.0"])
    # the course guard comes from the file's env_kwargs, the rest from --env-kwargs
    agent = {"control": "course", "swath_frame": "goal", "swath_edge": True,
             "course_guard": 150}
    assert run_agent_kwargs(run) == agent
    out = tmp_path / "board"
    report = leaderboard.main(["--concentrations", "0.2", "--episodes", "2", "--processes",
                               "1", "--out", str(out), "--policies", "straight",
                               "--trained", f"ppo={run}"] + SHORT)
    assert report["agent_kwargs"] == {"ppo": agent}
    assert "ppo with control='course'" in (out / "leaderboard.md").read_text()
    with pytest.raises(SystemExit):            # a run of another environment is refused
        leaderboard.main(["--env", "iceenvs/ShipNavigation-v0", "--trained", f"ppo={run}",
                          "--out", str(tmp_path / "v0")])
    env = gym.make("iceenvs/ShipNavigation-v1", concentration=0.2, goal_distance=200.0,
                   length=500.0, **agent)
    try:
        alone = [run_episode(env, TrainedPolicy(run), report["seed"] + k, None)["ret"]
                 for k in range(2)]
    finally:
        env.close()
    np.testing.assert_allclose([e["ret"] for e in report["episodes_detail"]["0.2"]["ppo"]],
                               alone, rtol=1e-9)


def test_default_outputs_stay_out_of_the_docs():
    """A first run writes under runs/; the documented records are written
    only when --out names them."""
    from agents import evaluate, tasks

    for out in (leaderboard.build_parser().get_default("out"), tasks.DEFAULT_OUT):
        assert out.parts[0] == "runs", out
    assert evaluate.build_parser().get_default("out") is None      # the run's own directory


def _field(ret, ipm):
    final = {key: 1.0e6 for key in leaderboard.NORMALISED}
    final.update(impulse_per_metre=ipm, path_length=1100.0, success=1.0)
    return {"seed": 0, "ret": ret, "length": 275, "terminated": True, "final": final,
            "decision_ms": 0.1}


def test_the_two_impulse_ratios_can_disagree_and_the_board_marks_it():
    # the straight line meets little ice on field 0 and much on field 1; the policy
    # meets 5 times the first and half the second: per-field ratios 5 and 0.5 (mean
    # 2.75 > 1) against a ratio of means 55 000 / 101 000 < 1
    board = {"0.4": {"straight": [_field(100.0, 1.0e3), _field(50.0, 1.0e5)],
                     "ppo": [_field(99.0, 5.0e3), _field(70.0, 5.0e4)]}}
    summary = leaderboard.summarise_board(board)
    s = summary["0.4"]["ppo"]
    assert s["ratio_impulse_per_metre"]["mean"] == pytest.approx(2.75, rel=1e-12)
    assert s["ipm_ratio_of_means"] == pytest.approx(5.5e4 / 1.01e5, rel=1e-12)
    assert leaderboard.ratios_disagree(s)
    assert not leaderboard.ratios_disagree(summary["0.4"]["straight"])
    report = {"summary": summary, "planners": ["straight"], "env": "test", "env_kwargs": {},
              "episodes": 2, "seed": 0, "machine": "m", "date": "d", "wall_s": 1.0,
              "recipes": {"straight": "cmd a", "ppo": "cmd b"}, "episodes_detail": board}
    text = leaderboard.board_markdown(report)
    assert "| 0.545 † |" in text and "| 1.000 |" in text
    assert leaderboard.RATIO_NOTE in text


def test_policies_of_one_command_share_a_recipe_row():
    report = {"recipes": {"straight": "cmd a", "swath": "cmd a", "ppo": "cmd b"},
              "commits": {"straight": "abc", "swath": "abc", "ppo": "abc"}}
    lines = leaderboard.recipe_lines(report)
    assert lines[2:4] == ["| straight, swath | `cmd a` | abc |", "| ppo | `cmd b` | abc |"]
    # another commit is another row
    report["commits"]["swath"] = "def"
    assert len(leaderboard.recipe_lines(report)) == 2 + 3 + 1


def test_an_error_of_rounding_shows_as_zero():
    from agents.metrics import format_pm

    # the straight line's ratio to itself, summed along two paths
    assert leaderboard._plus_minus(1.0000000000000002, 1.7e-12) == "1.00 ± 0"
    assert format_pm(0.4000000000000001, 1.2e-17) == "0.400 ± 0"
    assert format_pm(2.0, 4.3e-11) == "2 ± 0"
    # a real spread, however small against the value, is kept
    assert leaderboard._plus_minus(1.0, 1.7e-6) == "1.00 ± 0.0000017"
    assert format_pm(0.00596026, 1.4e-7) == "0.00596026 ± 0.00000014"


def test_policies_are_paired_with_any_other_and_seeds_grouped():
    board = {"0.2": {"straight": [_field(100.0, 1.0), _field(50.0, 1.0)],
                     "a": [_field(99.0, 1.0), _field(70.0, 1.0)],
                     "b": [_field(103.0, 1.0), _field(56.0, 1.0)]},
             "0.3": {"straight": [_field(80.0, 1.0), _field(60.0, 1.0)],
                     "a": [_field(84.0, 1.0), _field(66.0, 1.0)],
                     "b": [_field(82.0, 1.0), _field(64.0, 1.0)]}}
    # the group of a and b: on each field the mean of their returns
    group = leaderboard.grouped(board, {"ab": ["a", "b"]})
    assert [e["ret"] for e in group["0.2"]["ab"]] == [101.0, 63.0]
    text = leaderboard.against_markdown(board, "straight", {"ab": ["a", "b"]})
    rows = {line.split(" | ")[0][2:]: line for line in text.splitlines() if line.startswith("| ")}
    # a at 0.2: differences −1 and +20, mean 9.5 ± 10.5; over all −1, 20, 4 and 6: 7.25 ± 4.5
    assert "| 9.50 ± 10 |" in rows["a"]
    assert "| 7.25 ± 4.5 | – | – |" in rows["a"]
    # ab at 0.3: differences 3 and 5, mean 4 ± 1: better by 4 standard errors
    assert "| 4.00 ± 1.0 beats |" in rows["ab"]
    assert "straight" not in rows
    # members that sailed alike: the group is each of them exactly, and paired
    # with one of them it shows no difference, not the rounding of a sum
    alike = {"0.2": {"base": [_field(r, 1.0) for r in (147.23, 171.71, 0.1)],
                     **{m: [_field(r, 1.0) for r in (147.23, 171.71, 0.1)] for m in "xyz"}}}
    assert sum([0.1] * 3) / 3 != 0.1        # what a plain mean would give
    assert [e["ret"] for e in leaderboard.grouped(alike, {"g": list("xyz")})["0.2"]["g"]] == \
        [147.23, 171.71, 0.1]
    text = leaderboard.against_markdown(alike, "base", {"g": list("xyz")})
    assert "| g | 0 ± 0 | 0 ± 0 |" in text
    with pytest.raises(ValueError, match="group ab: c not on the board"):
        leaderboard.grouped(board, {"ab": ["a", "c"]})
    with pytest.raises(ValueError, match="--against swath: not on the board"):
        leaderboard.against_markdown(board, "swath")


def test_the_steps_outside_and_the_guards_overrides_are_counted():
    """agents.rollouts counts them per episode; the comparison shows the
    mean per field and the share of steps, a group's the mean of its members'."""
    import gymnasium as gym

    from agents.baselines import ConstantPolicy
    from agents.rollouts import run_episode
    from small_envs import SMALL

    nav = "iceenvs/ShipNavigation-v1"
    # full port course under a guard of 150 m in a channel 200 m wide: overridden
    env = gym.make(nav, **{**SMALL[nav], "control": "course", "course_guard": 150.0})
    episode = run_episode(env, ConstantPolicy(env, 0, action=[1.0]), 3, None)
    assert 0 < episode["guard_overrides"] <= episode["length"]
    assert episode["outside_steps"] == 0
    env.close()
    # yaw control without a guard: a circle of 100 m radius leaves the channel, nothing is
    # overridden
    env = gym.make(nav, **SMALL[nav])
    episode = run_episode(env, ConstantPolicy(env, 0, action=[0.5]), 3, None)
    assert "guard_overrides" not in episode and episode["outside_steps"] > 0
    env.close()
    field = dict(_field(1.0, 1.0), length=100, outside_steps=4, guard_overrides=10)
    other = dict(_field(2.0, 1.0), length=100, outside_steps=0, guard_overrides=0)
    board = {"0.2": {"straight": [_field(0.0, 1.0)], "a": [field], "b": [other]}}
    text = leaderboard.against_markdown(board, "straight", {"ab": ["a", "b"]})
    assert "| 4.0 | 10.0% |" in text and "| 2.0 | 5.0% |" in text


def test_a_record_keeps_its_summaries_to_eight_significant_figures():
    value = {"a": [1.2345678912345, float("nan")], "b": {"c": -0.000123456789123}, "d": 3}
    out = leaderboard.rounded(value)
    assert out["a"][0] == 1.2345679 and math.isnan(out["a"][1])
    assert out["b"]["c"] == -0.00012345679 and out["d"] == 3
