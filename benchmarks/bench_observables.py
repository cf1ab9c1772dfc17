"""Wall time of the observables: ``python -m benchmarks.bench_observables``
(``seaice bench observables``).

    python -m benchmarks.bench_observables [--seed 1] [--quiet] [--quick] [--json PATH | --no-json]
"""
from __future__ import annotations

import sys
import time

import numba
import numpy as np

from physics.clusters import cluster_statistics, find_clusters, g_ffd, g_rdf
from physics.domain import PeriodicBox
from physics.observables import Contacts, contacts_within, fabric, stress
from physics.params import HERMAN2011

from . import harness

SUITE = "observables"
TITLE = "Observables"
DESCRIPTION = """
Wall time of the observables on all threads, the best of five calls after a
warm-up call, on a Herman (2011) field (α_r = 1.5, mean diameter 2 m,
Ā = 0.75) of N = 100008 floes, a placed field of 2778 floes tiled 6 × 6:
clusters with d_m = 0.5 m, cluster statistics, g_ffd and g_rdf; fabric and
stress (per-floe parts included) from the first 10⁵ contacts of the pairs
closer than 1 m, with repulsive normal forces of random size.
"""
#: floes of ``--quick`` (the full benchmark: 100008)
QUICK_FLOES = 2000


def bench_observables(seed: int = 1, tiles: int = 6, quiet: bool = False,
                      floes: int = 100008) -> list[dict]:
    """Wall times of the observables on ``floes`` floes (see :data:`DESCRIPTION`)."""
    tile, tile_box = HERMAN2011.floe_field(floes // tiles ** 2, 0.75, seed=seed)
    shift = np.array([(a * tile_box.lx, b * tile_box.ly) for a in range(tiles)
                      for b in range(tiles)])
    pos = (tile.positions[None, :, :] + shift[:, None, :]).reshape(-1, 2)
    radii = np.tile(tile.radii, tiles * tiles)
    box = PeriodicBox(tiles * tile_box.lx, tiles * tile_box.ly)
    n = radii.size
    rows = []
    bar = harness.Progress(7, "observables", quiet)

    def record(case, seconds, **extra):
        rows.append(dict(case=case, seconds=seconds, **extra))
        bar.advance()
        bar.log(f"  {case}: {seconds * 1e3:.3g} ms")

    with bar:
        labels = find_clusters(pos, radii, box, 0.5)
        cs = cluster_statistics(labels, radii)
        record(f"find_clusters, N = {n}, d_m = 0.5 m",
               harness.best_time(lambda: find_clusters(pos, radii, box, 0.5)),
               clusters=cs.n_clusters, largest_fraction=cs.largest_fraction)
        record(f"cluster_statistics, {cs.n_clusters} clusters",
               harness.best_time(lambda: cluster_statistics(labels, radii)))
        record(f"g_ffd, N = {n}, x < 2 m, 100 bins",
               harness.best_time(lambda: g_ffd(pos, radii, box, 2.0, 100)))
        record(f"g_rdf, N = {n}, x < 10 m, 100 bins",
               harness.best_time(lambda: g_rdf(pos, box, 10.0, 100)))

        geo = contacts_within(pos, radii, box, 1.0)
        k = min(len(geo), 100000)
        rng = np.random.default_rng(seed)
        push = rng.uniform(1e3, 1e5, k)                  # repulsive normal forces [N]
        force = -push[:, None] * geo.normal[:k]
        c = Contacts(geo.i[:k], geo.j[:k], geo.normal[:k], geo.overlap[:k], push,
                     np.zeros(k), force, geo.contact_point[:k], geo.branch_i[:k],
                     geo.branch_j[:k])
        record(f"fabric, {k} contacts", harness.best_time(lambda: fabric(c, n)))
        record(f"stress with per-floe parts, {k} contacts",
               harness.best_time(lambda: stress(c, box.area, n_floes=n)))
        record(f"stress, tensor only, {k} contacts",
               harness.best_time(lambda: stress(c, box.area, per_floe=False)))
    return rows


def observables_table(rows: list[dict]) -> dict:
    """The table of a :func:`bench_observables` result and its notes."""
    notes = [f"{r['clusters']} clusters; the largest holds {100 * r['largest_fraction']:.1f} % "
             f"of the floe area" for r in rows if "clusters" in r]
    return harness.table(f"Observables, {numba.get_num_threads()} threads",
                         ["case", "wall time [ms]"],
                         [[r["case"], float(r["seconds"] * 1e3)] for r in rows],
                         "\n\n".join(notes))


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    p.add_argument("--seed", type=int, default=1)
    args, argv = harness.parse(p, argv)
    floes = QUICK_FLOES if args.quick else 100008
    t0 = time.perf_counter()
    rows = bench_observables(args.seed, quiet=args.quiet, floes=floes)
    record = harness.make_record(
        SUITE, TITLE, DESCRIPTION, harness.command_line(SUITE, argv), [observables_table(rows)],
        dict(seed=args.seed, floes=floes, quick=args.quick, rows=rows),
        time.perf_counter() - t0)
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
