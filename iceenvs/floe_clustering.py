"""``iceenvs/FloeClustering-v0``: herd hard-disc floes to a target largest-cluster fraction."""
from __future__ import annotations

import gymnasium as gym
import numpy as np

from physics import Forcing, HERMAN2011, make_floe_field
from physics.params import check_range

from .base import FloeEnv
from .observations import FLOE_FEATURES, Feature, feature_table, floe_physics
from .rewards import floe_clustering_reward

__all__ = ["FloeClusteringEnv"]

MAX_WIND = 20.0   # m/s per component at |action| = 1

_EXTRA = (
    Feature("target", "target largest-cluster fraction", "-", "none", 0.0, 1.0),
    Feature("collision_rate", "collisions per floe per second over the last interval",
            "1/s", "log rate", 0.0, 10.0),
)


class FloeClusteringEnv(FloeEnv):
    __doc__ = f"""Herd floes with the wind until the largest cluster holds a target
    fraction of the ice.

    ## Description
    The Small Floe Collider of Herman (2011): hard-disc floes with a
    power-law size distribution (α_r = 1.5, mean diameter 2 m, thickness
    1.5 m) drifting under wind and a weak current through drag in Stokes
    form (each floe relaxes to its own free-drift velocity, so floes of
    different sizes move differently and collide), with inelastic
    collisions (ε = 0.85) in a periodic box. Clusters are sets of floes
    closer than `cluster_gap` (default 0.1 m; with 0.5 m nearly all floes of
    the random start at Ā = 0.7 form one cluster) edge to edge. Strong steady
    wind makes floes of different sizes drift apart and collide, building
    large clusters at high concentration; changing the wind breaks them.

    ## Action Space
    `Box(-1, 1, (2,), float32)`: the wind vector in units of {MAX_WIND:g} m/s.

    ## Observation Space
    `Box(float32)` of {len(FLOE_FEATURES) + len(_EXTRA) + 2} entries. Contacts are pairs
    closer than 1 cm (hard discs touch only at collisions), the stress is
    the kinetic plus collision-virial stress averaged over the last control
    interval:

{feature_table(FLOE_FEATURES + _EXTRA)}
    | {len(FLOE_FEATURES) + len(_EXTRA)}, {len(FLOE_FEATURES) + len(_EXTRA) + 1} | `action` | the last action | - | none | [-1, 1] |

    ## Rewards
    :func:`iceenvs.rewards.floe_clustering_reward`: −|F_c,1/F_tot − target|.

    ## Starting State
    Floes placed at random without overlap (seeded) at `concentration`,
    with Gaussian velocities of 1 cm/s. Option `target` (default 0.5).

    ## Episode End
    Truncated after `episode_steps` (default 400 × 5 s); terminated only on
    a physics failure (`info["error"]`).

    ## Arguments
    `n_floes=300`, `concentration=0.7`, `preset=HERMAN2011`,
    `control_interval=5.0` [s], `episode_steps=400`, `cluster_gap=0.1`
    [m], `reward_fn`, `reward_params` (`target`), `render_mode`.

    ## Version History
    * v0: initial version.
    """

    action_space = gym.spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)
    action_names = ("wind_x", "wind_y")
    extra_features = _EXTRA
    reward_fn = staticmethod(floe_clustering_reward)

    def __init__(self, n_floes: int = 300, concentration: float = 0.7, preset=HERMAN2011,
                 control_interval: float = 5.0, episode_steps: int = 400,
                 cluster_gap: float = 0.1, **kwargs):
        if kwargs.get("stiffness_scale", 1.0) != 1.0:
            raise ValueError("stiffness_scale has no meaning for hard discs")
        super().__init__(n_floes=n_floes, concentration=concentration, preset=preset,
                         control_interval=control_interval, episode_steps=episode_steps,
                         cluster_gap=cluster_gap, **kwargs)
        self.target = 0.5

    def default_reward_params(self) -> dict:
        return dict(target=0.5)

    def _reset_options(self, options: dict) -> None:
        target = options.pop("target", 0.5)
        check_range("target", target, 0.0, 1.0)
        super()._reset_options(options)
        self.target = float(target)
        self.reward_params["target"] = self.target

    def _make_sim(self, rng, options):
        from physics import HardDiskSimulation

        p = self.preset
        field, box = make_floe_field(self.n_floes, concentration=self.concentration,
                                     alpha=p.fsd_exponent, mean_diameter=p.mean_diameter,
                                     thickness=p.thickness, density=p.forcing.ice_density,
                                     seed=int(rng.integers(2 ** 63)), velocity_std=0.01)
        self.forcing = Forcing(p.forcing, wind=(0.0, 0.0), coriolis=0.0)
        sim = HardDiskSimulation(field, box, restitution=p.contact.restitution,
                                 forcing=self.forcing, max_velocity_step=p.max_velocity_step,
                                 collision_duration=p.collision_duration)
        self._window = (0.0, 0)
        return sim

    def _apply_action(self, action):
        self.forcing.wind = MAX_WIND * action

    def _advance(self) -> None:
        self.sim.reset_stress()
        self._window = (self.sim.time, self.sim.collision_count)
        self.sim.advance(self.control_interval)

    def _measure(self) -> dict:
        sim = self.sim
        t0, c0 = self._window
        span = sim.time - t0
        tensor = sim.stress() if span > 0 else np.zeros((2, 2))
        self._contacts = sim.contacts(0.01)
        mobile = ~sim.field.frozen
        now = floe_physics(sim.positions, sim.velocities, sim.mass, sim.radius, sim.box,
                           self._contacts, tensor, sim.box.area, mobile,
                           cluster_gap=self.cluster_gap)
        now["target"] = self.target
        now["collision_rate"] = (sim.collision_count - c0) / sim.n / span if span > 0 else 0.0
        return now

    def _frame(self) -> np.ndarray:
        from .rendering import draw_floes

        sim = self.sim
        v = sim.velocities
        return draw_floes(sim.positions, sim.radius, (sim.box.lx, sim.box.ly),
                          np.hypot(v[:, 0], v[:, 1]))
