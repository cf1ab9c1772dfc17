"""Event calendar of the event-driven hard-disc engine: an indexed binary heap.

Every floe has exactly one pending event (its earliest predicted collision
or cell crossing), so the calendar is a min-heap of floe indices keyed by
event time, with a position map so that the key of any floe can be changed
in O(log N) when its prediction is redone (Rapaport 2004, ch. 14; the
"one event per particle" scheme of modern event-driven codes).

The calendar travels through the compiled kernels as one :class:`Calendar`
bundle of arrays, all of length N. The heap functions use only ``heap``,
``where`` and ``time``; ``partner`` and ``partner_changes`` describe the
event itself and are written by the hard-disc kernels
(:mod:`physics.harddisk_kernels`).

All functions are compiled and work in place, without Numba's reference
counting, like the kernels that inline them (see :mod:`physics.harddisk_kernels`).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

__all__ = ["Calendar", "heap_build", "heap_update", "heap_check", "new_calendar"]


class Calendar(NamedTuple):
    """The pending event of every floe, ordered by time.

    Attributes
    ----------
    heap : (N,) int64
        Floe at each heap slot; ``heap[0]`` has the earliest event.
    where : (N,) int64
        Heap slot of each floe.
    time : (N,) float
        Event time of each floe [s] (the heap key).
    partner : (N,) int64
        The other floe of a predicted collision, or a negative code for an
        event without partner (see :mod:`physics.harddisk_kernels`).
    partner_changes : (N,) int64
        The partner's count of course changes when the event was predicted;
        if the partner has changed course since, the event is stale.
    """

    heap: np.ndarray
    where: np.ndarray
    time: np.ndarray
    partner: np.ndarray
    partner_changes: np.ndarray


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _sift_up(cal, k):
    heap = cal.heap
    where = cal.where
    key = cal.time
    i = heap[k]
    t = key[i]
    while k > 0:
        parent = (k - 1) >> 1
        p = heap[parent]
        if key[p] <= t:
            break
        heap[k] = p
        where[p] = k
        k = parent
    heap[k] = i
    where[i] = k


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _sift_down(cal, k):
    heap = cal.heap
    where = cal.where
    key = cal.time
    n = heap.shape[0]
    i = heap[k]
    t = key[i]
    while True:
        child = 2 * k + 1
        if child >= n:
            break
        c = heap[child]
        tc = key[c]
        if child + 1 < n:
            c2 = heap[child + 1]
            if key[c2] < tc:
                child += 1
                c = c2
                tc = key[c2]
        if tc >= t:
            break
        heap[k] = c
        where[c] = k
        k = child
    heap[k] = i
    where[i] = k


@njit(cache=True, error_model="numpy", _nrt=False)
def heap_build(cal):
    """Arrange all floes into a heap by their event time (O(N), Floyd's method)."""
    n = cal.heap.shape[0]
    for k in range(n):
        cal.heap[k] = k
        cal.where[k] = k
    for k in range(n // 2 - 1, -1, -1):
        _sift_down(cal, k)


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def heap_update(cal, i, t):
    """Set the event time of floe i to ``t`` and restore the heap order."""
    old = cal.time[i]
    cal.time[i] = t
    if t < old:
        _sift_up(cal, cal.where[i])
    else:
        _sift_down(cal, cal.where[i])


@njit(cache=True, error_model="numpy", _nrt=False)
def heap_check(cal) -> bool:
    """True if the arrays form a consistent min-heap (for tests)."""
    heap = cal.heap
    n = heap.shape[0]
    for k in range(n):
        if cal.where[heap[k]] != k:
            return False
        if k > 0 and cal.time[heap[(k - 1) >> 1]] > cal.time[heap[k]]:
            return False
    return True


def new_calendar(n: int, no_partner: int = -1) -> Calendar:
    """An empty calendar for n floes: every event at infinity, without partner."""
    return Calendar(np.arange(n, dtype=np.int64), np.arange(n, dtype=np.int64),
                    np.full(n, np.inf), np.full(n, no_partner, dtype=np.int64),
                    np.zeros(n, dtype=np.int64))
