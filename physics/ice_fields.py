"""Floe sizes of published ice fields for ship navigation.

:data:`AUTO_ICENAV_SIZES` are the floe sizes of the simulated ice fields of
AUTO-IceNav (de Schaetzen, Botros, Zhong, Murrant, Gash and Smith,
"Real-time navigation for autonomous surface vessels in ice-covered waters",
IEEE Transactions on Robotics, 2025), as its public field generator draws
them (``ship_ice_planner/experiments/generate_rand_exp.py`` of the
``rdesc/AUTO-IceNav`` repository, function ``sample_ice_mass_from_lognorm``,
and its constants):

* the natural logarithm of a floe's mass m [kg] is drawn from a shifted
  log-normal law, ln m = loc + scale · exp(s Z) with Z standard normal,
  s = 0.54, loc = 10.21, scale = 0.9324 (SciPy's ``lognorm(s, loc, scale)``);
* the floe's area is m / (ρ h), with the ice density ρ = 900 kg/m³ and the
  thickness h = 1.2 m of its simulator;
* the radius √(area/π) is clipped to 2–50 m, and floes under 16 m² are
  not placed (the smallest mass the law gives, e^loc = 27 000 kg, is 25 m²
  already, so this never removes a floe).

The median floe is then e^(loc + scale) / (ρ h) = 64 m², a disc of radius
4.5 m, and the mean 103 m²; the tail is heavy (the 99th percentile is
665 m², radius 14.5 m, the 99.9th 3540 m², radius 34 m), so that half the
ice area lies in floes of more than about 120 m².
AUTO-IceNav's floes are convex polygons of 5 to 20 corners; a floe here is
a disc of the same area. :func:`floe_area_quantile` gives the law's
quantiles, :func:`draw_floe_areas` draws areas and :func:`covering_areas`
draws floes until they cover an area.

>>> import numpy as np
>>> from physics.ice_fields import AUTO_ICENAV_SIZES, floe_area_quantile
>>> round(floe_area_quantile(AUTO_ICENAV_SIZES, 0.5), 1)
63.9
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import NormalDist

import numpy as np

from .checks import check_range

__all__ = ["LogMassSizes", "AUTO_ICENAV_SIZES", "floe_area_quantile", "draw_floe_areas",
           "covering_areas"]


@dataclass(frozen=True)
class LogMassSizes:
    """Floe sizes whose log-mass follows a shifted log-normal law:
    ln(m / 1 kg) = ``loc`` + ``scale`` · exp(``s`` Z), Z standard normal;
    area = m / (``density`` · ``thickness``), the radius clipped to
    [``min_radius``, ``max_radius``] [m], areas under ``min_area`` [m²]
    dropped."""

    s: float
    loc: float
    scale: float
    density: float
    thickness: float
    min_radius: float
    max_radius: float
    min_area: float

    def __post_init__(self):
        for name in ("s", "scale", "density", "thickness", "min_radius"):
            check_range(name, getattr(self, name), 0.0, None, low_open=True)
        check_range("loc", self.loc)
        check_range("max_radius", self.max_radius, self.min_radius, None, low_open=True)
        check_range("min_area", self.min_area, 0.0, None)


#: the floe sizes of AUTO-IceNav's simulated ice fields (see the module docstring)
AUTO_ICENAV_SIZES = LogMassSizes(s=0.54, loc=10.21, scale=0.9324, density=900.0, thickness=1.2,
                                 min_radius=2.0, max_radius=50.0, min_area=16.0)


def _clipped_area(sizes: LogMassSizes, area):
    """Areas with their radii clipped into the bounds of ``sizes``."""
    low = math.pi * sizes.min_radius ** 2
    high = math.pi * sizes.max_radius ** 2
    return np.clip(area, low, high)


def floe_area_quantile(sizes: LogMassSizes, q: float) -> float:
    """The ``q``-quantile (0 < q < 1) of the floe area [m²] of ``sizes``,
    before floes under ``min_area`` are dropped."""
    check_range("q", q, 0.0, 1.0, low_open=True, high_open=True)
    z = NormalDist().inv_cdf(float(q))
    log_mass = sizes.loc + sizes.scale * math.exp(sizes.s * z)
    area = math.exp(log_mass) / (sizes.density * sizes.thickness)
    return float(_clipped_area(sizes, area))


def draw_floe_areas(sizes: LogMassSizes, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` floe areas [m²] drawn from ``sizes`` with ``rng`` (fewer when
    some fall under ``min_area``)."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
        raise ValueError(f"n must be a non-negative integer, got {n!r}")
    log_mass = sizes.loc + sizes.scale * np.exp(sizes.s * rng.standard_normal(int(n)))
    area = _clipped_area(sizes, np.exp(log_mass) / (sizes.density * sizes.thickness))
    return area[area >= sizes.min_area]


def covering_areas(sizes: LogMassSizes, target_area: float,
                   rng: np.random.Generator) -> np.ndarray:
    """Floe areas [m²] drawn from ``sizes`` until they cover ``target_area``
    [m²]: the draws in order, cut after the first that reaches it."""
    check_range("target_area", target_area, 0.0, None, low_open=True)
    median = floe_area_quantile(sizes, 0.5)
    areas = np.empty(0)
    while areas.sum() < target_area:
        more = max(16, int(2.0 * (target_area - areas.sum()) / median))
        areas = np.concatenate([areas, draw_floe_areas(sizes, more, rng)])
    return areas[: int(np.searchsorted(np.cumsum(areas), target_area)) + 1]
