"""Reward functions of the environments, one per task.

Every reward is a pure function ``reward(prev, action, now, **params)`` of
the previous and current *physical* observations (dicts of SI values, as
in ``info["physics"]``; see :mod:`iceenvs.observations`), the action the
agent took (after clipping, in the env's normalised action space) and the
task's parameters. An environment calls its reward as
``reward_fn(prev, action, now, **env.reward_params, **task)``, where
``task`` holds the episode's target (or heading); pass your own function
with that signature as ``reward_fn=`` to study another task.

Every built-in reward lies in [0, 1] each step: a score of how well the
task is done (1: exactly on target) times a safety factor that falls
from 1 to 0 as a stress passes its limit and reaches twice the limit
(:func:`safety`). A failed episode ends with reward 0 (the failed state is
absorbing and worth nothing), so no reward is ever negative and ending an
episode early never pays.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["excess", "safety", "closeness", "wind_drift_reward", "convergence_reward",
           "marginal_ice_zone_reward", "floe_clustering_reward", "wasserstein1",
           "thickness_distribution_reward"]


def excess(value: float, threshold: float) -> float:
    """How far ``value`` is above ``threshold``, relative to it (0 below)."""
    return max(0.0, value / threshold - 1.0)


def safety(value: float, threshold: float, weight: float = 1.0) -> float:
    """1 − ``weight`` × :func:`excess`, clipped to [0, 1]: 1 up to the
    threshold, 0 from (1 + 1/weight) × threshold on."""
    return min(1.0, max(0.0, 1.0 - weight * excess(value, threshold)))


def closeness(value: float, target: float, scale: float) -> float:
    """1 − |value − target| / scale, clipped to [0, 1]."""
    return min(1.0, max(0.0, 1.0 - abs(value - target) / scale))


def wind_drift_reward(prev, action, now, *, heading: float, pressure_max: float,
                      speed_scale: float = 1.0, pressure_weight: float = 1.0) -> float:
    """(1 + u_h / ``speed_scale``)/2, clipped to [0, 1], times
    :func:`safety` of the pressure against ``pressure_max`` [N/m].

    u_h [m/s] is the mean ice velocity along ``heading`` [rad, from the x
    axis]: 0.5 for ice at rest, 1 for ice moving along the heading at
    ``speed_scale`` or faster, 0 for ice moving the opposite way.
    """
    along = now["u_x"] * math.cos(heading) + now["u_y"] * math.sin(heading)
    score = min(1.0, max(0.0, 0.5 * (1.0 + along / speed_scale)))
    return score * safety(now["pressure"], pressure_max, pressure_weight)


def convergence_reward(prev, action, now, *, target: float, pressure_max: float,
                       concentration_scale: float = 0.1,
                       pressure_weight: float = 1.0) -> float:
    """:func:`closeness` of the concentration A to ``target`` (1 at A = A*,
    0 at |A − A*| >= ``concentration_scale``) times :func:`safety` of the
    pressure against ``pressure_max`` [N/m]."""
    return (closeness(now["concentration"], target, concentration_scale)
            * safety(now["pressure"], pressure_max, pressure_weight))


def marginal_ice_zone_reward(prev, action, now, *, target_speed: float,
                             edge_stress_max: float, speed_scale: float = 0.05,
                             stress_weight: float = 1.0) -> float:
    """:func:`closeness` of the along-edge transport (mean u_x of the mobile
    floes [m/s]) to ``target_speed`` (0 at ``speed_scale`` off) times
    :func:`safety` of the stress on the fast-ice edge
    (``now["edge_stress"]`` [N/m]) against ``edge_stress_max``."""
    return (closeness(now["u_x"], target_speed, speed_scale)
            * safety(now["edge_stress"], edge_stress_max, stress_weight))


def floe_clustering_reward(prev, action, now, *, target: float,
                           fraction_scale: float = 0.25) -> float:
    """:func:`closeness` of the largest-cluster fraction F_c,1/F_tot to
    ``target`` (0 at ``fraction_scale`` off)."""
    return closeness(now["largest_cluster"], target, fraction_scale)


def wasserstein1(g, g_target, h) -> float:
    """Wasserstein-1 distance [m] between two thickness distributions on the
    class thicknesses ``h`` (open water h = 0 first): ∫ |G(h) − G*(h)| dh
    with G the cumulative fractions."""
    g = np.asarray(g, dtype=float)
    t = np.asarray(g_target, dtype=float)
    h = np.asarray(h, dtype=float)
    diff = np.abs(np.cumsum(g / g.sum()) - np.cumsum(t / t.sum()))[:-1]
    return float(np.sum(diff * np.diff(h)))


def thickness_distribution_reward(prev, action, now, *, target, h,
                                  distance_scale: float = 1.0) -> float:
    """1 − W1(g, g*) / ``distance_scale`` [m], clipped to [0, 1]: the
    thickness distribution ``now["g"]`` kept close to ``target`` on the
    class thicknesses ``h``."""
    return closeness(wasserstein1(now["g"], target, h), 0.0, distance_scale)
