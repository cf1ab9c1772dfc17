"""Controllers of the ship environments: the straight line to the goal
(``"straight"``), steering for the least obstructed sector of the ice
lidar (``"reactive"``; both in the facts of :mod:`iceenvs.ship_navigation`
and :mod:`iceenvs.ship_beset`) and a greedy choice of the swath sensor's
courses (``"swath"``, in the facts of :mod:`iceenvs.ship_navigation_v1`).

They are controllers in the project's sense: they need only the
environment (its observation and public attributes, no privileged
state), their names end in ``Controller``, and they satisfy the
:class:`agents.policy.Policy` protocol. The planners that read the floes
are in :mod:`agents.planners`.
"""
from __future__ import annotations

import math

import numpy as np

from .controllers import Controller
from .ship_sensors import swath_courses

__all__ = ["StraightLineController", "ReactiveController", "SwathController"]


class StraightLineController(Controller):
    """A ship sailing straight for the goal line at full speed.

    The heading error is the bearing of the goal direction in the ship
    frame, atan2(``goal_sin``, ``goal_cos``). A prescribed ship turns at a
    yaw rate proportional to it (full rate at 0.1 rad); a dynamic ship
    runs at full thrust with a critically damped PD autopilot on it
    (natural frequency 0.05 rad/s, the ship's yaw inertia with added mass).
    The surge speed of ``control="speed_yaw"`` is the largest. With
    ``control="course"`` the policy commands the course of the bearing.

    The policies read the observation vector (``obs["vector"]`` of a dict
    observation); with ``obs_type="image"`` they read the environment's last
    physical observation instead, one environment at a time.
    """

    #: heading error [rad] of a full yaw-rate command
    GAIN_ANGLE = 0.1
    #: natural frequency [rad/s] of the dynamic ship's heading autopilot
    FREQUENCY = 0.05

    def __init__(self, env, seed: int = 0):
        super().__init__(env, seed)
        u = env.unwrapped
        if not hasattr(u, "lidar_sectors"):
            raise ValueError(f"{type(self).__name__} steers a ship environment, got "
                             f"{type(u).__name__}")
        self.unwrapped = u
        self._index = {f.name: k for k, f in enumerate(u.features)}
        self._scale = {f.name: (100.0 if f.scaling == "/ 100 m" else
                                0.1 if f.scaling == "/ 0.1 rad/s" else 1.0)
                       for f in u.features}

    def _reader(self, obs):
        """``get(name)``: the raw value of an observation entry."""
        if isinstance(obs, dict):
            obs = obs["vector"]
        if self.unwrapped.obs_type == "image":
            now = self.unwrapped.last_measurement
            return lambda name: float(now[name])
        return lambda name: float(obs[self._index[name]]) * self._scale[name]

    def _bearing(self, get) -> float:
        """Bearing of the goal [rad, ship frame, port positive]."""
        return math.atan2(get("goal_sin"), get("goal_cos"))

    def _steer(self, bearing: float, get) -> np.ndarray:
        u = self.unwrapped
        if u.control == "thrust":
            ship = u.ship                 # the episode's ship (set by reset)
            w = self.FREQUENCY
            moment = ship.total_mass[2] * (w * w * bearing - 2.0 * w * get("yaw_rate"))
            return np.array([1.0, moment / ship.max_yaw_moment])
        if u.control == "course":
            # the course (from the goal direction) that points the bow along the bearing
            return np.array([(bearing - self._bearing(get)) / u.episode["max_course"]])
        turn = bearing / self.GAIN_ANGLE
        return np.array([turn]) if u.control == "yaw" else np.array([1.0, turn])

    def act(self, obs):
        get = self._reader(obs)
        return self._steer(self._bearing(get), get)

    #: what the policy reads of its environment beyond the observation it is
    #: given (None: nothing): such a policy steers one environment at a time
    reads_environment: str | None = None

    def predict(self, obs, state=None, episode_start=None, deterministic: bool = True):
        space = self.action_space
        vector = obs["vector"] if isinstance(obs, dict) else obs
        if self.unwrapped.obs_type != "image" and np.ndim(vector) == 2:
            if self.reads_environment:
                raise ValueError(f"{type(self).__name__} steers one environment (it reads "
                                 f"{self.reads_environment}); got a batch of observations")
            if isinstance(obs, dict):
                rows = [{"vector": v} for v in vector]
            else:
                rows = list(vector)
            actions = np.stack([np.clip(self.act(o), space.low, space.high) for o in rows])
            return actions.astype(space.dtype), None
        return np.clip(self.act(obs), space.low, space.high).astype(space.dtype), None


class ReactiveController(StraightLineController):
    """Steer for the least obstructed sector of the ice lidar.

    Each sector k of the lidar (central bearing θ_k) scores
    d_k / range − c_k − ``turn_cost`` |θ_k − θ_goal|, with d_k the distance
    to the first floe edge, c_k the ice concentration of the sector and
    θ_goal the bearing of the goal; the ship steers for the best sector
    (bearings beyond 60° of the goal are clipped there) as
    :class:`StraightLineController` steers for the goal.
    """

    turn_cost = 0.5
    max_off_goal = math.radians(60.0)

    def act(self, obs):
        u = self.unwrapped
        get = self._reader(obs)
        k = u.lidar_sectors
        theta = -0.5 * math.pi + (np.arange(k) + 0.5) * math.pi / k
        d = np.array([get(f"lidar_distance_{i}") for i in range(k)]) / u.lidar_range
        c = np.array([get(f"lidar_concentration_{i}") for i in range(k)])
        goal = self._bearing(get)
        score = d - c - self.turn_cost * np.abs(theta - goal)
        best = float(theta[int(np.argmax(score))])
        return self._steer(float(np.clip(best, goal - self.max_off_goal,
                                         goal + self.max_off_goal)), get)


class SwathController(StraightLineController):
    """Steer for the course of the swath sensor that costs least: a greedy
    controller on the observation (ShipNavigation-v1).

    The swath sensor (:func:`iceenvs.ship_sensors.ice_swath`) gives, for
    each course k of its fan, the expected collision impulse S_k [N s] of
    the floes the hull's swath along it would meet, per band of distance
    ahead. Every step the controller scores each course

        S_near + ``far_weight`` S_far + c (L / cos φ_k − L)

    with φ_k the course's angle from the goal direction, L the sensor's
    reach and c the impulse one metre sailed is worth in the reward
    (:attr:`iceenvs.ship_env.ShipEnv.metre_cost`, 12 500 N s/m in v1; the
    lattice planner's too): the ice the course meets plus the price of its extra
    length over the reach. The far band counts ``far_weight`` (1/2) of
    its ice: the course will likely change before the ship is there. A
    course that would take the centroid closer than ``margin`` (15 m) to
    the channel's edge within ``lookahead`` (150 m) pays 10⁹ N s per metre
    beyond that line, so the controller keeps to the channel when it can and
    otherwise turns back the most. With the sensor's room in the channel
    (v1's ``swath_edge=True``) it reads the edge from the observation's
    rooms instead: a course that leaves the channel within ``lookahead``
    pays 10⁹ N s per metre of it beyond the edge. The ship then steers for the best
    course with the autopilot of ``control="course"``
    (:meth:`iceenvs.ship_env.ShipEnv.course_yaw_rate`: the heading error
    over `course_time`, 20 s), commanding its yaw rate under
    ``control="yaw"``, so that it sails the same path with either action
    (the thrust controls steer for it as :class:`StraightLineController` steers
    for the goal). Turned faster, the hull would sweep its sides through
    the ice.

    It is greedy (the courses are straight, and the best one is chosen
    again every step), decides on nothing but the observation, and costs a
    few tens of microseconds a decision: a baseline a policy of the same
    observation should reach. It reads the swath sums unscaled from the
    environment's last measurement (the observation holds their
    logarithms), so it steers one environment at a time. With ``show``
    (default) the chosen course and its swath are drawn on the
    environment's frames (placed at the ship's position, read for the
    drawing only).
    """

    reads_environment = "the unscaled swath sums of its last measurement"

    far_weight = 0.5
    margin = 15.0
    lookahead = 150.0
    #: cost [N s] per metre of the centroid beyond the channel line
    outside_cost = 1.0e9

    def __init__(self, env, seed: int = 0, *, show: bool = True):
        super().__init__(env, seed)
        u = self.unwrapped
        #: draw the chosen course and its swath on the environment's frames
        self.show = bool(show)
        if not getattr(u, "swath_rays", 0):
            raise ValueError(f"{type(self).__name__} reads the swath sensor, which "
                             f"{type(u).__name__} does not have (swath_rays=0 or none)")
        rays = u.swath_rays
        self._angles = swath_courses(rays, u.swath_fan)
        self._bands = [[f"swath_{b}_{k}" for k in range(rays)]
                       for b in range(len(u.swath_bands) - 1)]
        self._reach = float(u.swath_bands[-1])
        self._rooms = ([f"swath_room_{k}" for k in range(rays)]
                       if getattr(u, "swath_edge", False) else [])

    @property
    def metre_cost(self) -> float:
        """The impulse [N s] one metre sailed is worth in the reward
        (:attr:`iceenvs.ship_env.ShipEnv.metre_cost`; 0 for a reward
        without both terms, which then counts only the ice)."""
        return self.unwrapped.metre_cost or 0.0

    def act(self, obs):
        u = self.unwrapped
        get = self._reader(obs)
        now = u.last_measurement
        goal = self._bearing(get)
        # the courses as bearings in the ship frame, and as angles from the goal direction
        bearing = self._angles + (goal if u.swath_frame == "goal" else 0.0)
        off = np.clip(bearing - goal, -1.4, 1.4)
        ice = sum((1.0 if b == 0 else self.far_weight) * np.array([now[n] for n in names])
                  for b, names in enumerate(self._bands))
        detour = self._reach * (1.0 / np.cos(off) - 1.0)
        if self._rooms:
            # the edge as the observation shows it: the course's metres beyond it
            room = np.array([get(name) for name in self._rooms])
            beyond = np.maximum(self.lookahead - room, 0.0)
        else:
            half = 0.5 * u.channel_width
            lateral = get("channel_offset") * half + self.lookahead * np.sin(off)
            beyond = np.maximum(np.abs(lateral) - (half - self.margin), 0.0)
        score = ice + self.metre_cost * detour + self.outside_cost * beyond
        k = int(np.argmin(score))
        best = float(bearing[k])
        if self.show:
            # the chosen course over the sensor's reach, from the ship (drawing only)
            xy = np.asarray(u.sim.ship.position, dtype=float)
            course = np.array([math.cos(off[k]), math.sin(off[k])])
            u.plan_overlay = (np.stack([xy, xy + self._reach * course]), 0.5 * u.ship.hull.beam)
        if u.control == "yaw":
            # the yaw rate the course autopilot would command: the same path with either action
            e = u.episode
            rate = u.course_yaw_rate((best - goal) / e["max_course"], -goal)
            return np.array([rate / e["max_yaw_rate"]])
        return self._steer(best, get)


# The names before this release: user code and saved policies (``module:Class``
# references) may name them.
StraightLinePolicy = StraightLineController
ReactivePlanner = ReactiveController
SwathPlanner = SwathController
