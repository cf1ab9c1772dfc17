"""``iceenvs/Convergence-v0``: compress ice to a target concentration without breaking it."""
from __future__ import annotations

import gymnasium as gym
import numpy as np

from physics import HERMAN2013, DeformingPeriodicBox

from .base import HertzEnv, TaskParameter, interval, number, task_table
from .controllers import FloeController
from .facts import EnvFacts
from .observations import FLOE_FEATURES, Feature, feature_table, log_stress
from .rewards import convergence_reward
from .vector import vector_class

__all__ = ["ConvergenceEnv", "ConvergenceVectorEnv", "ConvergenceController", "MAX_START"]

MAX_EPISODE_STEPS = 150
#: random placement of this floe-size distribution jams near 0.86
MAX_START = 0.85

_EXTRA = (
    Feature("target", "target concentration A*", "-", "none", 0.0, 1.0),
    Feature("error", "(A − A*) / 0.1", "-", "none", -10.0, 10.0),
)

_TASK = (
    TaskParameter("target", None, "target concentration A*; None: drawn uniformly from "
                  "`target_range` every episode", number(0.0, 1.0, low_open=True,
                                                          high_open=True, optional=True)),
    TaskParameter("target_range", (0.75, 0.84), "range of the drawn targets",
                  interval(0.0, 1.0, low_open=True, high_open=True)),
    TaskParameter("concentration", None, f"start concentration (at most {MAX_START:g}); "
                  "None: drawn uniformly from `concentration_range` every episode",
                  number(0.0, MAX_START, low_open=True, optional=True)),
    TaskParameter("concentration_range", (0.70, 0.80), "range of the drawn start "
                  "concentrations", interval(0.0, MAX_START, low_open=True)),
    TaskParameter("max_rate", 2.0, "convergence rate dA/dt [1/h] at action +1",
                  number(0.0, 100.0, low_open=True)),
    TaskParameter("failure_pressure", 1e5, "pressure [N/m] at which the ice breaks (the "
                  "episode terminates)", number(0.0, None, low_open=True)),
)


class ConvergenceController(FloeController):
    """Proportional control of the concentration with a pressure limit.

    The convergence rate is ``-gain`` × the observed error (A − A*)/0.1,
    clipped to the action bounds: full convergence far below the target,
    slowing down within 0.1/gain of it, divergence above it. As the ice
    approaches jamming the pressure rises steeply; between half of the
    task's ``pressure_max`` and ``pressure_max`` the convergence rate is
    scaled down linearly in log pressure to 0, and above ``pressure_max``
    the box diverges slowly (−0.2) to relieve the pressure.
    """

    gain = 20.0

    def act(self, obs):
        rate = float(np.clip(-self.gain * self._get(obs, "error"), -1.0, 1.0))
        p = self._get(obs, "pressure")
        p_max = log_stress(self.reward_params["pressure_max"])
        p_soft = log_stress(0.5 * self.reward_params["pressure_max"])
        if p > p_max:
            rate = -0.2
        elif p > p_soft and rate > 0:
            rate *= (p_max - p) / (p_max - p_soft)
        return np.array([rate])


class ConvergenceEnv(HertzEnv):
    __doc__ = f"""Bring ice to a target concentration by convergence and hold it there,
    without the internal pressure passing a failure threshold.

    ## Description
    Floes of the Herman (2013) set-up in a deforming, doubly periodic box
    (experiment 1 of the paper: pure convergence, no wind). The box area
    changes at the rate the agent sets; the floes are remapped affinely.
    Pressure grows slowly with concentration and then sharply as the ice
    jams: 200 floes compressed from 0.70 at 4 per hour pass the failure
    pressure (10⁵ N/m) at A = 0.847–0.867 (seeds 0–3). Every episode has its own start
    concentration and target, both in the observation.

    ## Task analysis
    * *Reachable:* starts lie in [0.70, 0.80] and targets in [0.75, 0.84]; at
      the maximum rate of 2 per hour an episode of 150 × 2 s moves A by up
      to 0.167, more than the largest distance (0.14), in either direction.
    * *Best constant action:* a constant rate moves A linearly and cannot
      stop at targets that differ from episode to episode; full convergence
      also overshoots into jamming. The best of a grid of constant rates is
      measured in the docs' training page.
    * *What a good policy does:* converges (or diverges) at full rate while
      far from the target, slows down as A approaches it (the pressure
      rises steeply within 0.02 of jamming, and the top targets lie close
      to it), then holds A at the target with zero rate.

    ## Action Space
    `Box(-1, 1, (1,), float32)`: the convergence rate dA/dt in units of
    `max_rate` per hour (default 2 per hour, 50 times the 0.04 per hour of
    the paper, so that an episode is short; positive: convergence).

    ## Observation Space
    `Box(float32)` of {len(FLOE_FEATURES) + len(_EXTRA) + 1} entries: the common floe
    features, the target and the last action (with `horizon=N`,
    `time_left` before the action):

{feature_table(FLOE_FEATURES + _EXTRA)}
    | {len(FLOE_FEATURES) + len(_EXTRA)} | `action` | the last action | - | none | [-1, 1] |

    ## Rewards
    :func:`iceenvs.rewards.convergence_reward`, in [0, 1] every step:
    1 − |A − A*| / 0.1 (at least 0), times a safety factor that falls from
    1 to 0 as the pressure goes from `pressure_max` (default 1e4 N/m) to
    twice that. Broken ice (the pressure above `failure_pressure`) or a
    physics failure ends the episode with reward 0, so breaking the ice
    loses every reward the episode had left.

    ## Starting State
    Floes placed at random without overlap at the start concentration
    (seeded), at rest.

    ## Task parameters
    {task_table(_TASK)}

    ## Episode End
    Terminated when the pressure passes `failure_pressure` or the physics
    fails (`info["error"]`); truncated after `max_episode_steps`
    (registered: {MAX_EPISODE_STEPS} steps of 2 s).

    ## Arguments
    `n_floes=200`, `preset=HERMAN2013`, `control_interval=2.0` [s],
    `reward_fn`, `reward_params` (`pressure_max`, `concentration_scale`,
    `pressure_weight`), `stiffness_scale`, `cluster_gap`, `horizon=None`,
    `colour_scale=0.05` [m/s], `render_mode`, and the task parameters.

    ## Version History
    * v0: targets and start concentrations drawn per episode from ranges
      that are reachable (the former fixed target 0.90 was not), maximum
      rate 2 per hour, rewards in [0, 1] with broken ice worth 0, task
      parameters as `gymnasium.make` keywords, episode length by
      `max_episode_steps`.
    """

    action_space = gym.spaces.Box(-1.0, 1.0, (1,), dtype=np.float32)
    action_names = ("convergence_rate",)
    extra_features = _EXTRA
    task_parameters = _TASK
    reward_task_keys = ("target",)
    drawn = ("concentration", "target")
    reward_fn = staticmethod(convergence_reward)
    facts = EnvFacts(
        summary="compress ice to a target concentration",
        metrics={"concentration": "concentration", "target": "target", "pressure": "pressure",
                 "z_c": "Z_c", "f_nr": "non_rattler_fraction",
                 "largest_cluster": "largest_cluster_fraction"},
        main_metric="concentration",
        controllers={"heuristic": ConvergenceController},
        small={"n_floes": 60})
    impact_speed = 0.5

    episode_members = ("box",)

    def __init__(self, n_floes: int = 200, preset=HERMAN2013, control_interval: float = 2.0,
                 colour_scale: float = 0.05, **kwargs):
        super().__init__(n_floes=n_floes, preset=preset, control_interval=control_interval,
                         colour_scale=colour_scale, **kwargs)

    def default_reward_params(self) -> dict:
        return dict(pressure_max=1e4, concentration_scale=0.1, pressure_weight=1.0)

    def make_sim(self, rng):
        p = self.preset
        field, box = p.floe_field(self.n_floes, self.episode["concentration"],
                                  seed=int(rng.integers(2 ** 63)))
        self.box = DeformingPeriodicBox(box.lx, box.ly, concentration_rate=0.0)
        return self._hertz_sim(field, self.box, None)

    def apply_action(self, action):
        self.box.set_rate(float(action[0]) * self.episode["max_rate"] / 3600.0)

    def measure(self) -> dict:
        now = self._contact_physics()
        now["target"] = self.episode["target"]
        now["error"] = (now["concentration"] - self.episode["target"]) / 0.1
        return now

    def _terminated(self, now: dict) -> bool:
        return now["pressure"] > self.episode["failure_pressure"]

    def _frame_text(self):
        p = self._prev["pressure"]
        pressure = f"{p:.3g}" if abs(p) >= 1e-3 else "0"      # no "-0" for a slack pack
        return super()._frame_text() + [f"target A* = {self.episode['target']:.3f}",
                                        f"p = {pressure} N/m"]


#: N :class:`ConvergenceEnv` whose engines advance together (:mod:`iceenvs.vector`)
ConvergenceVectorEnv = vector_class(ConvergenceEnv)
