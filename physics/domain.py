"""The simulation box: periodic, deforming (convergence/divergence) and walled.

All boundary handling lives here and in the two small compiled helpers
(:func:`minimum_image`, :func:`wrap_coordinate`); force code asks for the
minimum-image displacement and never looks at the box otherwise.

Boxes are ``[0, Lx) × [0, Ly)``. A non-periodic side is a straight rigid wall
(at x = 0 and x = Lx, or y = 0 and y = Ly), in contact with the floes through
the same Hertz–Mindlin law as floe–floe contacts (the wall is a floe of
infinite radius and mass).

Boxes are handed to the compiled kernels as a small float array
(:meth:`Box.kernel_array`), see ``BOX_*`` indices below.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .params import check_range

__all__ = ["Box", "PeriodicBox", "DeformingPeriodicBox", "ChannelBox", "WalledBox",
           "minimum_image", "wrap_coordinate"]

# layout of Box.kernel_array()
BOX_LX, BOX_LY, BOX_PX, BOX_PY = 0, 1, 2, 3
BOX_DEFORM, BOX_C0, BOX_RATE, BOX_T0, BOX_LX0, BOX_LY0, BOX_AXES = 4, 5, 6, 7, 8, 9, 10
BOX_SIZE = 11


@njit(cache=True, inline="always", error_model="numpy")
def minimum_image(d, length, periodic):
    """Minimum-image component of a displacement ``d`` along an axis [m]."""
    if periodic:
        d -= length * math.floor(d / length + 0.5)
    return d


@njit(cache=True, inline="always", error_model="numpy")
def wrap_coordinate(x, length, periodic):
    """Map a coordinate into [0, length) along a periodic axis."""
    if periodic:
        x -= length * math.floor(x / length)
        if x >= length:      # round-off of floor for x just below 0
            x -= length
    return x


class Box:
    """A rectangular box ``[0, lx) × [0, ly)``; each axis periodic or walled.

    Parameters
    ----------
    lx, ly : float
        Side lengths [m].
    periodic : (bool, bool)
        Periodicity along x and y. A non-periodic axis has rigid walls at
        both ends.
    """

    deforming = False

    def __init__(self, lx, ly=None, periodic=(True, True)):
        if ly is None:
            if np.ndim(lx) == 1:
                lx, ly = lx
            else:
                ly = lx
        check_range(f"{type(self).__name__}.lx", lx, 0.0, None, low_open=True)
        check_range(f"{type(self).__name__}.ly", ly, 0.0, None, low_open=True)
        self.lx = float(lx)
        self.ly = float(ly)
        self.periodic = (bool(periodic[0]), bool(periodic[1]))

    # -- geometry ------------------------------------------------------------
    @property
    def lengths(self) -> np.ndarray:
        return np.array([self.lx, self.ly])

    @property
    def area(self) -> float:
        """Box area S [m²]."""
        return self.lx * self.ly

    def minimum_image(self, d):
        """Minimum-image form of displacement vectors ``d`` (..., 2) [m]."""
        d = np.array(d, dtype=float, copy=True)
        for k, (length, per) in enumerate(zip(self.lengths, self.periodic)):
            if per:
                d[..., k] -= length * np.floor(d[..., k] / length + 0.5)
        return d

    def wrap(self, positions):
        """Positions (..., 2) mapped into the box along periodic axes [m]."""
        p = np.array(positions, dtype=float, copy=True)
        for k, (length, per) in enumerate(zip(self.lengths, self.periodic)):
            if per:
                p[..., k] = np.mod(p[..., k], length)
                p[..., k][p[..., k] >= length] -= length
        return p

    def contains(self, positions) -> np.ndarray:
        """True where a position lies inside the box."""
        p = np.asarray(positions, dtype=float)
        return ((p[..., 0] >= 0) & (p[..., 0] < self.lx)
                & (p[..., 1] >= 0) & (p[..., 1] < self.ly))

    # -- kernels -------------------------------------------------------------
    def bind(self, total_floe_area: float) -> None:
        """Called once by an engine with the total floe area F [m²]."""

    def kernel_array(self, time: float = 0.0) -> np.ndarray:
        """Box state at model time ``time`` for the compiled kernels (see the
        ``BOX_*`` indices)."""
        b = np.zeros(BOX_SIZE)
        b[BOX_LX], b[BOX_LY] = self.lx, self.ly
        b[BOX_PX], b[BOX_PY] = float(self.periodic[0]), float(self.periodic[1])
        b[BOX_LX0], b[BOX_LY0] = self.lx, self.ly
        return b

    def update_from_kernel(self, b: np.ndarray) -> None:
        """Take back the box size after the kernels advanced it."""
        self.lx, self.ly = float(b[BOX_LX]), float(b[BOX_LY])

    def __repr__(self):
        return f"{type(self).__name__}(lx={self.lx:g}, ly={self.ly:g}, periodic={self.periodic})"


class PeriodicBox(Box):
    """Doubly periodic box: ``PeriodicBox(L)`` (square) or ``PeriodicBox(Lx, Ly)``."""

    def __init__(self, lx, ly=None):
        super().__init__(lx, ly, periodic=(True, True))


class ChannelBox(Box):
    """Periodic along x, rigid walls at y = 0 and y = ly (e.g. a coast or
    a fast-ice edge below and an open-ocean limit above)."""

    def __init__(self, lx, ly=None):
        super().__init__(lx, ly, periodic=(True, False))


class WalledBox(Box):
    """Rigid walls on all four sides."""

    def __init__(self, lx, ly=None):
        super().__init__(lx, ly, periodic=(False, False))


class DeformingPeriodicBox(PeriodicBox):
    """Periodic box whose area changes so that the ice concentration changes
    at a prescribed rate (convergence > 0, divergence < 0).

    The concentration is ``A(t) = A₀ + rate · (t − t₀)`` with ``A = F / S``
    (F the total floe area, S the box area), so the box area follows
    ``S(t) = F / A(t)``. The deformation is affine: every step, the positions
    of all mobile floes are scaled with the box ("remap x"); velocities are
    the floes' own (peculiar) velocities and are not remapped. Frozen floes
    stay where they are.

    Parameters
    ----------
    lx, ly : float
        Initial side lengths [m].
    concentration_rate : float
        dA/dt [1/s]; e.g. ``0.04 / 3600`` for the 0.04 per hour of Herman (2013).
    axes : {"xy", "x", "y"}
        "xy" scales both sides by the same factor (isotropic convergence);
        "x" or "y" deforms one side only (uniaxial).
    max_concentration : float
        The run stops with an error before A would pass this value.
    """

    deforming = True
    _AXES = {"xy": 0.0, "x": 1.0, "y": 2.0}

    def __init__(self, lx, ly=None, *, concentration_rate=0.0, axes="xy",
                 max_concentration=0.999):
        super().__init__(lx, ly)
        check_range("DeformingPeriodicBox.concentration_rate", concentration_rate)
        check_range("DeformingPeriodicBox.max_concentration", max_concentration, 0.0, 1.0,
                    low_open=True)
        if axes not in self._AXES:
            raise ValueError(f"DeformingPeriodicBox.axes must be one of {sorted(self._AXES)}, got {axes!r}")
        self.concentration_rate = float(concentration_rate)
        self.axes = axes
        self.max_concentration = float(max_concentration)
        self.total_floe_area = None

    def bind(self, total_floe_area: float) -> None:
        self.total_floe_area = float(total_floe_area)
        if self.concentration >= self.max_concentration:
            raise ValueError(
                f"initial concentration {self.concentration:.4f} is above "
                f"max_concentration={self.max_concentration}")

    @property
    def concentration(self) -> float:
        """Current ice concentration A = F / S [-]."""
        if self.total_floe_area is None:
            raise RuntimeError("the box is not bound to a floe field yet")
        return self.total_floe_area / self.area

    def set_rate(self, concentration_rate: float) -> None:
        """Change dA/dt for the next advance (the environments call this)."""
        check_range("DeformingPeriodicBox.concentration_rate", concentration_rate)
        self.concentration_rate = float(concentration_rate)

    def kernel_array(self, time: float = 0.0) -> np.ndarray:
        # A(t) is linear, so the reference state is simply the current one
        b = super().kernel_array(time)
        b[BOX_DEFORM] = 1.0
        b[BOX_C0] = self.concentration
        b[BOX_RATE] = self.concentration_rate
        b[BOX_T0] = time
        b[BOX_AXES] = self._AXES[self.axes]
        return b


@njit(cache=True, error_model="numpy")
def box_lengths_at(box, time):
    """Side lengths of a (possibly deforming) box at model time ``time``.

    Returns (lx, ly, concentration); the concentration is 0 for a rigid box.
    """
    if box[BOX_DEFORM] == 0.0:
        return box[BOX_LX], box[BOX_LY], 0.0
    c = box[BOX_C0] + box[BOX_RATE] * (time - box[BOX_T0])
    ratio = box[BOX_C0] / c                       # S(t) / S(t0)
    if box[BOX_AXES] == 0.0:
        s = math.sqrt(ratio)
        return box[BOX_LX0] * s, box[BOX_LY0] * s, c
    if box[BOX_AXES] == 1.0:
        return box[BOX_LX0] * ratio, box[BOX_LY0], c
    return box[BOX_LX0], box[BOX_LY0] * ratio, c
