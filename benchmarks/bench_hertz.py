"""Floe-steps per second of the Hertz engine: ``python -m benchmarks.bench_hertz``
(``seaice bench hertz``).

    python -m benchmarks.bench_hertz [--floes 20000] [--steps 2000] [--seed 1]
                               [--memory-floes 100000] [--cache-dir .bench_cache]
                               [--processes 3] [--quiet] [--quick]
                               [--json PATH | --no-json]
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numba
import numpy as np

from physics.domain import PeriodicBox
from physics.floes import FloeField
from physics.hertz import HertzSimulation
from physics.params import HERMAN2013

from . import harness
from .harness import PROCESSES, REPEATS

SUITE = "hertz"
TITLE = "Hertz engine"
DESCRIPTION = """
Floe-steps per second (floes × steps / wall time) of the Hertz engine with the
Herman (2013) material table, α = 1.8 floe sizes with mean radius 4 m, no
external forcing, compile time excluded:

* **Ā = 0.7**, random velocities of 3 cm/s per component: loose ice whose
  floes, with no forcing, drift straight on and seldom touch, so this case
  times the per-floe passes (integration, neighbour lists) rather than the
  contact law;
* **jammed ice, Ā = 0.95**: a packing in force balance made by FIRE relaxation
  (`physics.jamming`) above the field's jamming point A_J = 0.94, at rest:
  placed at 0.85, compressed to 0.925 in steps of 0.005 with a relaxation
  after each, then to 0.95 in one step and relaxed. The prepared fields are
  cached (`--cache-dir`) because the compression takes about a minute.

The contacts per floe of each case (twice the touching pairs over N) are
counted at the end of the timed steps of the first process: they tell the
regime each figure belongs to.

Each case is timed with the serial kernels, the parallel kernels on one thread
and the parallel kernels on all threads, after a warm-up that compiles
everything. The three take turns in one process, five rounds of one segment
each, so that all three see the same moments of a shared machine whose speed
drifts; three such fresh processes are run. Every row is the best segment of
all processes (the range of the processes' best beside it), and the notes give
the all-threads / one-thread ratio of the segments of one round.

Two control loops, timed the same way, show how much two threads can give on
the machine at all: scalar arithmetic with no memory traffic (the ceiling of
compute-bound work such as the jammed pair loop) and a kick–drift-like pass
over a cached (20000 × 8) state array (the ceiling of the per-floe passes that
dominate loose ice). The host ceiling runs the serial kernels in one process
pinned to each core at once. The peak memory of a run with N = 100000 floes is
measured in a fresh process.
"""

JAMMED = 0.95          # concentration of the jammed case (above A_J = 0.94 of the field)
#: sizes of ``--quick`` (no host or machine ceilings)
QUICK = dict(floes=400, steps=20, memory_floes=0, processes=1, ceilings=False)


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


def loose_state(n: int, seed: int, cache_dir: Path) -> Path:
    """Path of the saved Ā = 0.7 field (random velocities of 3 cm/s per
    component), made on first use."""
    path = Path(cache_dir) / f"hertz_a070_n{n}_seed{seed}_v2.npz"
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        field, box = HERMAN2013.floe_field(n, 0.7, seed=seed, velocity_std=0.03)
        _save_state(path, field, box)
    return path


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
    from physics.jamming import compress_floes

    path = Path(cache_dir) / f"hertz_jammed_n{n}_seed{seed}_a{target:.3f}_fire2.npz"
    if path.exists():
        return path, 0.0
    t0 = time.perf_counter()
    field, box = HERMAN2013.floe_field(n, 0.85, seed=seed)
    field, box, _ = compress_floes(field, box, 0.925, increment=0.005, force_tol=1e-3,
                                   progress=not quiet)
    field, box, res = compress_floes(field, box, target, increment=1.0, force_tol=1e-3,
                                     max_iter=100000)
    if not quiet:
        print(f"  jammed packing: {res}", flush=True)
    _save_state(path, field, box)
    return path, time.perf_counter() - t0


def prepared_cases(n: int, seed: int, cache_dir: Path, quiet: bool = True) -> list[tuple]:
    """The two cases, as (name, path of the saved field, Δt): Ā = 0.7 and
    jammed (prepared and saved on first use)."""
    loose_path = loose_state(n, seed, cache_dir)
    jam_path, prep = _jammed_state(n, seed, cache_dir, quiet)
    jam, jam_box = _load_state(jam_path)
    conc = jam.total_area / jam_box.area
    if not quiet:
        print(f"  ready (prepared in {prep:.0f} s), Ā = {conc:.4f}", flush=True)
    return [("Ā = 0.70", loose_path, HERMAN2013.time_step),
            (f"jammed, Ā = {conc:.2f}", jam_path, 1e-3)]


def kernel_configs(threads_all: int) -> list[tuple[str, bool, int]]:
    """(label, parallel kernels?, threads) of every timed configuration."""
    configs = [("serial", False, 1), ("parallel", True, 1)]
    if threads_all > 1:
        configs.append(("parallel", True, threads_all))
    return configs


def warm_sim(path: str, dt: float, parallel: bool) -> HertzSimulation:
    """A simulation of the saved state, its kernels compiled (or loaded from
    the cache) by a few warm-up steps."""
    field, box = _load_state(Path(path))
    sim = HertzSimulation(field, box, contact=HERMAN2013.contact, forcing=None, dt=dt,
                          parallel=parallel, allow_overlap=True)
    sim.step(5)
    return sim


def segment_rate(sim: HertzSimulation, steps: int) -> float:
    """Floe-steps per second of ``steps`` steps."""
    t0 = time.perf_counter()
    sim.step(steps)
    return sim.n_floes * steps / (time.perf_counter() - t0)


def warm_sims(path: str, dt: float) -> tuple[list, list]:
    """Every configuration of :func:`kernel_configs` (this process's thread
    pool) and a warmed-up simulation of the saved state for each, on its
    own copy. Returns (configurations, simulations)."""
    configs = kernel_configs(numba.config.NUMBA_NUM_THREADS)
    sims = []
    for _, parallel, threads in configs:
        numba.set_num_threads(threads)
        sims.append(warm_sim(path, dt, parallel))
    return configs, sims


def time_configs(configs: list, sims: list, steps: int, rounds: int = REPEATS) -> list[list]:
    """The rates of ``rounds`` rounds of one segment of ``steps`` steps of
    every simulation, each on its configuration's threads, the
    configurations taking turns (:func:`benchmarks.harness.interleaved_rounds`)."""
    def segment(threads, sim):
        def go():
            numba.set_num_threads(threads)
            return segment_rate(sim, steps)
        return go

    return harness.interleaved_rounds([segment(threads, sim) for (_, _, threads), sim
                                       in zip(configs, sims)], rounds)


def _time_child(path: str, steps: int, dt: float) -> dict:
    """Run in a fresh process whose thread pool has all threads: time every
    configuration of :func:`kernel_configs` on its own copy of the saved
    state, in ``REPEATS`` rounds of one segment of ``steps`` steps each,
    the configurations taking turns within a round (:func:`time_configs`).
    Returns the rates of every segment per configuration, contacts per
    floe and list rebuilds per segment."""
    configs, sims = warm_sims(path, dt)
    rebuilds0 = sims[0].n_rebuilds
    rates = time_configs(configs, sims, steps)
    return dict(rates=rates, contacts_per_floe=2.0 * len(sims[0].contacts()) / sims[0].n_floes,
                rebuilds=round((sims[0].n_rebuilds - rebuilds0) / REPEATS))


def _timed_steps(path: Path, dt: float, steps: int, threads: int) -> dict:
    """:func:`_time_child` in a fresh process with a pool of ``threads``
    threads and nothing else running in it."""
    return harness.spawn_call(_time_child, str(path), steps, dt, threads=threads)


def _memory_child(n: int) -> int:
    sim = HertzSimulation.from_preset(HERMAN2013, n, 0.7, seed=1, velocity_std=0.03,
                                      forcing=False)
    sim.step(200)
    return harness.peak_rss()


def peak_memory(n: int) -> int:
    """Peak resident memory [bytes] of a fresh process that builds and runs
    an N-floe Hertz simulation at Ā = 0.7 (Numba and NumPy included)."""
    return int(harness.spawn_call(_memory_child, n))


def _pinned_child(path: str, steps: int, dt: float) -> dict:
    """The rates of ``REPEATS`` segments of ``steps`` steps of the serial
    kernels (in a process pinned to one core)."""
    sim = warm_sim(path, dt, parallel=False)
    return dict(rates=[segment_rate(sim, steps) for _ in range(REPEATS)])


def core_speeds(path: Path, dt: float, steps: int) -> dict:
    """How much the host gives when all its cores are busy: the median rate
    of the serial kernels in a single-threaded process pinned to the first
    core, alone (before and after), and in one such process pinned to each
    core, all started together. If the cores were independent, the sum of
    the second would be the first times the number of cores; the ratio of
    the two is the most that any number of threads can gain over one
    thread on this code at that time."""
    cpus = sorted(os.sched_getaffinity(0))

    def run(which):
        outs = harness.spawn_together(_pinned_child, [(str(path), steps, dt)] * len(which),
                                      threads=1, cpus=which)
        return [float(np.median(o["rates"])) for o in outs]

    before = run(cpus[:1])[0]
    together = run(cpus)
    after = run(cpus[:1])[0]
    return dict(alone=0.5 * (before + after), together=together)


def bench_hertz(n: int = 20000, steps: int = 2000, seed: int = 1, cache_dir: Path | None = None,
                memory_floes: int = 100000, quiet: bool = False, processes: int = PROCESSES,
                ceilings: bool = True) -> list[dict]:
    """Time every case and kernel (see :data:`DESCRIPTION`); one row each.
    ``ceilings=False`` leaves out the host and machine ceilings."""
    threads_all = numba.config.NUMBA_NUM_THREADS
    cache_dir = Path(cache_dir) if cache_dir is not None else harness.CACHE_DIR
    rows = []
    if not quiet:
        print(f"dense ice (N = {n}) ...", flush=True)
    cases = prepared_cases(n, seed, cache_dir, quiet)
    ceilings = ceilings and threads_all > 1
    pinned = ceilings and hasattr(os, "sched_setaffinity") and len(os.sched_getaffinity(0)) > 1
    total = len(cases) * processes + 3 * pinned + 2 * processes * ceilings + bool(memory_floes)
    configs = kernel_configs(threads_all)
    with harness.Progress(total, "hertz", quiet) as bar:
        for name, path, dt in cases:
            # the same run differs by up to 1.7x between processes on a shared
            # virtual machine: the best of ``processes`` fresh processes, and their range
            runs = []
            for _ in range(processes):
                runs.append(_timed_steps(path, dt, steps, threads_all))
                bar.advance()
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
                bar.log(f"  {name:22s} {label:8s} {threads} thread(s): "
                        f"{r['rate']:.3g} floe-steps/s")
        if pinned:
            speeds = core_speeds(cases[0][1], HERMAN2013.time_step, steps)
            bar.advance(3)
            gain = sum(speeds["together"]) / speeds["alone"]
            rows.append(dict(case="cores", kernel="serial", threads=len(speeds["together"]),
                             rate=gain, contacts_per_floe=float("nan"), dt=HERMAN2013.time_step,
                             rebuilds=0, steps=steps, **speeds))
            bar.log(f"  serial kernels, one core alone: {speeds['alone']:.3g} floe-steps/s; "
                    f"all cores at once: " + ", ".join(f"{v:.3g}" for v in speeds["together"])
                    + f" (together {gain:.2f}x)")
        if ceilings:
            for kind in ("scalar", "stream"):
                ratios = harness.machine_scaling(threads_all, kind, processes)
                bar.advance(processes)
                rows.append(dict(case="control", kernel=kind, threads=threads_all,
                                 rate=float(np.median(ratios)), paired=ratios,
                                 contacts_per_floe=float("nan"), dt=0.0, rebuilds=0, steps=0))
                bar.log(f"  {kind} control loop, {threads_all} threads / 1 thread: median "
                        f"{np.median(ratios):.2f} (range {min(ratios):.2f}–{max(ratios):.2f})")
        if memory_floes:
            mem = peak_memory(memory_floes)
            bar.advance()
            rows.append(dict(case=f"memory, N = {memory_floes}", kernel="", threads=0, rate=mem,
                             contacts_per_floe=float("nan"), dt=HERMAN2013.time_step,
                             rebuilds=0, steps=200))
    return rows


SPECIAL = ("memory", "control", "cores")


def hertz_table(rows: list[dict], n: int) -> dict:
    """The table of the timed cases and its notes (ceilings, memory, ratios)."""
    body = []
    for r in rows:
        if r["case"].startswith(SPECIAL):
            continue
        lo, hi = r.get("spread", (r["rate"], r["rate"]))
        body.append([r["case"], r["kernel"], r["threads"], float(r["rate"]),
                     f"{lo:.3g}–{hi:.3g}", harness.format_number(r["contacts_per_floe"]),
                     f"{r['dt']:g}", r["rebuilds"]])
    return harness.table(f"Hertz engine, N = {n}, Herman (2013) material table",
                         ["case", "kernels", "threads", "floe-steps/s", "range over processes",
                          "contacts per floe", "Δt [s]", "list rebuilds"], body,
                         "\n\n".join(_notes(rows)))


def _notes(rows: list[dict]) -> list[str]:
    """The lines under the table: ceilings, memory and the thread ratios."""
    lines = []
    for r in rows:
        if r["case"].startswith("memory"):
            lines.append(f"Peak resident memory of a whole process running N = "
                         f"{r['case'].split('= ')[1]} floes: {r['rate'] / 2 ** 20:.0f} MiB")
        if r["case"] == "control":
            what = ("a streaming control loop over cached floe arrays (20000 × 8)"
                    if r["kernel"] == "stream" else
                    "a scalar control loop with no memory traffic")
            lines.append(f"Machine ceiling: {what} runs {r['rate']:.2f}x faster on "
                         f"{r['threads']} threads than on one (median of {len(r['paired'])} "
                         f"rounds; range {min(r['paired']):.2f}–{max(r['paired']):.2f})")
        if r["case"] == "cores":
            lines.append(f"Host ceiling: the serial kernels at Ā = 0.70 in a process pinned to "
                         f"one core run at {r['alone']:.3g} floe-steps/s alone, and at "
                         + " + ".join(f"{v:.3g}" for v in r["together"])
                         + f" with one such process on each core at once: all cores together "
                         f"give {r['rate']:.2f}x one core (medians of {REPEATS} segments)")
    by = {(r["case"], r["kernel"], r["threads"]): r for r in rows}
    for case in dict.fromkeys(r["case"] for r in rows if not r["case"].startswith(SPECIAL)):
        one = by.get((case, "parallel", 1))
        ser = by.get((case, "serial", 1))
        allt = [v for (c, k, t), v in by.items() if c == case and k == "parallel" and t > 1]
        if one and allt:
            paired = allt[0]["paired"]
            lines.append(f"{case}: all threads / one thread (parallel kernels): best / best = "
                         f"{allt[0]['rate'] / one['rate']:.2f}, same round: median "
                         f"{np.median(paired):.2f}, best {max(paired):.2f}; "
                         f"all threads / serial kernels = {allt[0]['rate'] / ser['rate']:.2f}")
    return lines


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    p.add_argument("--floes", type=int, default=None, help="floes of both cases (default 20000)")
    p.add_argument("--steps", type=int, default=None, help="timed steps per segment (default 2000)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--memory-floes", type=int, default=None,
                   help="floes of the memory measurement (default 100000; 0: skip)")
    p.add_argument("--processes", type=int, default=None,
                   help=f"fresh processes per case (default {PROCESSES})")
    p.add_argument("--cache-dir", type=Path, default=harness.CACHE_DIR,
                   help=f"where the prepared floe fields are kept "
                        f"(default {harness.in_checkout(harness.CACHE_DIR)})")
    args, argv = harness.parse(p, argv)
    sizes = dict(floes=20000, steps=2000, memory_floes=100000, processes=PROCESSES,
                 ceilings=True)
    if args.quick:
        sizes.update(QUICK)
    for key in ("floes", "steps", "memory_floes", "processes"):
        if getattr(args, key) is not None:
            sizes[key] = getattr(args, key)
    if sizes["floes"] < 100 or sizes["steps"] < 1 or sizes["processes"] < 1:
        p.error("--floes must be >= 100, --steps and --processes >= 1")
    if sizes["memory_floes"] < 0:
        p.error("--memory-floes must not be negative")
    t0 = time.perf_counter()
    rows = bench_hertz(sizes["floes"], sizes["steps"], args.seed, args.cache_dir,
                       sizes["memory_floes"], args.quiet, sizes["processes"],
                       sizes["ceilings"])
    record = harness.make_record(
        SUITE, TITLE, DESCRIPTION, harness.command_line(SUITE, argv),
        [hertz_table(rows, sizes["floes"])],
        dict(n=sizes["floes"], steps=sizes["steps"], seed=args.seed, rounds=REPEATS,
             processes=sizes["processes"], quick=args.quick, rows=rows),
        time.perf_counter() - t0)
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
