"""The ``seaice`` command: one entry point to the project's tools.

``seaice train``, ``seaice evaluate``, ``seaice scenarios``, ``seaice
crosscheck``, ``seaice bench``, ``seaice validate`` and ``seaice demo``
forward their arguments to the tools' own entry points (which also run as
``python -m ...``); see :mod:`seaice_gym.cli`.
"""
from __future__ import annotations

from importlib import metadata as _metadata

try:
    __version__ = _metadata.version("seaice-gym")
except _metadata.PackageNotFoundError:      # a source tree that is not installed
    __version__ = "0+unknown"

__all__ = ["__version__"]
