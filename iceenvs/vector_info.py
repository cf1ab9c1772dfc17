"""Gymnasium's vector info, built and read a column at a time: what
:meth:`gymnasium.vector.VectorEnv._add_info` builds from the
sub-environments' infos one by one (a dict of arrays, each key with its
mask ``_key`` of the sub-environments that have it), for the step of a
batch (:mod:`iceenvs.step`) and the native vector environments
(:mod:`iceenvs.vector`)."""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium.vector import VectorEnv

__all__ = ["batch_infos", "row_info", "set_row", "put_row", "spread_columns"]


def batch_infos(infos: Sequence[dict]) -> dict[str, Any]:
    """The infos of the sub-environments as one Gymnasium vector info: what
    :meth:`gymnasium.vector.VectorEnv._add_info` builds from them one by
    one (a dict of arrays, each key with its mask ``_key`` of the
    sub-environments that have it, nested dicts likewise; numbers in an
    array of the first one's type, arrays stacked, anything else in an
    object array), a column at a time."""
    n = len(infos)
    keys = list(infos[0]) if n else []
    if not (n and all(list(info) == keys for info in infos)):
        return _key_by_key(infos)
    # the common case: every sub-environment has the same keys, in one order
    out: dict[str, Any] = {}
    for key, values in zip(keys, zip(*(info.values() for info in infos))):
        first = values[0]
        array = None
        if isinstance(first, dict):
            if all(isinstance(v, dict) for v in values):
                array = batch_infos(values)
        else:
            array = _column(first, values)
        if array is None:
            array = _key_by_key([{key: v} for v in values])[key]
        out[key], out["_" + key] = array, np.ones(n, dtype=np.bool_)
    return out


def put_row(obs, k: int, value) -> None:
    """Sub-environment k's observation ``value`` into the batched ``obs``
    (an array, or a dict of arrays for a Dict space)."""
    if isinstance(obs, dict):
        for key in obs:
            obs[key][k] = value[key]
    else:
        obs[k] = value


def row_info(infos: dict[str, Any], k: int) -> dict[str, Any]:
    """Sub-environment k's info out of a vector info: the keys whose mask
    is set for k, numbers as Python numbers (the inverse of
    :func:`batch_infos` for one row)."""
    out = {}
    for key, value in infos.items():
        if key.startswith("_") or not infos.get("_" + key, np.zeros(k + 1, bool))[k]:
            continue
        if isinstance(value, dict):
            out[key] = row_info(value, k)
        elif value.dtype == object:
            out[key] = value[k]
        elif value.ndim == 1:
            out[key] = value[k].item()
        else:
            out[key] = value[k].copy()
    return out


def set_row(vector_env: VectorEnv, infos: dict[str, Any], info: dict[str, Any],
            k: int) -> dict[str, Any]:
    """``infos`` with sub-environment k's entries replaced by ``info``:
    its keys set (Gymnasium's ``_add_info``), the others' masks cleared
    for k."""
    for key, value in infos.items():
        if key.startswith("_") or key in info:
            continue
        infos["_" + key][k] = False
        if isinstance(value, dict):
            set_row(vector_env, value, {}, k)
        elif value.dtype != object:
            value[k] = 0
        else:
            value[k] = None
    return vector_env._add_info(infos, info, k)


def _key_by_key(infos: Sequence[dict]) -> dict[str, Any]:
    """:func:`batch_infos` for infos whose keys differ: key by key, each
    sub-environment's value put in its row."""
    n = len(infos)
    out: dict[str, Any] = {}
    for key in dict.fromkeys(k for info in infos for k in info):
        values = [info.get(key, _MISSING) for info in infos]
        present = [v is not _MISSING for v in values]
        first = next(v for v in values if v is not _MISSING)
        if isinstance(first, dict):
            array = batch_infos([{} if v is _MISSING else v for v in values])
        else:
            array = _empty_column(first, n)
            for k, v in enumerate(values):
                if v is not _MISSING:
                    array[k] = v
        out[key], out["_" + key] = array, np.array(present, dtype=np.bool_)
    return out


_MISSING = object()


def _is_number(value) -> bool:
    """Whether ``_add_info`` keeps ``value`` in an array of its own type."""
    return _is_number_type(type(value))


def _is_number_type(kind: type) -> bool:
    """Whether values of type ``kind`` are numbers for :func:`_is_number`."""
    return kind in (int, float, bool) or issubclass(kind, np.number)


def _empty_column(first, n: int) -> np.ndarray:
    """The array that ``_add_info`` starts a key with, from its first value."""
    if _is_number(first):
        return np.zeros(n, dtype=type(first))
    if isinstance(first, np.ndarray):
        return np.zeros((n,) + first.shape, dtype=first.dtype)
    return np.full(n, None, dtype=object)


def _column(first, values: Sequence) -> np.ndarray | None:
    """The column of a key that every sub-environment has, in one call where
    that gives what filling :func:`_empty_column` one by one gives (numbers
    of the first one's type; arrays of one shape and dtype); else None."""
    if _is_number(first):
        # the distinct types, each tested once: a column is mostly of one
        return (np.array(values, dtype=type(first))
                if all(_is_number_type(t) for t in set(map(type, values))) else None)
    if isinstance(first, np.ndarray) and all(
            isinstance(v, np.ndarray) and v.shape == first.shape and v.dtype == first.dtype
            for v in values):
        return np.stack(values)
    return None


def spread_columns(columns: dict, rows: np.ndarray, n: int) -> dict:
    """A vector info of ``n`` sub-environments from the ``columns`` of the
    sub-environments ``rows`` (each key with its mask ``_key``)."""
    out = {}
    full = rows.size == n
    mask = np.zeros(n, dtype=bool)
    mask[rows] = True
    for key, value in columns.items():
        if isinstance(value, dict):
            array = spread_columns(value, rows, n)
        elif full:
            array = value
        else:
            array = np.zeros((n,) + value.shape[1:], dtype=value.dtype)
            array[rows] = value
        out[key], out["_" + key] = array, mask.copy()
    return out
