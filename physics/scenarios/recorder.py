"""What one simulation of a scenario writes: time series, snapshots, results,
and the checkpoints that let it resume.

An experiment's ``simulate`` gets a :class:`Recorder` and calls

* ``rec.record(time, p=..., z_c=..., profile=("y", array))`` once per
  output time (scalars, or (dimension, 1-D array) pairs over a dimension
  declared with ``rec.coord``);
* ``rec.snapshot(time, positions, radii, velocities, contacts=(i, j, f))``
  at the chosen snapshot times;
* ``rec.result(a_j=...)`` for per-run results;
* ``rec.progress(fraction)`` for the progress bar;
* ``rec.checkpoint(state)`` after each output: every ``checkpoint_every``
  wall seconds the state (the simulation object, loop counters, generators:
  whatever :mod:`physics.scenarios.checkpoint` writes) and everything
  recorded so far are written together, atomically, so an interrupted run
  resumes exactly where its last checkpoint left it (``rec.restore()``
  returns that state, or ``None`` on a fresh start).

A checkpoint holds NumPy arrays and a YAML description of them, never a
pickle: reading one cannot run code. The previous checkpoint is kept beside
the newest (``NAME.previous.EXT`` next to ``NAME.EXT``); a checkpoint that
cannot be read is reported (on standard error and in the run's notes) and
the run continues from the previous one, or from the start.

:meth:`Recorder.dataset` turns it all into an ``xarray.Dataset`` with
dimensions ``sample`` (output times), ``snapshot``, ``floe`` and
``contact`` plus the declared ones. Snapshot variables: ``snapshot_time``,
``snapshot_lx``, ``snapshot_ly``, ``floe_x``, ``floe_y``, ``floe_u``,
``floe_v``, ``floe_radius``, ``floe_frozen``, ``contact_i``, ``contact_j``,
``contact_force``.
"""
from __future__ import annotations

import os
import sys
import time as _time
from pathlib import Path

import numpy as np

from .. import mpi
from . import checkpoint as _checkpoint


def atomic_write(path: Path, write, previous: Path | None = None) -> None:
    """Call ``write(tmp_path)`` and move the result onto ``path`` in one
    step: an interruption leaves either the old file or the new one. With
    ``previous``, the old ``path`` is first moved there (an interruption in
    between leaves ``previous`` and no ``path``)."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        write(tmp)
        if previous is not None and path.exists():
            os.replace(path, previous)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def checkpoint_files(path) -> tuple[Path, Path]:
    """(newest, previous): the two checkpoint files kept for the checkpoint
    path ``path`` (``NAME.EXT`` and ``NAME.previous.EXT``)."""
    path = Path(path)
    return path, path.with_name(f"{path.stem}.previous{path.suffix}")


def checkpoint_fraction(path) -> float:
    """The progress saved with the newest readable checkpoint of ``path``
    (0 if there is none), read without its arrays."""
    for file in checkpoint_files(path):
        if file.exists():
            try:
                return float(_checkpoint.read_meta(file).get("fraction", 0.0))
            except (_checkpoint.CheckpointError, TypeError, ValueError):
                continue
    return 0.0


def _to_stderr(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


_PAYLOAD = ("state", "rows", "coords", "snapshots", "results", "notes", "fraction")


class Recorder:
    """Collects one simulation's output; see the module docstring.

    Parameters
    ----------
    checkpoint_path : Path or None
        Where checkpoints go (none are written if ``None``).
    checkpoint_every : float
        Wall seconds between checkpoints (0: at every call).
    on_progress : callable(fraction) or None
        Receives the progress in [0, 1].
    variables : dict
        name → (units, description) of the recorded variables, written as
        attributes.
    keep_snapshots : bool
        Write the snapshot variables even when there are no snapshots.
    log : callable(str) or None
        Receives the report on a checkpoint that cannot be read (default:
        standard error).
    write : bool
        Whether this recorder writes checkpoint files. In a run on several
        MPI ranks only rank 0's does; the others read the checkpoints and
        take part in writing them (:meth:`checkpoint`).
    """

    def __init__(self, checkpoint_path: Path | None = None, checkpoint_every: float = 60.0,
                 on_progress=None, variables: dict | None = None, keep_snapshots: bool = True,
                 log=None, write: bool = True):
        self.checkpoint_path = Path(checkpoint_path) if checkpoint_path else None
        self.checkpoint_every = float(checkpoint_every)
        self.on_progress = on_progress
        self.variables = dict(variables or {})
        self.keep_snapshots = keep_snapshots
        self.write = bool(write)
        self.rows: list[tuple[float, dict]] = []
        self.coords: dict[str, tuple[np.ndarray, dict]] = {}
        self.snapshots: list[dict] = []
        self.results: dict[str, float] = {}
        self.notes: list[str] = []
        self.n_checkpoints = 0
        self._state = None
        self._last = _time.monotonic()
        self._fraction = 0.0
        self._newest_ok = False        # whether the newest checkpoint file is a good one
        if self.checkpoint_path is not None:
            self._load(log or _to_stderr)

    # -- writing -----------------------------------------------------------
    def coord(self, name: str, values, units: str = "", description: str = "") -> None:
        """Declare an extra dimension (e.g. the y bins of a profile)."""
        self.coords[name] = (np.asarray(values, dtype=float),
                             {"units": units, "long_name": description})

    def record(self, time: float, **values) -> None:
        row = {}
        for key, v in values.items():
            if isinstance(v, tuple):
                dim, arr = v
                if dim not in self.coords:
                    raise KeyError(f"record({key}=...) uses dimension {dim!r}; declare it with "
                                   f"coord() first")
                row[key] = (dim, np.asarray(arr, dtype=float).copy())
            else:
                row[key] = float(v)
        self.rows.append((float(time), row))

    def snapshot(self, time: float, positions, radii, velocities, *, box=(np.nan, np.nan),
                 contacts=None, frozen=None) -> None:
        """Floe positions, radii, velocities (and ``frozen`` mask) at
        ``time`` in a box of lengths ``box`` = (lx, ly); ``contacts`` = (i,
        j, normal force) of the touching pairs for force-network plots."""
        snap = dict(time=float(time), box=(float(box[0]), float(box[1])),
                    positions=np.array(positions, dtype=float),
                    radii=np.array(radii, dtype=float),
                    velocities=np.array(velocities, dtype=float))
        snap["frozen"] = (np.zeros(len(snap["radii"]), bool) if frozen is None
                          else np.array(frozen, bool))
        if contacts is not None:
            i, j, f = contacts
            snap["contacts"] = (np.asarray(i, np.int64).copy(), np.asarray(j, np.int64).copy(),
                                np.asarray(f, float).copy())
        self.snapshots.append(snap)

    def result(self, **values) -> None:
        self.results.update({k: float(v) for k, v in values.items()})

    def note(self, text: str) -> None:
        """A remark on the run (e.g. why it ended early), shown in the summary."""
        self.notes.append(str(text))

    def progress(self, fraction: float) -> None:
        self._fraction = min(max(float(fraction), 0.0), 1.0)
        if self.on_progress is not None:
            self.on_progress(self._fraction)

    # -- checkpoints -----------------------------------------------------------
    def restore(self):
        """The state saved by the last checkpoint, or ``None``."""
        return self._state

    def checkpoint(self, state, *, force: bool = False) -> bool:
        """Save ``state`` and the output so far if ``checkpoint_every`` wall
        seconds have passed (or ``force``). Returns whether it wrote. Raises
        :class:`TypeError` naming the part of ``state`` that a checkpoint
        cannot hold (see :mod:`physics.scenarios.checkpoint`)."""
        if self.checkpoint_path is None:
            return False
        now = _time.monotonic()
        due = force or now - self._last >= self.checkpoint_every
        if mpi.under_mpiexec():
            # every rank of a parallel run takes the same decision (rank 0's
            # clock may be ahead): the state of a LAMMPS engine is written
            # by all ranks together
            due = mpi.allreduce_max(float(due)) > 0.0
        if not due:
            return False
        payload = dict(state=state, rows=self.rows, coords=self.coords,
                       snapshots=self.snapshots, results=self.results, notes=self.notes,
                       fraction=self._fraction)
        if not self.write:
            _checkpoint.dumps(payload)          # the engine's part is collective
            self._last = now
            return False
        newest, previous = checkpoint_files(self.checkpoint_path)
        # the newest file becomes the previous one only if it is a good checkpoint
        atomic_write(newest, lambda tmp: _checkpoint.save(tmp, payload,
                                                          meta={"fraction": self._fraction}),
                     previous=previous if self._newest_ok else None)
        self._newest_ok = True
        self._last = now
        self.n_checkpoints += 1
        return True

    def _load(self, log) -> None:
        """Restore the newest checkpoint that can be read; report those that
        cannot (the run then continues from the previous one, or starts)."""
        problems = []
        for file in checkpoint_files(self.checkpoint_path):
            if not file.exists():
                continue
            try:
                payload = _checkpoint.load(file)
                if not (isinstance(payload, dict) and set(payload) == set(_PAYLOAD)):
                    raise _checkpoint.CheckpointError("it holds no recorder state")
            except _checkpoint.CheckpointError as exc:
                problems.append(f"checkpoint {file} cannot be read: {exc}")
                continue
            self._state = payload["state"]
            self.rows, self.coords = payload["rows"], payload["coords"]
            self.snapshots, self.results = payload["snapshots"], payload["results"]
            self.notes, self._fraction = payload["notes"], float(payload["fraction"])
            self._newest_ok = file == self.checkpoint_path
            outcome = f"the run continues from {file}"
            break
        else:
            outcome = "the run starts again from the beginning"
        if problems:
            message = "; ".join(problems) + "; " + outcome
            log(message)
            self.note(message)

    # -- output ------------------------------------------------------------
    def _snapshot_variables(self, ds) -> None:
        """Snapshot variables (zero-length when there are none, so that runs
        that ended before their first snapshot still combine)."""
        nf = max((len(s["radii"]) for s in self.snapshots), default=0)
        nc = max((len(s["contacts"][0]) for s in self.snapshots if "contacts" in s),
                 default=0)
        k = len(self.snapshots)
        ds.coords["snapshot"] = ("snapshot", np.arange(k))
        ds.coords["floe"] = ("floe", np.arange(nf))
        ds["snapshot_time"] = ("snapshot", np.array([s["time"] for s in self.snapshots]),
                               {"units": "s"})
        ds["snapshot_lx"] = ("snapshot", np.array([s["box"][0] for s in self.snapshots]),
                             {"units": "m", "long_name": "box length along x"})
        ds["snapshot_ly"] = ("snapshot", np.array([s["box"][1] for s in self.snapshots]),
                             {"units": "m", "long_name": "box length along y"})
        fields = {"floe_x": ("positions", 0, "m"), "floe_y": ("positions", 1, "m"),
                  "floe_u": ("velocities", 0, "m/s"), "floe_v": ("velocities", 1, "m/s"),
                  "floe_radius": ("radii", None, "m")}
        for name, (src, col, units) in fields.items():
            arr = np.full((k, nf), np.nan)
            for s, snap in enumerate(self.snapshots):
                a = snap[src] if col is None else snap[src][:, col]
                arr[s, :len(a)] = a
            ds[name] = (("snapshot", "floe"), arr, {"units": units})
        fz = np.zeros((k, nf), np.int8)
        for s, snap in enumerate(self.snapshots):
            fz[s, :len(snap["frozen"])] = snap["frozen"]
        ds["floe_frozen"] = (("snapshot", "floe"), fz, {"long_name": "1 for frozen floes"})
        ds.coords["contact"] = ("contact", np.arange(nc))
        ci = np.full((k, nc), -1, np.int64)
        cj = np.full((k, nc), -1, np.int64)
        cf = np.full((k, nc), np.nan)
        for s, snap in enumerate(self.snapshots):
            if "contacts" in snap:
                i, j, f = snap["contacts"]
                ci[s, :len(i)], cj[s, :len(j)], cf[s, :len(f)] = i, j, f
        ds["contact_i"] = (("snapshot", "contact"), ci,
                           {"long_name": "first floe of a touching pair (-1: none)"})
        ds["contact_j"] = (("snapshot", "contact"), cj,
                           {"long_name": "second floe of a touching pair (-1: none)"})
        ds["contact_force"] = (("snapshot", "contact"), cf,
                               {"units": "N", "long_name": "normal contact force"})

    def dataset(self):
        """Everything recorded, as an ``xarray.Dataset``."""
        import xarray as xr

        ds = xr.Dataset()
        for name, (values, attrs) in self.coords.items():
            ds.coords[name] = (name, values, attrs)
        n = len(self.rows)
        ds.coords["sample"] = ("sample", np.arange(n))
        ds["time"] = ("sample", np.array([t for t, _ in self.rows], dtype=float),
                      {"units": "s", "long_name": "model time of the output"})
        names = list(dict.fromkeys(k for _, row in self.rows for k in row))
        for key in names:
            first = next(row[key] for _, row in self.rows if key in row)
            if isinstance(first, tuple):
                dim = first[0]
                arr = np.full((n, len(self.coords[dim][0])), np.nan)
                for s, (_, row) in enumerate(self.rows):
                    if key in row:
                        arr[s] = row[key][1]
                ds[key] = (("sample", dim), arr)
            else:
                ds[key] = ("sample", np.array([row.get(key, np.nan) for _, row in self.rows]))
        if self.snapshots or self.keep_snapshots:
            self._snapshot_variables(ds)
        for key, value in self.results.items():
            ds[key] = ((), value)
        ds.attrs["notes"] = "\n".join(self.notes)
        for key, (units, description) in self.variables.items():
            if key in ds:
                ds[key].attrs.update(units=units, long_name=description)
        return ds
