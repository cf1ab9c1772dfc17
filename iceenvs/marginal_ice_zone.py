"""``iceenvs/MarginalIceZone-v0``: move ice along a fast-ice edge without loading the edge."""
from __future__ import annotations

import math

import gymnasium as gym
import numpy as np

from physics import ChannelBox, FloeField, Forcing, HERMAN2013, make_floe_field
from physics.params import check_range

from .base import HertzEnv
from .observations import FLOE_FEATURES, Feature, feature_table
from .rewards import marginal_ice_zone_reward

__all__ = ["MarginalIceZoneEnv"]

MAX_WIND = 20.0   # m/s at action[0] = 1

_EXTRA = (
    Feature("edge_stress", "force of the drifting floes on the fast ice per edge length, "
            "|Σ F| / L_x", "N/m", "log stress", -8.0, 8.0),
    Feature("edge_u_x", "mean u_x of the floes in the lowest quarter of the drifting ice", "m/s",
            "/ 1 m/s", -5.0, 5.0),
)


class MarginalIceZoneEnv(HertzEnv):
    __doc__ = f"""Maximise ice transport along a fast-ice edge while keeping the
    stress on the edge low.

    ## Description
    Experiment 3 of Herman (2013): floes along the lower boundary are
    frozen (a fast-ice edge: they never move but take part in contacts),
    the left and right sides are periodic and a rigid wall closes the top.
    The agent sets wind speed and direction. Wind towards the edge presses
    the ice against it (large edge stress, a jammed band and a narrow shear
    zone), wind away from it opens the ice; the best transport with little
    edge stress is in between.

    ## Action Space
    `Box(-1, 1, (2,), float32)`: action[0] → wind speed {MAX_WIND:g} (a + 1)/2 m/s
    (0 to {MAX_WIND:g} m/s), action[1] → wind direction π a [rad] from +x
    (±π: along −x; −π/2: towards the edge).

    ## Observation Space
    `Box(float32)` of {len(FLOE_FEATURES) + len(_EXTRA) + 2} entries: the common floe
    features (over all floes, frozen ones included for contacts, mobile
    ones for velocities), the edge entries and the last action:

{feature_table(FLOE_FEATURES + _EXTRA)}
    | {len(FLOE_FEATURES) + len(_EXTRA)}, {len(FLOE_FEATURES) + len(_EXTRA) + 1} | `action` | the last action | - | none | [-1, 1] |

    ## Rewards
    :func:`iceenvs.rewards.marginal_ice_zone_reward`: mean u_x of the
    mobile floes / 0.1 m/s − (relative excess of the edge stress over
    `edge_stress_max`, default 500 N/m) − 0.01 |action|².

    ## Starting State
    Floes placed at random (seeded) in a channel of aspect 2 (x : y = 2 : 1)
    at `concentration`; floes whose centres lie within `edge_width` of the
    bottom are frozen. All at rest, no wind.

    ## Episode End
    Truncated after `episode_steps` (default 200 × 5 s); terminated only on
    a physics failure (`info["error"]`).

    ## Arguments
    `n_floes=200`, `concentration=0.75`, `preset=HERMAN2013`,
    `control_interval=5.0` [s], `episode_steps=200`, `edge_width=10.0`
    [m], `reward_fn`, `reward_params` (`edge_stress_max`, `speed_scale`,
    `stress_weight`, `action_weight`), `stiffness_scale`, `cluster_gap`,
    `render_mode`.

    ## Version History
    * v0: initial version.
    """

    action_space = gym.spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)
    action_names = ("wind_speed", "wind_direction")
    extra_features = _EXTRA
    reward_fn = staticmethod(marginal_ice_zone_reward)

    def __init__(self, n_floes: int = 200, concentration: float = 0.75, preset=HERMAN2013,
                 control_interval: float = 5.0, episode_steps: int = 200,
                 edge_width: float = 10.0, **kwargs):
        check_range("edge_width", edge_width, 0.0, None, low_open=True)
        super().__init__(n_floes=n_floes, concentration=concentration, preset=preset,
                         control_interval=control_interval, episode_steps=episode_steps,
                         **kwargs)
        self.edge_width = float(edge_width)

    def default_reward_params(self) -> dict:
        return dict(edge_stress_max=500.0, speed_scale=0.1, stress_weight=1.0,
                    action_weight=0.01)

    def _make_sim(self, rng, options):
        p = self.preset
        field, box = make_floe_field(self.n_floes, concentration=self.concentration,
                                     alpha=p.fsd_exponent, mean_diameter=p.mean_diameter,
                                     thickness=p.thickness, density=p.forcing.ice_density,
                                     seed=int(rng.integers(2 ** 63)), aspect=0.5,
                                     box_type=ChannelBox)
        frozen = field.positions[:, 1] < self.edge_width
        if frozen.all() or not frozen.any():
            raise ValueError(f"edge_width={self.edge_width:g} m freezes "
                             f"{int(frozen.sum())} of {field.n} floes; choose it so that some "
                             f"but not all floes are frozen")
        field = FloeField(field.positions, field.radii, field.thickness, field.velocities,
                          density=field.density, frozen=frozen)
        self.forcing = Forcing(p.forcing, wind=(0.0, 0.0))
        return self._hertz_sim(field, box, self.forcing)

    def _apply_action(self, action):
        speed = MAX_WIND * 0.5 * (float(action[0]) + 1.0)
        angle = math.pi * float(action[1])
        self.forcing.wind = (speed * math.cos(angle), speed * math.sin(angle))

    def _measure(self) -> dict:
        now = self._contact_physics()
        sim = self.sim
        c = self._contacts
        frozen = sim.inv_mass == 0
        fi, fj = frozen[c.i], frozen[c.j]
        on_edge = (c.force * fi[:, None]).sum(axis=0) - (c.force * fj[:, None]).sum(axis=0)
        # only drifting floes pushing on the edge count (frozen pairs carry no force)
        now["edge_stress"] = float(math.hypot(*on_edge) / sim.box.lx)
        mobile = ~frozen
        y = sim.positions[:, 1]
        y0 = self.edge_width
        band = mobile & (y < y0 + 0.25 * (sim.box.ly - y0))
        now["edge_u_x"] = float(sim.velocities[band, 0].mean()) if band.any() else 0.0
        return now

