"""Floe fields: the floe state as arrays, floe-size distributions and placement.

* :class:`FloeField` — positions (N, 2), velocities (N, 2), angular velocities
  (N,), radii, thicknesses, density and a frozen mask, with derived masses
  m = ρ h π r² and moments of inertia I = m r² / 2 (discs).
* :func:`rank_order_diameters` — the "most probable rank-ordered sample" of a
  power-law FSD (Herman 2011, appendix A; :ref:`physics-fsd`).
* :func:`sample_power_law_diameters` — seeded random sample of a truncated
  power law.
* :func:`domain_size` — side of the square (or a rectangle of given aspect)
  holding the floes at a target mean concentration.
* :func:`place_floes` — non-overlapping random positions: random sequential
  insertion, largest floes first; where insertion stalls, the floes are
  inserted at reduced size and grown back while overlaps are relaxed away.
* :func:`spatial_order` — a numbering of floes along a Z-order (Morton)
  curve, so that floes near in space are near in memory.
* :func:`make_floe_field` — all of the above in one call; its floes are
  numbered in :func:`spatial_order`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from .input_checks import check_range
from .domain import Box, PeriodicBox, minimum_image, wrap_coordinate
from .neighbors import choose_cell_size, pair_list, radius_rank

__all__ = [
    "FloeField",
    "rank_order_diameters",
    "sample_power_law_diameters",
    "power_law_diameters",
    "domain_size",
    "place_floes",
    "max_overlap",
    "make_floe_field",
    "spatial_order",
    "PlacementError",
]


class PlacementError(ValueError):
    """The requested concentration cannot be reached without overlaps."""


def _as_array(name, value, shape, dtype=float):
    a = np.array(value, dtype=dtype, copy=True)
    if a.ndim == 0 and shape != ():
        a = np.full(shape, a, dtype=dtype)
    if a.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {a.shape}")
    if dtype is float and not np.all(np.isfinite(a)):
        bad = np.argwhere(~np.isfinite(a))[0]
        raise ValueError(f"{name} must be finite; entry {tuple(bad)} is {a[tuple(bad)]}")
    return a


@dataclass
class FloeField:
    """The state of N floes as a structure of arrays (SI units).

    Parameters
    ----------
    positions : (N, 2) array — floe centres [m]
    radii : (N,) array — r_i [m], > 0
    thickness : (N,) array or float — h_i [m], > 0
    velocities : (N, 2) array, optional — u_i [m/s] (default 0)
    angular_velocities : (N,) array, optional — ω_i [rad/s] (default 0)
    density : float — ice density ρ [kg/m³], > 0
    frozen : (N,) bool array, optional — frozen floes never move but take part
        in contacts (e.g. fast ice along a coast)
    """

    positions: np.ndarray
    radii: np.ndarray
    thickness: np.ndarray | float = 1.5
    velocities: np.ndarray | None = None
    angular_velocities: np.ndarray | None = None
    density: float = 910.0
    frozen: np.ndarray | None = field(default=None)

    def __post_init__(self):
        r = np.array(self.radii, dtype=float, copy=True)
        if r.ndim != 1 or r.size == 0:
            raise ValueError(f"radii must be a non-empty 1-D array, got shape {r.shape}")
        n = r.size
        self.radii = _as_array("radii", r, (n,))
        if np.any(self.radii <= 0):
            i = int(np.argmin(self.radii))
            raise ValueError(f"radii must be > 0; floe {i} has radius {self.radii[i]}")
        self.positions = _as_array("positions", self.positions, (n, 2))
        self.thickness = _as_array("thickness", self.thickness, (n,))
        if np.any(self.thickness <= 0):
            i = int(np.argmin(self.thickness))
            raise ValueError(f"thickness must be > 0; floe {i} has thickness {self.thickness[i]}")
        self.velocities = _as_array("velocities", 0.0 if self.velocities is None else self.velocities, (n, 2))
        self.angular_velocities = _as_array(
            "angular_velocities", 0.0 if self.angular_velocities is None else self.angular_velocities, (n,))
        check_range("density", self.density, 0.0, None, low_open=True)
        self.density = float(self.density)
        self.frozen = _as_array("frozen", False if self.frozen is None else self.frozen, (n,), dtype=bool)
        self.velocities[self.frozen] = 0.0
        self.angular_velocities[self.frozen] = 0.0

    # -- derived quantities ---------------------------------------------------
    @property
    def n(self) -> int:
        return self.radii.size

    def __len__(self):
        return self.n

    @property
    def diameters(self) -> np.ndarray:
        return 2.0 * self.radii

    @property
    def areas(self) -> np.ndarray:
        """π r² [m²]."""
        return math.pi * self.radii ** 2

    @property
    def total_area(self) -> float:
        """F = Σ π r² [m²]."""
        return float(self.areas.sum())

    @property
    def masses(self) -> np.ndarray:
        """m = ρ h π r² [kg]."""
        return self.density * self.thickness * self.areas

    @property
    def inertia(self) -> np.ndarray:
        """I = m r² / 2 [kg m²]."""
        return 0.5 * self.masses * self.radii ** 2

    def concentration(self, box: Box) -> float:
        """Ice concentration A = F / S in ``box`` [-]."""
        return self.total_area / box.area

    def copy(self) -> FloeField:
        return FloeField(self.positions.copy(), self.radii.copy(), self.thickness.copy(),
                         self.velocities.copy(), self.angular_velocities.copy(),
                         self.density, self.frozen.copy())

    def take(self, order) -> FloeField:
        """A new field of the floes ``order`` (indices into this one), e.g. a
        renumbering by :func:`spatial_order`."""
        order = np.asarray(order)
        if order.ndim != 1 or not np.issubdtype(order.dtype, np.integer):
            raise ValueError(f"order must be a 1-D integer array, got {order.dtype} of shape "
                             f"{order.shape}")
        if order.size and (order.min() < -self.n or order.max() >= self.n):
            raise ValueError(f"order holds indices outside 0..{self.n - 1}")
        return FloeField(self.positions[order], self.radii[order], self.thickness[order],
                         self.velocities[order], self.angular_velocities[order],
                         self.density, self.frozen[order])


# ---------------------------------------------------------------------------
# Floe-size distributions (:ref:`physics-fsd`)
# ---------------------------------------------------------------------------

def _check_fsd(n, alpha, mean_diameter):
    check_range("n", n, 1, None)
    check_range("alpha", alpha, 0.0, None, low_open=True)
    check_range("mean_diameter", mean_diameter, 0.0, None, low_open=True)


def rank_order_diameters(n: int, alpha: float, mean_diameter: float) -> np.ndarray:
    """Most probable rank-ordered sample of P(d) ∝ d^(−1−α), largest first.

    d_n = [(α N + 1) / (α n + 1)]^(1/α), n = 1..N (Herman 2011, eq. A4),
    rescaled so that mean(d) = ``mean_diameter`` [m].
    """
    _check_fsd(n, alpha, mean_diameter)
    k = np.arange(1, n + 1, dtype=float)
    d = ((alpha * n + 1.0) / (alpha * k + 1.0)) ** (1.0 / alpha)
    return d * (mean_diameter / d.mean())


def sample_power_law_diameters(n: int, alpha: float, d_min: float, d_max: float,
                               rng: np.random.Generator) -> np.ndarray:
    """Random sample of the truncated power law P(d) ∝ d^(−1−α) on
    [d_min, d_max] by inversion of its CDF, sorted largest first [m]."""
    check_range("n", n, 1, None)
    check_range("alpha", alpha, 0.0, None, low_open=True)
    check_range("d_min", d_min, 0.0, None, low_open=True)
    check_range("d_max", d_max, d_min, None, low_open=True)
    u = rng.random(n)
    a, b = d_min ** (-alpha), d_max ** (-alpha)
    d = (a - u * (a - b)) ** (-1.0 / alpha)
    return np.sort(d)[::-1]


def power_law_diameters(n: int, alpha: float, mean_diameter: float, *, method: str = "rank",
                        size_ratio: float | None = None,
                        rng: np.random.Generator | None = None) -> np.ndarray:
    """Power-law floe diameters with a given mean, largest first [m].

    ``method="rank"`` gives the deterministic rank-ordered sample;
    ``method="random"`` samples the truncated power law with
    d_max / d_min = ``size_ratio`` (default: the ratio of the rank-ordered
    sample of the same N, ((αN + 1)/(α + 1))^(1/α)) and rescales to the mean.
    """
    if method == "rank":
        return rank_order_diameters(n, alpha, mean_diameter)
    if method != "random":
        raise ValueError(f"method must be 'rank' or 'random', got {method!r}")
    _check_fsd(n, alpha, mean_diameter)
    if rng is None:
        raise ValueError("method='random' needs a seeded rng (np.random.default_rng(seed))")
    if size_ratio is None:
        size_ratio = ((alpha * n + 1.0) / (alpha + 1.0)) ** (1.0 / alpha)
    check_range("size_ratio", size_ratio, 1.0, None)
    d = sample_power_law_diameters(n, alpha, 1.0, max(size_ratio, 1.0 + 1e-12), rng)
    return d * (mean_diameter / d.mean())


def domain_size(diameters, concentration: float, aspect: float = 1.0):
    """Box sides (Lx, Ly) holding floes of these diameters at mean
    concentration Ā: Lx Ly = π Σ d² / (4 Ā), Ly = aspect · Lx [m]."""
    check_range("concentration", concentration, 0.0, 1.0, low_open=True, high_open=True)
    check_range("aspect", aspect, 0.0, None, low_open=True)
    area = math.pi * float(np.sum(np.asarray(diameters) ** 2)) / (4.0 * concentration)
    lx = math.sqrt(area / aspect)
    return lx, aspect * lx


# ---------------------------------------------------------------------------
# Placement
# ---------------------------------------------------------------------------

@njit(cache=True)
def _rsa_insert(pos, radius, order, lx, ly, px, py, cell, max_attempts, seed, cap):
    """Random sequential insertion in ``order`` (largest first).

    A floe is stored in every cell its bounding square touches, so a candidate
    is checked against the floes stored in the cells its own square touches.
    Returns (placed mask, number placed, overflow flag).
    """
    np.random.seed(seed)
    n = radius.shape[0]
    ncx = max(1, int(lx / cell))
    ncy = max(1, int(ly / cell))
    wx = lx / ncx
    wy = ly / ncy
    items = np.empty((ncx * ncy, cap), dtype=np.int64)
    count = np.zeros(ncx * ncy, dtype=np.int64)
    placed = np.zeros(n, dtype=np.bool_)
    n_placed = 0
    for k in range(n):
        i = order[k]
        r = radius[i]
        ok = False
        x = 0.0
        y = 0.0
        for _ in range(max_attempts):
            x = r + np.random.random() * (lx - 2 * r) if not px else np.random.random() * lx
            y = r + np.random.random() * (ly - 2 * r) if not py else np.random.random() * ly
            ok = True
            cx0 = int(math.floor((x - r) / wx))
            cx1 = int(math.floor((x + r) / wx))
            cy0 = int(math.floor((y - r) / wy))
            cy1 = int(math.floor((y + r) / wy))
            for gy in range(cy0, cy1 + 1):
                if not py and (gy < 0 or gy >= ncy):
                    continue
                for gx in range(cx0, cx1 + 1):
                    if not px and (gx < 0 or gx >= ncx):
                        continue
                    c = (gy % ncy) * ncx + (gx % ncx)
                    for q in range(count[c]):
                        j = items[c, q]
                        dx = minimum_image(pos[j, 0] - x, lx, px)
                        dy = minimum_image(pos[j, 1] - y, ly, py)
                        rr = r + radius[j]
                        if dx * dx + dy * dy < rr * rr:
                            ok = False
                            break
                    if not ok:
                        break
                if not ok:
                    break
            if ok:
                break
        if not ok:
            continue
        pos[i, 0] = x
        pos[i, 1] = y
        placed[i] = True
        n_placed += 1
        cx0 = int(math.floor((x - r) / wx))
        cx1 = int(math.floor((x + r) / wx))
        cy0 = int(math.floor((y - r) / wy))
        cy1 = int(math.floor((y + r) / wy))
        if cx1 - cx0 + 1 > ncx:
            cx0, cx1 = 0, ncx - 1
        if cy1 - cy0 + 1 > ncy:
            cy0, cy1 = 0, ncy - 1
        for gy in range(cy0, cy1 + 1):
            if not py and (gy < 0 or gy >= ncy):
                continue
            for gx in range(cx0, cx1 + 1):
                if not px and (gx < 0 or gx >= ncx):
                    continue
                c = (gy % ncy) * ncx + (gx % ncx)
                if count[c] >= cap:
                    return placed, n_placed, True
                items[c, count[c]] = i
                count[c] += 1
    return placed, n_placed, False


@njit(cache=True)
def _relax_overlaps(pos, radius, weight, start, nbr, lx, ly, px, py, sweeps, overshoot):
    """Gauss–Seidel removal of overlaps: each overlapping pair is pushed apart
    along its normal by (1 + overshoot) times the overlap, shared in
    proportion to the other floe's area (large floes hardly move).

    Returns (largest overlap relative to the smaller radius after the last
    sweep, largest displacement of any floe).
    """
    n = radius.shape[0]
    start_pos = pos.copy()
    worst = 0.0
    for _ in range(sweeps):
        worst = 0.0
        for i in range(n):
            for p in range(start[i], start[i + 1]):
                j = nbr[p]
                dx = minimum_image(pos[j, 0] - pos[i, 0], lx, px)
                dy = minimum_image(pos[j, 1] - pos[i, 1], ly, py)
                d = math.sqrt(dx * dx + dy * dy)
                delta = radius[i] + radius[j] - d
                if delta <= 0.0:
                    continue
                rel = delta / min(radius[i], radius[j])
                if rel > worst:
                    worst = rel
                if d == 0.0:
                    dx, dy, d = 1.0, 0.0, 1.0
                s = delta * (1.0 + overshoot) / d
                wi = weight[j] / (weight[i] + weight[j])
                wj = 1.0 - wi
                pos[i, 0] -= wi * s * dx
                pos[i, 1] -= wi * s * dy
                pos[j, 0] += wj * s * dx
                pos[j, 1] += wj * s * dy
        for i in range(n):
            if px:
                pos[i, 0] = wrap_coordinate(pos[i, 0], lx, True)
            else:
                pos[i, 0] = min(max(pos[i, 0], radius[i]), lx - radius[i])
            if py:
                pos[i, 1] = wrap_coordinate(pos[i, 1], ly, True)
            else:
                pos[i, 1] = min(max(pos[i, 1], radius[i]), ly - radius[i])
        if worst == 0.0:
            break
    moved = 0.0
    for i in range(n):
        dx = minimum_image(pos[i, 0] - start_pos[i, 0], lx, px)
        dy = minimum_image(pos[i, 1] - start_pos[i, 1], ly, py)
        moved = max(moved, math.sqrt(dx * dx + dy * dy))
    return worst, moved


def max_overlap(positions, radii, box: Box) -> float:
    """Largest overlap between any two floes relative to the smaller radius
    (0 when no floes overlap). Uses the cell/Verlet machinery, O(N)."""
    pos = box.wrap(positions)
    r = np.asarray(radii, dtype=float)
    rank = radius_rank(r)
    cell = choose_cell_size(r, box.lx, box.ly, 0.0)
    start, nbr = pair_list(pos, r, rank, box.lx, box.ly, box.periodic[0], box.periodic[1], 0.0, cell)
    if nbr.size == 0:
        return 0.0
    owner = np.repeat(np.arange(len(r)), np.diff(start))
    d = box.minimum_image(pos[nbr] - pos[owner])
    dist = np.sqrt((d ** 2).sum(1))
    rel = (r[owner] + r[nbr] - dist) / np.minimum(r[owner], r[nbr])
    return float(max(rel.max(), 0.0))


def _check_fits(radii, box: Box):
    r_max = float(np.max(radii))
    for length, per, axis in ((box.lx, box.periodic[0], "x"), (box.ly, box.periodic[1], "y")):
        need = 4.0 * r_max if per else 2.0 * r_max
        if length <= need:
            raise PlacementError(
                f"the largest floe (radius {r_max:.4g} m) does not fit the box along {axis} "
                f"(side {length:.4g} m, needs more than {need:.4g} m"
                f"{' in a periodic box' if per else ''}); use more floes or a larger box")


def place_floes(radii, box: Box, rng: np.random.Generator, *, max_attempts: int = 200,
                growth_steps: int = 30) -> np.ndarray:
    """Random non-overlapping positions of floes with these radii in ``box``.

    1. Random sequential insertion with the largest floes first (up to
       ``max_attempts`` tries a floe). Broad power-law FSDs get far beyond the
       ≈ 0.55 of monodisperse discs this way because small floes fill the gaps.
    2. If a floe finds no room, insertion is repeated with all radii scaled
       down by a factor s until every floe fits, and the floes are then grown
       back to full size in ``growth_steps`` steps, overlaps being relaxed
       away after each step (large floes hardly move, small ones slip into the
       gaps). This is the "growth" protocol of Lubachevsky & Stillinger.

    Returns positions (N, 2) with no overlap at all. Raises :class:`PlacementError` when the
    concentration is impossible (A ≥ 1, a floe larger than the box) or when
    the growth jams before full size.
    """
    r = np.asarray(radii, dtype=float)
    if r.ndim != 1 or r.size == 0 or np.any(~np.isfinite(r)) or np.any(r <= 0):
        raise ValueError("radii must be a non-empty 1-D array of finite positive values")
    area = math.pi * float(np.sum(r ** 2))
    conc = area / box.area
    if conc >= 1.0:
        raise PlacementError(f"the floes cover {conc:.3f} of the box area; a concentration "
                             f"of 1 or more cannot be reached without overlaps")
    _check_fits(r, box)
    check_range("max_attempts", max_attempts, 1, None)
    px, py = box.periodic
    order = np.argsort(-r, kind="stable")
    cap = 64
    scale = 1.0
    while True:
        seed = int(rng.integers(2 ** 31 - 1))
        cell = max(2.0 * float(np.median(r)) * scale, math.sqrt(box.area / (4.0 * r.size)))
        pos = np.zeros((r.size, 2))
        placed, n_placed, overflow = _rsa_insert(pos, r * scale, order, box.lx, box.ly, px, py,
                                                 cell, int(max_attempts), seed, cap)
        if overflow:
            cap *= 2
            continue
        if n_placed == r.size:
            break
        scale *= 0.97
        if scale < 0.3:
            raise PlacementError(f"random insertion failed even at {scale:.2f} of full size")
    if scale == 1.0:
        return pos
    _grow(pos, r, scale, box, growth_steps)
    return pos


def _grow(pos, r, scale, box: Box, growth_steps: int) -> None:
    """Grow radii from ``scale`` to 1 in geometric steps, relaxing overlaps."""
    px, py = box.periodic
    weight = r ** 2
    rank = radius_rank(r)
    skin = 0.5 * float(np.min(r))
    cell = choose_cell_size(r, box.lx, box.ly, skin)
    # Sizes are inflated by 1e-3 and relaxed to overlaps below 1e-3 of the
    # smaller radius: at true size every pair then has a positive gap.
    inflate = 1e-3
    factors = (scale ** (1.0 - np.arange(1, growth_steps + 1) / growth_steps)) * (1.0 + inflate)
    for f in factors:
        rs = r * f
        tol = inflate
        for _ in range(400):
            start, nbr = pair_list(pos, rs, rank, box.lx, box.ly, px, py, skin, cell)
            worst, moved = _relax_overlaps(pos, rs, weight, start, nbr, box.lx, box.ly,
                                           px, py, 20, 1e-3)
            if worst <= tol and moved < 0.25 * skin:
                break
        else:
            raise PlacementError(
                f"overlaps could not be relaxed at {f:.4f} of full size (worst overlap "
                f"{worst:.2e} of the smaller radius): the concentration "
                f"{math.pi * np.sum(r ** 2) / box.area:.4f} is at or above jamming for this FSD")
    worst = max_overlap(pos, r, box)
    if worst > 0.0:
        raise PlacementError(f"placement left an overlap of {worst:.2e} of a radius")


def _spread_bits(v: np.ndarray) -> np.ndarray:
    """The 16 low bits of ``v`` moved to the even bit positions (0, 2, 4, ...)."""
    v = v.astype(np.uint64) & np.uint64(0xFFFF)
    for shift, mask in ((8, 0x00FF00FF), (4, 0x0F0F0F0F), (2, 0x33333333), (1, 0x55555555)):
        v = (v | (v << np.uint64(shift))) & np.uint64(mask)
    return v


def spatial_order(positions, box: Box, levels: int = 12) -> np.ndarray:
    """Indices that number floes along a Z-order (Morton) curve through the
    box, divided into 2^levels × 2^levels cells (ties keep their order).

    With this numbering, floes near in space are near in memory. The
    parallel kernels of the Hertz engine give each thread a consecutive run
    of floes; in Z order each run is a compact patch of the box (the floes of
    the lower half of the box come first, and among them those of its
    lower-left quarter), so a thread's contacts are mostly between its own
    floes and little memory moves between the cores. At N = 20000,
    Ā = 0.7, two threads ran about 1.3 times faster on a field in this
    order than on the same field numbered by size (2.26e8 against 1.74e8
    floe-steps/s, with the scalar kick pass of the engine at the time).
    """
    p = np.asarray(positions, dtype=float)
    if p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f"positions must have shape (N, 2), got {p.shape}")
    check_range("levels", levels, 1, 16)
    top = (1 << int(levels)) - 1
    ix = np.clip(np.floor(p[:, 0] / box.lx * (top + 1)), 0, top).astype(np.int64)
    iy = np.clip(np.floor(p[:, 1] / box.ly * (top + 1)), 0, top).astype(np.int64)
    key = _spread_bits(ix) | (_spread_bits(iy) << np.uint64(1))
    return np.argsort(key, kind="stable")


def make_floe_field(n: int, *, concentration: float, alpha: float, mean_diameter: float,
                    thickness: float = 1.5, density: float = 910.0, seed: int | None = 0,
                    fsd: str = "rank", aspect: float = 1.0, velocity_std: float = 0.0,
                    box_type=PeriodicBox, repeat: int = 1):
    """A floe field at a target concentration in a new box.

    Diameters from :func:`power_law_diameters` (``fsd`` = "rank" or "random"),
    each of the ``n`` repeated ``repeat`` times (n · repeat floes: the same
    sizes in a box ``sqrt(repeat)`` times wider), a box of the right size
    (:func:`domain_size`), non-overlapping placement (:func:`place_floes`)
    and Gaussian velocities of standard deviation ``velocity_std`` [m/s] per
    component; every random number comes from
    ``np.random.default_rng(seed)``. The floes are then numbered in
    :func:`spatial_order` (not by size: use ``np.argsort(-field.radii)`` for
    that order).

    Returns (field, box).
    """
    check_range("repeat", repeat, 1, None)
    if int(repeat) != repeat:
        raise ValueError(f"repeat must be a whole number, got {repeat!r}")
    rng = np.random.default_rng(seed)
    d = np.repeat(power_law_diameters(n, alpha, mean_diameter, method=fsd, rng=rng), int(repeat))
    lx, ly = domain_size(d, concentration, aspect)
    box = box_type(lx, ly)
    r = 0.5 * d
    pos = place_floes(r, box, rng)
    vel = (rng.normal(0.0, velocity_std, size=(d.size, 2)) if velocity_std > 0
           else np.zeros((d.size, 2)))
    field_ = FloeField(pos, r, thickness, vel, density=density)
    return field_.take(spatial_order(field_.positions, box)), box
