"""The costmap: what the lattice planner costs, as a map a policy can read.

:func:`impulse_costmap` spreads each floe's expected collision impulse over
a grid, the cost of the lattice planner (:class:`agents.planners.LatticePlanner`
reads it from here); :func:`ice_costmap` makes of it a sensor, the
observation ``obs_type="costmap"`` of the ship environments.

The cost. Floe i, of radius r_i and expected collision impulse J_i [N s]
(:meth:`iceenvs.ship_env.ShipEnv.expected_impulses`: a head-on collision
with the hull at the ship's full speed), is met by a route whose centre
line passes within ρ_i = r_i + B/2 of its centre (B the beam). J_i is
spread over that enlarged disc as a cone, the density [N s/m]

    c_i(ρ) = J_i (1 − ρ / ρ_i) / ρ_i    (ρ ≤ ρ_i, else 0)

at distance ρ from the centre, so that the line integral of the density
along a route through the centre is J_i, and a glancing route pays less.
The density of the ice is the sum over the floes.

The map. A grid in the channel frame (x along the channel, towards the goal
line; y across it, to port): ``rows`` rows of ``cell`` [m] along x, the
far edge of row 0 ``ahead`` [m] ahead of the ship's centroid, so that the
map reaches at least ``behind`` [m] behind it; ``cols`` columns across,
centred on the ship's y and spanning at least the channel's width. Row 0 is
the farthest ahead and column 0 the farthest to port: seen from above with
the goal direction up, the map is the ice as it lies, port to the left. The
centre of cell (row i, column j) is the world point

    x = x_ship + ahead − (i + 1/2) cell,
    y = y_ship + cols cell / 2 − (j + 1/2) cell.

Channels (:data:`COSTMAP_CHANNELS`), float32:

0. ``impulse``: log(1 + c / :data:`COSTMAP_SCALE`), c the density averaged
   over the cell (on a grid of samples of the cell, at most
   :data:`SAMPLE_SPACING` apart), clipped at :data:`COSTMAP_CAP`. The
   scale, 12 500 N s/m, is the impulse one metre sailed is worth in
   ShipNavigation-v1's reward, so a cell of value log 2 ≈ 0.69 costs a
   route crossing it as much ice as its length in metres costs time;
1. ``outside_channel``: 1 where the cell centre lies outside the channel,
   |y − centre_y| > channel_width / 2, else 0;
2. ``beyond_goal``: 1 where the cell centre lies past the goal line,
   x > goal_x, else 0.

It is a sensor: only the floes whose enlarged disc reaches into the map
count. Along a periodic axis every image of a floe that reaches into the
map counts (the periodic channel of ShipNavigation-v1 shows the ice beyond
its edges, as the swath sensor sees it, and the mask says where the
channel ends).

Example
-------
>>> import numpy as np
>>> m = ice_costmap((0.0, 0.0), np.array([[50.0, 0.0]]), np.array([5.0]),
...                 np.array([1.0e5]), half_beam=9.0, goal_x=200.0, centre_y=0.0,
...                 channel_width=100.0)
>>> m.shape
(3, 64, 20)
>>> float(m[0].max()) > 0.0, float(m[1].max()), float(m[2, 0, 0]), float(m[2, -1, 0])
(True, 0.0, 1.0, 0.0)
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from physics.input_checks import check_range

from .ship_sensors import check_box, check_floes, check_pose

__all__ = ["impulse_costmap", "costmap_density", "costmap_scan", "ice_costmap", "costmap_shape",
           "costmap_samples", "costmap_space", "COSTMAP_CHANNELS", "COSTMAP_SCALE", "COSTMAP_CAP",
           "SAMPLE_SPACING", "MAX_COSTMAP_CELLS"]

#: the channels of the costmap, in order
COSTMAP_CHANNELS = ("impulse", "outside_channel", "beyond_goal")
#: the density [N s/m] that the impulse channel scales by: log(1 + c / scale)
COSTMAP_SCALE = 12_500.0
#: the largest value of the impulse channel (a density of about 2.8·10⁸ N s/m)
COSTMAP_CAP = 10.0
#: the largest distance [m] between the samples a cell's density is averaged on
SAMPLE_SPACING = 2.5
#: the most cells a costmap may have (rows × columns)
MAX_COSTMAP_CELLS = 1 << 20


@njit(cache=True)
def impulse_costmap(x0, y0, nx, ny, cell, px, py, reach, impulse, cone=False):
    """Cost density [N s/m] on a grid of ``nx`` × ``ny`` cells of side
    ``cell`` [m] whose corner is (``x0``, ``y0``): each floe spreads its
    ``impulse`` over the disc of radius ``reach`` about (``px``, ``py``),
    so that the line integral through the centre is the impulse: evenly
    (density impulse / (2 reach)) or, with ``cone``, as a cone (density
    impulse (1 − ρ/reach) / reach at distance ρ from the centre)."""
    cost = np.zeros((nx, ny))
    for i in range(px.size):
        r = reach[i]
        d = impulse[i] / (2.0 * r)
        lo_x = max(int(math.floor((px[i] - r - x0) / cell)), 0)
        hi_x = min(int(math.floor((px[i] + r - x0) / cell)), nx - 1)
        lo_y = max(int(math.floor((py[i] - r - y0) / cell)), 0)
        hi_y = min(int(math.floor((py[i] + r - y0) / cell)), ny - 1)
        for a in range(lo_x, hi_x + 1):
            cx = x0 + (a + 0.5) * cell - px[i]
            for b in range(lo_y, hi_y + 1):
                cy = y0 + (b + 0.5) * cell - py[i]
                q = cx * cx + cy * cy
                if q <= r * r:
                    cost[a, b] += 2.0 * d * (1.0 - math.sqrt(q) / r) if cone else d
    return cost


@njit(cache=True)
def _image_shifts(d, reach, low, high, length, periodic):
    """The first and last k of the images d + k·length of a coordinate
    whose interval [d − reach, d + reach] meets [low, high] (only k = 0
    along an axis that is not periodic; first > last when none does)."""
    if not periodic:
        if d + reach < low or d - reach > high:
            return 0, -1
        return 0, 0
    return (int(math.ceil((low - reach - d) / length)),
            int(math.floor((high + reach - d) / length)))


@njit(cache=True)
def costmap_density(x, y, positions, radii, impulses, half_beam, ahead, cell, rows, cols, sub,
                    lx, ly, periodic_x, periodic_y):
    """The density [N s/m] of the impulse channel before its scaling: the
    (``rows``, ``cols``) float64 means over ``sub`` × ``sub`` samples of
    each cell (at its sub-cells' centres) of the cone-spread density of
    :func:`impulse_costmap`, the floes (their radii enlarged by
    ``half_beam``) seen through every image that reaches into the map; row
    0 the farthest ahead, column 0 the farthest to port. The arguments as
    :func:`costmap_scan`."""
    # the map's rectangle as displacements from the ship, x and y ascending
    x_lo = ahead - rows * cell
    y_lo = -0.5 * cols * cell
    x_hi, y_hi = ahead, -y_lo
    n = radii.shape[0]
    px, py = np.empty(4 * n), np.empty(4 * n)
    reach, weight = np.empty(4 * n), np.empty(4 * n)
    m = 0
    for f in range(n):
        r = radii[f] + half_beam
        dx = positions[f, 0] - x
        dy = positions[f, 1] - y
        kx0, kx1 = _image_shifts(dx, r, x_lo, x_hi, lx, periodic_x)
        ky0, ky1 = _image_shifts(dy, r, y_lo, y_hi, ly, periodic_y)
        for kx in range(kx0, kx1 + 1):
            for ky in range(ky0, ky1 + 1):
                if m == px.size:              # more images than room: grow
                    px = np.concatenate((px, np.empty(px.size)))
                    py = np.concatenate((py, np.empty(py.size)))
                    reach = np.concatenate((reach, np.empty(reach.size)))
                    weight = np.concatenate((weight, np.empty(weight.size)))
                px[m], py[m] = dx + kx * lx, dy + ky * ly
                reach[m], weight[m] = r, impulses[f]
                m += 1
    fine = impulse_costmap(x_lo, y_lo, rows * sub, cols * sub, cell / sub, px[:m], py[:m],
                           reach[:m], weight[:m], True)
    density = np.empty((rows, cols))
    for a in range(rows):
        for b in range(cols):
            total = 0.0
            for s in range(a * sub, (a + 1) * sub):
                for t in range(b * sub, (b + 1) * sub):
                    total += fine[s, t]
            # row 0: the farthest ahead; column 0: the farthest to port
            density[rows - 1 - a, cols - 1 - b] = total / (sub * sub)
    return density


@njit(cache=True)
def costmap_scan(x, y, positions, radii, impulses, half_beam, goal_x, centre_y, half_width,
                 ahead, cell, rows, cols, sub, lx, ly, periodic_x, periodic_y):
    """:func:`ice_costmap` without the checks of its arguments: the ship's
    centroid at (``x``, ``y``), ``half_width`` half the channel's width,
    ``sub`` samples per cell side (:func:`costmap_samples`), the box of
    side lengths ``lx``, ``ly`` (used along the periodic axes only).
    Returns the (3, ``rows``, ``cols``) float32 map."""
    density = costmap_density(x, y, positions, radii, impulses, half_beam, ahead, cell, rows,
                              cols, sub, lx, ly, periodic_x, periodic_y)
    out = np.zeros((3, rows, cols), dtype=np.float32)
    for i in range(rows):
        beyond = x + ahead - (i + 0.5) * cell > goal_x
        for j in range(cols):
            out[0, i, j] = min(math.log1p(density[i, j] / COSTMAP_SCALE), COSTMAP_CAP)
            if abs(y + 0.5 * cols * cell - (j + 0.5) * cell - centre_y) > half_width:
                out[1, i, j] = 1.0
            if beyond:
                out[2, i, j] = 1.0
    return out


def costmap_shape(cell: float, behind: float, ahead: float, width: float) -> tuple[int, int]:
    """(rows, cols) of a costmap of cells of side ``cell`` [m] reaching
    ``behind`` [m] behind the ship and ``ahead`` [m] ahead of it and
    ``width`` [m] across: the fewest whole cells that cover them
    (``ValueError`` for a bad argument or a map of more than
    :data:`MAX_COSTMAP_CELLS` cells)."""
    check_range("costmap_cell", cell, 0.0, None, low_open=True)
    check_range("costmap_behind", behind, 0.0, None)
    check_range("costmap_ahead", ahead, 0.0, None, low_open=True)
    check_range("costmap width", width, 0.0, None, low_open=True)
    cell, behind, ahead, width = float(cell), float(behind), float(ahead), float(width)
    rows = max(int(math.ceil((behind + ahead) / cell - 1e-9)), 1)
    cols = max(int(math.ceil(width / cell - 1e-9)), 1)
    if rows * cols > MAX_COSTMAP_CELLS:
        raise ValueError(f"a costmap of cells of {cell:g} m over {behind + ahead:g} m × "
                         f"{width:g} m has {rows} × {cols} cells, more than "
                         f"{MAX_COSTMAP_CELLS}: make costmap_cell larger")
    return rows, cols


def costmap_space(size: tuple[int, int]):
    """The observation space of a costmap of ``size`` (rows, columns):
    ``Box(float32, (3, rows, columns))``, the impulse channel in
    [0, :data:`COSTMAP_CAP`], the masks in [0, 1]."""
    import gymnasium as gym

    high = np.ones((len(COSTMAP_CHANNELS), *size), dtype=np.float32)
    high[0] = COSTMAP_CAP
    return gym.spaces.Box(np.zeros_like(high), high, dtype=np.float32)


def costmap_samples(cell: float) -> int:
    """Samples per side of a cell of side ``cell`` [m] that its density is
    averaged on: the fewest that are at most :data:`SAMPLE_SPACING` apart."""
    return max(int(math.ceil(float(cell) / SAMPLE_SPACING - 1e-9)), 1)


def ice_costmap(ship_xy, positions, radii, impulses, *, half_beam: float, goal_x: float,
                centre_y: float, channel_width: float, cell: float = 5.0,
                behind: float = 20.0, ahead: float = 300.0, box_lengths=None,
                periodic=(False, False)) -> np.ndarray:
    """The costmap of the floes about a ship (see the module docstring).

    Parameters
    ----------
    ship_xy : (2,) array_like — the ship's centroid [m]
    positions : (N, 2) array_like — floe centres [m]
    radii : (N,) array_like — floe radii [m], positive
    impulses : (N,) array_like — each floe's expected collision impulse
        [N s], non-negative (:meth:`~iceenvs.ship_env.ShipEnv.expected_impulses`)
    half_beam : float — half the hull's beam [m], > 0
    goal_x : float — the goal line x = goal_x [m]
    centre_y, channel_width : float — the channel's centre line y [m] and
        width [m] (the map spans the width, centred on the ship)
    cell : float — side of a cell [m]
    behind, ahead : float — how far [m] the map reaches behind the ship and
        ahead of it
    box_lengths, periodic : the box's side lengths [m] and its periodic
        axes, as :func:`iceenvs.ship_sensors.ice_lidar`

    Returns
    -------
    (3, rows, cols) float32 array (:func:`costmap_shape`): the channels of
    :data:`COSTMAP_CHANNELS`, row 0 the farthest ahead, column 0 the
    farthest to port.
    """
    xy, _ = check_pose(ship_xy, 0.0)
    p, r = check_floes(positions, radii)
    w = np.asarray(impulses, dtype=float)
    if w.shape != r.shape or not (np.all(np.isfinite(w)) and np.all(w >= 0.0)):
        raise ValueError(f"impulses must be {r.shape[0]} finite non-negative numbers (one per "
                         f"floe), got shape {w.shape}")
    check_range("half_beam", half_beam, 0.0, None, low_open=True)
    check_range("goal_x", goal_x)
    check_range("centre_y", centre_y)
    check_range("channel_width", channel_width, 0.0, None, low_open=True)
    rows, cols = costmap_shape(cell, behind, ahead, channel_width)
    lengths, per = check_box(box_lengths, periodic)
    lx, ly = (1.0, 1.0) if lengths is None else (float(lengths[0]), float(lengths[1]))
    return costmap_scan(xy[0], xy[1], p, r, w, float(half_beam), float(goal_x),
                        float(centre_y), 0.5 * float(channel_width), float(ahead),
                        float(cell), rows, cols, costmap_samples(cell), lx, ly, per[0], per[1])


# -- the picture of the documentation ---------------------------------------------------------

#: colours of the impulse channel, from 0 to its largest value in the picture
_RAMP = np.array([[13, 8, 60], [60, 40, 140], [150, 60, 140], [235, 110, 70], [250, 230, 90]],
                 dtype=float)
#: colours of the masks: outside the channel, past the goal line, both, neither
_MASK_COLOURS = {"outside": (200, 70, 70), "beyond": (60, 200, 90), "both": (220, 200, 60),
                 "neither": (24, 26, 32)}


def _ramp(values: np.ndarray, top: float) -> np.ndarray:
    t = np.clip(values / top, 0.0, 1.0) * (len(_RAMP) - 1)
    k = np.minimum(t.astype(int), len(_RAMP) - 2)
    f = (t - k)[..., None]
    return ((1.0 - f) * _RAMP[k] + f * _RAMP[k + 1]).round().astype(np.uint8)


def _as_seen_from_above(channel: np.ndarray, scale: int) -> np.ndarray:
    """A channel turned as the frames show the channel: x (ahead) to the
    right, port up, each cell ``scale`` pixels square."""
    turned = channel.T[:, ::-1]
    return np.repeat(np.repeat(turned, scale, axis=0), scale, axis=1)


def costmap_picture(seed: int = 0, scale: int = 15) -> np.ndarray:
    """The picture of the documentation: a small ShipNavigation-v1 whose
    ship has turned to port and sailed into the ice; its frame (the view
    that follows the ship, from 20 m behind it to 300 m ahead, as the
    costmap), then the impulse channel and the masks of the costmap,
    turned the same way (x to the right, port up)."""
    import gymnasium as gym

    from . import ENV_IDS
    from .facts import env_facts, env_spec
    from .rendering import annotate

    # the id whose class lives in the module of ShipNavigation-v1
    module = f"{__package__}.ship_navigation_v1:"
    env_id = next(i for i in ENV_IDS if str(env_spec(i).entry_point).startswith(module))
    env = gym.make(env_id, **{**dict(env_facts(env_id).small), "goal_distance": 350.0},
                   obs_type="costmap", control="course", render_mode="rgb_array",
                   view_behind=20.0, view_ahead=300.0)
    try:
        obs, _ = env.reset(seed=seed)
        for k in range(30):
            obs = env.step(np.array([0.6 if k < 12 else -0.3], dtype=np.float32))[0]
        frame = env.render()
        u = env.unwrapped
        x, y = (float(v) for v in u.sim.ship.position)
        rows, cols = u.costmap_size
    finally:
        env.close()
    top = max(float(obs[0].max()), 1e-9)
    ice = annotate(_ramp(_as_seen_from_above(obs[0], scale), top), side="bottom", text=[
        "channel 0: impulse density",
        f"log(1 + c / {COSTMAP_SCALE:,.0f} N s/m)",
        f"dark 0, bright {top:.2f}",
        f"{rows} × {cols} cells of {u.costmap_cell:g} m",
        f"ship at x = {x:.0f} m, y = {y:.0f} m",
        f"x from {x - u.costmap_behind:.0f} m to {x + u.costmap_ahead:.0f} m",
        f"y from {y - 0.5 * cols * u.costmap_cell:.0f} m to "
        f"{y + 0.5 * cols * u.costmap_cell:.0f} m"])
    outside = _as_seen_from_above(obs[1], scale) > 0.5
    beyond = _as_seen_from_above(obs[2], scale) > 0.5
    masks = np.empty((*outside.shape, 3), dtype=np.uint8)
    for name, where in (("neither", ~outside & ~beyond), ("outside", outside & ~beyond),
                        ("beyond", beyond & ~outside), ("both", outside & beyond)):
        masks[where] = _MASK_COLOURS[name]
    masks = annotate(masks, side="bottom", legend=[
        (_MASK_COLOURS["outside"], "channel 1: outside the channel", "band"),
        (_MASK_COLOURS["beyond"], "channel 2: past the goal line", "band"),
        (_MASK_COLOURS["both"], "both", "band")])
    width = max(p.shape[1] for p in (frame, ice, masks))
    pad = [np.pad(p, ((0, 8), (0, width - p.shape[1]), (0, 0))) for p in (frame, ice, masks)]
    return np.concatenate(pad, axis=0)


def main(argv=None) -> int:
    import argparse
    from pathlib import Path

    from PIL import Image

    p = argparse.ArgumentParser(prog="python -m iceenvs.costmap",
                                description="Draw the costmap observation beside the ice it "
                                            "shows (the picture of the observation page).")
    p.add_argument("--out", type=Path, required=True, help="the folder of costmap.png")
    p.add_argument("--seed", type=int, default=0, help="the episode's seed (default 0)")
    args = p.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "costmap.png"
    Image.fromarray(costmap_picture(args.seed)).save(path, optimize=True)
    print(f"written: {path}")
    return 0


if __name__ == "__main__":
    import sys

    sys.exit(main())
