"""External forcing of floes: wind and water drag, Coriolis, rotational drag.

Herman (2013), eqs 6–7 (:ref:`physics-drag`), for a floe of radius r, thickness h
and freeboard h_f = h (ρ_w − ρ) / ρ_w:

    m du/dt = −m f k×u + a |u_a| u_a + b (u_w − u) + Σ_j F_ij
    I dω/dt = −c ω + Σ_j torques

with, for an edge area ``e · r · h_f`` above and ``e · r · (h − h_f)`` below
the waterline (e = π in Herman 2013, e = 2 in Herman 2011),

    a = ρ_a (π r² C_ha + e r h_f C_va)            [kg/m]
    b = ρ_w (π r² C_hw + e r (h − h_f) C_vw)      [kg/s]
    c = b r² / 2                                   [kg m²/s]

For e = π these are exactly the paper's π r ρ_a (r C_ha + h_f C_va) etc.

The Stokes form of Herman (2011), eqs 5–8, used by the hard-disc engine, is
``τ_i du/dt = u_eq,i − u`` with τ_i = m/b and u_eq,i = u_w + (a/b) |u_a| u_a.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .input_checks import NONNEG, POSITIVE, check_fields, check_range

__all__ = ["Forcing", "ForcingParams", "DragCoefficients", "steady_drift"]


@dataclass(frozen=True)
class ForcingParams:
    """Densities, drag coefficients and the wind/current/Coriolis set-up.

    Attributes
    ----------
    ice_density, water_density, air_density : float
        ρ, ρ_w, ρ_a [kg/m³].
    air_skin_drag, air_form_drag : float
        C_ha, C_va [-].
    water_skin_drag, water_form_drag : float
        C_hw, C_vw [m/s] (linear drag laws of both papers).
    edge_area_factor : float
        The exposed edge area of a floe is ``edge_area_factor · r · h_f`` above
        the waterline and ``edge_area_factor · r · (h − h_f)`` below it:
        π in Herman (2013), 2 (the diameter times the freeboard) in Herman (2011).
    wind_speed : float
        |u_a| [m/s].
    wind_direction : float
        Direction the wind blows towards, counter-clockwise from +x [degrees].
    current_speed : float
        |u_w| [m/s].
    current_angle : float
        Direction of the current relative to the wind direction [degrees]
        (Herman 2011 does not state it; 0, along the wind, is the choice here).
    coriolis : float
        Coriolis parameter f [1/s].
    """

    ice_density: float = 910.0
    water_density: float = 1025.0
    air_density: float = 1.23
    air_skin_drag: float = 2.0e-3
    air_form_drag: float = 2.0e-3
    water_skin_drag: float = 1.0e-3
    water_form_drag: float = 1.0e-3
    edge_area_factor: float = math.pi
    wind_speed: float = 10.0
    wind_direction: float = 0.0
    current_speed: float = 0.0
    current_angle: float = 0.0
    coriolis: float = 1.3e-4

    def __post_init__(self):
        check_fields(self, {
            "ice_density": POSITIVE,
            "water_density": POSITIVE,
            "air_density": NONNEG,
            "air_skin_drag": NONNEG,
            "air_form_drag": NONNEG,
            "water_skin_drag": NONNEG,
            "water_form_drag": NONNEG,
            "edge_area_factor": NONNEG,
            "wind_speed": NONNEG,
            "wind_direction": (None, None, False, False),
            "current_speed": NONNEG,
            "current_angle": (None, None, False, False),
            "coriolis": (None, None, False, False),
        })
        if self.ice_density >= self.water_density:
            raise ValueError(
                f"ForcingParams.ice_density must be below water_density={self.water_density:g} "
                f"for floes to float, got {self.ice_density!r}")

    def wind_vector(self) -> tuple[float, float]:
        """(u_a,x, u_a,y) [m/s]."""
        a = math.radians(self.wind_direction)
        return self.wind_speed * math.cos(a), self.wind_speed * math.sin(a)

    def current_vector(self) -> tuple[float, float]:
        """(u_w,x, u_w,y) [m/s]."""
        a = math.radians(self.wind_direction + self.current_angle)
        return self.current_speed * math.cos(a), self.current_speed * math.sin(a)


class DragCoefficients:
    """Per-floe coefficients a, b, c (see the module docstring) and m f."""

    def __init__(self, wind: np.ndarray, water: np.ndarray, rotation: np.ndarray,
                 coriolis_mass: np.ndarray):
        self.wind = wind
        self.water = water
        self.rotation = rotation
        self.coriolis_mass = coriolis_mass


class Forcing:
    """Wind, current, drag and Coriolis acting on every floe.

    Parameters
    ----------
    params : ForcingParams
        Densities and drag coefficients; its wind/current set the initial
        vectors. Defaults to Herman (2013), Table 1.
    wind, current : (2,) array-like, optional
        Override the vectors of ``params`` [m/s].
    coriolis : float, optional
        Override f [1/s].

    Notes
    -----
    The wind and current vectors may be changed between calls to an engine
    (``forcing.wind = (ux, uy)``); the environments do so every control step.

    Examples
    --------
    >>> from physics import Forcing, HERMAN2013
    >>> forcing = Forcing(HERMAN2013.forcing)          # 10 m/s along x, f = 1.3e-4
    >>> forcing.wind = (0.0, -5.0)
    """

    def __init__(self, params: ForcingParams | None = None, *, wind=None, current=None,
                 coriolis=None):
        self.params = params if params is not None else ForcingParams()
        self.wind = self.params.wind_vector() if wind is None else wind
        self.current = self.params.current_vector() if current is None else current
        self.coriolis = self.params.coriolis if coriolis is None else coriolis

    # -- settable vectors, validated ------------------------------------------
    @staticmethod
    def _vector(name, value):
        v = np.asarray(value, dtype=float)
        if v.shape != (2,) or not np.all(np.isfinite(v)):
            raise ValueError(f"{name} must be a finite 2-vector [m/s], got {value!r}")
        return v.copy()

    @property
    def wind(self) -> np.ndarray:
        """Wind velocity u_a (2,) [m/s]."""
        return self._wind

    @wind.setter
    def wind(self, value):
        self._wind = self._vector("wind", value)

    @property
    def current(self) -> np.ndarray:
        """Ocean current u_w (2,) [m/s]."""
        return self._current

    @current.setter
    def current(self, value):
        self._current = self._vector("current", value)

    @property
    def coriolis(self) -> float:
        """Coriolis parameter f [1/s]."""
        return self._coriolis

    @coriolis.setter
    def coriolis(self, value):
        check_range("coriolis", value)
        self._coriolis = float(value)

    # -- per-floe coefficients -------------------------------------------------
    def coefficients(self, radius, thickness, mass) -> DragCoefficients:
        """a, b, c and m f for floes of radius r, thickness h and mass m."""
        p = self.params
        r = np.asarray(radius, dtype=float)
        h = np.asarray(thickness, dtype=float)
        freeboard = h * (p.water_density - p.ice_density) / p.water_density
        draft = h - freeboard
        e = p.edge_area_factor
        a = p.air_density * (math.pi * r ** 2 * p.air_skin_drag + e * r * freeboard * p.air_form_drag)
        b = p.water_density * (math.pi * r ** 2 * p.water_skin_drag + e * r * draft * p.water_form_drag)
        c = 0.5 * b * r ** 2
        return DragCoefficients(a, b, c, np.asarray(mass, dtype=float) * self.coriolis)

    def kernel_vector(self) -> np.ndarray:
        """(u_a,x, u_a,y, u_w,x, u_w,y) for the compiled kernels."""
        return np.array([self.wind[0], self.wind[1], self.current[0], self.current[1]])

    def time_constant(self, radius, thickness, mass) -> np.ndarray:
        """Stokes time constant τ = m / b [s] (Herman 2011, eq 7)."""
        return np.asarray(mass, dtype=float) / self.coefficients(radius, thickness, mass).water

    def equilibrium_velocity(self, radius, thickness, mass) -> np.ndarray:
        """Free-drift velocity without Coriolis, u_eq = u_w + (a/b)|u_a| u_a,
        (N, 2) [m/s] (Herman 2011, eqs 6 and 8)."""
        k = self.coefficients(radius, thickness, mass)
        speed = float(np.hypot(*self.wind))
        return self.current[None, :] + (k.wind / k.water)[:, None] * speed * self.wind[None, :]

    def __repr__(self):
        return (f"Forcing(wind={self.wind.tolist()}, current={self.current.tolist()}, "
                f"coriolis={self.coriolis:g})")


def steady_drift(forcing: Forcing, radius, thickness, mass) -> np.ndarray:
    """Analytic steady free drift of eq 6 with Coriolis, (N, 2) [m/s].

    Solves 0 = −m f k×u + a |u_a| u_a + b (u_w − u) for u:
    with F = a |u_a| u_a + b u_w and g = m f,
    u = (b F − g k×F) / (b² + g²)  [k×F = (−F_y, F_x)]: for f > 0 the drift
    turns to the right of the force.
    """
    k = forcing.coefficients(radius, thickness, mass)
    speed = float(np.hypot(*forcing.wind))
    fx = k.wind * speed * forcing.wind[0] + k.water * forcing.current[0]
    fy = k.wind * speed * forcing.wind[1] + k.water * forcing.current[1]
    b, g = k.water, k.coriolis_mass
    den = b ** 2 + g ** 2
    return np.stack([(b * fx + g * fy) / den, (b * fy - g * fx) / den], axis=1)
