"""The contract both floe engines keep.

:class:`~physics.hertz.HertzSimulation` (soft Hertzian contacts, fixed time
step) and :class:`~physics.harddisk.HardDiskSimulation` (hard discs,
event-driven) model floes differently but are used the same way.
Environments, scenarios, benchmarks and the demo are written against
:class:`FloeEngine`, so that code which only reads the state, advances it
and measures it runs on either engine.

The contract
------------
Names
    The same name always means the same thing: ``n_floes``, ``time``,
    ``box``, ``positions``, ``velocities``, ``angular_velocities``,
    ``radii``, ``masses``, ``frozen``, ``concentration``, ``advance``,
    ``contacts``, ``fabric``, ``contact_stress``, ``kinetic_energy``,
    ``momentum`` and ``state``. The per-floe names are those of
    :class:`~physics.floes.FloeField`.
Input
    The :class:`~physics.floes.FloeField` given to the constructor is
    copied; the caller's arrays are never modified.
Arrays exposed
    ``positions``, ``velocities`` and ``angular_velocities`` are read-only
    snapshots taken at the call: they do not follow the simulation as it
    advances, and writing into them raises ``ValueError``. Assign a whole
    array to ``velocities`` (or ``angular_velocities``) to change the state;
    the assignment is checked (shape, finiteness, frozen floes at rest).
    ``radii``, ``masses`` and ``frozen`` never change during a run; they
    are read-only too (writing raises ``ValueError``), and may be views of
    the engine's own arrays rather than copies (:func:`read_only`).
Mistakes
    A wrong type is a ``TypeError``, a wrong value (out of range, wrong
    shape, not finite, overlapping floes) a ``ValueError``, both raised
    before anything changes. When the physics itself breaks down during
    :meth:`~FloeEngine.advance` (a non-finite or unstable state, a deforming
    box at its concentration limit, an inelastic collapse) the engine raises
    :class:`SimulationError`, whose :attr:`~SimulationError.reason` says
    which; the state is then no longer meaningful.
"""
from __future__ import annotations

import inspect
import math
from enum import Enum
from typing import Protocol, runtime_checkable

import numpy as np

from .input_checks import check_range
from .domain import Box
from .floes import FloeField, max_overlap
from .forcing import Forcing
from .observables import Contacts, Fabric, Stress
from .params import ContactParams, PaperPreset

__all__ = ["FailureReason", "FloeEngine", "FloeProperties", "SimulationError", "checked_motion",
           "engine_from_preset", "read_only", "snapshot"]


class FailureReason(str, Enum):
    """Why an engine stopped."""

    #: a position, velocity or event time became NaN or infinite
    NON_FINITE = "non-finite state"
    #: a floe moved too far in one step for the neighbour list (Hertz engine)
    UNSTABLE = "unstable integration"
    #: a deforming box reached its concentration limit (Hertz engine)
    CONCENTRATION_LIMIT = "concentration limit"
    #: a floe collided too often in too short a time (hard-disc engine, TC model off)
    INELASTIC_COLLAPSE = "inelastic collapse"


class SimulationError(RuntimeError, FloatingPointError):
    """The physics broke down during :meth:`FloeEngine.advance`.

    It is both a ``RuntimeError`` and a ``FloatingPointError``, so code
    written against either keeps catching it.

    Attributes
    ----------
    reason : FailureReason
    time : float
        Model time [s] at which it happened.
    """

    def __init__(self, message: str, reason: FailureReason, time: float):
        super().__init__(message)
        self.reason = FailureReason(reason)
        self.time = float(time)


@runtime_checkable
class FloeEngine(Protocol):
    """What every floe engine offers; see the module docstring for the
    copy and error semantics."""

    #: model time [s]
    time: float
    #: the simulation's box (it owns and updates it; a deforming box changes size)
    box: Box

    @property
    def n_floes(self) -> int:
        """Number of floes N."""
        ...

    @property
    def positions(self) -> np.ndarray:
        """(N, 2) floe centres [m], wrapped into the box; a read-only snapshot."""
        ...

    @property
    def velocities(self) -> np.ndarray:
        """(N, 2) floe velocities [m/s]; a read-only snapshot (assign to change)."""
        ...

    @property
    def angular_velocities(self) -> np.ndarray:
        """(N,) angular velocities [1/s]; a read-only snapshot (zero for hard discs)."""
        ...

    @property
    def radii(self) -> np.ndarray:
        """(N,) floe radii r [m]; read-only."""
        ...

    @property
    def masses(self) -> np.ndarray:
        """(N,) floe masses m = ρ h π r² [kg]; read-only."""
        ...

    @property
    def frozen(self) -> np.ndarray:
        """(N,) bool, True for the floes held fixed (inverse mass 0: they
        never move but take part in contacts); read-only."""
        ...

    @property
    def concentration(self) -> float:
        """Ice concentration A = Σ π r² / S of the box now [-]."""
        ...

    def advance(self, duration: float, *, progress: bool = False) -> None:
        """Advance the model time by ``duration`` seconds."""
        ...

    def contacts(self) -> Contacts:
        """The floe–floe contacts of the current state."""
        ...

    def fabric(self) -> Fabric:
        """The contact fabric tensor of the current state."""
        ...

    def contact_stress(self, *, per_floe: bool = True) -> Stress:
        """The contact stress tensor (and, if asked, its per-floe parts)."""
        ...

    def kinetic_energy(self) -> float:
        """Translational plus rotational kinetic energy [J]."""
        ...

    def momentum(self) -> np.ndarray:
        """Total linear momentum (2,) [kg m/s]."""
        ...

    def state(self) -> FloeField:
        """The current state as a new :class:`~physics.floes.FloeField`."""
        ...


def engine_from_preset(cls, preset, n, concentration, seed, forcing, defaults, kwargs: dict):
    """The engine ``cls`` set up from a paper preset: the work of the
    engines' ``from_preset`` class methods.

    The floes come from ``preset.floe_field(n, concentration, seed=seed)``
    with the keywords of ``kwargs`` that are not parameters of the
    constructor; the others go to the constructor and replace the
    preset's values given by ``defaults(preset)`` (a dict of constructor
    arguments). ``forcing`` True is the preset's
    (:meth:`~physics.params.PaperPreset.make_forcing`), False or None
    none, a :class:`~physics.forcing.Forcing` that one.
    """
    if not isinstance(preset, PaperPreset):
        raise TypeError(f"preset must be a PaperPreset, got {type(preset).__name__}")
    own = set(inspect.signature(cls.__init__).parameters) - {"self", "field", "box", "forcing"}
    engine = {k: kwargs.pop(k) for k in list(kwargs) if k in own}
    if forcing is True:
        forcing = preset.make_forcing()
    elif forcing is False:
        forcing = None
    field, box = preset.floe_field(n, concentration, seed=seed, **kwargs)
    return cls(field, box, forcing=forcing, **{**defaults(preset), **engine})


def snapshot(a: np.ndarray) -> np.ndarray:
    """A read-only copy of ``a``: what an engine's ``positions``,
    ``velocities`` and ``angular_velocities`` return."""
    c = np.array(a, copy=True)
    c.flags.writeable = False
    return c


def read_only(a: np.ndarray) -> np.ndarray:
    """A read-only view of ``a``, without a copy: what the engines'
    ``radii``, ``masses`` and ``frozen`` return, arrays that do not change
    during a run."""
    v = a.view()
    v.flags.writeable = False
    return v


class FloeProperties:
    """``radii``, ``masses`` and ``frozen`` of :class:`FloeEngine` for an
    engine that keeps them in its arrays ``_radius``, ``_mass`` and
    ``_frozen``: read-only views of those (:func:`read_only`)."""

    _radius: np.ndarray
    _mass: np.ndarray
    _frozen: np.ndarray

    @property
    def radii(self) -> np.ndarray:
        """(N,) floe radii [m] (a read-only view; they never change)."""
        return read_only(self._radius)

    @property
    def masses(self) -> np.ndarray:
        """(N,) floe masses ρ h π r² [kg] (a read-only view; they never change)."""
        return read_only(self._mass)

    @property
    def frozen(self) -> np.ndarray:
        """(N,) bool, True for the floes held fixed (inverse mass 0; a
        read-only view)."""
        return read_only(self._frozen)


def checked_motion(name: str, value, shape: tuple, frozen: np.ndarray, what: str) -> np.ndarray:
    """``value`` as a float array of ``shape``, finite and zero for the
    ``frozen`` floes, else ``ValueError``: the check of an assignment to an
    engine's ``velocities`` or ``angular_velocities``. ``what`` names the
    quantity in the message about frozen floes."""
    v = np.asarray(value, dtype=float)
    if v.shape != shape or not np.all(np.isfinite(v)):
        raise ValueError(f"{name} must be a finite array of shape {shape}")
    if np.any(v[frozen] != 0.0):
        raise ValueError(f"frozen floes must have zero {what}")
    return v


# -- the set-up checks of the Hertz engines (ours and LAMMPS's) ----------------------

def checked_hertz_arguments(field, box, contact, forcing, dt, impact_speed) -> ContactParams:
    """The common arguments of a Hertz engine checked (``TypeError`` or
    ``ValueError`` saying what is wrong); returns ``contact``, the default
    :class:`~physics.params.ContactParams` when it is None."""
    if not isinstance(field, FloeField):
        raise TypeError(f"field must be a FloeField, got {type(field).__name__}")
    if not isinstance(box, Box):
        raise TypeError(f"box must be a Box (e.g. PeriodicBox(L)), got {type(box).__name__}")
    contact = ContactParams() if contact is None else contact
    if not isinstance(contact, ContactParams):
        raise TypeError(f"contact must be a ContactParams, got {type(contact).__name__}")
    if forcing is not None and not isinstance(forcing, Forcing):
        raise TypeError(f"forcing must be a Forcing or None, got {type(forcing).__name__}")
    check_range("dt", dt, 0.0, None, low_open=True)
    check_range("impact_speed", impact_speed, 0.0, None, low_open=True)
    return contact


def check_time_step(dt: float, contact_time: float, what: str) -> None:
    """``ValueError`` unless ``dt`` is at most a tenth of ``contact_time``,
    the shortest contact time (of ``what``)."""
    if dt > 0.1 * contact_time:
        raise ValueError(
            f"dt={dt:g} s is above a tenth of the shortest contact time "
            f"({contact_time:.4g} s for {what}); "
            f"use dt <= {0.1 * contact_time:.3g} s")


def default_skin(radii: np.ndarray) -> float:
    """The skin [m] of a Hertz engine's neighbour lists unless one is given:
    a tenth of the mean radius."""
    return 0.1 * float(np.mean(radii))


def largest_radius(box: Box, skin: float) -> float:
    """The bound [m] that every floe radius must stay below for
    :func:`neighbour_cut` to accept the floes in ``box`` with ``skin``:
    each periodic side must exceed twice the largest pair's cut-off
    2 r_max + skin (infinite when no side is periodic)."""
    sides = [length for length, per in zip((box.lx, box.ly), box.periodic) if per]
    return min((0.5 * (0.5 * length - skin) for length in sides), default=math.inf)


def neighbour_cut(radii: np.ndarray, box: Box, skin: float | None) -> tuple[float, float]:
    """(skin, cut-off of the largest pair 2 r_max + skin) of a Hertz engine's
    neighbour lists: the skin defaults to :func:`default_skin`, and a
    periodic side must exceed twice the cut-off (``ValueError``)."""
    skin = default_skin(radii) if skin is None else float(skin)
    check_range("skin", skin, 0.0, None, low_open=True)
    cut = 2.0 * float(radii.max()) + skin
    for length, per, axis in ((box.lx, box.periodic[0], "x"), (box.ly, box.periodic[1], "y")):
        if per and cut >= 0.5 * length:
            raise ValueError(
                f"the box is too small along {axis} ({length:.4g} m) for the largest floe "
                f"(radius {radii.max():.4g} m): periodic sides must exceed "
                f"2 (2 r_max + skin) = {2 * cut:.4g} m")
    return skin, cut


def positions_in_box(field: FloeField, box: Box, allow_overlap: bool) -> np.ndarray:
    """The floe centres wrapped into ``box``; ``ValueError`` if a floe lies
    outside a walled box or, unless ``allow_overlap``, two floes overlap by
    more than 1 % of the smaller radius."""
    pos = box.wrap(field.positions)
    if not np.all(box.contains(pos)):
        bad = int(np.argmin(box.contains(pos)))
        raise ValueError(f"floe {bad} at {pos[bad]} is outside the walled box {box}")
    if not allow_overlap:
        worst = max_overlap(pos, field.radii, box)
        if worst > 0.01:
            raise ValueError(
                f"initial overlap of {worst:.3g} of the smaller radius exceeds 1 %; separate "
                f"the floes (physics.floes.place_floes) or pass allow_overlap=True")
    return pos
