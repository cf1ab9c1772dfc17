"""What a ship among the floes senses: a sector lidar, a swath sensor and
an egocentric occupancy image.

Both sensors read one snapshot of the ice, floes as discs (centres
``positions`` (N, 2) [m], ``radii`` (N,) [m]), and the ship's pose
(``ship_xy`` [m], ``heading`` [rad, anticlockwise from +x], as
:class:`physics.ship.ShipState` gives it). They are functions of arrays,
so an environment calls them on whatever engine it runs; the lidar is
compiled (:func:`lidar_scan`, the same without the checks of the
arguments, is what an environment calls every step).

The compiled sensors (:func:`lidar_scan`, :func:`swath_scan`) take their
arguments packed in a few float arrays: the ship's pose (x, y, heading:
the first entries of :attr:`physics.ship.Ship.motion`), the floes, the
sensor's setting (:data:`LIDAR_SETTING`, :data:`SWATH_SETTING`) and the
box (:data:`SCAN_BOX`, :func:`scan_box`), the entries named by these
tuples.

Frames. The ship frame has x forward (along the heading) and y to port;
angles are anticlockwise seen from above. Along a periodic axis of a box
of side lengths ``box_lengths`` every displacement is taken as its minimum
image, so the sensors see each floe once, through its nearest image: for
an exact picture the sensor's reach should stay below half the box length.

:func:`ice_lidar`
    The field of view ``fov`` [rad], centred on the heading, is cut into
    ``sectors`` equal angular sectors, sector 0 starting at
    heading − fov/2 and the index growing anticlockwise (with an odd
    number of sectors the middle one looks straight ahead). Per sector:

    * ``distance`` [m]: along the sector's central ray, the distance from
      the ship to the first floe edge it meets (exact ray–circle
      intersection); 0 when the ship stands inside a floe, ``max_range``
      when the ray meets nothing within ``max_range``;
    * ``concentration`` [-]: the fraction of the sector's wedge (radius 0
      to ``max_range``) covered by ice, counted on a fixed polar grid of
      :data:`LIDAR_RINGS` × :data:`LIDAR_RAYS` sample points per sector:
      rings at radii ``max_range sqrt((i + 1/2) / LIDAR_RINGS)`` (each
      point stands for the same area, so uniform coverage gives the
      true fraction) and angles at the midpoints of equal sub-sectors.
      A point counts when it lies inside any floe.

:func:`ice_swath`
    The ice a straight course would meet, with the floes' sizes: a fan of
    ``rays`` courses spanning ``fan`` [rad] about the heading (course k at
    heading − fan/2 + (k + 1/2) fan/rays, anticlockwise; with an odd
    number the middle one is straight ahead). A course's swath is the
    band of half-width ``half_beam`` [m] about its ray. A floe of radius r
    whose centre lies at ``along`` [m] along the ray and ``across`` [m]
    from it is met when across < r + half_beam, and adds its weight w (an
    expected collision impulse, say) times 1 − across / (r + half_beam):
    all of it when the course runs through its centre, little when it only
    grazes. The sums are kept per band of ``along``: ``bands`` are the
    band edges [m] (0, 100, 250: the ice within 100 m ahead of the ship's
    centroid and from 100 to 250 m). Floes behind the centroid are not
    counted. Unlike the lidar's first edge and wedge concentration, the
    sums tell a large floe from a few small ones: the weight grows with
    the floe's mass.

:func:`channel_room`
    What the swath's courses leave of the channel: how far the centroid
    can sail along each before it crosses the channel's edge, capped at
    the swath's reach. The swath sensor sees the ice of a periodic
    channel through its images, beyond the edge as within, so a course's
    ice alone does not tell whether the course stays in the channel.

:func:`occupancy_image`
    A (4, size, size) uint8 picture of a square of side ``extent`` [m]
    around the ship, the ship at the centre and its heading up (towards
    row 0), port to the left (towards column 0): a rotation of the map
    seen from above, never a mirror image. The centre of pixel (row i,
    column j) is the ship-frame point x = extent/2 − (i + 1/2) extent/size
    (forward), y = extent/2 − (j + 1/2) extent/size (to port). Channels:

    0. ice: 255 where the pixel centre lies inside a floe, else 0;
    1. hull: 255 where the pixel centre lies inside the hull, a convex
       polygon given by its world-frame corners, anticlockwise;
    2. goal: 255 (1 − g / extent), rounded and clipped at 0, where g [m]
       is the distance of the pixel centre to the goal line x = ``goal_x``
       (the minimum image of it when x is periodic);
    3. heading: the constant 255 (heading mod 2π) / 2π, rounded.

Both sensors first keep the floes within reach of the ship by one
distance test, so their cost grows with the number of floes with a small
constant and otherwise with the ice near the ship.

Example
-------
>>> import numpy as np
>>> from iceenvs.ship_sensors import ice_lidar
>>> distance, concentration = ice_lidar((0.0, 0.0), 0.0, np.array([[50.0, 0.0]]),
...                                     np.array([5.0]), sectors=3)
>>> distance.tolist()
[200.0, 45.0, 200.0]
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from physics.input_checks import check_range
from physics.domain import minimum_image

__all__ = ["ice_lidar", "lidar_scan", "ice_swath", "swath_scan", "swath_courses", "channel_room",
           "course_with_room",
           "check_bands", "occupancy_image", "LIDAR_RINGS", "LIDAR_RAYS", "SCAN_BOX",
           "LIDAR_SETTING", "SWATH_SETTING", "scan_box", "box_entries"]

#: radial sample points per lidar sector (the concentration grid)
LIDAR_RINGS = 8
#: angular sample points per lidar sector (the concentration grid)
LIDAR_RAYS = 4

_TWO_PI = 2.0 * math.pi

#: the entries of a box as the compiled sensors take it (a float array):
#: the side lengths [m] and whether x and y are periodic (1.0) or not (0.0)
SCAN_BOX = ("lx", "ly", "periodic_x", "periodic_y")
#: the entries of a lidar's setting (a float array): the number of sectors,
#: the field of view [rad] and the range [m]
LIDAR_SETTING = ("sectors", "fov", "max_range")
#: the entries of a swath sensor's setting (a float array): the number of
#: courses, the fan [rad] and the half-beam [m]
SWATH_SETTING = ("rays", "fan", "half_beam")
# the entries as constants of the compiled code (a pose is x, y, heading)
_LX, _LY, _PERIODIC_X, _PERIODIC_Y = range(len(SCAN_BOX))
_SECTORS, _FOV, _MAX_RANGE = range(len(LIDAR_SETTING))
_RAYS, _FAN, _HALF_BEAM = range(len(SWATH_SETTING))


def box_entries(lx: float, ly: float, periodic) -> tuple[float, float, float, float]:
    """The entries of :data:`SCAN_BOX` of the box of side lengths ``lx``,
    ``ly`` [m] and periodicity ``periodic`` (x, y), for a packed array that
    holds them among others."""
    return lx, ly, 1.0 if periodic[0] else 0.0, 1.0 if periodic[1] else 0.0


def scan_box(lx: float, ly: float, periodic) -> np.ndarray:
    """The box of side lengths ``lx``, ``ly`` [m] and periodicity
    ``periodic`` (x, y) as the compiled sensors take it (:data:`SCAN_BOX`)."""
    return np.array(box_entries(lx, ly, periodic))


# -- validation ------------------------------------------------------------------------------

def _check_int(name: str, value, low: int) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name} must be an integer ≥ {low}, got {value!r}")
    if value < low:
        raise ValueError(f"{name} must be an integer ≥ {low}, got {value!r}")
    return int(value)


def _check_pose(ship_xy, heading) -> tuple[np.ndarray, float]:
    try:
        xy = np.asarray(ship_xy, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"ship_xy must be a pair of finite numbers, got {ship_xy!r}") from None
    if xy.shape != (2,) or not np.all(np.isfinite(xy)):
        raise ValueError(f"ship_xy must be a pair of finite numbers, got {ship_xy!r}")
    check_range("heading", heading)
    return xy, float(heading)


def _check_floes(positions, radii) -> tuple[np.ndarray, np.ndarray]:
    p = np.asarray(positions, dtype=float)
    r = np.asarray(radii, dtype=float)
    if p.size == 0 and r.size == 0:
        return np.empty((0, 2)), np.empty(0)
    if p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f"positions must be an (N, 2) array, got shape {p.shape}")
    if r.shape != (p.shape[0],):
        raise ValueError(f"radii must be an (N,) array with N = {p.shape[0]} (one per "
                         f"position), got shape {r.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("positions must be finite")
    if not (np.all(np.isfinite(r)) and np.all(r > 0.0)):
        raise ValueError("radii must be finite and positive")
    return p, r


def _check_box(box_lengths, periodic) -> tuple[np.ndarray | None, tuple[bool, bool]]:
    try:
        px, py = periodic
    except (TypeError, ValueError):
        raise ValueError(f"periodic must be a pair of booleans, got {periodic!r}") from None
    per = (bool(px), bool(py))
    if box_lengths is None:
        if any(per):
            raise ValueError("box_lengths must be given when an axis is periodic")
        return None, per
    lengths = np.asarray(box_lengths, dtype=float)
    if lengths.shape != (2,) or not (np.all(np.isfinite(lengths)) and np.all(lengths > 0.0)):
        raise ValueError(f"box_lengths must be two finite positive lengths, got {box_lengths!r}")
    return lengths, per


def _minimum_image(d: np.ndarray, lengths, periodic) -> np.ndarray:
    """Displacements ``d`` (..., 2) in minimum-image form, in place."""
    if lengths is not None:
        for k in range(2):
            if periodic[k]:
                d[..., k] -= lengths[k] * np.floor(d[..., k] / lengths[k] + 0.5)
    return d


def _nearby(ship_xy, positions, radii, reach, lengths, periodic):
    """Displacements (M, 2) and radii (M,) of the floes whose disc comes
    within ``reach`` of the ship."""
    d = _minimum_image(positions - ship_xy, lengths, periodic)
    limit = reach + radii
    near = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] <= limit * limit
    return d[near], radii[near]


#: the checks of the sensors' arguments, for the other sensors of the package
check_pose, check_floes, check_box = _check_pose, _check_floes, _check_box


def _expand(item, lo, hi):
    """Every (item, index) pair of the index ranges [lo, hi]."""
    count = hi - lo + 1
    total = int(count.sum())
    each = np.repeat(item, count)
    index = np.arange(total) - np.repeat(np.cumsum(count) - count - lo, count)
    return each, index


# -- lidar -----------------------------------------------------------------------------------

def ice_lidar(ship_xy, heading: float, positions, radii, *, sectors: int = 9,
              fov: float = math.pi, max_range: float = 200.0, box_lengths=None,
              periodic=(False, False)) -> tuple[np.ndarray, np.ndarray]:
    """Distance to the nearest floe and ice concentration per angular sector.

    Parameters
    ----------
    ship_xy : (2,) array_like
        Ship position [m].
    heading : float
        Ship heading [rad, anticlockwise from +x].
    positions : (N, 2) array_like
        Floe centres [m].
    radii : (N,) array_like
        Floe radii [m], positive.
    sectors : int
        Number K ≥ 1 of equal sectors of the field of view.
    fov : float
        Field of view [rad], 0 < fov ≤ 2π, centred on the heading.
    max_range : float
        Range [m] > 0 of the sensor.
    box_lengths : (2,) array_like, optional
        Box side lengths [m]; needed when an axis is periodic.
    periodic : (bool, bool)
        Periodicity along x and y (minimum-image displacements).

    Returns
    -------
    distance : (K,) float array
        Per sector, the distance [m] along its central ray to the first floe
        edge, 0 inside a floe, ``max_range`` when nothing is hit.
    concentration : (K,) float array
        Per sector, the fraction [-] of its wedge of radius ``max_range``
        covered by floes (on the sample grid, see the module docstring).

    Raises
    ------
    ValueError
        An argument out of range or of the wrong shape; the message names it.
    """
    xy, heading = _check_pose(ship_xy, heading)
    k = _check_int("sectors", sectors, 1)
    check_range("fov", fov, 0.0, _TWO_PI, low_open=True)
    check_range("max_range", max_range, 0.0, None, low_open=True)
    p, r = _check_floes(positions, radii)
    lengths, per = _check_box(box_lengths, periodic)
    fov, max_range = float(fov), float(max_range)

    return lidar_scan(np.array([xy[0], xy[1], heading]), p, r, np.array([k, fov, max_range]),
                      _scan_box(lengths, per))


def _scan_box(lengths, periodic) -> np.ndarray:
    """:func:`scan_box` of checked lengths (None: no periodic axis, whose
    length is never read)."""
    lx, ly = (1.0, 1.0) if lengths is None else (float(lengths[0]), float(lengths[1]))
    return scan_box(lx, ly, periodic)


@njit(cache=True, inline="always", error_model="numpy")
def _unpacked_box(box):
    """(lx, ly, periodic_x, periodic_y) of a packed box (:data:`SCAN_BOX`)."""
    return box[_LX], box[_LY], box[_PERIODIC_X] != 0.0, box[_PERIODIC_Y] != 0.0


@njit(cache=True, inline="always", error_model="numpy")
def _grid_range(low, high, step, n):
    """The indices j of the grid angles (j + 1/2) step, j = 0 … n − 1, from
    ``low`` to ``high`` [rad] as a float pair (lo, hi); empty when not
    lo ≤ hi (a NaN bound included)."""
    lo = np.ceil(low / step - 0.5)
    hi = np.floor(high / step - 0.5)
    if lo < 0.0:
        lo = 0.0
    if hi > n - 1.0:
        hi = n - 1.0
    return lo, hi


@njit(cache=True, error_model="numpy")
def lidar_scan(pose, positions, radii, setting, box):
    """:func:`ice_lidar` without the checks of its arguments: the ship at
    (x, y) = ``pose[:2]`` heading ``pose[2]``, the lidar's ``setting``
    (:data:`LIDAR_SETTING`), the ``box`` (:data:`SCAN_BOX`; its side
    lengths are read along the periodic axes only). Returns (distance,
    concentration)."""
    x, y, heading = pose[0], pose[1], pose[2]
    sectors = int(setting[_SECTORS])
    fov, max_range = setting[_FOV], setting[_MAX_RANGE]
    lx, ly, periodic_x, periodic_y = _unpacked_box(box)
    n_ang = sectors * LIDAR_RAYS
    distance = np.full(sectors, max_range)
    covered = np.zeros((LIDAR_RINGS, n_ang), dtype=np.bool_)
    # the floes whose disc comes within range, as displacements from the ship
    n = radii.shape[0]
    near_x, near_y, near_r = np.empty(n), np.empty(n), np.empty(n)
    m = 0
    inside = False
    for f in range(n):
        dx = minimum_image(positions[f, 0] - x, lx, periodic_x)
        dy = minimum_image(positions[f, 1] - y, ly, periodic_y)
        r = radii[f]
        limit = max_range + r
        d2 = dx * dx + dy * dy
        if d2 <= limit * limit:
            near_x[m], near_y[m], near_r[m] = dx, dy, r
            m += 1
            inside = inside or d2 <= r * r
    if inside:
        distance[:] = 0.0
    start = heading - 0.5 * fov
    step = fov / sectors
    step_ang = fov / n_ang
    ray_cos, ray_sin = np.empty(sectors), np.empty(sectors)
    for ray in range(sectors):
        theta = start + (ray + 0.5) * step
        ray_cos[ray], ray_sin[ray] = math.cos(theta), math.sin(theta)
    for f in range(m):
        dx, dy, r = near_x[f], near_y[f], near_r[f]
        dist = math.hypot(dx, dy)
        bearing = (math.atan2(dy, dx) - start) % _TWO_PI
        # distance: a ray meets a disc outside the ship when its angle lies
        # within asin(r / dist) of the disc's bearing
        if not inside:
            half = math.asin(r / dist)
            for shift in (-_TWO_PI, 0.0, _TWO_PI):
                lo, hi = _grid_range(bearing - half + shift, bearing + half + shift, step, sectors)
                if lo <= hi:
                    for ray in range(int(lo), int(hi) + 1):
                        c, s = ray_cos[ray], ray_sin[ray]
                        across = dx * s - dy * c
                        chord = math.sqrt(max(r * r - across * across, 0.0))
                        distance[ray] = min(distance[ray], dx * c + dy * s - chord)
        # concentration: on ring i a disc covers the sample angles within
        # arccos((rho_i² + dist² − r²) / (2 rho_i dist)) of its bearing
        for i in range(LIDAR_RINGS):
            rho = max_range * math.sqrt((i + 0.5) / LIDAR_RINGS)
            if dist == 0.0:
                cos_half = -2.0 if rho <= r else 2.0
            else:
                cos_half = (rho * rho + dist * dist - r * r) / (2.0 * rho * dist)
            if cos_half <= 1.0:
                half = math.acos(max(cos_half, -1.0))
                for shift in (-_TWO_PI, 0.0, _TWO_PI):
                    lo, hi = _grid_range(bearing - half + shift, bearing + half + shift,
                                         step_ang, n_ang)
                    if lo <= hi:
                        for j in range(int(lo), int(hi) + 1):
                            covered[i, j] = True
    concentration = np.zeros(sectors)
    for i in range(LIDAR_RINGS):
        for j in range(n_ang):
            if covered[i, j]:
                concentration[j // LIDAR_RAYS] += 1.0
    return distance, concentration / (LIDAR_RINGS * LIDAR_RAYS)


# -- swath sensor ---------------------------------------------------------------------------

def ice_swath(ship_xy, heading, positions, radii, weights, *, rays: int = 9,
              fan: float = 0.5 * math.pi, half_beam: float = 9.0, bands=(0.0, 100.0, 250.0),
              box_lengths=None, periodic=(False, False)) -> np.ndarray:
    """The weights of the floes each of a fan of straight courses would
    meet, per band of distance ahead (see the module docstring).

    Parameters
    ----------
    ship_xy : (2,) [m]; heading : float [rad]
    positions : (N, 2) [m]; radii : (N,) [m]
    weights : (N,) — what a floe met through its centre adds (e.g. its
        expected collision impulse [N s]); non-negative
    rays : int ≥ 1; fan : float in (0, π] [rad]; half_beam : float > 0 [m]
    bands : increasing band edges [m], at least two, the first ≥ 0
    box_lengths, periodic : as :func:`ice_lidar`

    Returns
    -------
    (rays, len(bands) − 1) array: course k's sum in band b.

    Example
    -------
    >>> import numpy as np
    >>> s = ice_swath((0.0, 0.0), 0.0, np.array([[50.0, 0.0]]), np.array([5.0]),
    ...               np.array([2.0]), rays=3, half_beam=5.0)
    >>> s.round(3).tolist()     # the middle course runs through the centre
    [[0.0, 0.0], [2.0, 0.0], [0.0, 0.0]]
    """
    xy, heading = _check_pose(ship_xy, heading)
    k = _check_int("rays", rays, 1)
    check_range("fan", fan, 0.0, math.pi, low_open=True)
    check_range("half_beam", half_beam, 0.0, None, low_open=True)
    p, r = _check_floes(positions, radii)
    w = np.asarray(weights, dtype=float)
    if w.shape != r.shape or not (np.all(np.isfinite(w)) and np.all(w >= 0.0)):
        raise ValueError(f"weights must be {r.shape[0]} finite non-negative numbers (one per "
                         f"floe), got shape {w.shape}")
    edges = check_bands("bands", bands)
    lengths, per = _check_box(box_lengths, periodic)
    return swath_scan(np.array([xy[0], xy[1], heading]), p, r, w,
                      np.array([k, float(fan), float(half_beam)]), edges, _scan_box(lengths, per))


def check_bands(name: str, bands) -> np.ndarray:
    """The band edges [m] of a swath sensor as a float array: at least two
    finite, increasing distances from 0 on (``ValueError`` naming ``name``
    otherwise)."""
    try:
        edges = np.asarray(bands, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be at least two increasing finite distances [m] from 0 "
                         f"on, got {bands!r}") from None
    if (edges.ndim != 1 or edges.size < 2 or not np.all(np.isfinite(edges))
            or edges[0] < 0.0 or not np.all(np.diff(edges) > 0.0)):
        raise ValueError(f"{name} must be at least two increasing finite distances [m] from 0 "
                         f"on, got {bands!r}")
    return edges


def channel_room(offset, half_width: float, bearings, reach: float) -> np.ndarray:
    """How far [m] a centroid ``offset`` [m] to port of a channel's centre
    line (half-width ``half_width`` [m], along +x) can sail along each of
    ``bearings`` [rad, anticlockwise from +x] before it crosses the
    channel's edge outward, capped at ``reach`` [m]: (h − d)/sin α to port,
    (h + d)/(−sin α) to starboard, ``reach`` along the channel, and 0 on a
    course that leads further out from outside the channel.

    Example
    -------
    >>> channel_room(50.0, 100.0, [0.0, math.pi / 2, -math.pi / 6], 250.0).round(6).tolist()
    [250.0, 50.0, 250.0]
    """
    check_range("offset", offset)
    check_range("half_width", half_width, 0.0, None, low_open=True)
    check_range("reach", reach, 0.0, None, low_open=True)
    angles = np.asarray(bearings, dtype=float)
    if not np.all(np.isfinite(angles)):
        raise ValueError("bearings must be finite")
    d, h = float(offset), float(half_width)
    s = np.sin(angles)
    with np.errstate(divide="ignore"):
        room = np.where(s > 0.0, (h - d) / s, np.where(s < 0.0, (h + d) / -s, np.inf))
    return np.clip(room, 0.0, float(reach))


def course_with_room(course: float, offset: float, half_width: float, room: float) -> float:
    """The course [rad from the channel's direction, +x] nearest ``course``
    along which a centroid ``offset`` [m] to port of the centre line has at
    least ``room`` [m] before it leaves the channel (:func:`channel_room`):
    ``course`` clipped to [−asin((h + d)/g), asin((h − d)/g)], each sine
    capped to [−1, 1] (d the offset, h the half-width, g the room). From
    outside the channel only courses back towards it remain."""
    d, h, g = float(offset), float(half_width), float(room)
    port = math.asin(max(min((h - d) / g, 1.0), -1.0))
    starboard = -math.asin(max(min((h + d) / g, 1.0), -1.0))
    return min(max(float(course), starboard), port)


def swath_courses(rays: int, fan: float) -> np.ndarray:
    """The angles [rad] of the courses of :func:`ice_swath` from the centre
    of its fan, −fan/2 + (k + 1/2) fan/rays for k = 0 … rays − 1
    (anticlockwise; :func:`swath_scan` adds them to its ``heading``)."""
    return -0.5 * fan + (np.arange(rays) + 0.5) * fan / rays


@njit(cache=True, error_model="numpy")
def swath_scan(pose, positions, radii, weights, setting, bands, box):
    """:func:`ice_swath` without the checks of its arguments: the ship at
    (x, y) = ``pose[:2]``, the fan about the course ``pose[2]``, the
    sensor's ``setting`` (:data:`SWATH_SETTING`) and the ``box``
    (:data:`SCAN_BOX`)."""
    x, y, heading = pose[0], pose[1], pose[2]
    rays = int(setting[_RAYS])
    fan, half_beam = setting[_FAN], setting[_HALF_BEAM]
    lx, ly, periodic_x, periodic_y = _unpacked_box(box)
    nb = bands.size - 1
    out = np.zeros((rays, nb))
    far = bands[nb]
    ray_cos, ray_sin = np.empty(rays), np.empty(rays)
    for k in range(rays):
        theta = heading - 0.5 * fan + (k + 0.5) * fan / rays
        ray_cos[k], ray_sin[k] = math.cos(theta), math.sin(theta)
    for f in range(radii.shape[0]):
        dx = minimum_image(positions[f, 0] - x, lx, periodic_x)
        dy = minimum_image(positions[f, 1] - y, ly, periodic_y)
        reach = radii[f] + half_beam
        if dx * dx + dy * dy >= (far + reach) * (far + reach):
            continue
        for k in range(rays):
            along = dx * ray_cos[k] + dy * ray_sin[k]
            across = abs(dy * ray_cos[k] - dx * ray_sin[k])
            if across >= reach or along < bands[0] or along >= far:
                continue
            b = 0
            while along >= bands[b + 1]:
                b += 1
            out[k, b] += weights[f] * (1.0 - across / reach)
    return out


# -- occupancy image -------------------------------------------------------------------------

def _check_hull(hull_vertices) -> np.ndarray:
    v = np.asarray(hull_vertices, dtype=float)
    if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3:
        raise ValueError(f"hull_vertices must be a (K, 2) array with K ≥ 3, got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError("hull_vertices must be finite")
    edges = np.roll(v, -1, axis=0) - v
    area2 = float(np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1]))
    if area2 <= 0.0:
        raise ValueError("hull_vertices must run counter-clockwise and enclose an area")
    turn = edges[:, 0] * np.roll(edges[:, 1], -1) - edges[:, 1] * np.roll(edges[:, 0], -1)
    side = np.hypot(edges[:, 0], edges[:, 1])
    if np.any(turn < -1e-12 * side * np.roll(side, -1)):
        raise ValueError("hull_vertices must be a convex polygon")
    return v


def _pixel_ranges(centre, radius, half_extent, pixel, size):
    """First and last index of the pixel centres within ``centre ± radius``
    along one image axis (the axis' coordinate falls with the index)."""
    first = np.ceil((half_extent - (centre + radius)) / pixel - 0.5)
    last = np.floor((half_extent - (centre - radius)) / pixel - 0.5)
    first = np.clip(first, 0.0, size).astype(np.intp)
    last = np.clip(last, -1.0, size - 1.0).astype(np.intp)
    return first, last


def occupancy_image(ship_xy, heading: float, positions, radii, hull_vertices, goal_x: float,
                    *, size: int = 64, extent: float = 100.0, box_lengths=None,
                    periodic=(False, False)) -> np.ndarray:
    """Egocentric picture of ice, hull, goal distance and heading.

    Parameters
    ----------
    ship_xy : (2,) array_like
        Ship position [m], the centre of the image.
    heading : float
        Ship heading [rad, anticlockwise from +x], pointing up in the image.
    positions : (N, 2) array_like
        Floe centres [m].
    radii : (N,) array_like
        Floe radii [m], positive.
    hull_vertices : (K, 2) array_like
        The hull's corners in the world frame [m], convex, counter-clockwise.
    goal_x : float
        Position [m] of the goal line x = goal_x.
    size : int
        Image side in pixels, ≥ 8.
    extent : float
        Side [m] > 0 of the square the image covers.
    box_lengths : (2,) array_like, optional
        Box side lengths [m]; needed when an axis is periodic.
    periodic : (bool, bool)
        Periodicity along x and y (minimum-image displacements).

    Returns
    -------
    (4, size, size) uint8 array
        Channels ice, hull, goal and heading (see the module docstring).

    Raises
    ------
    ValueError
        An argument out of range or of the wrong shape; the message names it.
    """
    xy, heading = _check_pose(ship_xy, heading)
    p, r = _check_floes(positions, radii)
    hull = _check_hull(hull_vertices)
    check_range("goal_x", goal_x)
    size = _check_int("size", size, 8)
    check_range("extent", extent, 0.0, None, low_open=True)
    lengths, per = _check_box(box_lengths, periodic)
    extent = float(extent)

    image = np.zeros((4, size, size), dtype=np.uint8)
    half_extent = 0.5 * extent
    pixel = extent / size
    # ship-frame coordinate of the pixel centres: x along rows, y along columns
    centres = half_extent - (np.arange(size) + 0.5) * pixel
    c, s = math.cos(heading), math.sin(heading)

    # 0: ice, each nearby floe tested on the pixels of its bounding box only
    d, r = _nearby(xy, p, r, half_extent * math.sqrt(2.0), lengths, per)
    if r.size:
        fx = c * d[:, 0] + s * d[:, 1]
        fy = -s * d[:, 0] + c * d[:, 1]
        row0, row1 = _pixel_ranges(fx, r, half_extent, pixel, size)
        col0, col1 = _pixel_ranges(fy, r, half_extent, pixel, size)
        rows_n = np.maximum(row1 - row0 + 1, 0)
        cols_n = np.maximum(col1 - col0 + 1, 0)
        count = rows_n * cols_n
        if np.any(count):
            floe, local = _expand(np.arange(r.size), np.zeros_like(count), count - 1)
            width = cols_n[floe]
            rows = row0[floe] + local // width
            cols = col0[floe] + local % width
            ex = centres[rows] - fx[floe]
            ey = centres[cols] - fy[floe]
            inside = ex * ex + ey * ey <= r[floe] ** 2
            image[0, rows[inside], cols[inside]] = 255

    # 1: hull, pixel centres on the inner side of every edge
    v = _minimum_image(hull - xy, lengths, per)
    hx = c * v[:, 0] + s * v[:, 1]
    hy = -s * v[:, 0] + c * v[:, 1]
    row0, row1 = _pixel_ranges(0.5 * (hx.max() + hx.min()), 0.5 * (hx.max() - hx.min()),
                               half_extent, pixel, size)
    col0, col1 = _pixel_ranges(0.5 * (hy.max() + hy.min()), 0.5 * (hy.max() - hy.min()),
                               half_extent, pixel, size)
    if row0 <= row1 and col0 <= col1:
        px = centres[row0:row1 + 1][:, None]
        py = centres[col0:col1 + 1][None, :]
        inside = np.ones((row1 - row0 + 1, col1 - col0 + 1), dtype=bool)
        ex, ey = np.roll(hx, -1) - hx, np.roll(hy, -1) - hy
        for j in range(hx.size):
            inside &= ex[j] * (py - hy[j]) - ey[j] * (px - hx[j]) >= 0.0
        image[1, row0:row1 + 1, col0:col1 + 1][inside] = 255

    # 2: goal, a linear ramp of the distance to the line x = goal_x
    world_x = xy[0] + c * centres[:, None] - s * centres[None, :]
    gap = world_x - float(goal_x)
    if lengths is not None and per[0]:
        gap -= lengths[0] * np.floor(gap / lengths[0] + 0.5)
    ramp = 255.0 * (1.0 - np.abs(gap) / extent)
    image[2] = np.rint(np.clip(ramp, 0.0, 255.0)).astype(np.uint8)

    # 3: heading
    image[3] = min(int(round(255.0 * (heading % _TWO_PI) / _TWO_PI)), 255)
    return image
