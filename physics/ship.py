"""A ship among the floes: its description (:class:`Ship`), its motion and loads (:ref:`physics-ship`).

A :class:`Ship` describes the hull, the mass properties, the hydrodynamics
and how the ship moves; pass it to
:class:`~physics.hertz.HertzSimulation` as ``ship=``. The simulation then
exposes the running ship as ``sim.ship`` (a :class:`ShipState`: pose,
velocities, commands, loads, the collision log) and the statistics of a
window of the run as ``sim.ship_loads()`` (a :class:`ShipLoads`).

Two modes of motion:

``"prescribed"``
    The surge speed, sway speed and yaw rate follow the commands at once
    (as the ship of BenchNPIN's ``ship-ice-v0`` does). The ice loads are
    recorded but do not slow the ship; it has infinite mass in the contacts.
``"dynamic"``
    Surge, sway and yaw of a rigid body with added mass, linear and
    quadratic hydrodynamic damping (:class:`ShipHydrodynamics`), a bounded
    thrust and a bounded yaw moment. The ice loads slow it, turn it and can
    stop it.

Wind, current and Coriolis act on the floes only. With
``Ship(current_drag=True)`` the ship's hydrodynamic damping acts on its
velocity through the water (the simulation's current) instead of over the
ground. The hull does not touch the walls of a box.

Example
-------
>>> from physics import HERMAN2013, HertzSimulation
>>> from physics.ice_fields import transit_field
>>> from physics.ship import psv_ship
>>> field, box = transit_field(HERMAN2013, concentration=0.3, band=(150.0, 350.0),
...                            length=500.0, width=150.0, seed=1)
>>> ship = psv_ship(position=(50.0, 75.0), speed=2.0)
>>> sim = HertzSimulation(field, box, HERMAN2013.contact, dt=0.001, ship=ship)
>>> sim.advance(1.0)
>>> sim.ship.position.round(3).tolist()
[52.0, 75.0]
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from . import hull_contact as HC
from .input_checks import check_range
from .hull import MODEL_HULL, PSV_HULL, RESEARCH_HULL, Hull
from .params import GRAVITY
# the transit channel and its fields live with the other ice fields; kept importable here
from .ice_fields import FLOE_SIZE_LAWS, TransitBox, covering_diameters, transit_field  # noqa: F401

__all__ = ["Ship", "ShipHydrodynamics", "ShipState", "ShipLoads", "psv_ship", "model_ship",
           "FOSSEN_SUPPLY"]

#: Fossen's supply-vessel model (length 76.2 m, 6000 t), diagonal terms in
#: the bis system: (M_x, M_y, I_z) = m (1.1274, 1.8902, 0.1278 L²) with
#: added mass, linear damping (X_u, Y_v, N_r) = m √(g/L) (0.0358, 0.1183,
#: 0.0308 L²).
FOSSEN_SUPPLY = {"mass": (1.1274, 1.8902, 0.1278), "damping": (0.0358, 0.1183, 0.0308)}

_WATER_DENSITY = 1025.0


@dataclass(frozen=True)
class ShipHydrodynamics:
    """Added mass and hydrodynamic damping in surge, sway and yaw (ship frame).

    The default is no added mass and no damping (a ship in vacuum, for
    verification). :meth:`fossen_supply` gives documented values.

    Parameters
    ----------
    added_mass : (3,) floats
        ``-X_udot`` [kg], ``-Y_vdot`` [kg], ``-N_rdot`` [kg m²] (non-negative).
    linear_damping : (3,) floats
        ``X_u`` [N s/m], ``Y_v`` [N s/m], ``N_r`` [N m s], so that the
        force is ``-X_u u`` and so on.
    quadratic_damping : (3,) floats
        ``X_uu`` [N s²/m²], ``Y_vv`` [N s²/m²], ``N_rr`` [N m s²], so that
        the force is ``-X_uu |u| u`` and so on.
    """

    added_mass: tuple = (0.0, 0.0, 0.0)
    linear_damping: tuple = (0.0, 0.0, 0.0)
    quadratic_damping: tuple = (0.0, 0.0, 0.0)

    def __post_init__(self):
        for name in ("added_mass", "linear_damping", "quadratic_damping"):
            value = tuple(float(x) for x in getattr(self, name))
            if len(value) != 3 or not all(math.isfinite(x) and x >= 0.0 for x in value):
                raise ValueError(f"ShipHydrodynamics.{name} must be three non-negative "
                                 f"numbers (surge, sway, yaw), got {getattr(self, name)!r}")
            object.__setattr__(self, name, value)

    @classmethod
    def fossen_supply(cls, mass: float, length: float, yaw_inertia: float, draft: float,
                      water_density: float = _WATER_DENSITY) -> ShipHydrodynamics:
        """The manoeuvring coefficients of Fossen's supply-vessel model
        (:data:`FOSSEN_SUPPLY`), scaled to a ship of this ``mass`` [kg] and
        ``length`` [m] in the bis system (they are the same numbers at model
        scale under Froude scaling); the coupling terms of sway and yaw are
        left out. The yaw added mass is the model's total yaw inertia minus
        the rigid ``yaw_inertia``.

        The model is linear (a dynamic-positioning model). Quadratic terms
        are added for higher speeds: in surge the frictional resistance
        ``½ ρ S C_F u²`` of a wetted surface ``S = L (L/4 + 2T)`` with
        ``C_F = 0.0015``, and in sway and yaw the cross-flow drag of a
        flat plate of length L and draft T (``C_D = 1``): ``½ ρ T L v²``
        and ``½ ρ T L⁴/32 r²``.
        """
        m_bis, d_bis = FOSSEN_SUPPLY["mass"], FOSSEN_SUPPLY["damping"]
        root = math.sqrt(GRAVITY / length)
        yaw_total = m_bis[2] * mass * length ** 2
        added = ((m_bis[0] - 1.0) * mass, (m_bis[1] - 1.0) * mass,
                 max(yaw_total - yaw_inertia, 0.0))
        linear = (d_bis[0] * mass * root, d_bis[1] * mass * root,
                  d_bis[2] * mass * root * length ** 2)
        wetted = length * (0.25 * length + 2.0 * draft)
        quadratic = (0.5 * water_density * wetted * 0.0015,
                     0.5 * water_density * draft * length,
                     0.5 * water_density * draft * length ** 4 / 32.0)
        return cls(added, linear, quadratic)


_MODES = ("prescribed", "dynamic")


@dataclass(frozen=True)
class Ship:
    """A ship: hull, mass properties, hydrodynamics, mode and start.

    Parameters
    ----------
    hull : Hull
        The plan form (:class:`~physics.hull.Hull`).
    mass : float
        Mass [kg].
    yaw_inertia : float, optional
        Rigid-body yaw inertia [kg m²]; default: a uniform plate of the
        hull's plan form (:meth:`Hull.yaw_inertia`).
    hydrodynamics : ShipHydrodynamics
        Added mass and damping (default: none).
    mode : {"prescribed", "dynamic"}
    friction : float
        Coulomb coefficient of ice on the hull (default 0.05).
    position : (2,) floats
        Start of the centroid [m].
    heading : float
        Start heading [rad, anticlockwise from +x].
    speed : float
        Start surge speed [m/s] (also the first surge command of a
        prescribed ship).
    yaw_rate : float
        Start yaw rate [rad/s].
    max_speed, max_yaw_rate : float
        Bounds of a prescribed ship's commands [m/s, rad/s].
    max_thrust, max_yaw_moment : float
        Bounds of a dynamic ship's commands [N, N m]; the thrust may be
        negative down to −max_thrust (astern).
    current_drag : bool
        Damp the velocity through the water (the forcing's current) instead
        of over the ground.
    log_capacity : int
        Rows of the collision log kept in the compiled step (it is emptied
        whenever it fills).
    """

    hull: Hull
    mass: float
    yaw_inertia: float | None = None
    hydrodynamics: ShipHydrodynamics = ShipHydrodynamics()
    mode: str = "prescribed"
    friction: float = 0.05
    position: tuple = (0.0, 0.0)
    heading: float = 0.0
    speed: float = 0.0
    yaw_rate: float = 0.0
    max_speed: float = 10.0
    max_yaw_rate: float = 0.5
    max_thrust: float = math.inf
    max_yaw_moment: float = math.inf
    current_drag: bool = False
    log_capacity: int = 4096

    def __post_init__(self):
        if not isinstance(self.hull, Hull):
            raise TypeError(f"Ship.hull must be a Hull, got {type(self.hull).__name__}")
        if self.mode not in _MODES:
            raise ValueError(f"Ship.mode must be one of {_MODES}, got {self.mode!r}")
        if not isinstance(self.hydrodynamics, ShipHydrodynamics):
            raise TypeError("Ship.hydrodynamics must be a ShipHydrodynamics")
        check_range("Ship.mass", self.mass, 0.0, None, low_open=True)
        if self.yaw_inertia is None:
            object.__setattr__(self, "yaw_inertia", self.hull.yaw_inertia(self.mass))
        check_range("Ship.yaw_inertia", self.yaw_inertia, 0.0, None, low_open=True)
        check_range("Ship.friction", self.friction, 0.0, None)
        pos = tuple(float(x) for x in self.position)
        if len(pos) != 2 or not all(map(math.isfinite, pos)):
            raise ValueError(f"Ship.position must be two finite numbers, got {self.position!r}")
        object.__setattr__(self, "position", pos)
        for name in ("heading", "speed", "yaw_rate"):
            check_range(f"Ship.{name}", getattr(self, name))
        for name in ("max_speed", "max_yaw_rate"):
            check_range(f"Ship.{name}", getattr(self, name), 0.0, None)
        for name in ("max_thrust", "max_yaw_moment"):
            value = float(getattr(self, name))
            if not value >= 0.0:
                raise ValueError(f"Ship.{name} must be non-negative (inf: unbounded), got "
                                 f"{getattr(self, name)!r}")
        check_range("Ship.log_capacity", self.log_capacity, 16, None)
        if self.mode == "prescribed" and abs(self.speed) > self.max_speed:
            raise ValueError(f"Ship.speed {self.speed} exceeds max_speed {self.max_speed}")

    def replace(self, **changes) -> Ship:
        """A copy with some fields changed (``dataclasses.replace``)."""
        return dataclasses.replace(self, **changes)

    @property
    def dynamic(self) -> bool:
        return self.mode == "dynamic"

    @property
    def total_mass(self) -> tuple:
        """(M_x, M_y, I_z): mass in surge and sway and yaw inertia, each with
        its added mass."""
        a = self.hydrodynamics.added_mass
        return self.mass + a[0], self.mass + a[1], self.yaw_inertia + a[2]


def psv_ship(mode: str = "prescribed", *, draft: float = 6.0, **kwargs) -> Ship:
    """The full-scale platform supply vessel: :data:`~physics.hull.PSV_HULL`
    (76.2 m × 18 m), 6·10⁶ kg, Fossen's supply-vessel hydrodynamics
    (:meth:`ShipHydrodynamics.fossen_supply`, draft 6 m), a thrust of at
    most 500 kN (about 5.5 m/s in open water) and a yaw moment of at most
    9.5 MN m (0.025 rad/s steady turn). Keywords go to :class:`Ship`."""
    return _scaled_ship(PSV_HULL, 6.0e6, draft, mode, kwargs)


def research_ship(mode: str = "prescribed", *, draft: float = 6.8, **kwargs) -> Ship:
    """A research icebreaker of Araon's main dimensions:
    :data:`~physics.hull.RESEARCH_HULL` (110 m × 19 m, the pointed
    waterline of :func:`psv_ship` stretched to them, not Araon's lines),
    7.5·10⁶ kg, draft 6.8 m, the same non-dimensional hydrodynamics and
    bounds as :func:`psv_ship`. Keywords go to :class:`Ship`."""
    return _scaled_ship(RESEARCH_HULL, 7.5e6, draft, mode, kwargs)


def model_ship(mode: str = "prescribed", *, draft: float = 0.13, **kwargs) -> Ship:
    """The 1:45 model-scale hull: :data:`~physics.hull.MODEL_HULL`
    (1.84 m × 0.38 m), 90 kg, the same non-dimensional hydrodynamics and
    bounds as :func:`psv_ship`. Keywords go to :class:`Ship`."""
    return _scaled_ship(MODEL_HULL, 90.0, draft, mode, kwargs)


def _scaled_ship(hull, mass, draft, mode, kwargs):
    inertia = kwargs.pop("yaw_inertia", None) or hull.yaw_inertia(mass)
    hydro = kwargs.pop("hydrodynamics", None) or ShipHydrodynamics.fossen_supply(
        mass, hull.length, inertia, draft)
    # bounds as fractions of m g and m g L (those of the full-scale ship)
    kwargs.setdefault("max_thrust", 0.0085 * mass * GRAVITY)
    kwargs.setdefault("max_yaw_moment", 0.0021 * mass * GRAVITY * hull.length)
    return Ship(hull, mass, inertia, hydro, mode, **kwargs)


# ---------------------------------------------------------------------------
# The running ship
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class ShipLoads:
    """Statistics of the ice loads over a window of a run
    (:meth:`physics.hertz.HertzSimulation.ship_loads`). Forces in the ship
    frame; the resistance is the time mean of the ice force against the
    surge direction."""

    #: window [s]
    start: float
    end: float
    #: distance sailed (path length) [m] and mean surge speed [m/s]
    distance: float
    mean_speed: float
    #: mean ice force against surge [N]
    resistance: float
    #: its standard error from 20 blocks of the window [N]
    resistance_error: float
    #: mean ice force in sway [N] and mean ice moment [N m]
    mean_sway_force: float
    mean_moment: float
    #: largest ice force magnitude in one step [N]
    max_force: float
    #: collisions that ended in the window, and the floes among them
    collisions: int
    collided_floes: int
    #: mean and largest impulse magnitude of a collision [N s]
    mean_impulse: float
    max_impulse: float
    #: work done by the hull on the ice [J]
    energy_to_ice: float

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


class ShipState:
    """The ship of a running simulation (``sim.ship``): pose, velocities,
    commands, loads and the collision log.

    The simulation builds it; use :meth:`command` to steer, and read the
    step records with :meth:`records` and the finished collisions with
    :meth:`collisions`.
    """

    def __init__(self, ship: Ship, n_floes: int, law):
        self.ship = ship
        hull = ship.hull
        m_x, m_y, inertia = ship.total_mass
        hyd = ship.hydrodynamics
        state = np.zeros(HC.STATE_SIZE)
        state[HC.S_X], state[HC.S_Y] = ship.position
        state[HC.S_PSI] = ship.heading
        c, s = math.cos(ship.heading), math.sin(ship.heading)
        state[HC.S_VX], state[HC.S_VY] = c * ship.speed, s * ship.speed
        state[HC.S_R] = ship.yaw_rate
        command = np.zeros(3)
        if not ship.dynamic:
            command[0], command[2] = ship.speed, ship.yaw_rate
        self.reach = hull.circumradius
        self.skin = 0.0    # set by the simulation
        self._bundle = HC.ShipBundle(
            True, ship.dynamic, np.ascontiguousarray(hull.vertices[:, 0]),
            np.ascontiguousarray(hull.vertices[:, 1]), np.zeros(hull.n_vertices),
            np.zeros(hull.n_vertices), self.reach, 0.0, state, float(m_x), float(m_y),
            float(inertia), np.array(hyd.linear_damping + hyd.quadratic_damping), command,
            np.zeros(2), law._replace(mu=float(ship.friction)), np.zeros((n_floes, 2)),
            np.column_stack([-np.ones(n_floes), np.zeros((n_floes, 5))]),
            np.zeros(n_floes, dtype=np.int64), np.zeros(5, dtype=np.int64),
            np.zeros((int(ship.log_capacity), len(HC.LOG_COLUMNS))),
            np.zeros((0, len(HC.RECORD_COLUMNS))))
        self._records = []
        self._log = []

    # -- compiled step -------------------------------------------------------
    @property
    def kernel_bundle(self) -> HC.ShipBundle:
        """The compiled kernels' bundle of the ship's live state (not a
        copy: the kernels write into it), for benchmarks and tests that call
        a hull kernel alone; :meth:`bundle` readies it for a run."""
        return self._bundle

    def bundle(self, n_steps: int) -> HC.ShipBundle:
        """The bundle for a run of ``n_steps`` (a fresh record buffer, whose
        rows the run writes; :meth:`drain` keeps those it wrote)."""
        self._bundle = self._bundle._replace(record=np.empty((n_steps, len(HC.RECORD_COLUMNS))))
        self._bundle.counts[HC.C_RECORD] = 0
        return self._bundle

    def set_skin(self, skin: float):
        self.skin = float(skin)
        self._bundle = self._bundle._replace(skin=self.skin)
        # force a list build at the first step
        self._bundle.state[HC.S_HULL_TRAVEL] = 2.0 * self.skin

    def refresh(self):
        """The accelerations of a dynamic ship with its commands now (they
        may have changed since the last step) and the last ice load."""
        if self.ship.dynamic:
            st = self._bundle.state
            HC.ship_accelerations(self._bundle, st[HC.S_FX], st[HC.S_FY], st[HC.S_N])

    def set_current(self, current):
        if self.ship.current_drag:
            self._bundle.current[:] = current

    def drain(self):
        """Move the step records and finished collisions of the last run
        from the compiled buffers into the history."""
        b = self._bundle
        rows = int(b.counts[HC.C_RECORD])
        if rows:
            # the buffer is the run's own (bundle): its rows are kept without
            # a copy, unless the run stopped early and used less than half of it
            kept = b.record[:rows]
            self._records.append(kept if 2 * rows >= b.record.shape[0] else kept.copy())
        n_log = int(b.counts[HC.C_LOG])
        if n_log:
            self._log.append(b.log[:n_log].copy())
            b.counts[HC.C_LOG] = 0

    # -- pose and motion -----------------------------------------------------
    @property
    def mode(self) -> str:
        return self.ship.mode

    @property
    def position(self) -> np.ndarray:
        """Centroid (x, y) [m] (not wrapped into a periodic box)."""
        return self._bundle.state[[HC.S_X, HC.S_Y]].copy()

    @property
    def motion(self) -> np.ndarray:
        """(x, y, heading, Vx, Vy, yaw rate) [m, m, rad, m/s, m/s, rad/s] as
        one read-only array, a view of the state the compiled step moves
        (for a caller that reads the pose of many ships every step)."""
        view = self._bundle.state[:6]
        view.flags.writeable = False
        return view

    @property
    def heading(self) -> float:
        """Heading [rad, anticlockwise from +x]."""
        return float(self._bundle.state[HC.S_PSI])

    @property
    def velocity(self) -> np.ndarray:
        """Velocity (Vx, Vy) in the world frame [m/s]."""
        return self._bundle.state[[HC.S_VX, HC.S_VY]].copy()

    @property
    def surge(self) -> float:
        """Surge speed u [m/s] (ship frame)."""
        c, s = math.cos(self.heading), math.sin(self.heading)
        v = self._bundle.state
        return float(c * v[HC.S_VX] + s * v[HC.S_VY])

    @property
    def sway(self) -> float:
        """Sway speed v [m/s] (ship frame, to port)."""
        c, s = math.cos(self.heading), math.sin(self.heading)
        v = self._bundle.state
        return float(-s * v[HC.S_VX] + c * v[HC.S_VY])

    @property
    def yaw_rate(self) -> float:
        """Yaw rate r [rad/s]."""
        return float(self._bundle.state[HC.S_R])

    @property
    def vertices(self) -> np.ndarray:
        """(K, 2) hull corners in the world frame [m]."""
        x, y = self.position
        return self.ship.hull.world_vertices(x, y, self.heading)

    def set_motion(self, velocity=None, yaw_rate=None):
        """Set the ship's velocity (world frame) and yaw rate (a dynamic
        ship; a prescribed one follows its commands)."""
        if velocity is not None:
            v = np.asarray(velocity, dtype=float)
            if v.shape != (2,) or not np.all(np.isfinite(v)):
                raise ValueError(f"velocity must be two finite numbers, got {velocity!r}")
            self._bundle.state[HC.S_VX], self._bundle.state[HC.S_VY] = v
        if yaw_rate is not None:
            check_range("yaw_rate", yaw_rate)
            self._bundle.state[HC.S_R] = yaw_rate

    @property
    def kinetic_energy(self) -> float:
        """½ M_x u² + ½ M_y v² + ½ I_z r² with added mass [J]."""
        m_x, m_y, inertia = self.ship.total_mass
        return 0.5 * (m_x * self.surge ** 2 + m_y * self.sway ** 2 + inertia * self.yaw_rate ** 2)

    @property
    def momentum(self) -> np.ndarray:
        """Rigid-body linear momentum m (Vx, Vy) [kg m/s]."""
        return self.ship.mass * self.velocity

    # -- commands -------------------------------------------------------------
    @property
    def commands(self) -> dict:
        c = self._bundle.command
        if self.ship.dynamic:
            return {"thrust": float(c[0]), "yaw_moment": float(c[2])}
        return {"surge": float(c[0]), "sway": float(c[1]), "yaw_rate": float(c[2])}

    def command(self, **values) -> dict:
        """Set commands; values beyond the ship's bounds are clipped to them.

        A prescribed ship takes ``surge`` [m/s], ``sway`` [m/s] and
        ``yaw_rate`` [rad/s]; a dynamic ship ``thrust`` [N] and
        ``yaw_moment`` [N m]. Returns the commands now in force.

        Raises
        ------
        ValueError
            A non-finite value or a command the mode does not have.
        """
        ship = self.ship
        if ship.dynamic:
            slots = {"thrust": (0, ship.max_thrust), "yaw_moment": (2, ship.max_yaw_moment)}
        else:
            slots = {"surge": (0, ship.max_speed), "sway": (1, ship.max_speed),
                     "yaw_rate": (2, ship.max_yaw_rate)}
        for name, value in values.items():
            if name not in slots:
                raise ValueError(f"a {ship.mode} ship takes the commands {sorted(slots)}, "
                                 f"got {name!r}")
            try:
                v = float(value)
            except (TypeError, ValueError):
                raise ValueError(f"command {name} must be a number, got {value!r}") from None
            if not math.isfinite(v):
                raise ValueError(f"command {name} must be finite, got {value!r}")
            slot, bound = slots[name]
            self._bundle.command[slot] = min(max(v, -bound), bound)
        return self.commands

    # -- loads ----------------------------------------------------------------
    @staticmethod
    def _rows(chunks: list, columns: int) -> np.ndarray:
        if not chunks:
            rows = np.zeros((0, columns))
        else:
            rows = chunks[0].view() if len(chunks) == 1 else np.concatenate(chunks)
        rows.flags.writeable = False
        return rows

    def record_rows(self) -> np.ndarray:
        """The step records of :meth:`records` as one read-only (steps,
        len(RECORD_COLUMNS)) array, without a copy of each column (for a
        caller that reduces them every step)."""
        return self._rows(self._records, len(HC.RECORD_COLUMNS))

    def collision_rows(self) -> np.ndarray:
        """The finished collisions of :meth:`collisions` as one read-only
        (collisions, len(LOG_COLUMNS)) array (the floe as a float)."""
        return self._rows(self._log, len(HC.LOG_COLUMNS))

    def records(self) -> dict:
        """Every step since the start (or :meth:`clear`) as arrays, one per
        column of :data:`~physics.hull_contact.RECORD_COLUMNS`: time, pose,
        velocities (ship frame), ice force (surge, sway) and moment, the
        power of the hull on the ice, the number of floes touching, the
        sum of their normal contact forces [N] (what presses on the hull,
        also when the resultant cancels) and the sum of the magnitudes of
        their contact forces [N] (its time integral bounds the collisions'
        impulses: Σ_c |J_c| ≤ Σ_c ∫ |F_c| dt)."""
        rows = self.record_rows()
        return {name: rows[:, k].copy() for k, name in enumerate(HC.RECORD_COLUMNS)}

    def collisions(self) -> dict:
        """Finished collisions as arrays, one per column of
        :data:`~physics.hull_contact.LOG_COLUMNS`: start and end time, floe,
        impulse on the hull (surge, sway; ship frame) [N s], first contact
        point in the ship frame [m], floe mass [kg], peak force [N]."""
        rows = self.collision_rows()
        out = {name: rows[:, k].copy() for k, name in enumerate(HC.LOG_COLUMNS)}
        out["floe"] = out["floe"].astype(np.int64)
        return out

    @property
    def loads(self) -> dict:
        """The ice load of the last step: force (surge, sway) [N] and moment [N m]."""
        if not self._records or not len(self._records[-1]):
            return {"surge": 0.0, "sway": 0.0, "moment": 0.0}
        row = self._records[-1][-1]
        return {"surge": float(row[7]), "sway": float(row[8]), "moment": float(row[9])}

    def clear(self):
        """Forget the step records and the collision log (e.g. between
        episodes or to bound the memory of a long run)."""
        self._records.clear()
        self._log.clear()

    def statistics(self, start: float | None = None, end: float | None = None) -> ShipLoads:
        """:class:`ShipLoads` over the steps with start < t ≤ end."""
        rec = self.records()
        t = rec["time"]
        lo = -math.inf if start is None else float(start)
        hi = math.inf if end is None else float(end)
        sel = (t > lo) & (t <= hi)
        if not np.any(sel):
            raise ValueError(f"no ship records in the window ({lo}, {hi}]")
        ts = t[sel]
        dt = float(np.median(np.diff(t))) if t.size > 1 else 0.0
        steps = np.diff(np.column_stack([rec["x"], rec["y"]]), axis=0)
        path = np.concatenate([[0.0], np.hypot(steps[:, 0], steps[:, 1])])
        surge_force = rec["ice_surge"][sel]
        blocks = np.array_split(-surge_force, min(20, surge_force.size))
        means = np.array([b.mean() for b in blocks])
        err = float(means.std(ddof=1) / math.sqrt(means.size)) if means.size > 1 else math.nan
        force = np.hypot(rec["ice_surge"][sel], rec["ice_sway"][sel])
        log = self.collisions()
        lsel = (log["end"] > lo) & (log["end"] <= hi)
        imp = np.hypot(log["impulse_surge"][lsel], log["impulse_sway"][lsel])
        return ShipLoads(
            start=float(ts[0] - dt), end=float(ts[-1]), distance=float(path[sel].sum()),
            mean_speed=float(rec["surge"][sel].mean()), resistance=float(-surge_force.mean()),
            resistance_error=err, mean_sway_force=float(rec["ice_sway"][sel].mean()),
            mean_moment=float(rec["ice_moment"][sel].mean()), max_force=float(force.max()),
            collisions=int(lsel.sum()), collided_floes=int(np.unique(log["floe"][lsel]).size),
            mean_impulse=float(imp.mean()) if imp.size else 0.0,
            max_impulse=float(imp.max()) if imp.size else 0.0,
            energy_to_ice=float(np.sum(rec["ice_power"][sel]) * dt))

    def __repr__(self):
        x, y = self.position
        return (f"ShipState({self.ship.hull.name!r}, {self.mode}, position=({x:.4g}, {y:.4g}), "
                f"heading={self.heading:.4g}, surge={self.surge:.4g} m/s)")
