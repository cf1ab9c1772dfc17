"""The interface of a scenario's experiment, and the registry of experiments.

An experiment is the code behind a scenario file: it turns the resolved
parameters into runs, and runs into a summary and figures. Subclass
:class:`Experiment`, decorate it with :func:`register` and give it a file
in ``configs/``::

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
"""
from __future__ import annotations

import importlib
from pathlib import Path

from .engines import check_engine

_REGISTRY: dict[str, type] = {}
# modules whose import registers the shipped experiments
_MODULES = ("physics.scenarios.herman2013", "physics.scenarios.herman2011",
            "physics.scenarios.godlovitch", "physics.scenarios.ship_transit")


def register(name: str):
    def deco(cls):
        cls.name = name
        _REGISTRY[name] = cls
        return cls
    return deco


def experiments() -> dict[str, type]:
    """Experiment name → class (imports the shipped experiment modules)."""
    for mod in _MODULES:
        importlib.import_module(mod)
    return dict(_REGISTRY)


def get_experiment(name: str, engine: str = "numba") -> "Experiment":
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
