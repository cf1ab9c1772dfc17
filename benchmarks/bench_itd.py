"""Wall time of the ice-thickness-distribution models: ``python -m
benchmarks.bench_itd`` (``seaice bench itd``).

    python -m benchmarks.bench_itd [--quiet] [--quick] [--json PATH | --no-json]
"""
from __future__ import annotations

import sys
import time

import numpy as np

from physics.itd import ThorndikeModel, constant_kernel, solve_smoluchowski

from . import harness

SUITE = "itd"
TITLE = "Ice thickness distribution"
DESCRIPTION = """
Wall time of the ice-thickness-distribution models on one core, the best of
three calls after a warm-up call: a 2000-day generalised-Thorndike run with
200 classes of 0.1 m and daily steps for each kernel of Godlovitch et al.'s
Table 1 and for rafting (the rates of the `godlovitch-*` scenarios, from the
`GODLOVITCH` preset), and `solve_smoluchowski` with n = 1000 masses to t = 10
(constant kernel, monodisperse start).
"""
#: the full benchmark's sizes
FULL = dict(days=2000, masses=1000, repeats=3)
#: sizes of ``--quick``
QUICK = dict(days=50, masses=100, repeats=1)


def _itd_cases() -> list[tuple[str, dict]]:
    """The Table 1 kernels with their rates (Fig. 4) and rafting with the
    1 m cut-off (Fig. 5), from :data:`physics.params.GODLOVITCH`."""
    from physics.params import GODLOVITCH

    return list(GODLOVITCH.kernels.items()) + [("rafting", GODLOVITCH.rafting_params(1.0))]


def bench_itd(quiet: bool = False, days: int = 2000, masses: int = 1000,
              repeats: int = 3) -> list[dict]:
    """Wall times of the ITD models (see :data:`DESCRIPTION`)."""
    cases = _itd_cases()
    rows = []
    with harness.Progress(len(cases) + 1, "itd", quiet) as bar:
        for kind, params in cases:
            def run(kind=kind, params=params):
                m = ThorndikeModel(kind, **params)
                m.run(days)
                return m
            seconds = harness.best_time(run, repeats=repeats)
            m = run()
            rows.append(dict(case=f"Thorndike, {kind} kernel {params}, {days} days",
                             seconds=seconds, substeps=m.substeps, open_water=m.open_water,
                             mean_thickness=m.mean_thickness))
            bar.advance()
            bar.log(f"  {rows[-1]['case']}: {seconds:.3g} s")
        u0 = np.zeros(masses)
        u0[0] = 1.0
        k = constant_kernel(masses)
        seconds = harness.best_time(lambda: solve_smoluchowski(k, u0, [10.0]), repeats=repeats)
        rows.append(dict(case=f"solve_smoluchowski, n = {masses}, t = 10, constant kernel",
                         seconds=seconds))
        bar.advance()
        bar.log(f"  {rows[-1]['case']}: {seconds:.3g} s")
    return rows


def itd_table(rows: list[dict]) -> dict:
    """The table of a :func:`bench_itd` result."""
    body = []
    for r in rows:
        extra = ([r["substeps"], f"{r['open_water']:.3f}", f"{r['mean_thickness']:.3f}"]
                 if "substeps" in r else ["–", "–", "–"])
        body.append([r["case"], float(r["seconds"]), *extra])
    return harness.table("Ice thickness distribution, one core",
                         ["case", "wall time [s]", "Euler steps", "open water", "mean h [m]"],
                         body)


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    args, argv = harness.parse(p, argv)
    sizes = QUICK if args.quick else FULL
    t0 = time.perf_counter()
    rows = bench_itd(args.quiet, **sizes)
    record = harness.make_record(
        SUITE, TITLE, DESCRIPTION, harness.command_line(SUITE, argv), [itd_table(rows)],
        dict(sizes, quick=args.quick, rows=rows), time.perf_counter() - t0)
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
