"""Physical and numerical parameters, with the papers' tables as presets.

Every dataclass here is frozen and validated in ``__post_init__``: a bad value
raises :class:`ValueError` naming the field, the value and the allowed range.

Presets
-------
``HERMAN2013``  Table 1 of Herman (2013), the Hertzian soft-contact (DEM) set-up.
``HERMAN2011``  Table I of Herman (2011), the hard-disc "Small Floe Collider".

Units are SI throughout (m, s, kg, Pa); the linear water drag coefficients
``C_hw`` and ``C_vw`` are in m/s as in both papers.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

__all__ = [
    "ContactParams",
    "ForcingParams",
    "PaperPreset",
    "HERMAN2011",
    "HERMAN2013",
    "check_range",
]


def check_range(name: str, value, low=None, high=None, *, low_open=False,
                high_open=False) -> None:
    """Raise ``ValueError`` unless ``value`` is a finite number in the range.

    ``low_open``/``high_open`` make the corresponding bound strict.
    The message names the field, the value and the allowed range.
    """
    lo = "-inf" if low is None else f"{low:g}"
    hi = "inf" if high is None else f"{high:g}"
    interval = f"{'(' if (low_open or low is None) else '['}{lo}, {hi}{')' if (high_open or high is None) else ']'}"
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number in {interval}, got {value!r}") from None
    ok = math.isfinite(v)
    if ok and low is not None:
        ok = v > low if low_open else v >= low
    if ok and high is not None:
        ok = v < high if high_open else v <= high
    if not ok:
        raise ValueError(f"{name} must be in {interval}, got {value!r}")


def _check_fields(obj, spec: dict) -> None:
    for name, (low, high, low_open, high_open) in spec.items():
        check_range(f"{type(obj).__name__}.{name}", getattr(obj, name), low, high,
                    low_open=low_open, high_open=high_open)


# (low, high, low_open, high_open)
_POSITIVE = (0.0, None, True, False)
_NONNEG = (0.0, None, False, False)


@dataclass(frozen=True)
class ContactParams:
    """Hertz–Mindlin contact between floes (Herman 2013; :ref:`physics-contact`).

    Attributes
    ----------
    elastic_modulus : float
        Young's modulus E of sea ice [Pa]; 9e9 in Herman (2013).
    poisson_ratio : float
        Poisson ratio ν [-], in (-1, 0.5).
    restitution : float
        Normal coefficient of restitution e of a binary impact [-], in (0, 1].
        It is independent of impact speed for the Hertz law with the damping
        used here.
    friction : float
        Coulomb coefficient μ (the paper's "static yield criterion") [-], >= 0.
    tangential_damping : float
        Tangential damping coefficient as a multiple of the normal damping
        coefficient [-] (LAMMPS's ``x_gammat`` of ``tangential mindlin``).
        Default 0: with damping, the Coulomb cap of the Mindlin law can leave
        the spring pointing along the slip when a sliding contact starts, so
        that friction briefly pushes instead of brakes (see physics.contact).
    tangential_stiffness : float
        Multiplies the Mindlin tangential stiffness k_t = 8 G* √(R* δ) [-],
        > 0. Default 1 (Mindlin). Written as F_n = K_n √(R* δ) δ and
        F_t = K_t √(R* δ) Δs, Mindlin has K_t = 8 G* ≈ 1.2 K_n for ν = 0.33;
        LAMMPS's ``gran/hertz/history`` takes K_t = 2/7 K_n by default,
        i.e. ``tangential_stiffness`` = (2/7)(4/3) E* / (8 G*) ≈ 0.24.
    tangential_translation : bool
        Whether the tangential (friction) force of a contact acts on the
        floes' translation as well as on their rotation. Default True
        (Newton's third law at the contact point, as in LAMMPS). Herman
        (2013) writes its eqs 6–7 with only the normal force in the linear
        momentum equation and the tangential force in the angular momentum
        equation; False follows those equations as written. Then friction
        only turns floes: it does not resist sliding, and a sliding contact
        can spin floes up (towards rolling) without slowing them.
    damping_model : str
        How the damping coefficient α is set from ``restitution``:
        ``"exact"`` (default) solves the dimensionless Hertz impact so that the
        measured restitution equals the target; ``"lammps"`` uses the
        closed-form mapping of LAMMPS ``damping coeff_restitution``
        (α = √5 |ln e| / √(π² + ln² e)), which is what Herman (2013) ran with and
        gives a restitution a few per cent off the target.
    limit_damping : bool
        Clip the total normal force at zero so that damping never pulls floes
        together (ice floes have no cohesion; LAMMPS ``limit_damping``).
    """

    elastic_modulus: float = 9.0e9
    poisson_ratio: float = 0.33
    restitution: float = 0.5
    friction: float = 0.7
    tangential_damping: float = 0.0
    tangential_stiffness: float = 1.0
    tangential_translation: bool = True
    damping_model: str = "exact"
    limit_damping: bool = True

    def __post_init__(self):
        _check_fields(self, {
            "elastic_modulus": _POSITIVE,
            "poisson_ratio": (-1.0, 0.5, True, True),
            "restitution": (0.0, 1.0, True, False),
            "friction": _NONNEG,
            "tangential_damping": _NONNEG,
            "tangential_stiffness": _POSITIVE,
        })
        for name in ("tangential_translation", "limit_damping"):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise ValueError(f"ContactParams.{name} must be True or False, "
                                 f"got {getattr(self, name)!r}")
        if self.damping_model not in ("exact", "lammps"):
            raise ValueError(
                f"ContactParams.damping_model must be 'exact' or 'lammps', got {self.damping_model!r}")

    @property
    def effective_modulus(self) -> float:
        """E* = E / (2 (1 − ν²)) for two floes of the same ice [Pa]."""
        return self.elastic_modulus / (2.0 * (1.0 - self.poisson_ratio ** 2))

    @property
    def effective_shear_modulus(self) -> float:
        """G* = E / (4 (2 − ν)(1 + ν)) for two floes of the same ice [Pa]."""
        nu = self.poisson_ratio
        return self.elastic_modulus / (4.0 * (2.0 - nu) * (1.0 + nu))

    @property
    def wall_effective_modulus(self) -> float:
        """E* of a floe against a rigid wall, E / (1 − ν²) [Pa]."""
        return self.elastic_modulus / (1.0 - self.poisson_ratio ** 2)

    @property
    def wall_effective_shear_modulus(self) -> float:
        """G* of a floe against a rigid wall, E / (2 (2 − ν)(1 + ν)) [Pa]."""
        nu = self.poisson_ratio
        return self.elastic_modulus / (2.0 * (2.0 - nu) * (1.0 + nu))

    @property
    def damping_alpha(self) -> float:
        """Dimensionless damping α in η = α √(m* F_n,c / δ) (:ref:`physics-contact`)."""
        from .contact import damping_alpha

        return damping_alpha(self.restitution, self.damping_model, self.limit_damping)


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
        _check_fields(self, {
            "ice_density": _POSITIVE,
            "water_density": _POSITIVE,
            "air_density": _NONNEG,
            "air_skin_drag": _NONNEG,
            "air_form_drag": _NONNEG,
            "water_skin_drag": _NONNEG,
            "water_form_drag": _NONNEG,
            "edge_area_factor": _NONNEG,
            "wind_speed": _NONNEG,
            "wind_direction": (None, None, False, False),
            "current_speed": _NONNEG,
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


@dataclass(frozen=True)
class PaperPreset:
    """One paper's parameter table: forcing, contact, floe-size distribution
    and numerics. Pass its parts to the engines, or ``replace`` fields.

    Attributes
    ----------
    name : str
    forcing : ForcingParams
    contact : ContactParams
        For the hard-disc engine only ``contact.restitution`` is used.
    thickness : float
        Floe thickness h [m].
    fsd_exponent : float
        α of the power-law floe-size pdf P(d) ∝ d^(−1−α) [-].
    mean_diameter : float
        d̄ [m].
    n_floes : int
    concentration : float
        Default mean ice concentration Ā [-].
    time_step : float
        Δt of the Hertz engine [s] (Herman 2013).
    max_velocity_step : float
        Δt_max of the hard-disc engine's velocity updates [s] (Herman 2011).
    collision_duration : float
        Δt_c of the TC model [s] (Herman 2011).
    n_cells : int
        Cells per side of the hard-disc engine's grid in the paper.
    ensemble_members : int
    """

    name: str
    forcing: ForcingParams
    contact: ContactParams
    thickness: float
    fsd_exponent: float
    mean_diameter: float
    n_floes: int
    concentration: float
    time_step: float = 0.002
    max_velocity_step: float = 1.0
    collision_duration: float = 0.1
    n_cells: int = 10
    ensemble_members: int = 5
    notes: str = field(default="", compare=False)

    def __post_init__(self):
        _check_fields(self, {
            "thickness": _POSITIVE,
            "fsd_exponent": _POSITIVE,
            "mean_diameter": _POSITIVE,
            "n_floes": (1, None, False, False),
            "concentration": (0.0, 1.0, True, True),
            "time_step": _POSITIVE,
            "max_velocity_step": _POSITIVE,
            "collision_duration": _NONNEG,
            "n_cells": (1, None, False, False),
            "ensemble_members": (1, None, False, False),
        })

    @property
    def mean_radius(self) -> float:
        return 0.5 * self.mean_diameter

    def replace(self, **changes) -> "PaperPreset":
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)


#: Herman (2013), Table 1: Hertzian DEM of floes with Coriolis and rotation.
HERMAN2013 = PaperPreset(
    name="herman2013",
    forcing=ForcingParams(
        ice_density=910.0, water_density=1025.0, air_density=1.23,
        air_skin_drag=2.0e-3, air_form_drag=2.0e-3,
        water_skin_drag=1.0e-3, water_form_drag=1.0e-3,
        edge_area_factor=math.pi,
        wind_speed=10.0, wind_direction=0.0, current_speed=0.0,
        coriolis=1.3e-4,
    ),
    contact=ContactParams(elastic_modulus=9.0e9, poisson_ratio=0.33,
                          restitution=0.5, friction=0.7),
    thickness=1.5,
    fsd_exponent=1.8,
    mean_diameter=8.0,
    n_floes=20000,
    concentration=0.8,
    time_step=0.002,
    notes="Herman (2013), Ann. Glaciol. 54(62), Table 1. Restitution 0.5 is a "
          "choice (the paper does not state it).",
)

#: Herman (2011), Table I: the hard-disc Small Floe Collider (no Coriolis).
HERMAN2011 = PaperPreset(
    name="herman2011",
    forcing=ForcingParams(
        ice_density=910.0, water_density=1025.0, air_density=1.23,
        air_skin_drag=1.7e-3, air_form_drag=1.7e-3,
        water_skin_drag=1.3e-3, water_form_drag=1.3e-3,
        edge_area_factor=2.0,
        wind_speed=10.0, wind_direction=0.0,
        current_speed=0.1, current_angle=0.0,
        coriolis=0.0,
    ),
    contact=ContactParams(restitution=0.85, friction=0.0),
    thickness=1.5,
    fsd_exponent=1.5,
    mean_diameter=2.0,
    n_floes=3000,
    concentration=0.75,
    max_velocity_step=1.0,
    collision_duration=0.1,
    n_cells=10,
    notes="Herman (2011), Phys. Rev. E 84, 056104, Table I. The current "
          "(0.01 |u_a|) along the wind is a choice.",
)
