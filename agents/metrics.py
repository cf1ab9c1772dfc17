"""The physics metrics of each environment that training logs and
evaluation reports.

Which entries of ``info["physics"]`` each task logs, under which names, and
its main metric are facts of the environment (:class:`iceenvs.facts.EnvFacts`);
this module reads them. The floe environments share the observables of
:mod:`iceenvs.observations` (SI units: pressure [N/m], velocities [m/s],
fractions without unit); each task adds its own entries (edge stress,
collision rate, thickness distribution). Only scalar entries are taken.
"""
from __future__ import annotations

from iceenvs.facts import env_facts

__all__ = ["env_name", "physics_metrics"]


def env_name(env_id: str) -> str:
    """``"iceenvs/Convergence-v0"`` → ``"Convergence-v0"``."""
    return env_id.split("/")[-1]


def physics_metrics(env_id: str, info: dict) -> dict[str, float]:
    """The logged metrics of one ``info`` dict: the mapped scalar entries of
    ``info["physics"]`` (all finite scalar entries for an env without a
    map) and the episode metrics (a ship's path length, impulses, ...);
    empty when the info holds no physics
    (:meth:`iceenvs.facts.EnvFacts.logged_metrics`)."""
    return env_facts(env_id).logged_metrics(info)
