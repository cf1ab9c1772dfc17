"""The costmap lattice's route moved by a chosen offset (agents.route_offsets):
keeping the route sails the costmap lattice, the teacher keeps its best
rollout and leaves the episode as it was, a training run makes a learner
that plays, and bad input is refused."""
import json

import gymnasium as gym
import numpy as np
import pytest

from agents.planners import CostmapLatticePlanner
from agents.route_offsets import (KEEP, OFFSETS, OffsetChooser, OffsetStudent, RolloutOffsets,
                                  crossfit, gains_of, load_labels, main, refit, report,
                                  train_offsets)
from agents.waypoints import WaypointStudent
from test_waypoints import KWARGS, NAV, sail


class _Always(OffsetChooser):
    def __init__(self, env, seed=0, choice=KEEP, **kwargs):
        super().__init__(env, seed, **kwargs)
        self.choice = choice

    def choose(self, obs, base):
        return self.choice


def test_keeping_the_route_sails_the_costmap_lattice():
    """Choice 0 m keeps the costmap lattice's waypoints, which sail its
    episode; a teacher whose margin no rollout beats keeps them too, so its
    rollouts from snapshots leave the episode exactly as it was."""
    planner, ship_p, _ = sail(CostmapLatticePlanner, 1, 0.4, show=False)
    kept, ship_k, policy = sail(_Always, 1, 0.4)
    np.testing.assert_array_equal(kept, planner)
    np.testing.assert_array_equal(ship_k, ship_p)
    assert policy.choices == [KEEP] * len(policy.choices) and len(policy.choices) > 3
    taught, ship_t, teacher = sail(RolloutOffsets, 1, 0.4, margin=1e9, rollout_steps=10)
    np.testing.assert_array_equal(taught, planner)
    np.testing.assert_array_equal(ship_t, ship_p)
    assert len(teacher.returns) == len(teacher.choices)
    assert all(len(r) == len(OFFSETS) for r in teacher.returns)
    assert len({r for rs in teacher.returns for r in rs}) > len(OFFSETS)   # they differ


def test_the_teacher_keeps_the_best_rollout_by_more_than_its_margin():
    _, _, teacher = sail(RolloutOffsets, 2, 0.4, margin=0.5, rollout_steps=10)
    for choice, returns in zip(teacher.choices, teacher.returns):
        best = int(np.argmax(returns))
        if returns[best] - returns[KEEP] > 0.5:
            assert choice == best
        else:
            assert choice == KEEP
    assert teacher.reads_environment.startswith("its costmap")


def test_an_offset_moves_every_waypoint_across_the_channel_by_its_metres():
    env = gym.make(NAV, **{**KWARGS, "concentration": 0.2})
    env.reset(seed=1)
    chooser = _Always(env)
    y = float(env.unwrapped.sim.ship.position[1])
    kept = chooser.waypoint_route(chooser.moved(np.zeros(2), KEEP))
    for c, offset in enumerate(OFFSETS):
        route = chooser.waypoint_route(chooser.moved(np.zeros(2), c))
        np.testing.assert_allclose(route[1:3, 1] - kept[1:3, 1], offset, atol=1e-9)
        assert route[1, 1] == pytest.approx(y + offset, abs=1e-9)
        # the mirror image of a choice is its offset negated
        assert OFFSETS[len(OFFSETS) - 1 - c] == -offset
    env.close()


def test_a_training_run_makes_a_learner_that_plays(tmp_path, capsys):
    out = tmp_path / "run"
    record = train_offsets(out, 1, progress=False, quiet=True, episodes=1, rounds=1, epochs=1,
                           rollout_steps=10,
                           env_kwargs={**KWARGS, "concentration": 0.4, "costmap_ahead": 300.0})
    assert [r["round"] for r in record["rounds"]] == [0, 1]
    assert sum(record["labels"]) == sum(r["decisions"] for r in record["rounds"]) > 0
    assert all(0.0 <= r["moved"] <= 1.0 and 0.0 <= r["action_accuracy"] <= 1.0
               for r in record["rounds"])
    assert json.loads((out / "offsets.json").read_text())["settings"]["offsets"] == list(OFFSETS)
    with np.load(out / "labels.npz") as saved:
        n = sum(record["labels"])
        assert saved["labels"].shape == (n,) and saved["returns"].shape == (n, len(OFFSETS))
        assert saved["costmap"].shape[0] == n and sorted(set(saved["round"])) == [0, 1]
        np.testing.assert_array_equal(np.bincount(saved["labels"], minlength=len(OFFSETS)),
                                      record["labels"])
    rewards, _, learner = sail(OffsetStudent, 1, 0.4, run=str(out))
    assert len(learner.choices) == -(-len(rewards) // 5)
    assert all(0 <= c < len(OFFSETS) for c in learner.choices)
    with pytest.raises(ValueError, match="route_offsets:OffsetStudent"):
        sail(WaypointStudent, 1, 0.4, run=str(out))
    with pytest.raises(ValueError, match="holds no offset learner"):
        sail(OffsetStudent, 1, 0.4, run=str(tmp_path))
    gathered = tmp_path / "gathered"
    assert main(["report", str(out), "--out", str(gathered), "--held-out", "1",
                 "--held-out-seed", "7", "--no-progress"]) == 0
    assert (gathered / "offsets.md").read_text().count(str(out)) == 2
    assert (gathered / "offsets.png").stat().st_size > 0
    held = json.loads((gathered / "offsets.json").read_text())[out.as_posix()]["held_out"]
    assert held["decisions"] > 3 and 0.0 <= held["accuracy"] <= 1.0
    assert str(out) in (gathered / "held-out.md").read_text()


def test_labels_are_the_rollouts_best_and_learners_are_fitted_on_them_again(tmp_path):
    """The saved labels are the margin's rule on the saved rollout returns,
    so each earns at least what keeping the route does (more than the
    margin where it moves); a refit and a cross-fit need no rollouts."""
    import shutil

    out = tmp_path / "run"
    train_offsets(out, 2, progress=False, quiet=True, episodes=2, rounds=0, epochs=1,
                  rollout_steps=10, margin=0.2,
                  env_kwargs={**KWARGS, "concentration": 0.4, "costmap_ahead": 300.0})
    saved = load_labels(out)
    expected = [int(np.argmax(r)) if max(r) - r[KEEP] > 0.2 else KEEP for r in saved["returns"]]
    assert saved["labels"].tolist() == expected
    gains = gains_of(saved["returns"], saved["labels"])
    assert np.all(gains >= 0.0) and np.all(gains[saved["labels"] != KEEP] > 0.2)
    assert main(["refit", "--run", str(out), "--out", str(tmp_path / "refit"),
                 "--oversample", "3", "--epochs", "1"]) == 0
    rewards, _, learner = sail(OffsetStudent, 1, 0.4, run=str(tmp_path / "refit"))
    assert len(learner.choices) == -(-len(rewards) // 5)
    again = json.loads((tmp_path / "refit" / "offsets.json").read_text())
    assert again["settings"]["oversample"] == 3 and again["refit_of"] == out.as_posix()
    shutil.copytree(out, tmp_path / "twin")
    record = crossfit([out, tmp_path / "twin"], tmp_path / "cross", (1, 3), progress=False,
                      epochs=1)
    assert [(r["oversample"], r["decisions"]) for r in record["rows"]] == \
        [(m, len(expected)) for m in (1, 3) for _ in range(2)]
    assert all(r["teacher_gain"] >= 0.0 for r in record["rows"])
    assert (tmp_path / "cross" / "crossfit.md").read_text().count("| 3 |") >= 2
    with pytest.raises(ValueError, match="at least two runs"):
        crossfit([out], tmp_path / "cross")
    with pytest.raises(ValueError, match="unknown settings"):
        refit(out, tmp_path / "r2", episodes=3)
    with pytest.raises(ValueError, match="oversample must be"):
        refit(out, tmp_path / "r2", oversample=0)
    with pytest.raises(FileNotFoundError, match="labels.npz"):
        load_labels(tmp_path)
    # a file whose returns are not one row a decision is read without them
    np.savez(tmp_path / "twin" / "labels.npz", **{**saved, "returns": saved["returns"][:1]})
    assert "returns" not in load_labels(tmp_path / "twin")
    record = crossfit([out, tmp_path / "twin"], tmp_path / "cross", (1,), progress=False,
                      epochs=1)
    assert record["rows"][1]["gain"] is None and record["rows"][0]["gain"] is not None


def test_bad_input_is_refused(tmp_path):
    env = gym.make(NAV, **KWARGS)
    with pytest.raises(ValueError, match="rollout_steps must be"):
        RolloutOffsets(env, rollout_steps=3)
    with pytest.raises(ValueError, match="margin must be"):
        RolloutOffsets(env, margin=-1.0)
    with pytest.raises(ValueError, match="takes no teacher"):
        _Always(env, teacher="lattice")
    with pytest.raises(ValueError, match="form 'waypoints'"):
        _Always(env, form="stages")
    obs, _ = env.reset(seed=1)
    with pytest.raises(ValueError, match="not a choice"):
        _Always(env, choice=len(OFFSETS)).predict(obs)
    env.close()
    with pytest.raises(ValueError, match="unknown settings"):
        train_offsets(tmp_path, 1, episode=3)
    with pytest.raises(ValueError, match="beta must lie"):
        train_offsets(tmp_path, 1, beta=2.0)
    with pytest.raises(FileNotFoundError, match="agents.route_offsets train"):
        report([tmp_path], tmp_path / "out")
