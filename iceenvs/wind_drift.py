"""``iceenvs/WindDrift-v0``: steer drifting ice along a heading with the wind."""
from __future__ import annotations

import math

import gymnasium as gym
import numpy as np

from physics import HERMAN2013

from .base import MAX_WIND, HertzEnv, TaskParameter, number, task_table
from .controllers import FloeController
from .facts import EnvFacts
from .observations import FLOE_FEATURES, Feature, feature_table, log_stress
from .rewards import wind_drift_reward
from .vector import vector_class

__all__ = ["WindDriftEnv", "WindDriftVectorEnv", "WindDriftController"]

MAX_EPISODE_STEPS = 200

_EXTRA = (
    Feature("heading_cos", "cos of the target heading", "-", "none", -1.0, 1.0),
    Feature("heading_sin", "sin of the target heading", "-", "none", -1.0, 1.0),
    Feature("u_heading", "mean ice velocity along the target heading", "m/s", "/ 1 m/s",
            -5.0, 5.0),
    Feature("u_across", "mean ice velocity across the heading (positive to its left)", "m/s",
            "/ 1 m/s", -5.0, 5.0),
)

_TASK = (
    TaskParameter("heading", None, "target direction of the ice drift [rad] from +x; None: "
                  "drawn uniformly in [−π, π) every episode",
                  number(optional=True)),
    TaskParameter("concentration", 0.8, "ice concentration of the start state",
                  number(0.0, 0.85, low_open=True)),
    TaskParameter("max_wind", MAX_WIND, "wind speed [m/s] per component at |action| = 1",
                  number(0.0, 100.0, low_open=True)),
)


class WindDriftController(FloeController):
    """Blow along the target heading, corrected for the turning of the drift.

    The wind points along the heading (read from the observation), turned
    to the left by an angle ``turn`` and scaled so that its largest
    component is 1 (the strongest wind the action box allows in that
    direction; the drift speed grows with the wind, the action cost of
    0.01 |a|² is small against it). Coriolis turns the drift to the right
    of the wind, so ``turn`` is adapted from the measured drift: each step
    it changes by ``-gain`` × the angle of the mean ice velocity from the
    heading (once the ice moves faster than 1 cm/s), within ±45°. When the
    pressure passes the task's ``pressure_max`` the wind is halved, because
    the reward penalises the excess.
    """

    gain = 0.3
    max_turn = math.pi / 4
    turn = 0.0         # the current turn of the wind from the heading

    def reset(self, seed=None):
        self.turn = 0.0

    def act(self, obs):
        hx, hy = self._get(obs, "heading_cos"), self._get(obs, "heading_sin")
        ux, uy = self._get(obs, "u_x"), self._get(obs, "u_y")
        if math.hypot(ux, uy) > 0.01:
            error = math.atan2(hx * uy - hy * ux, hx * ux + hy * uy)   # drift left of heading > 0
            self.turn = float(np.clip(self.turn - self.gain * error, -self.max_turn,
                                      self.max_turn))
        heading = math.atan2(hy, hx) + self.turn
        wind = np.array([math.cos(heading), math.sin(heading)])
        wind /= np.max(np.abs(wind))
        if self._get(obs, "pressure") > log_stress(self.reward_params["pressure_max"]):
            wind *= 0.5
        return wind


class WindDriftEnv(HertzEnv):
    __doc__ = f"""Move sea ice along a target heading with the wind, without
    crushing it.

    ## Description
    Floes of the Herman (2013) set-up (power-law sizes α = 1.8, mean radius
    4 m, thickness 1.5 m, Hertz contacts with damping and Coulomb friction,
    air and water drag, Coriolis f = 1.3e-4 1/s) in a doubly periodic box at
    fixed concentration. The agent sets the wind; the ice responds through
    drag (spin-up time of the order of 10³ s), collisions and, at high
    concentration, a contact-force network. Every episode has its own
    target heading, given in the observation, so one policy learns all
    headings.

    ## Task analysis
    * *Reachable:* any heading. The drift keeps accelerating over the whole
      episode (about 0.49 m/s after 1000 s under 20 m/s wind along x, and
      0.98 m/s under the diagonal wind of 28 m/s): the task is never
      "done", it rewards the fastest drift along the heading.
    * *Best constant action:* over headings drawn uniformly, every constant
      wind moves the ice along the heading as often as against it. The
      best of a grid of 81 constant winds, (1, 1), earns 0.56 per step on
      the 20 evaluation episodes of the docs' training page, against 0.5
      for ice at rest and 0.69 for the hand-written controller.
    * *What a good policy does:* reads the heading and blows along it at
      full strength. The wind is limited per component and the air stress
      is quadratic in the wind (τ_a ∝ |u_a| u_a), so adding a cross
      component to the dominant one raises the stress along the heading;
      the Coriolis turning of the drift is a few degrees at these speeds.

    ## Action Space
    `Box(-1, 1, (2,), float32)`: the wind vector (u_a,x, u_a,y) in units of
    `max_wind` (default {MAX_WIND:g} m/s). NaN/inf entries are set to 0 and entries
    clipped.

    ## Observation Space
    `Box(float32)` of {len(FLOE_FEATURES) + len(_EXTRA) + 2} entries: the common floe
    features, the target heading, the ice velocity in the frame of the
    heading (so that progress is one entry, not a product of two) and the
    last action (with `horizon=N`, `time_left` before the action):

{feature_table(FLOE_FEATURES + _EXTRA)}
    | {len(FLOE_FEATURES) + len(_EXTRA)}, {len(FLOE_FEATURES) + len(_EXTRA) + 1} | `action` | the last action | - | none | [-1, 1] |

    `info["physics"]` holds the same quantities unscaled, in SI units, and
    `info["task"]` the episode's task parameters.

    ## Rewards
    :func:`iceenvs.rewards.wind_drift_reward`, in [0, 1] every step:
    (1 + u_h / 1 m/s)/2, clipped to [0, 1], with u_h the mean ice velocity
    along the heading (0.5 for ice at rest), times a safety factor that
    falls from 1 to 0 as the pressure goes from `pressure_max` (default
    2000 N/m) to twice that. A physics failure ends the episode with
    reward 0.

    ## Starting State
    Floes placed at random without overlap at `concentration` (seeded by
    `reset(seed=...)`), at rest, no wind; the heading drawn uniformly in
    [−π, π) unless `heading` is given.

    ## Task parameters
    {task_table(_TASK)}

    ## Episode End
    Truncated after `max_episode_steps` (registered: {MAX_EPISODE_STEPS}
    steps of 5 s); terminated only when the physics fails
    (`info["error"]`).

    ## Arguments
    `n_floes=200`, `preset=HERMAN2013`, `control_interval=5.0` [s],
    `reward_fn`, `reward_params` (`pressure_max`, `speed_scale`,
    `pressure_weight`), `stiffness_scale=1.0` (< 1: softer contacts and a
    longer time step, faster), `cluster_gap=0.1` [m], `horizon=None`,
    `colour_scale=0.5` [m/s], `render_mode`, and the task parameters.

    ## Version History
    * v0: a heading drawn per episode, rewards in [0, 1], task parameters
      as `gymnasium.make` keywords, episode length by `max_episode_steps`.
    """  # noqa: E501  (Markdown table rows cannot wrap)

    action_space = gym.spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)
    action_names = ("wind_x", "wind_y")
    extra_features = _EXTRA
    task_parameters = _TASK
    reward_task_keys = ("heading",)
    reward_fn = staticmethod(wind_drift_reward)
    facts = EnvFacts(
        summary="move ice along a heading with the wind",
        metrics={"u_heading": "u_heading", "u_x": "u_x", "u_y": "u_y", "pressure": "pressure",
                 "z_c": "Z_c", "largest_cluster": "largest_cluster_fraction",
                 "temperature": "granular_temperature"},
        main_metric="u_heading",
        controllers={"heuristic": WindDriftController},
        small={"n_floes": 60})

    episode_members = ("forcing",)

    def __init__(self, n_floes: int = 200, preset=HERMAN2013, control_interval: float = 5.0,
                 **kwargs):
        super().__init__(n_floes=n_floes, preset=preset, control_interval=control_interval,
                         **kwargs)

    def default_reward_params(self) -> dict:
        return dict(pressure_max=2000.0, speed_scale=1.0, pressure_weight=1.0)

    def _draw_episode(self, task, rng):
        if task["heading"] is None:
            task["heading"] = float(rng.uniform(-math.pi, math.pi))
        return task

    def make_sim(self, rng):
        p = self.preset
        field, box = p.floe_field(self.n_floes, self.episode["concentration"],
                                  seed=int(rng.integers(2 ** 63)))
        self.forcing = p.make_forcing(wind=(0.0, 0.0))
        return self._hertz_sim(field, box, self.forcing)

    def apply_action(self, action):
        self.forcing.wind = self.episode["max_wind"] * action

    def measure(self) -> dict:
        now = self._contact_physics()
        h = self.episode["heading"]
        now["heading_cos"] = math.cos(h)
        now["heading_sin"] = math.sin(h)
        now["u_heading"] = now["u_x"] * now["heading_cos"] + now["u_y"] * now["heading_sin"]
        now["u_across"] = now["u_y"] * now["heading_cos"] - now["u_x"] * now["heading_sin"]
        return now

    def _frame_text(self):
        return super()._frame_text() + [f"heading {math.degrees(self.episode['heading']):.0f}°"]

    def _frame_arrow(self):
        wind = np.asarray(self.forcing.wind, dtype=float)
        h = self.episode["heading"]
        return [((math.cos(h), math.sin(h)), "heading"),
                (wind / (self.episode["max_wind"] * math.sqrt(2.0)),
                 f"wind {np.hypot(*wind):.1f} m/s")]


#: N :class:`WindDriftEnv` whose engines advance together (:mod:`iceenvs.vector`)
WindDriftVectorEnv = vector_class(WindDriftEnv)
