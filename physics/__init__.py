"""Floe-scale sea-ice physics: two engines, observables and the ITD model.

Engines
    :class:`HertzSimulation` — Hertzian soft-contact DEM (Herman 2013).
    :class:`HardDiskSimulation` — event-driven hard discs (Herman 2011).
State and set-up
    :class:`FloeField`, :func:`make_floe_field`, boxes of :mod:`physics.domain`,
    :class:`Forcing`, parameter tables :data:`HERMAN2011`, :data:`HERMAN2013`.

This package never imports gymnasium or torch.
"""
from . import _jit_cache  # noqa: F401  (first: sets where compiled kernels are cached)
from .contact import damping_alpha
from .domain import Box, ChannelBox, DeformingPeriodicBox, PeriodicBox, WalledBox
from .floes import (FloeField, PlacementError, domain_size, make_floe_field, place_floes,
                    power_law_diameters, rank_order_diameters, sample_power_law_diameters)
from .forcing import Forcing, steady_drift
from .harddisk import CollisionLog, HardDiskSimulation
from .hertz import Contacts, HertzSimulation
from .params import HERMAN2011, HERMAN2013, ContactParams, ForcingParams, PaperPreset

__version__ = "0.1.0"

__all__ = [
    "Box", "ChannelBox", "DeformingPeriodicBox", "PeriodicBox", "WalledBox",
    "FloeField", "PlacementError", "domain_size", "make_floe_field", "place_floes",
    "power_law_diameters", "rank_order_diameters", "sample_power_law_diameters",
    "Forcing", "steady_drift", "Contacts", "HertzSimulation", "CollisionLog",
    "HardDiskSimulation",
    "HERMAN2011", "HERMAN2013", "ContactParams", "ForcingParams", "PaperPreset",
    "damping_alpha",
]
