"""Snapshots of an episode: :class:`Snapshot`, taken by
``env.unwrapped.snapshot()`` and brought back by ``env.unwrapped.restore(s)``
(:class:`iceenvs.base.ControlEnv`; a native vector environment per
sub-environment, :class:`iceenvs.vector.HertzVectorEnv`).

What a snapshot holds is what an episode changes: each environment class
lists its per-episode members (``episode_members``, gathered over its
classes by :func:`episode_attributes`): the engine (its floes, contact
history, neighbour lists, ship, box and time), the episode's drawn task,
step counter, last measurement and observation and the episode sums of the
ship tasks (the environment's row of its batch of episodes,
:class:`iceenvs.step.Episodes`), and the environment's random generator. They are copied
together in one deep copy, so the objects they share stay shared, and a
later step changes nothing in the snapshot; ``restore`` copies them again,
so one snapshot can be restored any number of times.

The configuration is not copied: the attributes that are not episode
members (spaces, preset, contact law, features, reward) are shared with the
environment, and where the episode's objects refer to them they refer to
the environment's own. A snapshot records the configuration's plain values
(numbers, strings and their tuples and dicts) and the spaces, and restores
only into an environment of the same class whose configuration has the
same values; render settings may differ.

Caches derived from the episode (``episode_caches``) are left out and
rebuilt by the environment after a restore.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

__all__ = ["Snapshot", "episode_attributes", "take_snapshot", "restore_snapshot", "ROW"]

#: the key of a snapshot's state that holds the environment's row of its batch
#: of episodes (:meth:`iceenvs.step.Episodes.row_state`)
ROW = "episode_row"


@dataclass(frozen=True, eq=False)
class Snapshot:
    """The state of one environment's episode at one step.

    Attributes
    ----------
    env_class : type
        The environment class it was taken of.
    configuration : tuple
        The plain values of the environment's configuration, compared at
        :meth:`~iceenvs.base.ControlEnv.restore`.
    state : mapping
        Per-episode member name → its copy (read-only mapping; restoring
        copies the values again).
    steps : int
        The episode's step count when it was taken (``info["steps"]``).
    """
    env_class: type
    configuration: tuple
    state: MappingProxyType
    steps: int

    def __repr__(self):
        return (f"Snapshot({self.env_class.__name__}, steps={self.steps}, "
                f"members={sorted(self.state)})")


def _classes_tuple(cls: type, name: str) -> tuple[str, ...]:
    """The names of the class attribute ``name`` of ``cls`` and its bases,
    base classes first, each once."""
    return tuple(dict.fromkeys(n for klass in reversed(cls.__mro__)
                               for n in klass.__dict__.get(name, ())))


def episode_attributes(cls: type) -> tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]:
    """(members, caches, render settings) of an environment class: the names
    its classes list in ``episode_members``, ``episode_caches`` and
    ``render_settings``."""
    return (_classes_tuple(cls, "episode_members"), _classes_tuple(cls, "episode_caches"),
            _classes_tuple(cls, "render_settings"))


def _plain(value) -> bool:
    """Whether ``value`` is plain data: a number, string, bool or None, or a
    tuple, list or str-keyed dict of them."""
    if value is None or isinstance(value, (bool, int, float, str, np.number)):
        return True
    if isinstance(value, (tuple, list)):
        return all(_plain(v) for v in value)
    if isinstance(value, dict):
        return all(isinstance(k, str) and _plain(v) for k, v in value.items())
    return False


def _configuration(env, skip: set) -> tuple:
    """The configuration's plain values and spaces of ``env``, as sorted
    (name, repr) pairs; ``skip``: the names that are not configuration."""
    pairs = [(name, repr(value)) for name, value in env.__dict__.items()
             if name not in skip and _plain(value)]
    pairs += [(name, repr(getattr(env, name))) for name in ("observation_space", "action_space")]
    return tuple(sorted(pairs))


def _shared(env, members: tuple, caches: tuple) -> dict:
    """A deep-copy memo that keeps the environment itself and its
    configuration (every attribute that is neither an episode member nor a
    cache, nor the very object of a member) shared."""
    memo: dict[int, Any] = {id(env): env}
    own = {id(env.__dict__[name]) for name in members if name in env.__dict__}
    for name, value in env.__dict__.items():
        if name not in members and name not in caches and id(value) not in own:
            memo[id(value)] = value
    return memo


def take_snapshot(env) -> Snapshot:
    """The :class:`Snapshot` of ``env``'s episode (see
    :meth:`iceenvs.base.ControlEnv.snapshot`)."""
    members, caches, render = episode_attributes(type(env))
    values = {name: env.__dict__[name] for name in members if name in env.__dict__}
    values[ROW] = env.episodes.row_state(env.row)
    state = copy.deepcopy(values, _shared(env, members, caches))
    return Snapshot(type(env), _configuration(env, set(members) | set(caches) | set(render)),
                    MappingProxyType(state), int(state[ROW]["steps"]))


def restore_snapshot(env, snapshot) -> dict:
    """Check that ``snapshot`` fits ``env`` and return a fresh copy of its
    members (the environment sets them: see
    :meth:`iceenvs.base.ControlEnv.restore`). Raises ``TypeError`` for
    anything but a :class:`Snapshot`, ``ValueError`` for one of another
    class or configuration."""
    if not isinstance(snapshot, Snapshot):
        raise TypeError(f"restore takes a Snapshot (from snapshot()), got "
                        f"{type(snapshot).__name__}")
    if snapshot.env_class is not type(env):
        raise ValueError(f"a snapshot of {snapshot.env_class.__name__} cannot be restored into "
                         f"{type(env).__name__}: take it of an environment of the same id")
    members, caches, render = episode_attributes(type(env))
    mine = _configuration(env, set(members) | set(caches) | set(render))
    if mine != snapshot.configuration:
        theirs = dict(snapshot.configuration)
        here = dict(mine)
        differ = sorted(name for name in set(theirs) | set(here)
                        if theirs.get(name) != here.get(name))
        detail = ", ".join(f"{name}: {theirs.get(name, 'absent')} in the snapshot, "
                           f"{here.get(name, 'absent')} here" for name in differ[:4])
        raise ValueError(f"the snapshot was taken of a {type(env).__name__} of another "
                         f"configuration ({detail}); restore it into an environment made "
                         f"with the same arguments")
    return copy.deepcopy(dict(snapshot.state), _shared(env, members, caches))
