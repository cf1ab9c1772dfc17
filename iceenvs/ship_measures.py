"""What a ship environment measures after each step, for one environment or
for many at once.

Every ship environment ends a step with the same work:

1. read the ship's step records and collision log of the control interval
   into the *step loads* (forces, impulses, energy, effort, path);
2. add them to the episode's running sums (collisions, impulses, the floes
   hit, the time spent below the beset speed);
3. measure the pose, sense the ice ahead with the lidar
   (:func:`iceenvs.ship_sensors.lidar_scan`) and the ice around the hull
   (:meth:`physics.HertzSimulation.local_ice`);
4. after the reward, update the episode metrics (:func:`update_metrics`).

:func:`measure_ships` does steps 1-3 for a list of environments of one class
and configuration: the records and the lidar of all of them in one compiled
call (:func:`measure_many`, parallel over the environments), the loads and
sums in numpy over the environments. The result is one matrix, a row per
environment and a column per raw measurement (:func:`measure_names`). A
single environment is a list of one; the native vector environment
(:mod:`iceenvs.vector`) passes its sub-environments, so a sub-environment and
the single environment seeded alike compute the same numbers with the same
code. Per environment, Python only collects references to its engine's
arrays and calls the compiled local-ice measure.

Each environment's episode sums are one row of floats (columns
:data:`SUM_COLUMNS`) of its batch of episodes (:class:`iceenvs.step.Episodes`),
so that a batch updates them all at once.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange, types
from numba.typed import List

from physics.hertz import KernelLists
from physics.hertz_batch import ICE_NEAR, ice_near_many
from physics.hull_contact import LOG_COLUMNS, RECORD_COLUMNS

from .ship_sensors import LIDAR_SETTING, SCAN_BOX, box_entries, lidar_scan

__all__ = ["POSE", "LOADS", "LOCAL", "SUM_COLUMNS", "METRICS", "INTEGER_MEASURES",
           "SHIP_COLUMNS", "SCENE", "measure_names", "measure_ships", "measure_many", "step_sums",
           "update_metrics", "metric_values", "metric_columns", "info_columns"]

#: the pose entries of a measurement (ship frame; the goal lies along +x)
POSE = ("goal_distance", "goal_cos", "goal_sin", "channel_offset", "surge", "sway", "yaw_rate")
#: the step loads (see :mod:`iceenvs.ship_env`)
LOADS = ("ice_surge", "ice_sway", "ice_moment", "hull_pressure", "peak_hull_pressure",
         "step_impulse", "step_contact_impulse", "step_energy", "step_effort", "step_path",
         "step_collisions")
#: after the lidar: the episode's concentration, the ice around the hull, the
#: model time, whether the goal line is reached (1) or not (0) and the kinetic
#: energy of all the ice [J] (translation and rotation)
LOCAL = ("concentration", "local_concentration", "local_contacts", "local_pressure", "time",
         "reached", "ice_kinetic_energy")
#: the measurements whose values are counts
INTEGER_MEASURES = ("step_collisions",)

#: the episode metrics in ``info``
METRICS = ("success", "time", "path_length", "efficiency", "effort", "collisions",
           "collided_floes", "mean_impulse", "max_impulse", "impulse_per_metre",
           "energy_to_ice", "ice_resistance", "max_hull_pressure", "mean_mass_hit",
           "ice_energy_gain", "energy_dissipated")
#: the metrics that are counts, and the one that is a flag
_INTEGER_METRICS = ("collisions", "collided_floes")
#: a row of episode sums: the metrics, then the running sums behind them
#: (collisions and impulses of the finished collisions, distinct floes hit,
#: the mass and number of the mobile ones, time below the beset speed,
#: ∫ ice surge force dt, the ship's last recorded position, the ice's kinetic
#: energy at the start)
SUM_COLUMNS = METRICS + ("n_collisions", "impulse_total", "impulse_max", "n_floes_hit",
                         "mass_hit", "n_mobile_hit", "slow_time", "resistance_sum", "x", "y",
                         "ice_energy_start")
_C = {name: k for k, name in enumerate(SUM_COLUMNS)}
# the columns as constants of the compiled code
(_M_SUCCESS, _M_TIME, _M_PATH, _M_EFFICIENCY, _M_EFFORT, _M_COLLISIONS, _M_FLOES,
 _M_MEAN_IMPULSE, _M_MAX_IMPULSE, _M_IMPULSE_PER_METRE, _M_ENERGY, _M_RESISTANCE,
 _M_MAX_PRESSURE, _M_MEAN_MASS, _M_ICE_GAIN, _M_DISSIPATED) = (_C[name] for name in METRICS)
(_SUM_COLLISIONS, _SUM_IMPULSE, _SUM_IMPULSE_MAX, _SUM_FLOES_HIT, _SUM_MASS_HIT,
 _SUM_MOBILE_HIT, _SUM_SLOW, _SUM_RESISTANCE, _SUM_X, _SUM_Y, _SUM_ICE_START) = (
    _C[name] for name in SUM_COLUMNS[len(METRICS):])

# the columns of the ship's step records and collision log read here
(_X, _Y, _SURGE, _SWAY, _YAW_RATE, _ICE_SURGE, _ICE_SWAY, _ICE_MOMENT, _ICE_POWER, _NORMAL_FORCE,
 _FORCE_MAGNITUDE_SUM) = (RECORD_COLUMNS.index(name) for name in (
    "x", "y", "surge", "sway", "yaw_rate", "ice_surge", "ice_sway", "ice_moment", "ice_power",
    "normal_force", "force_magnitude_sum"))
_FLOE, _IMPULSE_SURGE, _IMPULSE_SWAY, _FLOE_MASS = (LOG_COLUMNS.index(name) for name in (
    "floe", "impulse_surge", "impulse_sway", "floe_mass"))

#: a ship's row of the parameters :func:`measure_many` reads: its motion
#: (x, y, heading, Vx, Vy, yaw rate, as :attr:`physics.ship.Ship.motion`),
#: its commands (thrust, yaw moment; read for a dynamic ship), the linear and
#: the quadratic damping coefficients of surge, sway and yaw, its engine's
#: time step, its hull length and its beset speed
SHIP_COLUMNS = ("x", "y", "heading", "vx", "vy", "yaw_rate", "thrust", "yaw_moment",
                "linear_surge", "linear_sway", "linear_yaw", "quadratic_surge", "quadratic_sway",
                "quadratic_yaw", "dt", "hull_length", "beset_speed")
#: what the ships of :func:`measure_many` share (a float array): the box
#: (:data:`~iceenvs.ship_sensors.SCAN_BOX`), the lidar
#: (:data:`~iceenvs.ship_sensors.LIDAR_SETTING`), the goal line, the
#: channel's centre line and half-width [m], the control interval [s], and
#: whether the engines have just advanced and whether the ships are dynamic
#: (1.0) or not (0.0)
SCENE = SCAN_BOX + LIDAR_SETTING + ("goal_x", "centre_y", "half_channel", "control_interval",
                                    "advanced", "dynamic")
# the columns and entries as constants of the compiled code (x, y, heading,
# Vx, Vy and yaw rate first; a range as its start and its end)
_THRUST, _YAW_MOMENT, _LINEAR, _QUADRATIC, _DT, _HULL_LENGTH, _BESET_SPEED = (
    SHIP_COLUMNS.index(name) for name in ("thrust", "yaw_moment", "linear_surge",
                                          "quadratic_surge", "dt", "hull_length", "beset_speed"))
_BOX, _LIDAR, _LIDAR_END = 0, len(SCAN_BOX), len(SCAN_BOX) + len(LIDAR_SETTING)
_SECTORS = _LIDAR + LIDAR_SETTING.index("sectors")
_GOAL_X, _CENTRE_Y, _HALF_CHANNEL, _CONTROL_INTERVAL, _ADVANCED, _DYNAMIC = (
    SCENE.index(name) for name in ("goal_x", "centre_y", "half_channel", "control_interval",
                                   "advanced", "dynamic"))
# where the pose, the step loads and the lidar (distance and concentration
# interleaved) start in a row of measurements
_AT_POSE, _AT_LOADS, _AT_LIDAR = 0, len(POSE), len(POSE) + len(LOADS)


def measure_names(sectors: int, extra: tuple[str, ...] = ()) -> tuple[str, ...]:
    """The raw measurements of a ship environment with a lidar of
    ``sectors`` sectors, in the order of :func:`measure_ships`' columns
    (``extra``: the environment's own, last)."""
    lidar = tuple(name for k in range(sectors)
                  for name in (f"lidar_distance_{k}", f"lidar_concentration_{k}"))
    return POSE + LOADS + lidar + LOCAL + tuple(extra)


@njit(cache=True, error_model="numpy")
def step_sums(rows, x0, y0, dynamic, thrust, yaw_moment, linear_damping, quadratic_damping):
    """Sums over the ship's step records ``rows`` of one control interval
    (one row per engine step, the columns of
    :data:`physics.hull_contact.RECORD_COLUMNS`), the ship at (x0, y0)
    before the first: of the ice surge force, sway force and moment, of the
    hull's normal force (and its largest value), of the magnitude of the
    resultant ice force, of the contacts' force magnitudes, of the power of
    the hull on the ice, of the effort's power (a ``dynamic`` ship: the
    thrust's and the yaw moment's, |T u| + |M r|; a prescribed one: the
    power against ice and water, ice power + Σ (b v + a |v| v) v over surge,
    sway and yaw rate with the linear and quadratic damping coefficients b,
    a), and the path length."""
    surge = sway = moment = normal = force = magnitude = energy = effort = path = 0.0
    peak = -math.inf
    px, py = x0, y0
    b, a = linear_damping, quadratic_damping
    for k in range(rows.shape[0]):
        row = rows[k]
        fx, fy, fn = row[_ICE_SURGE], row[_ICE_SWAY], row[_NORMAL_FORCE]
        surge += fx
        sway += fy
        moment += row[_ICE_MOMENT]
        normal += fn
        peak = max(peak, fn)
        force += math.hypot(fx, fy)
        magnitude += row[_FORCE_MAGNITUDE_SUM]
        energy += row[_ICE_POWER]
        u, v, r = row[_SURGE], row[_SWAY], row[_YAW_RATE]
        if dynamic:
            effort += abs(thrust * u) + abs(yaw_moment * r)
        else:
            effort += row[_ICE_POWER] + ((b[0] * u + a[0] * abs(u) * u) * u
                                         + (b[1] * v + a[1] * abs(v) * v) * v
                                         + (b[2] * r + a[2] * abs(r) * r) * r)
        path += math.hypot(row[_X] - px, row[_Y] - py)
        px, py = row[_X], row[_Y]
    return surge, sway, moment, normal, peak, force, magnitude, energy, effort, path


@njit(cache=True, parallel=True, error_model="numpy")
def measure_many(rows, ships, positions, radii, floe_start, scene, table, raw):
    """The compiled part of :func:`measure_ships` for M ships, parallel over
    them (each writes only its own rows).

    Ship k has the step records ``rows[k]`` (a typed list of arrays), the
    parameters ``ships[k]`` (:data:`SHIP_COLUMNS`), the floes
    ``positions[floe_start[k]:floe_start[k + 1]]`` and ``radii``
    (likewise) and its row of episode sums ``table[k]``; ``scene``
    (:data:`SCENE`) is what the ships share. Writes into its row of
    measurements ``raw[k]`` (the columns of :func:`measure_names`) the pose
    entries (:data:`POSE`), the lidar (a field of view of π cut into the
    scene's sectors) and, when the engines advanced, the step loads
    (:data:`LOADS` but the collisions; zero otherwise), and adds the step
    to the sums: the ship's last position, ∫ ice surge force dt and the
    time below the beset speed (a dynamic ship)."""
    advanced = scene[_ADVANCED] != 0.0
    dynamic = scene[_DYNAMIC] != 0.0
    goal_x, centre_y, half_channel = scene[_GOAL_X], scene[_CENTRE_Y], scene[_HALF_CHANNEL]
    lidar, box = scene[_LIDAR:_LIDAR_END], scene[_BOX:_LIDAR]
    sectors = int(scene[_SECTORS])
    for i in prange(ships.shape[0]):
        m = np.int64(i)                     # typed lists take signed indices
        ship = ships[m]
        x, y, psi, vx, vy, r = ship[0], ship[1], ship[2], ship[3], ship[4], ship[5]
        c, s = math.cos(psi), math.sin(psi)
        out = raw[m]
        out[_AT_POSE] = goal_x - x
        out[_AT_POSE + 1] = c
        out[_AT_POSE + 2] = -s
        out[_AT_POSE + 3] = (y - centre_y) / half_channel
        out[_AT_POSE + 4] = c * vx + s * vy
        out[_AT_POSE + 5] = -s * vx + c * vy
        out[_AT_POSE + 6] = r
        f0, f1 = floe_start[m], floe_start[m + 1]
        d, a = lidar_scan(ship, positions[f0:f1], radii[f0:f1], lidar, box)
        for j in range(sectors):
            out[_AT_LIDAR + 2 * j] = d[j]
            out[_AT_LIDAR + 2 * j + 1] = a[j]
        for j in range(_AT_LOADS, _AT_LIDAR):
            out[j] = 0.0
        rec = rows[m]
        n = rec.shape[0]
        if advanced and n > 0:
            surge, sway, moment, normal, peak, force, magnitude, energy, effort, path = step_sums(
                rec, table[m, _SUM_X], table[m, _SUM_Y], dynamic, ship[_THRUST],
                ship[_YAW_MOMENT], ship[_LINEAR:_LINEAR + 3], ship[_QUADRATIC:_QUADRATIC + 3])
            h = ship[_DT]
            length = ship[_HULL_LENGTH]
            out[_AT_LOADS] = surge / n
            out[_AT_LOADS + 1] = sway / n
            out[_AT_LOADS + 2] = moment / n
            out[_AT_LOADS + 3] = normal / n / length
            out[_AT_LOADS + 4] = peak / length
            out[_AT_LOADS + 5] = force * h
            out[_AT_LOADS + 6] = magnitude * h
            out[_AT_LOADS + 7] = energy * h
            out[_AT_LOADS + 8] = effort * h
            out[_AT_LOADS + 9] = path
            table[m, _SUM_X] = rec[n - 1, _X]
            table[m, _SUM_Y] = rec[n - 1, _Y]
            table[m, _SUM_RESISTANCE] -= surge * h
        if advanced and dynamic:
            if out[_AT_POSE + 4] < ship[_BESET_SPEED]:
                table[m, _SUM_SLOW] += scene[_CONTROL_INTERVAL]
            else:
                table[m, _SUM_SLOW] = 0.0


#: :func:`measure_many` compiled without threads, for one ship: the same
#: arithmetic without the cost of starting the parallel loop
measure_one = njit(cache=True, error_model="numpy")(measure_many.py_func)


def _starts(counts) -> np.ndarray:
    return np.concatenate(([0], np.cumsum(counts))).astype(np.int64)


_RECORDS_TYPE = types.Array(types.float64, 2, "C", readonly=True)
#: kept typed lists of records, by length: a list's items are replaced (a few
#: µs each), where making a list costs some 70 µs
_RECORD_LISTS: dict[int, List] = {}
_NO_RECORDS = np.zeros((0, len(RECORD_COLUMNS)))
_NO_RECORDS.flags.writeable = False


def _record_list(arrays: list) -> List:
    """The ships' step records as the typed list :func:`measure_many`
    takes (a reference to each array: a copy of the records of many
    ships costs ten times as much)."""
    out = _RECORD_LISTS.get(len(arrays))
    fresh = out is None
    if fresh:
        out = List.empty_list(_RECORDS_TYPE)
    for k, a in enumerate(arrays):
        if a.flags.writeable or not a.flags.c_contiguous:
            a = np.ascontiguousarray(a).view()
            a.flags.writeable = False
        if fresh:
            out.append(a)
        else:
            out[k] = a
    _RECORD_LISTS[len(arrays)] = out
    return out


def _stacked(arrays: list, columns: int) -> np.ndarray:
    """The arrays of (k, columns) rows one after the other."""
    full = [a for a in arrays if a.shape[0]]
    if not full:
        return np.zeros((0, columns))
    return full[0] if len(full) == 1 else np.concatenate(full)


def measure_ships(envs, table: np.ndarray, *, advanced: bool,
                  lists: KernelLists | None = None) -> np.ndarray:
    """The raw measurements of the ship environments ``envs`` (of one class
    and configuration, each with its episode running), one row each, the
    columns of ``envs[0].measure_names``.

    ``advanced``: their engines have just run a control interval, whose step
    records and collisions are read (and cleared) into the step loads and
    added to the episode sums in ``table`` (M, len(:data:`SUM_COLUMNS`)),
    one row per environment, updated in place. Otherwise (the first
    measurement of an episode) the step loads are zero.

    ``lists``: the typed lists of the engines' last batch run
    (:func:`physics.hertz.advance_together`); where they still hold every
    engine's state, the ice around all the hulls is measured in one
    compiled call over them (:func:`physics.hertz_batch.ice_near_many`),
    else engine by engine, with the same arithmetic.
    """
    e0 = envs[0]
    n = len(envs)
    sims = [env.sim for env in envs]
    ships = [sim.ship for sim in sims]
    dynamic = e0.mode == "dynamic"
    params = _ship_rows(envs, sims, ships, dynamic and advanced)
    motion = params[:, :6]
    floe_xy = [sim.positions for sim in sims]
    floe_r = [sim.radii for sim in sims]
    if advanced:
        rows = [ship.record_rows() for ship in ships]
        logs = [ship.collision_rows() for ship in ships]
        for ship in ships:
            ship.clear()
    else:
        rows = [_NO_RECORDS] * n
    box = sims[0].box
    scene = np.array((*box_entries(float(box.lx), float(box.ly), box.periodic),
                      e0.lidar_sectors, math.pi, e0.lidar_range, e0.goal_x, e0.centre_y,
                      0.5 * e0.channel_width, e0.control_interval, advanced, dynamic),
                     dtype=float)
    # the measurement's columns, written in place: pose, loads, lidar (distance
    # and concentration interleaved), local ice, the environment's own
    k = 2 * e0.lidar_sectors
    lid = len(POSE) + len(LOADS)
    loc = lid + k
    raw = np.empty((n, len(e0.measure_names)))
    loads = raw[:, len(POSE):lid]
    kernel = measure_one if n == 1 else measure_many
    kernel(_record_list(rows), params, _stacked(floe_xy, 2), np.concatenate(floe_r),
           _starts([r.size for r in floe_r]), scene, table, raw)
    if advanced:
        for m, env in enumerate(envs):
            if env.render_mode is not None and rows[m].shape[0]:   # the path on the frames
                env.track.append(table[m, [_SUM_X, _SUM_Y]].copy())
        _add_collisions(envs, table, loads, logs)
    _local_ice(envs, sims, motion, lists, raw[:, loc:loc + len(LOCAL)])
    raw[:, loc + 5] = motion[:, 0] >= e0.goal_x
    if not advanced:
        table[:, _SUM_ICE_START] = raw[:, loc + 6]
    if e0.extra_measures:
        raw[:, loc + len(LOCAL):] = e0.extra_values(envs)
    return raw


def _local_ice(envs, sims, motion, lists, out) -> None:
    """The columns of :data:`LOCAL` but ``reached`` into ``out``: the
    episode's concentration, the ice within each environment's local radius
    of its ship (:meth:`physics.HertzSimulation.local_ice`), the model time
    and the kinetic energy of all the ice."""
    e0 = envs[0]
    box = sims[0].box
    near = np.empty((len(sims), len(ICE_NEAR)))
    kept = None if lists is None or len(sims) == 1 else lists.current(sims)
    if kept is not None:                     # in one compiled call, parallel over the engines
        ice_near_many(kept[0], kept[1], motion[:, :2], float(e0.local_radius), float(box.lx),
                      float(box.ly), box.periodic[0], box.periodic[1], near)
    else:
        for m, sim in enumerate(sims):
            near[m] = sim.ice_near_row((motion[m, 0], motion[m, 1]), e0.local_radius)
    n_floes, r2, n_contacts, sxx, syy = (near[:, j] for j in (0, 1, 2, 3, 6))
    area = math.pi * float(e0.local_radius) ** 2
    out[:, 0] = [env.field_concentration for env in envs]
    out[:, 1] = np.minimum(1.0, math.pi * r2 / area)
    out[:, 2] = np.divide(2.0 * n_contacts, n_floes, out=np.zeros(len(sims)), where=n_floes > 0)
    out[:, 3] = np.where(n_contacts > 0, 0.5 * (-sxx / area + -syy / area), 0.0)
    out[:, 4] = [sim.time for sim in sims]
    out[:, 6] = near[:, 7]


def _ship_rows(envs, sims, ships, commanded: bool) -> np.ndarray:
    """The ships' rows of parameters (:data:`SHIP_COLUMNS`) for
    :func:`measure_many`; the commands and the beset speed only where
    ``commanded`` (a dynamic ship that has just advanced), else zero."""
    out = np.zeros((len(envs), len(SHIP_COLUMNS)))
    for row, env, sim, ship in zip(out, envs, sims, ships):
        row[:6] = ship.motion
        linear, quadratic = env.damping
        row[_LINEAR:_LINEAR + 3] = linear
        row[_QUADRATIC:_QUADRATIC + 3] = quadratic
        row[_DT] = sim.dt
        row[_HULL_LENGTH] = env.hull_length
        if commanded:
            c = ship.commands
            row[_THRUST] = c["thrust"]
            row[_YAW_MOMENT] = c["yaw_moment"]
            row[_BESET_SPEED] = env.episode["beset_speed"]
    return out


def _add_collisions(envs, table, loads, logs):
    """The collisions that ended in the step into the step loads and the
    episode sums."""
    counts = np.array([log.shape[0] for log in logs])
    loads[:, -1] = counts
    if not counts.any():
        return
    log = _stacked(logs, len(LOG_COLUMNS))
    owner = np.repeat(np.arange(len(logs)), counts)
    impulses = np.hypot(log[:, _IMPULSE_SURGE], log[:, _IMPULSE_SWAY])
    table[:, _SUM_COLLISIONS] += counts
    table[:, _SUM_IMPULSE] += np.bincount(owner, impulses, minlength=len(logs))
    top = table[:, _SUM_IMPULSE_MAX].copy()
    np.maximum.at(top, owner, impulses)
    table[:, _SUM_IMPULSE_MAX] = top
    for k in np.flatnonzero(counts):
        hit = envs[k].floes_hit
        mine = log[owner == k]
        for floe, mass in zip(mine[:, _FLOE].astype(np.int64).tolist(),
                              mine[:, _FLOE_MASS].tolist()):
            if floe not in hit:
                hit.add(floe)
                if math.isfinite(mass):         # a frozen floe has no mass to count
                    table[k, _SUM_MASS_HIT] += mass
                    table[k, _SUM_MOBILE_HIT] += 1.0
        table[k, _SUM_FLOES_HIT] = len(hit)


def update_metrics(table: np.ndarray, now, goal_distance: float) -> None:
    """The episode metrics of ``table``'s rows after a step that measured
    ``now`` (a measurement dict of floats for one row, or of columns, one
    entry per row), in place; ``goal_distance`` [m] is the straight-line
    distance from the start to the goal line."""
    values = np.array([now[name] for name in _METRIC_INPUTS], dtype=float)
    if values.ndim == 1:                     # one measurement, for every row
        values = np.repeat(values[:, None], table.shape[0], axis=1)
    _update_metrics(table, values, float(goal_distance))


#: the measurements the metrics read, in the order of :func:`_update_metrics`' arguments
_METRIC_INPUTS = ("time", "step_path", "step_effort", "step_energy", "peak_hull_pressure",
                  "reached", "ice_kinetic_energy")


@njit(cache=True, error_model="numpy")
def _update_metrics(t, values, goal_distance):
    time, path, effort, energy, peak, reached, ice = (values[0], values[1], values[2],
                                                      values[3], values[4], values[5],
                                                      values[6])
    for m in range(t.shape[0]):
        t[m, _M_TIME] = time[m]
        t[m, _M_PATH] += path[m]
        t[m, _M_EFFORT] += effort[m]
        t[m, _M_ENERGY] += energy[m]
        n = t[m, _SUM_COLLISIONS]
        total = t[m, _SUM_IMPULSE]
        length = t[m, _M_PATH]
        t[m, _M_COLLISIONS] = n
        t[m, _M_FLOES] = t[m, _SUM_FLOES_HIT]
        t[m, _M_MEAN_IMPULSE] = total / n if n > 0 else 0.0
        t[m, _M_MAX_IMPULSE] = t[m, _SUM_IMPULSE_MAX]
        t[m, _M_IMPULSE_PER_METRE] = total / length if length > 0 else 0.0
        t[m, _M_RESISTANCE] = t[m, _SUM_RESISTANCE] / time[m] if time[m] > 0 else 0.0
        t[m, _M_MAX_PRESSURE] = max(t[m, _M_MAX_PRESSURE], peak[m])
        mobile = t[m, _SUM_MOBILE_HIT]
        t[m, _M_MEAN_MASS] = t[m, _SUM_MASS_HIT] / mobile if mobile > 0 else 0.0
        success = reached[m] > 0
        t[m, _M_SUCCESS] = 1.0 if success else 0.0
        t[m, _M_EFFICIENCY] = goal_distance / length if success and length > 0 else 0.0
        t[m, _M_ICE_GAIN] = ice[m] - t[m, _SUM_ICE_START]
        t[m, _M_DISSIPATED] = t[m, _M_ENERGY] - t[m, _M_ICE_GAIN]


def metric_values(row: np.ndarray) -> dict:
    """The episode metrics of one row of sums, as ``info`` holds them."""
    out = {name: float(row[k]) for k, name in enumerate(METRICS)}
    out["success"] = bool(row[_C["success"]])
    for name in _INTEGER_METRICS:
        out[name] = int(row[_C[name]])
    return out


def metric_columns(table: np.ndarray) -> dict:
    """The episode metrics of every row of sums, as columns of the types of
    :func:`metric_values`."""
    out = {name: table[:, k].copy() for k, name in enumerate(METRICS)}
    out["success"] = out["success"] > 0
    for name in _INTEGER_METRICS:
        out[name] = out[name].astype(np.int64)
    return out


def info_columns(names, raw: np.ndarray, sums: np.ndarray, steps: np.ndarray,
                 task: dict) -> dict:
    """What the info of each of a batch of ship environments holds after a
    step, as columns: ``physics`` (the measurements ``raw``, a row each, of
    the columns ``names``), ``time``, ``steps``, ``task`` (its columns) and
    the episode metrics of ``sums``."""
    physics = {name: raw[:, j].copy() for j, name in enumerate(names)}
    for name in INTEGER_MEASURES:
        physics[name] = physics[name].astype(np.int64)
    metrics = metric_columns(sums)
    return {"physics": physics, "time": metrics["time"], "steps": np.asarray(steps),
            "task": {key: value.copy() for key, value in task.items()}, **metrics}
