"""Contact fabric and stress of a floe field (Herman 2013, eqs 10–11).

Both engines describe their contacts with the same :class:`Contacts` table:

* the Hertz engine (:meth:`HertzSimulation.contacts`) lists every touching
  floe pair with its contact forces;
* the hard-disc engine (:meth:`HardDiskSimulation.contacts`) lists the pairs
  closer than a small gap, without forces (hard discs touch only at the
  instants of collision); its stress comes from the collision impulses over
  a time window, :func:`collision_stress`.

From a contact table:

* :func:`fabric` — the fabric tensor R of the non-rattlers (floes with at
  least two contacts), Z_c = λ1 + λ2 (counted: contact ends on
  non-rattlers per non-rattler), Z_a = (λ1 − λ2)/Z_c, f_nr;
* :func:`stress` — the Love–Weber stress σ = −(1/S) Σ_c l_c ⊗ F_c, where l_c
  is the centre-to-centre (branch) vector from floe i to floe j and F_c the
  contact force on i. The sign makes **compression positive**: two floes
  pressed together push each other apart, F_c is antiparallel to l_c and
  σ has a positive trace. Units N/m (a two-dimensional sheet). The tensor
  is split into per-floe parts σ_i = −(1/S) Σ_{c ∋ i} b_ic ⊗ F_ic (b_ic the
  vector from the centre of i to the contact point) that add up to σ; a
  floe's own mean stress is σ_i S / (π r_i²).

Principal values of the symmetric part σ_s = (σ + σᵀ)/2 give the pressure
p = (σ1 + σ2)/2 and the maximum shear stress τ = (σ1 − σ2)/2.

Only floe–floe contacts enter; forces from the walls of a walled box do not.

Example
-------
>>> c = sim.contacts()                          # a HertzSimulation
>>> fab = fabric(c, sim.n_floes)
>>> fab.z_c, fab.z_a, fab.f_nr
>>> s = stress(c, sim.box.area, n_floes=sim.n_floes)
>>> s.pressure, s.shear, s.per_floe.shape       # (N, 2, 2)
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .input_checks import check_range
from .domain import Box
from .neighbors import choose_cell_size, pair_list, radius_rank

__all__ = ["Contacts", "Fabric", "Stress", "LocalIce", "fabric", "stress", "collision_stress",
           "near_pairs", "contacts_within", "check_positions"]


@dataclass
class Contacts:
    """Contacts at one instant, one row per floe pair.

    Attributes
    ----------
    i, j : (K,) int — the two floes
    normal : (K, 2) — unit vector from the centre of i to the centre of j
    overlap : (K,) — δ = r_i + r_j − |x_j − x_i| [m] (negative: a gap)
    normal_force : (K,) — magnitude of the repulsive normal force [N]
    tangential_force : (K,) — tangential force on i along t = k × n [N]
    force : (K, 2) — total contact force on i (−force acts on j) [N]
    contact_point : (K, 2) — the middle of the overlap (or gap), r_i − δ/2
        from the centre of i along n [m] (in the box's coordinates, possibly
        outside [0, L) near a periodic edge)
    branch_i, branch_j : (K, 2) — vectors from the centres of i and j to the
        contact point [m]; ``branch_i − branch_j = x_j − x_i``
    """

    i: np.ndarray
    j: np.ndarray
    normal: np.ndarray
    overlap: np.ndarray
    normal_force: np.ndarray
    tangential_force: np.ndarray
    force: np.ndarray
    contact_point: np.ndarray
    branch_i: np.ndarray
    branch_j: np.ndarray

    def __len__(self):
        return int(self.i.size)

    @staticmethod
    def branches(positions, radii, i, j, normal, overlap):
        """Contact points (the middle of the overlap δ, or of the gap if δ < 0)
        and the branch vectors from the centres of i and j to them."""
        arm_i = (radii[i] - 0.5 * overlap)[:, None] * normal
        arm_j = -(radii[j] - 0.5 * overlap)[:, None] * normal
        return positions[i] + arm_i, arm_i, arm_j

    @classmethod
    def from_geometry(cls, positions, radii, i, j, normal, distance, force=None):
        """Build a table from pair geometry: the contact point is the middle
        of the overlap (or gap); ``force`` (K, 2) is the force on i (zero if
        omitted), split into its normal and tangential parts."""
        i = np.asarray(i, dtype=np.int64)
        j = np.asarray(j, dtype=np.int64)
        normal = np.asarray(normal, dtype=float).reshape(-1, 2)
        radii = np.asarray(radii, dtype=float)
        delta = radii[i] + radii[j] - np.asarray(distance, dtype=float)
        point, arm_i, arm_j = cls.branches(np.asarray(positions, dtype=float), radii, i, j,
                                           normal, delta)
        f = np.zeros((i.size, 2)) if force is None else np.asarray(force, dtype=float).reshape(-1, 2)
        tangent = np.stack([-normal[:, 1], normal[:, 0]], axis=1)
        return cls(i=i, j=j, normal=normal, overlap=delta, normal_force=-np.sum(f * normal, axis=1),
                   tangential_force=np.sum(f * tangent, axis=1), force=f,
                   contact_point=point, branch_i=arm_i, branch_j=arm_j)


@dataclass
class Fabric:
    """Contact fabric of the non-rattlers (Herman 2013, eq 10).

    Attributes
    ----------
    tensor : (2, 2) — R = (1/N_n) Σ_{i non-rattler} Σ_{j ∈ C_i} n_ij ⊗ n_ij
    eigenvalues : (2,) — λ1 ≥ λ2
    z_c : float — λ1 + λ2 = tr R, mean number of contacts of a non-rattler;
        computed as the count ratio it is (the normals are unit vectors), so
        it is exact and the same for the same contact pairs on every machine
    z_a : float — (λ1 − λ2)/Z_c, 0 isotropic … 1 all contacts along one axis
        (0 when there are no non-rattlers)
    f_nr : float — fraction N_n/N of non-rattlers
    direction : float — angle of the principal axis of λ1 from the x axis
        [rad, in [0, π)]; NaN when isotropic or empty
    coordination : (N,) int — contacts per floe
    non_rattler : (N,) bool — floes with at least two contacts
    """

    tensor: np.ndarray
    eigenvalues: np.ndarray
    z_c: float
    z_a: float
    f_nr: float
    direction: float
    coordination: np.ndarray
    non_rattler: np.ndarray


@dataclass
class Stress:
    """Contact stress of a floe field, compression positive [N/m].

    Attributes
    ----------
    tensor : (2, 2) — the Love–Weber (or collision-virial) tensor σ
    principal : (2,) — σ1 ≥ σ2, eigenvalues of the symmetric part
    pressure : float — p = (σ1 + σ2)/2
    shear : float — τ = (σ1 − σ2)/2
    direction : float — angle of the σ1 axis from the x axis [rad, in
        [0, π)]; NaN when isotropic
    per_floe : (N, 2, 2) or None — per-floe parts, summing to ``tensor``
    area : float — the area S the stress is averaged over [m²]
    """

    tensor: np.ndarray
    principal: np.ndarray
    pressure: float
    shear: float
    direction: float
    per_floe: np.ndarray | None
    area: float


class LocalIce(NamedTuple):
    """The ice within a disc around a point (e.g. a ship), from
    :meth:`physics.HertzSimulation.local_ice`.

    Attributes
    ----------
    n_floes : int — floes whose centre lies in the disc
    floe_area : float — their area π Σ r² [m²]
    n_contacts : int — floe–floe contacts whose contact point lies in the disc
    stress : (2, 2) — the Love–Weber stress of these contacts over the
        disc's area, σ = −(1/S) Σ_c l_c ⊗ F_c as in :func:`stress`,
        compression positive [N/m]
    area : float — the disc's area S = π R² [m²]
    """

    n_floes: int
    floe_area: float
    n_contacts: int
    stress: np.ndarray
    area: float

    @property
    def pressure(self) -> float:
        """p = (σ1 + σ2)/2 = tr σ / 2 [N/m]."""
        return 0.5 * float(self.stress[0, 0] + self.stress[1, 1])


# -- input checks ---------------------------------------------------------------

def _check_area(area) -> float:
    check_range("area [m^2]", area, 0.0, None, low_open=True)
    return float(area)


def _check_count(name, n) -> int:
    if isinstance(n, bool) or int(n) != n or n < 0:
        raise ValueError(f"{name} must be a non-negative integer, got {n!r}")
    return int(n)


def _contact_arrays(contacts, names, n_floes=None):
    """The named (K,) or (K, 2) arrays of a contact table, checked."""
    try:
        i = np.asarray(contacts.i)
        j = np.asarray(contacts.j)
    except AttributeError:
        raise ValueError("contacts must be a Contacts table (attributes i, j, normal, ...)") from None
    if i.ndim != 1 or i.shape != j.shape:
        raise ValueError(f"contacts.i and contacts.j must be 1-D of equal length, got shapes "
                         f"{i.shape} and {j.shape}")
    if i.size and not (np.issubdtype(i.dtype, np.integer) and np.issubdtype(j.dtype, np.integer)):
        raise ValueError("contact indices i, j must be integers")
    k = i.size
    if k and (min(i.min(), j.min()) < 0
              or (n_floes is not None and max(i.max(), j.max()) >= n_floes)):
        raise ValueError(f"contact indices must lie in [0, {n_floes}), got "
                         f"[{min(i.min(), j.min())}, {max(i.max(), j.max())}]")
    out = []
    for name in names:
        a = np.asarray(getattr(contacts, name), dtype=float)
        if a.shape != (k, 2):
            raise ValueError(f"contacts.{name} must have shape ({k}, 2), got {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"contacts.{name} contains NaN or infinite values")
        out.append(a)
    return i.astype(np.int64, copy=False), j.astype(np.int64, copy=False), out


def check_positions(positions, radii=None):
    """(N, 2) finite positions and, if given, (N,) non-negative finite radii,
    as float arrays; ``ValueError`` otherwise."""
    pos = np.asarray(positions, dtype=float)
    if pos.ndim != 2 or pos.shape[1] != 2:
        raise ValueError(f"positions must have shape (N, 2), got {pos.shape}")
    if not np.all(np.isfinite(pos)):
        raise ValueError("positions contain NaN or infinite values")
    if radii is None:
        return pos
    r = np.asarray(radii, dtype=float)
    if r.shape != (pos.shape[0],):
        raise ValueError(f"radii must have shape ({pos.shape[0]},) to match positions, "
                         f"got {r.shape}")
    if not np.all(np.isfinite(r)) or np.any(r < 0):
        raise ValueError("radii must be finite and non-negative")
    return pos, r


# -- tensors ---------------------------------------------------------------------

def _principal(sym):
    """Eigenvalues (descending) of a symmetric 2×2 tensor and the angle of
    the first axis in [0, π) (NaN if the two are equal)."""
    a, b, d = sym[0, 0], sym[0, 1], sym[1, 1]
    mean = 0.5 * (a + d)
    rad = math.hypot(0.5 * (a - d), b)
    scale = max(abs(a), abs(b), abs(d))
    if rad <= 1e-12 * scale or scale == 0.0:
        angle = math.nan
    else:
        angle = (0.5 * math.atan2(2.0 * b, a - d)) % math.pi
    return np.array([mean + rad, mean - rad]), angle


def _outer_sum(u, v, weight=None):
    """Σ_k w_k u_k ⊗ v_k for (K, 2) arrays u, v."""
    if weight is not None:
        u = u * weight[:, None]
    return u.T @ v


def fabric(contacts, n_floes: int) -> Fabric:
    """Fabric tensor, Z_c, Z_a and f_nr of a contact table (Herman 2013 eq 10).

    Every contact counts once for each of its floes that is a non-rattler
    (has at least two contacts); rattlers and their contacts with other
    rattlers do not enter R.

    Z_c = tr R = λ1 + λ2 equals, since every normal is a unit vector, the
    number of contact ends on non-rattlers divided by N_n; it is computed
    from these two integers (one correctly rounded division), not from R,
    whose floating-point sums depend on the summation order (and so on the
    BLAS kernels of the machine). Z_a = (λ1 − λ2)/Z_c with
    λ1 − λ2 = 2 √(((R_xx − R_yy)/2)² + R_xy²) from R.
    """
    n = _check_count("n_floes", n_floes)
    i, j, (normal,) = _contact_arrays(contacts, ["normal"], n)
    coord = np.bincount(i, minlength=n) + np.bincount(j, minlength=n)
    nr = coord >= 2
    n_n = int(nr.sum())
    if n_n == 0:
        return Fabric(np.zeros((2, 2)), np.zeros(2), 0.0, 0.0, 0.0, math.nan,
                      coord.astype(np.int64), nr)
    ends = nr[i].astype(np.int64) + nr[j].astype(np.int64)     # contact ends on non-rattlers
    r = _outer_sum(normal, normal, ends.astype(float)) / n_n
    r = 0.5 * (r + r.T)
    lam, angle = _principal(r)
    z_c = int(ends.sum()) / n_n
    z_a = float((lam[0] - lam[1]) / z_c) if z_c > 0 else 0.0
    return Fabric(r, lam, z_c, z_a, n_n / n if n else 0.0, angle, coord.astype(np.int64), nr)


def _stress_from(tensor, per_floe, area) -> Stress:
    sym = 0.5 * (tensor + tensor.T)
    sig, angle = _principal(sym)
    return Stress(tensor, sig, float(0.5 * (sig[0] + sig[1])), float(0.5 * (sig[0] - sig[1])),
                  angle, per_floe, area)


def _per_floe(n, i, j, ui, vi, uj, vj, scale):
    """(N, 2, 2) Σ over a floe's contacts of scale · u ⊗ v, from the i ends
    (ui, vi) and the j ends (uj, vj)."""
    out = np.empty((n, 2, 2))
    for a in range(2):
        for b in range(2):
            out[:, a, b] = scale * (np.bincount(i, ui[:, a] * vi[:, b], minlength=n)
                                    + np.bincount(j, uj[:, a] * vj[:, b], minlength=n))
    return out


def stress(contacts, area: float, *, n_floes: int | None = None,
           per_floe: bool = True) -> Stress:
    """Love–Weber contact stress of a contact table over the area S (the
    box area for the mean stress of the sheet), compression positive.

    σ = −(1/S) Σ_c (b_i − b_j) ⊗ F_c with b_i, b_j the branch vectors of the
    contact from the centres of i and j, F_c the force on i. Per-floe parts
    are computed for ``n_floes`` floes (default: the largest index + 1)
    unless ``per_floe`` is False.
    """
    s = _check_area(area)
    if n_floes is not None:
        n_floes = _check_count("n_floes", n_floes)
    i, j, (f, bi, bj) = _contact_arrays(contacts, ["force", "branch_i", "branch_j"], n_floes)
    tensor = -_outer_sum(bi - bj, f) / s
    parts = None
    if per_floe:
        n = n_floes if n_floes is not None else (int(max(i.max(), j.max())) + 1 if i.size else 0)
        parts = _per_floe(n, i, j, bi, f, bj, -f, -1.0 / s)
    return _stress_from(tensor, parts, s)


def collision_stress(log, radii, area: float, duration: float, *,
                     per_floe: bool = True) -> Stress:
    """Collision-virial stress of the hard-disc engine over a time window,
    compression positive: σ = (1/(S T)) Σ_collisions (r_i + r_j) n ⊗ J,
    with J the impulse on j along the unit vector n from i to j at contact
    and T the window length (``duration``). Floe i takes the part r_i n ⊗ J,
    floe j the part r_j n ⊗ J.

    ``log`` is a :class:`physics.harddisk.CollisionLog` (or any object with
    arrays i, j and impulse (K, 2)).
    """
    s = _check_area(area)
    check_range("duration", duration, 0.0, None, low_open=True)
    t = float(duration)
    r = np.asarray(radii, dtype=float)
    if r.ndim != 1 or not np.all(np.isfinite(r)) or np.any(r < 0):
        raise ValueError("radii must be a 1-D array of finite non-negative values")
    i, j, (imp,) = _contact_arrays(log, ["impulse"], r.size)
    mag = np.hypot(imp[:, 0], imp[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        n = np.where(mag[:, None] > 0, imp / mag[:, None], 0.0)
    arm_i = r[i][:, None] * n
    arm_j = r[j][:, None] * n
    tensor = _outer_sum(arm_i + arm_j, imp) / (s * t)
    parts = _per_floe(r.size, i, j, arm_i, imp, arm_j, imp, 1.0 / (s * t)) if per_floe else None
    return _stress_from(tensor, parts, s)


# -- geometric contacts ----------------------------------------------------------

def near_pairs(positions, radii, box: Box, max_gap: float):
    """All floe pairs with an edge-to-edge distance below ``max_gap``
    (overlapping pairs included), periodic images included; cell lists,
    linear in N for any floe-size distribution.

    Returns (i, j, dx, dy, distance): the vector x_j − x_i (minimum image)
    and its length. Requires 2 r_max + max_gap below half of each periodic
    side (``ValueError`` otherwise).
    """
    pos, r = check_positions(positions, radii)
    check_range("max_gap [m]", max_gap, 0.0, None)
    gap = float(max_gap)
    if not isinstance(box, Box):
        raise ValueError(f"box must be a physics.domain Box, got {type(box).__name__}")
    n = r.size
    empty = np.empty(0, dtype=np.int64)
    if n < 2:
        return empty, empty, np.empty(0), np.empty(0), np.empty(0)
    reach = 2.0 * float(r.max()) + gap
    for length, per, axis in zip((box.lx, box.ly), box.periodic, "xy"):
        if per and reach >= 0.5 * length:
            raise ValueError(f"the pair range 2 r_max + gap = {reach:.4g} m must be below half the "
                             f"periodic box side along {axis} ({length:.4g} m)")
    wrapped = box.wrap(pos) if any(box.periodic) else pos
    lx, ly = float(box.lx), float(box.ly)
    px, py = box.periodic
    cell = choose_cell_size(r, lx, ly, gap)
    start, nbr = pair_list(wrapped, r, radius_rank(r), lx, ly, px, py, gap, cell)
    i = np.repeat(np.arange(n, dtype=np.int64), np.diff(start))
    j = nbr
    d = box.minimum_image(wrapped[j] - wrapped[i])
    dist = np.hypot(d[:, 0], d[:, 1])
    keep = dist - r[i] - r[j] < gap
    return i[keep], j[keep], d[keep, 0], d[keep, 1], dist[keep]


def contacts_within(positions, radii, box: Box, gap: float) -> Contacts:
    """Geometric contacts: the floe pairs whose edges are closer than ``gap``
    (touching or overlapping pairs included), without forces."""
    i, j, dx, dy, dist = near_pairs(positions, radii, box, gap)
    with np.errstate(invalid="ignore", divide="ignore"):
        normal = np.where(dist[:, None] > 0, np.stack([dx, dy], axis=1) / dist[:, None], 0.0)
    pos = np.asarray(positions, dtype=float)
    return Contacts.from_geometry(pos, radii, i, j, normal, dist)
