"""Waypoint decisions (agents.waypoints): the lattice's two-stage waypoints
are the lattice, the route of a decision, a DAgger run that trains and
plays, and bad input refused."""
import json

import gymnasium as gym
import numpy as np
import pytest

from agents.planners import CostmapLatticePlanner, LatticePlanner
from agents.rollouts import run_episode
from agents.waypoints import (STAGE_CHOICES, WAYPOINT_DISTANCE, LatticeWaypoints, WaypointStudent,
                              decision_observation, decision_space, main, make_student,
                              mirrored, report, train_student, with_mirror)
from small_envs import SMALL

NAV = "iceenvs/ShipNavigation-v1"
# a short transit: about 60 steps of the small field
KWARGS = {**SMALL[NAV], "length": 300.0, "goal_distance": 150.0}


def sail(policy_class, seed, concentration=0.2, **kwargs):
    env = gym.make(NAV, **{**KWARGS, "concentration": concentration})
    try:
        policy = policy_class(env, seed=seed, **kwargs)
        obs, _ = env.reset(seed=seed)
        policy.reset(seed)
        rewards, positions, done = [], [], False
        while not done:
            obs, reward, terminated, truncated, _ = env.step(policy.predict(obs)[0])
            rewards.append(reward)
            positions.append(np.array(env.unwrapped.sim.ship.position))
            done = terminated or truncated
        return np.array(rewards), np.array(positions), policy
    finally:
        env.close()


@pytest.mark.parametrize("seed, form", [(1, "waypoints"), (7, "waypoints"), (1, "stages"),
                                        (7, "stages")])
def test_two_waypoints_at_the_stage_ends_sail_the_lattices_episode(seed, form):
    # the lattice's route is straight from stage to stage (30 m) and it replans
    # every 5 steps: a decision every 5 steps of its route's points 30 and 60 m
    # ahead is its route over the 20 m sailed until the next, so the pure
    # pursuit steers alike (the lattice also replans when 10 m off its route,
    # which a ship on its route is not); its first two stages are one of nine
    # choices of their slopes
    lattice, ship_l, _ = sail(LatticePlanner, seed, 0.4, show=False)
    waypoints, ship_w, policy = sail(LatticeWaypoints, seed, 0.4, form=form)
    np.testing.assert_array_equal(waypoints, lattice)
    np.testing.assert_array_equal(ship_w, ship_l)
    assert len(policy.decisions) == -(-len(lattice) // 5)
    assert len({str(d) for d in policy.decisions}) > 1      # it did steer


@pytest.mark.parametrize("form, blur", [("waypoints", 0.0), ("stages", 0.0),
                                        ("waypoints", 2.0)])
def test_the_costmap_teacher_sails_the_costmap_lattices_episode(form, blur):
    """Taught by the lattice on the costmap, the decisions sail the episode
    of :class:`CostmapLatticePlanner`, as the lattice's sail the lattice's
    (and with a blur of the cost, that of the planner with the same blur)."""
    planner, ship_p, _ = sail(CostmapLatticePlanner, 1, 0.4, show=False, blur=blur)
    waypoints, ship_w, policy = sail(LatticeWaypoints, 1, 0.4, form=form,
                                     teacher="costmap-lattice", blur=blur)
    np.testing.assert_array_equal(waypoints, planner)
    np.testing.assert_array_equal(ship_w, ship_p)
    assert policy.reads_environment == "its costmap"
    with pytest.raises(ValueError, match="teacher must be one of"):
        sail(LatticeWaypoints, 1, 0.4, teacher="oracle")


def test_a_teacher_with_settings_of_its_own_plans_with_them_at_the_followers_pace():
    """``settings``: the teacher's routes are planned with a tuned planner's
    route settings (its pace and pursuit settings are the follower's own),
    by the episode's concentration when ``bounds`` are given; so it sails
    the episode of a follower whose own settings they are."""
    own = {"blur": 2.5, "metre_cost": 30000.0}
    other = {"blur": 0.0, "metre_cost": 300.0, "fade": 150.0}
    pace = {"lookahead": 20.0, "replan_steps": 7}
    for a, setting in ((0.2, own), (0.4, other)):
        ref, ship_r, _ = sail(LatticeWaypoints, 1, a, teacher="costmap-lattice", **setting)
        one, ship_1, _ = sail(LatticeWaypoints, 1, a, teacher="costmap-lattice",
                              settings=[{**setting, **pace}])
        both, ship_b, policy = sail(LatticeWaypoints, 1, a, teacher="costmap-lattice",
                                    bounds=[0.3], settings=[{**own, **pace}, other])
        for rewards, ship in ((one, ship_1), (both, ship_b)):
            np.testing.assert_array_equal(rewards, ref)
            np.testing.assert_array_equal(ship, ship_r)
        assert len(policy.decisions) == -(-len(ref) // 5)     # the follower's pace
    # the two settings sail apart, so the comparisons above can fail
    _, apart, _ = sail(LatticeWaypoints, 1, 0.4, teacher="costmap-lattice", **own)
    assert abs(apart[-1, 1] - ship_r[-1, 1]) > 1.0
    env = gym.make(NAV, **KWARGS)
    for bad, match in ((dict(settings=[own], bounds=[0.3]), "2 mapping"),
                       (dict(settings=[{"cone": False}]), "a route's settings"),
                       (dict(bounds=[0.3]), "give settings too"),
                       (dict(settings=[own, own], bounds=[1.5]), "bounds must increase"),
                       (dict(settings=own), "1 mapping")):
        with pytest.raises(ValueError, match=match):
            LatticeWaypoints(env, teacher="costmap-lattice", **bad)
    env.close()


def test_a_tuned_planners_policy_string_gives_the_teachers_routes(tmp_path):
    """``teacher_route``: a planner's policy string as the teacher's route
    settings; a DAgger run keeps it in its record, and a teacher of the
    other kind is refused."""
    from agents.waypoint_follower import teacher_route

    joined = ("agents.tuned_lattice:ByConcentration?bounds=[0.45]&settings=[{metre_cost: 4000, "
              "blur: 2, lookahead: 25, replan_steps: 6}, {metre_cost: 7000, max_slope: 0.3}]")
    assert teacher_route(joined) == ("costmap-lattice", {
        "bounds": [0.45], "settings": [{"metre_cost": 4000, "blur": 2, "lookahead": 25,
                                        "replan_steps": 6},
                                       {"metre_cost": 7000, "max_slope": 0.3}]})
    assert teacher_route("agents.planners:LatticePlanner?blur=1.5") == (
        "lattice", {"bounds": None, "settings": [{"blur": 1.5}]})
    with pytest.raises(ValueError, match="a teacher's routes are a planner's"):
        teacher_route("agents.planners:RolloutPlanner?margin=1")
    record = train_student(tmp_path / "run", 0, progress=False, quiet=True, env_kwargs=KWARGS,
                           episodes=1, rounds=0, epochs=1, held_out_episodes=1,
                           teacher="costmap-lattice", teacher_policy=joined)
    assert record["settings"]["teacher_policy"] == joined
    report([tmp_path / "run"], tmp_path / "report")
    assert "costmap-lattice (its own settings)" in (tmp_path / "report" / "waypoints.md").read_text()
    with pytest.raises(ValueError, match="give teacher 'costmap-lattice'"):
        train_student(tmp_path / "bad", 0, progress=False, teacher_policy=joined)


def test_a_noisy_teacher_sails_its_labels_plus_seeded_normal_errors(monkeypatch):
    """``noise`` σ: each decision sailed is the teacher's label plus normal
    errors of σ drawn from a generator seeded by the episode, then clipped;
    the same seed sails the same episode, another seed other decisions."""
    labels = []
    label = LatticeWaypoints.label

    def kept(self):
        labels.append(label(self))
        return labels[-1]

    monkeypatch.setattr(LatticeWaypoints, "label", kept)
    sigma = 0.2
    rewards, _, policy = sail(LatticeWaypoints, 3, 0.4, teacher="costmap-lattice",
                              noise=sigma)
    errors = np.random.default_rng(3).normal(0.0, sigma, (len(labels), 2))
    np.testing.assert_allclose(np.array(policy.decisions),
                               np.clip(np.array(labels) + errors, -1.0, 1.0), rtol=0, atol=1e-12)
    again, _, _ = sail(LatticeWaypoints, 3, 0.4, teacher="costmap-lattice", noise=sigma)
    np.testing.assert_array_equal(again, rewards)
    labels.clear()
    _, _, other = sail(LatticeWaypoints, 4, 0.4, teacher="costmap-lattice", noise=sigma)
    errors = np.random.default_rng(4).normal(0.0, sigma, (len(labels), 2))
    np.testing.assert_allclose(np.array(other.decisions),
                               np.clip(np.array(labels) + errors, -1.0, 1.0), rtol=0, atol=1e-12)
    env = gym.make(NAV, **KWARGS)
    for bad in (-0.1, float("nan"), True):
        with pytest.raises(ValueError, match="noise must be"):
            LatticeWaypoints(env, noise=bad)
    with pytest.raises(ValueError, match="form 'waypoints' only"):
        LatticeWaypoints(env, form="stages", noise=0.1)
    env.close()


def test_a_decision_is_two_waypoints_along_the_channel_kept_inside_its_edges():
    env = gym.make(NAV, **KWARGS)
    env.reset(seed=1)
    policy = LatticeWaypoints(env)
    u = env.unwrapped
    x, y = (float(v) for v in u.sim.ship.position)
    route = policy.waypoint_route(np.array([0.5, -0.25]))
    # w_k is the slope to waypoint k as a fraction of the steepest, 0.5
    np.testing.assert_allclose(route[:3], [[x, y], [x + 30.0, y + 0.5 * 0.5 * 30.0],
                                           [x + WAYPOINT_DISTANCE, y - 0.25 * 0.5 * 60.0]])
    assert route[3, 1] == route[2, 1] and route[3, 0] > route[2, 0]
    # a waypoint past the edge margin is moved inside it (a margin that leaves
    # 20 m either side of the centre line)
    policy.edge_margin = 0.5 * u.channel_width - 20.0
    assert y == pytest.approx(u.centre_y)
    np.testing.assert_allclose(policy.waypoint_route(np.array([1.0, 1.0]))[1:, 1],
                               [y + 15.0, y + 20.0, y + 20.0])
    np.testing.assert_allclose(policy.waypoint_route(np.array([-1.0, -1.0]))[1:, 1],
                               [y - 15.0, y - 20.0, y - 20.0])
    env.close()


def test_the_decision_observation_is_the_costmap_and_the_ships_pose():
    env = gym.make(NAV, **KWARGS)
    env.reset(seed=2)
    seen = decision_observation(env)
    assert decision_space(env).contains(seen)
    np.testing.assert_array_equal(seen["costmap"], env.unwrapped.costmap())
    ship = env.unwrapped.sim.ship
    assert seen["vector"][0] == pytest.approx((ship.position[1] - env.unwrapped.centre_y) / 100)
    env.close()


@pytest.mark.parametrize("form", ["stages", "waypoints"])
def test_a_dagger_run_trains_a_student_that_plays(tmp_path, form):
    record = train_student(tmp_path / "run", 0, progress=False, quiet=True, env_kwargs=KWARGS,
                           form=form, episodes=1, rounds=1, epochs=2, held_out_episodes=1)
    assert [r["beta"] for r in record["rounds"]] == [1.0, 0.5]
    assert all(r["decisions"] > 5 for r in record["rounds"])
    held = record["held_out"]
    assert held["decisions"] > 5
    if form == "stages":
        assert 0.0 <= held["action_accuracy"] <= 1.0
    else:
        assert held["action_mse"] >= 0.0 and held["action_variance"] >= 0.0
    assert json.loads((tmp_path / "run" / "waypoints.json").read_text()) == record
    env = gym.make(NAV, **KWARGS)
    student = WaypointStudent(env, run=str(tmp_path / "run"))
    assert student.form == form
    episode = run_episode(env, student, seed=4, main_metric=None)
    env.close()
    assert episode["length"] > 5 and np.isfinite(episode["ret"])
    if form == "stages":
        assert all(d in range(9) for d in student.decisions)
    else:
        assert all(np.all(np.abs(w) <= 1.0) for w in student.decisions)
    # the runs' records gathered: one record and a table
    gathered = report([tmp_path / "run"], tmp_path / "report")
    assert gathered == {(tmp_path / "run").as_posix(): record}
    assert "| 1 | 0.5 |" in (tmp_path / "report" / "waypoints.md").read_text()
    # played where the costmap differs from the training's, it says so
    if form == "waypoints":
        longer = gym.make(NAV, **{**KWARGS, "costmap_ahead": 400.0})
        with pytest.raises(ValueError, match="trained on costmaps of shape"):
            WaypointStudent(longer, run=str(tmp_path / "run"))
        longer.close()


@pytest.mark.parametrize("refit, networks", [("warm", 1), ("fresh", 3)])
def test_a_fresh_refit_fits_a_new_network_each_round(tmp_path, monkeypatch, refit, networks):
    """``refit="fresh"``: each round after the first fits a network made anew
    (seeded alike) on all labels so far; ``"warm"`` goes on with one."""
    import agents.waypoints as waypoints

    made = []

    def counted(*args, **kwargs):
        made.append(kwargs.get("seed"))
        return make_student(*args, **kwargs)

    monkeypatch.setattr(waypoints, "make_student", counted)
    record = train_student(tmp_path / "run", 7, progress=False, quiet=True,
                           env_kwargs=KWARGS, episodes=1, rounds=2, epochs=1,
                           held_out_episodes=1, refit=refit, teacher="costmap-lattice")
    assert made == [7] * networks
    assert record["settings"]["refit"] == refit
    assert record["settings"]["teacher"] == "costmap-lattice"
    with pytest.raises(ValueError, match="refit must be one of"):
        train_student(tmp_path / "bad", 7, progress=False, refit="cold")


def test_bad_input_is_refused(tmp_path, capsys):
    with pytest.raises(ValueError, match="unknown settings"):
        train_student(tmp_path, 0, progress=False, epocs=3)
    with pytest.raises(ValueError, match="beta"):
        train_student(tmp_path, 0, progress=False, beta=1.5)
    with pytest.raises(ValueError, match="rounds"):
        train_student(tmp_path, 0, progress=False, rounds=-1)
    with pytest.raises(ValueError, match="form"):
        train_student(tmp_path, 0, progress=False, form="route")
    with pytest.raises(ValueError, match="decides two waypoints"):
        train_student(tmp_path, 0, progress=False, form="stages", points=3)
    env = gym.make(NAV, **KWARGS)
    with pytest.raises(FileNotFoundError, match="agents.waypoints train"):
        WaypointStudent(env, run=str(tmp_path / "none"))
    with pytest.raises(ValueError, match="points"):
        LatticeWaypoints(env, points=0)
    with pytest.raises(ValueError, match="distance"):
        LatticeWaypoints(env, distance=-5.0)
    with pytest.raises(ValueError, match="first two stages"):
        LatticeWaypoints(env, form="stages", distance=90.0)
    with pytest.raises(FileNotFoundError, match="not a run"):
        report([tmp_path], tmp_path / "out")
    with pytest.raises(SystemExit):
        main(["train", "--out", str(tmp_path), "--episodes", "0"])
    assert "episodes must be an integer >= 1" in capsys.readouterr().err
    env.close()


def test_the_mirror_of_a_field_is_seen_and_planned_as_its_mirror_image(monkeypatch):
    # the ship starts on the centre line: reflect every floe across it and the
    # costmap is the same with its columns reversed, and the lattice's waypoints
    # are the same with their shifts negated
    env = gym.make(NAV, **{**KWARGS, "concentration": 0.4})
    env.reset(seed=5)
    u = env.unwrapped
    teacher = LatticeWaypoints(env)
    seen, label = decision_observation(env), teacher.label()
    centre = u.centre_y
    assert u.sim.ship.position[1] == pytest.approx(centre)
    reflected = u.sim.positions.copy()
    reflected[:, 1] = np.mod(2.0 * centre - reflected[:, 1], u.sim.box.ly)
    # the engine's floes as the sensors and the planner read them, reflected
    monkeypatch.setattr(type(u.sim), "positions", property(lambda self: reflected))
    seen_m, label_m = decision_observation(env), teacher.label()
    env.close()
    flipped, flipped_label = mirrored(seen, label)
    assert seen["costmap"][0].max() > 0.5         # there is ice to see
    np.testing.assert_allclose(seen_m["costmap"], flipped["costmap"], rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(seen_m["vector"], flipped["vector"], atol=1e-7)
    assert np.abs(label).max() > 0.05             # the lattice turns ...
    np.testing.assert_allclose(label_m, flipped_label, atol=1e-12)   # ... the other way
    # off the centre line, turned and turning: the pose is mirrored too
    pose = {"costmap": np.arange(6.0).reshape(1, 1, 2, 3), "vector": np.array([[0.1, -0.2, 0.3]])}
    image, shifts = mirrored(pose, np.array([[0.4, -0.5]]))
    np.testing.assert_array_equal(image["vector"], [[-0.1, 0.2, -0.3]])
    np.testing.assert_array_equal(image["costmap"][0, 0], [[2.0, 1.0, 0.0], [5.0, 4.0, 3.0]])
    np.testing.assert_array_equal(shifts, [[-0.4, 0.5]])
    # the training's one array of the decisions and their images
    both, labels = with_mirror(pose, np.array([[0.4, -0.5]]))
    np.testing.assert_array_equal(both["costmap"], np.concatenate([pose["costmap"], image["costmap"]]))
    np.testing.assert_array_equal(both["vector"], [[0.1, -0.2, 0.3], [-0.1, 0.2, -0.3]])
    np.testing.assert_array_equal(labels, [[0.4, -0.5], [-0.4, 0.5]])
    _, choices = with_mirror(pose, np.array([0]), "stages")
    np.testing.assert_array_equal(choices, [0, len(STAGE_CHOICES) - 1])


def test_a_stage_choice_turns_each_stage_by_at_most_one_slope_step():
    env = gym.make(NAV, **KWARGS)
    env.reset(seed=1)
    policy = LatticeWaypoints(env, form="stages")
    # heading +x: slope 0; choice c turns the first stage by c // 3 - 1 steps of
    # 1.5 m per 30 m and the second by c % 3 - 1 more
    for c, (a, b) in enumerate(STAGE_CHOICES):
        w = policy.stage_waypoints(c)
        np.testing.assert_allclose(w * 0.5 * np.array([30.0, 60.0]), [1.5 * a, 1.5 * (2 * a + b)])
    assert STAGE_CHOICES[8 - 3] == tuple(-t for t in STAGE_CHOICES[3])
    env.close()
