"""The floe sizes of AUTO-IceNav's ice fields (physics.ice_fields): draws
follow the law's quantiles, covering draws cover their area and no more than
one floe beyond it, and a transit field of them has the asked concentration."""
import math

import numpy as np
import pytest

from physics.ice_fields import (AUTO_ICENAV_SIZES, LogMassSizes, covering_areas,
                                draw_floe_areas, floe_area_quantile)
from physics.params import HERMAN2013
from physics.ice_fields import transit_field


def test_the_median_floe_is_that_of_the_generator():
    # ln m = 10.21 + 0.9324 at the median; m / (900 kg/m³ × 1.2 m)
    want = math.exp(10.21 + 0.9324) / (900.0 * 1.2)
    assert floe_area_quantile(AUTO_ICENAV_SIZES, 0.5) == pytest.approx(want, rel=1e-12)
    # the smallest mass of the law, e^10.21 kg, is 25 m²: above the 16 m² cut
    assert math.exp(10.21) / 1080.0 > AUTO_ICENAV_SIZES.min_area


@pytest.mark.parametrize("q", [0.05, 0.25, 0.5, 0.75, 0.95])
def test_draws_follow_the_quantiles_of_the_law(q):
    """The fraction of n draws below the q-quantile is binomial: within 5
    standard deviations sqrt(q (1 − q) / n) of q (a false alarm once in
    about 3.5 million runs)."""
    n = 40_000
    areas = draw_floe_areas(AUTO_ICENAV_SIZES, n, np.random.default_rng(int(100 * q)))
    assert areas.size == n
    below = np.count_nonzero(areas < floe_area_quantile(AUTO_ICENAV_SIZES, q)) / n
    assert abs(below - q) < 5.0 * math.sqrt(q * (1.0 - q) / n)


def test_radii_are_clipped_and_small_floes_dropped():
    sizes = LogMassSizes(s=1.5, loc=3.0, scale=2.0, density=900.0, thickness=1.0,
                         min_radius=1.0, max_radius=10.0, min_area=5.0)
    areas = draw_floe_areas(sizes, 5000, np.random.default_rng(3))
    assert 0 < areas.size < 5000                       # some fall under 5 m²
    assert areas.min() >= 5.0 and areas.max() <= math.pi * 10.0 ** 2
    assert np.count_nonzero(areas == math.pi * 10.0 ** 2) > 0   # clipped at the top


def test_covering_areas_cover_the_target_with_one_floe_to_spare_at_most():
    rng = np.random.default_rng(4)
    for target in (10.0, 5.0e3, 1.0e5):
        areas = covering_areas(AUTO_ICENAV_SIZES, target, rng)
        assert areas.sum() >= target > areas[:-1].sum()


def test_same_seed_same_draws():
    a = covering_areas(AUTO_ICENAV_SIZES, 2.0e4, np.random.default_rng(9))
    b = covering_areas(AUTO_ICENAV_SIZES, 2.0e4, np.random.default_rng(9))
    np.testing.assert_array_equal(a, b)


def test_a_transit_field_of_auto_icenav_floes():
    field, box = transit_field(HERMAN2013, concentration=0.3, band=(100.0, 400.0), length=500.0,
                               width=200.0, seed=2, sizes="auto_icenav", thickness=1.2)
    covered = math.pi * np.sum(field.radii ** 2) / (300.0 * 200.0)
    # the floes cover the band's share and at most one floe more
    assert 0.3 <= covered <= 0.3 + math.pi * field.radii.max() ** 2 / (300.0 * 200.0)
    assert field.radii.min() >= 2.0 and np.all(field.thickness == 1.2)
    assert np.all((field.positions[:, 0] >= 100.0) & (field.positions[:, 0] <= 400.0))


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="q"):
        floe_area_quantile(AUTO_ICENAV_SIZES, 1.0)
    with pytest.raises(ValueError, match="n must be a non-negative integer"):
        draw_floe_areas(AUTO_ICENAV_SIZES, -1, np.random.default_rng(0))
    with pytest.raises(ValueError, match="target_area"):
        covering_areas(AUTO_ICENAV_SIZES, 0.0, np.random.default_rng(0))
    with pytest.raises(ValueError, match="max_radius"):
        LogMassSizes(s=0.5, loc=10.0, scale=1.0, density=900.0, thickness=1.0,
                     min_radius=5.0, max_radius=2.0, min_area=0.0)
    with pytest.raises(ValueError, match="sizes must be one of"):
        transit_field(HERMAN2013, concentration=0.3, band=(0.0, 100.0), length=100.0,
                      width=50.0, sizes="polygons")


def test_channel_field_covers_its_region_exactly_and_keeps_what_keep_says():
    """The diameters are scaled to cover the target area: the concentration
    covered is the one asked (to rounding), of the box or of its strip; the
    floes that ``keep`` rejects are gone, the others in the region."""
    from physics import HERMAN2013
    from physics.domain import Box
    from physics.ice_fields import channel_field

    box = Box(400.0, 200.0, periodic=(False, True))
    field, covered = channel_field(HERMAN2013, box, np.random.default_rng(3), concentration=0.3,
                                   sizes="lognormal", lognormal=(20.0, 0.5))
    assert covered == pytest.approx(0.3, rel=1e-12)
    assert np.pi * np.sum(field.radii ** 2) / box.area == pytest.approx(0.3, rel=1e-12)
    strip, covered = channel_field(HERMAN2013, box, np.random.default_rng(3), concentration=0.3,
                                   sizes="lognormal", lognormal=(20.0, 0.5), band=100.0,
                                   keep=lambda pos, r: pos[:, 0] > 100.0)
    assert covered == pytest.approx(0.3, rel=1e-12)
    assert strip.n > 0 and np.all(strip.positions[:, 0] > 100.0)
    assert np.all(strip.positions[:, 1] < 100.0)
    assert np.pi * np.sum(strip.radii ** 2) < 0.3 * 400.0 * 100.0
