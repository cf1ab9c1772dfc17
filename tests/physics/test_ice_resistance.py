"""The resistance laws of physics.ice_resistance against values worked out
by hand from their published forms, their exponents against calculus, and
their errors. (The sources available here print no worked example of their
own; the hand calculations are spelled out below.)"""
import math

import numpy as np
import pytest

from physics.ice_resistance import (HUANG_COEFFICIENT, huang_coefficient, huang_resistance,
                                    momentum_flux_resistance, power_law_exponent, power_law_fit,
                                    resistance_exponents, zuev_coefficient, zuev_resistance,
                                    zuev_terms)

#: a research icebreaker of Araon's main dimensions (L = 110 m, B = 19 m) at
#: 3 knots in 0.5 m floes of density 920 kg/m³
ARAON = dict(beam=19.0, thickness=0.5, density=920.0)
V3KN = 3.0 * 1852.0 / 3600.0


def test_zuev_by_hand():
    """Fr_h = 1.5433/√(9.81 · 0.5) = 0.69685; the bracket 0.13 · 38 + 1.3 · 0.69685
    + 0.5 · 0.69685² = 4.94 + 0.90591 + 0.24280 = 6.08871; ρ g B h² = 920 · 9.81
    · 19 · 0.25 = 42869.7 N; (2 − S) S² = 0.375 at S = 0.5: R = 97.88 kN."""
    r = zuev_resistance(V3KN, 0.5, **ARAON)
    assert r == pytest.approx(42869.7 * 6.08871 * 0.375, rel=1e-5)
    assert r == pytest.approx(97.88e3, rel=1e-4)
    terms = zuev_terms(V3KN, 0.5, **ARAON)
    assert terms["static"] == pytest.approx(42869.7 * 0.375 * 4.94, rel=1e-5)
    assert sum(terms.values()) == pytest.approx(r, rel=1e-12)


def test_huang_by_hand():
    """C_R ρ B h v² C^1.5 / Fn with Fn = 1.5433/√(9.81 · 110) = 0.046983: at
    C = 0.5, 0.2 · 900 · 19 · 0.5 · 1.5433² · 0.35355 / 0.046983 = 30.65 kN."""
    r = huang_resistance(V3KN, 0.5, 19.0, 0.5, 110.0, density=900.0)
    assert r == pytest.approx(0.2 * 900 * 19 * 0.5 * V3KN ** 2 * 0.5 ** 1.5
                              / (V3KN / math.sqrt(9.81 * 110.0)), rel=1e-12)
    assert r == pytest.approx(30.65e3, rel=1e-3)


def test_the_exponents_are_those_of_the_formulas():
    """Zuev: ∂ ln R/∂ ln S = 2 − S/(2 − S); ∂ ln R/∂ ln v = (k2 Fr + 2 k3 Fr²)
    / (k1 B/h + k2 Fr + k3 Fr²). Huang: 1.5 and 1. Momentum flux: 1 and 2."""
    s, v = 0.4, 2.0
    a, b = resistance_exponents(zuev_resistance, v, s, **ARAON)
    fr = v / math.sqrt(9.81 * 0.5)
    assert a == pytest.approx(2.0 - s / (2.0 - s), rel=1e-6)
    assert b == pytest.approx((1.3 * fr + fr ** 2) / (0.13 * 38 + 1.3 * fr + 0.5 * fr ** 2),
                              rel=1e-6)
    assert resistance_exponents(huang_resistance, v, s, beam=19.0, thickness=0.5,
                                length=110.0) == pytest.approx((1.5, 1.0), rel=1e-6)
    assert resistance_exponents(momentum_flux_resistance, v, s, width=18.0,
                                thickness=1.5) == pytest.approx((1.0, 2.0), rel=1e-6)


def test_the_coefficients_invert_the_laws():
    r = zuev_resistance(V3KN, 0.6, **ARAON)
    fr = V3KN / math.sqrt(9.81 * 0.5)
    assert zuev_coefficient(r, 0.6, **ARAON) == pytest.approx(
        0.13 * 38 + 1.3 * fr + 0.5 * fr ** 2, rel=1e-12)
    r = huang_resistance(V3KN, 0.6, 19.0, 0.5, 110.0)
    assert huang_coefficient(r, V3KN, 0.6, 19.0, 0.5, 110.0) == pytest.approx(
        HUANG_COEFFICIENT, rel=1e-12)


def test_arrays_and_the_dilute_limit():
    r = momentum_flux_resistance([1.0, 2.0], 0.1, 18.0, 1.5, restitution=0.5)
    assert r[1] == pytest.approx(4.0 * r[0], rel=1e-12)
    assert r[0] == pytest.approx(1.5 * 910.0 * 1.5 * 0.1 * 18.0, rel=1e-12)
    assert power_law_fit([1.0, 2.0, 3.0], momentum_flux_resistance(
        [1.0, 2.0, 3.0], 0.3, 18.0, 1.5))[1] == pytest.approx(2.0, rel=1e-9)


@pytest.mark.parametrize("call, message", [
    (lambda: zuev_resistance(1.0, 1.2, **ARAON), "concentration must be a fraction"),
    (lambda: zuev_resistance(1.0, 5, **ARAON), "concentration must be a fraction"),
    (lambda: zuev_resistance(-1.0, 0.5, **ARAON), "speed must be finite and >= 0"),
    (lambda: huang_resistance(1.0, 0.5, 19.0, 0.5, 0.0), "length"),
    (lambda: momentum_flux_resistance(1.0, 0.5, 18.0, 1.5, restitution=2.0), "restitution"),
])
def test_bad_input_is_refused(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_the_exponents_error_by_hand():
    """ln x = 0, 1, 2 and ln y = 0, 1 + d, 2: the line through them has
    slope 1 and intercept d/3, residuals (−d, 2d, −d)/3, so
    s² = (6 d²/9) / (3 − 2) and se(b) = √(s² / 2) = |d|/√3."""
    d = 0.3
    x = np.exp([0.0, 1.0, 2.0])
    b, se = power_law_exponent(x, np.exp([0.0, 1.0 + d, 2.0]))
    assert b == pytest.approx(1.0, rel=1e-12)
    assert se == pytest.approx(d / math.sqrt(3.0), rel=1e-12)
    b, se = power_law_exponent(x, 3.0 * x ** 1.5)             # an exact power law
    assert b == pytest.approx(1.5, rel=1e-12) and se < 1e-12
    b, se = power_law_exponent([1.0, 2.0, np.nan], [1.0, 4.0, 9.0])
    assert b == pytest.approx(2.0, rel=1e-12) and math.isnan(se)
