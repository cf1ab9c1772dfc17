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

from .input_checks import check_range
from .domain import Box, PeriodicBox
from .floes import FloeField, place_floes, power_law_diameters, spatial_order

__all__ = ["LogMassSizes", "AUTO_ICENAV_SIZES", "floe_area_quantile", "draw_floe_areas",
           "covering_areas", "Lead", "field_keep_probability", "navigation_field",
           "MAX_PLACED_CONCENTRATION", "TransitBox", "FLOE_SIZE_LAWS", "transit_field",
           "covering_diameters", "channel_field", "PLACEMENT_LIMIT", "scaled_placement",
           "place_then_compress"]


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


# ---------------------------------------------------------------------------
# The transit channel, and fields covering a box or a strip of it
# ---------------------------------------------------------------------------

class TransitBox(Box):
    """A transit channel: rigid walls ahead (x = lx) and behind (x = 0),
    periodic across (y), and a band of ice ``band = (x0, x1)`` with open
    water before and after it (:func:`transit_field` fills it)."""

    def __init__(self, lx, ly=None, *, band=None):
        super().__init__(lx, ly, periodic=(False, True))
        band = (0.0, self.lx) if band is None else tuple(float(b) for b in band)
        if not (len(band) == 2 and 0.0 <= band[0] < band[1] <= self.lx):
            raise ValueError(f"band must be (x0, x1) with 0 <= x0 < x1 <= lx = {self.lx:g}, "
                             f"got {band!r}")
        self.band = band

    @property
    def band_area(self) -> float:
        return (self.band[1] - self.band[0]) * self.ly

    def __repr__(self):
        return f"TransitBox({self.lx:g}, {self.ly:g}, band={self.band})"


#: the floe-size laws of :func:`transit_field` and :func:`covering_diameters`
FLOE_SIZE_LAWS = ("power", "lognormal", "auto_icenav")


def transit_field(preset, *, concentration: float, band: tuple, length: float, width: float,
                  seed: int | None = 0, sizes: str = "power", lognormal=(1.0, 0.5),
                  thickness: float | None = None, box_type=TransitBox):
    """A band of floes at rest in a transit channel.

    Parameters
    ----------
    preset : PaperPreset
        Material (thickness, density) and, with ``sizes="power"``, the
        power-law floe sizes of the preset (exponent and mean diameter).
    concentration : float
        Ice concentration in the band, in (0, 0.9].
    band : (x0, x1)
        The ice band along the channel [m].
    length, width : float
        The channel [m].
    sizes : {"power", "lognormal", "auto_icenav"}
        Power-law diameters of the preset (random draws between its
        cut-offs), log-normal diameters with ``lognormal = (median
        diameter [m], σ of ln d)``, clipped to 0.2–5 times the median, or
        the floe areas of AUTO-IceNav's ice fields
        (:data:`physics.ice_fields.AUTO_ICENAV_SIZES`), each floe a disc.
    box_type : class
        :class:`TransitBox` (default) or any box class taking
        ``(lx, ly)``, e.g. :class:`~physics.domain.ChannelBox`.

    Returns
    -------
    (FloeField, Box)
    """
    check_range("concentration", concentration, 0.0, 0.9, low_open=True)
    check_range("length", length, 0.0, None, low_open=True)
    check_range("width", width, 0.0, None, low_open=True)
    if sizes not in FLOE_SIZE_LAWS:
        raise ValueError(f"sizes must be one of {FLOE_SIZE_LAWS}, got {sizes!r}")
    box = box_type(length, width, band=band) if box_type is TransitBox else box_type(length, width)
    x0, x1 = (box.band if isinstance(box, TransitBox) else tuple(float(b) for b in band))
    if not 0.0 <= x0 < x1 <= length:
        raise ValueError(f"band must lie inside the channel (0, {length:g}), got {band!r}")
    rng = np.random.default_rng(seed)
    target = concentration * (x1 - x0) * width
    d = covering_diameters(preset, sizes, lognormal, target, rng)
    band_box = Box(x1 - x0, width, periodic=(False, box.periodic[1]))
    pos = place_floes(0.5 * d, band_box, rng)
    pos[:, 0] += x0
    h = preset.thickness if thickness is None else thickness
    field = FloeField(pos, 0.5 * d, h, np.zeros((d.size, 2)), density=preset.forcing.ice_density)
    return field.take(spatial_order(field.positions, box)), box


def covering_diameters(preset, sizes: str, lognormal, target_area: float,
                       rng: np.random.Generator) -> np.ndarray:
    """Floe diameters [m] whose discs just cover ``target_area`` [m²]: the
    floes of :func:`transit_field` (``sizes`` and ``lognormal`` as there,
    ``preset`` a :class:`~physics.params.PaperPreset`), drawn from ``rng``.
    The draw is repeated until it covers the area, and cut after the first
    floe that reaches it."""
    if sizes not in FLOE_SIZE_LAWS:
        raise ValueError(f"sizes must be one of {FLOE_SIZE_LAWS}, got {sizes!r}")
    if sizes == "auto_icenav":
        return 2.0 * np.sqrt(covering_areas(AUTO_ICENAV_SIZES, target_area, rng) / math.pi)
    if sizes == "power":
        mean_d = preset.mean_diameter
        alpha = preset.fsd_exponent
        n = max(int(target_area / (math.pi * 0.25 * mean_d ** 2 * 1.5)), 4)
        d = power_law_diameters(n, alpha, mean_d, method="random", rng=rng)
    else:
        median, sigma = (float(x) for x in lognormal)
        check_range("lognormal median", median, 0.0, None, low_open=True)
        check_range("lognormal sigma", sigma, 0.0, None)
        n = max(int(4 * target_area / (math.pi * median ** 2)), 4)
        d = np.clip(median * np.exp(sigma * rng.standard_normal(n)), 0.2 * median, 5 * median)
    # keep floes until they cover the target area
    area = np.cumsum(0.25 * math.pi * d ** 2)
    while area[-1] < target_area:
        d = np.concatenate([d, d])
        area = np.cumsum(0.25 * math.pi * d ** 2)
    return d[: int(np.searchsorted(area, target_area)) + 1]


#: the largest concentration :func:`channel_field` places floes at directly;
#: above it they are placed looser and compressed to it (FIRE relaxation)
PLACEMENT_LIMIT = 0.8


def scaled_placement(radii: np.ndarray, lengths, concentration: float,
                     rng: np.random.Generator, *, thickness, density: float):
    """The loose placement of :func:`place_then_compress` for floes of
    radii ``radii`` [m] that cover ``concentration`` of a box of side
    lengths ``lengths`` [m]: a function of a concentration c that places
    them at random with ``rng``, at rest, in a periodic box of the same
    shape that they cover at c (the sides times √(concentration / c)), and
    returns (FloeField, PeriodicBox)."""
    def place(c: float):
        k = math.sqrt(concentration / c)
        box = PeriodicBox(lengths[0] * k, lengths[1] * k)
        loose = FloeField(place_floes(radii, box, rng), radii, thickness,
                          np.zeros((radii.size, 2)), density=density)
        return loose, box
    return place


def place_then_compress(place, concentration: float, limit: float, *, increment: float = 0.005,
                        force_tol: float = 1e-3):
    """Floes at a concentration above what random placement reaches:
    placed loosely, then compressed. ``place(limit)`` places them at random,
    at rest, at the concentration ``limit`` in a periodic box and returns
    (FloeField, PeriodicBox) (:func:`scaled_placement`, or a preset's
    :meth:`~physics.params.PaperPreset.floe_field`);
    :func:`physics.jamming.compress_floes` then compresses them affinely to
    ``concentration``, relaxing them with FIRE after every ``increment`` of
    concentration to the force tolerance ``force_tol``. Below the field's
    jamming point the floes end without overlaps; above it they form a
    jammed packing in force balance (small overlaps).

    Returns
    -------
    (FloeField, PeriodicBox, RelaxResult)
        As :func:`~physics.jamming.compress_floes`: the floes at rest, the
        compressed box and the last relaxation.
    """
    from .jamming import compress_floes

    loose, box = place(limit)
    return compress_floes(loose, box, concentration, increment=increment, force_tol=force_tol)


def channel_field(preset, box, rng: np.random.Generator, *, concentration: float,
                  sizes: str = "power", lognormal=(1.0, 0.5), band: float | None = None,
                  keep=None) -> tuple[FloeField, float]:
    """Floes of ``preset``'s material at rest covering ``concentration`` of
    ``box``, or of its strip 0 ≤ y < ``band`` [m] (the fields of
    ShipNavigation-v0 and ShipBeset-v0).

    The diameters are those of :func:`covering_diameters` (``sizes``,
    ``lognormal``) for twice the target area, without the floes wider than
    a third of the region's shorter side, cut after the floe that covers the
    target and scaled so that they cover it exactly. They are placed at
    random; above :data:`PLACEMENT_LIMIT` (a whole periodic box only) they
    are placed looser and compressed to it. ``keep``, a function of
    (positions, radii) giving a mask, removes floes afterwards (those in
    the ship's way at its start).

    Returns
    -------
    (FloeField, float)
        The floes in spatial order, and the concentration they cover of the
        region before ``keep``.
    """
    region = box if band is None else Box(box.lx, band, periodic=box.periodic)
    target = concentration * region.area
    d = covering_diameters(preset, sizes, lognormal, 2.0 * target, rng)
    # no floe wider than a third of the box's shorter side: drop those and
    # keep the others until they cover the target
    d = d[d < min(region.lx, region.ly) / 3.0]
    area = np.cumsum(0.25 * math.pi * d ** 2)
    d = d[: int(np.searchsorted(area, target)) + 1]
    # the last floe overshoots the target: scale the diameters a little
    # so that the floes cover it exactly
    d *= math.sqrt(target / (0.25 * math.pi * float(np.sum(d ** 2))))
    r = 0.5 * d
    covered = math.pi * float(np.sum(r ** 2)) / region.area
    if concentration <= PLACEMENT_LIMIT or band is not None:
        pos = place_floes(r, region, rng)
    else:
        if not all(box.periodic):
            raise ValueError(f"concentration {concentration:g} is above {PLACEMENT_LIMIT} "
                             f"and the box has walls: floes are compressed to it only in "
                             f"a periodic box")
        a = math.pi * float(np.sum(r ** 2)) / box.area
        place = scaled_placement(r, (box.lx, box.ly), a, rng, thickness=preset.thickness,
                                 density=preset.forcing.ice_density)
        packed, box1, _ = place_then_compress(place, a, PLACEMENT_LIMIT, increment=0.01,
                                              force_tol=1e-2)
        pos = np.mod(packed.positions * (box.lx / box1.lx), [box.lx, box.ly])
    if keep is not None:
        mask = keep(pos, r)
        pos, r = pos[mask], r[mask]
    field = FloeField(pos, r, preset.thickness, np.zeros((r.size, 2)),
                      density=preset.forcing.ice_density)
    return field.take(spatial_order(field.positions, box)), covered
