"""Run a :class:`~physics.FloeField` in pymunk (Chipmunk2D) with our drag laws.

:class:`PymunkSimulation` builds one pymunk body per floe (a circle with the
floe's mass m = ρ h π r² and disc moment I = m r²/2) and applies the drag of
:mod:`physics.forcing` to every body at every step, so that the same set-up
can be run in our engines and in an independent impulse-based engine.

Contact law
-----------
Chipmunk resolves contacts with impulses (sequential impulses over
``iterations`` passes): the normal impulse makes the normal relative velocity
at the contact point −e times its value before the step, and the tangential
impulse is bounded by Coulomb's μ times the normal impulse; below that bound
the contact point is brought to rest (rigid sticking, no tangential
compliance). For two circles the contact arms are along the normal, so the
normal and tangential impulses do not couple and a single contact is solved
exactly by the first pass; further passes change nothing.

Chipmunk forms the pair values as *products* of the two shapes' values,
e_pair = e_a e_b and μ_pair = μ_a μ_b. Every floe shape therefore gets
elasticity √e and friction √μ, so that every floe–floe pair has exactly our
restitution e and Coulomb coefficient μ.

Boundary
--------
pymunk has no periodic boundary. Four static walls (thick segments whose
inner faces are the sides of the box) enclose a box of the size of the given
:class:`~physics.domain.PeriodicBox` or :class:`~physics.domain.WalledBox`;
a floe–wall contact has restitution ``wall_restitution`` (default 1) and
friction ``wall_friction`` (default 0), set on the pair itself (not by the
product rule). Comparisons with our periodic engines are therefore only
meaningful where the boundary does not matter: binary collisions far from
the walls, and dilute, spatially homogeneous systems over times in which the
walls take part in few collisions and the floes do not drift onto them (a
homogeneous cooling gas, whose elastic frictionless walls neither remove
energy nor bring any in; a drifting gas placed away from the downwind wall).
Dense, sheared or drifting-to-the-wall set-ups cannot be compared this way.

Collisions are found only once two circles overlap (at the end of a step),
so the contact normal is that of the overlapping position: an impact is
resolved with a normal rotated by about (tangential relative speed) × (time
since touching) / (r_i + r_j), an error of first order in the time step
unless the step ends exactly at the touching instant.

Drag
----
Applied through each body's velocity function (called by Chipmunk once a
step, after collision detection and before the impulse solver), with the
contact forces left out, over one step Δt:

* ``drag="stokes"`` — Herman (2011), the hard-disc engine's drag:
  τ_i du/dt = u_eq,i − u with τ_i and u_eq,i from
  :meth:`Forcing.time_constant` and :meth:`Forcing.equilibrium_velocity`.
  ``stokes_scheme="exponential"`` (default) uses the exact solution over the
  step, u ← u_eq + (u − u_eq) exp(−Δt/τ); ``"implicit"`` the hard-disc
  engine's linearly implicit update u ← (u + (Δt/τ) u_eq) / (1 + Δt/τ).
  There is no rotational drag and no Coriolis force (a Forcing with a
  non-zero Coriolis parameter is refused, as by the hard-disc engine).
* ``drag="herman2013"`` — Herman (2013) eqs 6–7 as in the Hertz engine:
  m du/dt = a |u_a| u_a + b (u_w − u) − m f k×u and I dω/dt = −c ω with
  a, b, c from :meth:`Forcing.coefficients`. With constant coefficients this
  is linear in u, so it too is integrated exactly over the step: in complex
  notation w = u_x + i u_y, dw/dt = A − λ w with λ = b/m + i f, so
  w ← w_eq + (w − w_eq) exp(−λ Δt), w_eq = A/λ; and ω ← ω exp(−(c/I) Δt).

The velocity functions replace Chipmunk's default velocity integration:
gravity, space damping and forces set on the bodies are not applied (the
space has none). A velocity function is a Python call per body and step
(a few µs), which dominates the cost of a dilute pymunk run with drag.

Example
-------
>>> import numpy as np
>>> from physics import FloeField, WalledBox
>>> from physics.crosscheck.pymunk_runner import PymunkSimulation
>>> field = FloeField(np.array([[10.0, 20.0], [14.0, 20.0]]), np.array([1.0, 1.0]), 1.0,
...                   np.array([[1.0, 0.0], [0.0, 0.0]]))
>>> sim = PymunkSimulation(field, WalledBox(40.0), restitution=1.0, dt=0.01)
>>> sim.advance(4.0)
>>> np.round(sim.velocities, 6).tolist()
[[0.0, 0.0], [1.0, 0.0]]
"""
from __future__ import annotations

import math

import numpy as np
import pymunk

from ..input_checks import check_range
from ..domain import Box
from ..floes import FloeField, max_overlap
from ..forcing import Forcing
from ..progress import steps_with_bar

__all__ = ["PymunkSimulation", "FLOE", "WALL"]

#: collision types of the floe and wall shapes
FLOE, WALL = 1, 2
_DRAGS = ("stokes", "herman2013")
_STOKES_SCHEMES = ("exponential", "implicit")


class PymunkSimulation:
    """A floe field in pymunk: circles, four static walls, our drag.

    Parameters
    ----------
    field : FloeField
        Initial state (copied). Floes must lie inside the box (a floe that
        crosses a side of a periodic box cannot be represented with walls)
        and must not overlap by more than 1 % of the smaller radius. Frozen
        floes become static bodies.
    box : Box
        A non-deforming box; only its size is used: walls are put on all
        four sides whatever its periodicity (see the module docstring).
    restitution : float
        Normal restitution e of a floe–floe pair, in (0, 1]; each shape gets
        elasticity √e.
    friction : float
        Coulomb coefficient μ ≥ 0 of a floe–floe pair; each shape gets √μ.
    forcing : Forcing or None
        Wind and current for the drag; ``None``: no external force.
    dt : float
        Time step [s] > 0. Keep the largest displacement per step, u_max Δt,
        well below the smallest radius (no tunnelling, small overlaps at
        detection) and, for a gas, Δt small against the mean free time.
    drag : {"stokes", "herman2013"} or None
        Drag law used with ``forcing`` (see the module docstring). Must not
        be ``None`` when a forcing is given.
    iterations : int
        Passes of Chipmunk's impulse solver per step (≥ 1). One pass solves
        an isolated contact of two circles exactly; clusters of touching
        floes need more.
    wall_restitution, wall_friction : float
        Restitution in [0, 1] and friction ≥ 0 of floe–wall contacts.
    collision_slop : float, optional
        Overlap [m] that Chipmunk leaves uncorrected (its position
        correction acts beyond it; velocities are never changed by it).
        Default 10⁻³ of the smallest radius (pymunk's own default, 0.1, is
        meant for pixels).
    stokes_scheme : {"exponential", "implicit"}
        Update of the Stokes drag (see the module docstring).

    Attributes
    ----------
    space : pymunk.Space
        The pymunk space (gravity 0, damping 1, no sleeping).
    bodies : list of pymunk.Body
        One per floe, in the order of the field.
    time : float
        Model time [s].
    n_steps : int
        Steps taken.
    """

    def __init__(self, field: FloeField, box: Box, restitution: float, friction: float = 0.0,
                 forcing: Forcing | None = None, dt: float = 0.01,
                 drag: str | None = "stokes", iterations: int = 10, *,
                 wall_restitution: float = 1.0, wall_friction: float = 0.0,
                 collision_slop: float | None = None, stokes_scheme: str = "exponential"):
        if not isinstance(field, FloeField):
            raise ValueError(f"field must be a FloeField, got {type(field).__name__}")
        if not isinstance(box, Box):
            raise ValueError(f"box must be a Box (e.g. PeriodicBox(L) or WalledBox(L)), "
                             f"got {type(box).__name__}")
        if box.deforming:
            raise ValueError("pymunk runs need a fixed box; a deforming box is not supported")
        check_range("restitution", restitution, 0.0, 1.0, low_open=True)
        check_range("friction", friction, 0.0, None)
        check_range("dt", dt, 0.0, None, low_open=True)
        check_range("iterations", iterations, 1, None)
        if int(iterations) != iterations:
            raise ValueError(f"iterations must be an integer >= 1, got {iterations!r}")
        check_range("wall_restitution", wall_restitution, 0.0, 1.0)
        check_range("wall_friction", wall_friction, 0.0, None)
        if forcing is not None and not isinstance(forcing, Forcing):
            raise ValueError(f"forcing must be a Forcing or None, got {type(forcing).__name__}")
        if forcing is not None and drag not in _DRAGS:
            raise ValueError(f"drag must be one of {_DRAGS} when a forcing is given, got {drag!r}")
        if forcing is None and drag is not None and drag not in _DRAGS:
            raise ValueError(f"drag must be one of {_DRAGS} or None, got {drag!r}")
        if stokes_scheme not in _STOKES_SCHEMES:
            raise ValueError(f"stokes_scheme must be one of {_STOKES_SCHEMES}, got {stokes_scheme!r}")

        f = field.copy()
        self.field = f
        self.box = box
        self.lx, self.ly = float(box.lx), float(box.ly)
        self.restitution = float(restitution)
        self.friction = float(friction)
        self.forcing = forcing
        self.drag = drag if forcing is not None else None
        self.stokes_scheme = stokes_scheme
        self.wall_restitution = float(wall_restitution)
        self.wall_friction = float(wall_friction)
        self._dt = float(dt)
        if self.drag == "stokes":
            self._check_coriolis()

        pos = box.wrap(f.positions)
        r = f.radii
        outside = ((pos[:, 0] - r < -1e-9 * r) | (pos[:, 0] + r > self.lx + 1e-9 * r)
                   | (pos[:, 1] - r < -1e-9 * r) | (pos[:, 1] + r > self.ly + 1e-9 * r))
        if np.any(outside):
            i = int(np.argmax(outside))
            raise ValueError(
                f"floe {i} (centre {pos[i].tolist()}, radius {r[i]:.4g} m) crosses a side of the "
                f"box: pymunk has walls, not periodic sides; place the floes inside a walled "
                f"box of the same size (physics.floes.place_floes with WalledBox)")
        worst = max_overlap(pos, r, box)
        if worst > 0.01:
            raise ValueError(f"initial overlap of {worst:.3g} of the smaller radius exceeds 1 %")

        space = pymunk.Space()
        space.gravity = (0.0, 0.0)
        space.damping = 1.0
        space.iterations = int(iterations)
        space.sleep_time_threshold = math.inf
        space.idle_speed_threshold = 0.0
        space.collision_slop = (1e-3 * float(r.min()) if collision_slop is None
                                else float(collision_slop))
        check_range("collision_slop", space.collision_slop, 0.0, None)
        self.space = space

        e_shape = math.sqrt(self.restitution)
        mu_shape = math.sqrt(self.friction)
        masses, inertia = f.masses, f.inertia
        self.bodies: list[pymunk.Body] = []
        self.shapes: list[pymunk.Circle] = []
        for i in range(f.n):
            if f.frozen[i]:
                body = pymunk.Body(body_type=pymunk.Body.STATIC)
            else:
                body = pymunk.Body(float(masses[i]), float(inertia[i]))
                body.velocity = (float(f.velocities[i, 0]), float(f.velocities[i, 1]))
                body.angular_velocity = float(f.angular_velocities[i])
            body.position = (float(pos[i, 0]), float(pos[i, 1]))
            shape = pymunk.Circle(body, float(r[i]))
            shape.elasticity = e_shape
            shape.friction = mu_shape
            shape.collision_type = FLOE
            space.add(body, shape)
            self.bodies.append(body)
            self.shapes.append(shape)
        self._mobile = [b for b, fr in zip(self.bodies, f.frozen) if not fr]
        self._mobile_mask = ~f.frozen

        # walls: thick static segments whose inner faces are the box sides
        w = max(float(r.max()), 1e-3 * max(self.lx, self.ly))
        lx, ly = self.lx, self.ly
        sb = space.static_body
        self.walls = [
            pymunk.Segment(sb, (-2 * w, -w), (lx + 2 * w, -w), w),           # y = 0
            pymunk.Segment(sb, (-2 * w, ly + w), (lx + 2 * w, ly + w), w),   # y = ly
            pymunk.Segment(sb, (-w, -2 * w), (-w, ly + 2 * w), w),           # x = 0
            pymunk.Segment(sb, (lx + w, -2 * w), (lx + w, ly + 2 * w), w),   # x = lx
        ]
        for seg in self.walls:
            seg.elasticity = 1.0
            seg.friction = 0.0
            seg.collision_type = WALL
            space.add(seg)

        self._collisions = 0
        self._wall_collisions = 0
        space.on_collision(FLOE, FLOE, begin=self._on_floe_begin)
        space.on_collision(FLOE, WALL, begin=self._on_wall_begin, pre_solve=self._on_wall_pre)

        # drag: per-body coefficients, shared with the velocity functions
        self._coef: list[tuple[complex, complex, float]] = []
        self._coef_key = None
        if self.drag is not None:
            self._coef = [(1.0 + 0j, 0j, 1.0)] * f.n
            self._update_drag()
            for i, body in enumerate(self.bodies):
                if not f.frozen[i]:
                    body.velocity_func = self._velocity_function(i)
        self.time = 0.0
        self.n_steps = 0

    # -- collision callbacks -------------------------------------------------
    def _on_floe_begin(self, arbiter, space, data):
        self._collisions += 1

    def _on_wall_begin(self, arbiter, space, data):
        self._wall_collisions += 1

    def _on_wall_pre(self, arbiter, space, data):
        arbiter.restitution = self.wall_restitution
        arbiter.friction = self.wall_friction

    # -- drag ------------------------------------------------------------------
    def _check_coriolis(self):
        if self.forcing.coriolis != 0.0:
            raise ValueError(f"drag='stokes' (Herman 2011) has no Coriolis force; got "
                             f"forcing.coriolis = {self.forcing.coriolis:g}: set it to 0 or use "
                             f"drag='herman2013'")

    def _drag_key(self):
        fo = self.forcing
        return (self._dt, tuple(fo.wind), tuple(fo.current), fo.coriolis, id(fo.params))

    def _update_drag(self):
        """(Re)compute each body's one-step factors when dt or the forcing changed."""
        key = self._drag_key()
        if key == self._coef_key:
            return
        f, fo, dt = self.field, self.forcing, self._dt
        m = f.masses
        if self.drag == "stokes":
            self._check_coriolis()
            tau = fo.time_constant(f.radii, f.thickness, m)
            u_eq = fo.equilibrium_velocity(f.radii, f.thickness, m)
            if self.stokes_scheme == "exponential":
                decay = np.exp(-dt / tau)
            else:
                decay = 1.0 / (1.0 + dt / tau)
            w_eq = u_eq[:, 0] + 1j * u_eq[:, 1]
            decay = decay.astype(complex)
            spin = np.ones(f.n)
        else:
            k = fo.coefficients(f.radii, f.thickness, m)
            speed = float(np.hypot(*fo.wind))
            ua = complex(fo.wind[0], fo.wind[1])
            uw = complex(fo.current[0], fo.current[1])
            lam = k.water / m + 1j * fo.coriolis
            w_eq = (k.wind * speed * ua + k.water * uw) / m / lam
            decay = np.exp(-lam * dt)
            spin = np.exp(-k.rotation / f.inertia * dt)
        self._coef[:] = [(complex(decay[i]), complex(w_eq[i]), float(spin[i])) for i in range(f.n)]
        self._coef_key = key

    def _velocity_function(self, i):
        coef = self._coef

        def velocity_func(body, gravity, damping, dt):
            decay, w_eq, spin = coef[i]
            vx, vy = body.velocity
            w = w_eq + (complex(vx, vy) - w_eq) * decay
            body.velocity = (w.real, w.imag)
            if spin != 1.0:
                body.angular_velocity = body.angular_velocity * spin

        return velocity_func

    # -- running -------------------------------------------------------------
    @property
    def dt(self) -> float:
        """Time step [s]; may be changed between calls to :meth:`step`."""
        return self._dt

    @dt.setter
    def dt(self, value):
        check_range("dt", value, 0.0, None, low_open=True)
        self._dt = float(value)

    def step(self, n: int = 1) -> None:
        """Advance by ``n`` time steps of :attr:`dt`."""
        check_range("n", n, 0, None)
        n = int(n)
        if self.drag is not None:
            self._update_drag()
        space, dt = self.space, self._dt
        for _ in range(n):
            space.step(dt)
        self.n_steps += n
        self.time += n * dt
        if n and not (np.all(np.isfinite(self.positions)) and np.all(np.isfinite(self.velocities))):
            raise FloatingPointError(f"non-finite floe state at t = {self.time:.6g} s")

    def advance(self, duration: float, *, progress: bool = False) -> None:
        """Advance by ``duration`` model seconds (rounded to whole steps);
        ``progress=True`` shows a progress bar."""
        check_range("duration", duration, 0.0, None)
        n = int(round(duration / self._dt))
        if not progress:
            self.step(n)
            return
        steps_with_bar(self.step, n, n // 100, "pymunk")

    # -- state -----------------------------------------------------------------
    @property
    def n(self) -> int:
        return self.field.n

    @property
    def positions(self) -> np.ndarray:
        """(N, 2) floe centres [m] (a copy)."""
        return np.array([tuple(b.position) for b in self.bodies], dtype=float).reshape(-1, 2)

    @property
    def velocities(self) -> np.ndarray:
        """(N, 2) floe velocities [m/s] (a copy; zero for frozen floes)."""
        return np.array([tuple(b.velocity) for b in self.bodies], dtype=float).reshape(-1, 2)

    @property
    def angular_velocities(self) -> np.ndarray:
        """(N,) floe spins [rad/s] (a copy)."""
        return np.array([b.angular_velocity for b in self.bodies], dtype=float)

    @property
    def masses(self) -> np.ndarray:
        """(N,) masses of the pymunk bodies [kg] (infinite for frozen floes)."""
        return np.array([b.mass if b.body_type == pymunk.Body.DYNAMIC else math.inf
                         for b in self.bodies])

    @property
    def moments(self) -> np.ndarray:
        """(N,) moments of inertia of the pymunk bodies [kg m²] (infinite for
        frozen floes)."""
        return np.array([b.moment if b.body_type == pymunk.Body.DYNAMIC else math.inf
                         for b in self.bodies])

    @property
    def collision_count(self) -> int:
        """Floe–floe contacts begun so far (Chipmunk's ``begin`` events of
        two floe shapes; walls not counted). For hard-disc-like impacts this
        is the number of collisions; a lasting contact counts once."""
        return self._collisions

    @property
    def wall_collision_count(self) -> int:
        """Floe–wall contacts begun so far."""
        return self._wall_collisions

    def kinetic_energy(self, rotation: bool = True) -> float:
        """Translational (plus, by default, rotational) kinetic energy of the
        mobile floes [J]."""
        mob = self._mobile_mask
        m = self.field.masses[mob]
        v = self.velocities[mob]
        e = 0.5 * float(np.sum(m * np.sum(v * v, axis=1)))
        if rotation:
            e += 0.5 * float(np.sum(self.field.inertia[mob] * self.angular_velocities[mob] ** 2))
        return e

    def momentum(self) -> np.ndarray:
        """Σ m u of the mobile floes (2,) [kg m/s]."""
        mob = self._mobile_mask
        return (self.field.masses[mob, None] * self.velocities[mob]).sum(axis=0)

    def mean_velocity(self) -> np.ndarray:
        """Mass-weighted mean velocity of the mobile floes (2,) [m/s]."""
        return self.momentum() / float(self.field.masses[self._mobile_mask].sum())

    def state(self) -> FloeField:
        """A copy of the current state as a FloeField."""
        f = self.field
        return FloeField(self.positions, f.radii.copy(), f.thickness.copy(), self.velocities,
                         self.angular_velocities, f.density, f.frozen.copy())

    def __repr__(self):
        return (f"PymunkSimulation(n={self.n}, box={self.lx:g} x {self.ly:g} m, "
                f"e={self.restitution:g}, mu={self.friction:g}, dt={self._dt:g}, "
                f"drag={self.drag!r}, time={self.time:.6g})")
