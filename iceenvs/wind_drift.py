"""``iceenvs/WindDrift-v0``: steer drifting ice with the wind."""
from __future__ import annotations

import math

import gymnasium as gym
import numpy as np

from physics import Forcing, HERMAN2013, make_floe_field

from .base import HertzEnv
from .observations import FLOE_FEATURES, Feature, feature_table
from .rewards import wind_drift_reward

MAX_WIND = 20.0   # m/s per component at |action| = 1

_EXTRA = (
    Feature("heading_cos", "cos of the target heading", "-", "none", -1.0, 1.0),
    Feature("heading_sin", "sin of the target heading", "-", "none", -1.0, 1.0),
)


class WindDriftEnv(HertzEnv):
    __doc__ = f"""Move sea ice along a target heading with the wind, without
    crushing it.

    ## Description
    Floes of the Herman (2013) set-up (power-law sizes α = 1.8, mean radius
    4 m, thickness 1.5 m, Hertz contacts with damping and Coulomb friction,
    air and water drag, Coriolis f = 1.3e-4 1/s) in a doubly periodic box at
    fixed concentration. The agent sets the wind; the ice responds through
    drag (spin-up time of the order of 10³ s), collisions and, at high
    concentration, a contact-force network. Because of Coriolis the drift
    turns to the right of the wind: the agent has to learn the Ekman-like
    turning and to avoid pressure build-ups.

    ## Action Space
    `Box(-1, 1, (2,), float32)`: the wind vector (u_a,x, u_a,y) in units of
    {MAX_WIND:g} m/s. NaN/inf entries are set to 0 and entries clipped.

    ## Observation Space
    `Box(float32)` of {len(FLOE_FEATURES) + len(_EXTRA) + 2} entries: the common floe
    features, the target heading and the last action:

{feature_table(FLOE_FEATURES + _EXTRA)}
    | {len(FLOE_FEATURES) + len(_EXTRA)}, {len(FLOE_FEATURES) + len(_EXTRA) + 1} | `action` | the last action | - | none | [-1, 1] |

    `info["physics"]` holds the same quantities unscaled, in SI units.

    ## Rewards
    :func:`iceenvs.rewards.wind_drift_reward`: along-heading mean ice
    velocity / 0.1 m/s − (relative excess of the pressure over
    `pressure_max`, default 2000 N/m) − 0.01 |action|².

    ## Starting State
    Floes placed at random without overlap at concentration `concentration`
    (seeded by `reset(seed=...)`), at rest, no wind. Option `heading` [rad]
    (default 0: along +x).

    ## Episode End
    Truncated after `episode_steps` steps (default 200 × 5 s = 1000 s).
    Terminated only when the physics fails (`info["error"]`).

    ## Arguments
    `n_floes=200`, `concentration=0.8`, `preset=HERMAN2013`,
    `control_interval=5.0` [s], `episode_steps=200`, `reward_fn`,
    `reward_params` (`pressure_max`, `speed_scale`, `pressure_weight`,
    `action_weight`), `stiffness_scale=1.0` (< 1: softer contacts and a
    longer time step, faster), `cluster_gap=0.1` [m], `render_mode`.

    ## Version History
    * v0: initial version.
    """

    action_space = gym.spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)
    action_names = ("wind_x", "wind_y")
    extra_features = _EXTRA
    reward_fn = staticmethod(wind_drift_reward)

    def __init__(self, n_floes: int = 200, concentration: float = 0.8,
                 preset=HERMAN2013, control_interval: float = 5.0, episode_steps: int = 200,
                 **kwargs):
        super().__init__(n_floes=n_floes, concentration=concentration, preset=preset,
                         control_interval=control_interval, episode_steps=episode_steps,
                         **kwargs)
        self.heading = 0.0

    def default_reward_params(self) -> dict:
        return dict(heading=0.0, pressure_max=2000.0, speed_scale=0.1, pressure_weight=1.0,
                    action_weight=0.01)

    def _reset_options(self, options: dict) -> None:
        heading = options.pop("heading", 0.0)
        if not math.isfinite(float(heading)):
            raise ValueError(f"heading must be a finite angle [rad], got {heading!r}")
        super()._reset_options(options)
        self.heading = float(heading)
        self.reward_params["heading"] = self.heading

    def _make_sim(self, rng, options):
        p = self.preset
        field, box = make_floe_field(self.n_floes, concentration=self.concentration,
                                     alpha=p.fsd_exponent, mean_diameter=p.mean_diameter,
                                     thickness=p.thickness,
                                     density=p.forcing.ice_density,
                                     seed=int(rng.integers(2 ** 63)))
        self.forcing = Forcing(p.forcing, wind=(0.0, 0.0))
        return self._hertz_sim(field, box, self.forcing)

    def _apply_action(self, action):
        self.forcing.wind = MAX_WIND * action

    def _measure(self) -> dict:
        now = self._contact_physics()
        now["heading_cos"] = math.cos(self.heading)
        now["heading_sin"] = math.sin(self.heading)
        return now
