"""This tree against another revision, side by side: ``python -m
benchmarks.bench_compare --against REV`` (``seaice bench compare``).

    python -m benchmarks.bench_compare --against REV [--suites hertz,harddisk,environments]
                                 [--rounds 5] [--ids WindDrift-v0 ...] [--quick]
                                 [--cache-dir .bench_cache] [--quiet]
                                 [--json PATH | --no-json]

The revision is checked out in a temporary ``git worktree`` (removed at the
end, also after an error or Ctrl-C). The workloads are prepared once with
the present code and saved; then each is timed in fresh processes, one
running the packages of the old tree and one those of this tree, taking
turns (old, new, old, new, ...) for ``--rounds`` rounds. Every process
warms up first (compile time is excluded) and reports where it imported
``physics`` from, which is checked.

The workloads use only what both revisions have: the engines' constructors,
``step``/``advance``, ``n_floes``, ``collision_count``,
:class:`~physics.floes.FloeField`,
the boxes, and ``gymnasium.make`` with ``reset``/``step``.
"""
from __future__ import annotations

import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from . import harness

SUITE = "compare"
DESCRIPTION = """
The same workloads timed side by side on two revisions in one run. Each
workload is prepared once with the present code and saved (the floe fields,
the jammed packing, the spun-up hard-disc state); then it is timed in fresh
processes that import the packages of the old revision or of this one, taking
turns (old, new, old, new, ...), each process warming up first so that compile
time is excluded:

* **Hertz engine** (as in the Hertz suite, N = 20000, Herman (2013) material
  table): Ā = 0.7 and jammed, with the serial kernels, the parallel kernels on
  one thread and on all threads taking turns in each process; floe-steps/s,
  the best of three segments per process;
* **hard-disc engine** (as in the hard-disc suite, one core): the elastic gas
  (N = 10000, η = 0.5) and the Herman (2011) set-up after its spin-up;
  collisions/s, the best of three runs per process;
* **every environment** (as in the environments suite, one thread, random
  actions, resets included): sustained steps/s, the mean of the timed runs.

For each workload the table gives the old and new rates (best and median over
the rounds) and the ratio new / old of the two processes of each round: its
median and its range, which is the run-to-run noise of the comparison.
"""
SUITE_NAMES = ("hertz", "harddisk", "environments")
#: sizes of the full comparison and of ``--quick``
FULL = dict(floes=20000, steps=2000, segments=3, gas_floes=10000, gas_collisions=1_000_000,
            herman_floes=3000, spin_up=4000.0, herman_collisions=200_000, seconds=20.0, runs=1,
            warmup=2.0)
QUICK = dict(floes=400, steps=20, segments=1, gas_floes=1000, gas_collisions=20_000,
             herman_floes=300, spin_up=200.0, herman_collisions=2000, seconds=0.5, runs=1,
             warmup=0.0)


# ---------------------------------------------------------------------------
# the old tree
# ---------------------------------------------------------------------------

def _git(*args: str, cwd: Path = harness.ROOT) -> str:
    out = subprocess.run(["git", *args], cwd=cwd, capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"git {' '.join(args)} failed: {out.stderr.strip()}")
    return out.stdout.strip()


class Worktree:
    """A detached ``git worktree`` of ``rev``, removed on exit (also after
    an error, Ctrl-C or SIGTERM).

    Its files get the commit's time as modification time, and the same
    revision gets the same directory while no other comparison uses it, so
    that Numba's on-disk cache of the old kernels (keyed by file path and
    time) serves a later comparison against the same revision.
    """

    def __init__(self, rev: str, repo: Path = harness.ROOT):
        self.repo = Path(repo)
        self.sha = _git("rev-parse", "--verify", f"{rev}^{{commit}}", cwd=self.repo)
        self.path: Path | None = None
        self._old_handler = None

    def __enter__(self) -> Path:
        path = Path(tempfile.gettempdir()) / f"seaice-compare-{self.sha[:12]}"
        if path.exists():
            path = Path(tempfile.mkdtemp(prefix=f"seaice-compare-{self.sha[:12]}-"))
            path.rmdir()
        _git("worktree", "prune", cwd=self.repo)
        _git("worktree", "add", "--detach", str(path), self.sha, cwd=self.repo)
        self.path = path
        try:
            if hasattr(signal, "SIGTERM"):
                self._old_handler = signal.signal(signal.SIGTERM, _terminate)
            stamp = float(_git("show", "-s", "--format=%ct", self.sha, cwd=self.repo))
            for root, dirs, files in os.walk(path):
                dirs[:] = [d for d in dirs if d != ".git"]
                for name in files:
                    os.utime(os.path.join(root, name), (stamp, stamp))
        except BaseException:
            self.__exit__()
            raise
        return path

    def __exit__(self, *exc) -> None:
        if self._old_handler is not None:
            signal.signal(signal.SIGTERM, self._old_handler)
        if self.path is not None:
            subprocess.run(["git", "worktree", "remove", "--force", str(self.path)],
                           cwd=self.repo, capture_output=True)
            subprocess.run(["git", "worktree", "prune"], cwd=self.repo, capture_output=True)
            self.path = None


def _terminate(signum, frame):
    raise SystemExit(128 + signum)


# ---------------------------------------------------------------------------
# workloads: prepared here with the present code, timed in children
# ---------------------------------------------------------------------------

def _save_field(path: Path, field, box) -> str:
    np.savez(path, positions=np.asarray(field.positions), radii=np.asarray(field.radii),
             thickness=np.asarray(field.thickness), velocities=np.asarray(field.velocities),
             angular_velocities=np.asarray(field.angular_velocities),
             density=float(field.density), lx=box.lx, ly=box.ly)
    return str(path)


def _load_field(path: str):
    """A saved field and its periodic box, with the API of both revisions."""
    from physics.domain import PeriodicBox
    from physics.floes import FloeField

    d = np.load(path)
    field = FloeField(positions=d["positions"], radii=d["radii"], thickness=d["thickness"],
                      velocities=d["velocities"], angular_velocities=d["angular_velocities"],
                      density=float(d["density"]))
    return field, PeriodicBox(float(d["lx"]), float(d["ly"]))


def _hertz_child(path: str, steps: int, dt: float, segments: int) -> list[float]:
    """Best floe-steps/s of every kernel configuration over ``segments``
    rounds (see :func:`benchmarks.bench_hertz.time_configs`)."""
    from .bench_hertz import time_configs, warm_sims

    configs, sims = warm_sims(path, dt)
    return [max(r) for r in time_configs(configs, sims, steps, segments)]


def _harddisk_child(path: str, kind: str, collisions: int, chunk: float,
                    segments: int) -> list[float]:
    """Best collisions/s over ``segments`` runs of ``collisions`` collisions,
    after a warm-up advance."""
    from . import bench_harddisk as H

    field, box = _load_field(path)
    sim = H.elastic_sim(field, box) if kind == "elastic" else H.herman_sim(field, box)
    sim.advance(0.1 * chunk)
    return [max(H.time_collisions(sim, collisions, chunk)[0] for _ in range(segments))]


def _environment_child(env_id: str, seconds: float, runs: int, seed: int,
                       warmup: float) -> list[float]:
    """Sustained steps/s (see :func:`benchmarks.bench_environments.measure_env`)."""
    from .bench_environments import measure_env

    return [measure_env(env_id, seconds, runs, seed, warmup)["mean"]]


def prepare(suites, sizes: dict, work: Path, cache_dir: Path, seed: int = 1, ids=None,
            quiet: bool = False) -> list[dict]:
    """The workloads of ``suites``, prepared with the present code and saved
    under ``work``: dicts of ``name``, ``labels`` (one per figure a child
    returns), ``unit``, the child function, its arguments and threads."""
    out = []
    if "hertz" in suites:
        import numba

        from .bench_hertz import kernel_configs, prepared_cases

        labels = [f"{k}, {t} thread{'s' * (t > 1)}"
                  for k, _, t in kernel_configs(numba.config.NUMBA_NUM_THREADS)]
        for name, path, dt in prepared_cases(sizes["floes"], seed, cache_dir, quiet):
            out.append(dict(name=f"Hertz, N = {sizes['floes']}, {name}", labels=labels,
                            unit="floe-steps/s", fn=_hertz_child,
                            args=(str(path), sizes["steps"], dt, sizes["segments"]),
                            threads=numba.config.NUMBA_NUM_THREADS))
    if "harddisk" in suites:
        from . import bench_harddisk as H

        field, box = H.gas_field(sizes["gas_floes"], 0.5, seed)
        sim = H.elastic_sim(field, box)
        sim.advance(1.0)                          # about 5 collisions per disc
        gas = _save_field(work / "gas.npz", sim.state(), box)
        field, box = H.herman_field(sizes["herman_floes"], seed)
        sim = H.herman_sim(field, box)
        sim.advance(sizes["spin_up"], progress=not quiet)
        herman = _save_field(work / "herman2011.npz", sim.state(), box)
        out.append(dict(name=f"hard discs, elastic, N = {sizes['gas_floes']}, η = 0.5",
                        labels=["one core"], unit="collisions/s", fn=_harddisk_child,
                        args=(gas, "elastic", sizes["gas_collisions"], 1.0, sizes["segments"]),
                        threads=None))
        out.append(dict(name=f"hard discs, Herman 2011, N = {sizes['herman_floes']}, Ā = 0.75, "
                             f"after {sizes['spin_up']:g} s",
                        labels=["one core"], unit="collisions/s", fn=_harddisk_child,
                        args=(herman, "herman", sizes["herman_collisions"], 100.0,
                              sizes["segments"]), threads=None))
    if "environments" in suites:
        from iceenvs import ENV_IDS

        from .bench_environments import resolve_ids

        for env_id in (resolve_ids(ids, ENV_IDS) if ids else ENV_IDS):
            out.append(dict(name=env_id, labels=["one thread"], unit="steps/s",
                            fn=_environment_child,
                            args=(env_id, sizes["seconds"], sizes["runs"], 0, sizes["warmup"]),
                            threads=1))
    return out



# ---------------------------------------------------------------------------
# the run
# ---------------------------------------------------------------------------

def _run_child(workload: dict, tree: Path) -> tuple[list[float], dict]:
    """One timed process of ``workload`` on the packages of ``tree``."""
    child = harness.Child(workload["fn"], workload["args"], threads=workload["threads"],
                          source=tree)
    rates = child.result()
    if "physics" not in child.loaded_from:
        raise RuntimeError(f"a child meant to run {tree} did not import physics")
    for name, where in child.loaded_from.items():
        if where is None or not Path(where).resolve().is_relative_to(tree.resolve()):
            raise RuntimeError(f"a child meant to run {tree} imported {name} from {where}")
    return rates, child.loaded_from


def run_rounds(workloads: list[dict], old: Path, new: Path, rounds: int,
               quiet: bool = False) -> tuple[list[dict], dict]:
    """Time every workload ``rounds`` times on each tree, the trees taking
    turns; returns one result per workload and label, and where the last
    process of each tree imported the packages from."""
    results = [dict(name=w["name"], label=lab, unit=w["unit"], old=[], new=[])
               for w in workloads for lab in w["labels"]]
    loaded = {}
    with harness.Progress(2 * rounds * len(workloads), "compare", quiet) as bar:
        for r in range(rounds):
            k = 0
            for w in workloads:
                for side, tree in (("old", old), ("new", new)):
                    rates, loaded[side] = _run_child(w, tree)
                    for j, rate in enumerate(rates):
                        results[k + j][side].append(rate)
                    bar.advance()
                for j, lab in enumerate(w["labels"]):
                    res = results[k + j]
                    bar.log(f"  round {r + 1}: {w['name']}, {lab}: old {res['old'][-1]:.4g}, "
                            f"new {res['new'][-1]:.4g} {w['unit']} "
                            f"(new / old {res['new'][-1] / res['old'][-1]:.3f})")
                k += len(w["labels"])
    for res in results:
        ratios = [b / a for a, b in zip(res["old"], res["new"])]
        res.update(ratios=ratios, ratio_median=statistics.median(ratios),
                   ratio_min=min(ratios), ratio_max=max(ratios),
                   old_best=max(res["old"]), old_median=statistics.median(res["old"]),
                   new_best=max(res["new"]), new_median=statistics.median(res["new"]))
    return results, loaded


def compare_table(results: list[dict], rounds: int, old_name: str, new_name: str) -> dict:
    """The table of :func:`run_rounds`."""
    body = [[f"{r['name']} ({r['label']})", r["unit"], float(r["old_best"]),
             float(r["old_median"]), float(r["new_best"]), float(r["new_median"]),
             f"{r['ratio_median']:.3f}", f"{r['ratio_min']:.3f}–{r['ratio_max']:.3f}"]
            for r in results]
    notes = (f"Old: {old_name}; new: {new_name}. Rates are the best and the median over "
             f"{rounds} rounds of one process per tree; new / old is the ratio of the two "
             f"processes of one round (its median, and its range over the rounds).")
    return harness.table(f"{new_name} against {old_name}, {rounds} rounds",
                         ["workload", "unit", "old best", "old median", "new best",
                          "new median", "new / old (median)", "new / old (range)"], body, notes)


def _describe_new() -> str:
    """This tree: its commit, and whether it has uncommitted changes."""
    try:
        head = _git("rev-parse", "--short", "HEAD")
        dirty = bool(_git("status", "--porcelain", "--untracked-files=no"))
    except RuntimeError:
        return "this tree"
    return f"{head} with uncommitted changes" if dirty else head


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, __doc__.split("\n\n")[0] + "\n\n" + DESCRIPTION, prog)
    p.add_argument("--against", required=True, metavar="REV",
                   help="the revision to compare against (a commit, tag or branch)")
    p.add_argument("--suites", default=",".join(SUITE_NAMES),
                   help=f"comma-separated workloads to compare (default {','.join(SUITE_NAMES)})")
    p.add_argument("--rounds", type=int, default=5,
                   help="processes per tree and workload, taking turns (default 5)")
    p.add_argument("--ids", nargs="+", metavar="ID",
                   help="environments to compare, e.g. WindDrift-v0 (default: all)")
    p.add_argument("--seed", type=int, default=1, help="seed of the prepared floe fields")
    p.add_argument("--cache-dir", type=Path, default=harness.CACHE_DIR,
                   help=f"where the Hertz suite's prepared fields are kept "
                        f"(default {harness.in_checkout(harness.CACHE_DIR)})")
    args, argv = harness.parse(p, argv)
    suites = [s.strip() for s in args.suites.split(",") if s.strip()]
    unknown = [s for s in suites if s not in SUITE_NAMES]
    if unknown or not suites:
        p.error(f"--suites takes some of {', '.join(SUITE_NAMES)}; got {args.suites!r}")
    if args.rounds < 1:
        p.error("--rounds must be at least 1")
    sizes = QUICK if args.quick else FULL
    t0 = time.perf_counter()
    try:
        tree = Worktree(args.against)
    except RuntimeError as exc:
        p.error(str(exc))
    new_name = _describe_new()
    old_name = f"{args.against} ({tree.sha[:7]})" if not tree.sha.startswith(args.against) \
        else tree.sha[:7]
    with tree as old, tempfile.TemporaryDirectory(prefix="seaice-compare-work-") as work:
        if not args.quiet:
            print(f"old tree: {old} ({tree.sha[:12]}); preparing the workloads ...", flush=True)
        workloads = prepare(suites, sizes, Path(work), args.cache_dir, args.seed, args.ids,
                            args.quiet)
        results, loaded = run_rounds(workloads, old, harness.ROOT, args.rounds, args.quiet)
    record = harness.make_record(
        SUITE, f"This commit against {args.against}", DESCRIPTION,
        harness.command_line(SUITE, argv),
        [compare_table(results, args.rounds, old_name, new_name)],
        dict(against=args.against, old_commit=tree.sha, new=new_name, rounds=args.rounds,
             suites=suites, sizes=sizes, quick=args.quick, results=results,
             imported_from={side: {k: f"{name}:{Path(v).resolve().relative_to(root.resolve())}"
                                   for k, v in loaded[side].items()}
                            for side, root, name in (("old", old, tree.sha[:7]),
                                                     ("new", harness.ROOT, "this tree"))}),
        time.perf_counter() - t0)
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
