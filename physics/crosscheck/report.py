"""``python -m physics.crosscheck``: run the cross-checks, write a report.

Commands
--------
``all``      every comparison (pymunk, and LAMMPS when it is installed)
``pymunk``   the hard-disc and Hertz engines against pymunk
``ship``     the Hertz engine's ship against a kinematic hull in pymunk
``lammps``   the Hertz engine against LAMMPS
``list``     what each group compares

Options: ``--out DIR`` (default ``runs/crosscheck``), ``--quick`` (smaller
systems, same tolerances; about a minute), ``--seed S``, ``--force`` (replace
an existing report directory), ``--no-progress``.

The report directory holds ``report.md`` (the table, the figures and the
notes on where the engines may differ), ``results.json`` (every row) and
the PNG figures. The exit status is 1 when a check fails, 0 otherwise; a
group that cannot run (LAMMPS absent) is reported as skipped with the
reason.
"""
from __future__ import annotations

import argparse
import json
import platform
import shutil
import sys
import time
from pathlib import Path

from .results import Check, format_table

__all__ = ["GROUPS", "run_groups", "write_report", "main"]

GROUPS = {
    "pymunk": ("physics.crosscheck.pymunk_checks",
               "binary impacts (frictionless: restitution law; frictional: Hertz vs pymunk), "
               "inelastic gas cooling (Haff), relaxation to the drift under drag, "
               "hard-disc engine vs pymunk speed"),
    "ship": ("physics.crosscheck.pymunk_ship",
             "the Hertz engine's ship vs a kinematic pymunk polygon: head-on impacts on an edge "
             "and a vertex, collisions and resistance of a hull through a dilute field"),
    "lammps": ("physics.crosscheck.lammps_checks",
               "forces and torques before any step, 500-step trajectories, the "
               "pressure–concentration curve of a convergence run, Hertz engine vs LAMMPS speed"),
}


def _versions() -> dict:
    import numba
    import numpy

    v = {"python": platform.python_version(), "numpy": numpy.__version__,
         "numba": numba.__version__}
    try:
        import pymunk

        v["pymunk"] = pymunk.version
    except ImportError:
        pass
    from ..lammps_library import lammps_available, lammps_version

    if lammps_available()[0]:
        v["lammps"] = lammps_version()
    return v


def run_groups(names, out_dir: Path | None, quick: bool, seed: int, progress: bool):
    """Run the named groups; returns (rows, skipped, seconds) with
    ``skipped`` a dict group → reason and ``seconds`` group → wall time."""
    import importlib

    rows: list[Check] = []
    skipped: dict[str, str] = {}
    seconds: dict[str, float] = {}
    for name in names:
        if name == "lammps":
            from ..lammps_library import lammps_available

            ok, why = lammps_available()
            if not ok:
                skipped[name] = why
                continue
        module = importlib.import_module(GROUPS[name][0])
        t0 = time.perf_counter()
        got = module.run(out_dir, quick=quick, seed=seed, progress=progress)
        seconds[name] = time.perf_counter() - t0
        if progress:
            print(f"{name}: {len(got)} rows in {seconds[name]:.0f} s", file=sys.stderr)
        rows += got
    return rows, skipped, seconds


NOTES = """\
## Where the engines may differ, and why

* **pymunk has no periodic boundary.** Its runs use four elastic,
  frictionless walls around a box of the same size; the comparisons use
  binary collisions far from the walls and dilute homogeneous gases, where
  the boundary does not change the quantities compared.
* **Friction in pymunk is impulse-based.** A sticking contact ends with no
  slip at the contact point (tangential restitution β = 0), whereas the
  Mindlin spring of the Hertz engine stores tangential elastic energy and
  gives it back (β > 0 at small impact angles). In gross sliding both follow
  Coulomb's law.
* **The ship against a kinematic pymunk polygon.** A head-on impact gives
  the same impulse; in a field, the soft Hertz contact lasts tens of
  milliseconds at the modulus used, during which a contact at a corner of the
  hull turns with the hull's motion, and Mindlin friction differs from
  pymunk's rigid friction where a contact sticks. A floe's path after such a
  contact differs between the engines, so the transits are compared as two
  realisations over several fields, not floe by floe.
* **LAMMPS and a new contact with tangential damping.** With x_γt > 0, a new
  contact whose viscous tangential force alone exceeds μ F_n gets the capped
  force in our engine and none in LAMMPS; Herman's set-up (and our default)
  has x_γt = 0, where the laws are identical.
* **A deforming box** is remapped after the drift in our engine and at the
  end of the step in LAMMPS. From a jammed packing the pressures agree; a run
  through the jamming point is chaotic, so rounding alone makes two runs
  part ways, and they agree only as two realisations of the same process.
"""


def write_report(rows, skipped, seconds, out_dir: Path, command: str, quick: bool) -> Path:
    """``report.md`` and ``results.json`` in ``out_dir``; returns the report path."""
    out_dir.mkdir(parents=True, exist_ok=True)
    versions = _versions()
    failed = [r.name for r in rows if r.passed is False]
    lines = ["# Cross-checks against pymunk and LAMMPS", "",
             f"Command: `{command}`" + (" (quick systems)" if quick else ""), "",
             "Versions: " + ", ".join(f"{k} {v}" for k, v in versions.items()), "",
             "Wall time: " + ", ".join(f"{k} {v:.0f} s" for k, v in seconds.items()), "",
             format_table(rows), ""]
    for name, why in skipped.items():
        lines += [f"**{name}: skipped** — {why}", ""]
    lines.append(f"**{len(failed)} of {sum(r.passed is not None for r in rows)} checks failed**"
                 + (": " + ", ".join(failed) if failed else "."))
    lines.append("")
    figures = [f for r in rows for f in r.figures]
    if figures:
        lines += ["## Figures", ""]
        for f in dict.fromkeys(figures):
            lines += [f"![{f}]({f})", ""]
    lines.append(NOTES)
    path = out_dir / "report.md"
    path.write_text("\n".join(lines))
    (out_dir / "results.json").write_text(json.dumps(
        {"command": command, "quick": quick, "versions": versions, "seconds": seconds,
         "skipped": skipped, "checks": [r.to_dict() for r in rows]}, indent=2))
    return path


def main(argv=None, prog: str = "python -m physics.crosscheck") -> int:
    parser = argparse.ArgumentParser(
        prog=prog,
        description="Cross-check the floe engines against pymunk and LAMMPS.")
    parser.add_argument("command", choices=["all", *GROUPS, "list"],
                        help="which comparisons to run ('list' describes them)")
    parser.add_argument("--out", type=Path, default=Path("runs/crosscheck"),
                        help="report directory (default: runs/crosscheck; the documented "
                             "report is docs/crosscheck, as make records writes it)")
    parser.add_argument("--quick", action="store_true",
                        help="smaller systems, same tolerances (about a minute)")
    parser.add_argument("--seed", type=int, default=0, help="seed of every random set-up")
    parser.add_argument("--force", action="store_true",
                        help="replace an existing report directory")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    args = parser.parse_args(argv)
    if args.command == "list":
        from ..lammps_library import lammps_available

        ok, why = lammps_available()
        for name, (_, what) in GROUPS.items():
            note = "" if name != "lammps" or ok else f"  [unavailable: {why}]"
            print(f"{name:8s} {what}{note}")
        return 0
    if args.seed < 0:
        parser.error(f"--seed must be >= 0, got {args.seed}")
    if args.out.exists() and any(args.out.iterdir()):
        if not args.force:
            parser.error(f"the report directory {args.out} exists; pass --force to replace it")
        shutil.rmtree(args.out)
    names = list(GROUPS) if args.command == "all" else [args.command]
    rows, skipped, seconds = run_groups(names, args.out, args.quick, args.seed,
                                        not args.no_progress)
    command = f"{prog} " + " ".join(argv if argv is not None else sys.argv[1:])
    path = write_report(rows, skipped, seconds, args.out, command, args.quick)
    print(format_table(rows))
    for name, why in skipped.items():
        print(f"{name}: skipped — {why}")
    failed = [r for r in rows if r.passed is False]
    print(f"\n{len(failed)} failed, {sum(r.passed is True for r in rows)} passed, "
          f"{sum(r.passed is None for r in rows)} reported; report: {path}")
    return 1 if failed else 0
