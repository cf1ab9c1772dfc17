"""Which engine runs the Hertz scenarios: our Numba engine or LAMMPS.

``ice-scenarios run NAME --engine lammps`` runs the Herman (2013)
scenarios on :class:`~physics.lammps_engine.LammpsHertzSimulation` instead
of :class:`~physics.hertz.HertzSimulation`; with ``--mpi N`` each run goes
to ``mpiexec -n N`` (:mod:`physics.scenarios.lammps_job`). The experiments
build their simulation with :func:`hertz_simulation`, which creates the
engine of the run; an experiment lists the engines it supports in its
``engines`` attribute.
"""
from __future__ import annotations

ENGINES = ("numba", "lammps")

_CURRENT = {"engine": "numba"}


def check_engine(name: str, experiment=None) -> str:
    """``name`` if it is an engine that exists, can be loaded and (given
    ``experiment``) runs that experiment; else a ``ValueError`` saying why."""
    if name not in ENGINES:
        raise ValueError(f"unknown engine {name!r}; valid engines: {', '.join(ENGINES)}")
    if experiment is not None and name not in experiment.engines:
        raise ValueError(f"scenario {experiment.name!r} runs on the "
                         f"{' or '.join(experiment.engines)} engine only, not on {name!r}")
    if name == "lammps":
        from ..lammps_library import lammps_available

        ok, why = lammps_available()
        if not ok:
            raise ValueError(f"{why}; the numba engine needs no extra")
    return name


def use_engine(name: str) -> None:
    """Make :func:`hertz_simulation` create ``name``'s engine (this process)."""
    _CURRENT["engine"] = check_engine(name)


def current_engine() -> str:
    return _CURRENT["engine"]


def hertz_simulation(*args, **kwargs):
    """The Hertz simulation of the current engine, created with these
    arguments (those of :class:`~physics.hertz.HertzSimulation`)."""
    if _CURRENT["engine"] == "lammps":
        from ..lammps_engine import LammpsHertzSimulation

        return LammpsHertzSimulation(*args, **kwargs)
    from ..hertz import HertzSimulation

    return HertzSimulation(*args, **kwargs)
