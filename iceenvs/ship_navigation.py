"""``iceenvs/ShipNavigation-v0``: sail a ship across a channel of drifting pack
ice to a goal line with as little ice impact as possible."""
from __future__ import annotations

import math


from physics import HERMAN2013
from physics.domain import Box

from .base import TaskParameter, choice, interval, number, task_table
from .observations import feature_table
from .rewards import ship_navigation_reward
from .ship_env import CONTROLS, FLOE_SIZES, ICE_LOADS, ShipEnv, ship_facts, ship_features
from .vector import vector_class

__all__ = ["ShipNavigationEnv", "ShipNavigationVectorEnv", "MAX_EPISODE_STEPS",
           "NAVIGATION_REWARD"]

MAX_EPISODE_STEPS = 300

_TASK = (
    TaskParameter("concentration", None, "ice concentration; None: drawn uniformly from "
                  "`concentration_range` every episode", number(0.0, 0.9, low_open=True,
                                                                optional=True)),
    TaskParameter("concentration_range", (0.2, 0.6), "range of the drawn concentrations "
                  "(up to 0.9: above 0.8 the floes are compressed into a jammed pack)",
                  interval(0.0, 0.9, low_open=True)),
    TaskParameter("floe_sizes", "pack", f"floe-size preset: one of {sorted(FLOE_SIZES)} "
                  "(pack: log-normal, median diameter 20 m; brash: median 6 m; "
                  "herman2013: the preset's power law, mean 8 m; auto_icenav: the floe "
                  "areas of AUTO-IceNav's ice fields, median 64 m², physics.ice_fields)",
                  choice(*FLOE_SIZES)),
    TaskParameter("wind_speed", None, "wind speed [m/s] that drives the ice; None: drawn "
                  "from `wind_speed_range`", number(0.0, 40.0, optional=True)),
    TaskParameter("wind_speed_range", (0.0, 0.0), "range of the drawn wind speeds [m/s] "
                  "(default: no wind)", interval(0.0, 40.0)),
    TaskParameter("wind_direction", None, "direction the wind blows to [rad from +x]; None: "
                  "drawn uniformly in [−π, π]", number(-math.pi, math.pi, optional=True)),
    TaskParameter("current_speed", None, "ocean current [m/s]; None: drawn from "
                  "`current_speed_range`", number(0.0, 2.0, optional=True)),
    TaskParameter("current_speed_range", (0.0, 0.0), "range of the drawn currents [m/s] "
                  "(default: none)", interval(0.0, 2.0)),
    TaskParameter("current_direction", None, "direction of the current [rad from +x]; "
                  "None: drawn uniformly in [−π, π]", number(-math.pi, math.pi, optional=True)),
    TaskParameter("speed", 2.0, "surge speed [m/s] of the ship with `control=\"yaw\"` (and "
                  "the start speed in every set-up)", number(0.1, 8.0)),
    TaskParameter("max_speed", 4.0, "surge speed [m/s] at action[0] = +1 with "
                  "`control=\"speed_yaw\"`", number(0.1, 8.0)),
    TaskParameter("max_yaw_rate", 0.04, "yaw rate [rad/s] at a full yaw action of the "
                  "prescribed set-ups (the autopilot's limit with `control=\"course\"`)",
                  number(0.0, 0.5, low_open=True)),
    TaskParameter("max_course", math.pi / 4, "course [rad from the goal direction] at a "
                  "full action with `control=\"course\"`", number(0.0, math.pi, low_open=True)),
    TaskParameter("course_time", 20.0, "time constant [s] of the autopilot of "
                  "`control=\"course\"`: it turns at (course − heading) / course_time (not "
                  "below the control interval), at most `max_yaw_rate`",
                  number(0.0, None, low_open=True)),
    TaskParameter("hull_friction", 0.05, "Coulomb coefficient of ice on the hull",
                  number(0.0, 1.0)),
    TaskParameter("beset_speed", 0.05, "with `control=\"thrust\"`: a ship whose surge speed "
                  "stays below this [m/s] ...", number(0.0, 1.0, low_open=True)),
    TaskParameter("beset_time", 60.0, "... for this long [s] is beset (the episode fails)",
                  number(0.0, None, low_open=True)),
    TaskParameter("channel_exit", "penalty", "leaving the channel: \"penalty\" (the reward's "
                  "`exit_weight` every step outside) or \"terminate\" (the episode fails)",
                  choice("penalty", "terminate")),
)

#: the reward weights of ShipNavigation-v0 (:func:`iceenvs.rewards.ship_navigation_reward`)
NAVIGATION_REWARD = dict(impulse_weight=1.0, impulse_scale=1.0e6, time_weight=0.05,
                         exit_weight=1.0, goal_bonus=10.0, failure_penalty=10.0)

_FEATURES = ship_features(9, 150.0)
#: entries of the default vector observation: the features, then the last action
_N_VECTOR = len(_FEATURES) + len(CONTROLS["yaw"][1])


class ShipNavigationEnv(ShipEnv):
    __doc__ = f"""Sail a ship across a channel of drifting pack ice to a goal line with
    as little ice impact as possible.

    ## Description
    The full-scale platform supply vessel of :func:`physics.ship.psv_ship`
    (76.2 m × 18 m, 6000 t, Fossen's supply-vessel hydrodynamics) sails
    through pack ice of the Herman (2013) material (1.5 m thick, Hertz
    contacts with friction) in a box of 400 m × 200 m, periodic both ways.
    It starts at x = 50 m on the centre line, heading along +x, and the
    goal line is x = 350 m. The channel is the band 150 m wide about the
    centre line. Each episode draws its concentration (default 0.2–0.6)
    and, optionally, a wind and a current that set the ice drifting (the
    floes start at their free drift).

    By default the ship sails at a fixed 2 m/s (about 4 knots; the model
    ship of BenchNPIN's `ship-ice-v0` at 0.3 m/s, scaled by Froude's law)
    and the agent sets its yaw rate, as in BenchNPIN. `control="speed_yaw"`
    adds the surge speed; `control="thrust"` gives a dynamic ship (thrust
    and yaw moment, the ice slows it and can beset it).

    ## Task analysis
    * *Reachable:* the straight line reaches the goal in 150 s (75 steps)
      at every default concentration, since the ship's speed is imposed.
    * *Best constant action:* sailing straight (action 0) is the best
      constant action for the progress term; it meets every floe in its
      path. Any other constant yaw rate sails in a circle.
    * *What a good policy does:* reads the lidar (or the image) and steers
      through the openings between the large floes, keeping close to the
      straight line, since every metre off it costs progress. How much
      that can gain is small at the default settings: at A = 0.4 the
      straight line loses about 11 of a return of 70 to the ice, and
      swerving round one floe meets the next (the reactive controller and the
      documented PPO run do worse than the straight line; see the docs'
      training page). Larger `impulse_weight` values make the ice count
      for more.

    ## Action Space
    `Box(-1, 1, (n,), float32)`. `control="yaw"` (default, n = 1): yaw rate
    = action[0] × `max_yaw_rate` (0.04 rad/s: a turning radius of 50 m at
    2 m/s). `control="speed_yaw"` (n = 2): surge speed `max_speed`
    (action[0] + 1)/2 and yaw rate action[1] × `max_yaw_rate`.
    `control="course"` (n = 1): the course action[0] × `max_course`
    (45°) from the goal direction, which an autopilot holds at the fixed
    speed (:meth:`~iceenvs.ship_env.ShipEnv.course_yaw_rate`: the yaw rate
    (course − heading) / `course_time`, 20 s, at most `max_yaw_rate`);
    action 0 sails straight for the goal line.
    `control="thrust"` (n = 2): thrust action[0] × 500 kN (astern below 0;
    full thrust: 5.5 m/s in open water) and yaw moment action[1] × 9.5 MN m.

    ## Observation Space
    `obs_type="vector"` (default): `Box(float32)` of {_N_VECTOR} entries: the
    {len(_FEATURES)} of the table below with the default 9-sector lidar (the
    lidar sees a half-disc of radius 150 m ahead; sector 0 looks to
    starboard, sector 8 to port), then `time_left` with `horizon=N`, then
    the last action (one entry with the default `control="yaw"`, two with
    the others). Forces are step means read from the engine's step records.

{feature_table(_FEATURES)}

    `obs_type="image"`: `Box(0, 255, (4, 64, 64), uint8)`, an egocentric
    picture of 150 m × 150 m around the ship (heading up), with the channels
    ice, hull footprint, goal distance and heading as BenchNPIN's
    (:func:`iceenvs.ship_sensors.occupancy_image`; `image_size` and
    `image_extent` change it). `obs_type="dict"`: both, under "vector"
    and "image".

    ## Rewards
    :func:`iceenvs.rewards.ship_navigation_reward`: progress (distance
    gained towards the goal line over the distance sailed at full speed in
    a step, in [−1, 1]) − `impulse_weight` (1) × min(J / `impulse_scale`,
    2), with J the impulse of the ice on the hull over the step and
    `impulse_scale` 10⁶ N s, − `time_weight` (0.05) − `exit_weight` (1)
    when outside the channel, + `goal_bonus` (10) on the step that reaches
    the goal. A failure gives −`failure_penalty` (−10).
    `env.unwrapped.reward_bounds` gives the bounds of one step.

    ## Ice loads
    {ICE_LOADS}

    ## Starting State
    Floes placed at random (seeded) at the drawn concentration with the
    preset sizes, those within the hull's reach of the start removed, at
    rest or at their free drift. The ship at (50 m, 100 m), heading +x,
    at `speed`.

    ## Task parameters
    {task_table(_TASK)}

    ## Episode End
    Terminated with success when the ship's centroid crosses the goal line
    (`info["success"]`); failed when a dynamic ship is beset, when it
    leaves the channel with `channel_exit="terminate"`, or on a physics
    failure (`info["error"]`). Truncated after `max_episode_steps`
    (registered: {MAX_EPISODE_STEPS} steps of 2 s, four times the straight transit).

    `info` holds, for the episode so far: `success`, `time`, `path_length`,
    `efficiency`, `effort`, `collisions`, `collided_floes`, `mean_impulse`,
    `max_impulse`, `impulse_per_metre`, `energy_to_ice`, `ice_resistance`,
    `max_hull_pressure`, `mean_mass_hit`, `ice_energy_gain`, `energy_dissipated`
    (see :mod:`iceenvs.ship_env`), with `physics` (the
    raw observation) and `task`.

    ## Arguments
    `control="yaw"`, `obs_type="vector"`, `image_size=64`,
    `image_extent=150.0` [m], `lidar_sectors=9`, `lidar_range=150.0` [m],
    `local_radius=100.0` [m], `length=400.0`, `width=200.0`,
    `channel_width=150.0`, `goal_distance=300.0` [m], `preset=HERMAN2013`,
    `control_interval=2.0` [s], `reward_fn`, `reward_params`
    (`impulse_weight`, `impulse_scale`, `time_weight`, `exit_weight`,
    `goal_bonus`, `failure_penalty`), `stiffness_scale`, `horizon=None`,
    `colour_scale=1.0` [m/s], `render_mode`, and the task parameters.

    ## Version History
    * v0: initial version. Its default engine step became the fast step
      (`free_drift=True`) once the equivalence test of the Benchmarks page
      (`seaice bench free_drift --env ...`) supported it; `free_drift=False`
      gives the exact step of the records made before.
    """

    task_parameters = _TASK
    drawn = ("concentration", "wind_speed", "wind_direction", "current_speed",
             "current_direction")
    reward_fn = staticmethod(ship_navigation_reward)
    facts = ship_facts(
        summary="sail a ship through pack ice to a goal",
        metrics={"goal_distance": "goal_distance", "surge": "surge",
                 "step_impulse": "step_impulse", "hull_pressure": "hull_pressure",
                 "concentration": "concentration"},
        main_metric="step_impulse",
        small={"concentration": 0.3},
        # ten times BenchNPIN ship-ice-v0 on the same machine (about 10 steps/s)
        speed_target=100)

    def __init__(self, preset=HERMAN2013, control_interval: float = 2.0, **kwargs):
        super().__init__(preset=preset, control_interval=control_interval, **kwargs)

    def default_reward_params(self) -> dict:
        return dict(NAVIGATION_REWARD)

    def _ice(self, rng):
        e = self.episode
        box = Box(self.length, self.width)
        forcing = self._forcing()
        field = self._floe_field(box, rng, concentration=e["concentration"],
                                 floe_sizes=e["floe_sizes"])
        return self._drifting(field, forcing), box, forcing


#: N :class:`ShipNavigationEnv` whose engines advance together (:mod:`iceenvs.vector`)
ShipNavigationVectorEnv = vector_class(ShipNavigationEnv)
