"""Ship hulls: rigid convex polygons, and where a floe touches one.

A hull is a convex polygon in the ship frame (x forward, y to port, origin
at the polygon's centroid after construction), its vertices counter-clockwise.
:func:`disc_hull_contact` finds, for one floe (a disc) and the hull placed in
the world, the overlap, the contact normal and the contact point from the
nearest feature of the polygon, an edge or a vertex; the contact law that
turns them into forces is that of the floe–floe contacts
(:mod:`physics.contact`).

Two hulls are ready-made:

``PSV_HULL``
    A full-scale platform supply vessel: length 76.2 m, beam 18 m, a
    parallel mid-body and a pointed bow.
``MODEL_HULL``
    A 1:45 model-scale hull: length 1.84 m, beam 0.38 m, the same plan form.

The plan form is our choice (the papers give the main dimensions only): a
rectangular mid-body with a flat stern and a symmetric bow, whose shoulders
start at 70 % of the length from the stern and narrow to the stem over the
last 30 %, with one knuckle at 85 % where the half-beam is 70 % of the full
half-beam. :meth:`Hull.pointed` builds others.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["Hull", "PSV_HULL", "MODEL_HULL", "disc_hull_contact", "FEATURE_NONE",
           "FEATURE_EDGE", "FEATURE_VERTEX"]

#: no contact
FEATURE_NONE = 0
#: the floe touches the inside of an edge (flat contact)
FEATURE_EDGE = 1
#: the floe touches a vertex (or its centre lies where a vertex is nearest)
FEATURE_VERTEX = 2


class Hull:
    """A rigid convex polygon in the ship frame.

    Parameters
    ----------
    vertices : (K, 2) array_like
        Corners in metres, counter-clockwise seen from above (x forward, y
        to port), K ≥ 3, strictly convex (no three in a line). They are
        shifted so that the centroid is the origin.
    name : str

    Raises
    ------
    ValueError
        Fewer than 3 vertices, non-finite coordinates, clockwise order, or a
        polygon that is not strictly convex; the message says which vertex.

    Examples
    --------
    >>> from physics.hull import Hull
    >>> h = Hull.box(10.0, 2.0)
    >>> round(h.area, 6), round(h.yaw_inertia(1200.0), 6)   # m (L² + B²) / 12
    (20.0, 10400.0)
    """

    def __init__(self, vertices, name: str = "hull"):
        v = np.asarray(vertices, dtype=float)
        if v.ndim != 2 or v.shape[1] != 2:
            raise ValueError(f"hull vertices must be a (K, 2) array, got shape {v.shape}")
        k = v.shape[0]
        if k < 3:
            raise ValueError(f"a hull needs at least 3 vertices, got {k}")
        if not np.all(np.isfinite(v)):
            raise ValueError("hull vertices must be finite")
        edges = np.roll(v, -1, axis=0) - v
        x0, y0, x1, y1, cross = _shoelace(v)
        area2 = float(np.sum(cross))
        if area2 < 0.0:
            raise ValueError("hull vertices run clockwise; give them counter-clockwise "
                             "(x forward, y to port), e.g. reversed")
        if area2 == 0.0:
            raise ValueError("hull vertices enclose no area")
        turn = edges[:, 0] * np.roll(edges[:, 1], -1) - edges[:, 1] * np.roll(edges[:, 0], -1)
        side = np.hypot(edges[:, 0], edges[:, 1])
        scale = side * np.roll(side, -1)
        bad = np.nonzero(turn <= 1e-12 * scale)[0]
        if bad.size:
            j = int((bad[0] + 1) % k)
            raise ValueError(f"the hull is not strictly convex at vertex {j} {tuple(v[j])}: "
                             f"give a convex polygon without repeated or collinear corners")
        centroid = np.array([np.sum((x0 + x1) * cross), np.sum((y0 + y1) * cross)]) / (3.0 * area2)
        self.vertices = v - centroid
        self.vertices.flags.writeable = False
        self.name = str(name)

    # -- construction -------------------------------------------------------
    @classmethod
    def box(cls, length: float, beam: float, name: str = "box") -> Hull:
        """A rectangle ``length`` × ``beam`` (a flat bow)."""
        _check_dimensions(length, beam)
        a, b = 0.5 * length, 0.5 * beam
        return cls([(-a, -b), (a, -b), (a, b), (-a, b)], name)

    @classmethod
    def pointed(cls, length: float, beam: float, *, shoulder: float = 0.7,
                knuckle: float = 0.85, knuckle_beam: float = 0.7,
                name: str = "pointed") -> Hull:
        """A flat stern, a parallel mid-body up to ``shoulder`` × length from
        the stern, and a bow narrowing to a stem, with one knuckle at
        ``knuckle`` × length where the half-beam is ``knuckle_beam`` × the
        half-beam (symmetric about the centre line)."""
        _check_dimensions(length, beam)
        if not 0.0 < shoulder < knuckle < 1.0:
            raise ValueError(f"need 0 < shoulder < knuckle < 1, got {shoulder}, {knuckle}")
        if not 0.0 < knuckle_beam < 1.0:
            raise ValueError(f"knuckle_beam must lie in (0, 1), got {knuckle_beam}")
        # convexity of the bow: the knuckle must lie outside the straight
        # line from the shoulder to the stem
        straight = (1.0 - knuckle) / (1.0 - shoulder)
        if knuckle_beam <= straight:
            raise ValueError(f"knuckle_beam must exceed {straight:.3g} for a convex bow")
        b = 0.5 * beam
        xs, xk, xe = shoulder * length, knuckle * length, length
        pts = [(0.0, -b), (xs, -b), (xk, -knuckle_beam * b), (xe, 0.0),
               (xk, knuckle_beam * b), (xs, b), (0.0, b)]
        return cls(pts, name)

    # -- geometry -----------------------------------------------------------
    @property
    def n_vertices(self) -> int:
        return self.vertices.shape[0]

    @property
    def area(self) -> float:
        """Plan area [m²]."""
        return 0.5 * float(np.sum(_shoelace(self.vertices)[4]))

    @property
    def length(self) -> float:
        """Extent along x [m]."""
        return float(np.ptp(self.vertices[:, 0]))

    @property
    def beam(self) -> float:
        """Extent along y [m]."""
        return float(np.ptp(self.vertices[:, 1]))

    @property
    def circumradius(self) -> float:
        """Largest distance of a vertex from the centroid [m]: the hull's
        reach in the neighbour search."""
        return float(np.max(np.hypot(self.vertices[:, 0], self.vertices[:, 1])))

    def yaw_inertia(self, mass: float) -> float:
        """Moment of inertia about the vertical axis through the centroid
        [kg m²] of a uniform plate of this plan form and ``mass`` [kg]."""
        if not (math.isfinite(mass) and mass > 0.0):
            raise ValueError(f"mass must be a positive number, got {mass!r}")
        x0, y0, x1, y1, cross = _shoelace(self.vertices)
        polar = float(np.sum(cross * (x0 * x0 + x0 * x1 + x1 * x1 + y0 * y0 + y0 * y1 + y1 * y1))) / 12.0
        return mass * polar / self.area

    def world_vertices(self, x: float, y: float, heading: float) -> np.ndarray:
        """(K, 2) corners in the world frame for the centroid at (x, y) and
        the bow pointing along ``heading`` [rad, anticlockwise from +x]."""
        c, s = math.cos(heading), math.sin(heading)
        v = self.vertices
        return np.column_stack((x + c * v[:, 0] - s * v[:, 1], y + s * v[:, 0] + c * v[:, 1]))

    def __repr__(self):
        return (f"Hull({self.name!r}, {self.n_vertices} vertices, length {self.length:.4g} m, "
                f"beam {self.beam:.4g} m)")


def _check_dimensions(length, beam):
    for name, value in (("length", length), ("beam", beam)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0.0):
            raise ValueError(f"{name} must be a positive number, got {value!r}")


def _shoelace(v):
    """Each corner (x0, y0), the next one (x1, y1), and x0 y1 − x1 y0: the
    terms of the polygon's area, centroid and second moment."""
    x0, y0 = v[:, 0], v[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    return x0, y0, x1, y1, x0 * y1 - x1 * y0


@njit(cache=True, error_model="numpy")
def disc_hull_contact(cx, cy, radius, vx, vy):
    """Where a disc touches a convex polygon.

    Parameters
    ----------
    cx, cy, radius : float
        The floe's centre and radius [m].
    vx, vy : (K,) float arrays
        The hull's corners in the world frame, counter-clockwise.

    Returns
    -------
    overlap : float
        δ = radius − (distance from the centre to the polygon), the
        distance counted negative when the centre is inside; δ ≤ 0 means no
        contact.
    nx, ny : float
        Unit normal from the hull towards the floe (the direction in which
        the hull pushes the floe).
    px, py : float
        Contact point: the middle of the overlap along the normal,
        ``(hull surface point) − n δ/2``.
    feature : int
        :data:`FEATURE_EDGE`, :data:`FEATURE_VERTEX`, or
        :data:`FEATURE_NONE` when δ ≤ 0.
    index : int
        The edge k (from corner k to corner k + 1) or the corner k.
    """
    k = vx.shape[0]
    best_d2 = math.inf
    best_x = 0.0
    best_y = 0.0
    best_feature = FEATURE_NONE
    best_index = -1
    inside = True
    depth = -math.inf          # largest signed distance over the edges' lines
    depth_edge = 0
    for a in range(k):
        b = a + 1 if a + 1 < k else 0
        ex = vx[b] - vx[a]
        ey = vy[b] - vy[a]
        len2 = ex * ex + ey * ey
        rx = cx - vx[a]
        ry = cy - vy[a]
        # outward normal of a counter-clockwise edge: (ey, -ex) / |e|
        signed = (rx * ey - ry * ex) / math.sqrt(len2)
        if signed > 0.0:
            inside = False
        if signed > depth:
            depth = signed
            depth_edge = a
        t = (rx * ex + ry * ey) / len2
        if t <= 0.0:
            qx, qy, feat, idx = vx[a], vy[a], FEATURE_VERTEX, a
        elif t >= 1.0:
            qx, qy, feat, idx = vx[b], vy[b], FEATURE_VERTEX, b
        else:
            qx, qy, feat, idx = vx[a] + t * ex, vy[a] + t * ey, FEATURE_EDGE, a
        dx = cx - qx
        dy = cy - qy
        d2 = dx * dx + dy * dy
        if d2 < best_d2:
            best_d2 = d2
            best_x = qx
            best_y = qy
            best_feature = feat
            best_index = idx
    if inside or best_d2 == 0.0:
        # centre inside the hull (or on its boundary): push out through the
        # nearest edge
        a = depth_edge
        b = a + 1 if a + 1 < k else 0
        ex = vx[b] - vx[a]
        ey = vy[b] - vy[a]
        le = math.sqrt(ex * ex + ey * ey)
        nx = ey / le
        ny = -ex / le
        overlap = radius - depth
        sx = cx - depth * nx
        sy = cy - depth * ny
        return overlap, nx, ny, sx - 0.5 * overlap * nx, sy - 0.5 * overlap * ny, FEATURE_EDGE, a
    d = math.sqrt(best_d2)
    overlap = radius - d
    nx = (cx - best_x) / d
    ny = (cy - best_y) / d
    feature = best_feature if overlap > 0.0 else FEATURE_NONE
    return (overlap, nx, ny, best_x - 0.5 * overlap * nx, best_y - 0.5 * overlap * ny, feature,
            best_index)


#: Full-scale platform supply vessel (76.2 m × 18 m, pointed bow).
PSV_HULL = Hull.pointed(76.2, 18.0, name="platform supply vessel")
#: 1:45 model-scale hull (1.84 m × 0.38 m), the same plan form.
MODEL_HULL = Hull.pointed(1.84, 0.38, name="1:45 model")

#: a research icebreaker of Araon's main dimensions (110 m × 19 m), with the
#: pointed waterline of the other hulls, not Araon's own lines
RESEARCH_HULL = Hull.pointed(110.0, 19.0, name="research icebreaker")
