"""``iceenvs/ShipNavigation-v1``: cross a kilometre of pack ice whose floes
and gaps are those of AUTO-IceNav's ice fields, with thickness classes,
leads and a concentration gradient as options."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from physics.input_checks import check_range
from physics.ice_fields import AUTO_ICENAV_SIZES, Lead, TransitBox, navigation_field

from .base import TaskParameter, choice, interval, number, revised_task, task_table
from .observations import Feature, feature_table
from .rewards import ship_navigation_reward
from .ship_controllers import SwathController
from .ship_env import CONTROLS, ICE_LOADS, ShipEnv, ship_features
from .ship_sensors import (channel_room, check_bands, course_with_room, scan_box, swath_courses,
                            swath_scan)
from .ship_navigation import NAVIGATION_REWARD, ShipNavigationEnv
from .vector import vector_class

__all__ = ["ShipNavigationV1Env", "ShipNavigationV1VectorEnv", "MAX_EPISODE_STEPS",
           "FIELD_SIZES", "ICE_AHEAD", "SWATH_FRAMES", "swath_features"]

#: two straight transits of the default field (275 steps each)
MAX_EPISODE_STEPS = 550

#: the floe-size laws of v1's fields: name → :class:`physics.ice_fields.LogMassSizes`
FIELD_SIZES = {"auto_icenav": AUTO_ICENAV_SIZES}

#: draws of the leads before a field that cannot be made is an error
LEAD_DRAWS = 10

#: open water [m] between the ship's start and the ice edge (AUTO-IceNav: 100 m)
ICE_AHEAD = 100.0

#: the swath sensor's default edges [m] of its bands of distance ahead
SWATH_BANDS = (0.0, 100.0, 250.0)


#: the directions the swath sensor's fan can be centred on: name → what about
SWATH_FRAMES = {"heading": "the ship's heading", "goal": "the goal direction (+x)"}


def swath_features(rays: int, bands=SWATH_BANDS, frame: str = "heading",
                   edge: bool = False) -> tuple[Feature, ...]:
    """The observation entries of the swath sensor
    (:func:`iceenvs.ship_sensors.ice_swath`) of ``rays`` courses fanned
    about the direction ``frame`` (:data:`SWATH_FRAMES`), band by band,
    course by course; with ``edge``, then each course's room in the channel
    (:func:`iceenvs.ship_sensors.channel_room`)."""
    about = SWATH_FRAMES[frame]
    reach = float(bands[-1])
    sums = tuple(
        Feature(f"swath_{b}_{k}", f"course {k} (of a fan about {about}): expected impulse of "
                f"the floes its swath meets {bands[b]:g}-{bands[b + 1]:g} m ahead", "N s",
                "log impulse", 0.0, 6.0)
        for b in range(len(bands) - 1) for k in range(rays))
    rooms = tuple(
        Feature(f"swath_room_{k}", f"course {k}: how far the centroid can sail along it before "
                f"it leaves the channel (capped at {reach:g} m)", "m", "/ 100 m", 0.0,
                reach / 100.0)
        for k in range(rays)) if edge else ()
    return sums + rooms


_FEATURES = ship_features(15, 250.0) + swath_features(9)
#: entries of the default vector observation: the features, then the last action
_N_VECTOR = len(_FEATURES) + len(CONTROLS["yaw"][1])


def _integer(low: int, high: int):
    def check(name, value):
        if isinstance(value, bool) or not float(value).is_integer() or not low <= value <= high:
            raise ValueError(f"{name} must be an integer in [{low}, {high}], got {value!r}")
        return int(value)
    return check


_CHANGED = {
    "concentration": ("ice concentration of the band of ice; None: drawn uniformly from "
                      "`concentration_range` every episode",
                      number(0.0, 0.8, low_open=True, optional=True)),
    "concentration_range": ("range of the drawn concentrations (AUTO-IceNav's fields: 0.2, 0.3, "
                            "0.4 and 0.5)", interval(0.0, 0.8, low_open=True)),
    "floe_sizes": (f"floe-size law: one of {sorted(FIELD_SIZES)} (auto_icenav: the floe areas "
                   "of AUTO-IceNav's ice fields, median 64 m², radii 2–50 m; "
                   "physics.ice_fields)", choice(*FIELD_SIZES)),
}
_DEFAULTS = {"concentration_range": (0.2, 0.5), "floe_sizes": "auto_icenav"}

# ShipNavigation-v0's parameters, revised, then v1's own
_TASK = revised_task(ShipNavigationEnv.task_parameters, _CHANGED, _DEFAULTS, added=(
    TaskParameter("ice_thickness", 1.2, "thickness [m] of the floes (AUTO-IceNav: 1.2 m of "
                  "first-year ice)", number(0.1, 10.0)),
    TaskParameter("thick_fraction", 0.0, "probability that a floe is of the thick class "
                  "(multi-year or ridged ice among the first-year floes)", number(0.0, 1.0)),
    TaskParameter("thick_thickness", 3.0, "thickness [m] of the thick class",
                  number(0.1, 10.0)),
    TaskParameter("leads", 2, "number of leads (straight bands of open water, at a drawn "
                  "angle to the route, through a drawn point of the ice; 0: AUTO-IceNav's "
                  "homogeneous field)", _integer(0, 20)),
    TaskParameter("lead_width", 20.0, "width [m] of a lead", number(1.0, 200.0)),
    TaskParameter("lead_length", 600.0, "longest lead [m]; a lead crosses the periodic "
                  "channel at most once (at angle θ it is at most width / |sin θ| long)",
                  number(10.0, 1.0e5)),
    TaskParameter("lead_angle_range", (-0.5 * math.pi, 0.5 * math.pi), "range of the drawn "
                  "angles [rad] of the leads to the route (0: along it; default: any)",
                  interval(-0.5 * math.pi, 0.5 * math.pi)),
    TaskParameter("gradient", 0.0, "concentration gradient across the channel: "
                  "A(y) = A (1 + gradient η), η from −1 (starboard edge) to 1 (port edge); "
                  "None: drawn from `gradient_range`", number(-1.0, 1.0, optional=True)),
    TaskParameter("gradient_range", (0.0, 0.0), "range of the drawn gradients",
                  interval(-1.0, 1.0)),
    TaskParameter("course_guard", None, "with `control=\"course\"`: room [m] in the channel "
                  "a commanded course must leave (the autopilot holds the nearest course that "
                  "does: `guarded_course`); None: every course is held",
                  number(1.0, 1.0e4, optional=True)),
))


class ShipNavigationV1Env(ShipEnv):
    __doc__ = f"""Cross a kilometre of pack ice, floes and gaps as in AUTO-IceNav's ice
    fields, with as little ice impact as possible.

    ## Description
    The ship, the material, the actions, the observation and the reward's
    terms are those of ShipNavigation-v0 (:class:`ShipNavigationEnv`); the
    ice field is new. It follows the simulated ice fields of AUTO-IceNav
    (de Schaetzen et al., IEEE Transactions on Robotics, 2025), whose full-scale
    supply vessel this suite models:

    * a channel 200 m wide, periodic across, with walls 50 m behind the
      ship's start and 350 m beyond the goal (far enough that the floes the
      bow pushes ahead never reach the wall before the ship is home: with
      100 m, a large floe pushed along was crushed against it);
    * the ship starts on the centre line heading along +x, 100 m before the
      ice edge; the ice covers the next 1000 m, to the goal line, 1100 m
      from the start (AUTO-IceNav: the same);
    * floe areas drawn from AUTO-IceNav's log-mass law (radii 2–50 m,
      median 64 m²; :data:`physics.ice_fields.AUTO_ICENAV_SIZES`), each floe
      a disc of its area (AUTO-IceNav's are convex polygons), at rest; the
      rare floes over 49.7 m in radius are shrunk to it, the largest that
      the engine's neighbour search allows across a periodic channel
      200 m wide;
    * Herman (2013) material (Hertz contacts with friction) 1.2 m thick;
    * the concentration drawn per episode from 0.2–0.5.

    Options make the field heterogeneous, as real ice is
    (:func:`physics.ice_fields.navigation_field`): a class of thicker
    floes (`thick_fraction`, `thick_thickness`), leads of open water
    (`leads`, `lead_width`, `lead_angle_range`) and a concentration
    gradient across the channel (`gradient`). Wind, current and the
    dynamic ship (`control="thrust"`) are options as in v0.

    ## Task analysis
    * *Reachable:* the straight line reaches the goal in 275 steps at
      every concentration (the ship's speed is imposed).
    * *Does route choice pay?* That is measured, not specified here: the
      docs' page "Ship navigation: does route choice pay?" ranks the
      straight line, the swath controller
      (:class:`iceenvs.ship_controllers.SwathController`, which decides on the
      observation alone), the lattice planner (:mod:`agents.planners`,
      which reads the floes) and PPO on the same seeded fields
      (`python -m agents.leaderboard`), with the default two leads and
      with AUTO-IceNav's homogeneous field (`leads=0`), in which nearly
      every beam-wide corridor holds floes every few metres.
    * *What a good policy does:* reads the ice ahead and steers for leads
      and the open water between the large floes, in gentle turns (a
      turning hull sweeps its sides through the ice).

    ## Action Space
    As ShipNavigation-v0: `Box(-1, 1, (1,), float32)`, the yaw rate
    action[0] × `max_yaw_rate` (0.04 rad/s) at a fixed 2 m/s
    (`control="yaw"`); `control="course"` (the course action[0] ×
    `max_course`, 45°, held by an autopilot), `control="speed_yaw"` and
    `control="thrust"` as there.
    With `course_guard=g` [m] the autopilot holds, for each commanded
    course, the nearest that leaves the ship at least g of room in the
    channel (:meth:`guarded_course`): a course guard that keeps the ship
    in the channel whatever the policy commands.

    ## Observation Space
    `obs_type="vector"` (default): `Box(float32)` of {_N_VECTOR} entries: the
    {len(_FEATURES)} of the table below, then `time_left` with `horizon=N`,
    then the last action. `obs_type="image"` and `"dict"` as v0. Beside
    v0's entries, with a 15-sector lidar reaching 250 m ahead (v0: 9
    sectors, 150 m), a *swath sensor* (:func:`iceenvs.ship_sensors.ice_swath`)
    shows the floes' sizes, which the lidar does not: for 9 straight
    courses fanned over ±40° about the heading, the expected collision
    impulse (:meth:`ShipEnv.expected_impulses`) of the floes the hull's
    swath along each would meet, 0-100 m and 100-250 m ahead of the ship.
    It weighs the floes by the impulse the lattice planner costs them at.
    `swath_frame="goal"` fans the courses about the goal direction (+x)
    instead, so that course k of the sensor is one course a policy can
    command with `control="course"`, whatever the heading. `swath_rays=0`
    leaves it out. The channel is periodic across, so the sensor sees the
    ice beyond the edge through its images, as if it lay inside;
    `swath_edge=True` adds, after the sums, each course's room in the
    channel (`swath_room_k`, :func:`iceenvs.ship_sensors.channel_room`):
    how far the centroid can sail along it before it leaves the channel,
    capped at 250 m.

{feature_table(_FEATURES)}

    ## Rewards
    :func:`iceenvs.rewards.ship_navigation_reward` with v1's weights:
    progress (in [−1, 1]) − min(J / 2.5·10⁵ N s, 10), with J the impulse of
    the ice on the hull over the step, − 0.2 a step − 1 a step outside the
    channel, + 10 on the step that reaches the goal; a failure gives −10.
    The progress over a whole transit is the same for every route that
    reaches the goal, so the return ranks routes by their ice impulse and
    their length (time at the fixed speed): one metre sailed costs as much
    as 0.2 / 4 m × 2.5·10⁵ N s = 12 500 N s of ice impulse, about 0.6 times
    the straight line's impulse per metre at A = 0.3-0.4. A detour that
    meets 30 % less ice sailing 10 % further, as the task analysis asks of
    a route choice, gains about a quarter of the straight line's ice
    penalty. The cap of 10 (2.5·10⁶ N s in a step) keeps a step's reward
    bounded and still counts a hit on a large floe.

    ## Ice loads
    {ICE_LOADS}

    ## Starting State
    A new field every episode (seeded). The ship at (50 m, 100 m),
    heading +x, at `speed`; the ice from 150 m to the goal line at 1150 m.

    ## Task parameters
    {task_table(_TASK)}

    ## Episode End
    As v0; truncated after `max_episode_steps` (registered:
    {MAX_EPISODE_STEPS} steps of 2 s, two straight transits). `info` holds
    v0's episode metrics.

    ## Arguments
    As v0, with the defaults `length=1500.0`, `width=200.0`,
    `channel_width=200.0`, `goal_distance=1100.0` [m], `lidar_sectors=15`
    and `lidar_range=250.0` [m]; and the swath sensor's `swath_rays=9`
    (0: none), `swath_fan=π/2` [rad] (the angle from the first course to
    the last is fan × (rays − 1) / rays), `swath_bands=(0, 100, 250)` [m],
    `swath_frame="heading"` (the fan's centre: `"heading"` or
    `"goal"`) and `swath_edge=False` (True: each course's room in the
    channel joins the observation). The frames (`render_mode="rgb_array"`
    or `"human"`) show `view="follow"` (default: a window that follows the
    ship, `view_behind=100.0` [m] behind it to `view_ahead=300.0` [m]
    ahead, the channel's whole width across) or `view="overview"` (the
    whole channel), to scale with axes in metres and a scale bar, the floes
    coloured by thickness class, the leads shaded, the contact forces, the
    track and the course a planner shows
    (:attr:`iceenvs.ship_env.ShipEnv.plan_overlay`); `view=None` gives
    v0's frame (the whole box, floes coloured by speed).
    The attribute `view` of the environment switches between them.

    ## Version History
    * v1: a field comparable to AUTO-IceNav's (v0 stays registered,
      unchanged). Its default engine step became the fast step
      (`free_drift=True`) once the equivalence test of the Benchmarks page
      (`seaice bench free_drift`) held every metric to the exact step's
      within its margin; `free_drift=False` gives the exact step of the
      records made before.
    """

    task_parameters = _TASK
    drawn = ShipNavigationEnv.drawn + ("gradient",)
    reward_fn = staticmethod(ship_navigation_reward)
    facts = replace(ShipNavigationEnv.facts,
                    summary="cross a kilometre of pack ice (AUTO-IceNav's fields)",
                    small={"concentration": 0.2, "length": 450.0, "goal_distance": 300.0},
                    speed_target=50,
                    controllers={**ShipNavigationEnv.facts.controllers, "swath": SwathController})

    episode_members = ("leads", "_swath_weights")

    def __init__(self, *, length: float = 1500.0, width: float = 200.0,
                 channel_width: float = 200.0, goal_distance: float = 1100.0,
                 lidar_sectors: int = 15, lidar_range: float = 250.0, swath_rays: int = 9,
                 swath_fan: float = 0.5 * math.pi, swath_bands=SWATH_BANDS,
                 swath_frame: str = "heading", swath_edge: bool = False,
                 view: str = "follow", view_behind: float = 100.0, view_ahead: float = 300.0,
                 **kwargs):
        self.view = view
        self._set_view_reach(view_behind, view_ahead)
        self.swath_rays = _integer(0, 64)("swath_rays", swath_rays)
        check_range("swath_fan", swath_fan, 0.0, math.pi, low_open=True)
        self.swath_fan = float(swath_fan)
        self.swath_bands = bands = check_bands("swath_bands", swath_bands)
        if swath_frame not in SWATH_FRAMES:
            raise ValueError(f"swath_frame must be one of {sorted(SWATH_FRAMES)}, "
                             f"got {swath_frame!r}")
        self.swath_frame = swath_frame
        if not isinstance(swath_edge, (bool, np.bool_)):
            raise ValueError(f"swath_edge must be True or False, got {swath_edge!r}")
        self.swath_edge = bool(swath_edge) and self.swath_rays > 0
        self.extra_features = swath_features(self.swath_rays, tuple(bands.tolist()),
                                             swath_frame, self.swath_edge)
        self.extra_measures = tuple(f.name for f in self.extra_features)
        super().__init__(length=length, width=width, channel_width=channel_width,
                         goal_distance=goal_distance, lidar_sectors=lidar_sectors,
                         lidar_range=lidar_range, **kwargs)
        if goal_distance <= ICE_AHEAD:
            raise ValueError(f"goal_distance {goal_distance:g} m leaves no ice: the ice starts "
                             f"{ICE_AHEAD:g} m ahead of the ship")

    def guarded_course(self, course: float) -> float:
        """The course [rad from the goal direction] the autopilot holds for
        ``course``: with a `course_guard` g, the nearest that leaves the
        ship's centroid at least g of room in the channel
        (:func:`iceenvs.ship_sensors.course_with_room`); ``course`` itself
        without one."""
        g = self.episode["course_guard"]
        if g is None:
            return float(course)
        offset = float(self.sim.ship.position[1]) - self.centre_y
        return course_with_room(course, offset, 0.5 * self.channel_width, g)

    def apply_action(self, action):
        if self.control == "course" and self.episode["course_guard"] is not None:
            turn = self.episode["max_course"]
            action = np.array([self.guarded_course(float(action[0]) * turn) / turn])
        super().apply_action(action)

    def _thickness_classes(self):
        """The episode's thickness classes [m]: the thin ice, and the thick
        class when floes may be of it (the frames colour each floe by its
        class, so that thick floes keep their colour in a field of them alone)."""
        e = self.episode
        if e["thick_fraction"] > 0:
            return (e["ice_thickness"], e["thick_thickness"])
        return (e["ice_thickness"],)

    def default_reward_params(self) -> dict:
        return dict(NAVIGATION_REWARD, impulse_scale=2.5e5, impulse_cap=10.0,
                    time_weight=0.2)

    def extra_values(self, envs) -> np.ndarray:
        """The swath sensor of each of ``envs``: (M, bands × rays), then with
        :attr:`swath_edge` each course's room in the channel (M, rays)."""
        out = np.empty((len(envs), len(self.extra_measures)))
        if not self.swath_rays:
            return out
        courses = swath_courses(self.swath_rays, self.swath_fan)
        n_sums = self.swath_rays * (len(self.swath_bands) - 1)
        for k, env in enumerate(envs):
            sim = env.sim
            # the swath's pose: the ship's (x, y, heading), or (x, y, 0) about +x
            pose = sim.ship.motion
            if self.swath_frame != "heading":
                pose = np.array([pose[0], pose[1], 0.0])
            box = sim.box
            sums = swath_scan(pose, sim.positions, sim.radii, env._swath_weights,
                              np.array([self.swath_rays, self.swath_fan,
                                        0.5 * env.ship.hull.beam]),
                              self.swath_bands, scan_box(float(box.lx), float(box.ly), box.periodic))
            out[k, :n_sums] = sums.T.ravel()
            if self.swath_edge:
                out[k, n_sums:] = channel_room(float(pose[1]) - env.centre_y,
                                               0.5 * env.channel_width, float(pose[2]) + courses,
                                               float(self.swath_bands[-1]))
        return out

    @staticmethod
    def _fitting(field, box):
        """``field`` with its few floes too large for the periodic channel
        ``box`` shrunk to fit: the engine's minimum-image neighbour search
        needs the largest pair's reach, 2 r + skin, below half the width
        (:func:`physics.engine.largest_radius`), so a 200 m channel holds
        radii up to about 49.7 m, and the floe law's (clipped at 50 m) are
        shrunk to that. Shrinking a floe opens no overlap."""
        from physics.engine import default_skin, largest_radius

        if field.n == 0:
            return field
        limit = 0.999 * largest_radius(box, default_skin(field.radii))
        if field.radii.max() <= limit:
            return field
        return replace(field, radii=np.minimum(field.radii, limit))

    def make_sim(self, rng):
        sim = super().make_sim(rng)
        self._swath_weights = self.expected_impulses(sim.masses)
        return sim

    @property
    def ice_band(self) -> tuple[float, float]:
        """(x0, x1) [m] of the band of ice: from 100 m ahead of the start to
        the goal line."""
        return self.start_x + ICE_AHEAD, self.goal_x

    def _leads(self, rng) -> tuple:
        e = self.episode
        x0, x1 = self.ice_band
        leads = []
        for _ in range(e["leads"]):
            x, y = float(rng.uniform(x0, x1)), float(rng.uniform(0.0, self.width))
            angle = float(rng.uniform(*e["lead_angle_range"]))
            crossing = self.width / max(abs(math.sin(angle)), 1e-12)
            leads.append(Lead(x, y, angle, e["lead_width"], min(e["lead_length"], crossing)))
        return tuple(leads)

    def _ice(self, rng):
        from physics.floes import spatial_order

        e = self.episode
        box = TransitBox(self.length, self.width, band=self.ice_band)
        forcing = self._forcing()
        for attempt in range(LEAD_DRAWS):
            self.leads = self._leads(rng)
            try:
                field, covered = navigation_field(
                    FIELD_SIZES[e["floe_sizes"]], concentration=e["concentration"],
                    band=self.ice_band, width=self.width, rng=rng, thickness=e["ice_thickness"],
                    density=self.preset.forcing.ice_density, thick_fraction=e["thick_fraction"],
                    thick_thickness=e["thick_thickness"], leads=self.leads,
                    gradient=e["gradient"])
                break
            except ValueError:
                # leads whose open water the concentration cannot spare are drawn again
                if not self.leads or attempt == LEAD_DRAWS - 1:
                    raise
        self.field_concentration = covered
        field = field.take(self._clear_of_start(field.positions, field.radii, box).nonzero()[0])
        field = self._fitting(field, box)
        field = self._drifting(field, forcing)
        return field.take(spatial_order(field.positions, box)), box, forcing


#: N :class:`ShipNavigationV1Env` whose engines advance together (:mod:`iceenvs.vector`)
ShipNavigationV1VectorEnv = vector_class(ShipNavigationV1Env)
