"""Reward functions of the environments, one per task.

Every reward is a pure function ``reward(prev, action, now, **params)`` of
the previous and current *physical* observations (dicts of SI values, as
in ``info["physics"]``; see :mod:`iceenvs.observations`), the action the
agent took (after clipping, in the env's normalised action space) and the
task's parameters. An environment calls its reward as
``reward_fn(prev, action, now, **env.reward_params, **task)``, where
``task`` holds the episode's target (or heading); pass your own function
with that signature as ``reward_fn=`` to study another task.

Every built-in reward of the ice-control tasks lies in [0, 1] each step:
a score of how well the task is done (1: exactly on target) times a
safety factor that falls from 1 to 0 as a stress passes its limit and
reaches twice the limit (:func:`safety`). A failed episode ends with
reward 0 (the failed state is absorbing and worth nothing), so no reward
is ever negative and ending an episode early never pays.

The ship tasks reward progress towards a goal line, so their rewards are
signed: progress over the step (the distance gained over the distance
the fastest ship sails in a step, in [−1, 1]), minus penalties that are
each bounded (the ice impulse or the hull pressure, a time cost, leaving
the channel), plus a bonus on the step that reaches the goal. A failure
(beset, a physics failure, leaving a walled channel) ends the episode
with −``failure_penalty``, below any sum of penalties a step can carry, so
that ending early never pays there either. :func:`ship_reward_bounds`
gives the bounds of one step. Their functions also take columns, dicts of
arrays with one entry per sub-environment, as the native vector
environments pass them (:class:`iceenvs.step.Episodes`).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["excess", "safety", "closeness", "wind_drift_reward", "convergence_reward",
           "marginal_ice_zone_reward", "floe_clustering_reward", "wasserstein1",
           "cumulative_fractions", "wasserstein1_to",
           "thickness_distribution_reward", "ship_navigation_reward", "ship_beset_reward",
           "ship_progress", "ship_reward_bounds"]


def excess(value: float, threshold: float) -> float:
    """How far ``value`` is above ``threshold``, relative to it (0 below);
    elementwise for arrays."""
    return np.maximum(0.0, value / threshold - 1.0)


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
    return wasserstein1_to(g, cumulative_fractions(g_target),
                           np.diff(np.asarray(h, dtype=float)))


def cumulative_fractions(g) -> np.ndarray:
    """The cumulative fractions G of the distribution ``g`` (normalised)."""
    g = np.asarray(g, dtype=float)
    return np.cumsum(g / g.sum())


def wasserstein1_to(g, target_cumulative: np.ndarray, dh: np.ndarray) -> float:
    """:func:`wasserstein1` of ``g`` to a target given by its cumulative
    fractions (:func:`cumulative_fractions`) on classes of widths ``dh``
    (``np.diff(h)``): the same numbers, for a target used step after step."""
    diff = np.abs(cumulative_fractions(g) - target_cumulative)[:-1]
    return float(np.sum(diff * dh))


def thickness_distribution_reward(prev, action, now, *, target, h,
                                  distance_scale: float = 1.0) -> float:
    """1 − W1(g, g*) / ``distance_scale`` [m], clipped to [0, 1]: the
    thickness distribution ``now["g"]`` kept close to ``target`` on the
    class thicknesses ``h``."""
    return closeness(wasserstein1(now["g"], target, h), 0.0, distance_scale)


# -- the ship tasks -------------------------------------------------------------------------

def ship_progress(prev, now, step_length: float) -> float:
    """Distance gained towards the goal line over the step,
    (d_prev − d_now) / ``step_length`` [m], clipped to [−1, 1]."""
    gained = (prev["goal_distance"] - now["goal_distance"]) / step_length
    return np.minimum(1.0, np.maximum(-1.0, gained))


def ship_navigation_reward(prev, action, now, *, step_length: float,
                           impulse_weight: float = 1.0, impulse_scale: float = 1.0e6,
                           time_weight: float = 0.05, exit_weight: float = 1.0,
                           goal_bonus: float = 10.0, failure_penalty: float = 10.0,
                           impulse_cap: float = 2.0) -> float:
    """:func:`ship_progress` − ``impulse_weight`` × min(J / ``impulse_scale``,
    ``impulse_cap``) − ``time_weight`` − ``exit_weight`` (outside the
    channel) + ``goal_bonus`` (goal line reached).

    J [N s] is the impulse of the ice on the hull over the step
    (``now["step_impulse"]``, the time integral of the ice force's
    magnitude); 10⁶ N s is about a head-on hit on a 20 m floe of 1.5 m ice at
    2 m/s. ``step_length`` [m] is the distance the fastest ship of the
    action set-up sails in a step. ``failure_penalty`` is the environment's
    (a failed step's reward is −failure_penalty)."""
    impact = np.minimum(now["step_impulse"] / impulse_scale, impulse_cap)
    outside = np.abs(now["channel_offset"]) > 1.0
    return (ship_progress(prev, now, step_length) - impulse_weight * impact - time_weight
            - exit_weight * outside + goal_bonus * now["reached"])


def ship_beset_reward(prev, action, now, *, step_length: float, pressure_limit: float,
                      pressure_weight: float = 1.0, time_weight: float = 0.05,
                      goal_bonus: float = 10.0, failure_penalty: float = 10.0) -> float:
    """:func:`ship_progress` − ``pressure_weight`` × min(:func:`excess` of the
    hull pressure over ``pressure_limit`` [N/m], 1) − ``time_weight`` +
    ``goal_bonus`` (goal line reached). The hull pressure
    (``now["hull_pressure"]``) is the sum of the normal contact forces on the
    hull over its length, mean over the step; the penalty grows from 0
    at the limit to its full weight at twice the limit."""
    over = np.minimum(excess(now["hull_pressure"], pressure_limit), 1.0)
    return (ship_progress(prev, now, step_length) - pressure_weight * over - time_weight
            + goal_bonus * now["reached"])


def ship_reward_bounds(params: dict) -> tuple[float, float]:
    """(lowest, highest) reward of one step of a ship task with these reward
    parameters (its ``env.reward_params``), a failure included."""
    low = -1.0 - params.get("time_weight", 0.0) \
        - params.get("impulse_cap", 2.0) * params.get("impulse_weight", 0.0) \
        - params.get("exit_weight", 0.0) - params.get("pressure_weight", 0.0)
    return (min(low, -params["failure_penalty"]), 1.0 + params.get("goal_bonus", 0.0))
