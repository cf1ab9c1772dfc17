"""One job of a scenario run: the simulation of one (case, member), run in
a worker process of the local pool, in a Dask task
(:mod:`physics.scenarios.dask_pool`), on the ranks of an MPI program
(:mod:`physics.scenarios.lammps_job`) or in the runner's own process
(:mod:`physics.scenarios.runner`, which lays out the jobs and gathers their
files).

A job writes ``RUN_DIR/jobs/caseCC_memberMM.nc`` (:func:`job_paths`) when
it finishes and its checkpoints beside it while it runs.
"""
from __future__ import annotations

import signal
import time
from pathlib import Path

from .. import mpi
from .config import parse_config
from .experiment import get_experiment
from .recorder import Recorder, atomic_write, checkpoint_files

_QUEUE = None


def init_worker(queue, threads):
    """Worker start-up: progress queue, one Numba thread, and Ctrl-C left to
    the parent (which stops the workers; their checkpoints are intact)."""
    global _QUEUE
    _QUEUE = queue
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if threads:
        import numba
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))


def job_paths(directory: Path, c: int, m: int) -> tuple[Path, Path]:
    """(NetCDF file, checkpoint) of the job of case ``c``, member ``m``."""
    base = directory / "jobs" / f"case{c:02d}_member{m:02d}"
    return base.with_suffix(".nc"), base.with_suffix(".ckpt")


def run_job(config_data: dict, params: dict, case: dict, seed: int, directory: str, c: int,
            m: int, checkpoint_every: float, job_id: int, on_progress=None,
            engine: str = "numba") -> str:
    """One simulation: (case c, member m) on ``engine``. Returns the path of
    its NetCDF. In a run on several MPI ranks every rank calls it; rank 0
    alone writes files."""
    root = mpi.world_rank() == 0
    cfg = parse_config(config_data)
    exp = get_experiment(cfg.name, engine)
    out, ckpt = job_paths(Path(directory), c, m)
    if on_progress is None and _QUEUE is not None:
        last = [0.0, -1.0]

        def on_progress(f):
            now = time.monotonic()
            if f >= 1.0 or now - last[0] > 0.5:
                last[0] = now
                _QUEUE.put((job_id, f))
    rec = Recorder(ckpt, checkpoint_every, on_progress, exp.variables,
                   keep_snapshots=exp.takes_snapshots, write=root)
    exp.simulate(params, case, seed, rec)
    rec.progress(1.0)
    if root:
        ds = rec.dataset()
        ds.attrs.update(case=c, member=m, seed=str(seed))
        atomic_write(out, lambda tmp: ds.to_netcdf(tmp, engine="h5netcdf"))
        for file in checkpoint_files(ckpt):
            file.unlink(missing_ok=True)
    return str(out)
