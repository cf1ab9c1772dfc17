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
           "covering_areas", "Lead", "field_keep_probability", "navigation_field",
           "MAX_PLACED_CONCENTRATION"]


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


# ---------------------------------------------------------------------------
# Heterogeneous navigation fields: thickness classes, leads, a gradient
# ---------------------------------------------------------------------------

#: highest concentration at which the floes of a field are placed before
#: leads and the gradient thin them (random sequential placement with growth,
#: :func:`physics.floes.place_floes`)
MAX_PLACED_CONCENTRATION = 0.8


@dataclass(frozen=True)
class Lead:
    """A straight lead (a band of open water) ``width`` [m] wide whose
    centre line runs through the point (``x``, ``y``) [m] at ``angle`` [rad]
    to the route (+x; 0: along the route, ±π/2: across it), ``length`` [m]
    long, centred on that point (default: without end). In a field periodic
    across (y) the lead wraps round."""

    x: float
    y: float
    angle: float
    width: float
    length: float = math.inf

    def distance(self, points: np.ndarray, period: float | None = None) -> np.ndarray:
        """Distance [m] of ``points`` (N, 2) from the lead's centre line
        (``period``: the field's width when y is periodic; the nearest
        periodic image counts)."""
        p = np.asarray(points, dtype=float)
        c, s = math.cos(self.angle), math.sin(self.angle)
        if not math.isfinite(self.length):
            if abs(c) < 1e-9:
                return np.abs(p[:, 0] - self.x)
            dy = p[:, 1] - (self.y + (s / c) * (p[:, 0] - self.x))
            if period is not None:
                dy = np.mod(dy + 0.5 * period, period) - 0.5 * period
            return np.abs(dy) * abs(c)
        half = 0.5 * self.length
        images = 0 if period is None else int(math.ceil(half * abs(s) / period)) + 1
        best = np.full(p.shape[0], np.inf)
        for k in range(-images, images + 1):
            dx = p[:, 0] - self.x
            dy = p[:, 1] + (k * period if period is not None else 0.0) - self.y
            along = np.clip(dx * c + dy * s, -half, half)
            best = np.minimum(best, np.hypot(dx - along * c, dy - along * s))
        return best


def field_keep_probability(points, radii, *, width: float, gradient: float = 0.0,
                           leads: tuple = (), periodic: bool = True) -> np.ndarray:
    """The probability that a floe placed at ``points`` (N, 2) with
    ``radii`` stays in a field of :func:`navigation_field`: 0 where the floe
    reaches into a lead, else (1 + ``gradient`` η) / (1 + |``gradient``|)
    with η = 2y/``width`` − 1 ∈ [−1, 1] the position across the field."""
    p = np.asarray(points, dtype=float)
    eta = 2.0 * p[:, 1] / width - 1.0
    keep = (1.0 + gradient * eta) / (1.0 + abs(gradient))
    for lead in leads:
        keep[lead.distance(p, width if periodic else None)
             < 0.5 * lead.width + np.asarray(radii, dtype=float)] = 0.0
    return keep


def navigation_field(sizes: LogMassSizes, *, concentration: float, band: tuple, width: float,
                     rng: np.random.Generator, thickness: float | None = None,
                     density: float | None = None, thick_fraction: float = 0.0,
                     thick_thickness: float = 3.0, leads: tuple = (), gradient: float = 0.0,
                     periodic: bool = True):
    """The floes of a heterogeneous ice field for ship navigation.

    Floes of the areas of ``sizes`` (each a disc) cover ``concentration``
    of the band x0 ≤ x < x1 (``band``) across the ``width`` [m] of the
    field, at rest. Three options make the field heterogeneous:

    * ``thick_fraction``: each floe is, with this probability, of the
      thicker class ``thick_thickness`` [m] (multi-year or ridged ice
      among first-year floes of ``thickness``);
    * ``leads``: :class:`Lead` bands of open water; no floe reaches into one;
    * ``gradient`` in [−1, 1]: the concentration varies linearly across the
      field, A(y) = A (1 + ``gradient`` η), η = 2y/``width`` − 1.

    Floes are placed somewhat above the concentration the leads and the
    gradient need where the ice is densest, then thinned: floe i stays when
    u_i / p_i < t, with u_i uniform in [0, 1), p_i its keep probability
    (:func:`field_keep_probability`) and t the one threshold at which the
    floes left cover ``concentration`` of the band (to one floe). Each floe
    so stays with probability t p_i, proportional to p_i; a placement too
    sparse for that (t p_i > 1 somewhere) is repeated denser.

    Parameters
    ----------
    sizes : LogMassSizes
        The floe-size law (e.g. :data:`AUTO_ICENAV_SIZES`).
    thickness, density : float, optional
        Of the floes [m], [kg/m³]; default those of ``sizes``.
    periodic : bool
        Whether the field is periodic across (y) (leads wrap round).

    Returns
    -------
    (FloeField, float)
        The floes (positions in the band's frame: x from x0) and the
        concentration they cover of the band.

    Raises
    ------
    ValueError
        For options out of range, or when the leads and the gradient need
        the floes placed above :data:`MAX_PLACED_CONCENTRATION`.
    """
    from .domain import Box
    from .floes import FloeField, place_floes

    check_range("concentration", concentration, 0.0, MAX_PLACED_CONCENTRATION, low_open=True)
    check_range("width", width, 0.0, None, low_open=True)
    check_range("thick_fraction", thick_fraction, 0.0, 1.0)
    check_range("thick_thickness", thick_thickness, 0.0, None, low_open=True)
    check_range("gradient", gradient, -1.0, 1.0)
    x0, x1 = (float(b) for b in band)
    if not (math.isfinite(x0) and math.isfinite(x1) and x1 > x0):
        raise ValueError(f"band must be (x0, x1) with x0 < x1, got {band!r}")
    leads = tuple(leads)
    for lead in leads:
        if not isinstance(lead, Lead):
            raise TypeError(f"leads must be Lead objects, got {type(lead).__name__}")
        check_range("lead width", lead.width, 0.0, None, low_open=True)
        if not lead.length > 0:
            raise ValueError(f"lead length must be > 0, got {lead.length!r}")
    h = sizes.thickness if thickness is None else float(thickness)
    rho = sizes.density if density is None else float(density)
    check_range("thickness", h, 0.0, None, low_open=True)
    region = Box(x1 - x0, width, periodic=(False, bool(periodic)))
    shifted = tuple(Lead(lead.x - x0, lead.y, lead.angle, lead.width, lead.length)
                    for lead in leads)
    placed = 1.1 * concentration * (1.0 + abs(gradient))
    target = concentration * region.area
    while True:
        if placed > MAX_PLACED_CONCENTRATION:
            raise ValueError(
                f"concentration {concentration:g} with these leads and gradient {gradient:g} "
                f"needs the floes placed above {MAX_PLACED_CONCENTRATION} where the ice is "
                f"densest: fewer or narrower leads, a smaller gradient or a lower "
                f"concentration")
        r = np.sqrt(covering_areas(sizes, placed * region.area, rng) / math.pi)
        # floes too large for the box (minimum images) are left out
        r = r[r < 0.999 * min(0.5 * region.lx, region.ly / (4.0 if periodic else 2.0))]
        pos = place_floes(r, region, rng)
        p = field_keep_probability(pos, r, width=width, gradient=gradient, leads=shifted,
                                   periodic=periodic)
        with np.errstate(divide="ignore"):
            key = np.where(p > 0.0, rng.random(r.size) / p, np.inf)
        order = np.argsort(key, kind="stable")
        area = np.cumsum(math.pi * r[order] ** 2)
        cut = int(np.searchsorted(area, target))
        if cut < r.size and key[order[cut]] * float(np.max(p)) <= 1.0:
            break
        placed *= 1.25
    kept = np.sort(order[: cut + 1])
    pos, r = pos[kept], r[kept]
    covered = math.pi * float(np.sum(r ** 2)) / region.area
    h_floe = np.where(rng.random(r.size) < thick_fraction, float(thick_thickness), h)
    pos[:, 0] += x0
    field = FloeField(pos, r, h_floe, np.zeros((r.size, 2)), density=rho)
    return field, covered
