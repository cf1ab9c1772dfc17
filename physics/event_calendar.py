"""Event calendar of the event-driven hard-disc engine: an indexed binary heap.

Every floe has exactly one pending event (its earliest predicted collision
or cell crossing), so the calendar is a min-heap of floe indices keyed by
event time, with a position map so that the key of any floe can be changed
in O(log N) when its prediction is redone (Rapaport 2004, ch. 14; the
"one event per particle" scheme of modern event-driven codes).

Arrays (all of length N):

* ``heap[k]``  — floe at heap slot k; ``heap[0]`` has the earliest event;
* ``where[i]`` — heap slot of floe i;
* ``key[i]``   — event time of floe i.

All functions are compiled and work in place.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["heap_build", "heap_update", "heap_check"]


@njit(cache=True, inline="always", error_model="numpy")
def _sift_up(heap, where, key, k):
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


@njit(cache=True, inline="always", error_model="numpy")
def _sift_down(heap, where, key, k):
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


@njit(cache=True, error_model="numpy")
def heap_build(heap, where, key):
    """Arrange all floes into a heap by ``key`` (O(N), Floyd's method)."""
    n = heap.shape[0]
    for k in range(n):
        heap[k] = k
        where[k] = k
    for k in range(n // 2 - 1, -1, -1):
        _sift_down(heap, where, key, k)


@njit(cache=True, inline="always", error_model="numpy")
def heap_update(heap, where, key, i, t):
    """Set the event time of floe i to ``t`` and restore the heap order."""
    old = key[i]
    key[i] = t
    if t < old:
        _sift_up(heap, where, key, where[i])
    else:
        _sift_down(heap, where, key, where[i])


@njit(cache=True, error_model="numpy")
def heap_check(heap, where, key) -> bool:
    """True if the arrays form a consistent min-heap (for tests)."""
    n = heap.shape[0]
    for k in range(n):
        if where[heap[k]] != k:
            return False
        if k > 0 and key[heap[(k - 1) >> 1]] > key[heap[k]]:
            return False
    return True


def new_heap(n: int):
    """Empty calendar arrays for n floes: (heap, where, key)."""
    return np.arange(n, dtype=np.int64), np.arange(n, dtype=np.int64), np.full(n, np.inf)
