"""The interface of a scenario's experiment, and the registry of experiments.

An experiment is the code behind a scenario file: it turns the resolved
parameters into runs, and runs into a summary and figures. Adding a
scenario takes one module in this package and one scenario file in
``configs/``:

* ``physics/scenarios/my_scenario.py`` subclasses :class:`Experiment` and
  registers it with :func:`register`, the decorator written at the start of
  a line::

    from .experiment import Experiment, register

    @register("my-scenario")
    class MyScenario(Experiment):
        variables = {"p": ("N/m", "pressure")}

        def cases(self, p):                    # one run per case and member
            return [{"concentration": a} for a in p["concentrations"]]

        def simulate(self, p, case, seed, rec):
            state = rec.restore() or {...}     # fresh start or checkpoint
            ...
            rec.record(t, p=...)
            rec.checkpoint(state)

        def summarise(self, ds, p):            # rows of the summary table
            return [("p at the end", f"{...:.3g} N/m", "paper value")]

        def plot(self, ds, p, out_dir):        # PNG paths
            ...

* ``physics/scenarios/configs/my-scenario.yaml`` gives its parameters
  (``name: my-scenario``; the format is in :mod:`physics.scenarios.config`).

Nothing else lists the experiments: :func:`experiments` imports the modules
of this package whose source has a line beginning with ``@register(`` (found
by reading the files, so the other modules stay unimported), and the tests
check that every registered experiment has a scenario file of its name and
every scenario file an experiment. An experiment that runs on the Hertz
engines lists them in ``engines`` and builds its simulation with
``engines.hertz_simulation(self.engine, ...)``: :attr:`Experiment.engine` is
the engine the run chose.
"""
from __future__ import annotations

import functools
import importlib
import pkgutil
import re
from pathlib import Path

from .engines import check_engine

_REGISTRY: dict[str, type] = {}
#: a line of a module that registers an experiment
_REGISTERS = re.compile(r"^@register\(", re.MULTILINE)


def experiment_modules(directory: Path = Path(__file__).parent,
                       package: str = __package__) -> list[str]:
    """The modules of ``package`` (in ``directory``) that register an
    experiment: those whose source has a line beginning with ``@register(``."""
    found = []
    for info in pkgutil.iter_modules([str(directory)]):
        path = directory / f"{info.name}.py"
        if not info.ispkg and path.is_file() and _REGISTERS.search(path.read_text("utf-8")):
            found.append(f"{package}.{info.name}")
    return found


@functools.cache
def _import_experiment_modules() -> None:
    for module in experiment_modules():
        importlib.import_module(module)


def register(name: str):
    """Class decorator: register an :class:`Experiment` subclass as the
    experiment of the scenario ``name`` (written at the start of a line, so
    that :func:`experiments` finds its module)."""
    def deco(cls):
        cls.name = name
        _REGISTRY[name] = cls
        return cls
    return deco


def experiments() -> dict[str, type]:
    """Experiment name → class (imports the modules of this package that
    register experiments, see :func:`experiment_modules`)."""
    _import_experiment_modules()
    return dict(_REGISTRY)


def get_experiment(name: str, engine: str = "numba") -> Experiment:
    """The experiment ``name``, running on ``engine`` (checked with
    :func:`~physics.scenarios.engines.check_engine`)."""
    found = experiments()
    if name not in found:
        raise ValueError(f"unknown scenario {name!r}; valid scenarios: {', '.join(sorted(found))}")
    return found[name](check_engine(engine, found[name]))


class Experiment:
    """Base class; see the module docstring."""

    name = ""
    #: variable name → (units, description), written as NetCDF attributes
    variables: dict[str, tuple[str, str]] = {}
    #: variables a finished run must hold (checked by the tests)
    required: tuple[str, ...] = ()
    #: the coordinate that labels the cases (for tables and plots)
    case_label: str | None = None
    #: whether runs store floe snapshots (their variables then always exist)
    takes_snapshots: bool = True
    #: the engines it runs on (:mod:`physics.scenarios.engines`)
    engines: tuple[str, ...] = ("numba",)

    def __init__(self, engine: str = "numba"):
        #: the engine this instance runs on (one of ``engines``)
        self.engine = engine

    def cases(self, p: dict) -> list[dict]:
        """One dict of coordinate values per independent run (default: one)."""
        return [{}]

    def workload(self, p: dict, case: dict) -> float:
        """Relative cost of a case (runs start with the largest)."""
        return 1.0

    def simulate(self, p: dict, case: dict, seed: int, rec) -> None:
        raise NotImplementedError

    def summarise(self, ds, p: dict) -> list[tuple[str, str, str]]:
        """Rows (quantity, value, paper) of the summary table."""
        return []

    def plot(self, ds, p: dict, out_dir: Path) -> list[Path]:
        return []
