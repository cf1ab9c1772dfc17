"""Cell lists and Verlet (pair) lists for polydisperse floes.

Floe sizes span two orders of magnitude, so a cell list whose cells are as
wide as the largest interaction range (2 r_max + skin) would put thousands of
small floes in every cell. Instead the cells are sized for the *typical* floe
and every pair is found once, by its larger member:

* floes are ranked by radius (ties broken by index); the pair (i, j) is owned
  by the floe of higher rank, which has the larger radius;
* floe i scans the cells within ``2 r_i + skin`` of its centre, which covers
  every partner j of lower rank (cut-off ``r_i + r_j + skin ≤ 2 r_i + skin``);
* the work per floe is proportional to r_i², so the total is proportional to
  the floe area, i.e. to the number of cells: linear in N however wide the
  size distribution.

Lists are stored in CSR form (``start[i]:start[i+1]`` slices of ``nbr``, each
slice sorted by partner index), sized exactly by a counting pass, so nothing
can overflow or be truncated. The Mindlin history of a contact is carried
from one list to the next by a merge of the sorted slices.

A list built with skin s stays valid while, for every pair,
``|Δd_i − Δd_j| + (1 − scale)(r_i + r_j + s) < s`` where Δd are displacements
since the build and ``scale`` is the affine factor of a deforming box;
:func:`needs_rebuild` checks a sufficient form of this.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .domain import minimum_image

__all__ = ["radius_rank", "choose_cell_size", "build_cells", "build_pair_list",
           "brute_force_pairs", "transfer_history", "reverse_incidence"]


def radius_rank(radius: np.ndarray) -> np.ndarray:
    """Rank of each floe by (radius, index): the pair owner has the higher rank."""
    order = np.lexsort((np.arange(len(radius)), radius))
    rank = np.empty(len(radius), dtype=np.int64)
    rank[order] = np.arange(len(radius))
    return rank


def choose_cell_size(radius: np.ndarray, lx: float, ly: float, skin: float,
                     max_cells_per_floe: float = 4.0) -> float:
    """Cell width: about the interaction range of a typical (median) floe,
    enlarged if the grid would have more than ``max_cells_per_floe`` cells
    per floe (memory and the cost of empty cells)."""
    n = max(len(radius), 1)
    c = 2.0 * float(np.median(radius)) + skin
    c_min_for_memory = math.sqrt(lx * ly / (max_cells_per_floe * n))
    return max(c, c_min_for_memory, 1e-12)


@njit(cache=True, error_model="numpy")
def build_cells(pos, lx, ly, cell_size):
    """Counting-sort floes into a grid of cells.

    Returns (ncx, ncy, cell_start (ncx*ncy + 1,), cell_floes (N,), cell_of (N,)).
    Positions outside the box (floes pushed into a wall) go to the edge cells.
    """
    n = pos.shape[0]
    ncx = max(1, int(lx / cell_size))
    ncy = max(1, int(ly / cell_size))
    cell_of = np.empty(n, dtype=np.int64)
    counts = np.zeros(ncx * ncy + 1, dtype=np.int64)
    for i in range(n):
        cx = int(pos[i, 0] / lx * ncx)
        cy = int(pos[i, 1] / ly * ncy)
        cx = min(max(cx, 0), ncx - 1)
        cy = min(max(cy, 0), ncy - 1)
        c = cy * ncx + cx
        cell_of[i] = c
        counts[c + 1] += 1
    for c in range(ncx * ncy):
        counts[c + 1] += counts[c]
    cell_start = counts.copy()
    fill = counts[:-1].copy()
    cell_floes = np.empty(n, dtype=np.int64)
    for i in range(n):
        c = cell_of[i]
        cell_floes[fill[c]] = i
        fill[c] += 1
    return ncx, ncy, cell_start, cell_floes, cell_of


@njit(cache=True, inline="always", error_model="numpy")
def _axis_range(c, reach, cell_width, ncell, periodic):
    """First cell offset and count of cells to scan along one axis."""
    k = int(math.ceil(reach / cell_width))
    if 2 * k + 1 >= ncell:
        if periodic:
            return 0, ncell, True          # whole axis once, absolute indices
        return 0, ncell, True
    if periodic:
        return c - k, 2 * k + 1, False
    lo = max(c - k, 0)
    hi = min(c + k, ncell - 1)
    return lo, hi - lo + 1, True


@njit(cache=True, inline="always", error_model="numpy")
def _scan_floe(i, pos, radius, rank, lx, ly, px, py, skin, ncx, ncy, cell_start,
               cell_floes, cell_of, out, write_at):
    """Partners of floe i of lower rank within r_i + r_j + skin.

    Writes them at ``out[write_at:]`` when ``write_at >= 0``; returns the count.
    """
    xi = pos[i, 0]
    yi = pos[i, 1]
    ri = radius[i]
    reach = 2.0 * ri + skin
    ci = cell_of[i]
    cx = ci % ncx
    cy = ci // ncx
    x0, nx_, absx = _axis_range(cx, reach, lx / ncx, ncx, px)
    y0, ny_, absy = _axis_range(cy, reach, ly / ncy, ncy, py)
    count = 0
    rank_i = rank[i]
    for oy in range(ny_):
        gy = y0 + oy
        if not absy:
            gy = gy % ncy
        for ox in range(nx_):
            gx = x0 + ox
            if not absx:
                gx = gx % ncx
            c = gy * ncx + gx
            for q in range(cell_start[c], cell_start[c + 1]):
                j = cell_floes[q]
                if rank[j] >= rank_i:
                    continue
                dx = minimum_image(pos[j, 0] - xi, lx, px)
                dy = minimum_image(pos[j, 1] - yi, ly, py)
                cut = ri + radius[j] + skin
                if dx * dx + dy * dy < cut * cut:
                    if write_at >= 0:
                        out[write_at + count] = j
                    count += 1
    return count


@njit(cache=True, parallel=True, error_model="numpy")
def build_pair_list(pos, radius, rank, lx, ly, px, py, skin, cell_size):
    """Verlet list of all pairs with centre distance < r_i + r_j + skin.

    Each pair appears once, in the slice of its owner (higher rank).
    Returns (start (N+1,), nbr (M,)) with every slice sorted by partner index.
    Requires the largest cut-off to be below half of each periodic side
    (checked by the callers).
    """
    n = pos.shape[0]
    ncx, ncy, cell_start, cell_floes, cell_of = build_cells(pos, lx, ly, cell_size)
    counts = np.zeros(n + 1, dtype=np.int64)
    dummy = np.empty(0, dtype=np.int64)
    for i in prange(n):
        counts[i + 1] = _scan_floe(i, pos, radius, rank, lx, ly, px, py, skin,
                                   ncx, ncy, cell_start, cell_floes, cell_of, dummy, -1)
    start = np.cumsum(counts)
    nbr = np.empty(start[n], dtype=np.int64)
    for i in prange(n):
        s = start[i]
        m = _scan_floe(i, pos, radius, rank, lx, ly, px, py, skin,
                       ncx, ncy, cell_start, cell_floes, cell_of, nbr, s)
        # insertion sort of the slice by partner index (slices are short)
        for a in range(s + 1, s + m):
            v = nbr[a]
            b = a - 1
            while b >= s and nbr[b] > v:
                nbr[b + 1] = nbr[b]
                b -= 1
            nbr[b + 1] = v
    return start, nbr


def brute_force_pairs(pos, radius, box, skin):
    """All pairs (i < j) with centre distance < r_i + r_j + skin, by testing
    every pair (O(N²); for tests and tiny systems)."""
    pos = np.asarray(pos, dtype=float)
    d = box.minimum_image(pos[None, :, :] - pos[:, None, :])
    dist2 = (d ** 2).sum(-1)
    cut = radius[:, None] + radius[None, :] + skin
    i, j = np.nonzero(np.triu(dist2 < cut ** 2, k=1))
    return np.stack([i, j], axis=1)


@njit(cache=True, error_model="numpy")
def transfer_history(old_start, old_nbr, old_hist, new_start, new_nbr, ncomp):
    """Carry per-pair history (``old_hist`` (M_old, ncomp)) to a new list by a
    merge of the sorted slices; pairs new to the list start from zero."""
    n = new_start.shape[0] - 1
    new_hist = np.zeros((new_nbr.shape[0], ncomp))
    for i in range(n):
        a = old_start[i]
        a_end = old_start[i + 1]
        for b in range(new_start[i], new_start[i + 1]):
            j = new_nbr[b]
            while a < a_end and old_nbr[a] < j:
                a += 1
            if a < a_end and old_nbr[a] == j:
                for k in range(ncomp):
                    new_hist[b, k] = old_hist[a, k]
    return new_hist


@njit(cache=True, error_model="numpy")
def reverse_incidence(start, nbr, n):
    """For each floe j, the pair slots where j is the (non-owner) partner.

    Returns (rev_start (N+1,), rev_pair (M,)) in CSR form; used by the
    parallel force gather so that no thread writes another floe's slot.
    """
    m = nbr.shape[0]
    counts = np.zeros(n + 1, dtype=np.int64)
    for p in range(m):
        counts[nbr[p] + 1] += 1
    for j in range(n):
        counts[j + 1] += counts[j]
    rev_start = counts.copy()
    fill = counts[:-1].copy()
    rev_pair = np.empty(m, dtype=np.int64)
    for p in range(m):
        j = nbr[p]
        rev_pair[fill[j]] = p
        fill[j] += 1
    return rev_start, rev_pair


@njit(cache=True, error_model="numpy")
def owners_of(start):
    """Owner floe of every pair slot (the i of slot p)."""
    n = start.shape[0] - 1
    owner = np.empty(start[n], dtype=np.int64)
    for i in range(n):
        for p in range(start[i], start[i + 1]):
            owner[p] = i
    return owner
