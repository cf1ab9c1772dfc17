"""The cost of a ship among the floes: ``python -m benchmarks.bench_ship``
(``seaice bench ship``).

    python -m benchmarks.bench_ship [--floes 2000 20000] [--steps STEPS] [--seed 1]
                              [--processes 3] [--quiet] [--quick]
                              [--json PATH | --no-json]
"""
from __future__ import annotations

import sys
import time

import numba
import numpy as np

from physics import hertz_kernels as K
from physics import hull_contact as HC
from physics.domain import PeriodicBox
from physics.hertz import HertzSimulation, hull_contact_time
from physics.hull import disc_hull_contact
from physics.params import HERMAN2013
from physics.ship import psv_ship

from . import harness
from .harness import PROCESSES, REPEATS

SUITE = "ship"
TITLE = "Ship among the floes"
DESCRIPTION = f"""
What a ship costs the Hertz engine: floe-steps per second (floes × steps / wall
time, compile time excluded) of one floe field with and without the platform
supply vessel (`psv_ship`, 76.2 m × 18 m, prescribed at 2 m/s), at N = 2000 and
N = 20000 floes.

The field is the Herman (2013) material table at Ā = 0.7 (α = 1.8 floe sizes,
mean radius 4 m, random velocities of 3 cm/s per component) in a periodic box,
with the preset's wind, drag and Coriolis forcing. The ship starts heading +x
in a slot cleared of floes: every floe whose disc comes within 0.5 m of the
hull is removed, at the position along the box's width (x = lx/4) that removes
the least ice, and the *same* floes are removed in the run without the ship,
so the ship is the only difference. Both runs use the full Herman (2013)
contact law with Δt = 1 ms, the longest step below a tenth of the shortest
contact time of a floe hitting the hull at 2 m/s (the preset's 2 ms is for
floe–floe impacts at 0.1 m/s). The ship sails into the ice for 1000 steps
(2 m) before the timing starts, so every segment has it pushing through ice.

Four configurations take turns in one process, five rounds of one segment
(5·10⁷ floe-steps) each: without and with the ship, on one thread (serial kernels) and on two
threads (parallel kernels). Three such fresh processes are run; the table gives
the median of all segments and their range, and the extra cost per step is
the median of the same-round ratios. The parallel step of a periodic box
runs as a team of threads that stays in one parallel region between list
rebuilds, with and without the ship; with the ship one thread does the hull's
contacts between the floes' kick–drift pass and their pair loop while the
other waits.

The ship's share of the step time is measured two ways: the hull kernels timed
on their own on the state of the run (the ship's kick–drift, the contacts of
the floes in the hull's list with their forces, collision log and step record,
and the O(N) build of the hull's list at the rate the run built it), and the
difference of the two runs. What the difference holds beyond the hull kernels
is the ship's effect on the floes: floes pushed at up to 3 m/s would expire the
floes' own Verlet list (one skin of 0.1 mean radius) every hundred steps or so.
With a ship the list gets a skin per floe instead: a floe moving at u relative
to the pack gets 2 u T and a floe the hull may hit 4 V T (T = {HC.SKIN_HORIZON_STEPS} steps),
within the floes' and the hull's skins, and the list expires when a floe has
moved half its own skin: the kick–drift pass checks the floes of the common
skin as before, and a short pass the few dozen wide-skinned ones. Each rebuild
of the floes' list is timed too. In ice of Ā = 0.7 the ship touches a floe in only a
few per cent of its steps: an impact lasts about 10 ms and sends the floe ahead
of the bow, so the ship's cost lies less in its own contacts than in what the
pushed floes do to the floes' Verlet list.
"""

#: sizes of ``--quick``
QUICK = dict(floes=[300], steps=20, processes=1, warmup=50)


def segment_steps(n: int, steps: int | None = None) -> int:
    """Steps of a timed segment: ``steps``, or :data:`SEGMENT` floe-steps."""
    return int(steps) if steps else max(1, SEGMENT // n)
CONCENTRATION = 0.7
SPEED = 2.0
#: floes closer than this to the hull at the start are removed [m]
CLEARANCE = 0.5
#: ship steps before the timing (the ship sails 2 m into the ice at 1 ms)
WARMUP = 1000
#: floe-steps of one timed segment (steps = this / N unless --steps is given)
SEGMENT = 50_000_000
#: configurations: (label, ship?, threads); one thread runs the serial kernels
CONFIGS = (("no ship", False, 1), ("ship", True, 1), ("no ship", False, 2), ("ship", True, 2))


# ---------------------------------------------------------------------------
# the floe field with its cleared slot
# ---------------------------------------------------------------------------

def _touching(field, box, x, y, clearance):
    """Indices of the floes whose discs come within ``clearance`` of the
    PSV hull with its centroid at (x, y), heading +x."""
    hull = psv_ship().hull
    corners = hull.world_vertices(0.0, 0.0, 0.0)
    vx, vy = np.ascontiguousarray(corners[:, 0]), np.ascontiguousarray(corners[:, 1])
    pos, r = field.positions, field.radii
    dx = (pos[:, 0] - x + 0.5 * box.lx) % box.lx - 0.5 * box.lx
    dy = (pos[:, 1] - y + 0.5 * box.ly) % box.ly - 0.5 * box.ly
    near = np.flatnonzero(np.hypot(dx, dy) < hull.circumradius + r + clearance)
    return np.array([i for i in near
                     if disc_hull_contact(dx[i], dy[i], r[i] + clearance, vx, vy)[0] > 0.0],
                    dtype=np.int64)


def ship_field(n: int, seed: int = 1):
    """The floe field of ``n`` floes at Ā = 0.7 with the slot for the ship
    cleared, its box side, and the ship's start: returns (field, box side,
    (x, y), removed floes). The slot is at x = lx / 4, at the y of a few
    tried that removes the least ice."""
    field, box = HERMAN2013.floe_field(n, CONCENTRATION, seed=seed, velocity_std=0.03)
    x = 0.25 * box.lx
    best = None
    for y in box.ly * (np.arange(8) + 0.5) / 8:
        idx = _touching(field, box, x, y, CLEARANCE)
        area = float(np.sum(field.radii[idx] ** 2))
        if best is None or area < best[0]:
            best = (area, y, idx)
    _, y, idx = best
    keep = np.setdiff1d(np.arange(field.n), idx)
    return field.take(keep), box.lx, (x, float(y)), idx.size


def time_step(field) -> float:
    """The step of both runs: 1 ms, below a tenth of the shortest contact
    time of a floe hitting the hull at :data:`SPEED` (checked)."""
    t_c = hull_contact_time(field.radii, field.thickness, field.density, HERMAN2013.contact,
                            SPEED)
    dt = 1e-3
    if dt > 0.1 * t_c:
        raise ValueError(f"Δt = {dt} s is above a tenth of the hull contact time {t_c:.4g} s")
    return dt


def _make_sim(field, side, start, ship: bool, parallel: bool, dt: float) -> HertzSimulation:
    return HertzSimulation(field, PeriodicBox(side, side), HERMAN2013.contact,
                           HERMAN2013.make_forcing(), dt, parallel=parallel,
                           ship=psv_ship(position=start, speed=SPEED) if ship else None)


# ---------------------------------------------------------------------------
# the hull kernels on their own
# ---------------------------------------------------------------------------

# Compiled in this process, like hertz_phases' loop (a cached caller would
# not notice a change of the kernels it calls).
@numba.njit(cache=False)
def _hull_loop(passes, ship, floes, box, dt, force, torque):
    """``passes`` calls of the ship's kick–drift (with Δt = 0: the hull stays
    where it is, so its list does not expire) and of the hull's contact
    pass on the same state."""
    for _ in range(passes):
        HC.ship_kick_drift(ship, 0.0, 0.0)
        HC.hull_forces(ship, floes, box, 0.0, dt, 0.0, force, torque)
    return ship.counts[HC.C_CAND]


@numba.njit(cache=False)
def _hull_build_loop(passes, ship, pos, radius, lx, ly):
    for _ in range(passes):
        HC.build_hull_list(ship, pos, radius, lx, ly, True, True)
    return ship.counts[HC.C_CAND]


def hull_kernel_times(sim: HertzSimulation, passes: int) -> dict:
    """Wall time per call [s] of the hull's step (kick–drift and contact
    pass, without a list build) and of a build of the hull's list, on a
    copy of the ship of ``sim`` at its current state, and of a rebuild of
    the floes' own Verlet list (serial kernels)."""
    b = sim.ship.kernel_bundle
    ship = b._replace(state=b.state.copy(), hist=b.hist.copy(), contact=b.contact.copy(),
                      cand=b.cand.copy(), counts=b.counts.copy(), log=b.log.copy(),
                      world_x=b.world_x.copy(), world_y=b.world_y.copy(),
                      record=np.zeros((1, len(HC.RECORD_COLUMNS))))
    ship.state[HC.S_HULL_TRAVEL] = 0.0
    ship.state[HC.S_FLOE_TRAVEL] = 0.0
    box = sim.box.kernel_box(sim.time)
    force, torque = np.zeros((sim.n_floes, 2)), np.zeros(sim.n_floes)
    view = sim.kernel_view()           # the kernels' own bundles of the live arrays
    floes = view.floes
    numba.set_num_threads(1)
    _hull_loop(2, ship, floes, box, sim.dt, force, torque)                  # compile
    _hull_build_loop(1, ship, floes.pos, floes.radius, box.lengths[0], box.lengths[1])
    ship.state[HC.S_HULL_TRAVEL] = 0.0
    builds = max(1, passes // 20)
    step, build, rebuild = [], [], []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        _hull_loop(passes, ship, floes, box, sim.dt, force, torque)
        step.append((time.perf_counter() - t0) / passes)
        t0 = time.perf_counter()
        _hull_build_loop(builds, ship, floes.pos, floes.radius, box.lengths[0], box.lengths[1])
        build.append((time.perf_counter() - t0) / builds)
        ship.state[HC.S_HULL_TRAVEL] = 0.0
        t0 = time.perf_counter()
        for _ in range(max(1, builds // 4)):
            K.rebuild(floes, view.verlet, box.lengths[0], box.lengths[1], True, True, False,
                      view.verlet.skins)
        rebuild.append((time.perf_counter() - t0) / max(1, builds // 4))
    return dict(hull_step=float(np.median(step)), hull_build=float(np.median(build)),
                floe_rebuild=float(np.median(rebuild)), candidates=int(ship.counts[HC.C_CAND]))


# ---------------------------------------------------------------------------
# the timing child
# ---------------------------------------------------------------------------

def _segment(sim: HertzSimulation, threads: int, steps: int):
    """Time ``steps`` steps on ``threads`` threads; returns a function that
    does it and gives (floe-steps/s, floe-list rebuilds, hull-list builds,
    mean floes touching the hull)."""
    def go():
        numba.set_num_threads(threads)
        rebuilds = sim.n_rebuilds
        builds = int(sim.ship.kernel_bundle.counts[HC.C_REBUILDS]) if sim.ship else 0
        t0 = time.perf_counter()
        sim.step(steps)
        rate = sim.n_floes * steps / (time.perf_counter() - t0)
        out = dict(rate=rate, rebuilds=sim.n_rebuilds - rebuilds)
        if sim.ship is not None:
            out["hull_builds"] = int(sim.ship.kernel_bundle.counts[HC.C_REBUILDS]) - builds
            touching = sim.ship.records()["contacts"][-steps:]
            out["touching"] = float(np.mean(touching))
            out["touch_steps"] = float(np.mean(touching > 0))
            out["collisions"] = int(sim.ship.collisions()["floe"].size)
            out["candidates"] = int(sim.ship.kernel_bundle.counts[HC.C_CAND])
            sim.ship.clear()
        return out
    return go


def time_child(n: int, steps: int, seed: int = 1, warmup: int = WARMUP) -> dict:
    """Run in a fresh process with a pool of two threads: build the field,
    the four simulations of :data:`CONFIGS` (each on its own copy), warm
    them up by ``warmup`` steps (the ship sails into the ice), time
    ``REPEATS`` rounds of one segment of ``steps`` steps of each, taking
    turns (:func:`benchmarks.harness.interleaved_rounds`), then the hull
    kernels on their own on the state of the one-thread ship run."""
    field, side, start, removed = ship_field(n, seed)
    dt = time_step(field)
    sims = []
    for _, ship, threads in CONFIGS:
        numba.set_num_threads(threads)
        sim = _make_sim(field, side, start, ship, threads > 1, dt)
        sim.step(warmup)
        if sim.ship is not None:
            sim.ship.clear()
        sims.append(sim)
    runs = harness.interleaved_rounds([_segment(sim, threads, steps) for (_, _, threads), sim
                                       in zip(CONFIGS, sims)])
    kernels = hull_kernel_times(sims[1], max(100, steps))
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    return dict(runs=runs, kernels=kernels, n=field.n, removed=removed, side=side, dt=dt,
                contacts_per_floe=[2.0 * len(s.contacts()) / s.n_floes for s in sims[:2]],
                ship_x=float(sims[1].ship.position[0] - start[0]))


# ---------------------------------------------------------------------------
# the suite
# ---------------------------------------------------------------------------

def _spread(values) -> list:
    return [float(min(values)), float(max(values))]


def summarise(n_asked: int, children: list[dict], steps: int) -> dict:
    """Medians, ranges, same-round overheads and the ship's share from the
    results of :func:`time_child` of one field size."""
    first = children[0]
    rates = [[seg["rate"] for c in children for seg in c["runs"][k]] for k in range(len(CONFIGS))]
    rows = []
    for k, (label, ship, threads) in enumerate(CONFIGS):
        segs = [seg for c in children for seg in c["runs"][k]]
        row = dict(config=label, ship=ship, threads=threads, rate=float(np.median(rates[k])),
                   spread=_spread(rates[k]),
                   rebuilds_per_1000=1000.0 * float(np.mean([s["rebuilds"] for s in segs])) / steps)
        if ship:
            row["hull_builds_per_1000"] = 1000.0 * float(
                np.mean([s["hull_builds"] for s in segs])) / steps
            row["touching"] = float(np.mean([s["touching"] for s in segs]))
            row["touch_steps"] = float(np.mean([s.get("touch_steps", 0.0) for s in segs]))
            row["collisions_per_1000"] = 1000.0 * float(
                np.mean([s.get("collisions", 0) for s in segs])) / steps
            row["candidates"] = float(np.mean([s["candidates"] for s in segs]))
        rows.append(row)
    kern = {key: float(np.median([c["kernels"][key] for c in children]))
            for key in ("hull_step", "hull_build", "floe_rebuild")}
    overhead = []
    for threads in (1, 2):
        k0 = next(k for k, (_, s, t) in enumerate(CONFIGS) if not s and t == threads)
        k1 = next(k for k, (_, s, t) in enumerate(CONFIGS) if s and t == threads)
        # same round: time per step with the ship / without, minus one
        paired = [a["rate"] / b["rate"] - 1.0 for c in children
                  for a, b in zip(c["runs"][k0], c["runs"][k1])]
        n = first["n"]
        t_without = n / rows[k0]["rate"]
        t_with = n / rows[k1]["rate"]
        hull = kern["hull_step"] + kern["hull_build"] * rows[k1]["hull_builds_per_1000"] / 1000
        extra_rebuilds = (rows[k1]["rebuilds_per_1000"] - rows[k0]["rebuilds_per_1000"]) / 1000
        overhead.append(dict(threads=threads, overhead=float(np.median(paired)),
                             overhead_spread=_spread(paired), step_without=t_without,
                             step_with=t_with, hull_kernels=hull,
                             hull_share=hull / t_with,
                             difference_share=(t_with - t_without) / t_with,
                             extra_rebuilds_per_step=extra_rebuilds,
                             extra_rebuild_time=extra_rebuilds * kern["floe_rebuild"]))
    return dict(n_asked=n_asked, n=first["n"], removed=first["removed"], side=first["side"],
                dt=first["dt"], steps=steps, processes=len(children), rounds=REPEATS,
                contacts_per_floe=first["contacts_per_floe"], ship_sailed=first["ship_x"],
                kernels=kern, rows=rows, overhead=overhead)


def bench_ship(sizes=(2000, 20000), steps: int | None = None, seed: int = 1,
               processes: int = PROCESSES, warmup: int = WARMUP, quiet: bool = False) -> list:
    """Time every field size of ``sizes`` in ``processes`` fresh processes
    with a pool of two threads each, in segments of ``steps`` steps
    (default: :func:`segment_steps`); one :func:`summarise` result per size."""
    out = []
    fixed = steps
    with harness.Progress(len(sizes) * processes, "ship", quiet) as bar:
        for n in sizes:
            steps = segment_steps(n, fixed)
            children = []
            for _ in range(processes):
                children.append(harness.spawn_call(time_child, n, steps, seed, warmup,
                                                   threads=2))
                bar.advance()
            res = summarise(n, children, steps)
            for r in res["rows"]:
                bar.log(f"  N = {res['n']:6d} {r['config']:8s} {r['threads']} thread(s): "
                        f"{r['rate']:.3g} floe-steps/s")
            for o in res["overhead"]:
                bar.log(f"  N = {res['n']:6d} {o['threads']} thread(s): ship costs "
                        f"{100 * o['overhead']:+.1f} % per step, hull kernels "
                        f"{100 * o['hull_share']:.1f} % of the step")
            out.append(res)
    return out


def _ms(seconds: float) -> str:
    return f"{seconds * 1e6:.1f} µs" if seconds < 1e-3 else f"{seconds * 1e3:.2f} ms"


def ship_tables(results: list) -> list[dict]:
    """The rate table and the cost table of :func:`bench_ship`'s results."""
    body = []
    for res in results:
        for r in res["rows"]:
            lo, hi = r["spread"]
            body.append([res["n"], r["config"], r["threads"],
                         "serial" if r["threads"] == 1 else "parallel", r["rate"],
                         f"{lo:.3g}–{hi:.3g}", f"{r['rebuilds_per_1000']:.1f}",
                         f"{r['hull_builds_per_1000']:.2f}" if r["ship"] else "–",
                         f"{100 * r['touch_steps']:.0f} %" if r["ship"] else "–",
                         f"{r['collisions_per_1000']:.1f}" if r["ship"] else "–",
                         f"{r['touching']:.2f} / {r['candidates']:.0f}" if r["ship"] else "–"])
    res0 = results[0]
    rates = harness.table(
        f"Floe-steps/s with and without the ship, Ā = 0.7, Δt = {res0['dt'] * 1e3:g} ms "
        f"(median of {res0['processes'] * REPEATS} segments)",
        ["floes", "run", "threads", "kernels", "floe-steps/s", "range", "floe-list rebuilds "
         "per 1000 steps", "hull-list builds per 1000 steps", "steps with a floe on the hull",
         "collisions per 1000 steps", "floes touching the hull (mean) / in its list"], body,
        "N is the field after the slot for the ship was cleared ("
        + ", ".join(f"{r['removed']} floes removed at N = {r['n_asked']}" for r in results)
        + "); the box side is " + ", ".join(f"{r['side']:.0f} m" for r in results)
        + ", and a segment has " + ", ".join(f"{r['steps']} steps" for r in results)
        + f" ({' and '.join(str(r['n']) for r in results)} floes).")
    body, notes = [], []
    for res in results:
        k = res["kernels"]
        for o in res["overhead"]:
            lo, hi = o["overhead_spread"]
            body.append([res["n"], o["threads"], f"{100 * o['overhead']:+.1f} %",
                         f"{100 * lo:+.1f} to {100 * hi:+.1f} %", _ms(o["step_without"]),
                         _ms(o["step_with"]), f"{100 * o['difference_share']:.1f} %",
                         _ms(o["hull_kernels"]), f"{100 * o['hull_share']:.1f} %",
                         _ms(o["extra_rebuild_time"])])
        notes.append(f"N = {res['n']}: the hull's step (kick–drift and contact pass) takes "
                     f"{_ms(k['hull_step'])} per step, a build of the hull's list "
                     f"{_ms(k['hull_build'])}, a rebuild of the floes' Verlet list "
                     f"{_ms(k['floe_rebuild'])} (serial kernels)")
    over = [o["overhead"] for res in results if res["n_asked"] >= 20000
            for o in res["overhead"]]
    if over:
        notes.append("Target of at most 20 % extra cost per step at N = 20000: "
                     + ", ".join(f"{100 * o['overhead']:+.1f} % on {o['threads']} thread"
                                 f"{'s' * (o['threads'] > 1)}"
                                 for res in results if res["n_asked"] >= 20000
                                 for o in res["overhead"])
                     + (" (met)" if max(over) <= 0.2 else " (not met)"))
    cost = harness.table(
        "What the ship costs per step",
        ["floes", "threads", "extra cost per step (same round, median)", "range",
         "step without ship", "step with ship", "share of the ship (difference of the runs)",
         "hull kernels per step", "share of the ship (hull kernels timed alone)",
         "extra floe-list rebuilds per step × rebuild time"], body,
        "The extra cost is the time per step with the ship over the time without it, "
        "minus one, of the two segments of one round. The hull kernels per step are the "
        "hull's step plus the build of its list at the rate the run built it; they run on "
        "one thread in both configurations. The last column is the ship's effect on the "
        "floes' own Verlet list, rated at the serial rebuild time.\n\n" + "\n\n".join(notes))
    return [rates, cost]


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    p.add_argument("--floes", type=int, nargs="+", default=None,
                   help="field sizes (default 2000 20000)")
    p.add_argument("--steps", type=int, default=None,
                   help=f"timed steps per segment (default {SEGMENT:.0e} floe-steps / N)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--processes", type=int, default=None,
                   help=f"fresh processes per field size (default {PROCESSES})")
    args, argv = harness.parse(p, argv)
    sizes = dict(floes=[2000, 20000], steps=None, processes=PROCESSES, warmup=WARMUP)
    if args.quick:
        sizes.update(QUICK)
    for key in ("floes", "steps", "processes"):
        if getattr(args, key) is not None:
            sizes[key] = getattr(args, key)
    if min(sizes["floes"]) < 100 or (sizes["steps"] or 1) < 1 or sizes["processes"] < 1:
        p.error("--floes must be >= 100, --steps and --processes >= 1")
    t0 = time.perf_counter()
    results = bench_ship(sizes["floes"], sizes["steps"], args.seed, sizes["processes"],
                         sizes["warmup"], args.quiet)
    record = harness.make_record(
        SUITE, TITLE, DESCRIPTION, harness.command_line(SUITE, argv), ship_tables(results),
        dict(sizes=sizes["floes"], seed=args.seed, rounds=REPEATS,
             processes=sizes["processes"], warmup=sizes["warmup"], speed=SPEED,
             concentration=CONCENTRATION, quick=args.quick, results=results),
        time.perf_counter() - t0, machine=harness.machine_info(2))
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
