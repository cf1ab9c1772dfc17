"""The physics metrics of each environment that training logs and
evaluation reports: which entries of ``info["physics"]`` to take and the
name each is logged under.

The floe environments share the observables of
:mod:`iceenvs.observations` (SI units: pressure [N/m], velocities [m/s],
fractions without unit); each task adds its own entries (edge stress,
collision rate, thickness distribution). Only scalar entries are taken.
"""
from __future__ import annotations

import math

from iceenvs.ship_env import METRICS as SHIP_METRICS

__all__ = ["PHYSICS_METRICS", "EPISODE_METRICS", "MAIN_METRIC", "env_name", "metric_names", "physics_metrics"]

#: per env name: ``{key of info["physics"]: logged name}``
PHYSICS_METRICS: dict[str, dict[str, str]] = {
    "WindDrift-v0": {"u_heading": "u_heading", "u_x": "u_x", "u_y": "u_y",
                     "pressure": "pressure",
                     "z_c": "Z_c", "largest_cluster": "largest_cluster_fraction",
                     "temperature": "granular_temperature"},
    "Convergence-v0": {"concentration": "concentration", "target": "target",
                       "pressure": "pressure",
                       "z_c": "Z_c", "f_nr": "non_rattler_fraction",
                       "largest_cluster": "largest_cluster_fraction"},
    "MarginalIceZone-v0": {"u_x": "u_x", "target_speed": "target_speed",
                           "edge_stress": "edge_stress",
                           "edge_u_x": "edge_u_x", "pressure": "pressure", "z_c": "Z_c",
                           "largest_cluster": "largest_cluster_fraction"},
    "FloeClustering-v0": {"largest_cluster": "largest_cluster_fraction", "target": "target",
                          "clusters_per_floe": "clusters_per_floe",
                          "cluster_alpha": "cluster_alpha",
                          "collision_rate": "collision_rate", "pressure": "pressure"},
    "ThicknessDistribution-v0": {"w1": "wasserstein1", "open_water": "open_water",
                                 "mean_thickness": "mean_thickness",
                                 "kernel_scale": "kernel_scale",
                                 "rafting_factor": "rafting_factor"},
    "ShipNavigation-v0": {"goal_distance": "goal_distance", "surge": "surge",
                          "step_impulse": "step_impulse", "hull_pressure": "hull_pressure",
                          "concentration": "concentration"},
    "ShipBeset-v0": {"goal_distance": "goal_distance", "surge": "surge",
                     "hull_pressure": "hull_pressure", "pressure_limit": "pressure_limit",
                     "step_impulse": "step_impulse", "concentration": "concentration"},
}

#: per env name: the episode metrics of ``info`` (top level, the episode so
#: far) logged with the physics
EPISODE_METRICS: dict[str, tuple[str, ...]] = {"ShipNavigation-v0": SHIP_METRICS,
                                               "ShipBeset-v0": SHIP_METRICS}

#: per env name: the logged name of the metric that says most about the task
MAIN_METRIC: dict[str, str] = {
    "WindDrift-v0": "u_heading",
    "Convergence-v0": "concentration",
    "MarginalIceZone-v0": "u_x",
    "FloeClustering-v0": "largest_cluster_fraction",
    "ThicknessDistribution-v0": "wasserstein1",
    "ShipNavigation-v0": "step_impulse",
    "ShipBeset-v0": "hull_pressure",
}


def env_name(env_id: str) -> str:
    """``"iceenvs/Convergence-v0"`` → ``"Convergence-v0"``."""
    return env_id.split("/")[-1]


def metric_names(env_id: str) -> dict[str, str] | None:
    """The ``{physics key: logged name}`` map of an env id (``None``: every
    scalar entry under its own name)."""
    return PHYSICS_METRICS.get(env_name(env_id))


def physics_metrics(env_id: str, info: dict) -> dict[str, float]:
    """The logged metrics of one ``info`` dict: the mapped scalar entries of
    ``info["physics"]`` (all finite scalar entries for an env without a
    map); empty when the info holds no physics."""
    physics = info.get("physics")
    if not physics:
        return {}
    names = metric_names(env_id)
    if names is None:
        names = {k: k for k, v in physics.items() if isinstance(v, (int, float))}
    out = {}
    for key, name in names.items():
        if key in physics:
            value = float(physics[key])
            out[name] = value if math.isfinite(value) else float("nan")
    # the ship environments' episode metrics (success, path length, impulses...)
    for key in EPISODE_METRICS.get(env_name(env_id), ()):
        if key in info:
            value = float(info[key])
            out[key] = value if math.isfinite(value) else float("nan")
    return out
