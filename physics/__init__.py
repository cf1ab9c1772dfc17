"""Floe-scale sea-ice physics: two engines, observables and the ITD model.

Engines
    :class:`HertzSimulation` — Hertzian soft-contact DEM (Herman 2013).
    :class:`HardDiskSimulation` — event-driven hard discs (Herman 2011).
State and set-up
    :class:`FloeField`, :func:`make_floe_field`, boxes of :mod:`physics.domain`,
    :class:`Forcing`, parameter tables :data:`HERMAN2011`, :data:`HERMAN2013`,
    :data:`GODLOVITCH`.
Observables
    :mod:`physics.observables` — contact fabric and stress (both engines).
    :mod:`physics.clusters` — clusters, power-law exponents, g_rdf, g_ffd.
Ice thickness distribution
    :mod:`physics.itd` — Smoluchowski coagulation, the generalised Thorndike
    model (:class:`ThorndikeModel`), Lensu's fragmentation.

This package never imports gymnasium or torch.
"""
from . import _jit_cache  # noqa: F401  (first: sets where compiled kernels are cached)
from .contact import damping_alpha
from .domain import Box, ChannelBox, DeformingPeriodicBox, PeriodicBox, WalledBox
from .floes import (FloeField, PlacementError, domain_size, make_floe_field, place_floes,
                    power_law_diameters, rank_order_diameters, sample_power_law_diameters)
from .forcing import Forcing, ForcingParams, steady_drift
from .clusters import (ClusterStats, cluster_statistics, find_clusters, fsd_exponent, g_ffd,
                       g_rdf, power_law_exponent, rank_order)
from .harddisk import CollisionLog, HardDiskSimulation
from .hertz import HertzSimulation
from .itd import ThorndikeModel, make_kernel, solve_fragmentation, solve_smoluchowski
from .observables import (Contacts, Fabric, Stress, collision_stress, contacts_within, fabric,
                          stress)
from .params import GODLOVITCH, HERMAN2011, HERMAN2013, ContactParams, ItdPreset, PaperPreset

__version__ = "0.1.0"

__all__ = [
    "Box", "ChannelBox", "DeformingPeriodicBox", "PeriodicBox", "WalledBox",
    "FloeField", "PlacementError", "domain_size", "make_floe_field", "place_floes",
    "power_law_diameters", "rank_order_diameters", "sample_power_law_diameters",
    "Forcing", "steady_drift", "Contacts", "HertzSimulation", "CollisionLog",
    "HardDiskSimulation",
    "Fabric", "Stress", "fabric", "stress", "collision_stress", "contacts_within",
    "ClusterStats", "find_clusters", "cluster_statistics", "power_law_exponent", "rank_order",
    "fsd_exponent", "g_rdf", "g_ffd",
    "ThorndikeModel", "make_kernel", "solve_smoluchowski", "solve_fragmentation",
    "HERMAN2011", "HERMAN2013", "ContactParams", "ForcingParams", "PaperPreset",
    "GODLOVITCH", "ItdPreset",
    "damping_alpha",
]
