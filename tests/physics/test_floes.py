"""Floe-size distributions, domain size and placement (Herman 2011,
appendix A; the Physics page: physics-fsd)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from physics import (FloeField, PeriodicBox, PlacementError, WalledBox, domain_size,
                     make_floe_field, place_floes, power_law_diameters, rank_order_diameters,
                     sample_power_law_diameters)
from physics.floes import max_overlap, spatial_order


def ml_exponent(x, k=1):
    """alpha_k = (N - k + 1) / sum_{n=k..N} ln(x_n / x_N) for x sorted largest
    first, and its standard error alpha_k (N - k + 1)^(-1/2)."""
    x = np.sort(np.asarray(x))[::-1]
    n = len(x)
    tail = x[k - 1:]
    alpha = (n - k + 1) / np.sum(np.log(tail / x[-1]))
    return alpha, alpha / math.sqrt(n - k + 1)


@pytest.mark.parametrize("n, alpha, mean_diameter", [(3000, 1.5, 2.0), (1000, 1.8, 8.0),
                                                     (10, 2.5, 1.0)])
def test_rank_order_diameters_formula(n, alpha, mean_diameter):
    """d_n = [(alpha N + 1)/(alpha n + 1)]^(1/alpha), n = 1..N, rescaled to
    the requested mean: values to 1e-12, mean to 1e-12, largest first, and
    the size ratio d_1/d_N = ((alpha N + 1)/(alpha + 1))^(1/alpha)."""
    d = rank_order_diameters(n, alpha, mean_diameter)
    k = np.arange(1, n + 1)
    raw = ((alpha * n + 1) / (alpha * k + 1)) ** (1 / alpha)
    np.testing.assert_allclose(d, raw * mean_diameter / raw.mean(), rtol=1e-12)
    assert d.mean() == pytest.approx(mean_diameter, rel=1e-12)
    assert np.all(np.diff(d) < 0)
    assert d[0] / d[-1] == pytest.approx(((alpha * n + 1) / (alpha + 1)) ** (1 / alpha), rel=1e-12)


@pytest.mark.parametrize("alpha", [1.5, 1.8])
def test_rank_order_sample_has_the_power_law_exponent(alpha):
    """The most probable rank-ordered sample of N = 3000 is a power-law
    sample: its maximum-likelihood exponent (k = 1) is alpha within three
    standard errors alpha N^(-1/2)."""
    a, err = ml_exponent(rank_order_diameters(3000, alpha, 2.0))
    assert abs(a - alpha) < 3 * err


@pytest.mark.parametrize("alpha", [1.2, 1.5, 1.8, 2.5])
def test_sampled_power_law_ml_exponent(alpha):
    """sample_power_law_diameters over [1, 1e6] (truncation negligible):
    all values in [d_min, d_max], sorted largest first, and the ML exponent
    of N = 20000 values recovers alpha within three standard errors."""
    rng = np.random.default_rng([2011, int(10 * alpha)])
    d = sample_power_law_diameters(20000, alpha, 1.0, 1e6, rng)
    assert d.min() >= 1.0 and d.max() <= 1e6
    assert np.all(np.diff(d) <= 0)
    a, err = ml_exponent(d)
    assert abs(a - alpha) < 3 * err


def test_sampled_truncated_power_law_follows_its_cdf():
    """A narrow truncation (d_max/d_min = 8, alpha = 1.5): every value in
    [2, 16], and a Kolmogorov-Smirnov test against the truncated CDF
    (d_min^-a - d^-a)/(d_min^-a - d_max^-a) does not reject at 1 %, while the
    untruncated law is rejected."""
    alpha, lo, hi = 1.5, 2.0, 16.0
    rng = np.random.default_rng(7)
    d = sample_power_law_diameters(5000, alpha, lo, hi, rng)
    assert d.min() >= lo and d.max() <= hi

    def cdf(x):
        return (lo ** -alpha - x ** -alpha) / (lo ** -alpha - hi ** -alpha)

    assert stats.kstest(d, cdf).pvalue > 0.01
    assert stats.kstest(d, lambda x: 1.0 - (x / lo) ** -alpha).pvalue < 1e-6


def test_random_fsd_is_seeded_and_has_the_mean():
    """power_law_diameters(method="random") gives the requested mean (1e-12),
    the same values for the same seed and different values for another."""
    a = power_law_diameters(500, 1.8, 8.0, method="random", rng=np.random.default_rng(1))
    b = power_law_diameters(500, 1.8, 8.0, method="random", rng=np.random.default_rng(1))
    c = power_law_diameters(500, 1.8, 8.0, method="random", rng=np.random.default_rng(2))
    assert a.mean() == pytest.approx(8.0, rel=1e-12)
    assert np.array_equal(a, b) and not np.array_equal(a, c)


@pytest.mark.parametrize("concentration, aspect", [(0.6, 1.0), (0.9, 1.0), (0.75, 0.25)])
def test_domain_size_gives_concentration(concentration, aspect):
    """domain_size: Lx Ly = pi sum d^2 / (4 A) and Ly = aspect Lx, so the floes
    cover the requested concentration (1e-12)."""
    d = rank_order_diameters(3000, 1.5, 2.0)
    lx, ly = domain_size(d, concentration, aspect)
    assert ly / lx == pytest.approx(aspect, rel=1e-12)
    assert math.pi * np.sum(d ** 2) / 4 / (lx * ly) == pytest.approx(concentration, rel=1e-12)
    assert lx == pytest.approx(math.sqrt(math.pi * np.sum(d ** 2) / (4 * concentration) / aspect),
                               rel=1e-12)


def test_floe_field_masses_and_inertia():
    """m = rho h pi r^2 and I = m r^2 / 2 (discs); frozen floes start at rest."""
    r = np.array([1.0, 2.5, 4.0])
    h = np.array([1.5, 0.5, 2.0])
    f = FloeField(np.zeros((3, 2)), r, h, np.ones((3, 2)), np.ones(3), density=900.0,
                  frozen=[False, True, False])
    np.testing.assert_allclose(f.masses, 900.0 * h * math.pi * r ** 2, rtol=1e-15)
    np.testing.assert_allclose(f.inertia, 0.5 * f.masses * r ** 2, rtol=1e-15)
    assert np.all(f.velocities[1] == 0.0) and f.angular_velocities[1] == 0.0
    assert np.all(f.velocities[[0, 2]] == 1.0)


@pytest.mark.parametrize("concentration, alpha, mean_diameter", [(0.85, 1.8, 8.0),
                                                                  (0.90, 1.5, 2.0)])
def test_dense_placement_has_no_overlap(concentration, alpha, mean_diameter):
    """make_floe_field with N = 1000 at A = 0.85 (Herman 2013 FSD) and
    A = 0.90 (Herman 2011 FSD): no two floes overlap at all (max_overlap == 0,
    also checked pair by pair), every centre is in the box and the
    concentration is the target (1e-12)."""
    floes, box = make_floe_field(1000, concentration=concentration, alpha=alpha,
                                 mean_diameter=mean_diameter, seed=5)
    assert max_overlap(floes.positions, floes.radii, box) == 0.0
    d = floes.positions[None, :, :] - floes.positions[:, None, :]
    d -= box.lx * np.round(d / box.lx)
    dist = np.hypot(d[..., 0], d[..., 1]) + np.diag(np.full(floes.n, np.inf))
    assert np.all(dist >= floes.radii[:, None] + floes.radii[None, :])
    assert np.all(box.contains(floes.positions))
    assert floes.concentration(box) == pytest.approx(concentration, rel=1e-12)
    assert floes.diameters.mean() == pytest.approx(mean_diameter, rel=1e-12)


def test_placement_is_reproducible():
    """Same seed, same positions (bitwise); another seed, other positions."""
    kwargs = dict(concentration=0.7, alpha=1.8, mean_diameter=8.0, velocity_std=0.05)
    a, _ = make_floe_field(200, seed=3, **kwargs)
    b, _ = make_floe_field(200, seed=3, **kwargs)
    c, _ = make_floe_field(200, seed=4, **kwargs)
    assert np.array_equal(a.positions, b.positions)
    assert np.array_equal(a.velocities, b.velocities)
    assert not np.array_equal(a.positions, c.positions)
    rng1, rng2 = np.random.default_rng(9), np.random.default_rng(9)
    r = 0.5 * rank_order_diameters(100, 1.5, 2.0)
    box = PeriodicBox(math.sqrt(math.pi * np.sum(r ** 2) / 0.5))
    assert np.array_equal(place_floes(r, box, rng1), place_floes(r, box, rng2))


def test_placement_in_walled_box_keeps_floes_inside():
    """In a walled box at A = 0.7 every floe lies wholly inside and none overlap."""
    r = 0.5 * rank_order_diameters(300, 1.8, 8.0)
    side = math.sqrt(math.pi * np.sum(r ** 2) / 0.7)
    box = WalledBox(side)
    pos = place_floes(r, box, np.random.default_rng(2))
    assert np.all(pos - r[:, None] >= 0.0) and np.all(pos + r[:, None] <= side)
    assert max_overlap(pos, r, box) == 0.0


def test_impossible_concentrations_raise_placement_error():
    """A = 1 or more, a floe wider than the (half) periodic box, and 60 equal
    discs at A = 0.93 (above hexagonal close packing, 0.9069) raise
    PlacementError."""
    rng = np.random.default_rng(0)
    r = np.full(50, 1.0)
    with pytest.raises(PlacementError, match="concentration"):
        place_floes(r, PeriodicBox(math.sqrt(math.pi * 50)), rng)
    with pytest.raises(PlacementError, match="concentration"):
        place_floes(r, PeriodicBox(math.sqrt(math.pi * 50 / 1.2)), rng)
    with pytest.raises(PlacementError, match="does not fit"):
        place_floes(np.array([1.0, 1.0, 6.0]), PeriodicBox(20.0), rng)
    with pytest.raises(PlacementError, match="does not fit"):
        place_floes(np.array([1.0, 11.0]), WalledBox(20.0, 40.0), rng)
    r = np.full(60, 1.0)
    with pytest.raises(PlacementError):
        place_floes(r, PeriodicBox(math.sqrt(math.pi * 60 / 0.93)), rng)


@pytest.mark.parametrize("fsd", ["rank", "random"])
def test_repeated_sample_has_the_same_sizes_in_a_wider_box(fsd):
    """make_floe_field(repeat=4): each of the n sampled diameters four times,
    at the target concentration, without overlaps, in a box twice as wide as
    that of the sample alone (same seed, same sizes)."""
    one, box1 = make_floe_field(300, concentration=0.6, alpha=1.5, mean_diameter=2.0, seed=3,
                                fsd=fsd)
    four, box4 = make_floe_field(300, concentration=0.6, alpha=1.5, mean_diameter=2.0, seed=3,
                                 fsd=fsd, repeat=4, velocity_std=0.01)
    assert four.n == 1200
    np.testing.assert_array_equal(np.sort(four.radii), np.sort(np.repeat(one.radii, 4)))
    assert box4.lx == pytest.approx(2.0 * box1.lx, rel=1e-12)
    assert four.total_area / box4.area == pytest.approx(0.6, rel=1e-12)
    assert max_overlap(four.positions, four.radii, box4) <= 0.0
    assert four.velocities.shape == (1200, 2) and four.velocities.std() > 0.005


@pytest.mark.parametrize("repeat", [0, 1.5, -2])
def test_repeat_must_be_a_positive_whole_number(repeat):
    with pytest.raises(ValueError, match="repeat"):
        make_floe_field(100, concentration=0.5, alpha=1.5, mean_diameter=2.0, repeat=repeat)


def test_spatial_order_numbers_floes_along_a_z_curve():
    """Four floes in the four quadrants of a box come out in Z order (lower
    left, lower right, upper left, upper right), and a generated field is
    numbered so that the floes of the lower half of the box come first (the
    top level of the curve) and consecutive floes are close: the mean
    distance between floes i and i + 1 is under a tenth of the box side
    (about half of it for a random numbering)."""
    box = PeriodicBox(100.0)
    pos = np.array([[70.0, 80.0], [20.0, 80.0], [80.0, 10.0], [10.0, 30.0]])
    assert list(spatial_order(pos, box)) == [3, 2, 1, 0]
    floes, box = make_floe_field(2000, concentration=0.6, alpha=1.8, mean_diameter=8.0, seed=4)
    upper = (floes.positions[:, 1] >= 0.5 * box.ly).astype(int)
    assert np.all(np.diff(upper) >= 0) and 0.3 < upper.mean() < 0.7
    step = np.linalg.norm(np.diff(floes.positions, axis=0), axis=1)
    assert step.mean() < 0.1 * box.lx
    with pytest.raises(ValueError, match="shape"):
        spatial_order(np.zeros(3), box)


def test_take_renumbers_every_floe_property():
    """``take`` keeps each floe's radius, thickness, velocities and frozen
    flag together, and rejects indices out of range."""
    f = FloeField(np.array([[0.0, 0.0], [5.0, 0.0], [10.0, 0.0]]), [1.0, 2.0, 1.5],
                  thickness=[1.0, 2.0, 3.0], velocities=[[1.0, 0.0], [0.0, 0.0], [3.0, 0.0]],
                  angular_velocities=[0.1, 0.0, 0.3], frozen=[False, True, False])
    g = f.take([2, 0, 1])
    np.testing.assert_array_equal(g.radii, [1.5, 1.0, 2.0])
    np.testing.assert_array_equal(g.thickness, [3.0, 1.0, 2.0])
    np.testing.assert_array_equal(g.velocities[:, 0], [3.0, 1.0, 0.0])
    np.testing.assert_array_equal(g.angular_velocities, [0.3, 0.1, 0.0])
    np.testing.assert_array_equal(g.frozen, [False, False, True])
    with pytest.raises(ValueError, match="outside"):
        f.take([0, 3])
