"""``ice-scenarios`` (also ``python -m physics.scenarios``): list, show, run and
plot the papers' experiments.

::

    ice-scenarios list
    ice-scenarios show herman2013-convergence
    ice-scenarios run herman2013-convergence --quick
    ice-scenarios run herman2011-clustering --floes 2000 --ensemble 2 --set concentrations=[0.6,0.8]
    ice-scenarios run my-copy.yaml --out runs/mine
    ice-scenarios run --resume runs/herman2013-convergence
    ice-scenarios run herman2013-wind --floes 200000 --engine lammps --mpi 8
    ice-scenarios run herman2013-wind --ensemble 8 --dask-local 4
    ice-scenarios plot runs/herman2013-convergence
    ice-scenarios summary runs/herman2013-convergence
    ice-scenarios compare runs/wind runs/wind-lammps
"""
from __future__ import annotations

import argparse
import shlex
import sys
import textwrap

from .config import bundled_configs, load_config, parse_set
from .runner import find_config, plot_run, resume_run, run_scenario, summarise_run


def _list() -> int:
    rows = [(name, load_config(path)) for name, path in bundled_configs().items()]
    width = max(len(n) for n, _ in rows)
    for name, cfg in rows:
        print(f"{name:{width}s}  {cfg.title} ({cfg.reproduces})")
    print("\nice-scenarios show NAME for its parameters; ice-scenarios run NAME --quick to try it")
    return 0


def _show(name: str) -> int:
    cfg = find_config(name)
    print(f"{cfg.name}: {cfg.title}")
    print(f"reproduces: {cfg.reproduces}")
    print(f"file: {cfg.path} (copy it, edit it, run the copy)\n")
    print(textwrap.fill(cfg.description, 88) + "\n")
    print("parameters (--set NAME=VALUE):")
    for key, p in cfg.params.items():
        quick = f"   (--quick: {cfg.quick[key]})" if key in cfg.quick else ""
        units = f" [{p.units}]" if p.units else ""
        print(f"  {key} = {p.default}{quick}")
        print(f"      {p.help}{units}; {p.allowed()}")
    return 0


def build_parser(prog: str = "ice-scenarios") -> argparse.ArgumentParser:
    """The command-line parser; ``prog`` is the command's name in the help."""
    ap = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=textwrap.dedent(__doc__.split("::", 1)[1]))
    sub = ap.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="the scenarios")
    s = sub.add_parser("show", help="a scenario's parameters and the figure it reproduces")
    s.add_argument("name")
    r = sub.add_parser("run", help="run a scenario (or --resume an interrupted run)")
    r.add_argument("name", nargs="?", help="scenario name or path of a scenario YAML file")
    r.add_argument("--floes", type=int, help="number of floes (the 'floes' parameter)")
    r.add_argument("--seed", type=int, default=0, help="seed of the run (default 0)")
    r.add_argument("--ensemble", type=int, default=1, help="ensemble members (default 1)")
    r.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="set a parameter (YAML value: 0.5, true, [0.6,0.8]); repeatable")
    r.add_argument("--out", help="run directory (default runs/NAME, runs/NAME-quick)")
    r.add_argument("--quick", action="store_true",
                   help="the reduced form: a small set-up that runs in seconds")
    r.add_argument("--force", action="store_true", help="overwrite an existing run directory")
    r.add_argument("--resume", metavar="RUN_DIR", help="continue an interrupted run")
    r.add_argument("--workers", type=int, help="parallel processes (default: one per core)")
    r.add_argument("--engine", choices=("numba", "lammps"), default="numba",
                   help="the engine of the Hertz scenarios: numba (default) or lammps")
    r.add_argument("--mpi", type=int, metavar="N",
                   help="run each LAMMPS job on N MPI ranks (mpiexec -n N; with --engine lammps)")
    dask = r.add_mutually_exclusive_group()
    dask.add_argument("--scheduler", metavar="ADDRESS",
                      help="run the jobs on the workers of this Dask scheduler "
                           "(tcp://HOST:8786); they must see the run directory")
    dask.add_argument("--dask-local", type=int, metavar="N",
                      help="run the jobs on a local Dask cluster of N worker processes")
    r.add_argument("--checkpoint-every", type=float, default=60.0, metavar="SECONDS",
                   help="wall seconds between checkpoints (default 60)")
    r.add_argument("--no-plots", action="store_true", help="skip the figures")
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    p = sub.add_parser("plot", help="(re)make the figures of a run directory")
    p.add_argument("run_dir")
    m = sub.add_parser("summary", help="print the summary table of a run directory, "
                                       "computed afresh from its results")
    m.add_argument("run_dir")
    c = sub.add_parser("compare", help="two runs of a scenario side by side: is the other's "
                                       "ensemble mean within the reference's spread?")
    c.add_argument("reference", help="run directory of the reference (e.g. our engine)")
    c.add_argument("other", help="run directory to compare with it (e.g. --engine lammps)")
    c.add_argument("--sigma", type=float, default=2.0, metavar="K",
                   help="means within K standard deviations of the members agree (default 2)")
    c.add_argument("--quantity", action="append", metavar="NAME",
                   help="compare only this quantity (repeatable)")
    c.add_argument("--check", action="store_true",
                   help="exit with 1 if a quantity is outside the spread")
    return ap


def main(argv=None, prog: str = "ice-scenarios") -> int:
    """Run the command line ``argv`` (default: this process's); ``prog`` is
    the command's name in the help and the messages (``seaice scenarios``
    runs this one). Returns the exit status."""
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser(prog).parse_args(argv)
    try:
        if args.command == "list":
            return _list()
        if args.command == "show":
            return _show(args.name)
        if args.command == "plot":
            for path in plot_run(args.run_dir):
                print(path)
            return 0
        if args.command == "summary":
            print(summarise_run(args.run_dir))
            return 0
        if args.command == "compare":
            from .compare import compare_runs
            result = compare_runs(args.reference, args.other, k=args.sigma,
                                  quantities=args.quantity)
            print(result.markdown())
            return 1 if args.check and result.outside else 0
        common = dict(workers=args.workers, checkpoint_every=args.checkpoint_every,
                      progress=not args.no_progress, plots=not args.no_plots,
                      dask=({"scheduler": args.scheduler} if args.scheduler is not None else
                            {"local": args.dask_local} if args.dask_local is not None else None))
        if args.resume:
            if args.engine != "numba" or args.mpi is not None:
                raise ValueError("--resume continues a run on the engine and ranks it was "
                                 "started with (recorded in its run.yaml)")
            if args.name or args.set or args.floes is not None or args.quick:
                raise ValueError("--resume continues a run as it was started; give only the "
                                 "run directory (and --workers, --checkpoint-every, "
                                 "--scheduler, --dask-local)")
            resume_run(args.resume, **common)
            return 0
        if not args.name:
            raise ValueError("run needs a scenario name (ice-scenarios list) or --resume RUN_DIR")
        run_scenario(args.name, overrides=parse_set(args.set), floes=args.floes, seed=args.seed,
                     ensemble=args.ensemble, quick=args.quick, out=args.out, force=args.force,
                     engine=args.engine, mpi_ranks=args.mpi,
                     command=f"{prog} {shlex.join(argv)}", **common)
        return 0
    except (ValueError, FileExistsError, FileNotFoundError) as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 2
    except (RuntimeError, FloatingPointError) as exc:
        # the physics stopped a run (a blow-up, inelastic collapse, a box at
        # its concentration limit): say why, without a traceback
        print(f"{prog}: the run stopped: {exc}\n"
              "The outputs and checkpoints written before are kept in the run directory.",
              file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
