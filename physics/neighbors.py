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

The skin may also be given per floe (an array ``s``): the pair (i, j) is
then listed within ``r_i + r_j + (s_i + s_j)/2``, and the list stays valid
while every floe has moved less than ``s_i/2`` (relative to a common
drift), because then ``|Δd_i − Δd_j| < (s_i + s_j)/2``. A fast floe can
carry a wide skin without widening every other floe's; the owner of a pair
scans ``2 r_i + (s_i + max s)/2``, which covers every partner of lower
rank. With one skin for all floes the lists are the same as with a scalar.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange, types
from numba.extending import overload

from .domain import minimum_image

__all__ = ["radius_rank", "choose_cell_size", "build_cells", "build_pair_list", "pair_list",
           "brute_force_pairs", "transfer_history"]


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
    for i in range(n):
        cx = int(pos[i, 0] / lx * ncx)
        cy = int(pos[i, 1] / ly * ncy)
        cx = min(max(cx, 0), ncx - 1)
        cy = min(max(cy, 0), ncy - 1)
        cell_of[i] = cy * ncx + cx
    cell_start, cell_floes = bucket_sort(cell_of, ncx * ncy)
    return ncx, ncy, cell_start, cell_floes, cell_of


@njit(cache=True, error_model="numpy")
def bucket_sort(keys, n_bins):
    """Counting sort of the items 0..M-1 by their ``keys`` (M,) in
    0..``n_bins``-1: (start (n_bins + 1,), order (M,)), the items of bin b
    being ``order[start[b]:start[b + 1]]``, in their order."""
    start = np.zeros(n_bins + 1, dtype=np.int64)
    for k in range(keys.shape[0]):
        start[keys[k] + 1] += 1
    for b in range(n_bins):
        start[b + 1] += start[b]
    fill = start[:-1].copy()
    order = np.empty(keys.shape[0], dtype=np.int64)
    for k in range(keys.shape[0]):
        b = keys[k]
        order[fill[b]] = k
        fill[b] += 1
    return start, order


N_CHUNKS = 64


def floe_skins(skin, n):
    """The skins of n floes: ``skin`` itself if it is an array, else n
    copies of the scalar (plain Python; compiled code uses the overload)."""
    if np.ndim(skin) == 0:
        return np.full(n, float(skin))
    return np.asarray(skin, dtype=float)


@overload(floe_skins)
def _floe_skins_overload(skin, n):
    if isinstance(skin, (types.Float, types.Integer)):
        return lambda skin, n: np.full(n, float(skin))
    return lambda skin, n: skin


@njit(cache=True, inline="always", error_model="numpy")
def _axis_range(c, reach, cell_width, ncell, periodic):
    """First cell and number of cells to scan along one axis. The first cell
    may be negative on a periodic axis (the caller wraps); a range longer
    than the axis is cut to the whole axis, visited once."""
    k = int(math.ceil(reach / cell_width))
    if 2 * k + 1 >= ncell:
        return 0, ncell
    if periodic:
        return c - k, 2 * k + 1
    lo = max(c - k, 0)
    hi = min(c + k, ncell - 1)
    return lo, hi - lo + 1


# modes of _scan_floes
COUNT, FILL, APPEND = 0, 1, 2


@njit(cache=True, error_model="numpy")
def _scan_floes(i_lo, i_hi, pos, radius, rank, lx, ly, px, py, skins, s_max, ncx, ncy,
                cell_start, cell_floes, cell_of, counts, start, out, mode, base, cap):
    """Partners of lower rank within r_i + r_j + (s_i + s_j)/2 of floes
    i_lo ≤ i < i_hi (``skins`` per floe, ``s_max`` their largest).

    ``mode`` COUNT: counts[i + 1] = number of partners. FILL: the partners
    of i written at out[start[i]:], sorted by index. APPEND: the partners of
    each floe in turn written one slice after the other from out[base] on,
    each slice sorted, and counts[i + 1] set; they must end before
    out[base + cap]. Returns the end of what APPEND wrote, or −1 if it
    would not fit (the other modes return ``base``).
    """
    wx = lx / ncx
    wy = ly / ncy
    end = base
    for i in range(i_lo, i_hi):
        xi = pos[i, 0]
        yi = pos[i, 1]
        ri = radius[i]
        rank_i = rank[i]
        si = skins[i]
        reach = 2.0 * ri + 0.5 * (si + s_max)
        ci = cell_of[i]
        x0, nxc = _axis_range(ci % ncx, reach, wx, ncx, px)
        y0, nyc = _axis_range(ci // ncx, reach, wy, ncy, py)
        if x0 < 0:
            x0 += ncx
        if y0 < 0:
            y0 += ncy
        count = 0
        at = start[i] if mode == FILL else end
        gy = y0
        for _ in range(nyc):
            if gy >= ncy:
                gy -= ncy
            row = gy * ncx
            gx = x0
            for _ in range(nxc):
                if gx >= ncx:
                    gx -= ncx
                c = row + gx
                for q in range(cell_start[c], cell_start[c + 1]):
                    j = cell_floes[q]
                    if rank[j] >= rank_i:
                        continue
                    dx = minimum_image(pos[j, 0] - xi, lx, px)
                    dy = minimum_image(pos[j, 1] - yi, ly, py)
                    cut = ri + radius[j] + 0.5 * (si + skins[j])
                    if dx * dx + dy * dy < cut * cut:
                        if mode != COUNT:
                            if mode == APPEND and at + count >= base + cap:
                                return -1
                            out[at + count] = j
                        count += 1
                gx += 1
            gy += 1
        if mode != COUNT:
            # insertion sort of the slice by partner index (slices are short)
            for a in range(at + 1, at + count):
                v = out[a]
                b = a - 1
                while b >= at and out[b] > v:
                    out[b + 1] = out[b]
                    b -= 1
                out[b + 1] = v
        if mode != FILL:
            counts[i + 1] = count
        if mode == APPEND:
            end += count
    return end


@njit(cache=True, error_model="numpy")
def _append_capacity(n, expected, n_chunks):
    """Room per chunk for the single pass of a list build: twice its share
    of ``expected`` pairs (the size of the previous list), four per floe,
    and a margin; a chunk that needs more makes the build fall back to a
    counting pass and a filling pass."""
    return (2 * expected + 4 * n) // n_chunks + 256


BLOCK = 32     # floes per block of a chunk of the parallel list build


@njit(cache=True, error_model="numpy")
def _scan_chunk(c, n, pos, radius, rank, lx, ly, px, py, skins, s_max, ncx, ncy, cell_start,
                cell_floes, cell_of, counts, start, out, mode, base, cap):
    """:func:`_scan_floes` over chunk c of the parallel build: the blocks
    c, c + N_CHUNKS, c + 2 N_CHUNKS, ... of ``BLOCK`` consecutive floes.
    Consecutive floes are neighbours in space when the floes are numbered in
    space, so a block reuses the cells it reads; and the few large floes,
    whose scans cost most, fall into blocks spread over all chunks and so
    over all threads. Returns the end of what APPEND wrote, or −1."""
    end = base
    for b in range(c * BLOCK, n, N_CHUNKS * BLOCK):
        end = _scan_floes(b, min(b + BLOCK, n), pos, radius, rank, lx, ly, px, py, skins, s_max,
                          ncx, ncy, cell_start, cell_floes, cell_of, counts, start, out, mode, end,
                          base + cap - end)
        if end < 0:
            return -1
    return end


@njit(cache=True, error_model="numpy")
def _copy_chunk(c, n, buf, base, start, nbr):
    """Copy the slices that chunk c (:func:`_scan_chunk`) appended to
    ``buf`` from ``base`` on to their places in ``nbr``."""
    at = base
    for b in range(c * BLOCK, n, N_CHUNKS * BLOCK):
        lo = start[b]
        hi = start[min(b + BLOCK, n)]
        nbr[lo:hi] = buf[at:at + hi - lo]
        at += hi - lo


@njit(cache=True, error_model="numpy")
def _all_fit(ends):
    """Whether every chunk's appended slices fit (no end is −1); a plain
    loop, since ``(ends >= 0).all()`` inside a parallel function would start
    a parallel region of its own."""
    for e in ends:
        if e < 0:
            return False
    return True


# not cached on disk: the Hertz step calls it from its own cached kernels
# (see the note in hertz_kernels.py); pair_list uses a cached copy
@njit(cache=False, parallel=True, error_model="numpy")
def build_pair_list(pos, radius, rank, lx, ly, px, py, skin, cell_size, expected=0):
    """Verlet list of all pairs with centre distance < r_i + r_j + skin.

    ``skin`` is one skin for all floes or an (N,) array of skins per floe
    (cut-off r_i + r_j + (s_i + s_j)/2, see the module notes).
    Each pair appears once, in the slice of its owner (higher rank).
    Returns (start (N+1,), nbr (M,)) with every slice sorted by partner index.
    Requires the largest cut-off to be below half of each periodic side
    (checked by the callers).

    The cells are scanned once, each chunk of floes appending its slices to
    a buffer of its own that is then copied into place; ``expected`` (the
    number of pairs of the previous list, if any) sizes the buffers. If a
    chunk's buffer is too small, the list is built by a counting pass and a
    filling pass instead (twice the scanning, the same list).
    """
    n = pos.shape[0]
    skins = floe_skins(skin, n)
    s_max = skins.max() if n > 0 else 0.0
    ncx, ncy, cell_start, cell_floes, cell_of = build_cells(pos, lx, ly, cell_size)
    counts = np.zeros(n + 1, dtype=np.int64)
    cap = _append_capacity(n, expected, N_CHUNKS)
    buf = np.empty(cap * N_CHUNKS, dtype=np.int64)
    ends = np.empty(N_CHUNKS, dtype=np.int64)
    for c in prange(N_CHUNKS):
        ends[c] = _scan_chunk(c, n, pos, radius, rank, lx, ly, px, py, skins, s_max, ncx, ncy,
                              cell_start, cell_floes, cell_of, counts, counts, buf, APPEND,
                              c * cap, cap)
    fit = _all_fit(ends)
    if not fit:
        for c in prange(N_CHUNKS):
            _scan_chunk(c, n, pos, radius, rank, lx, ly, px, py, skins, s_max, ncx, ncy,
                        cell_start, cell_floes, cell_of, counts, counts, buf, COUNT, 0, 0)
    start = np.cumsum(counts)
    nbr = np.empty(start[n], dtype=np.int64)
    for c in prange(N_CHUNKS):
        if fit:
            _copy_chunk(c, n, buf, c * cap, start, nbr)
        else:
            _scan_chunk(c, n, pos, radius, rank, lx, ly, px, py, skins, s_max, ncx, ncy,
                        cell_start, cell_floes, cell_of, counts, start, nbr, FILL, 0, 0)
    return start, nbr


@njit(cache=True, error_model="numpy")
def build_pair_list_serial(pos, radius, rank, lx, ly, px, py, skin, cell_size, expected=0):
    """:func:`build_pair_list` on the calling thread only (for the serial
    engine path, which must not wake a thread pool). With one chunk the
    appended slices are already in floe order: the buffer is the list."""
    n = pos.shape[0]
    skins = floe_skins(skin, n)
    s_max = skins.max() if n > 0 else 0.0
    ncx, ncy, cell_start, cell_floes, cell_of = build_cells(pos, lx, ly, cell_size)
    counts = np.zeros(n + 1, dtype=np.int64)
    cap = _append_capacity(n, expected, 1)
    buf = np.empty(cap, dtype=np.int64)
    end = _scan_floes(0, n, pos, radius, rank, lx, ly, px, py, skins, s_max, ncx, ncy, cell_start,
                      cell_floes, cell_of, counts, counts, buf, APPEND, 0, cap)
    if end >= 0:
        return np.cumsum(counts), buf[:end].copy()
    _scan_floes(0, n, pos, radius, rank, lx, ly, px, py, skins, s_max, ncx, ncy, cell_start,
                cell_floes, cell_of, counts, counts, counts, COUNT, 0, 0)
    start = np.cumsum(counts)
    nbr = np.empty(start[n], dtype=np.int64)
    _scan_floes(0, n, pos, radius, rank, lx, ly, px, py, skins, s_max, ncx, ncy, cell_start,
                cell_floes, cell_of, counts, start, nbr, FILL, 0, 0)
    return start, nbr


PARALLEL_MIN_FLOES = 5000   # smaller fields are scanned on the calling thread

# build_pair_list compiled for calls from Python only, cached on disk
_build_pair_list_cached = njit(cache=True, parallel=True, error_model="numpy")(
    build_pair_list.py_func)


def pair_list(pos, radius, rank, lx, ly, px, py, skin, cell_size):
    """:func:`build_pair_list` for large fields, :func:`build_pair_list_serial`
    below ``PARALLEL_MIN_FLOES`` floes: waking the thread pool costs more
    than the scan of a small field, and a process that never starts the
    OpenMP pool can still be forked safely (``gymnasium.make_vec`` with
    ``vectorization_mode="async"``)."""
    big = pos.shape[0] >= PARALLEL_MIN_FLOES
    build = _build_pair_list_cached if big else build_pair_list_serial
    return build(pos, radius, rank, lx, ly, px, py, skin, cell_size)


def brute_force_pairs(pos, radius, box, skin):
    """All pairs (i < j) with centre distance < r_i + r_j + skin (or
    r_i + r_j + (s_i + s_j)/2 with skins per floe), by testing every pair
    (O(N²); for tests and tiny systems)."""
    pos = np.asarray(pos, dtype=float)
    d = box.minimum_image(pos[None, :, :] - pos[:, None, :])
    dist2 = (d ** 2).sum(-1)
    skins = floe_skins(skin, len(radius))
    cut = radius[:, None] + radius[None, :] + 0.5 * (skins[:, None] + skins[None, :])
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
