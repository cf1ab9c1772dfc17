"""Event-driven hard-disc engine: the "Small Floe Collider" of Herman (2011).

Floes are hard discs in a periodic square box. They move on straight lines
between events; collisions are instantaneous and inelastic (eqs 10–11,
restitution ε, TC model against inelastic collapse); drag in Stokes form
relaxes every floe towards its own free-drift velocity u_eq,i with time
constant τ_i (eqs 5–8), by the linearly implicit update (eqs 13–14) at the
fixed times k Δt_max (:ref:`physics-harddisk`).

The compiled kernels (prediction, event handlers, main loop) are in
:mod:`physics.harddisk_kernels`, the event calendar in
:mod:`physics.event_calendar`.

Example
-------
>>> from physics import make_floe_field, HardDiskSimulation, Forcing, HERMAN2011
>>> field, box = make_floe_field(500, concentration=0.6, alpha=1.5, mean_diameter=2.0,
...                              thickness=1.5, seed=1, velocity_std=0.01)
>>> sim = HardDiskSimulation(field, box, restitution=0.85,
...                          forcing=Forcing(HERMAN2011.forcing))
>>> sim.advance(60.0)
>>> sim.collision_count > 0
True
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import harddisk_kernels as K
from .input_checks import check_range
from .domain import Box, PeriodicBox
from .engine import (FailureReason, FloeProperties, SimulationError, checked_motion,
                     engine_from_preset, snapshot)
from .event_calendar import new_calendar
from .floes import FloeField, max_overlap
from .forcing import Forcing
from .harddisk_kernels import HardDiskStatus
from .observables import Contacts, Fabric, Stress, collision_stress, contacts_within, fabric
from .params import PaperPreset

__all__ = ["HardDiskSimulation", "HardDiskStatus", "CollisionLog", "choose_cells"]

EVENTS_PER_CALL = 2_000_000     # events per kernel call (progress bar, Ctrl-C)


def _new_log(on: bool, size: int) -> K.LogBuffer:
    return K.LogBuffer(on, np.zeros(1, dtype=np.int64), np.zeros(size),
                       np.zeros((size, 2), dtype=np.int64), np.zeros((size, 2)))


@dataclass
class CollisionLog:
    """Collisions since the log was (re)started, in time order.

    time : (K,) [s]; i, j : (K,) int — the floes (impulse on j is +J, on i −J);
    impulse : (K, 2) — impulse J on j [N s], along the unit vector from i to j.
    """
    time: np.ndarray
    i: np.ndarray
    j: np.ndarray
    impulse: np.ndarray

    def __len__(self):
        return self.time.shape[0]


def choose_cells(radii: np.ndarray, length: float, floes_per_cell: float = 1.5,
                 max_big_fraction: float = 0.1):
    """Cell list sizing for a periodic square of side ``length``: (number of
    cells per side, cell side, indices of the big floes).

    The target cell side s₀ holds ``floes_per_cell`` floe centres on
    average. Floes with a diameter above s₀ (at most ``max_big_fraction`` of
    them, the largest) are "big" and handled by their bounding boxes (see
    :mod:`physics.harddisk_kernels`); the cell side is the largest diameter
    of the others, so for equal floes there are no big ones and the cell is
    one diameter.
    """
    r = np.asarray(radii, dtype=float)
    n = r.size
    s0 = np.sqrt(floes_per_cell * length * length / n)
    order = np.argsort(-r, kind="stable")
    n_big = min(int(np.sum(2.0 * r > s0)), int(max_big_fraction * n))
    bigs = order[:n_big]
    r_small = r[order[n_big]]
    bigs = bigs[r[bigs] > r_small]
    side = 2.0 * r_small * (1.0 + 1e-9)          # margin against round-off at cell walls
    nc = int(length // side)
    return nc, length / max(nc, 1), np.sort(bigs).astype(np.int64)


class HardDiskSimulation(FloeProperties):
    """Hard-disc floes with instantaneous inelastic collisions (Herman 2011).

    It keeps the :class:`~physics.engine.FloeEngine` contract: the input
    field is copied, ``positions``, ``velocities`` and
    ``angular_velocities`` are read-only snapshots, ``radii``, ``masses``
    and ``frozen`` read-only views (:class:`~physics.engine.FloeProperties`),
    wrong types raise ``TypeError``, wrong values ``ValueError``, and a
    breakdown of the physics during :meth:`advance` a
    :class:`~physics.engine.SimulationError`.

    Parameters
    ----------
    field : FloeField
        Floes (positions, radii, thickness, velocities, density, frozen
        mask); copied, never modified. Must not overlap. Frozen floes are
        immovable obstacles. Hard discs do not rotate: angular velocities
        are ignored.
    box : PeriodicBox
        A square, non-deforming periodic box (the only boundary of this engine).
    restitution : float
        ε in (0, 1] (Herman 2011: 0.85).
    forcing : Forcing or None
        Wind and current acting through drag in Stokes form (τ_i and
        u_eq,i from :meth:`Forcing.time_constant` and
        :meth:`Forcing.equilibrium_velocity`). ``None``: free flight. The
        Coriolis parameter must be zero (the 2011 model has none). Wind and
        current may be changed between calls to :meth:`advance`.
    max_velocity_step : float
        Δt_max [s] > 0: the drag update is applied at every multiple of it.
    collision_duration : float
        Δt_c [s] ≥ 0 of the TC model: a floe that collided less than Δt_c
        ago collides elastically. 0 switches the model off.
    log_collisions : bool
        Keep a log of every collision (time, pair, impulse) for stress and
        pressure from the collision virial; see :attr:`collision_log`.

    Attributes
    ----------
    time : float
        Model time [s].
    box : PeriodicBox
    field : FloeField
        The simulation's copy of the initial field.
    L : float
        Side of the box [m].

    Raises
    ------
    TypeError
        ``field`` not a :class:`~physics.floes.FloeField`, ``box`` not a
        :class:`~physics.domain.PeriodicBox`, ``forcing`` neither a
        :class:`~physics.forcing.Forcing` nor ``None``.
    ValueError
        A bad parameter, a deforming or non-square box, overlapping floes,
        a box too small for the cell list, a non-zero Coriolis parameter.
    """

    def __init__(self, field: FloeField, box: Box, restitution: float = 0.85,
                 forcing: Forcing | None = None, max_velocity_step: float = 1.0,
                 collision_duration: float = 0.1, *, log_collisions: bool = False):
        if not isinstance(field, FloeField):
            raise TypeError(f"field must be a FloeField, got {type(field).__name__}")
        if not isinstance(box, PeriodicBox):
            raise TypeError(f"the hard-disc engine needs a PeriodicBox, got {type(box).__name__}")
        if box.deforming:
            raise ValueError("the hard-disc engine needs a non-deforming PeriodicBox")
        if abs(box.lx - box.ly) > 1e-12 * box.lx:
            raise ValueError(f"the hard-disc engine needs a square box, got "
                             f"{box.lx:g} x {box.ly:g} m")
        check_range("restitution", restitution, 0.0, 1.0, low_open=True)
        check_range("max_velocity_step", max_velocity_step, 0.0, None, low_open=True)
        check_range("collision_duration", collision_duration, 0.0, None)
        if forcing is not None and not isinstance(forcing, Forcing):
            raise TypeError(f"forcing must be a Forcing or None, got {type(forcing).__name__}")
        n = field.n
        if n < 2:
            raise ValueError(f"need at least 2 floes, got {n}")
        self.box = box
        self.L = float(box.lx)
        self.restitution = float(restitution)
        self.max_velocity_step = float(max_velocity_step)
        self.collision_duration = float(collision_duration)
        self.forcing = forcing
        self._check_coriolis()

        pos = box.wrap(field.positions)
        worst = max_overlap(pos, field.radii, box)
        if worst > 1e-9:
            raise ValueError(f"hard discs must not overlap at the start: the worst overlap is "
                             f"{worst:.3g} of the smaller radius (physics.floes.place_floes "
                             f"places floes without overlap)")
        nc, cell, bigs = choose_cells(field.radii, self.L)
        big_r = field.radii[bigs].max() if bigs.size else 0.0
        if nc < 3 or (bigs.size and 2.0 * big_r / cell + 4 > nc):
            raise ValueError(
                f"the box ({self.L:.4g} m) is too small for the floes: it must hold at least 3 "
                f"cells of {2 * field.radii.max() if not bigs.size else cell:.4g} m and the "
                f"largest floe (radius {field.radii.max():.4g} m) with 2 cells to spare")

        self.field = f = field.copy()
        self._radius = f.radii.copy()
        self._mass = f.masses.copy()
        self._frozen = f.frozen.copy()
        self.n_cells, self.cell = nc, cell
        rank = np.full(n, -1, dtype=np.int64)
        rank[bigs] = np.arange(bigs.size)
        self._cells = K.Cells(
            side=float(cell), n=int(nc), length=self.L, head=np.full(nc * nc, -1, dtype=np.int64),
            nxt=np.full(n, -1, dtype=np.int64), prv=np.full(n, -1, dtype=np.int64),
            cell_of=np.full(n, -1, dtype=np.int64), cix=np.zeros(n, dtype=np.int64),
            ciy=np.zeros(n, dtype=np.int64))
        self._cover = K.Cover(
            rank=rank, floes=bigs, bbox=np.zeros((max(bigs.size, 1), 4), dtype=np.int64),
            lists=np.zeros((nc * nc, 8), dtype=np.int64), sizes=np.zeros(nc * nc, dtype=np.int64))
        self._discs = K.Discs(
            pos=pos.copy(), vel=f.velocities.copy(), t_loc=np.zeros(n),
            radius=self._radius, inv_mass=np.where(self._frozen, 0.0, 1.0 / self._mass),
            changes=np.zeros(n, dtype=np.int64), last_collision=np.full(n, -np.inf),
            rapid_time=np.full(n, -np.inf), rapid_run=np.zeros(n, dtype=np.int64))
        self._calendar = new_calendar(n, K.EV_NONE)
        self._law = K.CollisionLaw(self.restitution, self.collision_duration)
        self._counters = np.zeros(K.N_COUNTERS, dtype=np.int64)
        self._acc = np.zeros(K.N_ACC)
        self.time = 0.0
        self._next_sync = self.max_velocity_step
        self._t_drag = 0.0
        self._log = _new_log(bool(log_collisions), 1024 if log_collisions else 1)
        self._log_t0 = 0.0

        K.build_cells(self._discs, self._cells, self._cover)
        self._build_cover()
        K.kinetic_tensor(self._discs, self._acc)
        self._reschedule()

    @classmethod
    def from_preset(cls, preset: PaperPreset, n: int | None = None,
                    concentration: float | None = None, *, seed: int | None = 0,
                    forcing: bool | Forcing | None = True, **kwargs) -> HardDiskSimulation:
        """A simulation of a paper preset's floes, contact and numerics.

        The floes come from ``preset.floe_field(n, concentration, seed=seed)``
        (:meth:`~physics.params.PaperPreset.floe_field`); the restitution is
        ``preset.contact.restitution``, and ``max_velocity_step`` and
        ``collision_duration`` are the preset's.

        Parameters
        ----------
        preset : PaperPreset
            E.g. :data:`~physics.params.HERMAN2011`.
        n, concentration : optional
            Number of floes and ice concentration (default: the preset's).
        seed : int or None
            Seed of the floe field.
        forcing : bool, Forcing or None
            True: the preset's wind and current
            (:meth:`~physics.params.PaperPreset.make_forcing`); False or
            None: free flight; a :class:`~physics.forcing.Forcing`: that one.
        **kwargs
            Parameters of the constructor (``restitution``,
            ``max_velocity_step``, ``collision_duration``,
            ``log_collisions``) replace the preset's; any other keyword goes
            to :meth:`~physics.params.PaperPreset.floe_field` (e.g.
            ``velocity_std``, ``repeat``).

        Raises
        ------
        TypeError
            ``preset`` not a :class:`~physics.params.PaperPreset`, or an
            unknown keyword.
        ValueError
            A bad value (see the constructor), e.g. a preset with Coriolis.

        Examples
        --------
        >>> from physics import HERMAN2011, HardDiskSimulation
        >>> sim = HardDiskSimulation.from_preset(HERMAN2011, 300, 0.6, seed=1,
        ...                                      velocity_std=0.01)
        >>> sim.n_floes, sim.restitution, sim.collision_duration
        (300, 0.85, 0.1)
        >>> sim.advance(10.0)
        >>> sim.collision_count > 0
        True
        """
        def defaults(p):
            return {"restitution": p.contact.restitution,
                    "max_velocity_step": p.max_velocity_step,
                    "collision_duration": p.collision_duration}
        return engine_from_preset(cls, preset, n, concentration, seed, forcing, defaults, kwargs)

    # -- internals -------------------------------------------------------------
    def _check_coriolis(self):
        # the coriolis parameter of a Forcing may be changed between calls
        if self.forcing is not None and self.forcing.coriolis != 0.0:
            raise ValueError(f"the hard-disc engine has no Coriolis force (Herman 2011); "
                             f"got forcing.coriolis = {self.forcing.coriolis:g}, set it to 0")

    def _grow_log(self):
        old = self._log
        new = _new_log(True, 2 * old.time.shape[0])
        for name in ("time", "pair", "impulse"):
            getattr(new, name)[:old.time.shape[0]] = getattr(old, name)
        new.used[0] = old.used[0]
        self._log = new

    def _build_cover(self):
        """Cover lists of the big floes, growing them until none is full."""
        while True:
            self._counters[K.Counter.COVER_FULL] = 0
            K.build_cover(self._cover, self.n_cells, self._counters)
            if self._counters[K.Counter.COVER_FULL] == 0:
                return
            lists = self._cover.lists
            self._cover = self._cover._replace(
                lists=np.zeros((lists.shape[0], 2 * lists.shape[1]), dtype=np.int64))

    def _reschedule(self):
        self._discs.changes[:] += 1       # every stored prediction is now stale
        K.schedule_all(self.time, self._discs, self._cells, self._cover, self._calendar,
                       self._counters)

    def _drag(self) -> K.Drag:
        f = self.field
        if self.forcing is None:
            return K.Drag(False, self.max_velocity_step, np.zeros(f.n), np.zeros((f.n, 2)))
        tau = self.forcing.time_constant(f.radii, f.thickness, self._mass)
        u_eq = self.forcing.equilibrium_velocity(f.radii, f.thickness, self._mass)
        inv_tau = np.where(f.frozen, 0.0, 1.0 / tau)
        return K.Drag(True, self.max_velocity_step, inv_tau, np.ascontiguousarray(u_eq))

    def _failure(self, status: HardDiskStatus, t: float) -> SimulationError:
        if status is HardDiskStatus.COLLAPSE:
            return SimulationError(
                f"inelastic collapse at t = {t:.9g} s: a floe collided "
                f"{K.COLLAPSE_EVENTS} times in a row, each within {K.COLLAPSE_INTERVAL:g} s "
                f"of the last (restitution {self.restitution:g}). Use the TC model: "
                f"collision_duration > 0 (Herman 2011: 0.1 s)",
                FailureReason.INELASTIC_COLLAPSE, t)
        return SimulationError(f"non-finite event time at t = {t:.9g} s",
                               FailureReason.NON_FINITE, t)

    # -- running -------------------------------------------------------------
    def advance(self, duration: float, *, progress: bool = False) -> None:
        """Advance by ``duration`` model seconds; afterwards every floe's
        position is at :attr:`time`. ``progress=True`` shows a progress bar.

        Raises
        ------
        ValueError
            A negative or non-finite ``duration``, or a forcing with Coriolis.
        SimulationError
            Inelastic collapse (TC model off) or a non-finite event time;
            :attr:`~physics.engine.SimulationError.reason` says which.
        """
        check_range("duration", duration, 0.0, None)
        self._check_coriolis()
        drag = self._drag()
        t_end = self.time + float(duration)
        bar = None
        if progress:
            from tqdm.auto import tqdm
            bar = tqdm(total=float(duration), desc="hard discs",
                       bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} model s [{elapsed}<{remaining}]")
        t_start = self.time
        try:
            while True:
                status, t, self._next_sync, self._t_drag = K.run_events(
                    self.time, t_end, self._next_sync, self._t_drag, EVENTS_PER_CALL,
                    self._discs, self._cells, self._cover, self._calendar, self._law, drag,
                    self._log, self._acc, self._counters)
                status = HardDiskStatus(status)
                self.time = t
                if bar is not None:
                    bar.n = min(t - t_start, float(duration))
                    bar.refresh()
                if status is HardDiskStatus.DONE:
                    self.time = t_end
                    break
                if status is HardDiskStatus.LOG_FULL:
                    self._grow_log()
                elif status is HardDiskStatus.COVER_FULL:
                    self._build_cover()
                    self._reschedule()
                elif status in (HardDiskStatus.COLLAPSE, HardDiskStatus.NONFINITE):
                    raise self._failure(status, t)
        finally:
            if bar is not None:
                bar.close()

    # -- state -----------------------------------------------------------------
    @property
    def n_floes(self) -> int:
        """Number of floes N."""
        return self.field.n

    @property
    def positions(self) -> np.ndarray:
        """(N, 2) floe centres at :attr:`time`, wrapped into the box; a
        read-only snapshot."""
        d = self._discs
        dt = self.time - d.t_loc
        return snapshot(np.mod(d.pos + d.vel * dt[:, None], self.L))

    @property
    def velocities(self) -> np.ndarray:
        """(N, 2) floe velocities [m/s]; a read-only snapshot (assign a
        whole array to change them)."""
        return snapshot(self._discs.vel)

    @velocities.setter
    def velocities(self, value):
        vel = self._discs.vel
        v = checked_motion("velocities", value, vel.shape, self._frozen, "velocity")
        K.sync_all(self.time, self._discs)
        vel[:] = v
        K.accumulate(self.time, self._acc)
        K.kinetic_tensor(self._discs, self._acc)
        self._reschedule()

    @property
    def angular_velocities(self) -> np.ndarray:
        """(N,) zeros: hard discs do not rotate (read-only)."""
        return snapshot(np.zeros(self.n_floes))

    @property
    def collision_count(self) -> int:
        return int(self._counters[K.Counter.COLLISIONS])

    @property
    def diagnostics(self) -> dict:
        """Event counts: collisions, cell crossings, stale predictions, drag
        syncs, TC-model (elastic) collisions and round-off repairs."""
        c = self._counters
        C = K.Counter
        return dict(collisions=int(c[C.COLLISIONS]), crossings=int(c[C.CROSSINGS]),
                    stale=int(c[C.STALE]), syncs=int(c[C.SYNCS]),
                    tc_elastic=int(c[C.TC]), repairs_overlap=int(c[C.REPAIR_OVERLAP]),
                    repairs_time=int(c[C.REPAIR_TIME]),
                    energy_lost=float(self._acc[K.Acc.LOST]))

    @property
    def repairs(self) -> int:
        """Round-off repairs so far (overlapping approach collided at once,
        negative event time clamped)."""
        return int(self._counters[K.Counter.REPAIR_OVERLAP]
                   + self._counters[K.Counter.REPAIR_TIME])

    def kinetic_energy(self) -> float:
        """Σ m u²/2 of the mobile floes [J] (no rotation in this engine)."""
        d = self._discs
        mobile = d.inv_mass > 0
        return float(0.5 * np.sum(self._mass[mobile] * np.sum(d.vel[mobile] ** 2, axis=1)))

    def momentum(self) -> np.ndarray:
        """Σ m u of the mobile floes [kg m/s]."""
        d = self._discs
        mobile = d.inv_mass > 0
        return (self._mass[mobile, None] * d.vel[mobile]).sum(axis=0)

    # -- collision log and virial ----------------------------------------------
    @property
    def collision_log(self) -> CollisionLog:
        """The collisions since the start or :meth:`clear_collision_log`
        (needs ``log_collisions=True``)."""
        log = self._log
        if not log.on:
            raise ValueError("the collision log is off; create the simulation with "
                             "log_collisions=True")
        k = int(log.used[0])
        return CollisionLog(log.time[:k].copy(), log.pair[:k, 0].copy(),
                            log.pair[:k, 1].copy(), log.impulse[:k].copy())

    def clear_collision_log(self) -> None:
        """Empty the collision log; it starts a new window for :meth:`contact_stress`."""
        self._log.used[0] = 0
        self._log_t0 = self.time

    def contacts(self, gap: float = 0.01) -> Contacts:
        """Floe pairs whose edges are closer than ``gap`` [m] now (hard discs
        touch only at the instants of collision, so a contact is a near
        neighbour), without forces; see :func:`physics.observables.contacts_within`."""
        return contacts_within(self.positions, self._radius, self.box, gap)

    def fabric(self, gap: float = 0.01) -> Fabric:
        """Contact fabric of the pairs closer than ``gap`` [m] (see :meth:`contacts`)."""
        return fabric(self.contacts(gap), self.n_floes)

    def contact_stress(self, *, per_floe: bool = True) -> Stress:
        """Collision-virial stress over the collision log's window (since the
        start or :meth:`clear_collision_log`), compression positive [N/m]; the
        contact part of :meth:`stress` (see :func:`physics.observables.collision_stress`).
        Needs ``log_collisions=True``."""
        log = self.collision_log
        span = self.time - self._log_t0
        if span <= 0:
            raise ValueError("the collision window is empty: advance the simulation first")
        return collision_stress(log, self._radius, self.L * self.L, span, per_floe=per_floe)

    def reset_stress(self) -> None:
        """Start a new averaging window for :meth:`stress`."""
        K.accumulate(self.time, self._acc)
        A = K.Acc
        self._acc[[A.IKXX, A.IKXY, A.IKYY, A.WXX, A.WXY, A.WYX, A.WYY]] = 0.0
        self._acc[A.T0] = self.time

    def stress(self) -> np.ndarray:
        """Mean stress tensor since the start or :meth:`reset_stress` [N/m],
        compression positive: σ = (⟨Σ m u⊗u⟩ + Σ_collisions r_ij ⊗ J_ij / T) / A,
        with r_ij the centre-to-centre vector at contact, J_ij the impulse on
        j and T the window length (the kinetic part is the time average)."""
        A = K.Acc
        span = self.time - self._acc[A.T0]
        if span <= 0:
            raise ValueError("the averaging window is empty: advance the simulation first")
        K.accumulate(self.time, self._acc)
        a = self._acc
        kin = np.array([[a[A.IKXX], a[A.IKXY]], [a[A.IKXY], a[A.IKYY]]]) / span
        vir = np.array([[a[A.WXX], a[A.WXY]], [a[A.WYX], a[A.WYY]]]) / span
        return (kin + vir) / (self.L * self.L)

    def pressure(self) -> float:
        """Mean pressure tr(σ)/2 since the start or :meth:`reset_stress` [N/m]."""
        return float(0.5 * np.trace(self.stress()))

    def state(self) -> FloeField:
        """The current state as a new FloeField (e.g. to save or restart)."""
        f = self.field
        return FloeField(self.positions, f.radii, f.thickness, self._discs.vel,
                         density=f.density, frozen=f.frozen.copy())

    @property
    def concentration(self) -> float:
        """Ice concentration A = Σ π r² / L² [-]."""
        return float(np.sum(np.pi * self._radius ** 2) / self.L ** 2)

    def __repr__(self):
        return (f"HardDiskSimulation(n_floes={self.n_floes}, L={self.L:.4g}, "
                f"restitution={self.restitution:g}, time={self.time:.6g}, collisions={self.collision_count})")
