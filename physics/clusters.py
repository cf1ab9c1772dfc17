"""Clusters, size distributions and pair distributions of a floe field
(Herman 2011, section IV and appendix A).

* :func:`find_clusters` — two floes belong to the same cluster when their
  edges are closer than ``max_gap`` (d_m, 0.5 m in the paper), periodic
  images included; cell lists and union–find, linear in N.
* :func:`cluster_statistics` — cluster sizes F_c,k = Σ π d_i²/4, effective
  radii r_e,k = (F_c,k/π)^½, the largest-cluster fraction F_c,1/F_tot and
  the maximum-likelihood exponent α of P(r_e) ∝ r_e^(−1−α).
* :func:`power_law_exponent`, :func:`exponent_series`, :func:`rank_order` —
  the rank-ordering statistics of appendix A, for floe sizes or clusters
  (:func:`fsd_exponent` fits the floe-size distribution of a sample).
* :func:`g_rdf` (centre to centre) and :func:`g_ffd` (edge to edge) — pair
  distributions normalised by an ideal-gas (Poisson) configuration of the
  same floes, so that uncorrelated positions give 1.

Example
-------
>>> labels = find_clusters(sim.positions, field.radii, box, max_gap=0.5)
>>> cs = cluster_statistics(labels, field.radii)
>>> cs.largest_fraction, cs.alpha, cs.alpha_error
>>> x, g = g_ffd(sim.positions, field.radii, box, x_max=5.0)
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from .input_checks import check_range
from .domain import Box
from .observables import check_positions, near_pairs

__all__ = ["find_clusters", "ClusterStats", "cluster_statistics", "PowerLawFit",
           "power_law_exponent", "exponent_series", "rank_order", "fsd_exponent",
           "g_rdf", "g_ffd"]


# -- clusters -------------------------------------------------------------------

@njit(cache=True, error_model="numpy")
def _find(parent, a):
    while parent[a] != a:
        parent[a] = parent[parent[a]]          # path halving
        a = parent[a]
    return a


@njit(cache=True, error_model="numpy")
def union_find_roots(n, i, j):
    """Root of each of n elements after joining the pairs (i[k], j[k]),
    by union by size with path halving; the root of a set is its smallest
    member."""
    parent = np.arange(n)
    size = np.ones(n, dtype=np.int64)
    for k in range(i.shape[0]):
        a = _find(parent, i[k])
        b = _find(parent, j[k])
        if a == b:
            continue
        if size[a] < size[b]:
            a, b = b, a
        parent[b] = a
        size[a] += size[b]
    root = np.empty(n, dtype=np.int64)
    smallest = np.full(n, n, dtype=np.int64)
    for a in range(n):
        r = _find(parent, a)
        root[a] = r
        if a < smallest[r]:
            smallest[r] = a
    for a in range(n):
        root[a] = smallest[root[a]]
    return root


def _labels_by_area(root, areas):
    """Cluster labels 0, 1, ... in order of decreasing cluster area (ties:
    the cluster with the smaller smallest member first)."""
    uniq, inverse = np.unique(root, return_inverse=True)
    area = np.bincount(inverse, weights=areas, minlength=uniq.size)
    order = np.lexsort((uniq, -area))
    rank = np.empty(uniq.size, dtype=np.int64)
    rank[order] = np.arange(uniq.size)
    return rank[inverse]


def find_clusters(positions, radii, box: Box, max_gap: float = 0.5) -> np.ndarray:
    """Cluster label of every floe: floes whose edge-to-edge distance
    ‖x_i − x_j‖ − r_i − r_j is below ``max_gap`` [m] are linked (overlapping
    floes too, and touching ones for any ``max_gap`` > 0), periodic images
    included, and clusters are the connected sets of links.

    Labels run 0 … N_c − 1 in order of decreasing cluster area (label 0 is the
    largest cluster). Near-linear in N: cell lists sized for the typical floe
    and union–find, never all pairs.
    """
    i, j, _, _, _ = near_pairs(positions, radii, box, max_gap)     # validates the input
    r = np.asarray(radii, dtype=float)
    root = union_find_roots(r.size, i, j)
    return _labels_by_area(root, np.pi * r * r)


@dataclass
class ClusterStats:
    """Cluster statistics of one snapshot (Herman 2011, section IV C).

    Attributes
    ----------
    labels : (N,) int — cluster of each floe, 0 the largest
    n_clusters : int
    area : (N_c,) — F_c,k = Σ_{i ∈ C_k} π d_i²/4 [m²], decreasing (rank order)
    effective_radius : (N_c,) — r_e,k = (F_c,k/π)^½ [m]
    n_members : (N_c,) int — floes per cluster
    largest_fraction : float — F_c,1 / F_tot
    alpha, alpha_error : float — ML exponent of P(r_e) ∝ r_e^(−1−α) from the
        sub-sample k … N_c of the rank-ordered r_e, and its standard error
        (NaN when fewer than two distinct sizes)
    """

    labels: np.ndarray
    n_clusters: int
    area: np.ndarray
    effective_radius: np.ndarray
    n_members: np.ndarray
    largest_fraction: float
    alpha: float
    alpha_error: float


def cluster_statistics(labels, radii, *, k: int = 1) -> ClusterStats:
    """Sizes, effective radii, largest-cluster fraction and the power-law
    exponent of the clusters ``labels`` (any non-negative integers, e.g. from
    :func:`find_clusters`) of floes with radii ``radii``; ``k`` is the first
    rank of the sub-sample used for the exponent (k = 1: all clusters). The
    returned labels are renumbered so that cluster m has area ``area[m]``."""
    lab = np.asarray(labels)
    r = np.asarray(radii, dtype=float)
    if lab.ndim != 1 or lab.shape != r.shape:
        raise ValueError(f"labels and radii must be 1-D of equal length, got {lab.shape} "
                         f"and {r.shape}")
    if not np.all(np.isfinite(r)) or np.any(r < 0):
        raise ValueError("radii must be finite and non-negative")
    if lab.size == 0:
        raise ValueError("no floes")
    if not np.issubdtype(lab.dtype, np.integer) or lab.min() < 0:
        raise ValueError("labels must be non-negative integers")
    if isinstance(k, bool) or int(k) != k or k < 1:
        raise ValueError(f"k must be a positive integer, got {k!r}")
    areas = np.pi * r * r
    lab = _labels_by_area(lab, areas)          # canonical: 0 is the largest cluster
    n_c = int(lab.max()) + 1
    f_c = np.bincount(lab, weights=areas, minlength=n_c)
    members = np.bincount(lab, minlength=n_c)
    r_e = np.sqrt(f_c / np.pi)
    total = float(areas.sum())
    alpha = err = math.nan
    if k < n_c and r_e[k - 1] > r_e[-1] > 0:   # at least two distinct sizes to fit
        fit = power_law_exponent(r_e, k=int(k))
        alpha, err = fit.alpha, fit.error
    return ClusterStats(lab, n_c, f_c, r_e, members,
                        float(f_c[0] / total) if total > 0 else math.nan, alpha, err)


# -- rank-ordering statistics (appendix A) ---------------------------------------

class PowerLawFit(NamedTuple):
    """ML exponent α of P(x) ∝ x^(−1−α) and its standard error Δα, from the
    ``n`` smallest values of the sample (ranks k … N). A sub-sample of
    one repeated value raises ``ValueError`` (:func:`exponent_series` gives
    inf there)."""
    alpha: float
    error: float
    k: int
    n: int


def rank_order(values):
    """Rank-ordered sample for rank-order plots: (x_1 ≥ x_2 ≥ … ≥ x_N, ranks
    1 … N). For a power law P(x) ∝ x^(−1−α), log n against log x_n is a
    straight line of slope −α."""
    x = np.asarray(values, dtype=float)
    if x.ndim != 1:
        raise ValueError(f"values must be 1-D, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError("values contain NaN or infinite numbers")
    return np.sort(x)[::-1].copy(), np.arange(1, x.size + 1)


def _ranked_positive(values):
    x, _ = rank_order(values)
    if x.size < 2:
        raise ValueError(f"a power-law fit needs at least two values, got {x.size}")
    if x[-1] <= 0:
        raise ValueError("power-law values must be positive")
    return x


def exponent_series(values):
    """α_k and Δα_k for every k = 1 … N − 1 (Herman 2011 eq A2): the ML
    exponent from the sub-sample x_k … x_N of the rank-ordered values,
    α_k = (N − k + 1) / Σ_{n=k..N} ln(x_n / x_N), Δα_k = α_k (N − k + 1)^(−½).

    Returns (k, alpha, error) arrays; α_k is infinite where the sub-sample
    has a single distinct value. Useful to see from which rank on a sample
    follows a power law.
    """
    x = _ranked_positive(values)
    n = x.size
    logs = np.log(x / x[-1])
    tail = np.cumsum(logs[::-1])[::-1][:-1]          # Σ_{n=k..N}, k = 1 … N − 1
    m = n - np.arange(n - 1)                          # N − k + 1
    with np.errstate(divide="ignore"):
        alpha = m / tail
    return np.arange(1, n), alpha, alpha / np.sqrt(m)


def power_law_exponent(values, k: int = 1) -> PowerLawFit:
    """ML exponent α of P(x) ∝ x^(−1−α) from the rank-ordered sub-sample
    x_k … x_N (Herman 2011 eq A2; k = 1 uses the whole sample, larger k
    leaves out the k − 1 largest values), with Δα = α (N − k + 1)^(−½)."""
    x = _ranked_positive(values)
    n = x.size
    if isinstance(k, bool) or int(k) != k or not 1 <= k < n:
        raise ValueError(f"k must be an integer in [1, {n - 1}], got {k!r}")
    k = int(k)
    s = float(np.sum(np.log(x[k - 1:] / x[-1])))
    if s <= 0:
        raise ValueError("all values of the sub-sample are equal: no power-law exponent")
    m = n - k + 1
    alpha = m / s
    return PowerLawFit(alpha, alpha / math.sqrt(m), k, m)


def fsd_exponent(diameters, k: int = 1) -> PowerLawFit:
    """Exponent α_r of a floe-size sample, P(d) ∝ d^(−1−α_r) (e.g. of a
    :class:`FloeField`'s diameters); see :func:`power_law_exponent`."""
    return power_law_exponent(diameters, k)


# -- pair distributions ----------------------------------------------------------

def _check_histogram(name, x_max, bins, box):
    check_range(f"{name} [m]", x_max, 0.0, None, low_open=True)
    xm = float(x_max)
    if isinstance(bins, bool) or int(bins) != bins or bins < 1:
        raise ValueError(f"bins must be a positive integer, got {bins!r}")
    if not isinstance(box, Box) or not all(box.periodic):
        raise ValueError("pair distributions need a doubly periodic box (a wall would bias "
                         "the normalisation)")
    return xm, int(bins)


def g_rdf(positions, box: Box, r_max: float, bins: int = 100):
    """Radial distribution function of floe centres, g(x) = (pairs at centre
    distance in [x, x + dx)) / (the same for an ideal gas of N points in the
    box, N(N − 1)/2 · 2πx dx / A). Returns (bin centres x [m], g).

    An uncorrelated (Poisson) configuration gives g ≈ 1; non-overlapping
    floes give g = 0 below the smallest contact distance and spikes near
    the radii of the largest floes (Herman 2011, Fig. 7).
    """
    pos = check_positions(positions)
    xm, nb = _check_histogram("r_max", r_max, bins, box)
    n = pos.shape[0]
    if n < 2:
        raise ValueError("g_rdf needs at least two floes")
    _, _, _, _, dist = near_pairs(pos, np.zeros(n), box, xm)
    edges = np.linspace(0.0, xm, nb + 1)
    counts, _ = np.histogram(dist, bins=edges)
    ideal = 0.5 * n * (n - 1) * np.pi * np.diff(edges ** 2) / box.area
    return 0.5 * (edges[1:] + edges[:-1]), counts / ideal


def g_ffd(positions, radii, box: Box, x_max: float, bins: int = 100):
    """Floe–floe distance distribution (Herman 2011, section IV B): the
    distribution of edge-to-edge distances x = ‖x_i − x_j‖ − r_i − r_j over
    [0, x_max), divided by its value for the same floes at uncorrelated
    (Poisson) positions, Σ_{i<j} 2π (x + r_i + r_j) dx / A. Returns (bin
    centres x [m], g).

    A random configuration gives g ≈ 1 (for non-overlapping floes, slightly
    more near x = 0 at high concentration); clusters raise g near 0 by up
    to an order of magnitude. Overlaps (x < 0) are not counted.
    """
    pos, r = check_positions(positions, radii)
    xm, nb = _check_histogram("x_max", x_max, bins, box)
    n = r.size
    if n < 2:
        raise ValueError("g_ffd needs at least two floes")
    i, j, _, _, dist = near_pairs(pos, r, box, xm)
    gap = dist - r[i] - r[j]
    edges = np.linspace(0.0, xm, nb + 1)
    counts, _ = np.histogram(gap, bins=edges)
    pairs = 0.5 * n * (n - 1)
    ideal = 2.0 * np.pi / box.area * (0.5 * pairs * np.diff(edges ** 2)
                                      + (n - 1) * float(r.sum()) * np.diff(edges))
    return 0.5 * (edges[1:] + edges[:-1]), counts / ideal
