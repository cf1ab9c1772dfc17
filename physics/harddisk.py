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
from .domain import Box, PeriodicBox
from .event_calendar import new_heap
from .floes import FloeField, max_overlap
from .forcing import Forcing
from .observables import Contacts, Fabric, Stress, collision_stress, contacts_within, fabric
from .params import check_range

__all__ = ["HardDiskSimulation", "CollisionLog", "choose_cells"]

EVENTS_PER_CALL = 2_000_000     # events per kernel call (progress bar, Ctrl-C)


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


class HardDiskSimulation:
    """Hard-disc floes with instantaneous inelastic collisions (Herman 2011).

    Parameters
    ----------
    field : FloeField
        Floes (positions, radii, thickness, velocities, density, frozen
        mask). Must not overlap. Frozen floes are immovable obstacles.
    box : PeriodicBox
        A square periodic box (the only boundary of this engine).
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
    collision_count : int
        Floe–floe collisions so far.
    """

    def __init__(self, field: FloeField, box: Box, restitution: float = 0.85,
                 forcing: Forcing | None = None, max_velocity_step: float = 1.0,
                 collision_duration: float = 0.1, *, log_collisions: bool = False):
        if not isinstance(field, FloeField):
            raise ValueError(f"field must be a FloeField, got {type(field).__name__}")
        if not isinstance(box, PeriodicBox) or box.deforming:
            raise ValueError("the hard-disc engine needs a (non-deforming) PeriodicBox")
        if abs(box.lx - box.ly) > 1e-12 * box.lx:
            raise ValueError(f"the hard-disc engine needs a square box, got {box.lx:g} x {box.ly:g} m")
        check_range("restitution", restitution, 0.0, 1.0, low_open=True)
        check_range("max_velocity_step", max_velocity_step, 0.0, None, low_open=True)
        check_range("collision_duration", collision_duration, 0.0, None)
        if forcing is not None and not isinstance(forcing, Forcing):
            raise ValueError(f"forcing must be a Forcing or None, got {type(forcing).__name__}")
        f = field
        n = f.n
        if n < 2:
            raise ValueError(f"need at least 2 floes, got {n}")
        self.field = f
        self.box = box
        self.L = float(box.lx)
        self.restitution = float(restitution)
        self.max_velocity_step = float(max_velocity_step)
        self.collision_duration = float(collision_duration)
        self.forcing = forcing
        self._check_coriolis()
        self.radius = f.radii.copy()
        self.mass = f.masses.copy()

        pos = box.wrap(f.positions)
        worst = max_overlap(pos, f.radii, box)
        if worst > 1e-9:
            raise ValueError(f"hard discs must not overlap at the start: the worst overlap is "
                             f"{worst:.3g} of the smaller radius (physics.floes.place_floes "
                             f"places floes without overlap)")

        # cell list
        nc, cell, bigs = choose_cells(f.radii, self.L)
        big_r = f.radii[bigs].max() if bigs.size else 0.0
        if nc < 3 or (bigs.size and 2.0 * big_r / cell + 4 > nc):
            raise ValueError(
                f"the box ({self.L:.4g} m) is too small for the floes: it must hold at least 3 "
                f"cells of {2 * f.radii.max() if not bigs.size else cell:.4g} m and the largest "
                f"floe (radius {f.radii.max():.4g} m) with 2 cells to spare")
        self.n_cells, self.cell = nc, cell
        self._bigs = bigs
        self._big_rank = np.full(n, -1, dtype=np.int64)
        self._big_rank[bigs] = np.arange(bigs.size)
        self._bbox = np.zeros((max(bigs.size, 1), 4), dtype=np.int64)
        self._head = np.full(nc * nc, -1, dtype=np.int64)
        self._nxt = np.full(n, -1, dtype=np.int64)
        self._prv = np.full(n, -1, dtype=np.int64)
        self._cell_of = np.full(n, -1, dtype=np.int64)
        self._cix = np.zeros(n, dtype=np.int64)
        self._ciy = np.zeros(n, dtype=np.int64)
        self._cover = np.zeros((nc * nc, 8), dtype=np.int64)
        self._cover_n = np.zeros(nc * nc, dtype=np.int64)

        # state
        self._pos = pos.copy()
        self._vel = f.velocities.copy()
        self._inv_mass = np.where(f.frozen, 0.0, 1.0 / self.mass)
        self._t_loc = np.zeros(n)
        self._count = np.zeros(n, dtype=np.int64)
        self._ev_partner = np.full(n, K.EV_NONE, dtype=np.int64)
        self._ev_count = np.zeros(n, dtype=np.int64)
        self._heap, self._where, self._key = new_heap(n)
        self._last_coll = np.full(n, -np.inf)
        self._rapid = np.zeros((n, 2))
        self._rapid[:, 0] = -np.inf
        self._counters = np.zeros(K.N_COUNTERS, dtype=np.int64)
        self._acc = np.zeros(K.N_ACC)
        self.time = 0.0
        self._next_sync = self.max_velocity_step
        self._t_drag = 0.0
        self._log_on = bool(log_collisions)
        self._log_t0 = 0.0
        self._log_alloc(1024 if self._log_on else 1)

        K.build_cells(self._pos, self._big_rank, self.cell, nc, self._head, self._nxt, self._prv,
                      self._cell_of, self._cix, self._ciy, self._bbox, self.radius)
        self._build_cover()
        K.kinetic_tensor(self._vel, self._inv_mass, self._acc)
        self._reschedule()

    # -- internals -------------------------------------------------------------
    def _check_coriolis(self):
        # the coriolis parameter of a Forcing may be changed between calls
        if self.forcing is not None and self.forcing.coriolis != 0.0:
            raise ValueError(f"the hard-disc engine has no Coriolis force (Herman 2011); "
                             f"got forcing.coriolis = {self.forcing.coriolis:g}, set it to 0")

    def _log_alloc(self, size):
        self._log_t = np.zeros(size)
        self._log_ij = np.zeros((size, 2), dtype=np.int64)
        self._log_j = np.zeros((size, 2))
        self._log_n = 0

    def _grow_log(self):
        size = 2 * self._log_t.shape[0]
        for name in ("_log_t", "_log_ij", "_log_j"):
            old = getattr(self, name)
            new = np.zeros((size,) + old.shape[1:], dtype=old.dtype)
            new[:old.shape[0]] = old
            setattr(self, name, new)

    def _build_cover(self):
        """Cover lists of the big floes, growing them until none is full."""
        while True:
            self._counters[K.C_COVER_FULL] = 0
            K.build_cover(self._bbox, self._bigs.size, self.n_cells, self._cover, self._cover_n,
                          self._counters)
            if self._counters[K.C_COVER_FULL] == 0:
                return
            self._cover = np.zeros((self._cover.shape[0], 2 * self._cover.shape[1]),
                                   dtype=np.int64)

    def _reschedule(self):
        self._count += 1        # every stored prediction is now stale
        K.schedule_all(self.time, self._pos, self._vel, self.radius, self._t_loc, self._inv_mass,
                       self._big_rank, self._bigs, self._bbox, self.cell, self.n_cells, self.L,
                       self._head, self._nxt, self._cix, self._ciy, self._cover, self._cover_n,
                       self._count,
                       self._ev_partner, self._ev_count, self._heap, self._where, self._key,
                       self._counters)

    def _drag_arrays(self):
        f = self.field
        if self.forcing is None:
            return np.zeros(f.n), np.zeros((f.n, 2)), False
        tau = self.forcing.time_constant(f.radii, f.thickness, self.mass)
        u_eq = self.forcing.equilibrium_velocity(f.radii, f.thickness, self.mass)
        inv_tau = np.where(f.frozen, 0.0, 1.0 / tau)
        return inv_tau, np.ascontiguousarray(u_eq), True

    # -- running -------------------------------------------------------------
    def advance(self, duration: float, *, progress: bool = False) -> None:
        """Advance by ``duration`` model seconds; afterwards every floe's
        position is at :attr:`time`. ``progress=True`` shows a progress bar."""
        check_range("duration", duration, 0.0, None)
        self._check_coriolis()
        inv_tau, u_eq, has_drag = self._drag_arrays()
        t_end = self.time + float(duration)
        bar = None
        if progress:
            from tqdm.auto import tqdm
            bar = tqdm(total=float(duration), desc="hard discs",
                       bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} model s [{elapsed}<{remaining}]")
        t_start = self.time
        try:
            while True:
                status, t, self._next_sync, self._t_drag, self._log_n = K.run_events(
                    self.time, t_end, self._next_sync, self.max_velocity_step, EVENTS_PER_CALL,
                    self._pos, self._vel, self.radius, self._t_loc, self._inv_mass,
                    self._big_rank, self._bigs, self._bbox, self.cell, self.n_cells, self.L,
                    self._head, self._nxt, self._prv, self._cell_of, self._cix, self._ciy,
                    self._cover, self._cover_n, self._count, self._ev_partner, self._ev_count, self._heap, self._where,
                    self._key, self._last_coll, self._rapid, self.restitution,
                    self.collision_duration, inv_tau, u_eq, has_drag, self._t_drag, self._acc,
                    self._counters, self._log_t, self._log_ij, self._log_j, self._log_n,
                    self._log_on)
                self.time = t
                if bar is not None:
                    bar.n = min(t - t_start, float(duration))
                    bar.refresh()
                if status == K.STATUS_DONE:
                    self.time = t_end
                    break
                if status == K.STATUS_LOG_FULL:
                    self._grow_log()
                elif status == K.STATUS_COVER_FULL:
                    self._build_cover()
                    self._reschedule()
                elif status == K.STATUS_COLLAPSE:
                    raise RuntimeError(
                        f"inelastic collapse at t = {t:.9g} s: a floe collided "
                        f"{K.COLLAPSE_EVENTS} times in a row, each within {K.COLLAPSE_INTERVAL:g} s "
                        f"of the last (restitution {self.restitution:g}). Use the TC model: "
                        f"collision_duration > 0 (Herman 2011: 0.1 s)")
                elif status == K.STATUS_NONFINITE:
                    raise FloatingPointError(f"non-finite event time at t = {t:.9g} s")
        finally:
            if bar is not None:
                bar.close()

    # -- state -----------------------------------------------------------------
    @property
    def n(self) -> int:
        return self.field.n

    @property
    def positions(self) -> np.ndarray:
        """(N, 2) floe centres at :attr:`time`, wrapped into the box (a copy)."""
        dt = self.time - self._t_loc
        return np.mod(self._pos + self._vel * dt[:, None], self.L)

    @property
    def velocities(self) -> np.ndarray:
        """(N, 2) floe velocities (a copy; assign to change them)."""
        return self._vel.copy()

    @velocities.setter
    def velocities(self, value):
        v = np.asarray(value, dtype=float)
        if v.shape != self._vel.shape or not np.all(np.isfinite(v)):
            raise ValueError(f"velocities must be a finite array of shape {self._vel.shape}")
        if np.any(self.field.frozen & (np.hypot(*v.T) > 0)):
            raise ValueError("frozen floes must have zero velocity")
        K.sync_all(self.time, self._pos, self._vel, self._t_loc)
        self._vel[:] = v
        K.accumulate(self.time, self._acc)
        K.kinetic_tensor(self._vel, self._inv_mass, self._acc)
        self._reschedule()

    @property
    def collision_count(self) -> int:
        return int(self._counters[K.C_COLLISIONS])

    @property
    def diagnostics(self) -> dict:
        """Event counts: collisions, cell crossings, stale predictions, drag
        syncs, TC-model (elastic) collisions and round-off repairs."""
        c = self._counters
        return dict(collisions=int(c[K.C_COLLISIONS]), crossings=int(c[K.C_CROSSINGS]),
                    stale=int(c[K.C_STALE]), syncs=int(c[K.C_SYNCS]),
                    tc_elastic=int(c[K.C_TC]), repairs_overlap=int(c[K.C_REPAIR_OVERLAP]),
                    repairs_time=int(c[K.C_REPAIR_TIME]),
                    energy_lost=float(self._acc[K.A_LOST]))

    @property
    def repairs(self) -> int:
        """Round-off repairs so far (overlapping approach collided at once,
        negative event time clamped)."""
        return int(self._counters[K.C_REPAIR_OVERLAP] + self._counters[K.C_REPAIR_TIME])

    def kinetic_energy(self) -> float:
        """Σ m u²/2 of the mobile floes [J] (no rotation in this engine)."""
        mobile = self._inv_mass > 0
        return float(0.5 * np.sum(self.mass[mobile] * np.sum(self._vel[mobile] ** 2, axis=1)))

    def momentum(self) -> np.ndarray:
        """Σ m u of the mobile floes [kg m/s]."""
        mobile = self._inv_mass > 0
        return (self.mass[mobile, None] * self._vel[mobile]).sum(axis=0)

    # -- collision log and virial ----------------------------------------------
    @property
    def collision_log(self) -> CollisionLog:
        """The collisions since the start or :meth:`clear_collision_log`
        (needs ``log_collisions=True``)."""
        if not self._log_on:
            raise ValueError("the collision log is off; create the simulation with "
                             "log_collisions=True")
        k = self._log_n
        return CollisionLog(self._log_t[:k].copy(), self._log_ij[:k, 0].copy(),
                            self._log_ij[:k, 1].copy(), self._log_j[:k].copy())

    def clear_collision_log(self) -> None:
        """Empty the collision log; it starts a new window for :meth:`contact_stress`."""
        self._log_n = 0
        self._log_t0 = self.time

    def contacts(self, gap: float = 0.01) -> Contacts:
        """Floe pairs whose edges are closer than ``gap`` [m] now (hard discs
        touch only at the instants of collision, so a contact is a near
        neighbour), without forces; see :func:`physics.observables.contacts_within`."""
        return contacts_within(self.positions, self.radius, self.box, gap)

    def fabric(self, gap: float = 0.01) -> Fabric:
        """Contact fabric of the pairs closer than ``gap`` [m] (see :meth:`contacts`)."""
        return fabric(self.contacts(gap), self.n)

    def contact_stress(self, *, per_floe: bool = True) -> Stress:
        """Collision-virial stress over the collision log's window (since the
        start or :meth:`clear_collision_log`), compression positive [N/m]; the
        contact part of :meth:`stress` (see :func:`physics.observables.collision_stress`).
        Needs ``log_collisions=True``."""
        log = self.collision_log
        span = self.time - self._log_t0
        if span <= 0:
            raise ValueError("the collision window is empty: advance the simulation first")
        return collision_stress(log, self.radius, self.L * self.L, span, per_floe=per_floe)

    def reset_stress(self) -> None:
        """Start a new averaging window for :meth:`stress`."""
        K.accumulate(self.time, self._acc)
        self._acc[[K.A_IKXX, K.A_IKXY, K.A_IKYY, K.A_WXX, K.A_WXY, K.A_WYX, K.A_WYY]] = 0.0
        self._acc[K.A_T0] = self.time

    def stress(self) -> np.ndarray:
        """Mean stress tensor since the start or :meth:`reset_stress` [N/m],
        compression positive: σ = (⟨Σ m u⊗u⟩ + Σ_collisions r_ij ⊗ J_ij / T) / A,
        with r_ij the centre-to-centre vector at contact, J_ij the impulse on
        j and T the window length (the kinetic part is the time average)."""
        span = self.time - self._acc[K.A_T0]
        if span <= 0:
            raise ValueError("the averaging window is empty: advance the simulation first")
        K.accumulate(self.time, self._acc)
        a = self._acc
        kin = np.array([[a[K.A_IKXX], a[K.A_IKXY]], [a[K.A_IKXY], a[K.A_IKYY]]]) / span
        vir = np.array([[a[K.A_WXX], a[K.A_WXY]], [a[K.A_WYX], a[K.A_WYY]]]) / span
        return (kin + vir) / (self.L * self.L)

    def pressure(self) -> float:
        """Mean pressure tr(σ)/2 since the start or :meth:`reset_stress` [N/m]."""
        return float(0.5 * np.trace(self.stress()))

    def state(self) -> FloeField:
        """A FloeField of the current state (e.g. to save or restart)."""
        f = self.field
        return FloeField(self.positions, f.radii.copy(), f.thickness.copy(), self._vel.copy(),
                         density=f.density, frozen=f.frozen.copy())

    @property
    def concentration(self) -> float:
        return float(np.sum(np.pi * self.radius ** 2) / self.L ** 2)

    def __repr__(self):
        return (f"HardDiskSimulation(n={self.n}, L={self.L:.4g}, restitution={self.restitution:g}, "
                f"time={self.time:.6g}, collisions={self.collision_count})")
