"""Ship resistance in broken, floating ice: the laws the field uses, coded
once, beside the momentum flux that a two-dimensional collision model
reaches in dilute ice.

All functions take SI units (m, m/s, kg/m³) and return newtons; the
concentration is a fraction in [0, 1].

* :func:`momentum_flux_resistance`: a flat bow of width W at speed v through
  floes at rest that each leave at (1 + e) v: R = (1 + e) ρ_i h A W v². The
  dilute limit of the Hertz engine's ship (``physics.validate.
  flat_bow_resistance`` checks it to 0.3 %).
* :func:`zuev_resistance`: Zuev's semi-empirical law for broken ice,
  R = ρ_i g B h² (0.13 B/h + 1.3 Fr_h + 0.5 Fr_h²) (2 − S) S², with
  Fr_h = v / √(g h); :func:`zuev_terms` gives its three terms apart.
  From the Russian ice-performance literature (Zuev, Gramuzov and
  Dvoichenko, Gorky Polytechnic Institute, 1984–1989; Ionov and Gramuzov,
  *Ice propulsive quality of ships*, Sudostroenie, 2014), where it is
  quoted with S a fraction. The sources at hand give no range of validity
  beyond 0 ≤ S ≤ 1 and speeds of ships in ice (Fr_h up to about 1).
* :func:`huang_resistance`: Huang et al.'s fit to coupled CFD–DEM
  simulations of a ship in floating floes (Huang et al., "Ship resistance
  when operating in floating ice floes: a combined CFD&DEM approach",
  Marine Structures, 2020, and the empirical equation derived from it):
  R = C_R ρ_i B h v² C^1.5 / Fn, with Fn = v / √(g L) the ship's Froude
  number on its length and C_R ≈ 0.2 for the hull they simulated, as
  AUTO-IceNav's code uses it. Because R ∝ v² / Fn, it grows linearly with
  v. The form and C_R are taken from that code; the papers' own range of
  validity could not be read here and is not stated.

What the laws hold and the model does not: Zuev's constant term
(0.13 B/h, speed-independent) stands for breaking and submerging floes
under the hull and pushing them aside against their buoyancy, and its
linear term for the water's resistance to the floes' motion; a
two-dimensional model of rigid discs that neither break, tilt nor submerge
keeps only the inertial part, the Fr_h² term. :func:`resistance_exponents`
gives a law's local exponents in S and v, to be set beside those fitted to
the model's runs.
"""
from __future__ import annotations

import math

import numpy as np

from .input_checks import check_range
from .params import GRAVITY

#: Zuev's coefficients of B/h, Fr_h and Fr_h²
ZUEV_COEFFICIENTS = (0.13, 1.3, 0.5)

#: Huang et al.'s resistance coefficient for the hull of their simulations
HUANG_COEFFICIENT = 0.2


def _checked(speed, concentration, *lengths):
    v = np.asarray(speed, dtype=float)
    s = np.asarray(concentration, dtype=float)
    if np.any(~np.isfinite(v)) or np.any(v < 0.0):
        raise ValueError(f"speed must be finite and >= 0 m/s, got {speed!r}")
    if np.any(~np.isfinite(s)) or np.any((s < 0.0) | (s > 1.0)):
        raise ValueError(f"concentration must be a fraction in [0, 1], got {concentration!r}")
    for name, value in lengths:
        check_range(name, value, 0.0, None, low_open=True)
    return v, s


def _scalar(x):
    return float(x) if np.ndim(x) == 0 else x


def momentum_flux_resistance(speed, concentration, width, thickness, *, restitution=0.5,
                             density=910.0):
    """(1 + e) ρ_i h A W v² [N]: a flat bow of width ``width`` through floes
    at rest, each leaving at (1 + e) v, when floes rarely meet each other
    (dilute ice)."""
    v, s = _checked(speed, concentration, ("width", width), ("thickness", thickness))
    check_range("restitution", restitution, 0.0, 1.0)
    return _scalar((1.0 + restitution) * density * thickness * s * width * v ** 2)


def zuev_terms(speed, concentration, beam, thickness, *, density=910.0, gravity=GRAVITY):
    """Zuev's resistance [N] in its three terms: ``{"static": …, "linear": …,
    "quadratic": …}``, each ρ_i g B h² (2 − S) S² times 0.13 B/h, 1.3 Fr_h
    and 0.5 Fr_h² (Fr_h = v/√(g h)); their sum is :func:`zuev_resistance`."""
    v, s = _checked(speed, concentration, ("beam", beam), ("thickness", thickness))
    fr = v / math.sqrt(gravity * thickness)
    scale = density * gravity * beam * thickness ** 2 * (2.0 - s) * s ** 2
    k1, k2, k3 = ZUEV_COEFFICIENTS
    return {"static": _scalar(scale * k1 * beam / thickness * np.ones_like(fr)),
            "linear": _scalar(scale * k2 * fr), "quadratic": _scalar(scale * k3 * fr ** 2)}


def zuev_resistance(speed, concentration, beam, thickness, *, density=910.0, gravity=GRAVITY):
    """Zuev's resistance in broken ice [N]:
    ρ_i g B h² (0.13 B/h + 1.3 Fr_h + 0.5 Fr_h²) (2 − S) S², Fr_h = v/√(g h)."""
    return _scalar(sum(np.asarray(t) for t in zuev_terms(
        speed, concentration, beam, thickness, density=density, gravity=gravity).values()))


def zuev_coefficient(resistance, concentration, beam, thickness, *, density=910.0,
                     gravity=GRAVITY):
    """A resistance [N] in the form of Zuev's law: R / (ρ_i g B h² (2 − S) S²),
    which the law sets to 0.13 B/h + 1.3 Fr_h + 0.5 Fr_h²."""
    _, s = _checked(0.0, concentration, ("beam", beam), ("thickness", thickness))
    with np.errstate(divide="ignore", invalid="ignore"):
        return _scalar(np.asarray(resistance, dtype=float)
                       / (density * gravity * beam * thickness ** 2 * (2.0 - s) * s ** 2))


def huang_resistance(speed, concentration, beam, thickness, length, *,
                     coefficient=HUANG_COEFFICIENT, density=910.0, gravity=GRAVITY):
    """Huang et al.'s resistance in floating floes [N]:
    C_R ρ_i B h v² C^1.5 / Fn, Fn = v/√(g L), that is C_R ρ_i B h C^1.5 v √(g L)."""
    v, s = _checked(speed, concentration, ("beam", beam), ("thickness", thickness),
                    ("length", length))
    return _scalar(coefficient * density * beam * thickness * s ** 1.5
                   * v * math.sqrt(gravity * length))


def huang_coefficient(resistance, speed, concentration, beam, thickness, length, *,
                      density=910.0, gravity=GRAVITY):
    """A resistance [N] in the form of Huang et al.'s law:
    R Fn / (ρ_i B h v² C^1.5), which the law sets to C_R."""
    v, s = _checked(speed, concentration, ("beam", beam), ("thickness", thickness),
                    ("length", length))
    fn = v / math.sqrt(gravity * length)
    with np.errstate(divide="ignore", invalid="ignore"):
        return _scalar(np.asarray(resistance, dtype=float) * fn
                       / (density * beam * thickness * v ** 2 * s ** 1.5))


def resistance_exponents(law, speed, concentration, *, step=1e-4, **kwargs):
    """(∂ ln R/∂ ln S, ∂ ln R/∂ ln v) of ``law(speed, concentration,
    **kwargs)`` at one point, by central differences in the logarithms:
    the local exponents of a power law R ∝ S^a v^b."""
    def ln_r(v, s):
        return math.log(float(law(v, s, **kwargs)))

    v, s = float(speed), float(concentration)
    up, down = math.exp(step), math.exp(-step)
    a = (ln_r(v, s * up) - ln_r(v, s * down)) / (2.0 * step)
    b = (ln_r(v * up, s) - ln_r(v * down, s)) / (2.0 * step)
    return a, b


def _log_points(x, y) -> tuple[np.ndarray, np.ndarray]:
    """(ln x, ln y) of the finite, positive points."""
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    return np.log(x[ok]), np.log(y[ok])


def power_law_fit(x, y) -> tuple[float, float]:
    """(a, b) of y = a x^b by least squares of ln y against ln x over the
    finite, positive points; NaNs with fewer than two distinct x."""
    lx, ly = _log_points(x, y)
    if np.unique(lx).size < 2:
        return math.nan, math.nan
    b, ln_a = np.polyfit(lx, ly, 1)
    return float(math.exp(ln_a)), float(b)


def power_law_exponent(x, y) -> tuple[float, float]:
    """(b, its standard error) of the fit of :func:`power_law_fit`: the
    residuals' variance over n − 2 divided by the spread Σ (ln x − mean)²,
    so that it holds both the points' scatter and the curvature of ln y
    against ln x; NaN error with fewer than three distinct x."""
    lx, ly = _log_points(x, y)
    distinct = np.unique(lx).size
    if distinct < 2:
        return math.nan, math.nan
    b, ln_a = np.polyfit(lx, ly, 1)
    if distinct < 3:
        return float(b), math.nan
    residuals = ly - ln_a - b * lx
    return float(b), float(math.sqrt(np.sum(residuals ** 2) / (lx.size - 2)
                                     / np.sum((lx - lx.mean()) ** 2)))
