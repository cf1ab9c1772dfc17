"""Where compiled kernels are cached, keyed by the package's source code.

Numba's on-disk cache (``cache=True``) is invalidated only when the file of
a function itself changes, not when a function it inlines from another
module does; after an update that touched only ``physics/contact.py`` the
kernels of ``physics/hertz_kernels.py`` would silently run the old contact
law. So the cache lives in a directory named after a hash of every source
file of the package's top-level modules (where every kernel lives;
subpackages such as ``physics.scenarios`` hold no kernels and do not enter
the hash).

The base directory is ``$NUMBA_CACHE_DIR/seaice-gym`` if ``NUMBA_CACHE_DIR``
is set, else ``$XDG_CACHE_HOME/seaice-gym/numba`` (by default
``~/.cache/seaice-gym/numba``). Several checkouts or versions of the package
can share it: each uses its own hash directory. Every directory this module
creates holds a marker file (:data:`MARKER`) whose modification time is
renewed by every process that uses the directory. Nothing without a marker
is ever deleted; a marked directory of another version is removed only when
it has not been used for :data:`MAX_AGE_DAYS` days. (Unmarked directories,
such as those of releases before the marker, are never removed: delete them
by hand if they are no longer needed.)

The first time a process compiles a kernel (an empty or outdated cache), one
line goes to stderr saying that the kernels are being compiled, since that
takes a minute or two with nothing else printed; kernels loaded from the
cache print nothing. Set the environment variable ``SEAICE_QUIET=1`` to
silence it. ``python -m iceenvs.warmup`` compiles everything in advance.

This module must be imported before any module that compiles kernels.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import sys
import time
from pathlib import Path

import numba

#: name of the file that marks a cache directory as written by this module
MARKER = ".seaice-gym-cache"
#: marked cache directories of other versions unused for this many days are removed
MAX_AGE_DAYS = 30
#: environment variable that, set to a non-empty value other than ``0``,
#: silences the message printed before the first compilation
QUIET_ENV = "SEAICE_QUIET"
# modules whose kernels announce their first compilation
_KERNEL_PACKAGES = (__package__ or "physics", "iceenvs")


def _source_hash() -> str:
    h = hashlib.sha1()
    root = Path(__file__).resolve().parent
    for path in sorted(root.glob("*.py")):
        h.update(str(path.relative_to(root)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def base_dir() -> Path:
    """The directory that holds one cache directory per source hash."""
    base = os.environ.get("NUMBA_CACHE_DIR")
    if base:
        return Path(base) / "seaice-gym"
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "seaice-gym" / "numba"


def prune(base: Path, keep: Path, max_age_days: float = MAX_AGE_DAYS) -> list[Path]:
    """Remove the marked cache directories under ``base`` other than
    ``keep`` whose marker is older than ``max_age_days``; directories and
    files without a marker are left alone. Returns the removed paths."""
    removed = []
    limit = time.time() - max_age_days * 86400.0
    try:
        entries = list(base.iterdir())
    except OSError:
        return removed
    for other in entries:
        if other == keep or other.is_symlink() or not other.is_dir():
            continue
        marker = other / MARKER
        try:
            if not marker.is_file() or marker.stat().st_mtime >= limit:
                continue
        except OSError:
            continue
        shutil.rmtree(other, ignore_errors=True)
        removed.append(other)
    return removed


def configure() -> Path | None:
    """Point Numba's cache at this source's directory under :func:`base_dir`
    (created and marked if needed, its marker renewed) and prune marked
    directories unused for :data:`MAX_AGE_DAYS`. Returns the directory, or
    ``None`` when it cannot be written (Numba then keeps its defaults)."""
    base = base_dir()
    target = base / _source_hash()
    try:
        target.mkdir(parents=True, exist_ok=True)
        (target / MARKER).touch()          # creates it, or renews its time
    except OSError:
        return None         # read-only home: numba falls back to its defaults
    prune(base, target)
    numba.config.CACHE_DIR = str(target)
    return target


CACHE_DIR = configure()


def _quiet() -> bool:
    return os.environ.get(QUIET_ENV, "").strip() not in ("", "0")


def compile_notice(cache_dir: Path | None = None) -> str:
    """The line printed before the first compilation in a process."""
    where = f"load them from {cache_dir}" if cache_dir else "load them from Numba's cache"
    return (f"seaice-gym: compiling the physics kernels (first run only, up to 1-2 minutes; "
            f"later runs {where}; {QUIET_ENV}=1 hides this line)")


def is_package_kernel(dispatcher) -> bool:
    """A cached (``cache=True``) kernel of this project: its compilation is
    what a later run will load from the cache instead."""
    module = getattr(getattr(dispatcher, "py_func", None), "__module__", None) or ""
    if not any(module == p or module.startswith(p + ".") for p in _KERNEL_PACKAGES):
        return False
    cache = getattr(dispatcher, "_cache", None)
    return cache is not None and type(cache).__name__ != "NullCache"


def _install_compile_notice() -> None:
    """Print :func:`compile_notice` to stderr when a kernel of the package is
    compiled for the first time in this process. Numba emits its
    ``numba:compile`` event only for a real compilation: a kernel loaded
    from the on-disk cache returns before the event, so a warm cache prints
    nothing."""
    try:
        from numba.core import event
    except ImportError:          # an older Numba without the event API: no message
        return

    class _FirstCompile(event.Listener):
        done = False

        def on_start(self, ev):
            if self.done:
                return
            data = ev.data if isinstance(ev.data, dict) else {}
            if not is_package_kernel(data.get("dispatcher")):
                return
            self.done = True
            if not _quiet():
                print(compile_notice(CACHE_DIR), file=sys.stderr, flush=True)

        def on_end(self, ev):
            pass

    event.register("numba:compile", _FirstCompile())


_install_compile_notice()
