"""The Hertzian soft-contact engine of Herman (2013): :class:`HertzSimulation`.

Floes are discs moving under the forcing of :mod:`physics.forcing` and the
Hertz–Mindlin contacts of :mod:`physics.contact`, integrated with
velocity-Verlet (:mod:`physics.hertz_kernels`) over Verlet lists with a skin
(:mod:`physics.neighbors`), in a box of :mod:`physics.domain`.

It keeps the engine contract of :mod:`physics.engine`.

Example
-------
>>> from physics import make_floe_field, HertzSimulation, ContactParams, Forcing, HERMAN2013
>>> field, box = make_floe_field(500, concentration=0.7, alpha=1.8, mean_diameter=8.0, seed=1)
>>> sim = HertzSimulation(field, box, HERMAN2013.contact, Forcing(HERMAN2013.forcing), dt=0.002)
>>> sim.advance(10.0)                       # model seconds
>>> forces, torques = sim.contact_forces()
"""
from __future__ import annotations

import dataclasses
import math
import os
import weakref
from typing import NamedTuple
from contextlib import contextmanager

import numba
import numpy as np

from . import hertz_kernels as K
from . import hull_contact as HC
from .input_checks import check_range
from .contact import ContactLaw, contact_time, hertz_stiffness
from .domain import Box
from .engine import FailureReason, FloeProperties, SimulationError, engine_from_preset
from .engine import check_time_step, checked_hertz_arguments, neighbour_cut, positions_in_box
from .engine import checked_motion as _checked_motion
from .engine import snapshot as _snapshot
from .floes import FloeField
from .forcing import Forcing
from .hertz_kernels import HertzStatus
from .hertz_batch import run_many
from .hertz_free_drift import DEFAULT_WINDOW, TALLY
from .hertz_step import run_every_floe_parallel, run_one
from .neighbors import choose_cell_size, radius_rank
from .observables import Contacts, Fabric, LocalIce, Stress, fabric, stress
from .params import ContactParams, PaperPreset
from .progress import steps_with_bar
from .ship import Ship, ShipLoads, ShipState

__all__ = ["HertzSimulation", "Contacts", "minimum_contact_time", "usable_cores"]

#: the smallest field that runs the parallel step by default
PARALLEL_FROM = 5000


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity where the system
    tells it, else the machine's count)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:          # not on Linux
        return os.cpu_count() or 1


@contextmanager
def threads_within_cores(active: bool = True):
    """Run the block on at most :func:`usable_cores` of Numba's threads.

    More threads than cores (a pool sized for another machine, or
    ``NUMBA_NUM_THREADS`` set high on a shared host) only add waiting: at
    the end of each parallel region every thread waits for the slowest, and
    a thread that has no core of its own is the slowest by a whole time
    slice of the system's scheduler. The results do not change, since the
    parallel step's chunks do not depend on the threads
    (:func:`physics.hertz_kernels.chunk_count`)."""
    threads = numba.get_num_threads() if active else 0
    cores = usable_cores() if active else 0
    if threads <= cores:
        yield
        return
    numba.set_num_threads(cores)
    try:
        yield
    finally:
        numba.set_num_threads(threads)


def minimum_contact_time(radius, thickness, density, contact: ContactParams, speed: float,
                         walls: bool = False) -> float:
    """Shortest undamped Hertz contact time at impact speed ``speed`` [s]:
    t_c = 3.2181 (m*/k)^{2/5} v^{−1/5}, over each floe hitting its equal
    (m* = m/2, R* = r/2; the smallest floes collide fastest) and, with
    ``walls``, each floe hitting a rigid wall (m* = m, R* = r, stiffer E*)."""
    r = np.asarray(radius, dtype=float)
    m = density * np.asarray(thickness, dtype=float) * math.pi * r ** 2
    t = contact_time(0.5 * m, hertz_stiffness(contact.effective_modulus, 0.5 * r), speed)
    if walls:
        t = np.minimum(t, contact_time(m, hertz_stiffness(contact.wall_effective_modulus, r), speed))
    return float(np.min(t))


def hull_contact_time(radius, thickness, density, contact: ContactParams, speed: float) -> float:
    """Shortest undamped contact time of a floe hitting a rigid hull at
    ``speed`` [s] (m* = m, R* = r, the wall moduli;
    :mod:`physics.hull_contact`)."""
    r = np.asarray(radius, dtype=float)
    m = density * np.asarray(thickness, dtype=float) * math.pi * r ** 2
    return float(np.min(contact_time(m, hertz_stiffness(contact.wall_effective_modulus, r),
                                     speed)))


def ship_contact_time(field: FloeField, box: Box, contact: ContactParams, impact_speed: float,
                      ship_speed: float | None = None) -> tuple[float, str]:
    """The shortest contact time [s] the time step of ``field`` in ``box``
    must resolve, and which contacts set it (words for a message): the
    floes hitting each other (and the walls) at ``impact_speed`` [m/s] and,
    where a ship sails at ``ship_speed`` [m/s], a floe hitting its hull at
    the larger of ``impact_speed`` and the ship's speed."""
    t_c = minimum_contact_time(field.radii, field.thickness, field.density, contact, impact_speed,
                               walls=not all(box.periodic))
    what = f"the smallest floes at impact speed {impact_speed:g} m/s"
    if ship_speed is not None:
        speed = max(impact_speed, abs(ship_speed))
        t_hull = hull_contact_time(field.radii, field.thickness, field.density, contact, speed)
        if t_hull < t_c:
            t_c = t_hull
            what = f"the smallest floes hitting the hull at {speed:g} m/s"
    return t_c, what


def ship_time_step(field: FloeField, box: Box, contact: ContactParams, ship_speed: float,
                   drift: float, preset_dt: float, stiffness_scale: float) -> tuple[float, float]:
    """(impact speed [m/s], time step [s]) of a ship sailing at up to
    ``ship_speed`` [m/s] into ``field``, whose floes drift at up to
    ``drift`` [m/s]. The impact speed is (1 + e) ``ship_speed`` + 2
    ``drift`` (e the restitution: a floe the hull knocks ahead leaves at up
    to (1 + e) times its speed, and two drifting floes meet at up to twice
    their drift); the time step is the preset's ``preset_dt`` for the
    contact law softened by ``stiffness_scale`` (× stiffness_scale^(−2/5),
    as :func:`hertz_time_step`), never above a tenth of the shortest contact
    time at that impact speed, of the hull's contacts included
    (:func:`ship_contact_time`)."""
    impact = (1.0 + contact.restitution) * ship_speed + 2.0 * drift
    t_c, _ = ship_contact_time(field, box, contact, impact, ship_speed)
    return impact, min(preset_dt * stiffness_scale ** -0.4, 0.1 * t_c)


def scaled_contact(contact: ContactParams, stiffness_scale: float) -> ContactParams:
    """The contact law with Young's modulus multiplied by ``stiffness_scale``
    in (0, 1] (a softer contact allows a longer time step: Δt ∝ E^(−2/5))."""
    check_range("stiffness_scale", stiffness_scale, 0.0, 1.0, low_open=True)
    return dataclasses.replace(contact, elastic_modulus=contact.elastic_modulus * stiffness_scale)


def hertz_time_step(field: FloeField, box: Box, contact: ContactParams, impact_speed: float,
                    preset_dt: float, stiffness_scale: float) -> float:
    """Time step for a contact law softened by ``stiffness_scale``: the
    preset's Δt × stiffness_scale^(−2/5) (the contact time scales as
    E^(−2/5)), and never above a tenth of the shortest contact time at
    ``impact_speed`` [m/s]."""
    t_c = minimum_contact_time(field.radii, field.thickness, field.density, contact, impact_speed,
                               walls=not all(box.periodic))
    return min(preset_dt * stiffness_scale ** -0.4, 0.1 * t_c)


class KernelView(NamedTuple):
    """The compiled kernels' bundles of a simulation's live state
    (:meth:`HertzSimulation.kernel_view`)."""

    floes: K.Floes
    law: ContactLaw
    wall_law: ContactLaw
    drive: K.Drive
    verlet: K.VerletList


class HertzSimulation(FloeProperties):
    """Soft-contact discrete-element simulation of floes (Herman 2013).

    It keeps the engine contract (:class:`~physics.engine.FloeEngine`):
    the input field is copied, ``positions``, ``velocities`` and
    ``angular_velocities`` are read-only snapshots (assign a whole array to
    ``velocities`` or ``angular_velocities`` to change them), ``radii``,
    ``masses`` and ``frozen`` are read-only views
    (:class:`~physics.engine.FloeProperties`), and a breakdown of the
    physics during :meth:`advance` raises
    :class:`~physics.engine.SimulationError`.

    Parameters
    ----------
    field : FloeField
        Initial state; copied, never modified.
    box : Box
        ``PeriodicBox``, ``DeformingPeriodicBox``, ``ChannelBox`` or
        ``WalledBox``. The simulation owns and updates it (a deforming box
        shrinks or grows).
    contact : ContactParams, optional
        Contact law (default: Herman 2013 values, e = 0.5).
    forcing : Forcing or None
        Drag, wind, current and Coriolis; ``None`` means no external forces.
    dt : float
        Time step [s]; must be below a tenth of the shortest contact time at
        ``impact_speed``.
    impact_speed : float
        Largest relative speed expected at impact [m/s], used only for the
        time-step check (default 0.1 m/s: relative speeds of neighbouring
        floes in the wind- and convergence-driven set-ups of Herman (2013),
        whose Δt = 0.002 s it admits; raise it for violent impacts).
    skin : float, optional
        Verlet-list skin [m] (default 0.1 × the mean radius).
    parallel : bool, optional
        Use the multi-threaded kernels (default: when N ≥ 5000 and Numba has
        more than one thread). Both paths give the same result to rounding;
        the parallel one gives the same state bit for bit on any number of
        threads (its chunks, :attr:`n_chunks`, depend on N alone). It runs
        on at most as many threads as the process has cores.
    allow_overlap : bool
        Accept initial overlaps above 1 % of the smaller radius (e.g. when
        restoring a saved, compressed state).
    ship : Ship, optional
        A ship among the floes (:mod:`physics.ship`); it must not overlap a
        floe at the start. Then ``sim.ship`` is its
        :class:`~physics.ship.ShipState` and :meth:`ship_loads` gives the
        statistics of its ice loads. The time-step check then also covers a
        floe hitting the hull at the ship's speed.
    skip_resting : bool
        Skip the floes at rest (default False): a floe with zero velocity,
        angular velocity and force that touches nothing and has no wind or
        current acting on it is not integrated (velocity Verlet would leave
        it exactly where it is) until a contact with a moving floe or the
        hull wakes it (:mod:`physics.hertz_resting`). The set is found
        again at each :meth:`step`. The result is that of the full step (to
        rounding in the list's expiry test), at the cost of the moving
        floes: worth it when most floes lie still (a ship in calm ice). It
        runs the serial step only: with ``parallel=True`` it is a
        ``ValueError``, and ``parallel=None`` then means serial.
    free_drift : bool
        Let the floes that can touch nothing drift in closed form (default
        False): the run is cut into windows of :attr:`free_window` steps,
        and a floe that is shown to stay clear of every floe, wall and the
        hull through a window follows its forcing alone, computed for the
        whole window at once, while the others take the full step
        (:mod:`physics.hertz_free_drift`). Bounds on the motion of the
        others are checked at every step, and a window ends early where
        one fails. The result is that of the full step to rounding, at the
        cost of the floes that are close to something: worth it where most
        floes drift apart (a ship in loose ice). Serial only, as
        ``skip_resting``, which it includes; a rigid box only.

    Attributes
    ----------
    time : float — model time [s]
    positions, velocities, angular_velocities : read-only snapshots of the current state
    force, torque : read-only snapshots of the total force and torque of the last step
    n_steps, n_rebuilds : counters
    n_awake : floes integrated at the end of the last :meth:`step` (all of
        them unless ``skip_resting``; with ``free_drift``, the floes engaged
        in the last window)
    free_window : steps of a free-drift window (default 64)
    n_chunks : chunks of the parallel step (a function of N alone; the
        serial step ignores it)

    Examples
    --------
    A simulation set up from a paper's parameters (:meth:`from_preset`):
    its floe field, contact law, time step and forcing.

    >>> from physics import HERMAN2013, HertzSimulation
    >>> sim = HertzSimulation.from_preset(HERMAN2013, 300, 0.6, seed=1, velocity_std=0.01)
    >>> sim.dt, sim.forcing.wind.tolist()
    (0.002, [10.0, 0.0])
    >>> sim.advance(1.0)
    >>> sim.n_steps, sim.positions.shape
    (500, (300, 2))
    >>> sim.velocities = 0.5 * sim.velocities       # assign; the snapshot is read-only
    """

    def __init__(self, field: FloeField, box: Box, contact: ContactParams | None = None,
                 forcing: Forcing | None = None, dt: float = 0.002, *,
                 impact_speed: float = 0.1, skin: float | None = None,
                 parallel: bool | None = None, allow_overlap: bool = False,
                 ship: Ship | None = None, skip_resting: bool = False,
                 free_drift: bool = False):
        contact = checked_hertz_arguments(field, box, contact, forcing, dt, impact_speed)
        if ship is not None and not isinstance(ship, Ship):
            raise TypeError(f"ship must be a physics.ship.Ship or None, got {type(ship).__name__}")
        for name, value in (("skip_resting", skip_resting), ("free_drift", free_drift)):
            if not isinstance(value, (bool, np.bool_)):
                raise TypeError(f"{name} must be True or False, got {value!r}")
            if value and parallel:
                raise ValueError(f"{name}=True runs the serial step only: pass parallel=False "
                                 f"or None, not parallel=True")
        if skip_resting and free_drift:
            raise ValueError("skip_resting and free_drift are two serial steps: choose one "
                             "(free_drift lets resting floes lie as well)")
        if free_drift and box.kernel_box(0.0).deforming:
            raise ValueError("free_drift=True needs a rigid box: a deforming box moves every "
                             "floe at every step")
        self.skip_resting = bool(skip_resting)
        self.free_drift = bool(free_drift)
        #: steps of a free-drift window (:mod:`physics.hertz_free_drift`)
        self.free_window = DEFAULT_WINDOW
        #: the free-drift step's check mode: the free floes stepped one step at a
        #: time with the full step's arithmetic instead of in closed form (no
        #: faster than the full step; its result bit for bit where the windows
        #: are right)
        self.free_iterate = False
        #: what the free-drift step counted (:data:`physics.hertz_free_drift.TALLY`)
        self.free_tally = np.zeros(len(TALLY), dtype=np.int64)
        self.field = field.copy()
        self.box = box
        self.contact = contact
        self.forcing = forcing
        self.dt = float(dt)
        f = self.field
        self._radius = f.radii.copy()        # the kernels' own, as every array below
        n = f.n

        # time step against the shortest contact time
        t_c, what = ship_contact_time(f, box, contact, impact_speed,
                                      None if ship is None else ship.speed)
        check_time_step(self.dt, t_c, what)
        self.min_contact_time = t_c

        # neighbour-list sizing
        self.skin, self.max_cut = neighbour_cut(f.radii, box, skin)
        if parallel is None:
            parallel = (n >= PARALLEL_FROM and numba.get_num_threads() > 1
                        and not (skip_resting or free_drift))
        self.parallel = bool(parallel)
        #: chunks of the parallel step (:func:`physics.hertz_kernels.chunk_count`):
        #: a function of N alone, so that the new state does not depend on
        #: the number of threads
        self.n_chunks = int(K.chunk_count(n))

        # positions inside the box; walls must not cut floes deeply
        self._pos = positions_in_box(f, box, allow_overlap)

        # state arrays, shared with the kernels through the bundles below
        self._vel = f.velocities.copy()
        self._omega = f.angular_velocities.copy()
        self._mass = f.masses
        self._frozen = f.frozen.copy()
        mobile = ~self._frozen
        self._inv_mass = np.where(mobile, 1.0 / self._mass, 0.0)
        self._inv_inertia = np.where(mobile, 1.0 / f.inertia, 0.0)
        self._rank = radius_rank(f.radii)
        self.cell_size = choose_cell_size(f.radii, box.lx, box.ly, self.skin)
        box.bind(f.total_area)
        self.max_concentration = getattr(box, "max_concentration", 1.0)
        self._force = np.zeros((n, 2))
        self._torque = np.zeros(n)
        self._floes = K.Floes(self._pos, self._vel, self._omega, self._radius, self._inv_mass,
                              self._inv_inertia, self._rank, self._force, self._torque,
                              np.zeros((n, 4, 2)))
        self._law = ContactLaw.from_params(contact)
        self._wall_law = ContactLaw.from_params(contact, wall=True)
        self._set_drag()
        self.time = 0.0
        self.n_steps = 0
        self.n_rebuilds = 0
        self.n_awake = n
        self._build_list()
        self._no_ship = HC.inactive_bundle(self._wall_law)
        self.ship = None if ship is None else self._place_ship(ship)
        self._evaluate_forces(self._drive(), self._force, self._torque)

    @classmethod
    def from_preset(cls, preset: PaperPreset, n: int | None = None,
                    concentration: float | None = None, *, seed: int | None = 0,
                    forcing: bool | Forcing | None = True, **kwargs) -> HertzSimulation:
        """A simulation of a paper preset's floes, contact law and time step.

        The floes come from ``preset.floe_field(n, concentration, seed=seed)``
        (:meth:`~physics.params.PaperPreset.floe_field`), the contact law
        from ``preset.contact`` and the time step from ``preset.time_step``.

        Parameters
        ----------
        preset : PaperPreset
            E.g. :data:`~physics.params.HERMAN2013`.
        n, concentration : optional
            Number of floes and ice concentration (default: the preset's).
        seed : int or None
            Seed of the floe field.
        forcing : bool, Forcing or None
            True: the preset's wind, current, drag and Coriolis
            (:meth:`~physics.params.PaperPreset.make_forcing`); False or
            None: no external forces; a :class:`~physics.forcing.Forcing`:
            that one.
        **kwargs
            Parameters of the constructor (``contact``, ``dt``,
            ``impact_speed``, ``skin``, ``parallel``, ``allow_overlap``;
            ``contact`` and ``dt`` replace the preset's); any other keyword
            goes to :meth:`~physics.params.PaperPreset.floe_field` (e.g.
            ``velocity_std``, ``repeat``).

        Raises
        ------
        TypeError
            ``preset`` not a :class:`~physics.params.PaperPreset`, or an
            unknown keyword.
        ValueError
            A bad value (see the constructor).
        """
        def defaults(p):
            return {"contact": p.contact, "dt": p.time_step}
        return engine_from_preset(cls, preset, n, concentration, seed, forcing, defaults, kwargs)

    # -- set-up helpers ------------------------------------------------------
    def _place_ship(self, ship: Ship) -> ShipState:
        box = self.box
        state = ShipState(ship, self.n_floes, self._wall_law)
        # the hull's list skin: a quarter of the beam, at least the floes' skin
        state.set_skin(max(self.skin, 0.25 * ship.hull.beam))
        reach = state.reach + float(self._radius.max()) + state.skin
        for length, per, axis in ((box.lx, box.periodic[0], "x"), (box.ly, box.periodic[1], "y")):
            if per and 2.0 * reach >= length:
                raise ValueError(
                    f"the box is too small along {axis} ({length:.4g} m) for the ship: periodic "
                    f"sides must exceed 2 (hull reach + r_max + hull skin) = {2 * reach:.4g} m")
        if ship.current_drag and self.forcing is not None:
            state.set_current(self.forcing.current)
        bundle = state.bundle(0)
        b = box.kernel_box(self.time)
        HC.build_hull_list(bundle, self._pos, self._radius, b.lengths[0], b.lengths[1],
                           b.periodic_x, b.periodic_y)
        idx, data = HC.hull_contact_list(bundle, self._floes, b)
        if idx.size:
            raise ValueError(
                f"the ship overlaps {idx.size} floe(s) at the start (floe {int(idx[0])}, "
                f"overlap {data[0, 8]:.3g} m); start it in open water")
        return state

    def _set_drag(self):
        f = self.field
        n = f.n
        self._drag = np.zeros((n, 4))
        if self.forcing is not None:
            k = self.forcing.coefficients(f.radii, f.thickness, f.masses)
            mobile = ~f.frozen
            for col, a in enumerate((k.wind, k.water, k.rotation, k.coriolis_mass)):
                self._drag[:, col] = np.where(mobile, a, 0.0)

    def _drive(self) -> K.Drive:
        """The forcing bundle of the kernels, with the wind and current now
        (kept while the drag coefficients, the wind and the current stay)."""
        if self.forcing is None:
            key = (self._drag, 0.0, 0.0, 0.0, 0.0)
        else:
            (ax, ay), (wx, wy) = self.forcing.wind, self.forcing.current
            key = (self._drag, float(ax), float(ay), float(wx), float(wy))
        kept = self._kept_drive
        if kept is None or kept[0] is not key[0] or kept[1:5] != key[1:]:
            self._kept_drive = kept = key + (K.make_drive(self._drag, key[1:3], key[3:5]),)
        return kept[5]

    _kept_drive = None

    def _build_list(self):
        b = self.box
        n = self.n_floes
        empty = K.VerletList(np.zeros(n + 1, dtype=np.int64), np.zeros(0, dtype=np.int64),
                             np.zeros((0, 2)), self._pos.copy(), np.array([b.lx, b.ly]),
                             np.zeros(2), self.skin, self.cell_size, self.max_cut,
                             np.full(n, self.skin), self.skin, np.zeros(0, dtype=np.int64),
                             np.zeros((0, 2)), np.zeros(0))
        self._verlet = K.rebuild(self._floes, empty, b.lx, b.ly, b.periodic[0], b.periodic[1],
                                 self.parallel)

    def _evaluate_forces(self, drive: K.Drive, force: np.ndarray, torque: np.ndarray):
        """Forces at the current positions and velocities into ``force``,
        ``torque``, leaving the Mindlin history unchanged (as LAMMPS does at
        ``run 0``)."""
        floes = self._floes._replace(wall_hist=self._floes.wall_hist.copy())
        verlet = self._verlet._replace(hist=self._verlet.hist.copy())
        K.forces_serial(floes, self._law, self._wall_law, drive, self.box.kernel_box(self.time),
                        verlet, 0.0, force, torque)

    # -- the Verlet list, which may live in a batch's typed list -------------
    #: (typed list, index) where the simulation's current Verlet list lies
    #: (:class:`KernelLists`), or None
    _verlet_slot = None
    #: that slot, while the list there is newer than the one read here
    _verlet_home = None

    @property
    def _verlet(self) -> K.VerletList:
        """The Verlet list (read from a batch's typed list, the first time
        after a compiled batch run rebuilt it there)."""
        home = self._verlet_home
        if home is not None:
            self._verlet_home = None
            self._verlet_list = home[0][home[1]]
        return self._verlet_list

    @_verlet.setter
    def _verlet(self, value: K.VerletList) -> None:
        self._verlet_list = value
        self._verlet_slot = self._verlet_home = None

    def __getstate__(self) -> dict:
        """The state a copy (``copy.deepcopy``, pickle) takes: the current
        Verlet list, without the batch's typed list it may lie in (the copy
        is in no batch)."""
        state = self.__dict__.copy()
        state["_verlet_list"] = self._verlet
        state.pop("_verlet_slot", None)
        state.pop("_verlet_home", None)
        return state

    # -- running -------------------------------------------------------------
    @property
    def _step_mode(self) -> int:
        """The serial step's form (:data:`physics.hertz_step.MODES`): 0 full,
        1 skipping the resting floes, 2 free drift, 3 free drift stepped
        (:attr:`free_iterate`)."""
        if self.free_drift:
            return 3 if self.free_iterate else 2
        return 1 if self.skip_resting else 0

    def step(self, n: int = 1) -> None:
        """Advance by ``n`` time steps.

        Raises
        ------
        SimulationError
            If the state became non-finite, the integration unstable, or a
            deforming box reached its concentration limit.
        """
        n = self._steps_to_run(n)
        if n == 0:
            return
        left = n
        while left > 0:
            args = self._kernel_arguments(left)
            if self.parallel:
                with threads_within_cores(True):
                    done, status, nreb, self._verlet = run_every_floe_parallel(
                        args[0], self.dt, self.time, args[1:], self._verlet, self.n_chunks)
            else:
                done, status, nreb, self._verlet, awake = run_one(
                    self._step_mode, args[0], self.dt, self.time, args[1:], self._verlet,
                    self.free_window, self.free_tally)
                if awake >= 0:
                    self.n_awake = awake
            left = self._after_run(done, status, nreb, left)
        self._check_status(HertzStatus(status))

    _SHIP_CHUNK = 50_000

    def _steps_to_run(self, n) -> int:
        """``n`` checked, and the forcing and the ship made ready for a run."""
        check_range("n", n, 0, None)
        n = int(n)
        if n == 0:
            return 0
        if self.forcing is not None:
            self._set_drag_if_changed()
        if self.ship is not None:
            self.ship.set_current(self.forcing.current if self.forcing is not None else (0, 0))
            self.ship.refresh()
        return n

    def kernel_view(self) -> KernelView:
        """The bundles the compiled kernels take, over the simulation's own
        arrays (not copies), for benchmarks and tests that call one kernel
        alone (``benchmarks/bench_hertz_phases.py``): a kernel that writes
        into them changes the simulation."""
        return KernelView(self._floes, self._law, self._wall_law, self._drive(), self._verlet)

    def _kernel_arguments(self, left: int) -> tuple:
        """(steps of the next kernel run, floes, law, wall law, drive, box,
        ship bundle) for a run with ``left`` steps to go. With a ship the run
        is cut into pieces that bound the record buffer."""
        box = self.box.kernel_box(self.time)
        self._kernel_box = box
        k = left if self.ship is None else min(left, self._SHIP_CHUNK)
        ship = self._no_ship if self.ship is None else self.ship.bundle(k)
        return k, self._floes, self._law, self._wall_law, self._drive(), box, ship

    def _after_run(self, done: int, status: int, n_rebuilds: int, left: int) -> int:
        """Count a kernel run of ``done`` steps that ended with ``status``;
        the steps still to go (0 when the run must stop: done, or a failure
        that :meth:`_check_status` reports). The ship's collision log is
        emptied whenever it fills."""
        self.time += done * self.dt
        self.n_steps += done
        self.n_rebuilds += n_rebuilds
        self.box.update_from_kernel(self._kernel_box)
        left -= done
        if self.ship is None:
            return 0 if status != HertzStatus.OK else left
        self.ship.drain()
        return left if status in (HertzStatus.OK, HertzStatus.SHIP_LOG_FULL) else 0

    def _check_status(self, status: HertzStatus, finite: bool | None = None):
        """Raise the :class:`SimulationError` of a run that ended with
        ``status``; ``finite``: whether the compiled run found the floes'
        and the ship's state finite (None: look here)."""
        if status is HertzStatus.CONCENTRATION_LIMIT:
            raise SimulationError(
                f"the deforming box reached its concentration limit at t = {self.time:.6g} s "
                f"(A = {self.concentration:.4f})", FailureReason.CONCENTRATION_LIMIT, self.time)
        if status is HertzStatus.UNSTABLE:
            raise SimulationError(
                f"the integration became unstable at t = {self.time:.6g} s (step {self.n_steps}): "
                f"a floe moved more than half the Verlet skin ({self.skin:.3g} m) in one step. "
                f"The time step may be too large for the impact speeds, the ice compressed far "
                f"beyond jamming, or (for fast floes and long steps) the skin too small",
                FailureReason.UNSTABLE, self.time)
        if finite is None:
            finite = (np.all(np.isfinite(self._pos)) and np.all(np.isfinite(self._vel))
                      and (self.ship is None or np.all(np.isfinite(self.ship.kernel_bundle.state))))
        if status is HertzStatus.NON_FINITE or not finite:
            raise SimulationError(
                f"non-finite floe state at t = {self.time:.6g} s (step {self.n_steps}); "
                f"the time step is probably too large for the impact speeds",
                FailureReason.NON_FINITE, self.time)

    def _set_drag_if_changed(self):
        # the coefficients depend only on the floes and ForcingParams; the
        # coriolis parameter may be changed by the user between calls
        key = (id(self.forcing), self.forcing.coriolis, id(self.forcing.params))
        if getattr(self, "_drag_key", None) != key:
            self._set_drag()
            self._drag_key = key

    def advance(self, duration: float, *, progress: bool = False, chunk: float | None = None) -> None:
        """Advance by ``duration`` model seconds (rounded to whole steps).

        ``progress=True`` shows a progress bar (the run is done in chunks of
        ``chunk`` model seconds, default 1 % of the duration). Raises
        :class:`~physics.engine.SimulationError` as :meth:`step` does.
        """
        check_range("duration", duration, 0.0, None)
        n = int(round(duration / self.dt))
        if not progress:
            self.step(n)
            return
        steps_with_bar(self.step, n, round((chunk or duration / 100.0) / self.dt), "Hertz")

    # -- state -----------------------------------------------------------------
    @property
    def positions(self) -> np.ndarray:
        """(N, 2) floe centres [m], wrapped into the box (a read-only snapshot)."""
        return _snapshot(self._pos)

    @property
    def velocities(self) -> np.ndarray:
        """(N, 2) floe velocities [m/s] (a read-only snapshot; assign to change them)."""
        return _snapshot(self._vel)

    @velocities.setter
    def velocities(self, value):
        self._vel[...] = _checked_motion("velocities", value, self._vel.shape, self._frozen,
                                         "velocity")

    @property
    def angular_velocities(self) -> np.ndarray:
        """(N,) angular velocities [1/s] (a read-only snapshot; assign to change them)."""
        return _snapshot(self._omega)

    @angular_velocities.setter
    def angular_velocities(self, value):
        self._omega[...] = _checked_motion("angular_velocities", value, self._omega.shape,
                                           self._frozen, "angular velocity")

    # -- observation ---------------------------------------------------------
    @property
    def concentration(self) -> float:
        """Ice concentration A = F / S [-]."""
        return self.field.total_area / self.box.area

    @property
    def n_floes(self) -> int:
        return self.field.n

    @property
    def force(self) -> np.ndarray:
        """(N, 2) total force on each floe (contacts, walls, the hull and the
        forcing) of the last step, or of the initial state before the first
        [N]; a read-only snapshot."""
        return _snapshot(self._force)

    @property
    def torque(self) -> np.ndarray:
        """(N,) total torque on each floe, as :attr:`force` [N m]; a read-only snapshot."""
        return _snapshot(self._torque)

    def contact_forces(self):
        """Contact forces (N, 2) [N] and torques (N,) [N m] on every floe from
        contacts only (floes and walls), at the current positions and
        velocities, without advancing the contact history."""
        force = np.zeros((self.n_floes, 2))
        torque = np.zeros(self.n_floes)
        self._evaluate_forces(K.make_drive(np.zeros((self.n_floes, 4))), force, torque)
        if self.ship is not None:
            idx, data = self.hull_contacts()
            np.add.at(force, idx, data[:, 0:2])
            np.add.at(torque, idx, data[:, 2])
        return force, torque

    def hull_contacts(self):
        """The floes touching the hull now: (floes (K,), data (K, 9)) with
        per contact the force on the floe (x, y) [N], the torque on the floe
        and the moment on the hull [N m], the normal and tangential forces
        [N], the contact point relative to the ship's centroid (x, y; world
        frame) [m] and the overlap [m]. Empty without a ship."""
        if self.ship is None:
            return np.zeros(0, dtype=np.int64), np.zeros((0, 9))
        return HC.hull_contact_list(self.ship.kernel_bundle, self._floes,
                                    self.box.kernel_box(self.time))

    def ship_loads(self, start: float | None = None, end: float | None = None) -> ShipLoads:
        """Statistics of the ship's ice loads over the steps with
        start < t ≤ end (default: all recorded; see
        :meth:`physics.ship.ShipState.statistics`)."""
        if self.ship is None:
            raise ValueError("this simulation has no ship (pass ship= to HertzSimulation)")
        return self.ship.statistics(start, end)

    def contacts(self) -> Contacts:
        """Every touching floe pair at the current state (see :class:`Contacts`)."""
        i, j, d = K.contact_list(self._floes, self._law, self.box.kernel_box(self.time),
                                 self._verlet)
        normal = d[:, 0:2].copy()
        delta = d[:, 2].copy()
        point, arm_i, arm_j = Contacts.branches(self._pos, self._radius, i, j, normal, delta)
        return Contacts(i=i, j=j, normal=normal, overlap=delta, normal_force=d[:, 3].copy(),
                        tangential_force=d[:, 4].copy(), force=d[:, 5:7].copy(),
                        contact_point=point, branch_i=arm_i, branch_j=arm_j)

    def local_ice(self, centre, radius: float) -> LocalIce:
        """The ice within ``radius`` [m] of the point ``centre`` (x, y) [m]
        (minimum-image distances) at the current state, in one compiled pass
        over the floes and the Verlet list, without building a
        :class:`Contacts` table: the floes whose centre lies in the disc and
        the floe–floe contacts whose contact point does, with their
        Love–Weber stress over the disc's area π radius² (see
        :class:`~physics.observables.LocalIce`)."""
        try:
            cx, cy = (float(v) for v in centre)
        except (TypeError, ValueError):
            raise ValueError(f"centre must be a pair of finite numbers, got {centre!r}") from None
        if not (math.isfinite(cx) and math.isfinite(cy)):
            raise ValueError(f"centre must be a pair of finite numbers, got {centre!r}")
        check_range("radius", radius, 0.0, None, low_open=True)
        area = math.pi * float(radius) ** 2
        f, v, box = self._floes, self._verlet, self.box
        n_floes, r2, n_contacts, sxx, sxy, syx, syy = K.ice_within(
            f.pos, f.vel, f.omega, f.radius, f.inv_mass, v.start, v.nbr, v.hist, self._law,
            float(box.lx), float(box.ly), box.periodic[0], box.periodic[1], cx, cy, float(radius))
        return LocalIce(n_floes, math.pi * r2, n_contacts,
                        np.array([[-sxx / area, -sxy / area], [-syx / area, -syy / area]]), area)

    def ice_near_row(self, centre, radius: float) -> np.ndarray:
        """The row of :data:`physics.hertz_batch.ICE_NEAR` for the disc of
        ``radius`` round ``centre``: what :func:`~physics.hertz_batch.ice_near_many`
        computes for a batch, for this simulation alone."""
        f, v, box = self._floes, self._verlet, self.box
        row = np.empty(8)
        row[:7] = K.ice_within(f.pos, f.vel, f.omega, f.radius, f.inv_mass, v.start, v.nbr,
                               v.hist, self._law, float(box.lx), float(box.ly), box.periodic[0],
                               box.periodic[1], float(centre[0]), float(centre[1]), float(radius))
        row[7] = K.ice_energy(f.vel, f.omega, f.radius, f.inv_mass)
        return row

    def fabric(self) -> Fabric:
        """Contact fabric (Z_c, Z_a, f_nr, ...) of the current contacts
        (see :func:`physics.observables.fabric`)."""
        return fabric(self.contacts(), self.n_floes)

    def contact_stress(self, *, per_floe: bool = True) -> Stress:
        """Love–Weber stress of the current floe–floe contacts over the box
        area, compression positive [N/m] (see :func:`physics.observables.stress`)."""
        return stress(self.contacts(), self.box.area, n_floes=self.n_floes, per_floe=per_floe)

    def kinetic_energy(self) -> float:
        """Translational plus rotational kinetic energy of mobile floes [J]
        (the ship's is ``sim.ship.kinetic_energy``)."""
        m = self._mass
        mobile = self._inv_mass > 0
        e_t = 0.5 * np.sum(m[mobile] * np.sum(self._vel[mobile] ** 2, axis=1))
        e_r = 0.5 * np.sum(self.field.inertia[mobile] * self._omega[mobile] ** 2)
        return float(e_t + e_r)

    def momentum(self) -> np.ndarray:
        """Total linear momentum of mobile floes (2,) [kg m/s]."""
        mobile = self._inv_mass > 0
        return (self._mass[mobile, None] * self._vel[mobile]).sum(axis=0)

    def state(self) -> FloeField:
        """A copy of the current state as a FloeField."""
        f = self.field
        return FloeField(self._pos.copy(), f.radii.copy(), f.thickness.copy(), self._vel.copy(),
                         self._omega.copy(), f.density, f.frozen.copy())

    def __repr__(self):
        rest = (", skip_resting=True" if self.skip_resting
                else ", free_drift=True" if self.free_drift else "")
        return (f"HertzSimulation(n_floes={self.n_floes}, box={self.box!r}, dt={self.dt:g}, "
                f"time={self.time:.6g}, parallel={self.parallel}{rest})")


class KernelLists:
    """The typed lists that carry several simulations' kernel arguments into
    :func:`physics.hertz_batch.run_many`, kept from call to call.

    Numba types a new list from its first item, in Python: for the nested
    bundles of a simulation that costs about half a millisecond each time a
    list is made, as much as a ship environment's engine step. Replacing
    the items of a kept list costs some 10 µs each. One object per caller that
    advances the same kind of simulations again and again (a native vector
    environment) makes that saving; :func:`advance_together` makes a new
    one when given none.

    A simulation's Verlet list stays in its slot between calls: a run that
    rebuilds it leaves the new one there, and the simulation reads it only
    when it needs it (see ``HertzSimulation._verlet``); a slot is refilled
    only for another simulation, which first hands the list it held back to
    its simulation.
    """

    def __init__(self):
        self._lists: dict[int, tuple] = {}
        self._owners: dict[int, list] = {}

    def filled(self, runs: list, sims: list) -> tuple:
        """Typed lists holding ``runs`` and the Verlet lists of ``sims``:
        those of the last call with as many items, with the items replaced,
        or new ones when there are none or their item types differ."""
        from numba import typeof
        from numba.core.errors import NumbaError
        from numba.typed import List

        n = len(runs)
        kept = self._lists.get(n)
        if kept is not None:
            try:
                for k in range(n):
                    kept[0][k] = runs[k]
                    self._hold(n, k, sims[k])
                return kept
            except (NumbaError, TypeError, ValueError, AssertionError):
                pass     # items of another type (Numba fails to compile the cast): new lists
            self._release(n)
        kept = (List.empty_list(typeof(runs[0])), List.empty_list(typeof(sims[0]._verlet)))
        for run, sim in zip(runs, sims):
            kept[0].append(run)
            kept[1].append(sim._verlet)
        # reading and replacing an item compile on first use: now, not in a later step
        kept[0][0] = kept[0][0]
        kept[1][0] = kept[1][0]
        self._lists[n] = kept
        self._owners[n] = [None] * n
        for k, sim in enumerate(sims):
            self._own(n, k, sim)
        return kept

    def _holds(self, n: int, k: int, sim) -> bool:
        """Whether slot k of the lists of ``n`` items holds ``sim``'s Verlet list."""
        slot = sim._verlet_slot
        return slot is not None and slot[0] is self._lists[n][1] and slot[1] == k

    def _hold(self, n: int, k: int, sim) -> None:
        """Slot k of the lists of ``n`` items for ``sim``'s Verlet list."""
        if self._holds(n, k, sim):
            return                                  # it is there already
        self._hand_back(n, k)
        self._lists[n][1][k] = sim._verlet
        self._own(n, k, sim)

    def _own(self, n: int, k: int, sim) -> None:
        self._owners[n][k] = weakref.ref(sim)
        sim._verlet_slot = (self._lists[n][1], k)

    def _hand_back(self, n: int, k: int) -> None:
        """The simulation whose Verlet list lies in slot k takes it back."""
        ref = self._owners[n][k]
        sim = None if ref is None else ref()
        if sim is not None and self._holds(n, k, sim):
            sim._verlet = sim._verlet               # read it, and forget the slot
        self._owners[n][k] = None

    def _release(self, n: int) -> None:
        """Every simulation with a list in the lists of ``n`` items takes it back."""
        for k in range(len(self._owners.get(n, ()))):
            self._hand_back(n, k)

    def current(self, sims: list):
        """The typed lists (runs, Verlet lists) whose item k holds ``sims[k]``'s
        state now, as the last :func:`advance_together` left them, or None
        when they do not (a simulation filled in elsewhere, or one whose run
        took more than one call)."""
        n = len(sims)
        kept = self._lists.get(n)
        if kept is None:
            return None
        for k, (ref, sim) in enumerate(zip(self._owners[n], sims)):
            if ref is None or ref() is not sim or not self._holds(n, k, sim):
                return None
        return kept


def advance_together(sims, duration: float, *, lists: KernelLists | None = None) -> list:
    """Advance several independent simulations by ``duration`` model seconds
    each (rounded to whole steps of each one's Δt) in compiled calls that
    run the simulations in parallel over Numba's threads
    (:func:`physics.hertz_batch.run_many`), one simulation per thread at a
    time, handed to the threads one by one as they come free. Each
    simulation does exactly what its own :meth:`HertzSimulation.advance`
    would: the same arithmetic in the same order, so the same state.

    Parameters
    ----------
    sims : sequence of HertzSimulation
        Distinct serial simulations (``parallel=False``).
    duration : float
        Model seconds [s].
    lists : KernelLists, optional
        The typed lists to reuse (see :class:`KernelLists`); a caller that
        advances the same simulations step after step keeps one.

    Returns
    -------
    list
        Per simulation ``None``, or the :class:`~physics.engine.SimulationError`
        its :meth:`~HertzSimulation.advance` would have raised (the others
        are advanced all the same).

    Raises
    ------
    TypeError, ValueError
        A simulation that is not a serial :class:`HertzSimulation`, or one
        given twice.
    """
    sims = list(sims)
    for k, sim in enumerate(sims):
        if not isinstance(sim, HertzSimulation):
            raise TypeError(f"sims[{k}] is a {type(sim).__name__}; advance_together takes "
                            f"HertzSimulation objects")
        if sim.parallel:
            raise ValueError(f"sims[{k}] is a parallel simulation; advance_together runs the "
                             f"simulations in parallel, each serial (parallel=False)")
    if len({id(s) for s in sims}) != len(sims):
        raise ValueError("advance_together got the same simulation twice")
    check_range("duration", duration, 0.0, None)
    if len(sims) == 1:                      # one simulation: its own step, without threads
        try:
            sims[0].advance(duration)
        except SimulationError as err:
            return [err]
        return [None]
    left = [sim._steps_to_run(int(round(duration / sim.dt))) for sim in sims]
    status = [HertzStatus.OK] * len(sims)
    ok = [True] * len(sims)
    while True:
        todo = [k for k, n in enumerate(left) if n > 0]
        if not todo:
            break
        args = [sims[k]._kernel_arguments(left[k]) for k in todo]
        n_steps = np.array([a[0] for a in args], dtype=np.int64)
        runs, verlets = (lists or KernelLists()).filled([a[1:] for a in args],
                                                        [sims[k] for k in todo])
        dt = np.array([sims[k].dt for k in todo])
        time = np.array([sims[k].time for k in todo])
        mode = np.array([sims[k]._step_mode for k in todo], dtype=np.int64)
        window = np.array([sims[k].free_window for k in todo], dtype=np.int64)
        tally = np.stack([sims[k].free_tally for k in todo])
        done, stat, nreb, awake = (np.zeros(len(todo), dtype=np.int64) for _ in range(4))
        finite = np.zeros(len(todo), dtype=np.bool_)
        # one simulation at a time to whichever thread is free: a ship
        # environment's step costs twenty times as much late in an episode,
        # among the floes its ship has woken, as early on, among floes at
        # rest (`seaice bench where_time_goes`), and equal blocks of
        # simulations would leave threads waiting for the heaviest block
        with threads_within_cores(), numba.parallel_chunksize(1):
            run_many(n_steps, dt, time, mode, window, tally, runs, verlets, done, stat, nreb,
                     awake, finite)
        for m, k in enumerate(todo):
            sims[k].free_tally[:] = tally[m]
            ok[k] = bool(finite[m])
            if nreb[m]:                     # a rebuilt list, read when needed (10 µs)
                sims[k]._verlet_home = (verlets, m)
            if mode[m]:
                sims[k].n_awake = int(awake[m])
            status[k] = HertzStatus(int(stat[m]))
            left[k] = sims[k]._after_run(int(done[m]), status[k], int(nreb[m]), left[k])
    errors = []
    for sim, st, finite_now in zip(sims, status, ok):
        try:
            sim._check_status(st, finite_now)
        except SimulationError as err:
            errors.append(err)
        else:
            errors.append(None)
    return errors
