"""``iceenvs/Convergence-v0``: compress ice to a target concentration without breaking it."""
from __future__ import annotations

import gymnasium as gym
import numpy as np

from physics import DeformingPeriodicBox, HERMAN2013, make_floe_field
from physics.params import check_range

from .base import HertzEnv
from .observations import FLOE_FEATURES, Feature, feature_table
from .rewards import convergence_reward

_EXTRA = (
    Feature("target", "target concentration A*", "-", "none", 0.0, 1.0),
    Feature("error", "(A − A*) / 0.1", "-", "none", -10.0, 10.0),
)


class ConvergenceEnv(HertzEnv):
    __doc__ = f"""Bring ice to a target concentration by convergence and hold it there,
    without the internal pressure passing a failure threshold.

    ## Description
    Floes of the Herman (2013) set-up in a deforming, doubly periodic box
    (experiment 1 of the paper: pure convergence, no wind). The box area
    changes at the rate the agent sets; the floes are remapped affinely.
    Pressure grows roughly exponentially with concentration and then
    sharply as the ice jams (the paper finds A_J ≈ 0.92 for 20000 floes),
    so the target just below jamming is reached safely only by slowing down
    in time.

    ## Action Space
    `Box(-1, 1, (1,), float32)`: the convergence rate dA/dt in units of
    `max_rate` per hour (default 1 per hour, 25 times the 0.04 per hour of
    the paper, so that an episode is short; positive: convergence).

    ## Observation Space
    `Box(float32)` of {len(FLOE_FEATURES) + len(_EXTRA) + 1} entries: the common floe
    features, the target and the last action:

{feature_table(FLOE_FEATURES + _EXTRA)}
    | {len(FLOE_FEATURES) + len(_EXTRA)} | `action` | the last action | - | none | [-1, 1] |

    ## Rewards
    :func:`iceenvs.rewards.convergence_reward`: −|A − A*| / 0.01 − (relative
    excess of the pressure over `pressure_max`, default 1e4 N/m).

    ## Starting State
    Floes placed at random without overlap at a concentration drawn
    uniformly in [0.70, 0.80] (seeded), at rest. Options: `target` (default
    0.90), `concentration` (a fixed start concentration, at most 0.85:
    random placement of this floe-size distribution jams near 0.86).

    ## Episode End
    Terminated when the pressure passes `failure_pressure` (default 1e5 N/m)
    or the physics fails (`info["error"]`); truncated after
    `episode_steps` (default 150 × 2 s). Failure is absorbing: the failing
    step's reward is also charged for each step the episode had left, so
    that breaking the ice never ends the (negative) rewards early.

    ## Arguments
    `n_floes=200`, `preset=HERMAN2013`, `control_interval=2.0` [s],
    `episode_steps=150`, `max_rate=1.0` [1/h], `failure_pressure=1e5`
    [N/m], `reward_fn`, `reward_params` (`pressure_max`,
    `concentration_scale`, `pressure_weight`), `stiffness_scale`,
    `cluster_gap`, `render_mode`.

    ## Version History
    * v0: initial version.
    """

    action_space = gym.spaces.Box(-1.0, 1.0, (1,), dtype=np.float32)
    action_names = ("convergence_rate",)
    extra_features = _EXTRA
    reward_fn = staticmethod(convergence_reward)
    impact_speed = 0.5

    def __init__(self, n_floes: int = 200, preset=HERMAN2013, control_interval: float = 2.0,
                 episode_steps: int = 150, max_rate: float = 1.0,
                 failure_pressure: float = 1e5, **kwargs):
        check_range("max_rate", max_rate, 0.0, None, low_open=True)
        check_range("failure_pressure", failure_pressure, 0.0, None, low_open=True)
        super().__init__(n_floes=n_floes, concentration=0.75, preset=preset,
                         control_interval=control_interval, episode_steps=episode_steps,
                         **kwargs)
        self.max_rate = float(max_rate)
        self.failure_pressure = float(failure_pressure)
        self.target = 0.9

    def default_reward_params(self) -> dict:
        return dict(target=0.9, pressure_max=1e4, concentration_scale=0.01, pressure_weight=1.0)

    def _reset_options(self, options: dict) -> None:
        target = options.pop("target", 0.9)
        start = options.pop("concentration", None)
        check_range("target", target, 0.0, 1.0, low_open=True, high_open=True)
        if start is not None:
            # random placement of this FSD jams near 0.86
            check_range("concentration", start, 0.0, 0.85, low_open=True)
        super()._reset_options(options)
        self.target = float(target)
        self._start = start
        self.reward_params["target"] = self.target

    def _make_sim(self, rng, options):
        p = self.preset
        start = float(rng.uniform(0.70, 0.80)) if self._start is None else float(self._start)
        field, box = make_floe_field(self.n_floes, concentration=start, alpha=p.fsd_exponent,
                                     mean_diameter=p.mean_diameter, thickness=p.thickness,
                                     density=p.forcing.ice_density,
                                     seed=int(rng.integers(2 ** 63)))
        self.box = DeformingPeriodicBox(box.lx, box.ly, concentration_rate=0.0)
        return self._hertz_sim(field, self.box, None)

    def _apply_action(self, action):
        self.box.set_rate(float(action[0]) * self.max_rate / 3600.0)

    def _measure(self) -> dict:
        now = self._contact_physics()
        now["target"] = self.target
        now["error"] = (now["concentration"] - self.target) / 0.1
        return now

    def _terminated(self, now: dict) -> bool:
        return now["pressure"] > self.failure_pressure
