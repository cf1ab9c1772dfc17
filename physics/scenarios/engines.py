"""Which engine runs the Hertz scenarios: our Numba engine or LAMMPS.

``ice-scenarios run NAME --engine lammps`` runs the Herman (2013)
scenarios on :class:`~physics.lammps_engine.LammpsHertzSimulation` instead
of :class:`~physics.hertz.HertzSimulation`; with ``--mpi N`` each run goes
to ``mpiexec -n N`` (:mod:`physics.scenarios.lammps_job`). The experiments
build their simulation with :func:`hertz_simulation`, naming the engine
of the run, which the job gives the experiment
(:func:`physics.scenarios.experiment.get_experiment`); an experiment lists
the engines it supports in its ``engines`` attribute.
"""
from __future__ import annotations

ENGINES = ("numba", "lammps")


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


def hertz_simulation(engine: str, *args, **kwargs):
    """The Hertz simulation of ``engine`` ("numba" or "lammps"), created
    with the other arguments (those of :class:`~physics.hertz.HertzSimulation`)."""
    if engine == "lammps":
        from ..lammps_engine import LammpsHertzSimulation

        return LammpsHertzSimulation(*args, **kwargs)
    from ..hertz import HertzSimulation

    return HertzSimulation(*args, **kwargs)
