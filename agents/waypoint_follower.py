"""The waypoint decision and its follower: what the waypoint learner
(:mod:`agents.waypoints`) decides every 10 s, what it decides on, and the
pure pursuit that sails a decision until the next.

* :func:`decision_observation` (space :func:`decision_space`): the
  environment's costmap beside the ship's pose in the channel;
* :class:`WaypointFollower`: decides every ``interval`` steps
  (:meth:`~WaypointFollower.decide`, for a subclass to give) and follows the
  route through the decision's waypoints by the lattice planner's pure
  pursuit in between;
* :class:`LatticeWaypoints`: the lattice planner's decision, the teacher;
* :class:`WaypointStudent`: the learned decision, played from a run
  directory (``student.zip``); :func:`student_record` tells such a run
  from a run of :mod:`agents.train`;
* :class:`WaypointResidual`: the costmap lattice's decision corrected by a
  learned one (a fine-tuning with ``residual``).

The student's training is in :mod:`agents.waypoints`, which names all of these too;
fine-tuning by reinforcement learning in :mod:`agents.waypoint_rl`.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from .planners import (CostmapLatticePlanner, LatticePlanner, check_settings,
                       concentration_bounds, costmap_cost_grid, planner_for)

__all__ = ["DECISION_STEPS", "WAYPOINT_DISTANCE", "FORMS", "STAGE_CHOICES", "STUDENT", "RECORD",
           "FINETUNE_RECORD", "OFFSETS_RECORD", "PRIVILEGED", "TEACHERS", "ROUTE_SETTINGS",
           "PACE_SETTINGS", "ROUTE_TEACHERS", "route_planners", "teacher_route", "WaypointFollower",
           "Commanded", "WaypointStudent",
           "LatticeWaypoints", "WaypointResidual", "decision_observation", "decision_space",
           "load_student", "is_residual", "rollout_decision", "sail_fields", "student_decision",
           "student_record",
           "gather_records", "write_gathered"]

#: environment steps between decisions (10 s: the lattice planner's replan)
DECISION_STEPS = 5
#: how far ahead [m] along the channel the waypoint lies
WAYPOINT_DISTANCE = 60.0
#: the forms of a decision: ``points`` lateral shifts (continuous), or one of
#: the lattice's nine two-stage choices (:meth:`WaypointFollower.stage_waypoints`)
FORMS = ("waypoints", "stages")
#: the two-stage choices: the change of the route's slope at its first and at
#: its second stage, in the lattice's slope steps; choice c is
#: ``STAGE_CHOICES[c]`` = (c // 3 − 1, c % 3 − 1), and its mirror image 8 − c
STAGE_CHOICES = tuple((a, b) for a in (-1, 0, 1) for b in (-1, 0, 1))
#: scales of the pose entries of :func:`decision_observation`
_OFFSET_SCALE, _HEADING_SCALE, _YAW_SCALE = 100.0, 0.5, 0.04
#: the file of the student's policy, and of the run's record, in a run directory
STUDENT, RECORD = "student.zip", "waypoints.json"
#: the record of a fine-tuned student's run (:mod:`agents.waypoint_rl`), in place of RECORD
FINETUNE_RECORD = "finetune.json"
#: the record of a run of an offset learner (:mod:`agents.route_offsets`), in place of RECORD
OFFSETS_RECORD = "offsets.json"


#: the key of a privileged critic's signals beside a decision's observation
#: (:mod:`agents.waypoint_rl`, :mod:`agents.privileged`)
PRIVILEGED = "privileged"


def decision_space(env):
    """The ``Dict`` observation space of :func:`decision_observation` for the
    ship environment ``env``."""
    import gymnasium as gym

    from iceenvs.costmap import costmap_space

    u = env.unwrapped
    return gym.spaces.Dict({"costmap": costmap_space(u.costmap_size),
                            "vector": gym.spaces.Box(-10.0, 10.0, (3,), np.float32)})


def decision_observation(env) -> dict:
    """What the student decides on: ``{"costmap": the environment's costmap
    now, "vector": [lateral offset from the channel's centre line / 100 m,
    heading / 0.5 rad, yaw rate / 0.04 rad/s]}`` (float32)."""
    u = env.unwrapped
    ship = u.sim.ship
    pose = [(float(ship.position[1]) - u.centre_y) / _OFFSET_SCALE,
            float(ship.heading) / _HEADING_SCALE, float(ship.yaw_rate) / _YAW_SCALE]
    return {"costmap": np.asarray(u.costmap(), dtype=np.float32),
            "vector": np.clip(np.asarray(pose, dtype=np.float32), -10.0, 10.0)}


class WaypointFollower(LatticePlanner):
    """Decide waypoints every ``interval`` steps (:meth:`decide`) and
    follow the straight route through them by the lattice planner's pure
    pursuit in between (see :mod:`agents.waypoints`).

    Parameters
    ----------
    env, seed : as :class:`~agents.planners.LatticePlanner`
    points : int
        Waypoints of a decision, evenly spaced to ``distance``.
    distance : float [m]
        How far ahead the last waypoint lies.
    interval : int
        Environment steps between decisions.
    form : "waypoints" or "stages"
        A decision is ``points`` lateral shifts w_k (``"waypoints"``), or one
        of the lattice's nine two-stage choices (``"stages"``, an integer of
        :data:`STAGE_CHOICES`; ``points`` 2 and ``distance`` two stages).
    **kwargs : the lattice planner's (``max_slope``: a decision w_k = 1 is a
        slope of ``max_slope`` from the ship to waypoint k; ``edge_margin``;
        ``noise`` σ: each decision w is sailed as w + e, e normal of σ on
        each w_k, drawn from a generator seeded by the episode's seed, then
        clipped: a decider that errs as an imperfect student of it would;
        form ``"waypoints"`` only)

    Attributes
    ----------
    decisions : list
        Each decision of the episode: ``points`` numbers in [−1, 1], or a
        choice.
    """

    def __init__(self, env, seed: int = 0, *, points: int = 2,
                 distance: float = WAYPOINT_DISTANCE, interval: int = DECISION_STEPS,
                 form: str = "waypoints", **kwargs):
        kwargs.setdefault("show", False)
        super().__init__(env, seed, **kwargs)
        for name, value in (("points", points), ("interval", interval)):
            if isinstance(value, bool) or int(value) != value or value < 1:
                raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
        if not (math.isfinite(distance) and distance > 0):
            raise ValueError(f"distance must be a positive number, got {distance!r}")
        self.points, self.interval, self.distance = int(points), int(interval), float(distance)
        if form not in FORMS:
            raise ValueError(f"form must be one of {FORMS}, got {form!r}")
        if form == "stages" and (self.points != 2 or not math.isclose(
                self.distance, 2.0 * self.stage_length)):
            raise ValueError(f"form 'stages' decides the lattice's first two stages: points 2 "
                             f"and distance {2.0 * self.stage_length:g} m, got {points} and "
                             f"{distance:g}")
        self.form = form
        if self.noise and form != "waypoints":
            raise ValueError(f"noise errs on lateral shifts: form 'waypoints' only, got form "
                             f"{form!r}")
        self.decisions: list = []

    def reset(self, seed: int | None = None) -> None:
        super().reset(seed)
        self.decisions = []

    def decide(self, obs):
        """The decision for the episode now (``obs``: its observation):
        ``points`` numbers w, or a choice of :data:`STAGE_CHOICES`."""
        raise NotImplementedError

    def decide_next_step(self) -> None:
        """Make the next step decide anew, however long ago the last
        decision was (a driver that sets the decisions' pace itself)."""
        self._age = self.interval

    def stage_waypoints(self, choice: int) -> np.ndarray:
        """The decision w of the two-stage choice ``choice``: from the slope
        the lattice would start with at the ship's heading now
        (:meth:`~agents.planners.LatticePlanner.start_slope`), the first
        stage's slope changes by ``STAGE_CHOICES[choice][0]`` steps and the
        second's by ``[1]`` more, within the lattice's steepest; the
        waypoints are the two stages' ends."""
        _, steepest = self.lattice_steps()
        turn1, turn2 = STAGE_CHOICES[choice]
        first = max(min(self.start_slope(float(self.unwrapped.sim.ship.heading)) + turn1,
                        steepest), -steepest)
        second = max(min(first + turn2, steepest), -steepest)
        shifts = self.lateral_step * np.array([first, first + second], dtype=float)
        return shifts / (self.max_slope * self.distances)

    @property
    def distances(self) -> np.ndarray:
        """How far ahead [m] each waypoint of a decision lies."""
        return self.distance * np.arange(1, self.points + 1) / self.points

    def waypoint_route(self, w) -> np.ndarray:
        """The route of decision ``w`` from the ship's position now: through
        the waypoints, kept ``edge_margin`` inside the channel, then on
        along +x."""
        u = self.unwrapped
        x, y = (float(v) for v in u.sim.ship.position)
        d = self.distances
        targets = np.clip(y + np.asarray(w) * self.max_slope * d, *self.route_bounds())
        far = x + self.distance + 10.0 * u.channel_width
        return np.array([[x, y], *zip(x + d, targets), [far, targets[-1]]])

    def act(self, obs):
        if self.route is None or self._age >= self.interval:
            decision = self.decide(obs)
            if self.form == "stages":
                if int(decision) != decision or not 0 <= decision < len(STAGE_CHOICES):
                    raise ValueError(f"{type(self).__name__} decided {decision!r}, not a "
                                     f"choice 0-{len(STAGE_CHOICES) - 1}")
                self.decisions.append(int(decision))
                w = self.stage_waypoints(int(decision))
            else:
                w = np.asarray(decision, dtype=float).reshape(-1)
                if w.shape != (self.points,) or not np.all(np.isfinite(w)):
                    raise ValueError(f"{type(self).__name__} decided {decision!r}, not "
                                     f"{self.points} number(s)")
                if self.noise:
                    w = w + self._errors.normal(0.0, self.noise, self.points)
                w = np.clip(w, -1.0, 1.0)
                self.decisions.append(w)
            self.route = self.waypoint_route(w)
            self._age = 0
        self._age += 1
        return self._pursue(self.route, obs)


class Commanded(WaypointFollower):
    """Follows the decision it is given (:attr:`command`, set before each
    decision): what a driver of its own pace, or a rollout of a decision,
    sails."""

    def __init__(self, env, seed: int = 0, **kwargs):
        super().__init__(env, seed, **kwargs)
        self.command = None

    def decide(self, obs):
        return self.command


def rollout_decision(env, obs, w, steps: int, *, points: int, distance: float,
                     interval: int) -> float:
    """The summed reward of ``steps`` steps of the episode of ``env`` as it
    is now (``obs``: its observation): decision ``w`` followed for
    ``interval`` steps, then the lattice planning on the costmap
    (:class:`~agents.planners.CostmapLatticePlanner`); None: the costmap
    lattice throughout. Stepped on ``env.unwrapped``, below any wrapper,
    whose counters stay as they are; the caller snapshots and restores."""
    u = env.unwrapped
    lattice = CostmapLatticePlanner(env, 0, show=False)
    follower = Commanded(env, points=points, distance=distance, interval=interval)
    follower.command = w
    space = env.action_space
    total = 0.0
    for k in range(steps):
        action = (follower if w is not None and k < interval else lattice).predict(obs)[0]
        obs, reward, terminated, truncated, _ = u.step(
            np.clip(action, space.low, space.high).astype(space.dtype))
        total += float(reward)
        if terminated or truncated:
            break
    return total


def sail_fields(env, driver, first: int, episodes: int, desc: str,
                progress: bool) -> list[float]:
    """Sail ``episodes`` episodes of ``env`` under the policy ``driver``,
    episode k seeded ``first`` + k (the driver reset alike), with a progress
    bar unless not ``progress``; returns their returns."""
    from tqdm.auto import tqdm

    returns = []
    for k in tqdm(range(episodes), desc=desc, unit="episode", disable=not progress):
        obs, _ = env.reset(seed=first + k)
        driver.reset(first + k)
        done, total = False, 0.0
        while not done:
            obs, reward, terminated, truncated, _ = env.step(driver.predict(obs)[0])
            total += float(reward)
            done = terminated or truncated
        returns.append(total)
    return returns


def student_decision(policy, seen: dict):
    """The decision of the SB3 ``policy`` on ``seen`` (:func:`decision_observation`)."""
    action, _ = policy.predict(seen, deterministic=True)
    if _is_choice(policy):
        return int(np.asarray(action).reshape(-1)[0])
    return np.asarray(action, dtype=float).reshape(-1)


def _is_choice(policy) -> bool:
    import gymnasium as gym

    return isinstance(policy.action_space, gym.spaces.Discrete)


def load_student(run, env):
    """The SB3 policy of the run directory ``run`` (its ``student.zip``), in
    evaluation mode, checked against the costmaps of ``env``.

    Raises
    ------
    FileNotFoundError
        For a directory without ``student.zip``.
    ValueError
        When the student was trained on costmaps of another shape."""
    from stable_baselines3.common.policies import MultiInputActorCriticPolicy

    path = Path(run) / STUDENT
    if not path.is_file():
        raise FileNotFoundError(f"no student in {run!r}: {path} is missing (train one with "
                                f"python -m agents.waypoints train --out {run})")
    policy = MultiInputActorCriticPolicy.load(str(path), device="cpu")
    policy.set_training_mode(False)
    trained = policy.observation_space["costmap"].shape
    here = decision_space(env)["costmap"].shape
    if trained != here:
        raise ValueError(f"the student of {run!r} was trained on costmaps of shape "
                         f"{trained}, and this environment's are {here}: make it with the "
                         f"training's costmap settings (costmap_ahead, costmap_behind, "
                         f"costmap_cell; see {RECORD} in the run)")
    return policy


def is_residual(run) -> bool:
    """Whether the run directory ``run`` holds a residual on the costmap
    lattice (a fine-tuning with ``residual``, :mod:`agents.waypoint_rl`),
    whose policy decides a correction to the lattice's decision, not the
    decision itself."""
    path = Path(run) / FINETUNE_RECORD
    return path.is_file() and bool(
        json.loads(path.read_text())["settings"].get("residual", False))


class WaypointStudent(WaypointFollower):
    """The learned decision (sensor-only): an SB3 policy on
    :func:`decision_observation`, loaded from a run of :func:`agents.waypoints.train_student`
    (``run``: its directory, holding ``student.zip``)."""

    reads_environment = "its costmap and its own pose"

    def __init__(self, env, seed: int = 0, *, run: str, **kwargs):
        policy = load_student(run, env)
        if (Path(run) / OFFSETS_RECORD).is_file():
            raise ValueError(f"{run!r} holds an offset learner, which chooses an offset of the "
                             f"costmap lattice's route: play it with "
                             f"agents.route_offsets:OffsetStudent")
        if is_residual(run):
            raise ValueError(f"{run!r} holds a residual on the costmap lattice, which decides a "
                             f"correction to the lattice's decision: play it with "
                             f"agents.waypoints:WaypointResidual")
        shape = {"form": "stages"} if _is_choice(policy) else \
            {"points": int(policy.action_space.shape[0])}
        super().__init__(env, seed, **{**shape, **kwargs})
        self.policy = policy

    def decide(self, obs):
        return student_decision(self.policy, decision_observation(self.env))


#: the teachers of :class:`LatticeWaypoints`: the lattice on the floes
#: (privileged), or on the environment's costmap (what the student sees)
TEACHERS = ("lattice", "costmap-lattice")
#: a route's own settings in :class:`LatticeWaypoints`'s ``settings``; the
#: follower's pace and pursuit are its own
ROUTE_SETTINGS = ("metre_cost", "blur", "fade", "max_slope", "edge_margin", "horizon")
#: settings of a tuned planner that a waypoint follower sets itself
PACE_SETTINGS = ("lookahead", "replan_steps")


def route_planners(env, seed: int, teacher: str, bounds, settings):
    """(bounds, planners) of :class:`LatticeWaypoints`'s ``bounds`` and
    ``settings``: ([], []) for none; one planner a mapping otherwise (the
    lattice on the floes or on the costmap, as ``teacher``), planning only
    (it draws nothing)."""
    if settings is None:
        if bounds is not None:
            raise ValueError("bounds choose among settings: give settings too")
        return [], []
    edges = [] if bounds is None else concentration_bounds(bounds)
    check_settings(edges, settings)
    kind = CostmapLatticePlanner if teacher == "costmap-lattice" else LatticePlanner
    planners = []
    for s in settings:
        unknown = sorted(set(s) - set(ROUTE_SETTINGS) - set(PACE_SETTINGS))
        if unknown:
            raise ValueError(f"a route's settings are {ROUTE_SETTINGS} (and {PACE_SETTINGS}, "
                             f"which the follower sets itself), got {unknown}")
        route = {k: v for k, v in s.items() if k in ROUTE_SETTINGS}
        planners.append(kind(env, seed, show=False, **route))
    return edges, planners


#: the planners whose settings a teacher's routes may take (:func:`teacher_route`),
#: by class name: the teacher each plans as
ROUTE_TEACHERS = {"LatticePlanner": "lattice", "CostmapLatticePlanner": "costmap-lattice",
                  "ByConcentration": "costmap-lattice"}


def teacher_route(policy: str) -> tuple[str, dict]:
    """(teacher, {"bounds": ..., "settings": ...}) of a planner's policy
    string (``module:Class?key=value&...``): a lattice planner's settings,
    or :class:`agents.tuned_lattice.ByConcentration`'s by concentration, as
    :class:`LatticeWaypoints` takes them."""
    from .policy import parse_reference

    _, name, kwargs = parse_reference(policy)
    if name not in ROUTE_TEACHERS:
        raise ValueError(f"a teacher's routes are a planner's of {sorted(ROUTE_TEACHERS)}, "
                         f"got {name!r} in {policy!r}")
    if name == "ByConcentration":
        unknown = sorted(set(kwargs) - {"bounds", "settings"})
        if unknown:
            raise ValueError(f"ByConcentration takes bounds and settings, got {unknown}")
        return ROUTE_TEACHERS[name], {"bounds": kwargs.get("bounds"),
                                      "settings": kwargs.get("settings")}
    return ROUTE_TEACHERS[name], {"bounds": None, "settings": [kwargs]}


class LatticeWaypoints(WaypointFollower):
    """The lattice planner's decision (privileged: it reads every floe
    within 500 m): plan its route and take its points at the decision's
    distances as the waypoints (form ``"stages"``: the choice of its first
    two stages). With the defaults it sails the lattice planner's episode.

    ``teacher="costmap-lattice"``: the lattice plans on the environment's
    costmap instead (:class:`agents.planners.CostmapLatticePlanner`; not
    privileged), whose episode it then sails: a decision that is a function
    of what the student sees.

    ``settings``: the route is planned with settings of its own (a list of
    mappings of :class:`agents.planners.CostmapLatticePlanner`'s arguments,
    one more than ``bounds``, as :class:`agents.tuned_lattice.ByConcentration`
    takes them; the first where the episode's concentration, read from the
    observation at its first step, lies below ``bounds[0]``, and so on): a
    tuned planner's routes, at the follower's pace. Only the route's
    settings (``metre_cost``, ``blur``, ``fade``, ``max_slope``,
    ``edge_margin``, ``horizon``) are the teacher's; ``lookahead`` and
    ``replan_steps`` among them are not used, since the follower pursues
    every route by its own ``lookahead`` and decides every ``interval``
    steps, and a decision w_k = 1 is still a slope of the follower's
    ``max_slope``. The waypoints are kept the follower's ``edge_margin``
    inside the channel."""

    reads_environment = "its floes"

    def __init__(self, env, seed: int = 0, *, teacher: str = "lattice", bounds=None,
                 settings=None, **kwargs):
        super().__init__(env, seed, **kwargs)
        if teacher not in TEACHERS:
            raise ValueError(f"teacher must be one of {TEACHERS}, got {teacher!r}")
        self.teacher = teacher
        if teacher == "costmap-lattice":
            self.reads_environment = "its costmap"
        self.bounds, self.route_planners = route_planners(env, seed, teacher, bounds, settings)
        if self.bounds and "concentration" not in self._index:
            raise ValueError(f"settings by concentration read the observation's concentration "
                             f"entry, which {type(self.unwrapped).__name__} has not")
        self._chosen = None

    def reset(self, seed: int | None = None) -> None:
        super().reset(seed)
        for planner in self.route_planners:
            planner.reset(seed)
        self._chosen = None

    def act(self, obs):
        if self.route_planners and self._chosen is None:
            self._chosen = planner_for(self.bounds, self.route_planners, self._reader(obs))
        return super().act(obs)

    def cost_grid(self, x, y0, nx, ny, reach):
        if self.teacher == "costmap-lattice":
            return costmap_cost_grid(self.unwrapped, y0, nx, ny, self.lateral_step)
        return super().cost_grid(x, y0, nx, ny, reach)

    def label(self):
        """The lattice's decision from the episode now: w (unclipped), or
        the choice of its route's first two stages (a route planned from a
        straight heading, when none turns from the heading in time, is
        given the nearest choice)."""
        route = self.plan() if self._chosen is None else self._chosen.plan()
        x, y = (float(v) for v in self.unwrapped.sim.ship.position)
        d = self.distances
        ahead = np.interp(x + d, route[:, 0], route[:, 1])
        if self.form == "waypoints":
            return (ahead - y) / (self.max_slope * d)
        first = int(round((ahead[0] - y) / self.lateral_step))
        second = int(round((ahead[1] - ahead[0]) / self.lateral_step))
        start = self.start_slope(float(self.unwrapped.sim.ship.heading))
        turns = (max(min(first - start, 1), -1), max(min(second - first, 1), -1))
        return STAGE_CHOICES.index(turns)

    def decide(self, obs):
        return self.label()


class WaypointResidual(LatticeWaypoints):
    """The costmap lattice's decision corrected by a learned one (a residual
    policy: Silver et al. 2018, Johannink et al. 2019; sensor-only): at each
    decision, the lattice planning on the environment's costmap gives w₀
    (clipped to [−1, 1]) and the policy of ``run`` (a fine-tuning with
    ``residual``, :mod:`agents.waypoint_rl`) a correction δ from the costmap
    and the ship's pose; the ship sails w₀ + δ (clipped). A zero correction
    sails the costmap lattice's own episode.

    ``run``: the fine-tuning's directory; the follower's settings as
    :class:`LatticeWaypoints` (the teacher is the costmap lattice)."""

    reads_environment = "its costmap and its own pose"

    def __init__(self, env, seed: int = 0, *, run: str, **kwargs):
        if "teacher" in kwargs:
            raise ValueError("a residual corrects the costmap lattice; it takes no teacher")
        policy = load_student(run, env)
        if not is_residual(run):
            raise ValueError(f"{run!r} holds no residual (its policy decides the waypoints "
                             f"themselves): play it with agents.waypoints:WaypointStudent")
        super().__init__(env, seed, teacher="costmap-lattice",
                         **{"points": int(policy.action_space.shape[0]), **kwargs})
        self.policy = policy

    def decide(self, obs):
        base = np.clip(self.label(), -1.0, 1.0)
        return base + student_decision(self.policy, decision_observation(self.env))


def student_record(run) -> dict | None:
    """The record of a run directory that holds a waypoint student
    (``student.zip``): ``waypoints.json`` of a run of imitation, or
    ``finetune.json`` of a fine-tuned one (:mod:`agents.waypoint_rl`). Both
    hold ``settings`` (``env_id``, ``env_kwargs``, ``seed``), ``seconds`` and
    ``command``; imitation's ``rounds``, fine-tuning's ``decisions``. None
    for any other directory.

    Raises
    ------
    FileNotFoundError
        When the directory holds a student but neither record, which says
        the environment and the costmap it was trained on."""
    run = Path(run)
    if not (run / STUDENT).is_file():
        return None
    for name in (RECORD, FINETUNE_RECORD):
        if (run / name).is_file():
            return json.loads((run / name).read_text())
    raise FileNotFoundError(f"{run} holds a waypoint student ({STUDENT}) but not its record "
                            f"({RECORD} or {FINETUNE_RECORD}), which names its environment and "
                            f"costmap")


def gather_records(runs, record: str, command: str) -> dict:
    """The JSON file ``record`` of each run directory of ``runs``, by the
    directory as given (``FileNotFoundError`` naming ``command``, which
    makes such runs, for one without it; ``ValueError`` for no run)."""
    records = {}
    for run in runs:
        path = Path(run) / record
        if not path.is_file():
            raise FileNotFoundError(f"{run}: no {record} (not a run of python -m {command})")
        records[Path(run).as_posix()] = json.loads(path.read_text())
    if not records:
        raise ValueError("a report needs at least one run")
    return records


def write_gathered(out, record: str, records: dict, table: str, lines: list) -> Path:
    """Write gathered ``records`` to ``out/record`` and the table ``lines``
    to ``out/table``; returns ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / record).write_text(json.dumps(records, indent=1) + "\n")
    (out / table).write_text("\n".join(lines))
    return out
