"""Observations of the floe environments: physical values in SI units and
their normalised float32 vector.

:func:`floe_physics` measures one snapshot of an engine (a
:class:`physics.HertzSimulation` or :class:`physics.HardDiskSimulation`)
with :mod:`physics.observables` and :mod:`physics.clusters` and returns a
dict of SI values; :func:`normalise` maps such a dict to the vector the
agent sees, feature by feature, as listed in :data:`FLOE_FEATURES`. The raw
dict is what reward functions receive and what ``info["physics"]`` holds.

Scaling of the vector (every entry is clipped into the observation space):

* fractions and direction cosines are passed as they are;
* a stress s [N/m] is ``sign(s) log10(1 + |s| / 1 N/m)`` (so 1 ↔ 9 N/m,
  4 ↔ 10 kN/m), bounded to [−8, 8];
* velocities are divided by 1 m/s and bounded to [−5, 5];
* the granular temperature T [m²/s²] is ``log10(1 + T / 1e-6 m²/s²)``,
  bounded to [0, 10];
* a rate x [1/s] is ``log10(1 + x / 0.01 1/s)``, bounded to [0, 10];
* the cluster exponent α is passed as it is (0 when undefined), bounded to
  [0, 10];
* a force F [N] or moment M [N m] is ``sign(F) log10(1 + |F| / 1 N)`` (the
  stress scaling with 1 N or 1 N m);
* a distance is divided by 100 m and a yaw rate by 0.1 rad/s;
* an impulse J [N s] is ``log10(1 + J / 10⁴ N s)`` (so 1 ↔ 9·10⁴ N s,
  the head-on impulse of a floe of about 3 m radius from a ship at 2 m/s,
  and 3 ↔ 10⁷ N s, that of one of 40 m).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numba import njit

from physics import cluster_statistics, find_clusters
from physics.markdown import table_row

__all__ = ["Feature", "FLOE_FEATURES", "floe_physics", "normalise", "normalise_rows",
           "observation_vectors", "log_stress", "feature_table"]

STRESS_REF = 1.0          # N/m
TEMPERATURE_REF = 1e-6    # m²/s²
RATE_REF = 0.01           # 1/s
IMPULSE_REF = 1e4         # N s


@dataclass(frozen=True)
class Feature:
    """One observation entry: name, meaning, unit of the raw value, scaling,
    bounds of the scaled value."""
    name: str
    meaning: str
    unit: str
    scaling: str
    low: float
    high: float


def log_stress(s):
    """sign(s) log10(1 + |s| / 1 N/m)."""
    return float(_scaled(1, float(s)))


FLOE_FEATURES: tuple[Feature, ...] = (
    Feature("concentration", "ice concentration A = floe area / box area", "-", "none", 0.0, 1.0),
    Feature("z_c", "mean contact number of non-rattlers Z_c (Herman 2013 eq 10)", "-", "none",
            0.0, 20.0),
    Feature("z_a", "contact anisotropy Z_a", "-", "none", 0.0, 20.0),
    Feature("f_nr", "fraction of non-rattlers (floes with ≥ 2 contacts)", "-", "none", 0.0, 1.0),
    Feature("fabric_cos2", "cos 2θ_f of the fabric's principal direction θ_f", "-", "none",
            -1.0, 1.0),
    Feature("fabric_sin2", "sin 2θ_f", "-", "none", -1.0, 1.0),
    Feature("pressure", "p = (σ₁ + σ₂)/2 of the contact stress, compression > 0", "N/m",
            "log stress", -8.0, 8.0),
    Feature("shear", "τ = (σ₁ − σ₂)/2", "N/m", "log stress", -8.0, 8.0),
    Feature("stress_cos2", "cos 2θ_σ of the major principal stress direction θ_σ", "-", "none",
            -1.0, 1.0),
    Feature("stress_sin2", "sin 2θ_σ", "-", "none", -1.0, 1.0),
    Feature("u_x", "mean ice velocity, x (mass-weighted, mobile floes)", "m/s", "/ 1 m/s",
            -5.0, 5.0),
    Feature("u_y", "mean ice velocity, y", "m/s", "/ 1 m/s", -5.0, 5.0),
    Feature("temperature", "granular temperature ⟨|u − ū|²⟩/2 (mass-weighted)", "m²/s²",
            "log temperature", 0.0, 10.0),
    Feature("largest_cluster", "area of the largest cluster / total floe area", "-", "none",
            0.0, 1.0),
    Feature("clusters_per_floe", "number of clusters / number of floes", "-", "none", 0.0, 1.0),
    Feature("cluster_alpha", "ML exponent α of the cluster-size distribution (0: undefined)",
            "-", "exponent", 0.0, 10.0),
)


def _direction(tensor):
    """(cos 2θ, sin 2θ) of the major principal axis of a symmetric 2×2 tensor
    (0, 0 when isotropic)."""
    a, b, c = tensor[0, 0], tensor[0, 1], tensor[1, 1]
    x, y = a - c, 2.0 * b
    norm = math.hypot(x, y)
    if norm <= 1e-12 * (abs(a) + abs(c) + 1e-300):
        return 0.0, 0.0
    return x / norm, y / norm


def floe_physics(positions, velocities, masses, radii, box, contacts, stress_tensor, area,
                 mobile, *, cluster_gap: float) -> dict:
    """Physical observables of one snapshot, SI units (see :data:`FLOE_FEATURES`).

    ``contacts`` is a :class:`physics.Contacts` table, ``stress_tensor`` the
    (2, 2) contact stress [N/m] (compression positive), ``mobile`` the mask
    of floes that can move, ``cluster_gap`` [m] the largest edge-to-edge
    gap of two floes of one cluster.
    """
    from physics import fabric

    n = radii.size
    fab = fabric(contacts, n)
    s1, s2 = np.linalg.eigvalsh(0.5 * (stress_tensor + stress_tensor.T))[::-1]
    fc, fs = _direction(fab.tensor)
    sc, ss = _direction(stress_tensor)
    m = masses[mobile]
    v = velocities[mobile]
    if m.size:
        mean_v = (m[:, None] * v).sum(axis=0) / m.sum()
        temp = 0.5 * float((m * ((v - mean_v) ** 2).sum(axis=1)).sum() / m.sum())
    else:
        mean_v, temp = np.zeros(2), 0.0
    stats = cluster_statistics(find_clusters(positions, radii, box, cluster_gap), radii)
    return dict(
        concentration=float(np.pi * np.sum(radii ** 2) / area),
        z_c=float(fab.z_c), z_a=float(fab.z_a), f_nr=float(fab.f_nr),
        fabric_cos2=fc, fabric_sin2=fs,
        pressure=float(0.5 * (s1 + s2)), shear=float(0.5 * (s1 - s2)),
        stress_cos2=sc, stress_sin2=ss,
        u_x=float(mean_v[0]), u_y=float(mean_v[1]), temperature=temp,
        largest_cluster=float(stats.largest_fraction),
        clusters_per_floe=stats.n_clusters / n,
        cluster_alpha=float(stats.alpha) if math.isfinite(stats.alpha) else 0.0,
    )


def normalise(raw: dict, features) -> np.ndarray:
    """The float32 vector of ``features`` from a raw dict, scaled and clipped
    into each feature's bounds; a non-finite value becomes 0
    (:func:`normalise_rows` of one row)."""
    row = np.array([[float(raw[f.name]) for f in features]])
    return normalise_rows(row, features)[0]


def normalise_rows(raw: np.ndarray, features) -> np.ndarray:
    """:func:`normalise` of many raw measurements at once: ``raw`` (M,
    len(features)) holds one measurement per row, its columns the raw
    values of ``features``; returns the (M, len(features)) float32 array of
    their vectors, in one compiled call. A single environment calls it with
    one row, a vector environment with one row per sub-environment: the
    same arithmetic, so the same numbers."""
    codes, low, high = _feature_arrays(tuple(features))
    raw = np.ascontiguousarray(raw, dtype=np.float64)
    if raw.ndim != 2 or raw.shape[1] != codes.size:
        raise ValueError(f"raw must be an (M, {codes.size}) array (one column per feature), "
                         f"got shape {raw.shape}")
    return _normalise_rows(raw, codes, low, high)


def observation_vectors(raw: np.ndarray, features, actions: np.ndarray) -> np.ndarray:
    """The vector observations of an environment family: the scaled
    ``features`` of each row of ``raw`` (:func:`normalise_rows`), then that
    row's last action ``actions`` (M, n_actions) as float32."""
    return np.concatenate([normalise_rows(raw, features), actions.astype(np.float32)], axis=1)


#: the scalings (the names of the module docstring) as the codes of :func:`_scaled`
_SCALING_CODES = {"none": 0, "log stress": 1, "log force": 1, "/ 1 m/s": 2,
                  "log temperature": 3, "log rate": 4, "exponent": 5, "/ 100 m": 6,
                  "/ 0.1 rad/s": 7, "log impulse": 8}


@lru_cache(maxsize=64)
def _feature_arrays(features: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The scaling codes and the bounds of ``features``, as arrays."""
    return (np.array([_SCALING_CODES[f.scaling] for f in features], dtype=np.int64),
            np.array([f.low for f in features], dtype=np.float64),
            np.array([f.high for f in features], dtype=np.float64))


@njit(cache=True, error_model="numpy")
def _scaled(code, x):
    """The scaling ``code`` of :data:`_SCALING_CODES` applied to ``x``."""
    if code == 1:
        return math.copysign(math.log10(1.0 + abs(x) / STRESS_REF), x)
    if code == 2:
        return x / 1.0
    if code == 3:
        return math.log10(1.0 + max(x, 0.0) / TEMPERATURE_REF)
    if code == 4:
        return math.log10(1.0 + max(x, 0.0) / RATE_REF)
    if code == 5:
        return x if math.isfinite(x) else 0.0
    if code == 6:
        return x / 100.0
    if code == 7:
        return x / 0.1
    if code == 8:
        return math.log10(1.0 + max(x, 0.0) / IMPULSE_REF)
    return x


@njit(cache=True, error_model="numpy")
def _normalise_rows(raw, codes, low, high):
    out = np.empty(raw.shape, dtype=np.float32)
    for m in range(raw.shape[0]):
        for k in range(raw.shape[1]):
            x = _scaled(codes[k], raw[m, k])
            if not math.isfinite(x):
                x = 0.0
            out[m, k] = min(max(x, low[k]), high[k])
    return out


def feature_table(features) -> str:
    """Markdown table of the observation entries (for docstrings and the README)."""
    lines = ["| index | name | meaning | unit | scaling | bounds |", "|---|---|---|---|---|---|"]
    for k, f in enumerate(features):
        lines.append(table_row([k, f"`{f.name}`", f.meaning, f.unit, f.scaling,
                                f"[{f.low:g}, {f.high:g}]"]))
    return "\n".join(lines)
