"""Time of each phase of a Hertz step: ``python -m benchmarks.bench_hertz_phases``
(``seaice bench hertz_phases``).

    python -m benchmarks.bench_hertz_phases [--floes 20000] [--passes 2000] [--seed 1]
                                      [--cache-dir .bench_cache] [--quiet] [--quick]
                                      [--json PATH | --no-json]
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numba
import numpy as np

from physics import hertz_kernels as K
from physics.params import HERMAN2013

from . import harness
from .harness import REPEATS
from .bench_hertz import kernel_configs, loose_state, warm_sim

SUITE = "hertz_phases"
TITLE = "Phases of a Hertz step"
DESCRIPTION = """
The phases of a Hertz step timed one by one on the Ā = 0.7 field of the Hertz
suite (N = 20000, Herman (2013) material table, at rest in its own state): the
kick–drift pass, the pair loop, both, and a Verlet-list rebuild, with the
serial kernels, the parallel kernels on one thread and on all threads taking
turns in five rounds. Each phase is timed as a parallel region of its own, as
the step runs it. The kick–drift pass is timed with
Δt = 0: the same work as a real step, but the state stays as it is, so that
every pass is alike and no list rebuild is due. The parallel kernels run in
the chunks of the step (a number that depends on N alone). Times are medians of
the rounds; the speed-ups over the serial kernels are those of one round.
"""
#: sizes of ``--quick``
QUICK = dict(floes=400, passes=5)


# The phases of a Hertz step, timed one by one. Compiled in this process,
# like the parallel kernels it calls (see physics.hertz_kernels).
@numba.njit(cache=False)
def _phase_loop(passes, parallel, kick, pairs, dt, chunks, floes, law, box, verlet,
                buffers, ref, drive, still, periodic, unit):
    """``passes`` kick–drift passes and/or pair loops of the Hertz step with
    a kick and drift of Δt = ``still`` (0: the same work as a real step, but
    the state stays as it is, so that every pass is alike and no list
    rebuild is due); ``dt`` is the step of the contact history.

    The kick's constants (``still``, ``periodic``, the box scale ``unit`` =
    1) are arguments, not literals, and its results are summed and returned:
    with literals the compiler specialises the pass, and with its results
    unused it drops the displacement bookkeeping, and the serial pass timed
    about half of what it costs in a real step."""
    n = floes.pos.shape[0]
    step = K.Kick(still, still, box.lengths[0], box.lengths[1], periodic, periodic, unit, unit,
                  still, still)
    fbuf, tbuf = buffers.force, buffers.torque
    total = 0.0
    for _ in range(passes):
        if kick:
            if parallel:
                res = K.first_half_parallel(chunks.bounds.shape[0] - 1, floes, buffers, chunks,
                                            ref, drive, step)
            else:
                res = K.first_half(K.floe_rows(floes, 0, n, buffers), ref, drive, step)
            total += res[0] + res[1] + res[2] + res[3]
        if pairs:
            if parallel:
                K.pair_forces_parallel(chunks, floes, law, box, verlet, dt, buffers)
            else:
                K.owner_pairs(0, chunks.owners.shape[0], chunks.owners, floes, law, box, verlet,
                              dt, fbuf, tbuf)
    return total


# phases: (name, kick–drift pass?, pair loop?); the last one is a list rebuild
PHASES = (("kick–drift pass", True, False), ("pair loop", False, True),
          ("kick–drift pass + pair loop", True, True), ("list rebuild", False, False))
REBUILD = len(PHASES) - 1


def bench_phases(n: int = 20000, seed: int = 1, passes: int = 2000,
                 cache_dir: Path | None = None, quiet: bool = False) -> dict:
    """Wall time of each phase of a Hertz step at Ā = 0.7 (the field of
    :func:`benchmarks.bench_hertz.bench_hertz`): the kick–drift pass, the pair
    loop, both, and a Verlet-list rebuild, with the serial kernels, the
    parallel kernels on one thread and on all threads, taking turns in
    ``REPEATS`` rounds. Returns the field size ``n``, its listed pairs
    ``n_pairs`` and ``rows``, one per phase and configuration: the median
    time and the same-round speed-ups over the serial kernels."""
    threads_all = numba.config.NUMBA_NUM_THREADS
    cache_dir = Path(cache_dir) if cache_dir is not None else harness.CACHE_DIR
    path = loose_state(n, seed, cache_dir)
    dt = HERMAN2013.time_step
    sim = warm_sim(str(path), dt, parallel=False)
    box = sim.box.kernel_box(sim.time)
    view = sim.kernel_view()

    def arrays(n_chunks):
        f, v = view.floes, view.verlet
        floes = f._replace(pos=f.pos.copy(), vel=f.vel.copy(), omega=f.omega.copy())
        verlet = v._replace(hist=v.hist.copy(), ref=v.ref.copy())
        return (K.pair_chunks(verlet, n_chunks), floes, view.law, box, verlet,
                K.force_buffers(sim.n_floes), verlet.ref, view.drive)

    configs = kernel_configs(threads_all)
    data = [arrays(sim.n_chunks if parallel else 1) for _, parallel, threads in configs]

    def run(k, phase, count):
        _, parallel, threads = configs[k]
        numba.set_num_threads(threads)
        t0 = time.perf_counter()
        if phase == REBUILD:
            for _ in range(count):
                K.rebuild(view.floes, view.verlet, sim.box.lx, sim.box.ly, True, True, parallel)
        else:
            _, kick, pairs = PHASES[phase]
            _phase_loop(count, parallel, kick, pairs, dt, *data[k], 0.0, True, 1.0)
        return (time.perf_counter() - t0) / count

    with harness.Progress(len(configs) * len(PHASES) * (REPEATS + 1), "hertz_phases",
                          quiet, unit="phase") as bar:
        bar.log(f"phases of a step, N = {n}, Ā = 0.70 ...")
        for k in range(len(configs)):
            for phase in range(len(PHASES)):
                run(k, phase, 2)                      # compile
                bar.advance()
        times = np.zeros((REPEATS, len(configs), len(PHASES)))
        rebuild_count = max(1, passes // 200)
        for r in range(REPEATS):
            for k in range(len(configs)):
                for phase in range(len(PHASES)):
                    times[r, k, phase] = run(k, phase,
                                             rebuild_count if phase == REBUILD else passes)
                    bar.advance()
    numba.set_num_threads(threads_all)
    rows = []
    for phase, (name, _, _) in enumerate(PHASES):
        for k, (label, _, threads) in enumerate(configs):
            ratio = times[:, 0, phase] / times[:, k, phase]
            rows.append(dict(phase=name, kernel=label, threads=threads,
                             seconds=float(np.median(times[:, k, phase])),
                             speedup=float(np.median(ratio)), speedup_best=float(ratio.max())))
    return dict(n=n, n_pairs=int(view.verlet.start[-1]), rows=rows)


def phases_table(result: dict) -> dict:
    """The table of a :func:`bench_phases` result."""
    body = []
    for r in result["rows"]:
        t = r["seconds"]
        shown = f"{t * 1e3:.2f} ms" if t > 1e-3 else f"{t * 1e6:.1f} µs"
        body.append([r["phase"], r["kernel"], r["threads"], shown,
                     f"{r['speedup']:.2f}, {r['speedup_best']:.2f}"])
    return harness.table(f"Phases of a Hertz step, N = {result['n']}, Ā = 0.70 "
                         f"({result['n_pairs']} listed pairs), median of {REPEATS} rounds",
                         ["phase", "kernels", "threads", "time",
                          "serial / this (same round: median, best)"], body)


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    p.add_argument("--floes", type=int, default=None, help="floes of the field (default 20000)")
    p.add_argument("--passes", type=int, default=None,
                   help="timed passes per phase and round (default 2000)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--cache-dir", type=Path, default=harness.CACHE_DIR,
                   help=f"where the prepared floe field is kept "
                        f"(default {harness.in_checkout(harness.CACHE_DIR)})")
    args, argv = harness.parse(p, argv)
    sizes = dict(floes=20000, passes=2000)
    if args.quick:
        sizes.update(QUICK)
    sizes.update({k: getattr(args, k) for k in sizes if getattr(args, k) is not None})
    if sizes["floes"] < 100 or sizes["passes"] < 1:
        p.error("--floes must be >= 100 and --passes >= 1")
    t0 = time.perf_counter()
    result = bench_phases(sizes["floes"], args.seed, sizes["passes"], args.cache_dir, args.quiet)
    record = harness.make_record(
        SUITE, TITLE, DESCRIPTION, harness.command_line(SUITE, argv), [phases_table(result)],
        dict(result, passes=sizes["passes"], seed=args.seed, rounds=REPEATS, quick=args.quick),
        time.perf_counter() - t0)
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
