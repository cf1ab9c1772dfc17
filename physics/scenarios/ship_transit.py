"""A ship crossing a band of pack ice on the Hertz engine (:ref:`physics-ship`):
``ship-transit``.

The full-scale platform supply vessel (:func:`physics.ship.psv_ship`, 76.2 m
× 18 m) sails along a channel (rigid walls ahead and behind, periodic
across) through a band of floes at rest with open water before and after
it. Floes of the Herman (2013) material (h = 1.5 m, its contact law) have
power-law diameters (exponent 1.8, mean ``mean_diameter``, largest over
smallest ``size_ratio``) or log-normal ones (a log-normal law of the
diameter, not AUTO-IceNav's law of the log-mass: see
:mod:`physics.ice_fields`). One run per (concentration, speed, mode, wind):

* a concentration sweep at ``reference_speed`` and a speed sweep at
  ``reference_concentration``;
* ``prescribed`` mode: the surge speed is held at the case's speed whatever
  the ice does; ``dynamic`` mode: a constant thrust ``T = X_u v + X_uu v²``
  that gives the case's speed v in open water (the surge damping of
  :meth:`physics.ship.ShipHydrodynamics.fossen_supply`), a heading autopilot
  (yaw moment −I_z (ω² Δψ + 2 ω r), ω = 0.1 rad/s, within the ship's
  bound) and nothing else: the ice slows the ship and can stop it;
* without wind, or with an onshore wind of ``wind_speed`` blowing across the
  channel onto the ship's port side (−y); the floes then start at their
  free-drift velocity (no spin-up) and the drifting pack presses against
  the hull. Water drag acts in both; Coriolis is left out (a transit lasts
  minutes).

The beset sweep (``sides`` ``walls`` or ``both``): in the periodic channel
the onshore wind only drifts the pack across and the ship shoves a plug of
ice into the open water ahead, so nothing compresses the ice and the ship is
never beset. The walled variant closes the channel with rigid walls on all
four sides (``Box(lx, ly, periodic=(False, False))``): the lee wall at
y = 0 is the coast the onshore wind presses the pack against, the band runs
to ``wall_gap`` (default 0) short of the wall ahead, and the ship starts
with its centre line at ``ship_offset`` (default 1/3) of the width from the
coast, in the pressed ice. The floes touch the walls with the wall contact
law; the hull does not touch walls, so a run ends (with a note) if the hull
comes within :data:`WALL_CLEARANCE` of one, and a transit ends (completed,
not beset) with the bow ``walled_finish`` (default 80 m, about a ship
length) short of the wall ahead: closer to it any pack is squeezed against
that wall and besets the ship. The ice the ship displaces
cannot escape across the channel: it is pushed ahead against the wall ahead
and around the hull into the wake. One dynamic run per concentration of
``walled_concentrations`` at the weak thrust of ``walled_speed`` (default
0.25 m/s, 19 kN) and each wind setting. The wind itself adds little: its
line load on a pack of fetch F is about τ_a F, τ_a = ρ_a C_a U² ≈ 0.25 Pa
at 10 m/s (skin drag alone), some 50 N/m across a 200 m channel, 4 kN
along the hull, against a thrust of 19 kN.

The ice band ends where the floes end: its length is set so that the floes
cover exactly the case's concentration of it. Above ``placement_limit`` the
floes are placed at that concentration in a periodic box and compressed
affinely with FIRE relaxation (:func:`physics.jamming.compress_floes`), as
in ``herman2013-wind``. A band with open water before and after it cannot
be jammed: released at its free edges, the overlaps of a jammed packing
would burst it apart. A concentration at which the compressed floes overlap
by more than 1 % of a radius is therefore an error (the power-law fields
here jam near 0.87).

Measured in the window where the whole hull is inside the band (bow
between x0 + L and x1; the ship's length L): the resistance (time mean of
the ice force against surge) with its standard error from 20 blocks, the
mean surge speed, the sway force and yaw moment, the collisions and their
impulses. A dynamic ship is *beset* when its surge speed stays below
``beset_speed`` for ``beset_time``; the run ends there, its speed loss is 1,
and the beset concentration of a sweep is the lowest concentration at
which the ship was beset.

Output per run: the track every ``output_interval`` (pose, velocities, the
ice loads averaged over the interval, their largest magnitude), the
collision log (dimension ``collision``: start, end, floe, impulse on the
hull, first contact point in the ship frame, floe mass, peak force), the
window statistics as results, and snapshots with the floe–floe force
chains when the bow passes ``snapshot_at`` of the band and at the end.

The time step is a tenth of the shortest Hertz contact time of the
smallest floe hitting the hull or another floe at (1 + e) × the ship's
speed (a floe knocked ahead leaves at up to that speed), and never above
the Herman (2013) Δt scaled by ``stiffness_scale``^(−2/5)
(:func:`physics.hertz.ship_time_step`). With the true material
(``stiffness_scale`` = 1) that is about 1 ms at 1–4 m/s.
"""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from ..domain import Box
from ..engine import FloeEngine
from ..floes import (FloeField, PlacementError, max_overlap, place_floes, power_law_diameters,
                     spatial_order)
from ..forcing import steady_drift
from ..hertz import HertzSimulation, ship_time_step
from ..hull_contact import LOG_COLUMNS
from ..ice_resistance import power_law_fit
from ..params import HERMAN2013
from ..ice_fields import (AUTO_ICENAV_SIZES, TransitBox, covering_areas, place_then_compress,
                          scaled_placement)
from ..ship import psv_ship, research_ship
from . import plots
from .experiment import Experiment, register
from .herman2013 import advance, contact_law

#: open water between the bow at the start and the ice [m]
LEAD_IN = 10.0
#: open water between the bow at the end of a run and the wall ahead [m]
OPEN_WATER_AHEAD = 80.0
#: distance of the stern from the wall behind at the start [m]
STERN_CLEARANCE = 5.0
#: least distance of the bow from the wall ahead in a channel closed across [m]
WALL_CLEARANCE = 5.0
#: natural frequency of the heading autopilot of a dynamic ship [rad/s]
AUTOPILOT_FREQUENCY = 0.1
#: blocks of the standard error of the resistance
ERROR_BLOCKS = 20

MODES = {"both": ("prescribed", "dynamic"), "prescribed": ("prescribed",),
         "dynamic": ("dynamic",)}
WINDS = {"both": (False, True), "off": (False,), "on": (True,)}
SIDES = {"both": ("periodic", "walls"), "periodic": ("periodic",), "walls": ("walls",)}

TRACK_VARIABLES = {
    "x": ("m", "x of the ship's centroid (along the channel)"),
    "y": ("m", "y of the ship's centroid (across the channel, not wrapped)"),
    "heading": ("rad", "heading, anticlockwise from +x"),
    "surge": ("m/s", "surge speed u"),
    "sway": ("m/s", "sway speed v (to port)"),
    "yaw_rate": ("rad/s", "yaw rate r"),
    "bow_x": ("m", "x of the bow"),
    "ice_surge": ("N", "ice force on the hull along surge, mean over the output interval"),
    "ice_sway": ("N", "ice force on the hull along sway (to port), mean over the interval"),
    "ice_moment": ("N m", "ice yaw moment on the hull, mean over the interval"),
    "ice_force_max": ("N", "largest ice force magnitude of a step in the interval"),
    "ice_power": ("W", "power of the hull on the ice, mean over the interval"),
    "hull_contacts": ("1", "floes touching the hull, mean over the interval"),
    "in_window": ("1", "fraction of the interval with the whole hull inside the band"),
    "yaw_moment": ("N m", "commanded yaw moment of the autopilot (dynamic mode)"),
}
COLLISION_VARIABLES = {
    "collision_start": ("s", "time at which a collision (a hull-floe contact) began"),
    "collision_end": ("s", "time at which it ended"),
    "collision_floe": ("1", "the floe (index into the floe dimension)"),
    "impulse_surge": ("N s", "impulse of the collision on the hull along surge"),
    "impulse_sway": ("N s", "impulse on the hull along sway (to port)"),
    "impulse": ("N s", "magnitude of the impulse on the hull"),
    "impact_x": ("m", "first contact point in the ship frame, forward of the centroid"),
    "impact_y": ("m", "first contact point in the ship frame, to port of the centroid"),
    "collision_floe_mass": ("kg", "mass of the floe"),
    "collision_peak_force": ("N", "largest contact force of the collision"),
}
RESULT_VARIABLES = {
    "resistance": ("N", "mean ice force against surge in the window (whole hull in the band)"),
    "resistance_error": ("N", f"standard error of the resistance from {ERROR_BLOCKS} blocks"),
    "mean_speed": ("m/s", "mean surge speed in the window"),
    "speed_loss": ("1", "1 - mean_speed / open-water speed (1 when beset)"),
    "mean_sway_force": ("N", "mean ice force along sway in the window"),
    "mean_moment": ("N m", "mean ice yaw moment in the window"),
    "max_force": ("N", "largest ice force magnitude of a step in the window"),
    "energy_to_ice": ("J", "work of the hull on the ice in the window"),
    "window_collisions": ("1", "collisions that ended in the window"),
    "mean_impulse": ("N s", "mean impulse magnitude of those collisions"),
    "max_impulse": ("N s", "largest impulse magnitude of those collisions"),
    "window_time": ("s", "time the whole hull spent inside the band"),
    "window_complete": ("1", "1 if the ship sailed through the whole window"),
    "beset": ("1", "1 if the ship was beset (dynamic mode)"),
    "beset_time": ("s", "time at which the ship was beset (NaN: never)"),
    "beset_distance": ("m", "distance of the bow into the band when beset (NaN: never)"),
    "transit_time": ("s", "time from the bow entering the band to the stern leaving it"),
    "completed": ("1", "1 if the stern left the band"),
    "thrust": ("N", "constant thrust of a dynamic ship (0: prescribed)"),
    "open_water_speed": ("m/s", "the case's speed (a dynamic ship's speed in open water)"),
    "n_floes": ("1", "number of floes"),
    "band_start": ("m", "x0: where the ice band begins"),
    "band_end": ("m", "x1: where it ends"),
    "band_concentration": ("1", "floe area over the band's area"),
    "channel_width": ("m", "width of the channel"),
    "ship_start_y": ("m", "y of the ship's centroid at the start (walled channel: from the lee "
                          "wall, the coast at y = 0)"),
    "hull_length": ("m", "length of the hull"),
    "dt": ("s", "time step"),
    "ice_drift": ("m/s", "free-drift speed of the mean floe in the wind (0 without)"),
}


# ---------------------------------------------------------------------------
# the ice, the ship and the simulation
# ---------------------------------------------------------------------------

#: the hulls a run can sail (the ``hull`` parameter; ship-transit sails the PSV)
SHIPS = {"psv": psv_ship, "research": research_ship}


def transit_ship(p: dict):
    """The ship builder of a run's ``hull`` (:data:`SHIPS`; the PSV without one)."""
    return SHIPS[p.get("hull", "psv")]


def floe_diameters(p: dict, target_area: float, rng: np.random.Generator) -> np.ndarray:
    """Diameters [m] in random order whose discs cover ``target_area``
    (the last one dropped if it would overshoot it): power-law (exponent of
    Herman 2013, mean ``mean_diameter``, d_max/d_min = ``size_ratio``) or
    log-normal (median ``lognormal_median``, σ of ln d ``lognormal_sigma``,
    clipped to 0.2–5 times the median as in :func:`physics.ice_fields.transit_field`)
    or AUTO-IceNav's (``"auto_icenav"``: :data:`physics.ice_fields.AUTO_ICENAV_SIZES`,
    the draws in order up to the first that covers the area)."""
    if p["sizes"] == "auto_icenav":
        # AUTO-IceNav's log-normal masses, radii clipped to 2-50 m
        return 2.0 * np.sqrt(covering_areas(AUTO_ICENAV_SIZES, target_area, rng) / math.pi)
    if p["sizes"] == "power":
        mean_area = 0.25 * math.pi * p["mean_diameter"] ** 2
        n = max(int(2.0 * target_area / mean_area), 16)
        draw = lambda k: power_law_diameters(k, HERMAN2013.fsd_exponent, p["mean_diameter"],  # noqa: E731
                                             method="random", size_ratio=p["size_ratio"],
                                             rng=rng)
    else:
        median, sigma = p["lognormal_median"], p["lognormal_sigma"]
        n = max(int(2.0 * target_area / (0.25 * math.pi * median ** 2)), 16)
        draw = lambda k: np.clip(median * np.exp(sigma * rng.standard_normal(k)),  # noqa: E731
                                 0.2 * median, 5.0 * median)
    d = rng.permutation(draw(n))
    while 0.25 * math.pi * np.sum(d ** 2) < target_area:
        d = np.concatenate([d, rng.permutation(draw(n))])
    area = np.cumsum(0.25 * math.pi * d ** 2)
    return d[: max(int(np.searchsorted(area, target_area, side="right")), 1)]


def hull_extent(hull) -> tuple[float, float]:
    """(bow, stern): distances of the bow and the stern from the centroid [m]."""
    return float(hull.vertices[:, 0].max()), float(-hull.vertices[:, 0].min())


def pack_ice(p: dict, concentration: float, seed: int, walls: bool = False):
    """The floe field and the transit channel of a run, and its geometry
    (a dict: band start and end, bow and stern offsets, ship start).

    ``walls``: the channel is closed across by rigid walls (the lee wall,
    the coast, at y = 0), the band runs to ``wall_gap`` short of the wall
    ahead and the ship starts with its centre line at ``ship_offset`` of
    the width from the coast; else the channel is periodic across, with
    open water after the band, and the ship starts on its centre line."""
    rng = np.random.default_rng(int(seed))
    width = float(p["channel_width"])
    d = floe_diameters(p, concentration * p["band_length"] * width, rng)
    r = 0.5 * d
    area = math.pi * float(np.sum(r ** 2))
    band = area / (concentration * width)           # the floes cover exactly A of it
    limit = p["placement_limit"]
    walls = bool(walls)
    if concentration <= limit:
        pos = place_floes(r, Box(band, width, periodic=(False, not walls)), rng)
    elif walls:
        raise PlacementError(
            f"concentration {concentration:g} is above placement_limit = {limit:g}: the floes "
            f"of a channel closed by walls across are placed directly, up to placement_limit "
            f"(the power-law fields cannot be placed between walls at 0.85: use at most 0.8)")
    else:
        place = scaled_placement(r, (band, width), concentration, rng,
                                 thickness=HERMAN2013.thickness,
                                 density=HERMAN2013.forcing.ice_density)
        packed, box1, _ = place_then_compress(place, concentration, limit)
        worst = max_overlap(packed.positions, r, box1)
        if worst > 0.01:
            # a jammed packing: released at the band's free edges it would
            # burst into the open water
            raise PlacementError(
                f"concentration {concentration:g} is above the jamming point of this floe "
                f"field (compressed to it, floes overlap by up to {worst:.2g} of the smaller "
                f"radius): a band with open water around it cannot hold it; choose a lower "
                f"concentration (the fields of this scenario jam near 0.87)")
        pos = np.mod(packed.positions, [band, width])
    bow, stern = hull_extent(transit_ship(p)().hull)
    x_ship = STERN_CLEARANCE + stern
    x0 = x_ship + bow + LEAD_IN
    x1 = x0 + band
    end_bow = x1 + bow + stern                      # the stern leaves the band
    pos = pos + [x0, 0.0]
    if walls:
        # rigid walls on all four sides: the lee wall (the coast) at y = 0
        box = Box(x1 + p["wall_gap"], width, periodic=(False, False))
        end_bow = min(end_bow, x1 + p["wall_gap"] - max(p["walled_finish"], WALL_CLEARANCE))
        y_ship = p["ship_offset"] * width
    else:
        box = TransitBox(end_bow + OPEN_WATER_AHEAD, width, band=(x0 - 1e-9, x1 + 1e-9))
        y_ship = 0.5 * width
    field = FloeField(pos, r, HERMAN2013.thickness, np.zeros((r.size, 2)),
                      density=HERMAN2013.forcing.ice_density)
    field = field.take(spatial_order(field.positions, box))
    geo = dict(x0=x0, x1=x1, bow=bow, stern=stern, length=bow + stern, x_ship=x_ship,
               y_ship=y_ship, end_bow=end_bow, concentration=area / (band * width))
    return field, box, geo


def open_water_thrust(ship, speed: float) -> float:
    """Thrust [N] that holds ``speed`` [m/s] in open water, ``X_u v + X_uu v²``."""
    h = ship.hydrodynamics
    return h.linear_damping[0] * speed + h.quadratic_damping[0] * speed * abs(speed)


def build_simulation(p: dict, case: dict, seed: int, *, skip_resting: bool = True):
    """(simulation, geometry, constants) of one run; ``skip_resting``: the
    engine skips the floes at rest (``HertzSimulation(skip_resting=...)``,
    the same result)."""
    c, v = float(case["concentration"]), float(case["speed"])
    walls = bool(case.get("walls", 0))
    field, box, geo = pack_ice(p, c, seed, walls)
    wind = float(case["wind"])
    # onshore wind across the channel onto the ship's port side; water drag
    # in every run, no Coriolis
    forcing = HERMAN2013.make_forcing(wind=(0.0, -wind), current=(0.0, 0.0), coriolis=0.0)
    drift = 0.0
    if wind > 0.0:
        u = steady_drift(forcing, field.radii, field.thickness, field.masses)
        field = FloeField(field.positions, field.radii, field.thickness, u,
                          density=field.density)
        drift = float(np.mean(np.hypot(u[:, 0], u[:, 1])))
    contact = contact_law(p)
    impact, dt = ship_time_step(field, box, contact, v, drift, HERMAN2013.time_step,
                                p["stiffness_scale"])
    dynamic = bool(case["dynamic"])
    ship = transit_ship(p)("dynamic" if dynamic else "prescribed",
                           position=(geo["x_ship"], geo["y_ship"]), speed=v,
                           friction=p["hull_friction"], max_speed=max(10.0, v))
    thrust = open_water_thrust(ship, v) if dynamic else 0.0
    if thrust > ship.max_thrust:
        raise ValueError(f"speed {v:g} m/s needs a thrust of {thrust / 1e3:.0f} kN in open "
                         f"water, above the ship's {ship.max_thrust / 1e3:.0f} kN")
    sim = HertzSimulation(field, box, contact, forcing, dt=dt, impact_speed=impact,
                          allow_overlap=c > p["placement_limit"], ship=ship,
                          skip_resting=skip_resting)
    if dynamic:
        sim.ship.command(thrust=thrust, yaw_moment=0.0)
    constants = dict(thrust=thrust, open_water_speed=v, n_floes=field.n, band_start=geo["x0"],
                     band_end=geo["x1"], band_concentration=geo["concentration"],
                     channel_width=box.ly, hull_length=geo["length"], dt=dt, ice_drift=drift,
                     ship_start_y=geo["y_ship"])
    return sim, geo, constants


def autopilot(ship_state, heading: float) -> float:
    """Yaw moment [N m] of the PD heading autopilot of a dynamic ship:
    −I_z (ω² (ψ − ψ_0) + 2 ω r) with the yaw inertia I_z including added
    mass, ω = :data:`AUTOPILOT_FREQUENCY` (critically damped)."""
    inertia = ship_state.ship.total_mass[2]
    w = AUTOPILOT_FREQUENCY
    err = math.remainder(ship_state.heading - heading, 2.0 * math.pi)
    return -inertia * (w * w * err + 2.0 * w * ship_state.yaw_rate)


# ---------------------------------------------------------------------------
# analysis helpers
# ---------------------------------------------------------------------------

def beset_concentration(concentration, beset) -> float:
    """The lowest concentration at which the ship was beset (NaN: never)."""
    c = np.asarray(concentration, dtype=float).ravel()
    b = np.asarray(beset, dtype=float).ravel() > 0.5
    return float(np.min(c[b])) if b.any() else math.nan


def _block_error(means, weights) -> float:
    """Standard error of a weighted mean from up to ERROR_BLOCKS blocks of
    consecutive intervals."""
    means, weights = np.asarray(means, float), np.asarray(weights, float)
    keep = weights > 0
    means, weights = means[keep], weights[keep]
    k = min(ERROR_BLOCKS, means.size)
    if k < 2:
        return math.nan
    parts = np.array_split(np.arange(means.size), k)
    block = np.array([np.average(means[i], weights=weights[i]) for i in parts])
    return float(block.std(ddof=1) / math.sqrt(k))


def _attach_collision_log(rec, st: dict) -> None:
    """Make ``rec.dataset()`` also hold the collision log of the run, as
    variables along a dimension ``collision``. (The recorder writes time
    series, snapshots and scalar results; the log is a table of its own.)"""
    cls_dataset = type(rec).dataset

    def dataset():
        ds = cls_dataset(rec)
        log = collision_table(st["log"])
        ds.coords["collision"] = ("collision", np.arange(log.shape[0]))
        cols = {name: log[:, k] for k, name in enumerate(LOG_COLUMNS)}
        values = {"collision_start": cols["start"], "collision_end": cols["end"],
                  "collision_floe": cols["floe"], "impulse_surge": cols["impulse_surge"],
                  "impulse_sway": cols["impulse_sway"],
                  "impulse": np.hypot(cols["impulse_surge"], cols["impulse_sway"]),
                  "impact_x": cols["point_x"], "impact_y": cols["point_y"],
                  "collision_floe_mass": cols["floe_mass"],
                  "collision_peak_force": cols["peak_force"]}
        for name, arr in values.items():
            units, description = COLLISION_VARIABLES[name]
            ds[name] = ("collision", np.asarray(arr, dtype=float),
                        {"units": units, "long_name": description})
        return ds
    rec.dataset = dataset


def collision_table(chunks) -> np.ndarray:
    """The logged collisions as one (K, len(LOG_COLUMNS)) array."""
    chunks = [np.asarray(c, dtype=float).reshape(-1, len(LOG_COLUMNS)) for c in chunks]
    return np.concatenate(chunks) if chunks else np.zeros((0, len(LOG_COLUMNS)))


# ---------------------------------------------------------------------------
# the experiment
# ---------------------------------------------------------------------------

@register("ship-transit")
class ShipTransit(Experiment):
    """A ship crossing a band of pack ice; see the module docstring."""

    variables = {**TRACK_VARIABLES, **COLLISION_VARIABLES, **RESULT_VARIABLES}
    required = ("time", "x", "y", "heading", "surge", "bow_x", "ice_surge", "ice_sway",
                "ice_moment", "collision_start", "collision_floe", "impulse", "impact_x",
                "impact_y", "collision_floe_mass", "resistance", "resistance_error",
                "speed_loss", "beset", "floe_x", "contact_force")
    case_label = "concentration"

    # -- runs ------------------------------------------------------------------
    def cases(self, p: dict) -> list[dict]:
        pairs = [(float(c), float(p["reference_speed"])) for c in p["concentrations"]]
        pairs += [(float(p["reference_concentration"]), float(v)) for v in p["speeds"]]
        pairs = list(dict.fromkeys(pairs))
        winds = [w for w in WINDS[p["wind"]] if not (w and p["wind_speed"] <= 0.0)] or [False]
        sides = SIDES[p["sides"]]
        out = []
        if "periodic" in sides:
            out += [{"concentration": c, "speed": v, "dynamic": int(mode == "dynamic"),
                     "wind": float(p["wind_speed"]) if w else 0.0, "walls": 0}
                    for mode in MODES[p["modes"]] for w in winds for c, v in pairs]
        if "walls" in sides and "dynamic" in MODES[p["modes"]]:
            # the beset sweep: a dynamic ship at walled_speed in the channel
            # closed across, its band of ice running to the wall ahead
            out += [{"concentration": float(c), "speed": float(p["walled_speed"]), "dynamic": 1,
                     "wind": float(p["wind_speed"]) if w else 0.0, "walls": 1}
                    for w in winds for c in dict.fromkeys(p["walled_concentrations"])]
        if not out:
            raise ValueError("sides = 'walls' runs only the dynamic ship (the beset sweep): "
                             "choose modes 'dynamic' or 'both'")
        return out

    def workload(self, p: dict, case: dict) -> float:
        # floes × steps: floes ∝ A, steps ∝ 1/(v dt) with dt ∝ v^(-1/5)
        return (float(case["concentration"]) * p["band_length"] * p["channel_width"]
                * float(case["speed"]) ** -0.8 * (2.0 if case["dynamic"] else 1.0))

    def simulate(self, p: dict, case: dict, seed: int, rec) -> None:
        st = rec.restore()
        if st is None:
            sim, geo, constants = build_simulation(p, case, seed)
            rec.result(**constants)
            st = dict(sim=sim, geo=geo, heading=float(sim.ship.heading), log=[], error=None,
                      slow_since=None, beset_time=None, snap_taken=False, window=[],
                      entered=None, left=None,
                      snapshot_x=geo["x0"] + p["snapshot_at"] * (geo["x1"] - geo["x0"]))
            self._record(rec, st, np.zeros(0), _no_records(sim))
            rec.progress(0.0)
            rec.checkpoint(st)
        _attach_collision_log(rec, st)
        sim, geo = st["sim"], st["geo"]
        v = float(case["speed"])
        nominal = (geo["end_bow"] - geo["x_ship"] - geo["bow"]) / v
        max_time = p["max_time_factor"] * nominal
        while st["error"] is None and st["beset_time"] is None:
            bow_x = sim.ship.position[0] + geo["bow"] * math.cos(sim.ship.heading)
            if bow_x >= geo["end_bow"] or sim.time >= max_time - 0.5 * sim.dt:
                break
            st["error"] = advance(sim, min(p["output_interval"], max_time - sim.time))
            if st["error"] is None and not all(sim.box.periodic):
                st["error"] = _hull_at_wall(sim)
            records = sim.ship.records()
            log = sim.ship.collisions()
            st["log"].append(np.column_stack([log[k] for k in LOG_COLUMNS]).astype(float))
            sim.ship.clear()
            self._record(rec, st, records["time"], records)
            if case["dynamic"]:
                self._control(p, st)
            rec.progress(min(1.0, max(sim.time / max_time,
                                      (self._bow(st) - geo["x_ship"] - geo["bow"])
                                      / (geo["end_bow"] - geo["x_ship"] - geo["bow"]))))
            rec.checkpoint(st)
        self._finish(p, case, st, rec, max_time)

    @staticmethod
    def _bow(st) -> float:
        ship = st["sim"].ship
        return float(ship.position[0] + st["geo"]["bow"] * math.cos(ship.heading))

    def _record(self, rec, st, t, r) -> None:
        """One output: the pose now, the loads averaged over the steps ``r``
        of the interval, the window bookkeeping and the snapshots."""
        sim, geo = st["sim"], st["geo"]
        ship = sim.ship
        n = len(t)
        bow_steps = r["x"] + geo["bow"] * np.cos(r["heading"]) if n else np.zeros(0)
        inside = (bow_steps >= geo["x0"] + geo["length"]) & (bow_steps <= geo["x1"])
        force = np.hypot(r["ice_surge"], r["ice_sway"]) if n else np.zeros(0)
        if n:
            # per-interval sums over the window steps (for the window statistics)
            w = inside
            st["window"].append([float(w.sum()), float(np.sum(-r["ice_surge"][w])),
                                 float(np.sum(r["surge"][w])), float(np.sum(r["ice_sway"][w])),
                                 float(np.sum(r["ice_moment"][w])),
                                 float(force[w].max()) if w.any() else 0.0,
                                 float(np.sum(r["ice_power"][w]) * sim.dt),
                                 float(t[w][0] - sim.dt) if w.any() else math.nan,
                                 float(t[w][-1]) if w.any() else math.nan])
            entered = np.nonzero(bow_steps >= geo["x0"])[0]
            if st["entered"] is None and entered.size:
                st["entered"] = float(t[entered[0]])
            left = np.nonzero(bow_steps >= geo["end_bow"])[0]
            if st["left"] is None and left.size:
                st["left"] = float(t[left[0]])
        mean = (lambda a: float(np.mean(a))) if n else (lambda a: 0.0)
        bow = self._bow(st)
        rec.record(sim.time, x=ship.position[0], y=ship.position[1], heading=ship.heading,
                   surge=ship.surge, sway=ship.sway, yaw_rate=ship.yaw_rate, bow_x=bow,
                   ice_surge=mean(r["ice_surge"]), ice_sway=mean(r["ice_sway"]),
                   ice_moment=mean(r["ice_moment"]),
                   ice_force_max=float(force.max()) if n else 0.0,
                   ice_power=mean(r["ice_power"]), hull_contacts=mean(r["contacts"]),
                   in_window=float(inside.mean()) if n else 0.0,
                   yaw_moment=ship.commands.get("yaw_moment", 0.0))
        if not st["snap_taken"] and bow >= st["snapshot_x"]:
            st["snap_taken"] = True
            _snapshot(rec, sim)

    def _control(self, p, st) -> None:
        """Autopilot and besetting of a dynamic ship, once per output."""
        sim = st["sim"]
        ship = sim.ship
        ship.command(yaw_moment=autopilot(ship, st["heading"]))
        if ship.surge < p["beset_speed"] and self._bow(st) > st["geo"]["x0"]:
            if st["slow_since"] is None:
                st["slow_since"] = sim.time
            elif sim.time - st["slow_since"] >= p["beset_time"] - 1e-9:
                st["beset_time"] = sim.time
        else:
            st["slow_since"] = None

    def _finish(self, p, case, st, rec, max_time) -> None:
        sim, geo = st["sim"], st["geo"]
        if not rec.snapshots or rec.snapshots[-1]["time"] < sim.time:
            _snapshot(rec, sim)
        win = np.array(st["window"], dtype=float).reshape(-1, 9)
        steps = win[:, 0]
        total = float(steps.sum())
        log = collision_table(st["log"])
        beset = st["beset_time"] is not None
        v = float(case["speed"])
        res = dict(beset=float(beset), completed=float(st["left"] is not None),
                   beset_time=st["beset_time"] if beset else math.nan,
                   beset_distance=(self._bow(st) - geo["x0"]) if beset else math.nan,
                   transit_time=(st["left"] - st["entered"]) if st["left"] is not None
                   and st["entered"] is not None else math.nan,
                   window_time=total * sim.dt,
                   window_complete=float(self._bow(st) > geo["x1"]))
        if total > 0:
            with np.errstate(invalid="ignore", divide="ignore"):
                res_means = win[:, 1] / steps
            start, end = np.nanmin(win[:, 7]), np.nanmax(win[:, 8])
            sel = (log[:, 1] > start) & (log[:, 1] <= end)
            imp = np.hypot(log[sel, 3], log[sel, 4])
            mean_speed = float(win[:, 2].sum() / total)
            res.update(resistance=float(win[:, 1].sum() / total),
                       resistance_error=_block_error(res_means, steps),
                       mean_speed=mean_speed, speed_loss=1.0 - mean_speed / v,
                       mean_sway_force=float(win[:, 3].sum() / total),
                       mean_moment=float(win[:, 4].sum() / total),
                       max_force=float(win[:, 5].max()), energy_to_ice=float(win[:, 6].sum()),
                       window_collisions=float(sel.sum()),
                       mean_impulse=float(imp.mean()) if imp.size else 0.0,
                       max_impulse=float(imp.max()) if imp.size else 0.0)
        else:
            res.update({k: math.nan for k in ("resistance", "resistance_error", "mean_speed",
                                              "speed_loss", "mean_sway_force", "mean_moment",
                                              "max_force", "energy_to_ice", "mean_impulse",
                                              "max_impulse")}, window_collisions=0.0)
        if beset:
            res["speed_loss"] = 1.0
        rec.result(**res)
        if st["error"] is not None:
            rec.note(f"ended at t = {sim.time:.1f} s: {st['error']}")
        elif beset:
            rec.note(f"beset at t = {st['beset_time']:.1f} s, "
                     f"{res['beset_distance']:.0f} m into the band")
        elif st["left"] is None:
            rec.note(f"the stern had not left the band after {max_time:.0f} s "
                     f"(max_time_factor × the transit time at the open-water speed)")

    # -- summary ------------------------------------------------------------
    def summarise(self, ds, p: dict) -> list[tuple[str, str, str]]:
        rows = []
        for key, label in _groups(ds):
            conc = _sweep(ds, key, "concentration", p)
            v0 = _sweep_speed(p, key)
            if conc is not None:
                a, b = power_law_fit(conc["x"], conc["resistance"])
                fit = (f"a = {a / 1e3:.3g} kN, b = {b:.2f}" if np.isfinite(b) else
                       "no fit (fewer than two concentrations with a resistance window)")
                rows.append((f"{label}: R = a A^b at v = {v0:g} m/s",
                             f"{fit}; R = "
                             + ", ".join("—" if not np.isfinite(r) else f"{r / 1e3:.3g}"
                                         for r in conc["mean"]) + " kN at A = "
                             + ", ".join(f"{x:g}" for x in conc["xs"]),
                             "grows with A"))
            speed = _sweep(ds, key, "speed", p)
            if speed is not None:
                a, b = power_law_fit(speed["x"], speed["resistance"])
                rows.append((f"{label}: R = a v^b at A = {p['reference_concentration']:g}",
                             f"a = {a / 1e3:.3g} kN (m/s)^-b, b = {b:.2f}",
                             "b ≈ 2 for collisional (momentum-flux) resistance"))
            if key[0] and conc is not None:
                loss = ", ".join(f"{x:g}: {s:.2f}" for x, s in zip(conc["xs"], conc["loss"]))
                bc = beset_concentration(conc["xs"], conc["beset"])
                rows.append((f"{label}: speed loss by A (v = {v0:g} m/s in "
                             f"open water)", loss, "grows with A"))
                rows.append((f"{label}: beset concentration",
                             f"{bc:g}" if np.isfinite(bc) else
                             f"not beset up to A = {max(conc['xs']):g}",
                             "the pack pressed against the walls and the wall ahead besets the "
                             "ship" if key[2] else "—"))
                if key[2]:
                    with warnings.catch_warnings():     # runs never beset: all NaN
                        warnings.simplefilter("ignore", RuntimeWarning)
                        dist = np.nanmean(ds["beset_distance"].values[conc["cases"]], axis=1)
                    band = np.nanmean(ds["band_end"].values[conc["cases"]]
                                      - ds["band_start"].values[conc["cases"]], axis=1)
                    rows.append((f"{label}: bow's distance into the band when beset "
                                 f"(band length)",
                                 ", ".join(f"A = {x:g}: " + (f"{d:.0f} m" if np.isfinite(d)
                                                             else "not beset")
                                           + f" ({b_:.0f} m)"
                                           for x, d, b_ in zip(conc["xs"], dist, band)),
                                 "shorter in denser ice"))
        sway = _wind_sway(ds, _walls(ds) == 0)
        if sway:
            rows.append(("mean ice sway force without / with wind (periodic channel)", sway,
                         "the wind presses the pack onto the port side (sway force < 0)"))
        return rows

    # -- figures ------------------------------------------------------------
    def plot(self, ds, p: dict, out_dir: Path) -> list[Path]:
        out_dir = Path(out_dir)
        out = [self._plot_resistance(ds, p, out_dir), self._plot_impacts(ds, p, out_dir),
               self._plot_snapshot(ds, p, out_dir)]
        if np.any(ds.coords["dynamic"].values == 1):
            out.append(self._plot_dynamic(ds, p, out_dir))
        return [f for f in out if f is not None]

    def _plot_resistance(self, ds, p, out_dir):
        plt = plots.pyplot()
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
        for k, (sweep, xlabel, ref) in enumerate((
                ("concentration", "ice concentration A", f"v = {p['reference_speed']:g} m/s"),
                ("speed", "speed v [m/s] (open water for the dynamic ship)",
                 f"A = {p['reference_concentration']:g}"))):
            ax = axes[k]
            for i, (key, label) in enumerate(_groups(ds)):
                s = _sweep(ds, key, sweep, p)
                if s is None:
                    continue
                colour = f"C{i}"
                ax.errorbar(s["xs"], s["mean"] / 1e3, yerr=s["err"] / 1e3, marker="o" if not
                            key[0] else "s", ls="none", color=colour, capsize=2,
                            label=label + (f", v₀ = {p['walled_speed']:g} m/s" if key[2]
                                           else ""))
                a, b = power_law_fit(s["x"], s["resistance"])
                if np.isfinite(b):
                    xx = np.geomspace(min(s["xs"]), max(s["xs"]), 50)
                    ax.plot(xx, a * xx ** b / 1e3, color=colour, lw=1,
                            ls="-" if not key[1] else "--", label=f"fit: b = {b:.2f}")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(xlabel)
            ax.set_ylabel("resistance R [kN]")
            ax.set_title(f"({'ab'[k]}) R against {sweep} at {ref}, "
                         f"fit R = a {'A' if k == 0 else 'v'}^b", fontsize=9)
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=7)
        return plots.savefig(fig, out_dir / "ship_resistance.png")

    def _plot_impacts(self, ds, p, out_dir):
        """Collision points on the hull (ship frame) coloured by impulse:
        the prescribed runs (else the dynamic ones) of the concentration
        sweep, one panel per wind setting."""
        from matplotlib.colors import LogNorm

        plt = plots.pyplot()
        hull = psv_ship().hull
        dyn = ds.coords["dynamic"].values
        mode = 0 if np.any(dyn == 0) else 1
        winds = sorted(set(ds.coords["wind"].values.tolist()))
        fig, axes = plt.subplots(len(winds), 1, figsize=(10, 3.2 * len(winds)), squeeze=False)
        imp_all = ds["impulse"].values
        finite = imp_all[np.isfinite(imp_all) & (imp_all > 0)]
        norm = LogNorm(vmin=max(float(np.percentile(finite, 1)), 1e-9) if finite.size else 1.0,
                       vmax=float(finite.max()) if finite.size else 10.0)
        sc = None
        for ax, w in zip(axes[:, 0], winds):
            cases = [c for c in range(ds.sizes["case"]) if dyn[c] == mode
                     and ds.coords["wind"].values[c] == w
                     and ds.coords["speed"].values[c] == p["reference_speed"]]
            pts = [(ds["impact_x"].values[c].ravel(), ds["impact_y"].values[c].ravel(),
                    ds["impulse"].values[c].ravel()) for c in cases]
            x, y, j = (np.concatenate(z) if pts else np.zeros(0) for z in zip(*pts)) \
                if pts else (np.zeros(0),) * 3
            ok = np.isfinite(x) & np.isfinite(j) & (j > 0)
            order = np.argsort(j[ok])
            verts = np.vstack([hull.vertices, hull.vertices[:1]])
            ax.fill(verts[:, 0], verts[:, 1], color="0.9", ec="k", lw=1)
            sc = ax.scatter(x[ok][order], y[ok][order], c=j[ok][order], s=8, cmap="inferno_r",
                            norm=norm)
            ax.set_aspect("equal")
            ax.set_xlabel("x, forward [m]")
            ax.set_ylabel("y, to port [m]")
            mode_name = "prescribed" if mode == 0 else "dynamic"
            ax.set_title(f"impact points on the hull, {mode_name} ship at "
                         f"{p['reference_speed']:g} m/s, A = "
                         + ", ".join(f"{a:g}" for a in sorted({float(ds.coords['concentration']
                                                                      .values[c])
                                                                for c in cases}))
                         + (f", wind {w:g} m/s onto port" if w > 0 else ", no wind")
                         + f" ({int(ok.sum())} collisions)", fontsize=8)
        if sc is not None:
            fig.colorbar(sc, ax=axes[:, 0].tolist(), label="impulse [N s]", shrink=0.9)
        fig.savefig(out_dir / "ship_hull_impacts.png", dpi=120, bbox_inches="tight")
        plt.close(fig)
        return out_dir / "ship_hull_impacts.png"

    def _plot_snapshot(self, ds, p, out_dir):
        """Floes, hull and floe–floe force chains around the hull at the
        mid-band snapshot of the densest prescribed run at the reference
        speed, without and with wind."""
        plt = plots.pyplot()
        picks = []
        for w in sorted(set(ds.coords["wind"].values.tolist())):
            walls = _walls(ds)
            cand = [c for c in range(ds.sizes["case"])
                    if ds.coords["wind"].values[c] == w
                    and ds.coords["speed"].values[c] == p["reference_speed"] and not walls[c]]
            cand = cand or [c for c in range(ds.sizes["case"])
                            if ds.coords["wind"].values[c] == w]
            if not cand:
                continue
            pres = [c for c in cand if ds.coords["dynamic"].values[c] == 0] or cand
            picks.append(max(pres, key=lambda c: ds.coords["concentration"].values[c]))
        fig, axes = plt.subplots(1, len(picks), figsize=(6.2 * len(picks), 5), squeeze=False)
        hull = psv_ship().hull
        for ax, c in zip(axes[0], picks):
            snap = ds.isel(case=c, member=0, snapshot=0)
            t_snap = float(snap["snapshot_time"])
            t = ds["time"].values[c, 0]
            k = int(np.nanargmin(np.abs(t - t_snap)))
            xs, ys, psi = (float(ds[v].values[c, 0, k]) for v in ("x", "y", "heading"))
            ly = float(snap["snapshot_ly"])
            ys_w = ys % ly
            verts = hull.world_vertices(xs, ys_w, psi)
            plots.draw_snapshot(ax, snap, forces=True)
            # the hull, and its periodic image if it crosses the channel's side
            for shift in (-ly, 0.0, ly):
                ax.fill(verts[:, 0], verts[:, 1] + shift, color="0.25", zorder=3)
            touch = _touching(snap, verts, ly)
            if touch.any():
                ax.scatter(snap["floe_x"].values[touch], snap["floe_y"].values[touch], s=6,
                           color="orange", zorder=4, label="floes on the hull")
                ax.legend(fontsize=7, loc="upper left")
            half = 0.9 * hull.length
            ax.set_xlim(xs - half, xs + half)
            ax.set_ylim(max(0.0, ys_w - 0.6 * half), min(ly, ys_w + 0.6 * half))
            mode = "dynamic" if ds.coords["dynamic"].values[c] else "prescribed"
            w = float(ds.coords["wind"].values[c])
            ax.set_title(f"{mode}, A = {float(ds.coords['concentration'].values[c]):g}, "
                         f"v = {float(ds.coords['speed'].values[c]):g} m/s, "
                         + (f"wind {w:g} m/s (-y)" if w > 0 else "no wind")
                         + f", t = {t_snap:.0f} s\nred: floe–floe force chains "
                           "(width ∝ √force), colour: floe speed", fontsize=9)
        return plots.savefig(fig, out_dir / "ship_force_chains.png")

    def _plot_dynamic(self, ds, p, out_dir):
        plt = plots.pyplot()
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
        for i, (key, label) in enumerate(_groups(ds)):
            if not key[0]:
                continue
            s = _sweep(ds, key, "concentration", p)
            if s is None:
                continue
            colour = f"C{i}"
            axes[0].plot(s["xs"], s["loss"], marker="s", color=colour, ls="--" if key[2] else "-",
                         label=label + f", v₀ = {_sweep_speed(p, key):g} m/s")
            bc = beset_concentration(s["xs"], s["beset"])
            if np.isfinite(bc):
                axes[0].axvline(bc, color=colour, ls=":", lw=1.2)
                axes[0].annotate(f"beset from A = {bc:g}", (bc, 1.0), color=colour, fontsize=8,
                                 xytext=(-4, -12 - 12 * i), textcoords="offset points",
                                 ha="right")
            for c in s["cases"]:
                bow = ds["bow_x"].values[c, 0] - float(ds["band_start"].values[c, 0])
                u = ds["surge"].values[c, 0]
                axes[1].plot(bow, u, color=colour, lw=0.8,
                             alpha=0.4 + 0.6 * float(ds.coords["concentration"].values[c]))
        axes[0].set_xlabel("ice concentration A")
        axes[0].set_ylabel("speed loss 1 − ū/v₀ (1: beset)")
        axes[0].set_ylim(-0.05, 1.1)
        if axes[0].get_legend_handles_labels()[0]:
            axes[0].legend(fontsize=7)
        axes[0].set_title(f"(a) dynamic ship, v₀: open-water speed; dotted: beset "
                          f"concentration\n(beset: u < {p['beset_speed']:g} m/s for "
                          f"{p['beset_time']:g} s)", fontsize=9)
        axes[1].axvline(0.0, color="0.5", lw=0.8)
        axes[1].set_xlabel("bow position from the start of the band [m]")
        axes[1].set_ylabel("surge speed u [m/s]")
        axes[1].set_title("(b) surge speed along the transit (darker: denser ice)", fontsize=9)
        return plots.savefig(fig, out_dir / "ship_speed_loss.png")


def _hull_at_wall(sim) -> str | None:
    """A message if the hull has come within :data:`WALL_CLEARANCE` of a
    wall of the box (the hull does not touch walls, so the run must end
    before it would), else None."""
    ship = sim.ship
    v = ship.ship.hull.world_vertices(ship.position[0], ship.position[1], ship.heading)
    for k, (length, per) in enumerate(zip((sim.box.lx, sim.box.ly), sim.box.periodic)):
        if not per and (v[:, k].min() < WALL_CLEARANCE or v[:, k].max() > length - WALL_CLEARANCE):
            return (f"the hull came within {WALL_CLEARANCE:g} m of a wall at "
                    f"{'xy'[k]} = {v[:, k].min():.1f}..{v[:, k].max():.1f} m (the hull does not "
                    f"touch walls)")
    return None


def _no_records(sim) -> dict:
    from ..hull_contact import RECORD_COLUMNS
    return {k: np.zeros(0) for k in RECORD_COLUMNS}


def _snapshot(rec, sim: FloeEngine) -> None:
    c = sim.contacts()
    rec.snapshot(sim.time, sim.positions, sim.radii, sim.velocities,
                 box=(sim.box.lx, sim.box.ly), contacts=(c.i, c.j, c.normal_force))


def _touching(snap, verts, ly) -> np.ndarray:
    """Floes of a snapshot whose discs reach the hull polygon ``verts``
    (world frame; periodic across with width ``ly``)."""
    x = np.asarray(snap["floe_x"], float)
    y = np.asarray(snap["floe_y"], float)
    r = np.asarray(snap["floe_radius"], float)
    ok = np.isfinite(x)
    out = np.zeros(x.shape, bool)
    for shift in (-ly, 0.0, ly):
        v = verts + [0.0, shift]
        a, b = v, np.roll(v, -1, axis=0)
        d = np.full(x.shape, np.inf)
        inside = np.ones(x.shape, bool)
        for p0, p1 in zip(a, b):
            e = p1 - p0
            px, py = x - p0[0], y - p0[1]
            s = np.clip((px * e[0] + py * e[1]) / (e @ e), 0.0, 1.0)
            d = np.minimum(d, np.hypot(px - s * e[0], py - s * e[1]))
            inside &= (e[0] * py - e[1] * px) >= 0.0
        out |= ok & (inside | (d < r))
    return out


def _walls(ds) -> np.ndarray:
    """1 for the runs in the channel closed across (0 for the periodic one)."""
    if "walls" in ds.coords:
        return np.nan_to_num(np.asarray(ds.coords["walls"].values, float)).astype(int)
    return np.zeros(ds.sizes["case"], int)


def _groups(ds):
    """((dynamic, wind, walls), label) of the mode × wind × sides groups present."""
    dyn = ds.coords["dynamic"].values
    wind = ds.coords["wind"].values
    keys = sorted({(int(d), float(w), int(s)) for d, w, s in zip(dyn, wind, _walls(ds))})
    return [(k, ("dynamic" if k[0] else "prescribed")
             + (f", wind {k[1]:g} m/s" if k[1] > 0 else ", no wind")
             + (", walled channel" if k[2] else "")) for k in keys]


def _sweep_speed(p: dict, key) -> float:
    """Speed of the concentration sweep of group ``key``."""
    return float(p["walled_speed"] if key[2] else p["reference_speed"])


def _sweep(ds, key, sweep: str, p: dict):
    """Cases of group ``key`` in the concentration sweep (at the reference
    speed) or the speed sweep (at the reference concentration), with their
    resistance (case × member), member means and standard errors; None when
    fewer than two cases."""
    dyn = ds.coords["dynamic"].values
    wind = ds.coords["wind"].values
    walls = _walls(ds)
    conc = ds.coords["concentration"].values
    speed = ds.coords["speed"].values
    if sweep == "concentration":
        sel = [c for c in range(ds.sizes["case"]) if (dyn[c], wind[c], walls[c]) == key
               and speed[c] == _sweep_speed(p, key)]
        xs = conc
    else:
        if key[2]:
            return None
        sel = [c for c in range(ds.sizes["case"]) if (dyn[c], wind[c], walls[c]) == key
               and conc[c] == p["reference_concentration"]]
        xs = speed
    sel = sorted(sel, key=lambda c: xs[c])
    if len(sel) < 2:
        return None
    r = ds["resistance"].values[sel]                 # (cases, members)
    x = np.repeat(xs[sel][:, None], r.shape[1], axis=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        mean = np.nanmean(r, axis=1)
        if r.shape[1] > 1:
            err = np.nanstd(r, axis=1, ddof=1) / np.sqrt(np.sum(np.isfinite(r), axis=1))
        else:
            err = ds["resistance_error"].values[sel][:, 0]
        loss = np.nanmean(ds["speed_loss"].values[sel], axis=1)
    beset = np.nan_to_num(ds["beset"].values[sel]).max(axis=1)
    return dict(cases=sel, xs=xs[sel], x=x, resistance=r, mean=mean,
                err=np.where(np.isfinite(err), err, 0.0), loss=loss,
                beset=np.where(beset > 0.5, 1.0, 0.0))


def _wind_sway(ds, keep=None) -> str:
    keep = np.ones(ds.sizes["case"], bool) if keep is None else np.asarray(keep, bool)
    wind = ds.coords["wind"].values[keep]
    if not (np.any(wind == 0) and np.any(wind > 0)):
        return ""
    f = ds["mean_sway_force"].values[keep]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        a, b = np.nanmean(f[wind == 0]), np.nanmean(f[wind > 0])
    return f"{a / 1e3:.3g} kN / {b / 1e3:.3g} kN"
