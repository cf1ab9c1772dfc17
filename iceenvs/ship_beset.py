"""``iceenvs/ShipBeset-v0``: keep a ship moving towards its goal through pack ice
that an onshore wind presses against a coast, with the ice pressure on the hull
below a limit."""
from __future__ import annotations

import numpy as np

from physics import HERMAN2013
from physics.domain import Box

from .base import TaskParameter, choice, interval, number, task_table
from .observations import Feature, feature_table
from .rewards import ship_beset_reward
from .ship_env import CONTROLS, FLOE_SIZES, ShipEnv, ship_facts, ship_features
from .vector import vector_class

__all__ = ["ShipBesetEnv", "ShipBesetVectorEnv", "MAX_EPISODE_STEPS"]

MAX_EPISODE_STEPS = 300
#: the hull must keep this far [m] from the coast and the far wall
WALL_MARGIN = 5.0

_EXTRA = (
    Feature("pressure_limit", "the episode's limit of the hull pressure", "N/m", "log stress",
            0.0, 10.0),
)

_TASK = (
    TaskParameter("concentration", None, "ice concentration of the pack along the coast; "
                  "None: drawn uniformly from `concentration_range` every episode",
                  number(0.0, 0.8, low_open=True, optional=True)),
    TaskParameter("concentration_range", (0.6, 0.75), "range of the drawn concentrations "
                  "(walls on both sides: the floes are placed directly, up to 0.8)",
                  interval(0.0, 0.8, low_open=True)),
    TaskParameter("ice_edge", 130.0, "width [m] of the pack from the coast (y = 0); open "
                  "water beyond it up to the far wall", number(60.0, 200.0)),
    TaskParameter("floe_sizes", "pack", f"floe-size preset: one of {sorted(FLOE_SIZES)}",
                  choice(*FLOE_SIZES)),
    TaskParameter("wind_speed", None, "onshore wind [m/s] (towards the coast, −y); None: "
                  "drawn from `wind_speed_range`", number(0.0, 40.0, optional=True)),
    TaskParameter("wind_speed_range", (10.0, 20.0), "range of the drawn wind speeds [m/s]",
                  interval(0.0, 40.0)),
    TaskParameter("pressure_limit", 1.0e4, "hull pressure [N/m] (normal forces over the hull "
                  "length, mean over a step) above which the reward is penalised",
                  number(0.0, None, low_open=True)),
    TaskParameter("ship_offset", 50.0, "the ship's start: its centre line this far [m] from "
                  "the coast", number(30.0, 170.0)),
    TaskParameter("speed", 1.0, "start surge speed [m/s]", number(0.0, 6.0)),
    TaskParameter("thrust_fraction", 1.0, "the largest thrust and yaw moment as a fraction "
                  "of the ship's (500 kN, 9.5 MN m)", number(0.0, 1.0, low_open=True)),
    TaskParameter("hull_friction", 0.05, "Coulomb coefficient of ice on the hull",
                  number(0.0, 1.0)),
    TaskParameter("beset_speed", 0.05, "a ship whose surge speed stays below this [m/s] ...",
                  number(0.0, 1.0, low_open=True)),
    TaskParameter("beset_time", 60.0, "... for this long [s] is beset (the episode fails)",
                  number(0.0, None, low_open=True)),
)

_FEATURES = ship_features(9, 150.0) + _EXTRA
#: entries of the vector observation: the features, then the last action
_N_VECTOR = len(_FEATURES) + len(CONTROLS["thrust"][1])


class ShipBesetEnv(ShipEnv):
    __doc__ = f"""Keep a ship moving towards its goal through pack ice that an onshore
    wind presses against a coast, with the ice pressure on the hull below a
    limit.

    ## Description
    The platform supply vessel of :func:`physics.ship.psv_ship` in its
    dynamic mode (thrust and yaw moment; the ice slows it, turns it and can
    beset it) sails along a coast. The box is 400 m long (periodic along
    x) and 200 m wide between two rigid walls: the coast at y = 0 and a
    far wall at y = 200 m. A pack of Herman (2013) floes fills the strip
    0 ≤ y < `ice_edge` (130 m) at the drawn concentration (default
    0.6–0.75) and an onshore wind (default 10–20 m/s, towards −y) presses
    it against the coast; beyond the ice edge lies an open lead. The ship
    starts in the pack, 50 m from the coast, heading +x, and the goal line
    is 300 m ahead.

    The task: keep moving towards the goal while the ice pressure on the
    hull (the sum of the normal contact forces over the hull length)
    stays below `pressure_limit`. No other public environment measures the
    ice pressure on the hull.

    ## Task analysis
    * *Reachable:* at full thrust the ship reaches the goal through the
      pack in about 140 s at A = 0.75 and 15 m/s of wind (seed 0).
    * *Best constant action:* full thrust straight ahead is the fastest and
      pushes the pack hardest; any constant yaw moment turns the ship into
      a wall.
    * *What a good policy does:* throttles when the hull pressure rises,
      and steers out of the pack into the lead (where the ice cannot
      press), then runs for the goal.

    ## Action Space
    `Box(-1, 1, (2,), float32)`: thrust action[0] × `thrust_fraction` ×
    500 kN (astern below 0; full thrust gives 5.5 m/s in open water) and
    yaw moment action[1] × `thrust_fraction` × 9.5 MN m.

    ## Observation Space
    `obs_type="vector"` (default): `Box(float32)` of {_N_VECTOR} entries: the
    {len(_FEATURES)} of the table below (as `ShipNavigation-v0`'s, the channel
    being the box between the walls, and the pressure limit), then
    `time_left` with `horizon=N`, then the last action (two entries):

{feature_table(_FEATURES)}

    `obs_type="image"` and `"dict"` as in `ShipNavigation-v0`.

    ## Rewards
    :func:`iceenvs.rewards.ship_beset_reward`: progress (distance gained
    towards the goal line over the distance sailed at full speed in a step,
    in [−1, 1]) − `pressure_weight` (1) × min(p / `pressure_limit` − 1, 1)
    above the limit − `time_weight` (0.05) + `goal_bonus` (10) on the step
    that reaches the goal. A failure gives −`failure_penalty` (−10).

    ## Starting State
    Floes placed at random (seeded) in the strip along the coast, at rest,
    those within the hull's reach of the start removed; the ship at
    (50 m, `ship_offset`), heading +x, at `speed` (1 m/s).

    ## Task parameters
    {task_table(_TASK)}

    ## Episode End
    Terminated with success when the ship's centroid crosses the goal line;
    failed when the ship is beset (surge below `beset_speed` for
    `beset_time`), when the hull comes within {WALL_MARGIN:g} m of a wall (the
    hull does not touch walls), or on a physics failure (`info["error"]`).
    Truncated after `max_episode_steps` (registered: {MAX_EPISODE_STEPS} steps of 2 s).
    `info` holds the episode metrics of `ShipNavigation-v0`.

    ## Arguments
    `obs_type="vector"`, `image_size=64`, `image_extent=150.0` [m],
    `lidar_sectors=9`, `lidar_range=150.0` [m], `local_radius=100.0` [m],
    `length=400.0`, `width=200.0`, `goal_distance=300.0` [m],
    `preset=HERMAN2013`, `control_interval=2.0` [s], `reward_fn`,
    `reward_params` (`pressure_weight`, `time_weight`, `goal_bonus`,
    `failure_penalty`), `stiffness_scale`, `horizon=None`,
    `colour_scale=1.0` [m/s], `render_mode`, and the task parameters.

    ## Version History
    * v0: initial version. Its default engine step became the fast step
      (`free_drift=True`) once the equivalence test of the Benchmarks page
      (`seaice bench free_drift --env ...`) supported it; `free_drift=False`
      gives the exact step of the records made before.
    """

    controls = ("thrust",)
    task_parameters = _TASK
    extra_features = _EXTRA
    drawn = ("concentration", "wind_speed")
    reward_task_keys = ("pressure_limit",)
    reward_fn = staticmethod(ship_beset_reward)
    facts = ship_facts(
        summary="keep a ship moving in pressured ice",
        metrics={"goal_distance": "goal_distance", "surge": "surge",
                 "hull_pressure": "hull_pressure", "pressure_limit": "pressure_limit",
                 "step_impulse": "step_impulse", "concentration": "concentration"},
        main_metric="hull_pressure",
        small={"concentration": 0.6})

    def __init__(self, preset=HERMAN2013, control_interval: float = 2.0, width: float = 200.0,
                 **kwargs):
        kwargs.setdefault("channel_width", width - 2.0 * WALL_MARGIN)
        super().__init__(control="thrust", preset=preset, control_interval=control_interval,
                         width=width, **kwargs)

    def default_reward_params(self) -> dict:
        return dict(pressure_weight=1.0, time_weight=0.05, goal_bonus=10.0,
                    failure_penalty=10.0)

    def _check_episode_task(self, task):
        if task["ice_edge"] > self.width:
            raise ValueError(f"ice_edge {task['ice_edge']:g} m exceeds the width {self.width:g} m")
        if not WALL_MARGIN + 10.0 <= task["ship_offset"] <= self.width - WALL_MARGIN - 10.0:
            raise ValueError(f"ship_offset {task['ship_offset']:g} m puts the hull within "
                             f"{WALL_MARGIN:g} m of a wall of the {self.width:g} m box")

    def _ship_start(self):
        return (self.start_x, self.episode["ship_offset"]), 0.0

    def _make_ship(self, rng):
        from physics.ship import psv_ship

        full = psv_ship("dynamic")
        f = self.episode["thrust_fraction"]
        (x, y), heading = self._ship_start()
        return psv_ship("dynamic", position=(x, y), heading=heading, speed=self.episode["speed"],
                        friction=self.episode["hull_friction"],
                        max_thrust=f * full.max_thrust, max_yaw_moment=f * full.max_yaw_moment)

    def _ice(self, rng):
        e = self.episode
        box = Box(self.length, self.width, periodic=(True, False))
        forcing = self.preset.make_forcing(wind=(0.0, -e["wind_speed"]), current=(0.0, 0.0))
        field = self._floe_field(box, rng, concentration=e["concentration"],
                                 floe_sizes=e["floe_sizes"], band=e["ice_edge"])
        return field, box, forcing

    extra_measures = ("pressure_limit", "wall_clearance")

    def extra_values(self, envs) -> np.ndarray:
        """The episode's pressure limit and the hull's clearance [m] from the
        nearer wall."""
        out = np.empty((len(envs), 2))
        for k, env in enumerate(envs):
            y = env.sim.ship.vertices[:, 1]
            out[k] = env.episode["pressure_limit"], min(y.min(), env.width - y.max())
        return out

    def ends(self, envs, nows, cols, sums, task):
        # fails also when the hull comes within WALL_MARGIN of a wall
        succeeded, failed = super().ends(envs, nows, cols, sums, task)
        return succeeded, failed | (cols["wall_clearance"] < WALL_MARGIN)

    def _frame_text(self):
        return super()._frame_text() + [
            f"limit {self.episode['pressure_limit'] / 1e3:.3g} kN/m"]


#: N :class:`ShipBesetEnv` whose engines advance together (:mod:`iceenvs.vector`)
ShipBesetVectorEnv = vector_class(ShipBesetEnv)
