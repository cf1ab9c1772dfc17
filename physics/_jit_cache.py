"""Where compiled kernels are cached, keyed by the package's source code.

Numba's on-disk cache (``cache=True``) is invalidated only when the file of
a function itself changes, not when a function it inlines from another
module does; after an update that touched only ``physics/contact.py`` the
kernels of ``physics/hertz_kernels.py`` would silently run the old contact
law. So the cache lives in a directory named after a hash of every source
file of the package's top-level modules (where every kernel lives;
subpackages such as ``physics.scenarios`` hold no kernels and do not enter
the hash), and other such directories are removed.

The base directory is ``$NUMBA_CACHE_DIR`` if set, else
``$XDG_CACHE_HOME/seaice-gym/numba`` (``~/.cache/seaice-gym/numba``).
This module must be imported before any module that compiles kernels.
"""
from __future__ import annotations

import hashlib
import os
import shutil
from pathlib import Path

import numba


def _source_hash() -> str:
    h = hashlib.sha1()
    root = Path(__file__).resolve().parent
    for path in sorted(root.glob("*.py")):
        h.update(str(path.relative_to(root)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def configure() -> Path | None:
    base = os.environ.get("NUMBA_CACHE_DIR")
    if base:
        base = Path(base) / "seaice-gym"
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "seaice-gym" / "numba"
    target = base / _source_hash()
    try:
        target.mkdir(parents=True, exist_ok=True)
        for other in base.iterdir():
            if other.is_dir() and other != target:
                shutil.rmtree(other, ignore_errors=True)
    except OSError:
        return None         # read-only home: numba falls back to its defaults
    numba.config.CACHE_DIR = str(target)
    return target


CACHE_DIR = configure()
