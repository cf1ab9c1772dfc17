"""Benchmarks of the engines, the observables, the ITD models and the
environments, apart from the library.

This package comes with a source checkout and is not installed with
seaice-gym: run its suites from the checkout's root (``make bench``,
``python -m benchmarks.bench_<suite>``, or ``seaice bench <suite>``, which
also finds the checkout named by ``SEAICE_GYM_SOURCE``).

One module per suite, ``bench_<suite>.py`` (:func:`suite_module`; the
prefix keeps a suite's module apart from the library module it times, such
as :mod:`physics.hertz`), each with a ``main(argv)`` and a ``python -m``
entry point (``seaice bench <suite>`` runs the same), all sharing
:mod:`benchmarks.harness`. The suite's name, not its module's, is what
``seaice bench`` takes and what its records are keyed by:

===================  ==============================================================
suite                what is timed
===================  ==============================================================
``hertz``            floe-steps/s of the Hertz engine at Ā = 0.7 and jammed, on
                     the serial and parallel kernels (:mod:`benchmarks.bench_hertz`)
``hertz_phases``     each phase of a Hertz step on its own
                     (:mod:`benchmarks.bench_hertz_phases`)
``harddisk``         collisions/s of the hard-disc engine (:mod:`benchmarks.bench_harddisk`)
``observables``      clusters, g_ffd, g_rdf, fabric and stress on 10⁵ floes
                     (:mod:`benchmarks.bench_observables`)
``itd``              the ice-thickness-distribution models (:mod:`benchmarks.bench_itd`)
``environments``     sustained steps/s of every environment
                     (:mod:`benchmarks.bench_environments`)
``vector``           env steps/s of the native vector environments against the
                     single environment, SyncVectorEnv and SubprocVecEnv, and
                     PPO training steps/s with each (:mod:`benchmarks.bench_vector`)
``ship``             floe-steps/s with and without a ship among the floes, and
                     the ship's share of a step (:mod:`benchmarks.bench_ship`)
``resting``          ship transits with and without skipping the floes at rest,
                     and env steps/s of a long channel (:mod:`benchmarks.bench_resting`)
``free_drift``       ShipNavigation-v1 episodes with the free-drift step against
                     the exact one: paired statistics, route choice under each,
                     env steps/s (:mod:`benchmarks.bench_free_drift`)
``sensors``          one call of the ship's lidar, swath sensor and image, and
                     their share of a step (:mod:`benchmarks.bench_sensors`)
``scaling``          speed-up against Numba threads of the Hertz step, the native
                     vector environments and PPO, beside a memory-bound ceiling
                     loop (:mod:`benchmarks.bench_scaling`)
``where_time_goes``  where the time of a ShipNavigation-v1 step and of PPO on it
                     goes: a late engine substep in parts, the episode, a
                     profile of training (:mod:`benchmarks.bench_where_time_goes`)
``compare``          this tree against another revision, side by side
                     (:mod:`benchmarks.bench_compare`)
``lammps_scaling``   the LAMMPS engine on MPI ranks against ours on threads at
                     N = 200000, its strong and weak scaling, and a projection
                     to 10⁶ floes on a cluster (:mod:`benchmarks.bench_lammps_scaling`)
===================  ==============================================================

Every suite writes one JSON record to ``runs/benchmarks/<suite>.json`` of
the checkout, whatever the working directory
(:func:`benchmarks.harness.write_record`); with ``--docs`` it writes the
record the documentation shows and renders
(:func:`benchmarks.harness.render_markdown`), ``docs/benchmarks/<suite>.json``,
as ``make records`` does for every suite. ``python -m benchmarks.headline``
puts the headline figures of the documented records into the README.
Every suite takes ``--quick``, a run small enough for the tests.

This package imports neither :mod:`physics` nor :mod:`iceenvs` on import:
:mod:`benchmarks.bench_compare` runs the same workloads on another revision's
packages in fresh processes.
"""
from __future__ import annotations

import importlib

#: the suites, in the order the documentation shows them
SUITES = ("hertz", "hertz_phases", "harddisk", "observables", "itd", "environments", "vector",
          "ship", "resting", "free_drift", "sensors", "scaling", "where_time_goes", "compare",
          "lammps_scaling")

__all__ = ["SUITES", "suite_module", "main"]


def suite_module(suite: str) -> str:
    """The module of ``suite``: ``benchmarks.bench_<suite>``."""
    return f"{__name__}.bench_{suite}"


def main(suite: str, argv: list[str] | None = None) -> int:
    """Run ``suite`` (one of :data:`SUITES`) with the command-line arguments
    ``argv``; returns its exit status.

    Raises
    ------
    TypeError
        If ``suite`` is not a string.
    ValueError
        If ``suite`` is not one of :data:`SUITES`.
    """
    if not isinstance(suite, str):
        raise TypeError(f"suite must be a string, got {type(suite).__name__}")
    if suite not in SUITES:
        raise ValueError(f"unknown benchmark suite {suite!r}; known: {', '.join(SUITES)}")
    return importlib.import_module(suite_module(suite)).main(argv)
