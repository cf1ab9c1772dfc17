"""The papers' experiments as named, configurable scenarios.

Command line: ``ice-scenarios`` (or ``python -m physics.scenarios``); see
:mod:`physics.scenarios.cli`. From Python::

    from physics.scenarios import run_scenario
    res = run_scenario("herman2013-convergence", quick=True, out="runs/conv")
    res.dataset        # the NetCDF file (xarray), res.figures, res.summary

Layout: ``configs/*.yaml`` the scenario files (parameters, ranges, the
``--quick`` form); ``config.py`` their parsing and checks; ``experiment.py``
the interface and registry of experiments, and how to add one; ``herman2013.py``,
``herman2011.py``, ``godlovitch.py``, ``ship_transit.py``, ``ship_resistance.py``
the experiments; ``recorder.py`` time series, snapshots and checkpoints; ``checkpoint.py`` the checkpoint file
format (NumPy arrays and YAML, no pickle); ``jobs.py`` one simulation of a
run; ``runner.py`` ensembles, run directories,
NetCDF; ``plots.py`` shared figure helpers; ``cli.py`` the command line.

Needs the ``plots`` extra (matplotlib, xarray, h5netcdf, PyYAML).
"""
from .config import Param, ScenarioConfig, bundled_configs, load_config
from .experiment import Experiment, experiments, get_experiment, register
from .recorder import Recorder
from .runner import RunResult, find_config, plot_run, resume_run, run_scenario

__all__ = ["Param", "ScenarioConfig", "bundled_configs", "load_config", "Experiment",
           "experiments", "get_experiment", "register", "Recorder", "RunResult", "find_config",
           "plot_run", "resume_run", "run_scenario"]
