"""The ship of the Hertz engine against a kinematic hull in pymunk (Chipmunk2D).

The same hull (:class:`~physics.hull.Hull`) is driven at the same constant
speed along +x (heading 0, so the ship frame is the world frame) through the
same floes, in our Hertz engine as a prescribed :class:`~physics.ship.Ship`
and in pymunk as a kinematic polygon (:class:`PymunkShipSimulation`):

* :func:`single_impacts` — one floe at rest hit head-on by the flat bow of
  :meth:`Hull.box <physics.hull.Hull.box>` (an edge) or by the stem of
  :meth:`Hull.pointed <physics.hull.Hull.pointed>` (a vertex): the impulse
  on the hull from our collision log against the floe's momentum change in
  pymunk, and both against the rigid law (1 + e) m v;
* :func:`dilute_transit` — a pointed hull through a dilute field of floes
  at rest in a walled channel, several seeds: the number of hull–floe
  collisions and the mean resistance (the time mean of the ice force against
  the motion) of the two engines, compared within their statistical error;

:func:`run` runs both.

The pymunk model
----------------
The hull is a ``pymunk.Poly`` with the hull's corners (ship frame, centroid
at the body's position) on a KINEMATIC body moving at (v, 0): infinite mass,
its velocity unchanged by the contacts, as a prescribed ship. The floes are
the dynamic circles of :class:`~physics.crosscheck.pymunk_runner.PymunkSimulation`
(mass ρ h π r², moment of a disc), the walls its four static segments. There
is no drag and no gravity on either side.

Chipmunk forms the pair values of a contact as products of the two shapes'
values (e_pair = e_a e_b, μ_pair = μ_a μ_b). The floe shapes carry √e and √μ
(floe–floe pairs: e and μ), and so does the hull shape: every floe–hull pair
has exactly the restitution e and the Coulomb coefficient μ of our
``ContactParams(restitution=e)`` and ``Ship(friction=μ)``; the walls carry
e and μ on the pair itself, as our walls do.

What is measured
----------------
*Collisions*: in pymunk the ``begin`` events of the hull and a floe (a
contact that starts after at least one step apart); in ours the rows of the
collision log (:meth:`~physics.ship.ShipState.collisions`) plus the floes
still touching at the end.

*Impulse and resistance*: pymunk's impulse on the hull is the sum over the
steps of ``arbiter.total_impulse`` in ``post_solve`` callbacks (the impulse
on the first shape of the handler, the hull; the single impacts check it
against the floe's momentum change, to rounding). Its resistance is
−(impulse along x) / (run time); ours is
:attr:`ShipLoads.resistance <physics.ship.ShipLoads.resistance>` over the
same time.

*Statistics of the transit*: each field is run in both engines, so the
per-field differences are paired; the check is the mean difference over its
standard error (standard deviation of the differences / √n), a Student t
with n − 1 = 4 degrees of freedom for 5 fields. Its tolerance 4.6 is the
two-sided 99 % quantile: with 4 degrees of freedom the error estimate itself
is uncertain by a third, and |t| > 3 happens by chance in 4 % of sets of
fields (in 2 of 18 sets tried, with no bias over 40 fields; see below).
The seed means of each engine and their standard errors are given too;
their spread from field to field (the floes in the hull's path) is several
times the error of the paired difference.

Where the engines differ
------------------------
* Our contacts are soft (Hertz; at the soft modulus used, E = 10⁸ Pa, a
  hull contact lasts 30–100 ms), pymunk's are instantaneous. A head-on impact
  gives the same impulse. A glancing contact at a corner of the hull does
  not: during the soft contact the hull moves on and the normal from the
  corner to the floe turns, by (tangential speed × contact time) / r, and
  the normal speed with it. One such contact at the bow's knuckle (a floe of
  r = 2.7 m at rest, nothing else touching) gave an 8 % smaller surge impulse
  in our engine than in pymunk at 10⁸ Pa, and 1 % at 9·10⁹ Pa.
* Friction: a Mindlin spring against rigid Coulomb friction (see
  :mod:`physics.crosscheck.pymunk_checks`); where a contact sticks (a floe
  hit nearly head-on on the stem, floe–floe impacts) the floe leaves with a
  different spin and tangential velocity.
* pymunk detects a contact once the shapes overlap (by up to the relative
  speed × Δt) and resolves it with the normal of that position; on an edge
  the normal is exact, at a corner it is off by up to (tangential speed) Δt
  / r (5·10⁻³ rad here).

Either difference changes a floe's path after the contact, and later
contacts of that floe with the hull, other floes and the walls; the transits
are therefore compared as two realisations of the same process. Over 40
fields of :data:`TRANSIT_QUICK` the mean relative difference of the
resistance (Hertz − pymunk) was +0.7 % ± 1.0 % and of the collisions
−0.5 ± 0.6 out of 29 a field; over 20 fields of :data:`TRANSIT`,
−1.4 % ± 1.2 % and −1.3 ± 2.0 out of 90.
"""
from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pymunk

from ..domain import Box, WalledBox
from ..floes import FloeField, place_floes
from ..hertz import HertzSimulation, hull_contact_time
from ..hull import Hull
from ..params import ContactParams
from ..ship import Ship
from .pymunk_runner import FLOE, PymunkSimulation
from .results import Check, save_figure

__all__ = ["PymunkShipSimulation", "HULL", "TRANSIT", "TRANSIT_QUICK", "hertz_hull_impact",
           "pymunk_hull_impact", "dilute_field", "transit_fields", "hertz_transit",
           "pymunk_transit", "seed_comparison", "single_impacts", "dilute_transit", "run"]

#: collision type of the hull shape (floes and walls: FLOE = 1, WALL = 2)
HULL = 3

#: contact law of both engines: restitution, Coulomb coefficient (floe–floe
#: and floe–hull), and our Young's modulus (soft, so that the Hertz time step
#: is affordable; pymunk has no modulus)
RESTITUTION = 0.5
FRICTION = 0.1
MODULUS = 1.0e8
THICKNESS = 1.0


# ---------------------------------------------------------------------------
# The pymunk ship
# ---------------------------------------------------------------------------

class PymunkShipSimulation:
    """Floes in pymunk (:class:`PymunkSimulation`, no drag) and a hull as a
    kinematic polygon moving at a constant velocity along +x.

    Parameters
    ----------
    field : FloeField
        Floes (copied); inside ``box``, not overlapping the hull.
    box : Box
        Its size gives the four walls (see
        :class:`~physics.crosscheck.pymunk_runner.PymunkSimulation`).
    hull : Hull
        The plan form; its corners in the ship frame become the polygon.
    position : (2,) floats
        Start of the hull's centroid [m] (heading 0: bow along +x).
    speed : float
        Constant surge speed [m/s].
    restitution, friction : float
        e and μ of every floe–floe, floe–hull and floe–wall pair.
    dt : float
        pymunk time step [s].
    iterations : int
        Passes of Chipmunk's impulse solver per step.

    Attributes
    ----------
    floes : PymunkSimulation
        The floes (``floes.space`` is the pymunk space of both).
    body, shape : pymunk.Body, pymunk.Poly
        The hull.
    hull_collisions : list of (float, int)
        (time at the end of the step, floe) of every hull–floe contact begun.
    impulse : (2,) array
        Total impulse of the floes on the hull since the start [N s] (world
        frame = ship frame).
    """

    def __init__(self, field: FloeField, box: Box, hull: Hull, position, speed: float,
                 restitution: float, friction: float, dt: float, iterations: int = 10):
        self.floes = PymunkSimulation(field, box, restitution=restitution, friction=friction,
                                      forcing=None, dt=dt, drag=None, iterations=iterations,
                                      wall_restitution=restitution, wall_friction=friction)
        space = self.floes.space
        self.hull = hull
        self.speed = float(speed)
        body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        body.position = (float(position[0]), float(position[1]))
        body.angle = 0.0
        body.velocity = (self.speed, 0.0)
        shape = pymunk.Poly(body, [tuple(map(float, v)) for v in hull.vertices], radius=0.0)
        shape.elasticity = math.sqrt(restitution)
        shape.friction = math.sqrt(friction)
        shape.collision_type = HULL
        space.add(body, shape)
        self.body, self.shape = body, shape
        self._index = {s: i for i, s in enumerate(self.floes.shapes)}
        self.hull_collisions: list[tuple[float, int]] = []
        self.impulse = np.zeros(2)
        self._jx = 0.0
        self._jy = 0.0
        self.pair_values: set[tuple[float, float]] = set()
        self._open: dict[int, list] = {}
        self._episodes: list[tuple] = []
        self._t_end = 0.0
        space.on_collision(HULL, FLOE, begin=self._on_begin, post_solve=self._on_post_solve,
                           separate=self._on_separate)

    def _on_begin(self, arbiter, space, data):
        i = self._index[arbiter.shapes[1]]
        self.hull_collisions.append((self._t_end, i))
        self._open[i] = [self._t_end, 0.0, 0.0]
        self.pair_values.add((arbiter.restitution, arbiter.friction))

    def _on_post_solve(self, arbiter, space, data):
        # total_impulse is the impulse of this step on the first shape of the
        # handler, the hull (the floe receives its opposite)
        j = arbiter.total_impulse
        self._jx += j.x
        self._jy += j.y
        episode = self._open[self._index[arbiter.shapes[1]]]
        episode[1] += j.x
        episode[2] += j.y

    def _on_separate(self, arbiter, space, data):
        start, jx, jy = self._open.pop(self._index[arbiter.shapes[1]])
        self._episodes.append((start, self._t_end, self._index[arbiter.shapes[1]], jx, jy))

    def step(self, n: int = 1) -> None:
        """Advance by ``n`` steps of ``floes.dt``."""
        floes = self.floes
        space, dt = floes.space, floes.dt
        t0 = floes.time
        for k in range(int(n)):
            self._t_end = t0 + (k + 1) * dt
            space.step(dt)
        floes.time = t0 + int(n) * dt
        floes.n_steps += int(n)
        self.impulse = np.array([self._jx, self._jy])
        if n and not np.all(np.isfinite(floes.velocities)):
            raise FloatingPointError(f"non-finite floe state at t = {floes.time:.6g} s")

    def advance(self, duration: float) -> None:
        """Advance by ``duration`` [s] (rounded to whole steps)."""
        self.step(int(round(duration / self.floes.dt)))

    @property
    def time(self) -> float:
        return self.floes.time

    def collisions(self) -> dict:
        """Finished hull–floe contacts as arrays, as
        :meth:`physics.ship.ShipState.collisions`: ``start`` and ``end``
        (ends of the first and of the first separated step) [s], ``floe``,
        ``impulse_surge``, ``impulse_sway`` on the hull [N s]."""
        rows = np.array(self._episodes, dtype=float).reshape(-1, 5)
        out = {name: rows[:, k].copy() for k, name in
               enumerate(("start", "end", "floe", "impulse_surge", "impulse_sway"))}
        out["floe"] = out["floe"].astype(np.int64)
        return out

    @property
    def hull_position(self) -> np.ndarray:
        return np.array(tuple(self.body.position), dtype=float)

    @property
    def collision_count(self) -> int:
        """Hull–floe contacts begun."""
        return len(self.hull_collisions)

    @property
    def touching(self) -> int:
        """Floes touching the hull now."""
        n = 0

        def count(arbiter):
            nonlocal n
            n += 1

        self.body.each_arbiter(count)
        return n


# ---------------------------------------------------------------------------
# Single impacts
# ---------------------------------------------------------------------------

def _floe(x, y, radius, thickness=THICKNESS):
    return FloeField(np.array([[x, y]], dtype=float), np.array([float(radius)]), thickness,
                     np.zeros((1, 2)))


def _contact(restitution, friction):
    return ContactParams(elastic_modulus=MODULUS, restitution=restitution, friction=friction)


def _impact_hull(feature: str) -> Hull:
    if feature == "edge":
        return Hull.box(10.0, 4.0)
    if feature == "vertex":
        return Hull.pointed(10.0, 4.0)
    raise ValueError(f"feature must be 'edge' or 'vertex', got {feature!r}")


IMPACT_BOX = 80.0          # side of the (walled) box of a single impact [m]
IMPACT_START = (20.0, 40.0)  # the hull's centroid at the start [m]
IMPACT_GAP = 0.05          # floe–bow gap at the start [m]


def hertz_hull_impact(feature: str, restitution: float, friction: float, speed: float,
                      radius: float = 1.0, steps_per_contact: int = 1000) -> dict:
    """A floe at rest hit head-on by a prescribed hull at ``speed`` in our
    Hertz engine: on the middle of the flat bow of ``Hull.box(10, 4)``
    (``feature="edge"``) or on the stem of ``Hull.pointed(10, 4)``
    (``"vertex"``), Δt the undamped contact time over ``steps_per_contact``.

    Returns a dict: ``impulse`` (2,) on the hull from the collision log
    (ship frame) [N s], ``collisions`` (rows of the log), ``velocity`` (2,)
    of the floe after the impact, ``mass``, ``dt`` and ``steps``.
    """
    hull = _impact_hull(feature)
    x0, y0 = IMPACT_START
    bow = float(hull.vertices[:, 0].max())
    field = _floe(x0 + bow + radius + IMPACT_GAP, y0, radius)
    law = _contact(restitution, friction)
    t_c = hull_contact_time(field.radii, THICKNESS, field.density, law, speed)
    dt = t_c / steps_per_contact
    ship = Ship(hull, 1.0e6, friction=friction, position=IMPACT_START, speed=speed,
                max_speed=max(10.0, speed))
    sim = HertzSimulation(field, WalledBox(IMPACT_BOX), law, None, dt, impact_speed=speed,
                          ship=ship)
    sim.advance(IMPACT_GAP / speed)
    touched = False
    for _ in range(400):
        sim.advance(0.25 * t_c)
        touching = sim.hull_contacts()[0].size > 0
        touched = touched or touching
        if touched and not touching:
            break
    else:
        raise RuntimeError("the Hertz hull impact did not end")
    sim.advance(t_c)
    log = sim.ship.collisions()
    return dict(impulse=np.array([log["impulse_surge"].sum(), log["impulse_sway"].sum()]),
                collisions=int(log["floe"].size), velocity=sim.velocities[0],
                mass=float(field.masses[0]), dt=dt, steps=sim.n_steps)


def pymunk_hull_impact(feature: str, restitution: float, friction: float, speed: float,
                       radius: float = 1.0, step_fraction: float = 1e-3,
                       iterations: int = 10) -> dict:
    """The impact of :func:`hertz_hull_impact` in pymunk: steps of
    ``step_fraction`` × r / v, until the floe has left the bow.

    Returns a dict: ``impulse`` (2,) on the hull, the floe's momentum change
    reversed [N s]; ``arbiter_impulse`` (2,) the sum of the post-solve
    impulses; ``collisions`` (contacts begun), ``velocity``, ``mass``, ``dt``,
    ``steps``; ``pair`` the set of (e, μ) of the hull–floe arbiters.
    """
    hull = _impact_hull(feature)
    x0, y0 = IMPACT_START
    bow = float(hull.vertices[:, 0].max())
    field = _floe(x0 + bow + radius + IMPACT_GAP, y0, radius)
    dt = step_fraction * radius / speed
    sim = PymunkShipSimulation(field, WalledBox(IMPACT_BOX), hull, IMPACT_START, speed,
                               restitution, friction, dt, iterations)
    # until the contact has begun and ended, then a quarter as long again
    steps = 0
    limit = int(math.ceil(3.0 * (IMPACT_GAP + radius) / (speed * dt))) + 10
    while steps < limit and not (sim.collision_count and not sim.touching):
        sim.step(1)
        steps += 1
    if sim.touching or not sim.collision_count:
        raise RuntimeError("the pymunk hull impact did not end")
    sim.step(steps // 4 + 1)
    m = float(field.masses[0])
    v = sim.floes.velocities[0]
    return dict(impulse=-m * v, arbiter_impulse=sim.impulse.copy(),
                collisions=sim.collision_count, velocity=v, mass=m, dt=dt,
                steps=sim.floes.n_steps, pair=set(sim.pair_values))


IMPACT_RESTITUTIONS = (0.3, 0.5, 0.9)


def single_impacts(out_dir: Path | None = None, quick: bool = False, seed: int = 0,
                   progress: bool = True, restitutions=IMPACT_RESTITUTIONS,
                   speed: float = 2.0, friction: float = FRICTION) -> list[Check]:
    """Head-on impacts of a floe (r = 1 m, h = 1 m, at rest) by the flat bow
    (edge) and by the stem (vertex) of a hull at ``speed``, for each
    restitution: the impulse on the hull in our Hertz engine (collision log;
    Δt = t_c/1000) against pymunk's (the floe's momentum change; Δt =
    10⁻³ r/v, 10 solver passes). Compared: the largest relative difference
    of the surge impulses over the restitutions (tolerance 10⁻³); the detail
    gives pymunk against the rigid law (1 + e) m v, the post-solve sum
    against the momentum change, and the sway impulses (zero by symmetry).

    pymunk gives (1 + e) m v to rounding (a head-on impulse is exact in one
    solver pass, whatever Δt). Our engine's impulse is (1 + e) m v within
    1.7·10⁻⁴ (at e = 0.3; 7·10⁻⁶ at e = 0.9), an error of the time step: at
    e = 0.3 it is 3.8·10⁻⁴, 1.7·10⁻⁴ and 2.6·10⁻⁵ at t_c/250, t_c/1000 and
    t_c/4000.
    """
    rows = []
    for feature in ("edge", "vertex"):
        worst = worst_pm_law = worst_hz_law = worst_arb = worst_sway = 0.0
        counts = []
        for e in restitutions:
            hz = hertz_hull_impact(feature, e, friction, speed)
            pm = pymunk_hull_impact(feature, e, friction, speed)
            law = -(1.0 + e) * pm["mass"] * speed
            worst = max(worst, abs(hz["impulse"][0] / pm["impulse"][0] - 1.0))
            worst_pm_law = max(worst_pm_law, abs(pm["impulse"][0] / law - 1.0))
            worst_hz_law = max(worst_hz_law, abs(hz["impulse"][0] / law - 1.0))
            worst_arb = max(worst_arb, float(np.max(np.abs(pm["arbiter_impulse"] - pm["impulse"])))
                            / abs(law))
            worst_sway = max(worst_sway, abs(hz["impulse"][1]) / abs(law),
                             abs(pm["impulse"][1]) / abs(law))
            counts.append((hz["collisions"], pm["collisions"]))
        name = "flat bow (edge of Hull.box(10, 4))" if feature == "edge" else \
            "stem (vertex of Hull.pointed(10, 4))"
        rows.append(Check(
            f"ship/impact/{feature}/hertz-vs-pymunk",
            f"head-on impact of a floe at rest by the {name} at {speed:g} m/s: largest relative "
            f"difference of the impulse on the hull, Hertz engine vs pymunk kinematic polygon",
            worst, 1e-3,
            detail=(f"e = {', '.join(f'{e:g}' for e in restitutions)}, μ = {friction:g}, r = 1 m; "
                    f"vs (1 + e) m v: Hertz {worst_hz_law:.2g} (Δt = t_c/1000), pymunk "
                    f"{worst_pm_law:.2g} (Δt = 10⁻³ r/v); pymunk post-solve sum vs momentum "
                    f"change {worst_arb:.2g}; sway impulse {worst_sway:.2g} of the surge one; "
                    f"collisions (Hertz, pymunk) {sorted(set(counts))}")))
    return rows


# ---------------------------------------------------------------------------
# A dilute field
# ---------------------------------------------------------------------------

#: the transit of the full check: hull (length, beam of Hull.pointed), speed,
#: channel, ice band, concentration in the band, floe radii, seeds
TRANSIT = dict(hull=(40.0, 10.0), speed=2.0, length=700.0, width=40.0, band=(60.0, 660.0),
               concentration=0.1, radii=(1.0, 3.0), seeds=5)
#: the reduced transit of the quick report and the tests (a band of 200 m)
TRANSIT_QUICK = dict(TRANSIT, length=300.0, band=(60.0, 260.0))
#: acceptance of the seed comparison, |mean difference| / its standard error:
#: the two-sided 99 % quantile of Student's t with 4 degrees of freedom
TRANSIT_TOLERANCE = 4.6


def dilute_field(rng: np.random.Generator, *, width: float, band: tuple,
                 concentration: float, radii=(1.0, 3.0), thickness: float = THICKNESS
                 ) -> FloeField:
    """Floes at rest with radii uniform in ``radii`` [m], placed at random
    without overlap in the band x0 < x < x1 of a channel of ``width``,
    clear of its sides: radii are drawn until the discs cover
    ``concentration`` of the band (the last one overshoots it)."""
    x0, x1 = (float(b) for b in band)
    target = concentration * (x1 - x0) * width
    r: list[float] = []
    area = 0.0
    while area < target:
        r.append(float(rng.uniform(*radii)))
        area += math.pi * r[-1] ** 2
    r = np.array(r)
    pos = place_floes(r, WalledBox(x1 - x0, width), rng)
    pos[:, 0] += x0
    return FloeField(pos, r, thickness, np.zeros((r.size, 2)))


def _transit_setup(p: dict):
    """The hull, its start (stern 1 m off the back wall, on the centre line)
    and the run time (until the bow is 10 m beyond the band)."""
    hull = Hull.pointed(*p["hull"])
    stern = float(hull.vertices[:, 0].min())
    bow = float(hull.vertices[:, 0].max())
    start = (1.0 - stern, 0.5 * p["width"])
    duration = (p["band"][1] + 10.0 - (start[0] + bow)) / p["speed"]
    return hull, start, duration


def hertz_transit(field: FloeField, p: dict, *, restitution: float = RESTITUTION,
                  friction: float = FRICTION, modulus: float = MODULUS,
                  steps_per_contact: float = 25.0) -> dict:
    """The transit ``p`` (:data:`TRANSIT`) through ``field`` in our Hertz
    engine: a prescribed ``Hull.pointed(*p["hull"])`` at ``p["speed"]``
    from the stern 1 m off the back wall until the bow is 10 m beyond the
    band, in a :class:`~physics.domain.WalledBox`, no drag; e and μ for
    floe–floe, floe–wall and floe–hull contacts. Δt: the shortest undamped
    hull contact time at twice the ship speed over ``steps_per_contact``.

    Returns a dict: ``collisions`` (logged plus touching at the end),
    ``resistance`` (mean ice force against the motion over the run) [N],
    ``impulses`` (surge impulses of the logged collisions) [N s],
    ``duration`` [s], ``steps``, ``dt`` [s], ``wall`` (wall-clock seconds).
    """
    hull, start, duration = _transit_setup(p)
    v = p["speed"]
    law = ContactParams(elastic_modulus=modulus, restitution=restitution, friction=friction)
    t_c = hull_contact_time(field.radii, field.thickness, field.density, law, 2.0 * v)
    dt = t_c / steps_per_contact
    ship = Ship(hull, 1.0e9, friction=friction, position=start, speed=v)
    t0 = time.perf_counter()
    sim = HertzSimulation(field, WalledBox(p["length"], p["width"]), law, None, dt,
                          impact_speed=2.0 * v, ship=ship)
    sim.advance(duration)
    loads = sim.ship_loads()
    return dict(collisions=loads.collisions + int(sim.hull_contacts()[0].size),
                resistance=loads.resistance, impulses=sim.ship.collisions()["impulse_surge"],
                duration=sim.time, steps=sim.n_steps, dt=dt, wall=time.perf_counter() - t0)


def pymunk_transit(field: FloeField, p: dict, *, restitution: float = RESTITUTION,
                   friction: float = FRICTION, step_fraction: float = 0.005,
                   iterations: int = 10) -> dict:
    """The transit of :func:`hertz_transit` in pymunk
    (:class:`PymunkShipSimulation`), steps of ``step_fraction`` × r_min / v
    (the hull moves 0.5 % of the smallest radius a step). Returns the dict
    of :func:`hertz_transit` (collisions: contacts begun; resistance: minus
    the post-solve impulses along x over the run time)."""
    hull, start, duration = _transit_setup(p)
    v = p["speed"]
    dt = step_fraction * float(field.radii.min()) / v
    t0 = time.perf_counter()
    sim = PymunkShipSimulation(field, WalledBox(p["length"], p["width"]), hull, start, v,
                               restitution, friction, dt, iterations)
    sim.step(int(round(duration / dt)))
    return dict(collisions=sim.collision_count, resistance=-float(sim.impulse[0]) / sim.time,
                impulses=sim.collisions()["impulse_surge"], duration=sim.time,
                steps=sim.floes.n_steps, dt=dt, wall=time.perf_counter() - t0)


def transit_fields(p: dict, seed: int = 0) -> list[FloeField]:
    """The ``p["seeds"]`` fields of a transit (:func:`dilute_field`), from
    ``numpy.random.SeedSequence(seed + 21)``."""
    children = np.random.SeedSequence(seed + 21).spawn(int(p["seeds"]))
    return [dilute_field(np.random.default_rng(c), width=p["width"], band=p["band"],
                         concentration=p["concentration"], radii=p["radii"]) for c in children]


def seed_comparison(a, b) -> dict:
    """Two engines' values of one quantity on the same seeds (paired).

    Returns a dict: ``mean_a``, ``mean_b`` and their standard errors
    ``error_a``, ``error_b`` (seed-to-seed standard deviation / √n),
    ``difference`` (mean of a − b), ``paired_error`` (standard deviation of
    the per-seed differences / √n: the standard error of the difference,
    the two engines running the same fields), ``combined_error``
    (√(error_a² + error_b²), the error of two independent samples) and
    ``t`` = |difference| / paired_error.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != b.shape or a.ndim != 1 or a.size < 2:
        raise ValueError("need the two engines' values on the same two or more seeds")
    n = math.sqrt(a.size)
    d = a - b
    out = dict(mean_a=float(a.mean()), mean_b=float(b.mean()),
               error_a=float(a.std(ddof=1) / n), error_b=float(b.std(ddof=1) / n),
               difference=float(d.mean()), paired_error=float(d.std(ddof=1) / n))
    out["combined_error"] = math.hypot(out["error_a"], out["error_b"])
    diff, err = abs(out["difference"]), out["paired_error"]
    out["t"] = diff / err if err > 0.0 else (0.0 if diff == 0.0 else math.inf)
    return out


def dilute_transit(out_dir: Path | None = None, quick: bool = False, seed: int = 0,
                   progress: bool = True, params: dict | None = None,
                   tolerance: float = TRANSIT_TOLERANCE) -> list[Check]:
    """A pointed hull through a dilute field, in both engines, over seeds.

    :data:`TRANSIT` (``quick``: :data:`TRANSIT_QUICK`; or ``params``):
    ``Hull.pointed(40, 10)`` at 2 m/s through floes at rest (radii uniform
    in 1–3 m, h = 1 m, A = 0.1 in a band of 600 m, 200 m with ``quick``)
    in a walled channel 40 m wide, no drag, e = 0.5, μ = 0.1 for every
    contact; 5 fields, each run in both engines (:func:`hertz_transit`,
    :func:`pymunk_transit`). For (a) the hull–floe collisions and (b) the
    mean resistance over the run: the seed means of both engines and the
    mean of the per-seed differences over its standard error
    (:func:`seed_comparison`; tolerance :data:`TRANSIT_TOLERANCE`, the 99 %
    quantile of Student's t with 4 degrees of freedom; see the module
    docstring). The runs are chaotic (a floe's path after a floe–floe or
    corner contact depends on the contact law), so the per-seed values
    differ, as two realisations of the same transit; the fields being
    shared, the difference has a much smaller error than either engine's
    seed mean.
    """
    p = dict(params if params is not None else (TRANSIT_QUICK if quick else TRANSIT))
    fields = transit_fields(p, seed)
    hz, pm = [], []
    iterator = fields
    if progress:
        from tqdm.auto import tqdm

        iterator = tqdm(fields, desc="ship transit (seeds)", leave=False, dynamic_ncols=True)
    for field in iterator:
        hz.append(hertz_transit(field, p))
        pm.append(pymunk_transit(field, p))
    n_floes = [f.n for f in fields]
    impulse_hz = np.concatenate([r["impulses"] for r in hz])
    impulse_pm = np.concatenate([r["impulses"] for r in pm])
    common = (f"Hull.pointed{tuple(p['hull'])} at {p['speed']:g} m/s, channel {p['length']:g} m "
              f"× {p['width']:g} m, band {tuple(p['band'])}, A = {p['concentration']:g}, radii "
              f"{tuple(p['radii'])} m, {min(n_floes)}–{max(n_floes)} floes, {len(fields)} seeds, "
              f"e = {RESTITUTION:g}, μ = {FRICTION:g}, no drag; Hertz E = {MODULUS:.0e} Pa, "
              f"Δt = {hz[0]['dt']:.2g} s; pymunk Δt = {pm[0]['dt']:.2g} s; mean surge impulse "
              f"of a collision {-impulse_hz.mean():.4g} / {-impulse_pm.mean():.4g} N s; wall "
              f"time {sum(r['wall'] for r in hz):.1f} s / {sum(r['wall'] for r in pm):.1f} s "
              f"(Hertz / pymunk)")
    figures: list[str] = []
    rows, values = [], {}
    for key, label, scale, unit in (("collisions", "hull–floe collisions", 1.0, ""),
                                    ("resistance", "mean resistance", 1e-3, " kN")):
        a = np.array([r[key] for r in hz]) * scale
        b = np.array([r[key] for r in pm]) * scale
        c = seed_comparison(a, b)
        values[key] = (a, b)
        rows.append(Check(
            f"ship/transit/{key}",
            f"pointed hull through a dilute field: {label}, Hertz engine vs pymunk kinematic "
            f"polygon, |mean per-seed difference| over its standard error", c["t"], tolerance,
            unit="σ",
            detail=(f"Hertz {c['mean_a']:.4g} ± {c['error_a']:.2g}{unit}, pymunk "
                    f"{c['mean_b']:.4g} ± {c['error_b']:.2g}{unit} (seed means ± standard "
                    f"errors); difference {c['difference']:+.3g} ± {c['paired_error']:.2g}{unit} "
                    f"({c['difference'] / c['mean_b']:+.2%}; vs the unpaired error "
                    f"{c['combined_error']:.2g}{unit}: "
                    f"{abs(c['difference']) / c['combined_error']:.2f} σ); per seed Hertz "
                    f"{np.round(a, 3).tolist()}, pymunk {np.round(b, 3).tolist()}; {common}"),
            figures=figures))
    if out_dir is not None:
        figures.append(_transit_figure(out_dir, values, p))
    return rows


def _transit_figure(out_dir, values, p) -> str:
    from .pymunk_checks import new_figure

    fig, axes = new_figure((10.0, 4.0), ncols=2)
    for ax, (key, label) in zip(axes, (("collisions", "hull–floe collisions"),
                                       ("resistance", "mean resistance [kN]"))):
        a, b = values[key]
        seeds = np.arange(a.size)
        ax.plot(seeds, a, "o", mfc="none", label="Hertz engine")
        ax.plot(seeds, b, "x", ms=7, label="pymunk (kinematic hull)")
        ax.set_xticks(seeds)
        ax.set_xlabel("field (seed)")
        ax.set_ylabel(label)
        ax.legend(fontsize=8)
    axes[0].set_title(f"Hull.pointed{tuple(p['hull'])} at {p['speed']:g} m/s, "
                      f"A = {p['concentration']:g}", fontsize=9)
    return save_figure(fig, out_dir, "pymunk_ship_transit.png")


# ---------------------------------------------------------------------------

def run(out_dir: Path | None = None, quick: bool = False, seed: int = 0,
        progress: bool = True) -> list[Check]:
    """Every ship comparison with pymunk (``quick``: a shorter channel)."""
    out = Path(out_dir) if out_dir is not None else None
    rows: list[Check] = []
    for check in (single_impacts, dilute_transit):
        rows += check(out, quick=quick, seed=seed, progress=progress)
    return rows
