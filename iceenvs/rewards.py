"""Reward functions of the environments, one per task.

Every reward is a pure function ``reward(prev, action, now, **params)`` of
the previous and current *physical* observations (dicts of SI values, as
in ``info["physics"]``; see :mod:`iceenvs.observations`), the action the
agent took (after clipping, in the env's normalised action space) and the
task parameters. An environment calls its reward as
``reward_fn(prev, action, now, **env.reward_params)``; pass your own
function with that signature as ``reward_fn=`` to study another task.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["excess", "wind_drift_reward", "convergence_reward", "marginal_ice_zone_reward",
           "floe_clustering_reward", "wasserstein1", "thickness_distribution_reward"]


def excess(value: float, threshold: float) -> float:
    """How far ``value`` is above ``threshold``, relative to it (0 below)."""
    return max(0.0, value / threshold - 1.0)


def wind_drift_reward(prev, action, now, *, heading: float, pressure_max: float,
                      speed_scale: float = 0.1, pressure_weight: float = 1.0,
                      action_weight: float = 0.01) -> float:
    """Along-heading mean ice velocity (in units of ``speed_scale`` [m/s])
    − ``pressure_weight`` × relative excess of the pressure over
    ``pressure_max`` [N/m] − ``action_weight`` × |action|².

    ``heading`` [rad] is the target direction of motion, from the x axis.
    """
    along = now["u_x"] * math.cos(heading) + now["u_y"] * math.sin(heading)
    a2 = float(np.sum(np.square(action)))
    return (along / speed_scale - pressure_weight * excess(now["pressure"], pressure_max)
            - action_weight * a2)


def convergence_reward(prev, action, now, *, target: float, pressure_max: float,
                       concentration_scale: float = 0.01,
                       pressure_weight: float = 1.0) -> float:
    """−|A − A*| (in units of ``concentration_scale``) − ``pressure_weight``
    × relative excess of the pressure over ``pressure_max`` [N/m]."""
    return (-abs(now["concentration"] - target) / concentration_scale
            - pressure_weight * excess(now["pressure"], pressure_max))


def marginal_ice_zone_reward(prev, action, now, *, edge_stress_max: float,
                             speed_scale: float = 0.1, stress_weight: float = 1.0,
                             action_weight: float = 0.01) -> float:
    """Along-edge ice transport (mean u_x of the mobile floes over
    ``speed_scale``) − ``stress_weight`` × relative excess of the stress on
    the fast-ice edge (``now["edge_stress"]`` [N/m]) over
    ``edge_stress_max`` − ``action_weight`` × |action|²."""
    a2 = float(np.sum(np.square(action)))
    return (now["u_x"] / speed_scale - stress_weight * excess(now["edge_stress"], edge_stress_max)
            - action_weight * a2)


def floe_clustering_reward(prev, action, now, *, target: float) -> float:
    """−|F_c,1/F_tot − target|: the largest-cluster fraction held at ``target``."""
    return -abs(now["largest_cluster"] - target)


def wasserstein1(g, g_target, h) -> float:
    """Wasserstein-1 distance [m] between two thickness distributions on the
    class thicknesses ``h`` (open water h = 0 first): ∫ |G(h) − G*(h)| dh
    with G the cumulative fractions."""
    g = np.asarray(g, dtype=float)
    t = np.asarray(g_target, dtype=float)
    h = np.asarray(h, dtype=float)
    diff = np.abs(np.cumsum(g / g.sum()) - np.cumsum(t / t.sum()))[:-1]
    return float(np.sum(diff * np.diff(h)))


def thickness_distribution_reward(prev, action, now, *, target, h) -> float:
    """−W1(g, g*) [m]: the thickness distribution ``now["g"]`` kept close to
    ``target`` on the class thicknesses ``h``."""
    return -wasserstein1(now["g"], target, h)
