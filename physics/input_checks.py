"""Checks of input values, shared by every module of the package.

A bad value raises :class:`ValueError` naming the value, what it is and the
allowed range. This module imports nothing from the package, so that any
module may use it.
"""
from __future__ import annotations

import math

__all__ = ["check_range", "check_fields", "POSITIVE", "NONNEG"]


def check_range(name: str, value, low=None, high=None, *, low_open=False,
                high_open=False) -> None:
    """Raise ``ValueError`` unless ``value`` is a finite number in the range.

    ``low_open``/``high_open`` make the corresponding bound strict.
    The message names the field, the value and the allowed range.
    """
    lo = "-inf" if low is None else f"{low:g}"
    hi = "inf" if high is None else f"{high:g}"
    opening = "(" if (low_open or low is None) else "["
    closing = ")" if (high_open or high is None) else "]"
    interval = f"{opening}{lo}, {hi}{closing}"
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number in {interval}, got {value!r}") from None
    ok = math.isfinite(v)
    if ok and low is not None:
        ok = v > low if low_open else v >= low
    if ok and high is not None:
        ok = v < high if high_open else v <= high
    if not ok:
        raise ValueError(f"{name} must be in {interval}, got {value!r}")


#: the ranges of :func:`check_fields`, as (low, high, low_open, high_open)
POSITIVE = (0.0, None, True, False)
NONNEG = (0.0, None, False, False)


def check_fields(obj, spec: dict) -> None:
    """:func:`check_range` on the attributes of ``obj`` named by ``spec``,
    ``{name: (low, high, low_open, high_open)}``; the message names them
    ``Class.name``."""
    for name, (low, high, low_open, high_open) in spec.items():
        check_range(f"{type(obj).__name__}.{name}", getattr(obj, name), low, high,
                    low_open=low_open, high_open=high_open)
