"""The simulation box: periodic, deforming (convergence/divergence) and walled.

All boundary handling lives here and in the two small compiled helpers
(:func:`minimum_image`, :func:`wrap_coordinate`); force code asks for the
minimum-image displacement and never looks at the box otherwise.

Boxes are ``[0, Lx) × [0, Ly)``. A non-periodic side is a straight rigid wall
(at x = 0 and x = Lx, or y = 0 and y = Ly), in contact with the floes through
the same Hertz–Mindlin law as floe–floe contacts (the wall is a floe of
infinite radius and mass).

Boxes are handed to the compiled kernels as a named bundle,
:class:`KernelBox` (:meth:`Box.kernel_box`).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .input_checks import check_range

__all__ = ["Box", "PeriodicBox", "DeformingPeriodicBox", "ChannelBox", "WalledBox",
           "KernelBox", "minimum_image", "wrap_coordinate"]


class KernelBox(NamedTuple):
    """A box as the compiled kernels see it (:meth:`Box.kernel_box`).

    ``lengths`` is the one mutable part: the kernels that advance a
    deforming box write its new side lengths there, and
    :meth:`Box.update_from_kernel` takes them back.
    """

    #: (2,) current side lengths (lx, ly) [m]
    lengths: np.ndarray
    periodic_x: bool
    periodic_y: bool
    #: whether the size follows the concentration (:class:`DeformingPeriodicBox`)
    deforming: bool
    #: concentration A at ``time0`` [-] (0 for a rigid box)
    concentration: float
    #: dA/dt [1/s]
    rate: float
    #: model time [s] of the reference state
    time0: float
    #: side lengths [m] at ``time0``
    lx0: float
    ly0: float
    #: which sides deform: 0 both ("xy"), 1 x only, 2 y only
    axes: int
    #: the concentration at which the kernels stop a deforming box
    max_concentration: float


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

    def kernel_box(self, time: float = 0.0) -> KernelBox:
        """Box state at model time ``time`` for the compiled kernels."""
        return KernelBox(np.array([self.lx, self.ly]), self.periodic[0], self.periodic[1],
                         False, 0.0, 0.0, float(time), self.lx, self.ly, 0, 1.0)

    def update_from_kernel(self, b: KernelBox) -> None:
        """Take back the box size after the kernels advanced it."""
        self.lx, self.ly = float(b.lengths[0]), float(b.lengths[1])

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
    _AXES = {"xy": 0, "x": 1, "y": 2}

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

    def kernel_box(self, time: float = 0.0) -> KernelBox:
        # A(t) is linear, so the reference state is simply the current one
        return super().kernel_box(time)._replace(
            deforming=True, concentration=float(self.concentration),
            rate=self.concentration_rate, axes=self._AXES[self.axes],
            max_concentration=self.max_concentration)


@njit(cache=True, error_model="numpy")
def box_lengths_at(box, time):
    """Side lengths of a (possibly deforming) box at model time ``time``.

    Returns (lx, ly, concentration); the concentration is 0 for a rigid box.
    """
    if not box.deforming:
        return box.lengths[0], box.lengths[1], 0.0
    c = box.concentration + box.rate * (time - box.time0)
    ratio = box.concentration / c                 # S(t) / S(t0)
    if box.axes == 0:
        s = math.sqrt(ratio)
        return box.lx0 * s, box.ly0 * s, c
    if box.axes == 1:
        return box.lx0 * ratio, box.ly0, c
    return box.lx0, box.ly0 * ratio, c
