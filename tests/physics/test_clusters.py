"""Clusters of floes against hand-built configurations and a brute-force
union-find, the rank-ordering (maximum-likelihood) power-law exponents of
Herman (2011, appendix A) on samples of known power laws, and the pair
distributions g_rdf and g_ffd against Poisson configurations and an
all-pairs histogram."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from physics import (ChannelBox, FloeField, PeriodicBox, WalledBox, make_floe_field,
                     sample_power_law_diameters)
from physics.clusters import (ClusterStats, PowerLawFit, cluster_statistics, exponent_series,
                              find_clusters, fsd_exponent, g_ffd, g_rdf, power_law_exponent,
                              rank_order)
from physics.floes import max_overlap
from physics.neighbors import brute_force_pairs
from physics.observables import near_pairs


# ---------------------------------------------------------------------------
# Helpers
# ---------------------------------------------------------------------------

def partition(labels):
    """The clusters of a labelling as a set of frozensets of floe indices."""
    groups = {}
    for i, lab in enumerate(np.asarray(labels).tolist()):
        groups.setdefault(lab, set()).add(i)
    return {frozenset(g) for g in groups.values()}


def reference_partition(pos, radii, box, max_gap):
    """Clusters by brute force: every pair with centre distance below
    r_i + r_j + max_gap (edge gap below max_gap, minimum image) from the
    O(N^2) brute_force_pairs, joined by a plain-Python union-find."""
    n = len(radii)
    parent = list(range(n))

    def find(a):
        while parent[a] != a:
            a = parent[a]
        return a

    for i, j in brute_force_pairs(np.asarray(pos, dtype=float), np.asarray(radii, dtype=float),
                                  box, max_gap).tolist():
        a, b = find(i), find(j)
        if a != b:
            parent[max(a, b)] = min(a, b)
    groups = {}
    for i in range(n):
        groups.setdefault(find(i), set()).add(i)
    return {frozenset(g) for g in groups.values()}


def canonical(labels):
    """Relabel every floe by the smallest index of its cluster: two
    labellings describe the same partition iff their canonical forms agree."""
    lab = np.asarray(labels)
    smallest = np.full(lab.max() + 1, lab.size)
    np.minimum.at(smallest, lab, np.arange(lab.size))
    return smallest[lab]


def assert_label_order(labels, radii):
    """Labels are exactly 0 ... N_c - 1, cluster areas (sum of pi r^2) do not
    increase with the label, and clusters of exactly equal area are ordered
    by their smallest member."""
    lab = np.asarray(labels)
    n_c = lab.max() + 1
    assert np.array_equal(np.unique(lab), np.arange(n_c))
    area = np.array([math.fsum(np.pi * np.asarray(radii)[lab == c] ** 2) for c in range(n_c)])
    # fsum is exact to rounding, so 1e-12 relative only absorbs that rounding
    assert np.all(area[:-1] >= area[1:] * (1.0 - 1e-12))
    first = np.array([np.flatnonzero(lab == c)[0] for c in range(n_c)])
    ties = area[:-1] == area[1:]
    assert np.all(first[:-1][ties] < first[1:][ties])


def random_floes(rng, n, box, radii="power"):
    """Uniformly random (overlapping) positions in the box with power-law
    (diameters 1-12 m, alpha = 1.8, shuffled) or uniform (0.5-3 m) radii."""
    if radii == "power":
        r = 0.5 * sample_power_law_diameters(n, 1.8, 1.0, 12.0, rng)
        rng.shuffle(r)
    else:
        r = rng.uniform(0.5, 3.0, n)
    pos = rng.random((n, 2)) * np.array([box.lx, box.ly])
    return pos, r


def pareto(rng, n, alpha, x_min=1.0):
    """Pareto sample P(x) ∝ x^(-1-alpha) on [x_min, inf): x = x_min U^(-1/alpha),
    U uniform on (0, 1]."""
    return x_min * (1.0 - rng.random(n)) ** (-1.0 / alpha)


# ---------------------------------------------------------------------------
# Clusters: hand-built configurations
# ---------------------------------------------------------------------------

def boundary_floes(L=20.0):
    """Seven floes in a square of side L:
    0, 1 (r = 1) at x = 1.1 and x = L - 1.1: edge gap 0.2 only across x = 0/L;
    2, 3 (r = 1) at y = 1.1 and y = L - 1.1: edge gap 0.2 only across y = 0/L;
    4, 5 (r = 0.6) at (0.5, 0.5) and (L - 0.5, L - 0.5): centre distance
         sqrt(2), edge gap 0.214, only through the corner (both axes wrapped);
    6 (r = 1) alone in the middle."""
    pos = np.array([[1.1, 8.0], [L - 1.1, 8.0], [10.0, 1.1], [10.0, L - 1.1],
                    [0.5, 0.5], [L - 0.5, L - 0.5], [10.0, 10.0]])
    radii = np.array([1.0, 1.0, 1.0, 1.0, 0.6, 0.6, 1.0])
    return pos, radii


def test_clusters_across_periodic_boundaries():
    """Floes within max_gap = 0.5 of each other only through a periodic edge
    (x, y, or the corner, both axes at once) form one cluster in a periodic
    box; in a walled box the same positions are seven isolated floes; in a
    channel (periodic along x only) only the pair across x = 0/L is joined.
    Exact partitions."""
    pos, radii = boundary_floes()
    f = frozenset
    assert partition(find_clusters(pos, radii, PeriodicBox(20.0))) == {
        f({0, 1}), f({2, 3}), f({4, 5}), f({6})}
    assert partition(find_clusters(pos, radii, WalledBox(20.0))) == {f({k}) for k in range(7)}
    assert partition(find_clusters(pos, radii, ChannelBox(20.0))) == {
        f({0, 1}), f({2}), f({3}), f({4}), f({5}), f({6})}


def test_periodic_clusters_are_translation_invariant():
    """Shifting every floe by the same vector (here by whole and fractional
    box lengths, so that many floes land outside [0, L)) leaves the labels
    of a periodic configuration unchanged, exactly: the partition and the
    area order do not depend on where the box edges are."""
    pos, radii = boundary_floes()
    box = PeriodicBox(20.0)
    ref = find_clusters(pos, radii, box)
    for shift in ([7.3, -2.9], [-40.0 + 0.25, 60.0 - 0.6], [3 * 20.0, 0.0]):
        assert np.array_equal(find_clusters(pos + np.array(shift), radii, box), ref)


def chain(gaps, radii, origin, angle):
    """Centres of floes in a straight line at ``angle``: floe k + 1 sits
    r_k + gaps[k] + r_{k+1} beyond floe k (edge-to-edge gap gaps[k])."""
    step = np.asarray(radii[:-1]) + np.asarray(gaps) + np.asarray(radii[1:])
    s = np.concatenate([[0.0], np.cumsum(step)])
    return np.asarray(origin) + s[:, None] * np.array([math.cos(angle), math.sin(angle)])


CHAIN_RADII = np.array([1.0, 2.5, 0.4, 1.7, 0.9, 3.0, 0.6, 1.2, 0.5])


@pytest.mark.parametrize("max_gap", [0.5, 0.05, 0.0])
@pytest.mark.parametrize("box", [PeriodicBox(200.0), WalledBox(200.0, 150.0)], ids=["periodic",
                                                                                 "walled"])
def test_chain_is_one_cluster_and_breaks_at_max_gap(max_gap, box):
    """Nine floes of radii 0.4-3 m in a tilted straight chain, each edge
    max_gap - (0.05 ... 0.3) m from the next (overlapping for max_gap = 0):
    one cluster although the ends are tens of metres apart. Making one
    middle gap max_gap + 1e-9 splits the chain exactly there, max_gap - 1e-9
    keeps it whole (the link test is on the edge gap, strict < max_gap;
    positions are ~1e2 m, so rounding is ~1e-13 m, far below 1e-9)."""
    u = np.array([0.05, 0.3, 0.1, 0.25, 0.15, 0.2, 0.12, 0.28])
    gaps = max_gap - u
    pos = chain(gaps, CHAIN_RADII, origin=(60.0, 40.0), angle=0.6)
    n = len(CHAIN_RADII)
    # set-up: non-adjacent floes are at least 0.2 m beyond max_gap (the
    # smallest floe, 0.8 m across, separates them), ends 19-23 m apart
    d = np.hypot(*(pos[:, None, :] - pos[None, :, :]).transpose(2, 0, 1))
    edge = d - CHAIN_RADII[:, None] - CHAIN_RADII[None, :]
    far = np.abs(np.subtract.outer(np.arange(n), np.arange(n))) >= 2
    assert edge[far].min() > max_gap + 0.2 and edge[0, -1] > 15.0

    assert partition(find_clusters(pos, CHAIN_RADII, box, max_gap)) == {frozenset(range(n))}
    for m in (3, 5):
        above, below = gaps.copy(), gaps.copy()
        above[m] = max_gap + 1e-9
        below[m] = max_gap - 1e-9
        split = find_clusters(chain(above, CHAIN_RADII, (60.0, 40.0), 0.6), CHAIN_RADII, box,
                              max_gap)
        assert partition(split) == {frozenset(range(m + 1)), frozenset(range(m + 1, n))}
        whole = find_clusters(chain(below, CHAIN_RADII, (60.0, 40.0), 0.6), CHAIN_RADII, box,
                              max_gap)
        assert partition(whole) == {frozenset(range(n))}


def test_isolated_floes_are_their_own_clusters():
    """Floes on a 10 m grid with radii up to 3 m (edge gaps >= 4 m > max_gap):
    N clusters, labelled by decreasing radius (area); equal radii are
    labelled by index; equal areas in pairs by index within each area.
    A single floe is cluster 0 and no floe gives no labels."""
    rng = np.random.default_rng(3)
    xs, ys = np.meshgrid(np.arange(5) * 10.0 + 5.0, np.arange(4) * 10.0 + 5.0)
    pos = np.stack([xs.ravel(), ys.ravel()], axis=1)
    box = PeriodicBox(50.0, 40.0)
    radii = rng.uniform(0.5, 3.0, 20)
    labels = find_clusters(pos, radii, box)
    assert np.array_equal(labels, np.argsort(np.argsort(-radii)))   # rank by decreasing radius
    assert np.array_equal(find_clusters(pos, np.ones(20), box), np.arange(20))
    labels = find_clusters(pos[:4], [1.0, 2.0, 1.0, 2.0], box)
    assert np.array_equal(labels, [2, 0, 3, 1])
    assert np.array_equal(find_clusters([[3.0, 4.0]], [1.0], box), [0])
    assert find_clusters(np.zeros((0, 2)), np.zeros(0), box).size == 0


def test_label_zero_is_the_largest_area_not_the_most_floes():
    """Ten 1 m floes in a chain (area 10 pi) and two 3 m floes 0.2 m apart
    (area 18 pi): the pair is cluster 0, the chain cluster 1. Two clusters
    of exactly equal area, {12, 15} and {13, 14} (radii 1.5 and 0.5 each),
    follow in the order of their smallest member (12 before 13) although
    {12, 15} has the larger largest member; the three isolated 1 m floes
    (area pi each) come last, by index."""
    small = [0, 1, 2, 4, 5, 6, 8, 9, 10, 11]
    n = 19
    pos = np.zeros((n, 2))
    radii = np.ones(n)
    pos[small] = chain(np.full(9, 0.2), np.ones(10), (5.0, 10.0), 0.0)
    radii[[3, 7]] = 3.0
    pos[[3, 7]] = [[50.0, 50.0], [56.2, 50.0]]
    radii[[12, 13, 14, 15]] = [1.5, 1.5, 0.5, 0.5]
    pos[[12, 15]] = [[10.0, 80.0], [10.0 + 1.5 + 0.3 + 0.5, 80.0]]
    pos[[13, 14]] = [[40.0, 80.0], [40.0 + 1.5 + 0.3 + 0.5, 80.0]]
    pos[[16, 17, 18]] = [[80.0, 20.0], [80.0, 50.0], [80.0, 80.0]]
    labels = find_clusters(pos, radii, PeriodicBox(100.0))
    expected = np.empty(n, dtype=int)
    expected[[3, 7]] = 0
    expected[small] = 1
    expected[[12, 15]] = 2
    expected[[13, 14]] = 3
    expected[[16, 17, 18]] = [4, 5, 6]
    assert np.array_equal(labels, expected)
    assert_label_order(labels, radii)


# ---------------------------------------------------------------------------
# Clusters: random configurations against brute force
# ---------------------------------------------------------------------------

RANDOM_CASES = [
    pytest.param(lambda: PeriodicBox(110.0), 600, "power", 0.5, 1, id="square-power-0.5"),
    pytest.param(lambda: PeriodicBox(110.0), 800, "power", 1.3, 2, id="square-power-1.3"),
    pytest.param(lambda: PeriodicBox(150.0, 60.0), 500, "uniform", 1.0, 3, id="rect-uniform-1.0"),
    pytest.param(lambda: PeriodicBox(60.0, 140.0), 400, "power", 0.0, 4, id="rect-power-0"),
    pytest.param(lambda: WalledBox(90.0, 130.0), 800, "power", 0.3, 5, id="walled-power-0.3"),
    pytest.param(lambda: WalledBox(80.0), 300, "uniform", 0.7, 6, id="walled-uniform-0.7"),
    pytest.param(lambda: ChannelBox(120.0, 70.0), 500, "power", 0.5, 7, id="channel-power-0.5"),
]


def random_configuration(make_box, n, radii, seed):
    """A random configuration with a few floes exactly on the box edges and
    corners and, in a walled box, a few pushed slightly through a wall."""
    box = make_box()
    rng = np.random.default_rng([17, seed])
    pos, r = random_floes(rng, n, box, radii)
    pos[:4] = [[0.0, 0.0], [box.lx * (1 - 1e-12), 0.5 * box.ly], [0.5 * box.lx, 0.0],
               [box.lx * (1 - 1e-12), box.ly * (1 - 1e-12)]]
    if not box.periodic[1]:
        pos[4:6] = [[0.3 * box.lx, -0.4], [0.6 * box.lx, box.ly + 0.2]]
    return box, pos, r


@pytest.mark.parametrize("make_box, n, radii, max_gap, seed", RANDOM_CASES)
def test_random_clusters_equal_brute_force_union_find(make_box, n, radii, max_gap, seed):
    """300-800 random overlapping floes (power-law or uniform radii) in
    square and rectangular periodic boxes, a channel and walled boxes, with
    max_gap from 0 to 1.3 m: the partition of find_clusters equals, as a set
    of sets, the union-find of all brute-force pairs with edge gap below
    max_gap; labels follow the area order; the inputs are not modified. The
    cases are non-trivial: both isolated floes and clusters of >= 5 floes."""
    box, pos, r = random_configuration(make_box, n, radii, seed)
    pos0, r0 = pos.copy(), r.copy()
    labels = find_clusters(pos, r, box, max_gap)
    assert labels.shape == (n,) and np.issubdtype(labels.dtype, np.integer)
    expected = reference_partition(pos, r, box, max_gap)
    assert partition(labels) == expected
    sizes = sorted(len(c) for c in expected)
    assert sizes[0] == 1 and sizes[-1] >= 5 and len(expected) < n
    assert_label_order(labels, r)
    assert np.array_equal(pos, pos0) and np.array_equal(r, r0)


# ---------------------------------------------------------------------------
# Cluster statistics
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("make_box, n, radii, max_gap, seed", RANDOM_CASES[:3] + RANDOM_CASES[4:5])
def test_cluster_statistics_of_random_configurations(make_box, n, radii, max_gap, seed):
    """For find_clusters labels: the cluster areas are the per-label sums of
    pi r^2 (label k = area[k]) and add up to the total floe area (1e-12
    relative; only summation order differs), r_e = sqrt(area/pi) (1e-14),
    n_members counts the floes of each label and sums to N, the largest
    fraction is area[0]/total, and alpha, alpha_error are the power-law fit
    of r_e (1e-12; with k = 1 and k = 3)."""
    box, pos, r = random_configuration(make_box, n, radii, seed)
    labels = find_clusters(pos, r, box, max_gap)
    total = math.fsum(np.pi * r ** 2)
    for k in (1, 3):
        cs = cluster_statistics(labels, r, k=k)
        assert isinstance(cs, ClusterStats)
        assert np.array_equal(cs.labels, labels)
        assert cs.n_clusters == labels.max() + 1 == cs.area.size
        per_label = np.array([math.fsum(np.pi * r[labels == c] ** 2)
                              for c in range(cs.n_clusters)])
        np.testing.assert_allclose(cs.area, per_label, rtol=1e-12, atol=0)
        assert math.fsum(cs.area) == pytest.approx(total, rel=1e-12)
        np.testing.assert_allclose(cs.effective_radius, np.sqrt(cs.area / np.pi), rtol=1e-14)
        assert np.array_equal(cs.n_members, np.bincount(labels))
        assert cs.n_members.sum() == n
        assert cs.largest_fraction == pytest.approx(cs.area[0] / total, rel=1e-12)
        fit = power_law_exponent(np.sqrt(per_label / np.pi), k=k)
        assert cs.alpha == pytest.approx(fit.alpha, rel=1e-12)
        assert cs.alpha_error == pytest.approx(fit.error, rel=1e-12)


def test_cluster_statistics_of_isolated_floes():
    """Isolated floes: every cluster is one floe, so the areas are pi r^2 in
    decreasing order, r_e are the radii largest first (1e-14), all
    n_members are 1, the largest fraction is max r^2 / sum r^2 (1e-12) and
    alpha is the exponent of the floe sizes (alpha is scale-free, so that
    of the diameters, fsd_exponent, to 1e-12)."""
    rng = np.random.default_rng(8)
    xs, ys = np.meshgrid(np.arange(10) * 10.0 + 5.0, np.arange(8) * 10.0 + 5.0)
    pos = np.stack([xs.ravel(), ys.ravel()], axis=1)
    radii = 0.5 * sample_power_law_diameters(80, 1.5, 1.0, 6.0, rng)
    rng.shuffle(radii)
    cs = cluster_statistics(find_clusters(pos, radii, PeriodicBox(100.0, 80.0)), radii)
    assert cs.n_clusters == 80
    assert np.all(cs.n_members == 1)
    np.testing.assert_allclose(cs.effective_radius, np.sort(radii)[::-1], rtol=1e-14)
    np.testing.assert_allclose(cs.area, np.pi * np.sort(radii)[::-1] ** 2, rtol=1e-14)
    assert cs.largest_fraction == pytest.approx(radii.max() ** 2 / np.sum(radii ** 2), rel=1e-12)
    fit = fsd_exponent(2.0 * radii)
    assert cs.alpha == pytest.approx(fit.alpha, rel=1e-12)
    assert cs.alpha_error == pytest.approx(fit.error, rel=1e-12)


def test_cluster_statistics_of_arbitrary_labels_and_one_cluster():
    """Labels need not be 0 ... N_c - 1: labels {9: radii 1, 1, 1; 2: radius
    2; 5: radius 0.5} give areas 4 pi, 3 pi, 0.25 pi in that order with 1, 3,
    1 members (1e-14), largest fraction 4/7.25, labels renumbered to match;
    an invalid k is an error, not a NaN. One cluster: fraction 1 and no
    exponent (NaN, a single size)."""
    cs = cluster_statistics(np.array([9, 2, 9, 5, 9]), [1.0, 2.0, 1.0, 0.5, 1.0])
    assert cs.n_clusters == 3
    np.testing.assert_allclose(cs.area, np.pi * np.array([4.0, 3.0, 0.25]), rtol=1e-14)
    assert np.array_equal(cs.n_members, [1, 3, 1])
    assert cs.largest_fraction == pytest.approx(4.0 / 7.25, rel=1e-14)
    # returned labels are renumbered so that cluster m has area area[m]
    assert np.array_equal(cs.labels, [1, 0, 1, 2, 1])
    for bad_k in (0, 1.5, True):
        with pytest.raises(ValueError, match="k must be"):
            cluster_statistics(np.array([9, 2, 9, 5, 9]), [1.0, 2.0, 1.0, 0.5, 1.0], k=bad_k)
    one = cluster_statistics(np.zeros(4, dtype=int), [1.0, 2.0, 3.0, 0.5])
    assert one.n_clusters == 1 and one.largest_fraction == 1.0
    assert math.isnan(one.alpha) and math.isnan(one.alpha_error)


# ---------------------------------------------------------------------------
# Rank-ordering statistics and power-law exponents
# ---------------------------------------------------------------------------

def test_power_law_exponent_by_hand():
    """x = (1, 8, 2, 4) (any order): sum ln(x_n/x_N) = 6 ln 2, so
    alpha_1 = 4/(6 ln 2), Delta = alpha_1/2; alpha_2 = 3/(3 ln 2) (drops 8),
    Delta = alpha_2/sqrt(3); alpha_3 = 2/ln 2, Delta = alpha_3/sqrt(2)
    (1e-14). rank_order gives (8, 4, 2, 1) and ranks 1-4, leaving its input
    alone; exponent_series gives the same three values."""
    x = np.array([1.0, 8.0, 2.0, 4.0])
    ln2 = math.log(2.0)
    expected = {1: 4 / (6 * ln2), 2: 3 / (3 * ln2), 3: 2 / ln2}
    for k, a in expected.items():
        fit = power_law_exponent(x, k)
        assert isinstance(fit, PowerLawFit)
        assert fit.alpha == pytest.approx(a, rel=1e-14)
        assert fit.error == pytest.approx(a / math.sqrt(5 - k), rel=1e-14)
        assert (fit.k, fit.n) == (k, 5 - k)
    ranked, ranks = rank_order(x)
    assert np.array_equal(ranked, [8.0, 4.0, 2.0, 1.0]) and np.array_equal(ranks, [1, 2, 3, 4])
    assert np.array_equal(x, [1.0, 8.0, 2.0, 4.0])
    ks, alpha, err = exponent_series(x)
    assert np.array_equal(ks, [1, 2, 3])
    np.testing.assert_allclose(alpha, [expected[1], expected[2], expected[3]], rtol=1e-14)
    np.testing.assert_allclose(err, alpha / np.sqrt([4, 3, 2]), rtol=1e-14)


@pytest.mark.parametrize("alpha, seed", [(0.8, 11), (1.5, 12), (2.5, 13)])
def test_power_law_exponent_recovers_pareto_alpha(alpha, seed):
    """N = 2000 Pareto values (x_min = 0.3): the ML exponent is alpha within
    two standard errors (a 95 % interval; the estimator's bias, 2/N
    relative, is 0.1 standard error). The estimate does not depend on the
    order of the sample or the unit of x (exactly the same sums up to
    rounding: 1e-12)."""
    rng = np.random.default_rng(seed)
    x = pareto(rng, 2000, alpha, x_min=0.3)
    fit = power_law_exponent(x)
    assert (fit.k, fit.n) == (1, 2000)
    assert fit.error == pytest.approx(fit.alpha / math.sqrt(2000), rel=1e-14)
    assert abs(fit.alpha - alpha) < 2.0 * fit.error
    assert power_law_exponent(rng.permutation(x)).alpha == fit.alpha
    assert power_law_exponent(37.0 * x).alpha == pytest.approx(fit.alpha, rel=1e-12)


def test_power_law_exponent_error_is_calibrated():
    """Over 200 seeded Pareto samples of N = 500 with alpha = 1.5, the
    fraction of estimates within 2 Delta-alpha of the truth is in
    [0.90, 0.99]. Exactly (Renyi's representation: sum ln(x_n/x_N) =
    Gamma(N - 1)/alpha) the probability is P(|1 - G/N| < 2/sqrt(N)) for
    G ~ Gamma(N - 1), 0.95 to 0.01 and independent of alpha; 200 samples
    give a binomial standard deviation of 0.015, so the band is > 3 sigma
    below and > 2.5 sigma above."""
    n, alpha = 500, 1.5
    p = (stats.gamma.cdf(n + 2 * math.sqrt(n), n - 1)
         - stats.gamma.cdf(n - 2 * math.sqrt(n), n - 1))
    assert p == pytest.approx(0.95, abs=0.01)
    rng = np.random.default_rng(2011)
    hits = 0
    for _ in range(200):
        fit = power_law_exponent(pareto(rng, n, alpha))
        hits += abs(fit.alpha - alpha) < 2.0 * fit.error
    assert 0.90 <= hits / 200 <= 0.99


def test_exponent_series_equals_power_law_exponent():
    """exponent_series gives, for every k = 1 ... N - 1, the same alpha_k and
    error as power_law_exponent(x, k) (checked at k = 1, 2, 17, 500, N - 1;
    1e-12, the sums are accumulated in a different order); the series has
    N - 1 entries, and it is infinite where the sub-sample is one repeated
    value."""
    rng = np.random.default_rng(21)
    x = pareto(rng, 1000, 1.7)
    ks, alpha, err = exponent_series(x)
    assert np.array_equal(ks, np.arange(1, 1000))
    for k in (1, 2, 17, 500, 999):
        fit = power_law_exponent(x, k)
        assert alpha[k - 1] == pytest.approx(fit.alpha, rel=1e-12)
        assert err[k - 1] == pytest.approx(fit.error, rel=1e-12)
    _, alpha, _ = exponent_series([3.0, 1.0, 1.0])
    assert alpha[0] == pytest.approx(3.0 / math.log(3.0), rel=1e-14) and math.isinf(alpha[1])


def truncated_alpha_limit(alpha, ratio):
    """Large-N limit of the ML estimator for P(d) ∝ d^(-1-alpha) truncated to
    [d_min, ratio d_min]: 1/E[ln(d/d_min)], with
    E[ln(d/d_min)] = 1/alpha - ln(R) R^-alpha / (1 - R^-alpha)."""
    tail = ratio ** -alpha
    return 1.0 / (1.0 / alpha - math.log(ratio) * tail / (1.0 - tail))


@pytest.mark.parametrize("alpha, d_max, seed", [(0.8, 1e6, 31), (1.5, 1e4, 32), (2.5, 1e2, 33)])
def test_fsd_exponent_of_sampled_floe_field(alpha, d_max, seed):
    """Diameters of a FloeField from sample_power_law_diameters(2000, alpha,
    1 m, d_max): fsd_exponent recovers alpha within 2.5 standard errors.
    The estimator assumes an untruncated tail; the cut at d_max biases it
    upwards (truncated_alpha_limit), so d_max is chosen per alpha to keep
    that bias below 0.1 standard error (asserted). Using x_N instead of
    d_min costs ~1/(alpha N) in ln x, negligible too."""
    n = 2000
    bias = truncated_alpha_limit(alpha, d_max) / alpha - 1.0
    assert 0.0 < bias < 0.1 / math.sqrt(n)
    rng = np.random.default_rng(seed)
    d = sample_power_law_diameters(n, alpha, 1.0, d_max, rng)
    field = FloeField(rng.random((n, 2)) * 1e4, 0.5 * d)
    fit = fsd_exponent(field.diameters)
    assert abs(fit.alpha - alpha) < 2.5 * fit.error
    assert fit == power_law_exponent(field.diameters)


def test_fsd_exponent_sees_the_truncation_bias():
    """A strongly truncated sample (alpha = 1.5, d_max/d_min = 10, N = 20000):
    the estimate is the truncated limit 1/E[ln(d/d_min)] = 1.691 within
    three standard errors (the reported error alpha/sqrt(N) overestimates
    the spread of a truncated sample, so this is conservative), and more
    than ten standard errors above the alpha of the law, 1.5 — the ML
    exponent is only unbiased for an untruncated tail."""
    rng = np.random.default_rng(41)
    d = sample_power_law_diameters(20000, 1.5, 1.0, 10.0, rng)
    fit = fsd_exponent(d)
    limit = truncated_alpha_limit(1.5, 10.0)
    assert limit == pytest.approx(1.6907, abs=1e-4)
    assert abs(fit.alpha - limit) < 3.0 * fit.error
    assert fit.alpha - 1.5 > 10.0 * fit.error


# ---------------------------------------------------------------------------
# Pair distributions
# ---------------------------------------------------------------------------

def all_pair_geometry(pos, radii, box):
    """Minimum-image centre distances and radius sums r_i + r_j of all pairs
    i < j (O(N^2))."""
    d = box.minimum_image(pos[None, :, :] - pos[:, None, :])
    iu, ju = np.triu_indices(len(pos), k=1)
    dist = np.sqrt(d[iu, ju, 0] ** 2 + d[iu, ju, 1] ** 2)
    return dist, radii[iu] + radii[ju]


def ideal_rdf_counts(n, edges, area):
    """Expected pair counts per bin for N uniform independent points on a
    torus (bins below half the shortest side): N(N-1)/2 pi (x2^2 - x1^2)/A."""
    return 0.5 * n * (n - 1) * np.pi * np.diff(edges ** 2) / area


def ideal_ffd_counts(sums, edges, area):
    """Expected pair counts per edge-gap bin [x1, x2) for uniform independent
    points: sum over pairs of pi ((x2 + s)^2 - (x1 + s)^2)/A, s = r_i + r_j
    (the annulus of centre distances [x1 + s, x2 + s))."""
    return np.array([np.sum(np.pi * ((x2 + sums) ** 2 - (x1 + sums) ** 2)) / area
                     for x1, x2 in zip(edges[:-1], edges[1:])])


@pytest.mark.parametrize("box", [PeriodicBox(70.0), PeriodicBox(90.0, 50.0)],
                         ids=["square", "rectangle"])
def test_pair_distributions_equal_all_pairs_histogram(box):
    """400 random overlapping floes: g_rdf and g_ffd equal the all-pairs
    histogram of minimum-image centre distances (resp. edge gaps >= 0,
    overlaps excluded) divided by the ideal-gas counts computed pair by pair
    (1e-12 relative; bin centres exact to 1e-15)."""
    rng = np.random.default_rng(51)
    pos, r = random_floes(rng, 400, box)
    dist, sums = all_pair_geometry(pos, r, box)
    edges = np.linspace(0.0, 12.0, 25)
    x, g = g_rdf(pos, box, 12.0, 24)
    np.testing.assert_allclose(x, 0.5 * (edges[1:] + edges[:-1]), rtol=0, atol=1e-15)
    counts, _ = np.histogram(dist, bins=edges)
    np.testing.assert_allclose(g, counts / ideal_rdf_counts(400, edges, box.area), rtol=1e-12)
    edges = np.linspace(0.0, 6.0, 13)
    x, g = g_ffd(pos, r, box, 6.0, 12)
    np.testing.assert_allclose(x, 0.5 * (edges[1:] + edges[:-1]), rtol=0, atol=1e-15)
    counts, _ = np.histogram(dist - sums, bins=edges)
    assert np.sum(dist - sums < 0) > 100            # overlapping pairs exist and are left out
    np.testing.assert_allclose(g, counts / ideal_ffd_counts(sums, edges, box.area), rtol=1e-12)


@pytest.mark.parametrize("box, n", [(PeriodicBox(100.0), 4000), (PeriodicBox(120.0, 80.0), 3500)],
                         ids=["square", "rectangle"])
def test_g_rdf_of_poisson_points_is_one(box, n):
    """N uniform independent points (N = 4000 in a 100 m square, 3500 in a
    120 x 80 m box), r_max = 10 m, 10 bins: on a torus the pair indicators
    are uncorrelated (given x_i, x_j and x_k are independent and uniform),
    so the count in a bin is a sum of M uncorrelated Bernoulli(p), mean
    M p, variance M p (1 - p). Every bin of g is 1 within 4 sigma,
    sigma = sqrt((1 - p)/(M p)) (2 % in the first bin, 0.5 % in the last),
    and so is the pooled value over all bins."""
    rng = np.random.default_rng([61, n])
    pos = rng.random((n, 2)) * np.array([box.lx, box.ly])
    x, g = g_rdf(pos, box, 10.0, 10)
    edges = np.linspace(0.0, 10.0, 11)
    np.testing.assert_allclose(x, np.arange(10) + 0.5, rtol=0, atol=1e-14)
    expected = ideal_rdf_counts(n, edges, box.area)
    p = expected / (0.5 * n * (n - 1))
    sigma = np.sqrt((1.0 - p) / expected)
    assert np.all(np.abs(g - 1.0) < 4.0 * sigma)
    pooled = np.sum(g * expected) / np.sum(expected)
    assert abs(pooled - 1.0) < 4.0 / math.sqrt(np.sum(expected))


def test_g_ffd_of_poisson_floes_is_one():
    """2000 floes with radii uniform in [0.2, 1.5] m at uniform independent
    positions in a 70 m periodic square, x_max = 5 m, 10 bins: the pair
    indicators are uncorrelated as for g_rdf, so the count of each bin has
    variance below its mean E (computed pair by pair); every bin of g is 1
    within 4/sqrt(E) (E ~ 2000-7000, so 4-9 %)."""
    box = PeriodicBox(70.0)
    rng = np.random.default_rng(71)
    r = rng.uniform(0.2, 1.5, 2000)
    pos = rng.random((2000, 2)) * 70.0
    x, g = g_ffd(pos, r, box, 5.0, 10)
    edges = np.linspace(0.0, 5.0, 11)
    iu, ju = np.triu_indices(2000, k=1)
    expected = ideal_ffd_counts(r[iu] + r[ju], edges, box.area)
    assert expected.min() > 1500
    assert np.all(np.abs(g - 1.0) < 4.0 / np.sqrt(expected))


def test_g_rdf_of_non_overlapping_floes_vanishes_below_contact():
    """A placed (non-overlapping) field of 400 floes at concentration 0.6:
    no centre distance is below r_i + r_j >= 2 r_min, so every bin of g_rdf
    ending at or below 2 r_min is exactly 0 (at least three such bins), and
    pairs do appear beyond it; g_ffd counts every pair (no overlaps to
    drop): sum(g_ffd * ideal counts) = number of pairs with gap < x_max."""
    field, box = make_floe_field(400, concentration=0.6, alpha=1.8, mean_diameter=4.0, seed=5)
    assert max_overlap(field.positions, field.radii, box) == 0.0
    contact = 2.0 * field.radii.min()
    r_max = 5.3 * contact
    x, g = g_rdf(field.positions, box, r_max, 20)
    edges = np.linspace(0.0, r_max, 21)
    below = edges[1:] <= contact
    assert below.sum() >= 3
    assert np.all(g[below] == 0.0)
    assert g[~below].max() > 0.0
    x_max = 2.0
    _, gf = g_ffd(field.positions, field.radii, box, x_max, 8)
    dist, sums = all_pair_geometry(box.wrap(field.positions), field.radii, box)
    counts = gf * ideal_ffd_counts(sums, np.linspace(0.0, x_max, 9), box.area)
    n_pairs = int(np.sum(dist - sums < x_max))
    assert n_pairs > 100
    assert np.sum(counts) == pytest.approx(n_pairs, rel=1e-10)


# ---------------------------------------------------------------------------
# Bad input
# ---------------------------------------------------------------------------

POS = np.array([[1.0, 1.0], [3.0, 1.0], [5.0, 4.0]])
RAD = np.array([0.5, 0.7, 0.4])
BOX = PeriodicBox(20.0)

BAD_CALLS = [
    ("positions (N, 3)", lambda: find_clusters(np.zeros((3, 3)), RAD, BOX), "shape"),
    ("radii too short", lambda: find_clusters(POS, RAD[:2], BOX), "shape"),
    ("radii 2-D", lambda: find_clusters(POS, RAD[:, None], BOX), "shape"),
    ("negative radius", lambda: find_clusters(POS, [0.5, -0.1, 0.4], BOX), "non-negative"),
    ("NaN radius", lambda: find_clusters(POS, [0.5, np.nan, 0.4], BOX), "finite"),
    ("NaN position", lambda: find_clusters([[1.0, np.nan], [3, 1], [5, 4]], RAD, BOX), "NaN"),
    ("inf position", lambda: find_clusters([[1.0, np.inf], [3, 1], [5, 4]], RAD, BOX), "infinite"),
    ("max_gap < 0", lambda: find_clusters(POS, RAD, BOX, max_gap=-0.1), "max_gap"),
    ("max_gap NaN", lambda: find_clusters(POS, RAD, BOX, max_gap=np.nan), "max_gap"),
    ("max_gap inf", lambda: find_clusters(POS, RAD, BOX, max_gap=np.inf), "max_gap"),
    # 2 r_max + max_gap = 1.4 + 8.6 = 10 = L/2: a floe could meet two images
    ("max_gap at L/2", lambda: find_clusters(POS, RAD, BOX, max_gap=8.6), "half the periodic"),
    ("max_gap, short side", lambda: find_clusters(POS, RAD, PeriodicBox(100.0, 8.0), 2.7),
     "along y"),
    ("not a box", lambda: find_clusters(POS, RAD, (20.0, 20.0)), "Box"),
    ("labels/radii lengths", lambda: cluster_statistics([0, 0, 1], [1.0, 2.0]), "equal length"),
    ("labels 2-D", lambda: cluster_statistics(np.zeros((2, 2), int), np.ones((2, 2))), "1-D"),
    ("negative label", lambda: cluster_statistics([0, -1], [1.0, 2.0]), "non-negative"),
    ("float labels", lambda: cluster_statistics([0.0, 1.0], [1.0, 2.0]), "integers"),
    ("no floes", lambda: cluster_statistics(np.zeros(0, int), np.zeros(0)), "no floes"),
    ("negative radius (stats)", lambda: cluster_statistics([0, 1], [1.0, -2.0]), "non-negative"),
    ("zero value", lambda: power_law_exponent([1.0, 2.0, 0.0]), "positive"),
    ("negative value", lambda: power_law_exponent([1.0, -2.0, 3.0]), "positive"),
    ("NaN value", lambda: power_law_exponent([1.0, np.nan, 3.0]), "NaN"),
    ("one value", lambda: power_law_exponent([2.0]), "at least two"),
    ("no values", lambda: power_law_exponent([]), "at least two"),
    ("2-D values", lambda: power_law_exponent(np.ones((2, 2))), "1-D"),
    ("k = 0", lambda: power_law_exponent([1.0, 2.0, 3.0], 0), "k must"),
    ("k = N", lambda: power_law_exponent([1.0, 2.0, 3.0], 3), "k must"),
    ("k = 1.5", lambda: power_law_exponent([1.0, 2.0, 3.0], 1.5), "k must"),
    ("k = True", lambda: power_law_exponent([1.0, 2.0, 3.0], True), "k must"),
    ("equal values", lambda: power_law_exponent([2.0, 2.0, 2.0]), "equal"),
    ("series, one value", lambda: exponent_series([2.0]), "at least two"),
    ("series, zero", lambda: exponent_series([2.0, 0.0]), "positive"),
    ("fsd, zero", lambda: fsd_exponent([2.0, 0.0, 1.0]), "positive"),
    ("r_max = 0", lambda: g_rdf(POS, BOX, 0.0), "r_max"),
    ("r_max < 0", lambda: g_rdf(POS, BOX, -1.0), "r_max"),
    ("r_max NaN", lambda: g_rdf(POS, BOX, np.nan), "r_max"),
    ("r_max = L/2", lambda: g_rdf(POS, BOX, 10.0), "half the periodic"),
    ("bins = 0", lambda: g_rdf(POS, BOX, 5.0, 0), "bins"),
    ("bins < 0", lambda: g_rdf(POS, BOX, 5.0, -3), "bins"),
    ("bins = 2.5", lambda: g_rdf(POS, BOX, 5.0, 2.5), "bins"),
    ("walled box (rdf)", lambda: g_rdf(POS, WalledBox(20.0), 5.0), "periodic"),
    ("channel (rdf)", lambda: g_rdf(POS, ChannelBox(20.0), 5.0), "periodic"),
    ("one floe (rdf)", lambda: g_rdf(POS[:1], BOX, 5.0), "two floes"),
    ("NaN position (rdf)", lambda: g_rdf([[1.0, np.nan], [3, 1]], BOX, 5.0), "NaN"),
    ("x_max = 0", lambda: g_ffd(POS, RAD, BOX, 0.0), "x_max"),
    ("x_max inf", lambda: g_ffd(POS, RAD, BOX, np.inf), "x_max"),
    ("bins = 0 (ffd)", lambda: g_ffd(POS, RAD, BOX, 2.0, 0), "bins"),
    ("walled box (ffd)", lambda: g_ffd(POS, RAD, WalledBox(20.0), 2.0), "periodic"),
    ("channel (ffd)", lambda: g_ffd(POS, RAD, ChannelBox(20.0), 2.0), "periodic"),
    ("radii mismatch (ffd)", lambda: g_ffd(POS, RAD[:2], BOX, 2.0), "shape"),
    ("negative radius (ffd)", lambda: g_ffd(POS, [0.5, -0.7, 0.4], BOX, 2.0), "non-negative"),
    ("2 r_max + x_max = L/2 (ffd)", lambda: g_ffd(POS, RAD, BOX, 8.6), "half the periodic"),
]


@pytest.mark.parametrize("call, message", [pytest.param(c, m, id=name) for name, c, m in BAD_CALLS])
def test_bad_input_raises_value_error(call, message):
    """Each malformed call raises ValueError, and for the stated reason (the
    message names the offending quantity)."""
    with pytest.raises(ValueError, match=message):
        call()


def test_largest_allowed_max_gap():
    """Just below the limit 2 r_max + max_gap < L/2 (1.4 + 8.599 m in a
    20 m box) clustering works and links the three floes (edge gaps 0.8,
    2.5 and 4.1 m, all separate at max_gap = 0.5); a walled box has no
    such limit (max_gap = 50 m joins everything)."""
    assert partition(find_clusters(POS, RAD, BOX, max_gap=8.599)) == {frozenset({0, 1, 2})}
    assert partition(find_clusters(POS, RAD, WalledBox(20.0), max_gap=50.0)) == {
        frozenset({0, 1, 2})}
    assert partition(find_clusters(POS, RAD, BOX, max_gap=0.5)) == {frozenset({0}),
                                                                    frozenset({1}),
                                                                    frozenset({2})}


# ---------------------------------------------------------------------------
# Many floes
# ---------------------------------------------------------------------------

def test_twenty_thousand_floes():
    """N = 20000 power-law floes (diameters 1-10 m) at uniform positions,
    concentration 0.35, max_gap = 0.5 m: N labels; both ends of every pair
    from near_pairs carry the same label; and the partition is exactly the
    connected components (scipy) of the near_pairs graph, i.e. no two
    clusters that should be one and no cluster that should be split; label
    order by area holds. (Near-linear cost: this runs in well under a
    second.)"""
    n = 20000
    rng = np.random.default_rng(81)
    r = 0.5 * sample_power_law_diameters(n, 1.8, 1.0, 10.0, rng)
    rng.shuffle(r)
    side = math.sqrt(np.pi * np.sum(r ** 2) / 0.35)
    box = PeriodicBox(side)
    pos = rng.random((n, 2)) * side
    labels = find_clusters(pos, r, box, 0.5)
    assert labels.shape == (n,)
    i, j, _, _, _ = near_pairs(pos, r, box, 0.5)
    assert i.size > n // 2
    assert np.array_equal(labels[i], labels[j])
    graph = coo_matrix((np.ones(i.size), (i, j)), shape=(n, n))
    n_comp, comp = connected_components(graph, directed=False)
    assert labels.max() + 1 == n_comp
    assert np.array_equal(canonical(labels), canonical(comp))
    cs = cluster_statistics(labels, r)
    assert np.all(np.diff(cs.area) <= 0) and cs.n_members.sum() == n
    assert 1 < cs.n_clusters < n
