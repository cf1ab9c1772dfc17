"""The physics metrics of each environment that training logs and
evaluation reports, and how they are shown to people.

Which entries of ``info["physics"]`` each task logs, under which names, and
its main metric are facts of the environment (:class:`iceenvs.facts.EnvFacts`);
this module reads them. The floe environments share the observables of
:mod:`iceenvs.observations` (SI units: pressure [N/m], velocities [m/s],
fractions without unit); each task adds its own entries (edge stress,
collision rate, thickness distribution). Only scalar entries are taken.

Every logged metric is recorded in SI (``evaluation.json``, the
leaderboard's JSON). Tables and plots show it as :data:`METRIC_UNITS` says:
a readable header, the display unit and the scale (the displayed value is
the SI value over the scale: an impulse per metre of 19 950 N s/m shows as
19.95 kN s/m). A metric not in the table keeps its name and its SI value.

>>> metric_header("impulse_per_metre")
'ice impulse per metre [kN s/m]'
>>> scaled("impulse_per_metre", 19950.0)
19.95
>>> format_pm(143.62, 2.08)
'143.6 ± 2.1'
"""
from __future__ import annotations

import math
from typing import NamedTuple

from iceenvs.facts import env_facts

__all__ = ["env_name", "physics_metrics", "MetricUnit", "METRIC_UNITS", "HEADLINE",
           "LAST_STEP", "TARGET_METRICS", "metric_unit", "metric_header", "scaled",
           "significant", "format_pm", "logged_names"]


class MetricUnit(NamedTuple):
    """How a quantity is shown: ``header`` (words), ``unit`` (the display
    unit, empty for fractions, counts and other numbers without unit),
    ``scale`` (the display unit in SI: shown value = SI value / scale) and
    ``si`` (the SI unit the environments log it in)."""
    header: str
    unit: str = ""
    scale: float = 1.0
    si: str = ""


def _m(header: str, si: str = "", shown: str | None = None, scale: float = 1.0) -> MetricUnit:
    """A quantity logged in ``si``, shown in ``shown`` (default: ``si``)."""
    return MetricUnit(header, si if shown is None else shown, scale, si)


#: every metric the environments log (and the task parameters they draw per
#: episode), by logged name; the SI unit of each is documented where the
#: environment measures it (:mod:`iceenvs.observations`,
#: :mod:`iceenvs.ship_env`, the task modules)
METRIC_UNITS: dict[str, MetricUnit] = {
    # the episode
    "return": _m("return"),
    "length": _m("steps"),
    # the floe environments (iceenvs.observations and the tasks' own entries)
    "concentration": _m("ice concentration"),
    "target": _m("target"),                # of the main metric: A* or F_c,1/F_tot
    "pressure": _m("ice pressure", "N/m"),
    "Z_c": _m("contacts per non-rattler Z_c"),
    "non_rattler_fraction": _m("non-rattler fraction"),
    "largest_cluster_fraction": _m("largest cluster (fraction of the ice)"),
    "granular_temperature": _m("granular temperature", "m²/s²", "mm²/s²", 1e-6),
    "u_heading": _m("ice velocity along the heading", "m/s"),
    "u_x": _m("ice velocity u_x", "m/s"),
    "u_y": _m("ice velocity u_y", "m/s"),
    "target_speed": _m("target transport u*", "m/s"),
    "edge_stress": _m("edge stress", "N/m"),
    "edge_u_x": _m("u_x at the edge", "m/s"),
    "clusters_per_floe": _m("clusters per floe"),
    "cluster_alpha": _m("cluster-size exponent α"),
    "collision_rate": _m("collisions per floe and second", "1/s"),
    # the thickness distribution
    "wasserstein1": _m("W1 distance to the target g(h)", "m"),
    "open_water": _m("open-water fraction"),
    "mean_thickness": _m("mean ice thickness", "m"),
    "kernel_scale": _m("redistribution kernel scale"),
    "rafting_factor": _m("rafting factor"),
    # the ship environments: the last step's loads and pose (iceenvs.ship_env)
    "goal_distance": _m("distance to the goal line", "m"),
    "surge": _m("surge speed", "m/s"),
    "step_impulse": _m("ice impulse in the step", "N s", "kN s", 1e3),
    "hull_pressure": _m("hull pressure", "N/m", "kN/m", 1e3),
    "pressure_limit": _m("hull pressure limit", "N/m", "kN/m", 1e3),
    # ... and the episode's metrics (iceenvs.ship_measures.METRICS)
    "success": _m("success", "", "%", 1e-2),
    "time": _m("time", "s"),
    "path_length": _m("path", "m"),
    "efficiency": _m("efficiency"),
    "effort": _m("effort (work of the thrust, or against ice and water)", "J", "MJ", 1e6),
    "collisions": _m("collisions"),
    "collided_floes": _m("floes hit"),
    "mean_impulse": _m("mean impulse", "N s", "kN s", 1e3),
    "max_impulse": _m("max impulse", "N s", "MN s", 1e6),
    "impulse_per_metre": _m("ice impulse per metre", "N s/m", "kN s/m", 1e3),
    "energy_to_ice": _m("energy to the ice", "J", "MJ", 1e6),
    "ice_resistance": _m("mean ice resistance", "N", "kN", 1e3),
    "max_hull_pressure": _m("max hull pressure", "N/m", "kN/m", 1e3),
    "mean_mass_hit": _m("mean mass hit", "kg", "t", 1e3),
    "ice_energy_gain": _m("kinetic energy gained by the ice", "J", "MJ", 1e6),
    "energy_dissipated": _m("energy dissipated", "J", "MJ", 1e6),
    # task parameters drawn per episode
    "heading": _m("target heading", "rad"),
    "wind_speed": _m("wind speed", "m/s"),
    "wind_direction": _m("wind direction", "rad"),
    "current_speed": _m("current speed", "m/s"),
    "current_direction": _m("current direction", "rad"),
    "gradient": _m("concentration gradient"),
}

#: the metrics of the main evaluation table, after the return, the main
#: metric and its target, and the compared metric, where an environment
#: logs them (the other final metrics follow in a second table)
HEADLINE = ("success", "impulse_per_metre", "energy_to_ice", "path_length", "time",
            "collisions", "max_hull_pressure")
#: logged names whose final value is the last step's alone (a ship's step
#: loads and pose), not a summary of the episode: never in the main table
LAST_STEP = ("goal_distance", "surge", "step_impulse", "hull_pressure")
#: logged names that hold the episode's target of the main metric
TARGET_METRICS = ("target", "target_speed")


def env_name(env_id: str) -> str:
    """``"iceenvs/Convergence-v0"`` → ``"Convergence-v0"``."""
    return env_id.split("/")[-1]


def physics_metrics(env_id: str, info: dict) -> dict[str, float]:
    """The logged metrics of one ``info`` dict: the mapped scalar entries of
    ``info["physics"]`` (all finite scalar entries for an env without a
    map) and the episode metrics (a ship's path length, impulses, ...);
    empty when the info holds no physics
    (:meth:`iceenvs.facts.EnvFacts.logged_metrics`)."""
    return env_facts(env_id).logged_metrics(info)


def logged_names(env_id: str) -> tuple[str, ...]:
    """The logged names of an environment's metrics (its map of
    ``info["physics"]``, then its episode metrics); empty for an
    environment that logs every scalar entry under its own name."""
    facts = env_facts(env_id)
    return (*(facts.metrics or {}).values(), *facts.episode_metrics)


def metric_unit(name: str) -> MetricUnit:
    """The :class:`MetricUnit` of ``name``; for a name not in
    :data:`METRIC_UNITS`, the name itself in SI."""
    return METRIC_UNITS.get(name) or MetricUnit(name)


def metric_header(name: str) -> str:
    """``"ice impulse per metre [kN s/m]"``: the header and the display unit
    of ``name`` (the name alone for one not in :data:`METRIC_UNITS`)."""
    header, unit = metric_unit(name)[:2]
    return f"{header} [{unit}]" if unit else header


def scaled(name: str, value: float) -> float:
    """The SI ``value`` of ``name`` in its display unit."""
    return value / metric_unit(name).scale


def _decimals(x: float, digits: int) -> int:
    """Decimals that show ``x`` to ``digits`` significant figures (negative:
    rounded to tens, hundreds, …)."""
    return digits - 1 - int(math.floor(math.log10(abs(x))))


def _fixed(x: float, decimals: int) -> str:
    if decimals < 0:
        return f"{round(x, decimals):.0f}"
    return f"{x:.{decimals}f}"


def significant(x: float, digits: int = 3, whole: bool = False) -> str:
    """``x`` to ``digits`` significant figures, without an exponent
    (``218600000.0`` → ``"219000000"``, ``0.0001234`` → ``"0.000123"``);
    with ``whole``, the integer part is never rounded (``1234.5`` →
    ``"1234"``)."""
    if not math.isfinite(x):
        return "–" if math.isnan(x) else str(x)
    if x == 0:
        return "0"
    decimals = _decimals(x, digits)
    return _fixed(x, max(decimals, 0) if whole else decimals)


#: an error at most this fraction of its value is the rounding of floats (a
#: quantity the same in every episode, summed along different paths), not a spread
ROUNDING_NOISE = 1e-9


def rounding_noise(value: float, error: float) -> bool:
    """Whether ``error`` is no spread but the rounding of floats about
    ``value`` (at most :data:`ROUNDING_NOISE` × |value|): such an error
    shows as ``± 0``, not as ``± 0.0000000000017``."""
    return math.isfinite(error) and abs(error) <= ROUNDING_NOISE * abs(value)


def format_pm(mean: float, error: float, digits: int = 3, error_digits: int = 2) -> str:
    """``"143.6 ± 2.1"``: ``mean`` to ``digits`` significant figures, or to
    the last decimal of ``error`` (shown to ``error_digits`` significant
    figures) where that shows more, yet never more than two decimals
    beyond the error's nor more than six significant figures; no
    exponent; an integer without error as it is, and an error that is only
    the rounding of floats (:func:`rounding_noise`) as ``± 0``. NaN shows as
    ``"–"``."""
    if not math.isfinite(mean):
        return "–"
    if not math.isfinite(error) or error <= 0 or rounding_noise(mean, error):
        if float(mean).is_integer() and abs(mean) < 1e6:     # a count the same in every episode
            return f"{int(mean)} ± 0"
        return f"{significant(mean + 0.0, digits)} ± 0"
    shown = _decimals(error, error_digits)
    decimals = shown if mean == 0 else min(max(_decimals(mean, digits), shown),
                                           _decimals(mean, 6), shown + 2)
    text = _fixed(mean, decimals)
    if float(text) == 0:                 # no "-0.0"
        text = _fixed(0.0, decimals)
    return f"{text} ± {_fixed(error, shown)}"
