"""Benchmarks of the physics engines and observables: ``python -m physics.bench
hertz``, ``python -m physics.bench harddisk`` and ``python -m physics.bench
observables``.

Hertz engine (Herman 2013 material table, α = 1.8 floe sizes with mean
radius 4 m, no external forcing):

* Ā = 0.7 with random velocities of 3 cm/s per component;
* jammed ice, Ā = 0.95: a packing in force balance made by FIRE
  relaxation (:mod:`physics.jamming`) above the field's jamming point
  A_J = 0.94, at rest. The prepared states are cached (``--cache-dir``)
  because the compression takes about a minute.

Each case is timed with the serial kernels, the parallel kernels on one
thread and the parallel kernels on all threads, after a warm-up that
compiles everything (compile time is excluded). The three take turns in
one process, five rounds of one segment each, so that all three see the
same moments of a shared machine whose speed drifts; three such fresh
processes are run. Figures are floe-steps per second (floes × steps / wall
time): the best segment of all processes (the range of the processes'
best is shown), and the all-threads / one-thread ratio of the segments of
one round. Two control loops, timed the same way, show how much two
threads can give on the machine at all: scalar arithmetic with no memory
traffic (the ceiling of compute-bound work such as the jammed pair loop)
and a kick-drift-like pass over a cached (20000 × 8) state array (the
ceiling of the per-floe passes that dominate loose ice). The peak memory
of a run with N = 100000 floes is measured in a fresh process.

``python -m physics.bench phases`` times the phases of a Hertz step one by
one on the Ā = 0.7 field: the kick–drift pass, the pair loop, both, and a
Verlet-list rebuild, with the same three kernel configurations taking turns.

Hard-disc engine (collisions per second, one core, compile time excluded):

* elastic equal discs, N = 10000, packing fraction 0.5, no drag, Gaussian
  velocities of 1 m/s per component, after 5 collisions per disc to lose
  the placement's structure;
* the Herman (2011) set-up: N = 3000, α_r = 1.5, mean diameter 2 m,
  Ā = 0.75, wind 10 m/s, ε = 0.85, Δt_max = 1 s, Δt_c = 0.1 s, timed in
  the quasi-steady state after 4000 s of model time.

Observables (wall time, best of five calls after a warm-up call, all
threads): a Herman (2011) field (α_r = 1.5, mean diameter 2 m, Ā = 0.75) of
N = 100 008 floes, a placed field of 2778 floes tiled 6 × 6; clusters with
d_m = 0.5 m, cluster statistics, g_ffd and g_rdf; fabric and stress
(per-floe parts included) from the first 10⁵ contacts of the pairs closer
than 1 m, with repulsive normal forces of random size.

Ice thickness distribution (one core, best of three after a warm-up):
a 2000-day generalised-Thorndike run with 200 classes of 0.1 m and daily
steps for each kernel of Table 1 and rafting, and ``solve_smoluchowski``
with n = 1000 masses to t = 10 (constant kernel, monodisperse start).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import resource
import subprocess
import sys
import time
from pathlib import Path

import numba
import numpy as np

from .domain import PeriodicBox
from .floes import FloeField, make_floe_field
from . import hertz_kernels as K
from .hertz import HertzSimulation
from .params import HERMAN2013

ALPHA = HERMAN2013.fsd_exponent
JAMMED = 0.95          # concentration of the jammed case (above A_J = 0.94 of the field)
MEAN_DIAMETER = HERMAN2013.mean_diameter


def _save_state(path: Path, field: FloeField, box) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, positions=field.positions, radii=field.radii,
                        velocities=field.velocities, angular_velocities=field.angular_velocities,
                        lx=box.lx, ly=box.ly)


def _load_state(path: Path):
    d = np.load(path)
    field = FloeField(d["positions"], d["radii"], HERMAN2013.thickness, d["velocities"],
                      d["angular_velocities"], density=HERMAN2013.forcing.ice_density)
    return field, PeriodicBox(float(d["lx"]), float(d["ly"]))


REPEATS = 5   # rounds of timed segments per process; the best segment of each kind is reported
PROCESSES = 3   # fresh processes per case; the best is reported (host noise only slows a run)


def _loose_state(n: int, seed: int, cache_dir: Path) -> Path:
    """Path of the saved Ā = 0.7 field (random velocities of 3 cm/s per
    component), made on first use."""
    path = Path(cache_dir) / f"hertz_a070_n{n}_seed{seed}_v2.npz"
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        field, box = make_floe_field(n, concentration=0.7, alpha=ALPHA,
                                     mean_diameter=MEAN_DIAMETER, seed=seed, velocity_std=0.03)
        _save_state(path, field, box)
    return path


def _kernel_configs(threads_all: int) -> list[tuple[str, bool, int]]:
    """(label, parallel kernels?, threads) of every timed configuration."""
    configs = [("serial", False, 1), ("parallel", True, 1)]
    if threads_all > 1:
        configs.append(("parallel", True, threads_all))
    return configs


def _time_child(path: str, steps: int, dt: float) -> None:
    """Run in a fresh process whose thread pool has all threads: time every
    configuration of :func:`_kernel_configs` on its own copy of the saved
    state, in ``REPEATS`` rounds of one segment of ``steps`` steps each,
    the configurations taking turns within a round. On a shared machine
    whose speed drifts over seconds, the turns put each configuration
    through the same good and bad moments, and the ratio of two
    configurations in one round compares like with like. Prints, as JSON,
    the rates of every segment per configuration, contacts per floe and
    list rebuilds per segment."""
    configs = _kernel_configs(numba.config.NUMBA_NUM_THREADS)
    sims = []
    for _, parallel, threads in configs:
        numba.set_num_threads(threads)
        sims.append(_warm_sim(path, dt, parallel))
    rebuilds0 = sims[0].n_rebuilds
    rates = [[] for _ in configs]
    for _ in range(REPEATS):
        for k, ((_, _, threads), sim) in enumerate(zip(configs, sims)):
            numba.set_num_threads(threads)
            rates[k].append(_segment_rate(sim, steps))
    print(json.dumps(dict(
        rates=rates, contacts_per_floe=2.0 * len(sims[0].contacts()) / sims[0].n_floes,
        rebuilds=round((sims[0].n_rebuilds - rebuilds0) / REPEATS))))


def _warm_sim(path: str, dt: float, parallel: bool) -> HertzSimulation:
    """A simulation of the saved state, its kernels compiled (or loaded from
    the cache) by a few warm-up steps."""
    field, box = _load_state(Path(path))
    sim = HertzSimulation(field, box, HERMAN2013.contact, None, dt=dt, parallel=parallel,
                          allow_overlap=True)
    sim.step(5)
    return sim


def _segment_rate(sim: HertzSimulation, steps: int) -> float:
    """Floe-steps per second of ``steps`` steps."""
    t0 = time.perf_counter()
    sim.step(steps)
    return sim.n_floes * steps / (time.perf_counter() - t0)


def _child(*args: str, threads: int | None = None):
    """Run ``python -m physics.bench <args>`` in a fresh process (with a
    thread pool of ``threads`` threads if given) and return the JSON of the
    last line it prints."""
    env = dict(os.environ)
    if threads is not None:
        env["NUMBA_NUM_THREADS"] = str(threads)
    out = subprocess.run([sys.executable, "-m", "physics.bench", *args], check=True,
                         capture_output=True, text=True, env=env)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _timed_steps(path: Path, dt: float, steps: int, threads: int) -> dict:
    """:func:`_time_child` in a fresh process with a pool of ``threads``
    threads and nothing else running in it."""
    return _child("_time", str(path), str(steps), repr(dt), threads=threads)


@numba.njit(parallel=True, cache=True)
def _control_loop(reps):
    """Scalar, branchy arithmetic with no memory traffic: how well the
    machine itself runs two threads at once."""
    out = np.zeros(64)
    for c in numba.prange(64):
        t = 0.0
        for i in range(reps):
            x = (i * 2654435761 + c) % 1000 * 0.001
            if x > 0.5:
                t += x * x
            else:
                t -= x
        out[c] = t
    return out


STREAM_PASSES = 6   # updates per floe and step: a step costs about what a Hertz step does


@numba.njit(parallel=True, cache=True)
def _stream_loop(state, steps):
    """A kick-drift-like pass over an (N, 8) floe-state array per step, in
    64 chunks: how well the machine runs two threads on a streaming kernel
    whose data, like the Hertz engine's at N = 20000, sits in the caches."""
    n = state.shape[0]
    for _ in range(steps):
        for c in numba.prange(64):
            for i in range(c * n // 64, (c + 1) * n // 64):
                for _ in range(STREAM_PASSES):
                    state[i, 2] += 1e-6 * state[i, 4]
                    state[i, 3] += 1e-6 * state[i, 5]
                    state[i, 0] += 1e-3 * state[i, 2]
                    state[i, 1] += 1e-3 * state[i, 3]
                    state[i, 6] = state[i, 2] * state[i, 2] + state[i, 3] * state[i, 3]


def _control_child(kind: str = "scalar") -> None:
    """Time a control loop on one thread and on all threads, taking turns
    as :func:`_time_child` does; print the all-threads / one-thread ratio
    of every round as JSON."""
    if kind == "stream":
        state = np.random.default_rng(0).random((20000, 8))
        _stream_loop(state, 2)
        run = lambda: _stream_loop(state, 2000)  # noqa: E731
    else:
        _control_loop(10)
        run = lambda: _control_loop(500000)  # noqa: E731
    ratios = []
    for _ in range(REPEATS):
        seconds = []
        for threads in (1, numba.config.NUMBA_NUM_THREADS):
            numba.set_num_threads(threads)
            t0 = time.perf_counter()
            run()
            seconds.append(time.perf_counter() - t0)
        ratios.append(seconds[0] / seconds[1])
    print(json.dumps(dict(ratios=ratios)))


def machine_scaling(threads: int, kind: str = "scalar") -> list[float]:
    """Speed-ups of a control kernel on ``threads`` threads over one thread,
    one per round of :func:`_control_child` in ``PROCESSES`` fresh
    processes: ``kind="scalar"``, arithmetic with no memory traffic (the
    ceiling for compute-bound kernels), or ``"stream"``, a pass over cached
    floe-state arrays (the ceiling for the per-floe passes)."""
    return [x for _ in range(PROCESSES)
            for x in _child("_control", kind, threads=threads)["ratios"]]


def _jammed_state(n: int, seed: int, cache_dir: Path, quiet: bool, target: float = JAMMED):
    """Path of a jammed packing at concentration ``target``: placed at 0.85,
    compressed to 0.925 in steps of 0.005 with a FIRE relaxation after each
    (:func:`physics.jamming.compress_floes`; the floes are still unjammed
    there), then to ``target`` in one step and relaxed to force balance.
    Returns (path, seconds spent).

    The frictionless jamming point of this floe field (N = 20000, seed 1)
    is A_J = 0.9406 ± 0.0006 (:func:`physics.jamming.jamming_concentration`);
    at 0.92 a relaxed packing has no force network at all, so the jammed
    case is timed above A_J, with Z ≈ 4 contacts per floe.
    """
    from .jamming import compress_floes

    path = cache_dir / f"hertz_jammed_n{n}_seed{seed}_a{target:.3f}_fire2.npz"
    if path.exists():
        return path, 0.0
    t0 = time.perf_counter()
    field, box = make_floe_field(n, concentration=0.85, alpha=ALPHA, mean_diameter=MEAN_DIAMETER,
                                 seed=seed)
    field, box, _ = compress_floes(field, box, 0.925, increment=0.005, force_tol=1e-3,
                                   progress=not quiet)
    field, box, res = compress_floes(field, box, target, increment=1.0, force_tol=1e-3,
                                     max_iter=100000)
    if not quiet:
        print(f"  jammed packing: {res}", flush=True)
    _save_state(path, field, box)
    return path, time.perf_counter() - t0


def _memory_child(n: int) -> None:
    field, box = make_floe_field(n, concentration=0.7, alpha=ALPHA, mean_diameter=MEAN_DIAMETER,
                                 seed=1, velocity_std=0.03)
    sim = HertzSimulation(field, box, HERMAN2013.contact, None, dt=HERMAN2013.time_step)
    sim.step(200)
    print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)


def peak_memory(n: int) -> int:
    """Peak resident memory [bytes] of a fresh process that builds and runs
    an N-floe Hertz simulation at Ā = 0.7 (Numba and NumPy included)."""
    return int(_child("_memory", str(n)))


def _pinned_child(path: str, steps: int, dt: float, cpu: int) -> None:
    """Pin this process to core ``cpu`` and print, as JSON, the rates of
    ``REPEATS`` segments of ``steps`` steps of the serial kernels."""
    os.sched_setaffinity(0, {cpu})
    sim = _warm_sim(path, dt, parallel=False)
    print(json.dumps(dict(rates=[_segment_rate(sim, steps) for _ in range(REPEATS)])))


def core_speeds(path: Path, dt: float, steps: int) -> dict:
    """How much the host gives when all its cores are busy: the median rate
    of the serial kernels in a single-threaded process pinned to the first
    core, alone (before and after), and in one such process pinned to each
    core, all started together. If the cores were independent, the sum of
    the second would be the first times the number of cores; the ratio of
    the two is the most that any number of threads can gain over one
    thread on this code at that time."""
    env = dict(os.environ, NUMBA_NUM_THREADS="1")
    cpus = sorted(os.sched_getaffinity(0))

    def run(which):
        procs = [subprocess.Popen([sys.executable, "-m", "physics.bench", "_pinned", str(path),
                                   str(steps), repr(dt), str(cpu)], stdout=subprocess.PIPE,
                                  text=True, env=env) for cpu in which]
        outs = [p.communicate()[0] for p in procs]
        if any(p.returncode for p in procs):
            raise RuntimeError("a pinned benchmark process failed")
        return [float(np.median(json.loads(o.strip().splitlines()[-1])["rates"])) for o in outs]

    before = run(cpus[:1])[0]
    together = run(cpus)
    after = run(cpus[:1])[0]
    return dict(alone=0.5 * (before + after), together=together)


def bench_hertz(n: int = 20000, steps: int = 2000, seed: int = 1, cache_dir: Path | None = None,
                memory_floes: int = 100000, quiet: bool = False) -> list[dict]:
    """Time every case and kernel (see the module docstring); one row each."""
    threads_all = numba.config.NUMBA_NUM_THREADS
    cache_dir = Path(cache_dir) if cache_dir is not None else Path.cwd() / ".bench_cache"
    rows = []

    def log(msg):
        if not quiet:
            print(msg, flush=True)

    loose_path = _loose_state(n, seed, cache_dir)
    log(f"dense ice (N = {n}) ...")
    jam_path, prep = _jammed_state(n, seed, cache_dir, quiet)
    jam, jam_box = _load_state(jam_path)
    conc = jam.total_area / jam_box.area
    log(f"  ready (prepared in {prep:.0f} s), Ā = {conc:.4f}")
    cases = [("Ā = 0.70", loose_path, HERMAN2013.time_step),
             (f"jammed, Ā = {conc:.2f}", jam_path, 1e-3)]
    configs = _kernel_configs(threads_all)
    for name, path, dt in cases:
        # the same run differs by up to 1.7x between processes on a shared
        # virtual machine: the best of PROCESSES fresh processes, and their range
        runs = [_timed_steps(path, dt, steps, threads_all) for _ in range(PROCESSES)]
        for k, (label, _, threads) in enumerate(configs):
            best = [max(run["rates"][k]) for run in runs]
            r = dict(case=name, kernel=label, threads=threads, dt=dt, steps=steps,
                     rate=max(best), spread=[min(best), max(best)],
                     contacts_per_floe=runs[0]["contacts_per_floe"],
                     rebuilds=runs[0]["rebuilds"])
            if threads > 1:
                # the same round's two segments, all threads against one thread
                r["paired"] = [a / b for run in runs
                               for a, b in zip(run["rates"][k], run["rates"][1])]
            rows.append(r)
            log(f"  {name:22s} {label:8s} {threads} thread(s): {r['rate']:.3g} floe-steps/s")
    if threads_all > 1 and hasattr(os, "sched_setaffinity") and len(os.sched_getaffinity(0)) > 1:
        speeds = core_speeds(loose_path, HERMAN2013.time_step, steps)
        gain = sum(speeds["together"]) / speeds["alone"]
        rows.append(dict(case="cores", kernel="serial", threads=len(speeds["together"]),
                         rate=gain, contacts_per_floe=float("nan"), dt=HERMAN2013.time_step,
                         rebuilds=0, steps=steps, **speeds))
        log(f"  serial kernels, one core alone: {speeds['alone']:.3g} floe-steps/s; all cores "
            f"at once: " + ", ".join(f"{v:.3g}" for v in speeds["together"])
            + f" (together {gain:.2f}x)")
    if threads_all > 1:
        for kind in ("scalar", "stream"):
            ratios = machine_scaling(threads_all, kind)
            rows.append(dict(case="control", kernel=kind, threads=threads_all,
                             rate=float(np.median(ratios)), paired=ratios,
                             contacts_per_floe=float("nan"), dt=0.0, rebuilds=0, steps=0))
            log(f"  {kind} control loop, {threads_all} threads / 1 thread: "
                f"median {np.median(ratios):.2f} (range {min(ratios):.2f}–{max(ratios):.2f})")
    if memory_floes:
        mem = peak_memory(memory_floes)
        rows.append(dict(case=f"memory, N = {memory_floes}", kernel="", threads=0, rate=mem,
                         contacts_per_floe=float("nan"), dt=HERMAN2013.time_step, rebuilds=0,
                         steps=200))
    return rows


# The phases of a Hertz step, timed one by one. Compiled in this process,
# like the parallel kernels it calls (see physics.hertz_kernels).
@numba.njit(cache=False)
def _phase_loop(passes, parallel, n_threads, kick, pairs, dt, owners, bounds, shared, pos, vel,
                omega, radius, inv_mass, inv_inertia, cp, box, start, nbr, hist, fbuf, tbuf, ref,
                drag, fv, lx, ly, still, periodic, unit):
    """``passes`` kick–drift passes and/or pair loops of the Hertz step with
    a kick and drift of Δt = ``still`` (0: the same work as a real step, but
    the state stays as it is, so that every pass is alike and no list
    rebuild is due); ``dt`` is the step of the contact history.

    The kick's constants (``still``, ``periodic``, the box scale ``unit`` =
    1) are arguments, not literals, and its results are summed and returned:
    with literals the compiler specialises the pass, and with its results
    unused it drops the displacement bookkeeping, and the serial pass timed
    about half of what it costs in a real step."""
    n = pos.shape[0]
    total = 0.0
    for _ in range(passes):
        if kick:
            if parallel:
                res = K.first_half_parallel(n_threads * K.KICK_TASKS_PER_THREAD, still, still,
                                            pos, vel, omega, fbuf, tbuf, shared, inv_mass,
                                            inv_inertia, lx, ly, periodic, periodic, unit, unit,
                                            ref, still, still, drag, fv, False)
            else:
                res = K.first_half(0, n, still, still, pos, vel, omega, fbuf[0], tbuf[0],
                                   inv_mass, inv_inertia, lx, ly, periodic, periodic, unit, unit,
                                   ref, still, still, drag, fv, False)
            total += res[0] + res[1] + res[2] + res[3]
        if pairs:
            if parallel:
                K.pair_forces_parallel(owners, bounds, pos, vel, omega, radius, inv_mass, cp,
                                       box, start, nbr, hist, dt, fbuf, tbuf)
            else:
                K.owner_pairs(0, owners.shape[0], owners, pos, vel, omega, radius, inv_mass, cp,
                              box, start, nbr, hist, dt, fbuf[0], tbuf[0], 0, n, fbuf[0],
                              tbuf[0])
    return total


# phases: (name, kick–drift pass?, pair loop?); the last one is a list rebuild
PHASES = (("kick–drift pass", True, False), ("pair loop", False, True),
          ("kick–drift pass + pair loop", True, True), ("list rebuild", False, False))
REBUILD = len(PHASES) - 1


def bench_phases(n: int = 20000, seed: int = 1, passes: int = 2000,
                 cache_dir: Path | None = None, quiet: bool = False) -> dict:
    """Wall time of each phase of a Hertz step at Ā = 0.7 (the field of
    :func:`bench_hertz`): the kick–drift pass, the pair loop, both, and a
    Verlet-list rebuild, with the serial kernels, the parallel kernels on
    one thread and on all threads, taking turns in ``REPEATS`` rounds.
    Returns the field size ``n``, its listed pairs ``n_pairs`` and
    ``rows``, one per phase and configuration: the median time and the
    same-round speed-ups over the serial kernels."""
    threads_all = numba.config.NUMBA_NUM_THREADS
    cache_dir = Path(cache_dir) if cache_dir is not None else Path.cwd() / ".bench_cache"
    path = _loose_state(n, seed, cache_dir)
    dt = HERMAN2013.time_step
    sim = _warm_sim(str(path), dt, parallel=False)
    box = sim.box.kernel_array(sim.time)
    fv = sim._forcing_vector()

    def arrays(n_chunks):
        owners, bounds = K.owner_chunks(sim._start, n_chunks)
        shared = K.scatter_floes(owners, bounds, sim._start, sim._nbr, sim.n_floes)
        return (owners, bounds, shared, sim.positions.copy(), sim.velocities.copy(),
                sim.angular_velocities.copy(), sim.radius, sim.inv_mass, sim.inv_inertia,
                sim._cp, box, sim._start, sim._nbr, sim._hist.copy(),
                *K.force_buffers(n_chunks, sim.n_floes),
                sim._ref.copy(), sim._drag, fv, sim.box.lx, sim.box.ly)

    configs = _kernel_configs(threads_all)
    data = [arrays(threads if parallel else 1) for _, parallel, threads in configs]

    def run(k, phase, count):
        _, parallel, threads = configs[k]
        numba.set_num_threads(threads)
        t0 = time.perf_counter()
        if phase == REBUILD:
            for _ in range(count):
                K.rebuild(sim.positions, sim.radius, sim.rank, sim.box.lx, sim.box.ly, True, True,
                          sim.skin, sim.cell_size, sim._start, sim._nbr, sim._hist, parallel)
        else:
            _, kick, pairs = PHASES[phase]
            _phase_loop(count, parallel, threads, kick, pairs, dt, *data[k], 0.0, True, 1.0)
        return (time.perf_counter() - t0) / count

    if not quiet:
        print(f"phases of a step, N = {n}, Ā = 0.70 ...", flush=True)
    for k in range(len(configs)):
        for phase in range(len(PHASES)):
            run(k, phase, 2)                      # compile
    times = np.zeros((REPEATS, len(configs), len(PHASES)))
    rebuild_count = max(1, passes // 200)
    for r in range(REPEATS):
        for k in range(len(configs)):
            for phase in range(len(PHASES)):
                times[r, k, phase] = run(k, phase, rebuild_count if phase == REBUILD else passes)
    numba.set_num_threads(threads_all)
    rows = []
    for phase, (name, _, _) in enumerate(PHASES):
        for k, (label, _, threads) in enumerate(configs):
            ratio = times[:, 0, phase] / times[:, k, phase]
            rows.append(dict(phase=name, kernel=label, threads=threads,
                             seconds=float(np.median(times[:, k, phase])),
                             speedup=float(np.median(ratio)), speedup_best=float(ratio.max())))
    return dict(n=n, n_pairs=int(sim._start[-1]), rows=rows)


def format_phases_table(result: dict) -> str:
    lines = [f"Phases of a Hertz step, N = {result['n']}, Ā = 0.70 ({result['n_pairs']} listed "
             f"pairs), median of {REPEATS} rounds",
             "",
             "| phase | kernels | threads | time | serial / this (same round: median, best) |",
             "|---|---|---|---|---|"]
    for r in result["rows"]:
        t = r["seconds"]
        shown = f"{t * 1e3:.2f} ms" if t > 1e-3 else f"{t * 1e6:.1f} µs"
        lines.append(f"| {r['phase']} | {r['kernel']} | {r['threads']} | {shown} | "
                     f"{r['speedup']:.2f}, {r['speedup_best']:.2f} |")
    return "\n".join(lines)


def format_table(rows: list[dict], n: int) -> str:
    lines = [f"Hertz engine, N = {n}, Herman (2013) material table, {platform.processor() or platform.machine()}, "
             f"{os.cpu_count()} cores, numba {numba.__version__}",
             "",
             "| case | kernels | threads | floe-steps/s | range over processes | contacts per floe "
             "| Δt [s] | list rebuilds |",
             "|---|---|---|---|---|---|---|---|"]
    special = ("memory", "control", "cores")
    for r in rows:
        if r["case"].startswith(special):
            continue
        lo, hi = r.get("spread", (r["rate"], r["rate"]))
        lines.append(f"| {r['case']} | {r['kernel']} | {r['threads']} | {r['rate']:.3g} | "
                     f"{lo:.3g}–{hi:.3g} | {r['contacts_per_floe']:.2f} | {r['dt']:g} | "
                     f"{r['rebuilds']} |")
    for r in rows:
        if r["case"].startswith("memory"):
            lines.append("")
            lines.append(f"Peak resident memory of a whole process running N = "
                         f"{r['case'].split('= ')[1]} floes: {r['rate'] / 2 ** 20:.0f} MiB")
        if r["case"] == "control":
            if r["kernel"] != "stream":
                lines.append("")
            what = ("a streaming control loop over cached floe arrays (20000 × 8)"
                    if r["kernel"] == "stream" else
                    "a scalar control loop with no memory traffic")
            lines.append(f"Machine ceiling: {what} runs {r['rate']:.2f}x faster on "
                         f"{r['threads']} threads than on one (median of {len(r['paired'])} "
                         f"rounds; range {min(r['paired']):.2f}–{max(r['paired']):.2f})")
        if r["case"] == "cores":
            lines.append("")
            lines.append(f"Host ceiling: the serial kernels at Ā = 0.70 in a process pinned to "
                         f"one core run at {r['alone']:.3g} floe-steps/s alone, and at "
                         + " + ".join(f"{v:.3g}" for v in r["together"])
                         + f" with one such process on each core at once: all cores together "
                         f"give {r['rate']:.2f}x one core (medians of {REPEATS} segments)")
    by = {(r["case"], r["kernel"], r["threads"]): r for r in rows}
    for case in dict.fromkeys(r["case"] for r in rows if not r["case"].startswith(special)):
        one = by.get((case, "parallel", 1))
        ser = by.get((case, "serial", 1))
        allt = [v for (c, k, t), v in by.items() if c == case and k == "parallel" and t > 1]
        if one and allt:
            paired = allt[0]["paired"]
            lines.append(f"{case}: all threads / one thread (parallel kernels): best / best = "
                         f"{allt[0]['rate'] / one['rate']:.2f}, same round: median "
                         f"{np.median(paired):.2f}, best {max(paired):.2f}; "
                         f"all threads / serial kernels = {allt[0]['rate'] / ser['rate']:.2f}")
    return "\n".join(lines)


# ---------------------------------------------------------------------------
# hard-disc engine
# ---------------------------------------------------------------------------

def _harddisk_gas(n: int, eta: float, seed: int):
    from .floes import place_floes
    r = 0.5
    length = float(np.sqrt(n * np.pi * r * r / eta))
    box = PeriodicBox(length)
    rng = np.random.default_rng(seed)
    pos = place_floes(np.full(n, r), box, rng)
    vel = rng.normal(0.0, 1.0, (n, 2))
    vel -= vel.mean(axis=0)
    return FloeField(pos, np.full(n, r), 1.0, vel), box


def _time_collisions(sim, min_collisions: int, chunk: float) -> tuple[float, float, int]:
    """Advance in chunks of model time until ``min_collisions`` collisions;
    returns (collisions per wall second, model seconds, collisions)."""
    c0 = sim.collision_count
    t0 = sim.time
    w0 = time.perf_counter()
    while sim.collision_count - c0 < min_collisions:
        sim.advance(chunk)
    wall = time.perf_counter() - w0
    done = sim.collision_count - c0
    return done / wall, sim.time - t0, done


def bench_harddisk(seed: int = 1, quiet: bool = False) -> list[dict]:
    """Collisions per second of the hard-disc engine (see the module docstring)."""
    from .forcing import Forcing
    from .harddisk import HardDiskSimulation
    from .params import HERMAN2011

    def log(msg):
        if not quiet:
            print(msg, flush=True)

    rows = []
    # warm-up: compile (or load) every kernel on a tiny system
    f, b = _harddisk_gas(200, 0.3, seed)
    HardDiskSimulation(f, b, restitution=1.0, collision_duration=0.0).advance(1.0)
    field, box = _harddisk_gas(10000, 0.5, seed)
    sim = HardDiskSimulation(field, box, restitution=1.0, collision_duration=0.0)
    sim.advance(1.0)                          # about 5 collisions per disc
    best = 0.0
    for _ in range(REPEATS):
        rate, span, done = _time_collisions(sim, 1_000_000, 1.0)
        best = max(best, rate)
    d = sim.diagnostics
    rows.append(dict(case="elastic, N = 10000, η = 0.5", rate=best, collisions=done,
                     model_time=span, repairs=sim.repairs,
                     crossings_per_collision=d["crossings"] / d["collisions"]))
    log(f"  {rows[-1]['case']}: {best:.3g} collisions/s")

    P = HERMAN2011
    field, box = make_floe_field(3000, concentration=0.75, alpha=P.fsd_exponent,
                                 mean_diameter=P.mean_diameter, thickness=P.thickness, seed=seed,
                                 velocity_std=0.01)
    forcing = Forcing(P.forcing)
    sim = HardDiskSimulation(field, box, restitution=P.contact.restitution, forcing=forcing,
                             max_velocity_step=1.0, collision_duration=0.1)
    sim.advance(4000.0, progress=not quiet)
    rate, span, done = _time_collisions(sim, 200_000, 100.0)
    m = sim.mass
    u = float((m * sim.velocities[:, 0]).sum() / m.sum())
    d = sim.diagnostics
    rows.append(dict(case="Herman 2011, N = 3000, Ā = 0.75", rate=rate, collisions=done,
                     model_time=span, repairs=sim.repairs,
                     crossings_per_collision=d["crossings"] / d["collisions"],
                     mean_drift=u))
    log(f"  {rows[-1]['case']}: {rate:.3g} collisions/s, mass-weighted drift {u:.3f} m/s")
    return rows


def _table_head(title: str, columns: list[str]) -> list[str]:
    """Title line (with the machine and numba version) and Markdown table head."""
    return [f"{title}, {platform.processor() or platform.machine()}, numba {numba.__version__}",
            "", "| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]


def format_harddisk_table(rows: list[dict]) -> str:
    lines = _table_head("Hard-disc engine, one core",
                        ["case", "collisions/s", "collisions timed", "model time [s]",
                         "cell crossings per collision", "repairs"])
    for r in rows:
        lines.append(f"| {r['case']} | {r['rate']:.3g} | {r['collisions']} | {r['model_time']:.4g} | "
                     f"{r['crossings_per_collision']:.2f} | {r['repairs']} |")
    for r in rows:
        if "mean_drift" in r:
            lines.append("")
            lines.append(f"Herman (2011) set-up after {4000 + r['model_time']:.0f} s: mass-weighted "
                         f"mean along-wind velocity {r['mean_drift']:.3f} m/s (paper: about 0.23)")
    return "\n".join(lines)


def _best_time(fn, repeats: int = 5) -> float:
    """Best wall time of ``repeats`` calls of ``fn`` after one warm-up call [s]."""
    fn()
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def bench_observables(seed: int = 1, tiles: int = 6, quiet: bool = False) -> list[dict]:
    """Wall times of the observables on N ≈ 10⁵ floes (see the module docstring)."""
    from .clusters import cluster_statistics, find_clusters, g_ffd, g_rdf
    from .observables import Contacts, contacts_within, fabric, stress
    from .params import HERMAN2011

    P = HERMAN2011
    tile, tile_box = make_floe_field(100008 // tiles ** 2, concentration=0.75,
                                     alpha=P.fsd_exponent, mean_diameter=P.mean_diameter,
                                     thickness=P.thickness, seed=seed)
    shift = np.array([(a * tile_box.lx, b * tile_box.ly) for a in range(tiles)
                      for b in range(tiles)])
    pos = (tile.positions[None, :, :] + shift[:, None, :]).reshape(-1, 2)
    radii = np.tile(tile.radii, tiles * tiles)
    box = PeriodicBox(tiles * tile_box.lx, tiles * tile_box.ly)
    n = radii.size
    rows = []

    def record(case, seconds, **extra):
        rows.append(dict(case=case, seconds=seconds, **extra))
        if not quiet:
            print(f"  {case}: {seconds * 1e3:.3g} ms", flush=True)

    labels = find_clusters(pos, radii, box, 0.5)
    cs = cluster_statistics(labels, radii)
    record(f"find_clusters, N = {n}, d_m = 0.5 m",
           _best_time(lambda: find_clusters(pos, radii, box, 0.5)),
           clusters=cs.n_clusters, largest_fraction=cs.largest_fraction)
    record(f"cluster_statistics, {cs.n_clusters} clusters",
           _best_time(lambda: cluster_statistics(labels, radii)))
    record(f"g_ffd, N = {n}, x < 2 m, 100 bins",
           _best_time(lambda: g_ffd(pos, radii, box, 2.0, 100)))
    record(f"g_rdf, N = {n}, x < 10 m, 100 bins",
           _best_time(lambda: g_rdf(pos, box, 10.0, 100)))

    geo = contacts_within(pos, radii, box, 1.0)
    k = min(len(geo), 100000)
    rng = np.random.default_rng(seed)
    push = rng.uniform(1e3, 1e5, k)                  # repulsive normal forces [N]
    force = -push[:, None] * geo.normal[:k]
    c = Contacts(geo.i[:k], geo.j[:k], geo.normal[:k], geo.overlap[:k], push,
                 np.zeros(k), force, geo.contact_point[:k], geo.branch_i[:k], geo.branch_j[:k])
    record(f"fabric, {k} contacts", _best_time(lambda: fabric(c, n)))
    record(f"stress with per-floe parts, {k} contacts",
           _best_time(lambda: stress(c, box.area, n_floes=n)))
    record(f"stress, tensor only, {k} contacts",
           _best_time(lambda: stress(c, box.area, per_floe=False)))
    return rows


def format_observables_table(rows: list[dict]) -> str:
    lines = _table_head(f"Observables, {numba.get_num_threads()} threads",
                        ["case", "wall time [ms]"])
    for r in rows:
        lines.append(f"| {r['case']} | {r['seconds'] * 1e3:.3g} |")
    for r in rows:
        if "clusters" in r:
            lines.append("")
            lines.append(f"{r['clusters']} clusters; the largest holds "
                         f"{100 * r['largest_fraction']:.1f} % of the floe area")
    return "\n".join(lines)


def _itd_cases():
    """The Table 1 kernels with the rates of ``python -m physics.itd_figures``
    (Fig. 4) and its rafting run with the 1 m cut-off (Fig. 5)."""
    from .itd_figures import KERNELS, R0, RAFT_FACTOR
    return list(KERNELS.items()) + [("rafting", dict(r=R0, h_raft=1.0, factor=RAFT_FACTOR))]


def bench_itd(quiet: bool = False) -> list[dict]:
    """Wall times of the ITD models (see the module docstring)."""
    from .itd import ThorndikeModel, constant_kernel, solve_smoluchowski

    rows = []
    for kind, params in _itd_cases():
        def run(kind=kind, params=params):
            m = ThorndikeModel(kind, **params)
            m.run(2000)
            return m
        seconds = _best_time(run, repeats=3)
        m = run()
        rows.append(dict(case=f"Thorndike, {kind} kernel {params}, 2000 days", seconds=seconds,
                         substeps=m.substeps, open_water=m.open_water,
                         mean_thickness=m.mean_thickness))
        if not quiet:
            print(f"  {rows[-1]['case']}: {seconds:.3g} s", flush=True)
    n = 1000
    u0 = np.zeros(n)
    u0[0] = 1.0
    k = constant_kernel(n)
    seconds = _best_time(lambda: solve_smoluchowski(k, u0, [10.0]), repeats=3)
    rows.append(dict(case="solve_smoluchowski, n = 1000, t = 10, constant kernel",
                     seconds=seconds))
    if not quiet:
        print(f"  {rows[-1]['case']}: {seconds:.3g} s", flush=True)
    return rows


def format_itd_table(rows: list[dict]) -> str:
    lines = _table_head("Ice thickness distribution, one core",
                        ["case", "wall time [s]", "Euler steps", "open water", "mean h [m]"])
    for r in rows:
        extra = (f"{r['substeps']} | {r['open_water']:.3f} | {r['mean_thickness']:.3f}"
                 if "substeps" in r else "– | – | –")
        lines.append(f"| {r['case']} | {r['seconds']:.3g} | {extra} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m physics.bench", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="engine", required=True)
    h = sub.add_parser("hertz", help="floe-steps per second of the Hertz engine")
    h.add_argument("--floes", type=int, default=20000)
    h.add_argument("--steps", type=int, default=2000, help="timed steps per case")
    h.add_argument("--seed", type=int, default=1)
    h.add_argument("--memory-floes", type=int, default=100000,
                   help="floes of the memory measurement (0: skip)")
    h.add_argument("--cache-dir", type=Path, default=Path(".bench_cache"),
                   help="where the prepared floe fields are kept (default ./.bench_cache)")
    h.add_argument("--quiet", action="store_true")
    ph = sub.add_parser("phases", help="time of each phase of a Hertz step (kick-drift pass, "
                                       "pair loop, list rebuild) on one and on all threads")
    ph.add_argument("--floes", type=int, default=20000)
    ph.add_argument("--passes", type=int, default=2000, help="timed passes per phase and round")
    ph.add_argument("--seed", type=int, default=1)
    ph.add_argument("--cache-dir", type=Path, default=Path(".bench_cache"))
    ph.add_argument("--quiet", action="store_true")
    hd = sub.add_parser("harddisk", help="collisions per second of the hard-disc engine")
    hd.add_argument("--seed", type=int, default=1)
    hd.add_argument("--quiet", action="store_true")
    ob = sub.add_parser("observables", help="wall time of clusters, fabric and stress")
    ob.add_argument("--seed", type=int, default=1)
    ob.add_argument("--quiet", action="store_true")
    sub.add_parser("itd", help="wall time of the ice-thickness-distribution models")
    ctl = sub.add_parser("_control")
    ctl.add_argument("kind", nargs="?", default="scalar", choices=("scalar", "stream"))
    pin = sub.add_parser("_pinned")
    pin.add_argument("path")
    pin.add_argument("steps", type=int)
    pin.add_argument("dt", type=float)
    pin.add_argument("cpu", type=int)
    m = sub.add_parser("_memory")
    m.add_argument("n", type=int)
    t = sub.add_parser("_time")
    t.add_argument("path")
    t.add_argument("steps", type=int)
    t.add_argument("dt", type=float)
    args = p.parse_args(argv)
    if args.engine == "phases":
        if args.floes < 100 or args.passes < 1:
            p.error("--floes must be >= 100 and --passes >= 1")
        print(format_phases_table(bench_phases(args.floes, args.seed, args.passes, args.cache_dir,
                                               args.quiet)))
        return 0
    if args.engine == "harddisk":
        hd_rows = bench_harddisk(args.seed, args.quiet)
        print()
        print(format_harddisk_table(hd_rows))
        return 0
    if args.engine == "observables":
        ob_rows = bench_observables(args.seed, quiet=args.quiet)
        print()
        print(format_observables_table(ob_rows))
        return 0
    if args.engine == "itd":
        print(format_itd_table(bench_itd()))
        return 0
    if args.engine == "_control":
        _control_child(args.kind)
        return 0
    if args.engine == "_pinned":
        _pinned_child(args.path, args.steps, args.dt, args.cpu)
        return 0
    if args.engine == "_memory":
        _memory_child(args.n)
        return 0
    if args.engine == "_time":
        _time_child(args.path, args.steps, args.dt)
        return 0
    if args.floes < 100 or args.steps < 1:
        p.error("--floes must be >= 100 and --steps >= 1")
    rows = bench_hertz(args.floes, args.steps, args.seed, args.cache_dir, args.memory_floes,
                       args.quiet)
    print()
    print(format_table(rows, args.floes))
    return 0


if __name__ == "__main__":
    sys.exit(main())
