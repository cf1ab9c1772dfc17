"""``seaice`` (also ``python -m seaice_gym``): the project's tools under one
command.

::

    seaice train --env iceenvs/ThicknessDistribution-v0 --algo ppo
    seaice evaluate runs/ppo-thickness
    seaice scenarios run herman2013-convergence --quick
    seaice crosscheck all --quick
    seaice bench hertz --quick
    seaice validate
    seaice demo

Each sub-command hands the rest of the command line to a tool's own entry
point, which also runs on its own (``python -m agents.train``,
``ice-scenarios``, ...); ``seaice SUB --help`` shows its options.
"""
from __future__ import annotations

import argparse
import importlib
import inspect
import os
import sys
import time
from pathlib import Path

from . import __version__

#: sub-command → (entry point "module:function", or None for the groups below, one-line
#: description)
COMMANDS = {
    "train": ("agents.train:main", "train a stable-baselines3 agent on an environment"),
    "evaluate": ("agents.evaluate:main", "compare a trained policy with the baselines"),
    "tune": ("agents.tune:main", "search an algorithm's hyperparameters with Optuna"),
    "scenarios": ("physics.scenarios.cli:main", "run the papers' experiments (ice-scenarios)"),
    "crosscheck": ("physics.crosscheck.report:main",
                   "cross-check the engines against pymunk and LAMMPS"),
    "bench": (None, "run a benchmark suite (seaice bench --help lists them)"),
    "validate": ("physics.validate:main", "check the Hertz engine against theory"),
    "demo": (None, "an engine run, then a training run (as make demo)"),
}

#: benchmark suite → one-line description; ``seaice bench SUITE`` runs its module
#: (:func:`bench_module`)
BENCH_SUITES = {
    "hertz": "floe-steps/s of the Hertz engine at A = 0.7 and jammed",
    "hertz_phases": "each phase of a Hertz step on its own",
    "harddisk": "collisions/s of the hard-disc engine",
    "observables": "clusters, g_ffd, g_rdf, fabric and stress on many floes",
    "itd": "the ice-thickness-distribution models",
    "environments": "sustained steps/s of every environment",
    "vector": "native vector environments against the others, and PPO steps/s with each",
    "ship": "floe-steps/s with and without a ship, and the ship's share of a step",
    "sensors": "one call of the ship's lidar, swath sensor and image, and their share of a step",
    "scaling": "speed-up against Numba threads: Hertz step, vector envs, PPO, the memory-bound ceiling",
    "where_time_goes": "where a ShipNavigation-v1 step and PPO on it spend their time",
    "compare": "this tree against another revision, side by side",
    "lammps_scaling": "LAMMPS on MPI ranks against ours on threads, its scaling, a projection",
    "resting": "skipping the floes at rest: transit statistics on and off, env steps/s",
    "free_drift": "the free-drift step against the exact one: paired episode statistics, env steps/s",
    "headline": "put the headline figures of the records into the README",
}

#: the entries of :data:`BENCH_SUITES` that are tools beside the suites, not suites
BENCH_TOOLS = ("headline",)


def bench_module(name: str) -> str:
    """The module that ``seaice bench NAME`` runs: ``benchmarks.bench_NAME``
    for a suite (as ``benchmarks.suite_module`` names it, which this
    cannot import before it has found the checkout), ``benchmarks.NAME``
    for a tool of :data:`BENCH_TOOLS`."""
    return f"benchmarks.{name}" if name in BENCH_TOOLS else f"benchmarks.bench_{name}"


#: the variable that names the source checkout whose suites ``seaice bench`` runs
#: (default: the current directory, when it holds ``benchmarks/``)
SOURCE_VARIABLE = "SEAICE_GYM_SOURCE"

#: the parts of ``seaice demo``, run in this order when none is named
DEMOS = {
    "physics": ("physics.demo:main", "force chains and a ship transit in the Hertz engine, "
                                     "with figures"),
    "agents": ("agents.demo:main", "a short PPO training, evaluated against the baselines"),
}


def _parser(prog: str, description: str, entries: dict, what: str, required: bool = True,
            epilog: str | None = None) -> argparse.ArgumentParser:
    """A parser that reads only the first argument, the name of an entry
    (``what`` it is called in the messages)."""
    parser = argparse.ArgumentParser(prog=prog, description=description, epilog=epilog,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest=what, required=required)
    for name, (_, text) in entries.items():
        sub.add_parser(name, help=text, add_help=False)
    return parser


def _pick(parser: argparse.ArgumentParser, argv: list[str], what: str) -> str | None:
    """The entry named by ``argv[0]``; help, usage errors (an unknown name
    lists the valid ones) and ``--version`` exit as argparse does."""
    return getattr(parser.parse_args(argv[:1]), what)


def _call(target: str, argv: list[str], prog: str) -> int:
    """Run the entry point ``module:function`` with ``argv``; its return
    value becomes an exit status (0 unless it returns an int)."""
    module_name, func_name = target.split(":")
    module = importlib.import_module(module_name)
    func = getattr(module, func_name)
    params = inspect.signature(func).parameters
    result = func(list(argv), **({"prog": prog} if "prog" in params else {}))
    return result if isinstance(result, int) and not isinstance(result, bool) else 0


def benchmarks_checkout() -> Path | None:
    """The source checkout whose benchmark suites ``seaice bench`` runs: the
    directory named by :data:`SOURCE_VARIABLE` if it is set, else the current
    directory if it holds the ``benchmarks`` package, else ``None`` (then
    ``benchmarks`` is imported from the module path, if it is there at all).

    Raises
    ------
    ValueError
        If :data:`SOURCE_VARIABLE` names a directory without ``benchmarks/``.
    """
    named = os.environ.get(SOURCE_VARIABLE, "")
    root = Path(named or os.curdir).resolve()
    if (root / "benchmarks" / "__init__.py").is_file():
        return root
    if named:
        raise ValueError(f"{SOURCE_VARIABLE}={named!r} has no benchmarks/ folder; it must "
                         f"name the root of a source checkout of seaice-gym")
    return None


def _bench(argv: list[str], prog: str) -> int:
    entries = {name: (f"{bench_module(name)}:main", text) for name, text in BENCH_SUITES.items()}
    parser = _parser(prog, "Run one benchmark suite (python -m benchmarks.bench_SUITE).", entries,
                     "suite", epilog=f"{prog} SUITE --help shows the options of a suite.\n\n"
                                     f"The suites come with a source checkout, not with the "
                                     f"installed package: run\n{prog} from the root of a "
                                     f"checkout, or set {SOURCE_VARIABLE} to that root.")
    suite = _pick(parser, argv, "suite")
    try:
        root = benchmarks_checkout()
    except ValueError as exc:
        parser.error(str(exc))
    if root is not None and str(root) not in sys.path:
        sys.path.insert(0, str(root))        # as python -m benchmarks.bench_SUITE from the root
    module = bench_module(suite)
    try:
        importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name not in ("benchmarks", module):
            raise
        parser.error(f"the benchmark suites are not installed with seaice-gym: they come with "
                     f"a source checkout. Run `{prog} {suite}` (or `python -m "
                     f"{module}`) from the root of a checkout, or set "
                     f"{SOURCE_VARIABLE} to that root.")
    return _call(entries[suite][0], argv[1:], f"{prog} {suite}")


def _demo(argv: list[str], prog: str) -> int:
    parser = _parser(prog, f"{prog}: the engine demo, then the training demo, as make demo runs\n"
                           f"them. {prog} physics, {prog} agents: that demo alone, with its\n"
                           f"own options ({prog} physics --help).", DEMOS, "part",
                     required=False)
    part = _pick(parser, argv, "part")
    if part is not None:
        return _call(DEMOS[part][0], argv[1:], f"{prog} {part}")
    t0 = time.perf_counter()
    for name, (target, _) in DEMOS.items():
        status = _call(target, [], f"{prog} {name}")
        if status:
            return status
    print(f"{prog}: done in {time.perf_counter() - t0:.0f} s")
    return 0


#: the sub-commands that choose among several entry points
_GROUPS = {"bench": _bench, "demo": _demo}


def build_parser(prog: str = "seaice") -> argparse.ArgumentParser:
    """The parser of the first argument (the sub-command), for the help and
    the usage errors."""
    examples = __doc__.split("::", 1)[1].split("\n\n")[1]
    parser = _parser(prog, "The tools of seaice-gym (environments, engines, scenarios, agents) "
                           "under one command.", COMMANDS, "command",
                     epilog=f"examples:\n{examples}\n\n{prog} COMMAND --help shows the options "
                            f"of a command.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``seaice`` with ``argv`` (default: the command line); returns the
    exit status of the sub-command."""
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    command = _pick(parser, argv, "command")
    prog = f"{parser.prog} {command}"
    if command in _GROUPS:
        return _GROUPS[command](argv[1:], prog)
    return _call(COMMANDS[command][0], argv[1:], prog)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
