"""Shared plumbing of the ship environments: :class:`ShipEnv`.

A ship environment runs the Hertz engine with a ship among the floes
(:class:`physics.HertzSimulation` with ``ship=``, :mod:`physics.ship`).
The agent commands the ship; every step the engine advances by the control
interval, and the environment reads from the ship's step records and
collision log what happened in that interval (impulse and energy given to
the ice, collisions, the path sailed), senses the ice ahead
(:mod:`iceenvs.ship_sensors`) and measures the ice around the hull.

Data flow of one step::

    action → NaN → 0, ±inf → bound, clip → ship commands → engine.advance(control interval)
      → step loads (records, collision log) + sensors + local ice → SI dict
        (:func:`iceenvs.ship_measures.measure_ships`, for one environment or many)
      → reward(prev, action, now) and the observation (vector, image or both)

Subclasses say what the task is:

* ``_ice(rng)`` — the floe field and the box of an episode, and the forcing;
* ``_ship_start()`` — where the ship starts (position, heading);
* ``ends(envs, nows, cols, sums, task)`` — goal reached and failure, on
  the columns of a batch of environments (a step is one batch,
  :class:`iceenvs.step.Episodes`: the single environment is a batch of one);
* ``controls`` (the action set-ups the task offers) and the reward.

Step loads (``info["physics"]``, for the last step; forces in the ship frame):
``ice_surge``, ``ice_sway`` [N] and ``ice_moment`` [N m] (means over the
engine steps), ``hull_pressure`` and ``peak_hull_pressure`` [N/m] (mean and
largest sum of the normal contact forces over the hull's length),
``step_impulse`` [N s] (∫ |Σ_c F_c| dt, the impulse of the resultant ice
force), ``step_contact_impulse`` [N s] (Σ_c ∫ |F_c| dt, of each contact's
force; at least ``step_impulse``, and over an episode at least the total of
the collisions' impulses |J_c|), ``step_energy`` [J] (work of the hull on
the ice), ``step_effort`` [J] (work of the thrust, or of the prescribed
ship against ice and water), ``step_path`` [m] and ``step_collisions``
(collisions that ended in the step).

Episode metrics (``info``, after every step, for the episode so far):
``success``, ``time`` [s], ``path_length`` [m], ``efficiency`` (the
straight-line distance to the goal over the path length, when the goal is
reached, else 0), ``effort`` [J], ``collisions``, ``collided_floes``,
``mean_impulse`` and ``max_impulse`` [N s] (of the finished collisions),
``impulse_per_metre`` [N s/m] (their total over the path length),
``energy_to_ice`` [J], ``ice_resistance`` [N] (mean ice force against
surge), ``max_hull_pressure`` [N/m] (the largest sum of the normal
contact forces on the hull over its length in any engine step) and
``mean_mass_hit`` [kg] (the mean mass of the mobile floes hit, each
counted once: AUTO-IceNav's mean collided obstacle mass),
``ice_energy_gain`` [J] (the kinetic energy of all the ice now less at the
start, translation and rotation) and ``energy_dissipated`` [J]
(``energy_to_ice`` − ``ice_energy_gain``: what the contacts and the
water took). AUTO-IceNav's three kinetic-energy metrics map onto these:
its ship's kinetic-energy loss is ``energy_to_ice`` (the work of the ice
on the hull, which a prescribed ship's motion makes good), the ice's gain
is ``ice_energy_gain`` and the system's loss ``energy_dissipated``. For a
head-on hit at speed v on a floe of mass m at rest that leaves at
(1 + e) v, they are v m (1 + e) v, ½ m (1 + e)² v² and ½ m v² (1 − e²).
"""
from __future__ import annotations

import math

import gymnasium as gym
import numpy as np

from physics import HERMAN2013, ice_fields
from physics.input_checks import check_range

from .base import ControlEnv
from .costmap import costmap_samples, costmap_scan, costmap_shape, costmap_space
from .facts import EnvFacts
from .observations import Feature
from .ship_controllers import ReactiveController, StraightLineController
from .ship_measures import (INTEGER_MEASURES, METRICS, SUM_COLUMNS, info_columns,
                            measure_names, measure_ships, metric_values, update_metrics)
from .step import as_measurement
from .ship_sensors import occupancy_image

__all__ = ["ShipEnv", "ship_features", "ship_facts", "FLOE_SIZES", "CONTROLS", "OBS_TYPES",
           "ICE_LOADS", "METRICS", "SLOW_TIME"]

#: the "Ice loads" section of the ShipNavigation tasks' docs: what the
#: loads on the hull hold, and where they are set beside the field's laws
ICE_LOADS = """The hull meets the floes through Hertz contacts in the plane, with
    friction along it: the loads, and the impulse J of the reward, are the
    momentum the ship gives the floes it pushes aside, the inertial part of
    a ship's resistance in pack ice, with the water drag on the floes it
    sets moving. A plane model of rigid floes leaves out their breaking,
    their turning and submerging under the hull, their added mass and
    ventilation: the speed-independent term of Zuev's law, which holds most
    of the resistance at low speed. The `ship-resistance` scenario sets the
    loads beside Zuev's law and Huang et al.'s fit (the Validation page,
    "Ship resistance beside the field's laws"); its table's rows "at the
    ShipNavigation tasks' speeds and concentrations" give how far they are
    from each law at the tasks' speed (Froude number on the ice thickness
    0.5-0.6) and drawn concentrations, for both hulls and floe-size laws.
    No measured resistance in floating, unbroken floes is compared yet."""


#: floe-size presets: (``sizes`` of :func:`physics.ice_fields.transit_field`,
#: log-normal (median diameter [m], σ of ln d))
FLOE_SIZES = {
    "pack": ("lognormal", (20.0, 0.5)),
    "brash": ("lognormal", (6.0, 0.5)),
    "herman2013": ("power", (1.0, 0.5)),
    "auto_icenav": ("auto_icenav", None),
}

#: the action set-ups: name → (ship mode, action names)
CONTROLS = {
    "yaw": ("prescribed", ("yaw_rate",)),
    "speed_yaw": ("prescribed", ("surge_speed", "yaw_rate")),
    "course": ("prescribed", ("course",)),
    "thrust": ("dynamic", ("thrust", "yaw_moment")),
}

OBS_TYPES = ("vector", "image", "dict", "costmap", "costmap_dict")
#: the column of the time below the beset speed in a row of episode sums
SLOW_TIME = SUM_COLUMNS.index("slow_time")
#: the range of a drawn direction [rad]
ANGLE = (-math.pi, math.pi)

def ship_facts(*, summary: str, metrics: dict, main_metric: str, small: dict,
               **more) -> EnvFacts:
    """The facts of a ship environment: the task's own (``summary``,
    ``metrics``, ``main_metric``, ``small`` and any other field of
    :class:`~iceenvs.facts.EnvFacts`) with what every ship task shares: the
    episode metrics of :data:`METRICS`, the ice impulse per metre compared
    like the return (lower is better), and the controllers of
    :mod:`iceenvs.ship_controllers` (``"heuristic"`` is the reactive one)."""
    return EnvFacts(summary=summary, metrics=metrics, main_metric=main_metric, small=small,
                    episode_metrics=METRICS, compared_metric=("impulse_per_metre", True),
                    controllers={"heuristic": ReactiveController, "straight": StraightLineController,
                                 "reactive": ReactiveController}, **more)


#: below this concentration the floes are placed directly; above it they are
#: placed at it and compressed (FIRE relaxation; :func:`physics.ice_fields.channel_field`)
PLACEMENT_LIMIT = ice_fields.PLACEMENT_LIMIT
#: open water [m] left between the hull's reach and the floes at the start
START_CLEARANCE = 2.0


def ship_features(sectors: int, lidar_range: float) -> tuple[Feature, ...]:
    """The observation entries of a ship environment with a lidar of
    ``sectors`` sectors reaching ``lidar_range`` [m]."""
    top = lidar_range / 100.0
    head = (
        Feature("goal_distance", "distance of the ship's centroid to the goal line (negative "
                "once past it)", "m", "/ 100 m", -20.0, 20.0),
        Feature("goal_cos", "cosine of the goal direction (normal to the goal line) in the "
                "ship frame", "-", "none", -1.0, 1.0),
        Feature("goal_sin", "sine of it (positive: the goal lies to port)", "-", "none",
                -1.0, 1.0),
        Feature("channel_offset", "distance of the centroid from the channel's centre line "
                "over the channel's half-width, positive to port of it, y above it (|x| > 1: "
                "outside)", "-", "none", -3.0, 3.0),
        Feature("surge", "surge speed u (ship frame, forward)", "m/s", "/ 1 m/s", -10.0, 10.0),
        Feature("sway", "sway speed v (ship frame, to port)", "m/s", "/ 1 m/s", -10.0, 10.0),
        Feature("yaw_rate", "yaw rate r (anticlockwise)", "rad/s", "/ 0.1 rad/s", -10.0, 10.0),
        Feature("ice_surge", "ice force on the hull along surge, mean over the step", "N",
                "log force", -10.0, 10.0),
        Feature("ice_sway", "ice force on the hull along sway, mean over the step", "N",
                "log force", -10.0, 10.0),
        Feature("ice_moment", "ice moment on the hull about its centroid, mean over the step",
                "N m", "log force", -12.0, 12.0),
        Feature("hull_pressure", "sum of the normal contact forces on the hull over its length, "
                "mean over the step", "N/m", "log stress", 0.0, 10.0),
    )
    lidar = tuple(
        Feature(f"lidar_distance_{k}", f"sector {k}: distance to the first floe edge along "
                f"its central ray ({lidar_range:g} m: none within range)", "m", "/ 100 m",
                0.0, top) for k in range(sectors)) + tuple(
        Feature(f"lidar_concentration_{k}", f"sector {k}: ice concentration of its wedge",
                "-", "none", 0.0, 1.0) for k in range(sectors))
    tail = (
        Feature("concentration", "ice concentration of the episode (floe area / box area)",
                "-", "none", 0.0, 1.0),
        Feature("local_concentration", "ice concentration within the local radius of the "
                "ship", "-", "none", 0.0, 1.0),
        Feature("local_contacts", "contacts per floe among the floes within the local "
                "radius (2 contacts / floes)", "-", "none", 0.0, 20.0),
        Feature("local_pressure", "pressure (σ₁ + σ₂)/2 of the floe-floe contact stress "
                "within the local radius, compression > 0", "N/m", "log stress", -8.0, 8.0),
    )
    return head + lidar + tail


class ShipEnv(ControlEnv):
    """Base of the ship environments (not registered itself).

    Arguments common to the ship environments
    -----------------------------------------
    control : str — the action set-up (a key of :data:`CONTROLS` the task offers)
    obs_type : "vector", "image", "dict", "costmap" or "costmap_dict"
    image_size : int — pixels of a side of the image observation
    image_extent : float — metres of a side of the image observation
    costmap_cell, costmap_behind, costmap_ahead : float [m] — the cells of
    the costmap observation (:mod:`iceenvs.costmap`) and how far it reaches
    behind the ship and ahead of it (across: the channel's width)
    lidar_sectors : int, lidar_range : float [m] — the sector lidar
    local_radius : float [m] — radius of the local ice measures
    length, width : float [m] — the box; channel_width [m] — the channel
    goal_distance : float [m] — from the ship's start to the goal line
    free_drift : bool — the engine step. True (default), the fast step: the
    floes that provably touch nothing during a window of engine steps drift
    in closed form under their forcing, the others take the full contact
    step (:mod:`physics.hertz_free_drift`). It approximates nothing in the
    physics: every contact is found at the step the exact step finds it,
    and what differs is the rounding of the closed form, about 1e-13 m a
    window. Contacts amplify rounding, so an episode departs from the exact
    step's after some seconds in ice, as two exact runs a rounding error
    apart do; over many fields the two give the same ice impulse,
    collisions, energy and path within the margin of the equivalence test
    on the Benchmarks page (``seaice bench free_drift``). False: the exact
    step, every floe takes the contact step (the floes at rest skipped), as
    the records made before the fast step became the default did.
    preset, control_interval, reward_fn, reward_params, stiffness_scale,
    horizon, colour_scale, render_mode and the task parameters as every
    floe environment.
    """

    controls: tuple[str, ...] = tuple(CONTROLS)
    # a batch of ship environments (:class:`iceenvs.step.Episodes`, a single one
    # included) advances its engines together and measures, rewards and (for a
    # vector observation) observes on columns (:mod:`iceenvs.ship_measures`)
    engines_together = True
    single_together = True
    measures_in_batch = True
    rewards_on_columns = True
    sum_columns = SUM_COLUMNS
    integer_measures = INTEGER_MEASURES
    #: each episode's field is drawn in the channel (:meth:`_floe_field`)
    own_field = True
    #: the goal line lies ahead along +x; the channel is centred on the box
    start_x = 50.0
    episode_members = ("forcing", "n_floes", "impact_speed", "_ship", "damping",
                       "hull_length", "track", "floes_hit", "field_concentration",
                       "plan_overlay")
    render_settings = ("_view", "view_behind", "view_ahead")

    def __init__(self, *, control: str = "yaw", obs_type: str = "vector", image_size: int = 64,
                 image_extent: float = 150.0, lidar_sectors: int = 9,
                 lidar_range: float = 150.0, local_radius: float = 100.0,
                 length: float = 400.0, width: float = 200.0, channel_width: float = 150.0,
                 goal_distance: float = 300.0, preset=HERMAN2013,
                 control_interval: float = 2.0, colour_scale: float = 1.0,
                 free_drift: bool = True, costmap_cell: float = 5.0,
                 costmap_behind: float = 20.0, costmap_ahead: float = 300.0, **kwargs):
        if control not in self.controls:
            raise ValueError(f"control must be one of {self.controls}, got {control!r}")
        if obs_type not in OBS_TYPES:
            raise ValueError(f"obs_type must be one of {OBS_TYPES}, got {obs_type!r}")
        for name, value, low in (("image_size", image_size, 8), ("lidar_sectors", lidar_sectors, 1)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
                raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
        for name, value in (("image_extent", image_extent), ("lidar_range", lidar_range),
                            ("local_radius", local_radius), ("length", length),
                            ("width", width), ("channel_width", channel_width),
                            ("goal_distance", goal_distance)):
            check_range(name, value, 0.0, None, low_open=True)
        if self.start_x + goal_distance >= length:
            raise ValueError(f"goal_distance {goal_distance:g} m puts the goal line beyond the "
                             f"box: it must be below length − {self.start_x:g} m = "
                             f"{length - self.start_x:g} m")
        if channel_width > width:
            raise ValueError(f"channel_width {channel_width:g} m exceeds the box width "
                             f"{width:g} m")
        if not isinstance(free_drift, (bool, np.bool_)):
            raise TypeError(f"free_drift must be True or False, got {free_drift!r}")
        #: the engine step of the episodes (:class:`physics.HertzSimulation`'s ``free_drift``)
        self.free_drift = bool(free_drift)
        self.control = control
        self.mode, self.action_names = CONTROLS[control]
        self.action_space = gym.spaces.Box(-1.0, 1.0, (len(self.action_names),),
                                           dtype=np.float32)
        self.obs_type = obs_type
        self.image_size = int(image_size)
        self.image_extent = float(image_extent)
        #: (rows, columns) of the costmap observation (checks its arguments)
        self.costmap_size = costmap_shape(costmap_cell, costmap_behind, costmap_ahead,
                                          channel_width)
        self.costmap_cell = float(costmap_cell)
        self.costmap_behind, self.costmap_ahead = float(costmap_behind), float(costmap_ahead)
        self.lidar_sectors = int(lidar_sectors)
        self.lidar_range = float(lidar_range)
        self.local_radius = float(local_radius)
        self.length, self.width = float(length), float(width)
        self.channel_width = float(channel_width)
        self.goal_distance = float(goal_distance)
        self.base_features = ship_features(self.lidar_sectors, self.lidar_range)
        #: the raw measurements of a step, in the order of :func:`measure_ships`' columns
        self.measure_names = measure_names(self.lidar_sectors, self.extra_measures)
        super().__init__(n_floes=None, preset=preset, control_interval=control_interval,
                         colour_scale=colour_scale, **kwargs)
        vector_space = self.observation_space
        image_space = gym.spaces.Box(0, 255, (4, self.image_size, self.image_size),
                                     dtype=np.uint8)
        if obs_type == "image":
            self.observation_space = image_space
        elif obs_type == "dict":
            self.observation_space = gym.spaces.Dict({"vector": vector_space,
                                                      "image": image_space})
        elif obs_type.startswith("costmap"):
            space = costmap_space(self.costmap_size)
            self.observation_space = space if obs_type == "costmap" else gym.spaces.Dict(
                {"costmap": space, "vector": vector_space})
        # the vector observation's features as columns of a measurement (time_left:
        # filled in by the batch)
        column = {name: j for j, name in enumerate(self.measure_names)}
        self.feature_columns = np.array([column.get(f.name, 0) for f in self.features])

    # -- geometry -------------------------------------------------------------------
    @property
    def goal_x(self) -> float:
        """x of the goal line [m]."""
        return self.start_x + self.goal_distance

    @property
    def centre_y(self) -> float:
        return 0.5 * self.width

    def _ship_start(self) -> tuple:
        """((x, y), heading) of the ship at the start."""
        return (self.start_x, self.centre_y), 0.0

    # -- the episode's ice and ship --------------------------------------------------
    def _ice(self, rng: np.random.Generator):
        """(field, box, forcing) of a new episode."""
        raise NotImplementedError

    def _floe_field(self, box, rng, *, concentration: float, floe_sizes: str,
                    band: float | None = None):
        """Floes of the preset's material at rest covering ``concentration``
        of ``box``, or of its strip 0 ≤ y < ``band`` [m]
        (:func:`physics.ice_fields.channel_field`), those within reach of the
        ship's start removed. Sets the concentration the observation reports
        (of the box or of the strip)."""
        sizes, lognormal = FLOE_SIZES[floe_sizes]
        field, self.field_concentration = ice_fields.channel_field(
            self.preset, box, rng, concentration=concentration, sizes=sizes,
            lognormal=lognormal, band=band,
            keep=lambda positions, radii: self._clear_of_start(positions, radii, box))
        return field

    def _clear_of_start(self, positions, radii, box) -> np.ndarray:
        """Mask of the floes (``positions``, ``radii`` in ``box``) that leave
        :data:`START_CLEARANCE` of open water round the hull's reach at the
        ship's start."""
        from physics.hull import PSV_HULL

        start, _ = self._ship_start()
        gap = box.minimum_image(np.asarray(positions) - np.asarray(start))
        return np.hypot(gap[:, 0], gap[:, 1]) > PSV_HULL.circumradius + radii + START_CLEARANCE

    def _make_ship(self, rng):
        from physics.ship import psv_ship

        (x, y), heading = self._ship_start()
        speed = self._start_speed()
        extra = {} if self.mode == "dynamic" else dict(max_speed=self.max_speed,
                                                       max_yaw_rate=self.episode["max_yaw_rate"])
        return psv_ship(self.mode, position=(x, y), heading=heading, speed=speed,
                        friction=self.episode["hull_friction"], **extra)

    @property
    def max_speed(self) -> float:
        """Largest surge speed [m/s] the actions give (the reward's speed scale)."""
        if self.control in ("yaw", "course"):
            return self.episode["speed"]
        if self.control == "speed_yaw":
            return self.episode["max_speed"]
        return self._open_water_speed(self._ship.max_thrust)

    def _open_water_speed(self, thrust: float) -> float:
        """Surge speed [m/s] where the thrust balances the open-water damping."""
        h = self._ship.hydrodynamics
        a, b = h.quadratic_damping[0], h.linear_damping[0]
        return (-b + math.sqrt(b * b + 4.0 * a * thrust)) / (2.0 * a) if a > 0 else thrust / b

    def _start_speed(self) -> float:
        return self.episode["speed"]

    def make_sim(self, rng):
        from physics import HertzSimulation
        from physics.hertz import ship_time_step

        field, box, forcing = self._ice(rng)
        self.forcing = forcing
        self._ship = self._make_ship(rng)
        # constants of the ship that every step reads
        h = self._ship.hydrodynamics
        self.damping = (tuple(float(v) for v in h.linear_damping),
                         tuple(float(v) for v in h.quadratic_damping))
        self.hull_length = self._ship.hull.length
        drift = float(np.max(np.hypot(field.velocities[:, 0], field.velocities[:, 1]))) \
            if field.n else 0.0
        impact, dt = ship_time_step(field, box, self.contact,
                                    max(self.max_speed, self._start_speed()), drift,
                                    self.preset.time_step, self.stiffness_scale)
        sim = HertzSimulation(field, box, self.contact, forcing, dt=dt, impact_speed=impact,
                              parallel=False, ship=self._ship,
                              skip_resting=not self.free_drift, free_drift=self.free_drift,
                              allow_overlap=self.episode["concentration"] > PLACEMENT_LIMIT)
        self.n_floes = field.n
        self.impact_speed = impact
        self.track = [sim.ship.position]
        self._sums[:] = 0.0
        self._sums[[SUM_COLUMNS.index("x"), SUM_COLUMNS.index("y")]] = self.track[0]
        self.floes_hit = set()
        self.plan_overlay = None
        return sim

    # -- wind and current (the tasks with `wind_speed`, `wind_direction`,
    # `current_speed` and `current_direction` parameters)
    def _draw_range(self, name, task):
        # a drawn direction is an angle, drawn over the whole circle
        return ANGLE if name.endswith("direction") else super()._draw_range(name, task)

    def _forcing(self):
        """The episode's wind and current forcing."""
        e = self.episode

        def vector(speed, angle):
            return (speed * math.cos(angle), speed * math.sin(angle))

        return self.preset.make_forcing(wind=vector(e["wind_speed"], e["wind_direction"]),
                                        current=vector(e["current_speed"],
                                                       e["current_direction"]))

    def _drifting(self, field, forcing):
        """``field`` at its free drift under the episode's wind and current
        (unchanged, at rest, without them)."""
        from physics import FloeField
        from physics.forcing import steady_drift

        e = self.episode
        if e["wind_speed"] > 0.0 or e["current_speed"] > 0.0:
            u = steady_drift(forcing, field.radii, field.thickness, field.masses)
            field = FloeField(field.positions, field.radii, field.thickness, u,
                              density=field.density)
        return field

    # -- actions ---------------------------------------------------------------------
    def apply_action(self, action):
        ship = self.sim.ship
        if self.control == "yaw":
            ship.command(surge=self.episode["speed"],
                         yaw_rate=float(action[0]) * self.episode["max_yaw_rate"])
        elif self.control == "speed_yaw":
            ship.command(surge=0.5 * (float(action[0]) + 1.0) * self.episode["max_speed"],
                         yaw_rate=float(action[1]) * self.episode["max_yaw_rate"])
        elif self.control == "course":
            ship.command(surge=self.episode["speed"],
                         yaw_rate=self.course_yaw_rate(float(action[0]), float(ship.heading)))
        else:
            ship.command(thrust=float(action[0]) * self._ship.max_thrust,
                         yaw_moment=float(action[1]) * self._ship.max_yaw_moment)

    def course_yaw_rate(self, action: float, heading: float) -> float:
        """The autopilot of ``control="course"``: the yaw rate [rad/s] that
        turns ``heading`` [rad from the goal direction, +x] towards the
        course ``action`` × `max_course`, the heading error over
        `course_time` (not below the control interval, which would
        overshoot), limited to ±`max_yaw_rate` (the turning radius). The
        heading error is taken in (−π, π].

        A heading that follows its course with a time constant, as a
        ship's autopilot does, also filters a policy's step-to-step
        changes of course: turned within one step, each change would yaw
        the hull at up to its full rate, sweeping its sides through the
        ice."""
        e = self.episode
        error = math.remainder(action * e["max_course"] - heading, 2.0 * math.pi)
        limit = e["max_yaw_rate"]
        rate = error / max(e["course_time"], self.control_interval)
        return min(max(rate, -limit), limit)

    # -- one step ----------------------------------------------------------------------
    #: the environment's own measurements, after those of every ship environment
    extra_measures: tuple[str, ...] = ()

    def extra_values(self, envs) -> np.ndarray:
        """(M, len(extra_measures)) values of :attr:`extra_measures` for the
        environments ``envs`` of this class (a measurement's last columns)."""
        return np.zeros((len(envs), 0))

    def measure(self) -> dict:
        # the first measurement of an episode; a step measures in its batch
        raw = measure_ships([self], self._sums[None, :], advanced=False)
        return as_measurement(self.measure_names, raw[0], INTEGER_MEASURES)

    def measure_batch(self, envs, sums: np.ndarray, lists=None) -> np.ndarray:
        """The measurements after a step of ``envs`` (of this class and
        configuration), a row each (:func:`~iceenvs.ship_measures.measure_ships`;
        ``sums``: their rows of episode sums, updated in place)."""
        return measure_ships(envs, sums, advanced=True, lists=lists)

    def update_sums(self, sums: np.ndarray, cols: dict) -> None:
        """The episode metrics of ``sums`` after a step measured ``cols``."""
        update_metrics(sums, cols, self.goal_distance)

    def info_columns(self, raw, sums, steps, task) -> dict:
        """The info of a batch's step, on columns
        (:func:`~iceenvs.ship_measures.info_columns`)."""
        return info_columns(self.measure_names, raw, sums, steps, task)

    @property
    def observes_on_columns(self) -> bool:
        """A vector observation is made on columns over a batch."""
        return self.obs_type == "vector"

    @property
    def _sums(self) -> np.ndarray:
        """The episode's sums and metrics (:data:`~iceenvs.ship_measures.SUM_COLUMNS`):
        its row of the batch's ``sums``."""
        return self.episodes.sums[self.row]

    @property
    def slow_time(self) -> float:
        """Time [s] the ship has spent below the beset speed since it last
        sailed faster (a dynamic ship; 0 for a prescribed one)."""
        return float(self._sums[SUM_COLUMNS.index("slow_time")])

    # -- observation, info, end --------------------------------------------------------
    def observe(self, now: dict):
        if self.obs_type == "vector":
            return super().observe(now)
        if self.obs_type == "costmap":
            return self.costmap()
        if self.obs_type == "costmap_dict":
            return {"costmap": self.costmap(), "vector": super().observe(now)}
        image = self._image()
        if self.obs_type == "image":
            return image
        return {"vector": super().observe(now), "image": image}

    def _image(self) -> np.ndarray:
        sim = self.sim
        ship = sim.ship
        return occupancy_image(ship.position, ship.heading, sim.positions, sim.radii,
                               ship.vertices, self.goal_x, size=self.image_size,
                               extent=self.image_extent,
                               box_lengths=(sim.box.lx, sim.box.ly), periodic=sim.box.periodic)

    def costmap(self) -> np.ndarray:
        """The costmap of the ice about the ship now (the observation
        ``obs_type="costmap"``, :func:`iceenvs.costmap.ice_costmap`): the
        floes weighed by :meth:`expected_impulses`, the hull's half-beam
        added to their radii, cells of `costmap_cell` from `costmap_behind`
        behind the ship to `costmap_ahead` ahead, the channel's width
        across."""
        sim = self.sim
        x, y = sim.ship.position
        rows, cols = self.costmap_size
        box = sim.box
        return costmap_scan(float(x), float(y), sim.positions, sim.radii,
                            self.expected_impulses(sim.masses), 0.5 * float(self._ship.hull.beam),
                            self.goal_x, self.centre_y, 0.5 * self.channel_width,
                            self.costmap_ahead, self.costmap_cell, rows, cols,
                            costmap_samples(self.costmap_cell), float(box.lx), float(box.ly),
                            bool(box.periodic[0]), bool(box.periodic[1]))

    @property
    def _metrics(self) -> dict:
        """The episode metrics so far (:data:`METRICS`)."""
        return metric_values(self._sums)

    def make_info(self, now: dict) -> dict:
        # the metrics as the step (its batch) left them
        info = super().make_info(now)
        info.update(self._metrics)
        return info

    def ends(self, envs, nows, cols: dict, sums: np.ndarray, task: dict) -> tuple:
        """(succeeded, failed), boolean arrays, of a batch of environments
        ``envs`` of this class and configuration: ``cols`` the columns of their
        measurements (name → array), ``sums`` their rows of episode sums
        (:data:`SUM_COLUMNS`), ``task`` the columns of their episodes'
        tasks. Every ship task succeeds when its ship reaches the goal line.
        It fails when a dynamic ship stays below `beset_speed` for
        `beset_time` (a task with that parameter), and when the ship leaves
        the channel with `channel_exit="terminate"` (a task with that
        parameter); a task adds its own failures."""
        succeeded = cols["reached"] > 0
        failed = np.zeros_like(succeeded)
        if self.mode == "dynamic" and "beset_time" in task:
            failed |= sums[:, SLOW_TIME] >= task["beset_time"]
        if "channel_exit" in task:
            failed |= ((task["channel_exit"] == "terminate")
                       & (np.abs(cols["channel_offset"]) > 1.0))
        return succeeded, failed

    @property
    def ship(self):
        """The :class:`~physics.ship.Ship` of the current episode (set by
        ``reset``)."""
        return self._ship

    # the reward contract of ControlEnv: a failure pays -failure_penalty, and every
    # step's reward lies in reward_bounds
    @property
    def failure_reward(self) -> float:
        """The reward of a step that fails the task (beset, out of the
        channel, a physics failure): ``-failure_penalty`` of the reward
        parameters (:mod:`iceenvs.rewards`)."""
        return -float(self.reward_params["failure_penalty"])

    @property
    def reward_bounds(self) -> tuple[float, float]:
        """(lowest, highest) reward of one step, a failure's included
        (:func:`iceenvs.rewards.ship_reward_bounds`)."""
        from .rewards import ship_reward_bounds

        return ship_reward_bounds(self.reward_params)

    def reward_kwargs(self) -> dict:
        kwargs = super().reward_kwargs()
        kwargs["step_length"] = self.max_speed * self.control_interval
        return kwargs

    # -- privileged sensing (planners) -----------------------------------------------
    def ice_near(self, distance: float) -> dict:
        """The floes whose centres lie within ``distance`` [m] of the ship's
        centroid, as the engine holds them now: ``positions`` (K, 2) [m]
        (the periodic image nearest the ship), ``velocities`` (K, 2) [m/s],
        ``radii`` (K,) [m], ``masses`` (K,) [kg] and ``index`` (K,) (the
        engine's floe indices).

        This is *privileged* information: a planner may read it (as
        AUTO-IceNav's planners read the floe polygons from their simulator),
        a policy sees only its observation."""
        check_range("distance", distance, 0.0, None, low_open=True)
        sim = self.sim
        centre = np.asarray(sim.ship.position, dtype=float)
        gap = sim.box.minimum_image(sim.positions - centre)
        near = np.nonzero(gap[:, 0] ** 2 + gap[:, 1] ** 2 <= distance * distance)[0]
        return {"positions": centre + gap[near], "velocities": sim.velocities[near].copy(),
                "radii": sim.radii[near].copy(), "masses": sim.masses[near].copy(),
                "index": near}

    @property
    def metre_cost(self) -> float | None:
        """The ice impulse [N s] that one metre sailed is worth in the
        reward: it charges `time_weight` a step of `max_speed` ×
        `control_interval` metres and `impulse_weight` / `impulse_scale`
        per N s, so a metre is worth impulse_scale · time_weight /
        (impulse_weight · max_speed · control_interval). None for a reward
        without both terms."""
        p = self.reward_params
        if p.get("impulse_weight", 0.0) > 0 and p.get("time_weight", 0.0) > 0 \
                and "impulse_scale" in p:
            return (p["impulse_scale"] * p["time_weight"]
                    / (p["impulse_weight"] * self.max_speed * self.control_interval))
        return None

    def expected_impulses(self, masses) -> np.ndarray:
        """The impulse [N s] each floe of ``masses`` [kg] is expected to take
        from the hull: that of a head-on collision at the ship's full speed
        v, (1 + e) v m M / (m + M), with e the restitution and M the ship's
        mass. The lattice planner's ice cost and v1's swath sensor weigh
        the floes by it."""
        m = np.asarray(masses, dtype=float)
        big = float(self._ship.mass)
        return (1.0 + self.contact.restitution) * self.max_speed * m * big / (m + big)

    #: a planned route to draw on the frames: ((K, 2) points [m], swath half-width [m]) or None
    plan_overlay = None

    # -- frames ------------------------------------------------------------------------
    #: how far [m] the "follow" view reaches behind the ship and ahead of it
    view_behind = 100.0
    view_ahead = 300.0
    #: the largest plot [px] (width, height) of each view (:meth:`view_box`)
    VIEW_PLOTS = {"follow": (960, 600), "overview": (1240, 600)}
    _view = None

    @property
    def view(self) -> str | None:
        """What the frames show: ``"follow"``, a window that follows the
        ship (:attr:`view_behind` behind it to :attr:`view_ahead` ahead,
        the box's whole width across); ``"overview"``, the whole box — both
        to scale with axes in metres, a scale bar and the floes coloured by
        thickness class (:meth:`_view_frame`); None, the whole box with the
        floes coloured by speed (the frames of ShipNavigation-v0 and
        ShipBeset-v0)."""
        return self._view

    @view.setter
    def view(self, value) -> None:
        from .rendering import VIEWS

        if value is not None and (not isinstance(value, str) or value not in VIEWS):
            raise ValueError(f"view must be one of {VIEWS} or None, got {value!r}")
        self._view = value

    def _set_view_reach(self, behind, ahead) -> None:
        """Check and set :attr:`view_behind` and :attr:`view_ahead` [m]."""
        check_range("view_behind", behind, 0.0, None)
        check_range("view_ahead", ahead, 0.0, None)
        if not behind + ahead > 0:
            raise ValueError(f"view_behind + view_ahead must be positive, got {behind!r} + "
                             f"{ahead!r}")
        self.view_behind, self.view_ahead = float(behind), float(ahead)

    def view_box(self):
        """The :class:`~iceenvs.rendering.ViewBox` of the frames of
        :attr:`view` now (where a point of the box lies in the frame: its
        plot is at the top left of the frame)."""
        from .rendering import view_box, view_window

        view = self.view or "overview"
        sim = self.sim
        window = view_window(view, (sim.box.lx, sim.box.ly), float(sim.ship.position[0]),
                             behind=self.view_behind, ahead=self.view_ahead)
        width, height = self.VIEW_PLOTS[view]
        return view_box(window, max_width=width, max_height=height)

    def _thickness_classes(self):
        """The thicknesses [m] of the floes' classes, for the frames' colours
        (default: the distinct thicknesses of the episode's floes)."""
        return None

    def _view_frame(self) -> np.ndarray:
        """The frame of the views "follow" and "overview" (:attr:`view`)."""
        from .rendering import (CHAIN, CHANNEL, GOAL, HULL, LEAD, OUTSIDE, ROUTE, TRACK,
                                annotate, draw_view, thickness_colours)

        sim = self.sim
        c = sim.contacts()
        box = self.view_box()
        lx, ly = sim.box.lx, sim.box.ly
        colours, legend = thickness_colours(sim.field.thickness, self._thickness_classes())
        leads = tuple(getattr(self, "leads", ()))
        y0 = self.centre_y - 0.5 * self.channel_width
        channel = (y0, y0 + self.channel_width)
        if self.view == "follow":
            title = (f"following the ship: {self.view_behind:g} m behind it to "
                     f"{self.view_ahead:g} m ahead")
        else:
            title = f"the whole channel, {lx:g} m × {ly:g} m"
        picture = draw_view(box, sim.positions, sim.radii, (lx, ly), periodic=sim.box.periodic,
                            floe_colours=colours, contact_i=c.i, contact_j=c.j,
                            contact_force=c.normal_force, hull_vertices=sim.ship.vertices,
                            track=np.array(self.track), goal_x=self.goal_x, channel=channel,
                            route=self.plan_overlay, leads=leads,
                            ice_band=getattr(sim.box, "band", None), title=title)
        if leads:
            legend.append((LEAD, "lead (open water at the start)", "band"))
        legend += [(HULL, "ship", "band"), (TRACK, "ship's track", "line")]
        if self.plan_overlay is not None:
            legend.append((ROUTE, "planned course", "line"))
        legend += [(GOAL, "goal line", "line"), (CHAIN, "contact force (wider: stronger)", "line")]
        if self.channel_width < ly:
            legend.append((CHANNEL, "channel edge", "line"))
        walled = [(box.x0 < 0.0 or box.x1 > lx) and not sim.box.periodic[0],
                  (box.y0 < 0.0 or box.y1 > ly) and not sim.box.periodic[1]]
        if any(walled):                       # the window reaches beyond a wall
            legend.append((OUTSIDE, "beyond a wall", "band"))
        return annotate(picture, legend=legend, arrow=self._frame_arrow(),
                        text=self._frame_text(), side="bottom")

    def _frame(self) -> np.ndarray:
        if self.view is not None:
            return self._view_frame()
        from .rendering import annotate, draw_floes, draw_ship

        sim = self.sim
        c = sim.contacts()          # at the state the observation was made of
        box = (sim.box.lx, sim.box.ly)
        picture = draw_floes(sim.positions, sim.radii, box,
                             np.hypot(sim.velocities[:, 0], sim.velocities[:, 1]),
                             contact_i=c.i, contact_j=c.j, contact_force=c.normal_force,
                             speed_scale=self.colour_scale)
        y0 = self.centre_y - 0.5 * self.channel_width
        picture = draw_ship(picture, box, sim.ship.vertices, np.array(self.track),
                            goal_x=self.goal_x, channel=(y0, y0 + self.channel_width),
                            route=self.plan_overlay)
        return annotate(picture, colour_bar=(self.colour_label, 0.0, self.colour_scale),
                        arrow=self._frame_arrow(), text=self._frame_text())

    def _frame_text(self) -> list[str]:
        now = self._prev
        m = self._metrics
        return [f"t = {self.sim.time:.0f} s", f"A = {now['concentration']:.2f}",
                f"speed {now['surge']:.2f} m/s", f"to goal {now['goal_distance']:.0f} m",
                f"collisions {m['collisions']}", f"hull {now['hull_pressure'] / 1e3:.3g} kN/m"]

    def _frame_arrow(self):
        wind = np.asarray(self.forcing.wind, dtype=float)
        speed = float(np.hypot(*wind))
        if speed == 0.0:
            return None
        return [(wind / max(speed, 20.0), f"wind {speed:.1f} m/s")]
