"""How a waypoint student's error falls with its labels
(agents.imitation_scaling): the split keeps test fields apart and nests
the shares, the law is the line through log error against log labels, and
a run's kept labels refit its own student."""
import json

import numpy as np
import pytest

from agents.imitation_scaling import (main, power_law, refit_error, render, scaling,
                                      split_fields)
from agents.imitation_scaling import load_labels
from agents.waypoints import train_student
from small_envs import SMALL

NAV = "iceenvs/ShipNavigation-v1"
KWARGS = {**SMALL[NAV], "length": 300.0, "goal_distance": 150.0}


def test_the_test_fields_are_apart_and_the_shares_nested():
    rounds = np.repeat([0, 1], 60)                       # two rounds of 6 fields, 10 decisions
    fields = np.concatenate([np.repeat(np.arange(100, 106), 10),
                             np.repeat(np.arange(200, 206), 10)])
    test, trains = split_fields(rounds, fields, 2, [0.25, 0.5, 1.0], seed=3)
    for r in (0, 1):
        assert len(np.unique(fields[test & (rounds == r)])) == 2
        sizes = [len(np.unique(fields[t & (rounds == r)])) for t in trains]
        assert sizes == [1, 2, 4]                           # ⌈f × 4⌉ of the 4 left
    for small, large in zip(trains, trains[1:]):
        assert not np.any(small & ~large)                   # nested
    assert not np.any(test & trains[-1]) and np.all(test | trains[-1])
    # the same seed draws the same split, another seed another
    again, _ = split_fields(rounds, fields, 2, [0.25, 0.5, 1.0], seed=3)
    assert np.array_equal(test, again)
    others = [split_fields(rounds, fields, 2, [1.0], seed=s)[0] for s in range(4, 10)]
    assert any(not np.array_equal(test, o) for o in others)
    with pytest.raises(ValueError, match="too few"):
        split_fields(rounds, fields, 6, [1.0], seed=3)
    with pytest.raises(ValueError, match="fractions"):
        split_fields(rounds, fields, 2, [0.0, 1.0], seed=3)
    with pytest.raises(ValueError, match="one length"):
        split_fields(rounds, fields[:-1], 2, [1.0], seed=3)


def test_the_law_is_the_line_through_log_error_against_log_labels():
    n = np.array([1000.0, 2000.0, 4000.0, 8000.0])
    law = power_law(n, 0.3 * n ** -0.4, targets=[0.01])
    assert law["alpha"] == pytest.approx(0.4, rel=1e-9)
    assert law["c"] == pytest.approx(0.3, rel=1e-9)
    # 0.3 n^-0.4 = 0.01 at n = 30^(1/0.4)
    assert law["decisions_for"]["0.01"] == pytest.approx(30.0 ** 2.5, rel=1e-9)
    assert power_law(n, 0.01 * n ** 0.1, targets=[0.005])["decisions_for"]["0.005"] is None
    with pytest.raises(ValueError, match="two or more positive"):
        power_law([1000.0], [0.05])


def test_a_runs_kept_labels_refit_its_own_student(tmp_path):
    settings = dict(env_kwargs=KWARGS, episodes=3, rounds=1, epochs=2, held_out_episodes=1,
                    refit="fresh", teacher="costmap-lattice")
    kept = train_student(tmp_path / "kept", 4, progress=False, quiet=True, keep_labels=True,
                         **settings)
    assert kept["settings"]["keep_labels"] is True
    data = load_labels(tmp_path / "kept")
    assert len(data["labels"]) == sum(r["decisions"] for r in kept["rounds"])
    assert len(data["held_labels"]) == kept["held_out"]["decisions"]
    assert sorted(np.unique(data["field"])) == list(range(30000, 30006))
    assert np.array_equal(np.unique(data["field"][data["round"] == 1]), [30003, 30004, 30005])
    assert np.all(data["held_field"] == 50000)
    # the last round's fit, on every label with the run's seeds, is the run's student
    last = kept["rounds"][-1]
    again = refit_error(data, np.ones(len(data["labels"]), dtype=bool), {"held": None},
                        epochs=2, fit_seed=4 * 1000 + 1)
    assert again["own"] == pytest.approx(last["action_mse"] / last["action_variance"], rel=1e-3)
    held = kept["held_out"]
    assert again["held"] == pytest.approx(held["action_mse"] / held["action_variance"],
                                          rel=1e-3)
    # the study on it: two shares, one test field a round
    record = scaling([tmp_path / "kept"], tmp_path / "study", progress=False,
                     fractions=[0.5, 1.0], test_fields=1, epochs=1, extra_epochs=[3])
    fits = record["runs"][(tmp_path / "kept").as_posix()]
    assert [f["epochs"] for f in fits.values()] == [2, 1, 3]
    assert fits["share 0.5"]["decisions"] < fits["share 1"]["decisions"]
    assert fits["share 1"]["decisions"] == fits["all, 3 epochs"]["decisions"]
    assert all(f[t] > 0.0 for f in fits.values() for t in ("own", "test", "held"))
    assert json.loads((tmp_path / "study" / "scaling.json").read_text()) == record
    assert "| share 0.5 |" in (tmp_path / "study" / "scaling.md").read_text()
    assert (tmp_path / "study" / "scaling.png").stat().st_size > 0
    laws = record["laws"][(tmp_path / "kept").as_posix()]
    assert set(laws) == {"test", "held", "test_last", "held_last", "decisions_a_second"}
    # two shares: the line through all is the line through the two largest
    assert laws["test"]["alpha"] == pytest.approx(laws["test_last"]["alpha"], rel=1e-9)
    # rendered again from the record alone, the tables are the same
    table = (tmp_path / "study" / "scaling.md").read_text()
    assert render(tmp_path / "study")["laws"] == record["laws"]
    assert (tmp_path / "study" / "scaling.md").read_text() == table


def test_bad_input_is_refused(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main([str(tmp_path), "--out", str(tmp_path / "out"), "--no-progress"])
    assert "not a run of python -m agents.waypoints train" in capsys.readouterr().err
    (tmp_path / "waypoints.json").write_text(json.dumps({"settings": {"form": "waypoints"}}))
    with pytest.raises(SystemExit):
        main([str(tmp_path), "--out", str(tmp_path / "out"), "--no-progress"])
    assert "--keep-labels" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["--render", "--out", str(tmp_path / "nothing")])
    assert "no scaling.json" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["--out", str(tmp_path / "out")])
    assert "give one or more run directories" in capsys.readouterr().err
    with pytest.raises(ValueError, match="two or more different shares"):
        scaling([tmp_path], tmp_path / "out", fractions=[1.0])
    with pytest.raises(ValueError, match="give the share 1 among the fractions"):
        scaling([tmp_path], tmp_path / "out", fractions=[0.25, 0.5], extra_epochs=[10])
    with pytest.raises(ValueError, match="unknown settings"):
        scaling([tmp_path], tmp_path / "out", epocs=3)
