"""Pictures of the environments, drawn with pygame.

* :func:`draw_floes` — the floes of a periodic box as discs coloured by speed on
  a fixed scale (:data:`SPEED_SCALE`, frozen floes grey) or by cluster (the
  largest cluster highlighted), with their periodic images across the box edges
  and, optionally, the contact force chains;
* :func:`draw_ship` — a ship over such a picture: the hull, its track, the
  goal line and the channel's edges;
* :func:`draw_view` — a window of a channel (:func:`view_window`: one that
  follows the ship, or the whole channel) to scale, with axes in metres and
  a scale bar: the floes as discs at their true size coloured by thickness
  class (:func:`thickness_colours`), the leads, the walls, the contact
  forces, the ship, its track, its planned course and the goal line;
* :func:`annotate` — a frame with a panel on its right or under it: lines of
  text (time, concentration, target...), one or two direction arrows (wind,
  heading), a colour bar of the speed colormap and a legend of colour swatches;
* :func:`draw_itd` — the ice-thickness distribution as a bar chart with axis
  labels, the model day and season in a title, and an optional target
  distribution drawn over it;
* :class:`Window` — a window that shows such frames for ``render_mode="human"``.

The drawing functions return RGB arrays ``(H, W, 3)`` of ``uint8`` and need no
display. Text is written with pygame's bundled default font; when fonts are
unavailable the text is left out and everything else is still drawn. pygame is
an optional dependency (the ``render`` extra); it is imported only when
something is drawn, and a missing pygame raises
:class:`gymnasium.error.DependencyNotInstalled`.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from gymnasium.error import DependencyNotInstalled

__all__ = ["draw_floes", "draw_ship", "draw_view", "view_box", "view_window", "ViewBox",
           "thickness_colours", "annotate", "draw_itd", "season", "Window", "SPEED_SCALE",
           "LARGEST_CLUSTER", "CLUSTER_PALETTE", "SINGLE_FLOE", "FROZEN", "CLUSTER_LEGEND",
           "VIEWS", "THICKNESS_COLOURS", "LEAD", "OUTSIDE", "SIDES", "LEGEND_KINDS"]

#: Speed [m/s] mapped to the top of the floe colormap by default; faster floes
#: saturate at the top colour. Fixed, so that frames of a run can be compared.
SPEED_SCALE = 0.5

BACKGROUND = (22, 62, 112)      # sea blue
FROZEN = (150, 150, 150)        # grey
CHAIN = (140, 20, 20)           # dark red

#: Bright colour of the largest cluster (by total disc area) in cluster colouring.
LARGEST_CLUSTER = (255, 196, 0)
#: Muted colours of the other clusters, chosen by ``label % len(CLUSTER_PALETTE)``.
CLUSTER_PALETTE = (
    (92, 150, 140),     # sage teal
    (150, 118, 168),    # mauve
    (172, 150, 98),     # khaki
    (176, 108, 108),    # dusty rose
    (122, 162, 96),     # moss
    (132, 166, 202),    # sky
)
#: Plain muted colour of the floes that form a cluster on their own.
SINGLE_FLOE = (88, 106, 132)
#: Legend entries ``(colour, text)`` of the cluster colouring, for :func:`annotate`.
CLUSTER_LEGEND = (
    (LARGEST_CLUSTER, "largest cluster"),
    (CLUSTER_PALETTE[0], "other clusters"),
    (SINGLE_FLOE, "single floes"),
    (FROZEN, "frozen"),
)

PANEL_BACKGROUND = (28, 30, 36)  # dark grey
PANEL_TEXT = (232, 232, 232)
ARROW_CIRCLE = (110, 116, 128)
#: Default colours of the first and second arrow of :func:`annotate`.
ARROW_COLOURS = ((255, 255, 255), (255, 140, 30))
#: Default panel width of :func:`annotate`, as a fraction of the picture width,
#: and its minimum [px].
PANEL_FRACTION = 0.3
PANEL_MIN_WIDTH = 150

ITD_BACKGROUND = (245, 247, 250)
ITD_AXES = (40, 40, 40)
ITD_OPEN_WATER = (40, 110, 190)
ITD_ICE = (120, 170, 210)
ITD_TARGET = (225, 110, 20)

_FONT_ERRORS = (ImportError, NotImplementedError, OSError, RuntimeError)
_SEASONS = ("winter", "spring", "summer", "autumn")

# A few samples of the viridis colormap, interpolated linearly in between.
_VIRIDIS = np.array([
    (68, 1, 84), (71, 44, 122), (59, 82, 139), (44, 113, 142), (33, 145, 140),
    (39, 173, 129), (92, 200, 99), (170, 220, 50), (253, 231, 37),
], dtype=float)


def _pygame():
    """Import pygame (with gfxdraw) or say how to install it."""
    try:
        import pygame
        import pygame.gfxdraw
    except ImportError as exc:
        raise DependencyNotInstalled(
            'pygame is needed for rendering; install it with pip install "seaice-gym[render]" '
            "(or pip install pygame)") from exc
    return pygame


def _colormap(values: np.ndarray) -> np.ndarray:
    """Viridis-like RGB colours ``(N, 3)`` uint8 of values in [0, 1] (clipped)."""
    v = np.clip(np.asarray(values, dtype=float), 0.0, 1.0)
    knots = np.linspace(0.0, 1.0, len(_VIRIDIS))
    rgb = np.stack([np.interp(v, knots, _VIRIDIS[:, c]) for c in range(3)], axis=-1)
    return np.rint(rgb).astype(np.uint8)


def _shifts(c: float, r: float, length: float) -> tuple:
    """Shifts along one axis at which a disc (centre c, radius r) is drawn."""
    if c - r < 0:
        return (0.0, length)
    if c + r > length:
        return (0.0, -length)
    return (0.0,)


def _to_array(surf, pygame) -> np.ndarray:
    return np.transpose(np.array(pygame.surfarray.pixels3d(surf)), axes=(1, 0, 2))


def _vector(name: str, x, n: int | None = None, dtype=float) -> np.ndarray:
    a = np.asarray(x, dtype=dtype)
    if a.ndim != 1 or (n is not None and a.shape[0] != n):
        want = f"({n},)" if n is not None else "1-D"
        raise ValueError(f"{name} must have shape {want}, got {a.shape}")
    if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite")
    return a


def _check_size(size, name: str = "size") -> int:
    if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size < 1:
        raise ValueError(f"{name} must be a positive integer, got {size!r}")
    return int(size)


def _check_colour(name: str, colour) -> tuple:
    """An RGB colour as a tuple of three ints in [0, 255]."""
    try:
        c = np.asarray(colour)
    except (TypeError, ValueError):
        c = None
    if (c is None or c.shape != (3,) or c.dtype.kind not in "iuf"
            or not np.all(np.isfinite(c)) or np.any(c != np.round(c))
            or np.any(c < 0) or np.any(c > 255)):
        raise ValueError(f"{name} must be an RGB triple of integers in [0, 255], got {colour!r}")
    return tuple(int(v) for v in c)


def _check_number(name: str, x) -> float:
    if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)) \
            or not np.isfinite(x):
        raise ValueError(f"{name} must be a finite number, got {x!r}")
    return float(x)


class _Writer:
    """Renders text with pygame's default font; gives ``None`` when fonts are unavailable."""

    def __init__(self, pygame):
        self.pygame = pygame
        self.fonts = {}
        self.ok = True

    def font(self, px: int):
        px = int(px)
        if px < 8 or not self.ok:
            return None
        if px not in self.fonts:
            try:
                self.pygame.font.init()
                self.fonts[px] = self.pygame.font.Font(None, px)
            except _FONT_ERRORS + (self.pygame.error,):
                self.ok = False
                return None
        return self.fonts[px]

    def render(self, text: str, px: int, colour, max_width: int | None = None):
        """A surface with the text (shrunk to fit ``max_width`` [px] if needed), or None."""
        font = self.font(px)
        if font is None:
            return None
        try:
            surf = font.render(text, True, colour)
            if max_width is not None and surf.get_width() > max_width > 0:
                smaller = self.font(int(px * max_width / surf.get_width()))
                if smaller is not None:
                    surf = smaller.render(text, True, colour)
        except _FONT_ERRORS + (self.pygame.error,):
            return None
        return surf

    def write(self, surf, text: str, px: int, colour, anchor: str, at,
              max_width: int | None = None) -> None:
        """Blit the text with its rectangle's ``anchor`` (e.g. "midleft") at ``at``."""
        label = self.render(text, px, colour, max_width)
        if label is not None:
            rect = label.get_rect(**{anchor: (int(round(at[0])), int(round(at[1])))})
            surf.blit(label, rect)


def _floe_colours(rad: np.ndarray, spd: np.ndarray, frz: np.ndarray, labels, speed_scale):
    """Colours ``(N, 3)`` uint8 of the floes, by speed or, given labels, by cluster."""
    if labels is None:
        colours = _colormap(np.abs(spd) / speed_scale)
    else:
        colours = np.empty((rad.shape[0], 3), dtype=np.uint8)
        if rad.shape[0]:
            values, inverse, counts = np.unique(labels, return_inverse=True, return_counts=True)
            area = np.bincount(inverse, weights=rad**2, minlength=values.shape[0])
            area[counts < 2] = -1.0                  # a lone floe is never "the largest"
            largest = int(np.argmax(area)) if np.any(counts >= 2) else -1
            palette = np.array(CLUSTER_PALETTE, dtype=np.uint8)
            colours[:] = palette[np.mod(labels, len(CLUSTER_PALETTE))]
            colours[counts[inverse] < 2] = SINGLE_FLOE
            colours[inverse == largest] = LARGEST_CLUSTER
    colours[frz] = FROZEN
    return colours


def draw_floes(positions, radii, box_size, speeds, *, frozen=None, contact_i=None,
               contact_j=None, contact_force=None, speed_scale=SPEED_SCALE, labels=None,
               size=600) -> np.ndarray:
    """RGB frame ``(H, W, 3)`` uint8 of the floes in a periodic box.

    Parameters
    ----------
    positions : (N, 2) array of float
        Floe centres [m]; the box spans ``[0, lx] x [0, ly]``.
    radii : (N,) array of float
        Floe radii [m], positive.
    box_size : (lx, ly)
        Box side lengths [m], positive.
    speeds : (N,) array of float
        Floe speeds [m/s], mapped to a viridis-like colormap on the fixed scale
        ``[0, speed_scale]`` (unused for the colour when ``labels`` is given).
    frozen : (N,) array of bool, optional
        Floes drawn grey (:data:`FROZEN`) whatever the colouring.
    contact_i, contact_j, contact_force : (K,) arrays of int, int, float, optional
        Force chains [N], drawn as dark-red segments between the centres
        (minimum image), 1 to 5 px wide in proportion to force / max force;
        contacts with zero force are skipped. Given all three or none.
    speed_scale : float, optional
        Speed [m/s] mapped to the top of the colormap, default
        :data:`SPEED_SCALE` (0.5 m/s); faster floes saturate at the top colour.
        The same speed has the same colour in every frame.
    labels : (N,) array of int, optional
        Cluster label of each floe. When given, floes are coloured by cluster
        instead of speed: the largest cluster of two floes or more (by total
        disc area, the sum of r²; ties go to the smaller label) in
        :data:`LARGEST_CLUSTER`, every other cluster of two floes or more in
        ``CLUSTER_PALETTE[label % len(CLUSTER_PALETTE)]`` (so floes of one
        cluster share a colour), floes alone in their cluster in
        :data:`SINGLE_FLOE`. :data:`CLUSTER_LEGEND` describes these colours.
    size : int, optional
        Image width [px]; the height is ``round(size * ly / lx)``.

    Returns
    -------
    np.ndarray
        ``(H, W, 3)`` uint8 RGB picture with y pointing up and ``size / lx``
        pixels per metre. A floe crossing a box edge is drawn also on the
        opposite side so the picture tiles.
    """
    pos = np.asarray(positions, dtype=float)
    if pos.ndim != 2 or pos.shape[1] != 2:
        raise ValueError(f"positions must have shape (N, 2), got {pos.shape}")
    if not np.all(np.isfinite(pos)):
        raise ValueError("positions must be finite")
    n = pos.shape[0]
    rad = _vector("radii", radii, n)
    if np.any(rad <= 0):
        raise ValueError("radii must be positive")
    spd = _vector("speeds", speeds, n)
    box = np.asarray(box_size, dtype=float)
    if box.shape != (2,) or not np.all(np.isfinite(box)) or np.any(box <= 0):
        raise ValueError(f"box_size must be two positive finite lengths, got {box_size!r}")
    frz = np.zeros(n, dtype=bool) if frozen is None else _vector("frozen", frozen, n, bool)
    given = [c is not None for c in (contact_i, contact_j, contact_force)]
    if any(given) and not all(given):
        raise ValueError("contact_i, contact_j and contact_force must be given together")
    if all(given):
        ci = _vector("contact_i", contact_i, dtype=np.int64)
        k = ci.shape[0]
        cj = _vector("contact_j", contact_j, k, np.int64)
        cf = np.abs(_vector("contact_force", contact_force, k))
        for name, idx in (("contact_i", ci), ("contact_j", cj)):
            if np.any((idx < 0) | (idx >= n)):
                raise ValueError(f"{name} must index floes in [0, {n})")
    if labels is not None:
        lab = np.asarray(labels)
        if lab.ndim != 1 or lab.shape[0] != n:
            raise ValueError(f"labels must have shape ({n},), got {lab.shape}")
        if lab.dtype.kind not in "iu":
            raise ValueError(f"labels must be integers, got dtype {lab.dtype}")
        labels = lab.astype(np.int64)
    if speed_scale is None:
        speed_scale = SPEED_SCALE
    if isinstance(speed_scale, bool) or not np.isfinite(speed_scale) or speed_scale <= 0:
        raise ValueError(f"speed_scale must be positive and finite, got {speed_scale!r}")
    size = _check_size(size)

    pygame = _pygame()
    lx, ly = box
    scale = size / lx
    width, height = size, max(1, round(size * ly / lx))

    colours = _floe_colours(rad, spd, frz, labels, float(speed_scale))
    pos = np.mod(pos, box)

    def screen(p):
        return int(round(p[0] * scale)), int(round(height - p[1] * scale))

    surf = pygame.Surface((width, height))
    surf.fill(BACKGROUND)
    for p, r, c in zip(pos, rad, colours):
        c = tuple(int(v) for v in c)
        r_px = max(1, int(round(r * scale)))
        for dx in _shifts(p[0], r, lx):
            for dy in _shifts(p[1], r, ly):
                x, y = screen(p + (dx, dy))
                pygame.gfxdraw.aacircle(surf, x, y, r_px, c)
                pygame.gfxdraw.filled_circle(surf, x, y, r_px, c)

    if all(given) and k and cf.max() > 0:
        fmax = cf.max()
        for i, j, f in zip(ci, cj, cf):
            if f == 0:
                continue
            d = pos[j] - pos[i]
            d -= box * np.round(d / box)          # minimum image
            line_width = 1 + int(round(4 * f / fmax))
            pygame.draw.line(surf, CHAIN, screen(pos[i]), screen(pos[i] + d), line_width)

    return _to_array(surf, pygame)


def _route_edges(points: np.ndarray, half: float) -> tuple[np.ndarray, np.ndarray]:
    """The two edges of a route's swath: ``points`` (M ≥ 2, 2) moved
    ``half`` [m] to either side along the route's normal."""
    d = np.gradient(points, axis=0)
    normal = np.column_stack([-d[:, 1], d[:, 0]])
    normal /= np.maximum(np.hypot(normal[:, 0], normal[:, 1]), 1e-12)[:, None]
    return points - half * normal, points + half * normal


HULL = (235, 90, 40)            # orange
TRACK = (250, 250, 250)         # white
GOAL = (60, 220, 90)            # green
CHANNEL = (120, 160, 200)       # light blue
ROUTE = (255, 60, 200)          # magenta: a planner's route and swath


def draw_ship(picture, box_size, hull_vertices, track=None, *, goal_x=None,
              channel=None, route=None) -> np.ndarray:
    """The picture of :func:`draw_floes` with a ship drawn over it.

    Parameters
    ----------
    picture : (H, W, 3) uint8
        A frame of :func:`draw_floes` of the box ``box_size``.
    box_size : (lx, ly)
        Box side lengths [m].
    hull_vertices : (K, 2) array of float
        Hull corners in the world frame [m] (not wrapped; the hull is drawn
        at its image whose centroid lies in the box).
    track : (M, 2) array of float, optional
        Past positions of the ship [m], drawn as a white line (wrapped into
        the box; a jump across a periodic edge is not joined).
    goal_x : float, optional
        The goal line x = goal_x [m], drawn green across the box.
    channel : (y0, y1), optional
        The channel's edges [m], drawn as light-blue lines.
    route : ((K, 2) array, float), optional
        A planned route [m] and the half-width [m] of its swath: the route
        drawn as a magenta line, the swath's edges as thin ones (wrapped
        into the box like the track).

    Returns
    -------
    np.ndarray
        A new (H, W, 3) uint8 picture.
    """
    pic = np.asarray(picture)
    if pic.ndim != 3 or pic.shape[2] != 3 or pic.dtype != np.uint8:
        raise ValueError(f"picture must be an (H, W, 3) uint8 array, got {pic.shape} {pic.dtype}")
    box = np.asarray(box_size, dtype=float)
    if box.shape != (2,) or not np.all(np.isfinite(box)) or np.any(box <= 0):
        raise ValueError(f"box_size must be two positive finite lengths, got {box_size!r}")
    hull = np.asarray(hull_vertices, dtype=float)
    if hull.ndim != 2 or hull.shape[1] != 2 or hull.shape[0] < 3 or not np.all(np.isfinite(hull)):
        raise ValueError(f"hull_vertices must be a finite (K >= 3, 2) array, got {hull.shape}")
    pygame = _pygame()
    height, width = pic.shape[:2]
    scale = width / box[0]

    def screen(p):
        return int(round(p[0] * scale)), int(round(height - p[1] * scale))

    surf = pygame.surfarray.make_surface(np.ascontiguousarray(np.transpose(pic, (1, 0, 2))))
    if channel is not None:
        for y in channel:
            pygame.draw.line(surf, CHANNEL, screen((0.0, y)), screen((box[0], y)), 1)
    if goal_x is not None:
        x = float(goal_x) % box[0]
        pygame.draw.line(surf, GOAL, screen((x, 0.0)), screen((x, box[1])), 3)
    def polyline(points, colour, width):
        t = np.asarray(points, dtype=float).reshape(-1, 2)
        wrapped = np.mod(t, box)
        for a, b, ra, rb in zip(wrapped[:-1], wrapped[1:], t[:-1], t[1:]):
            if np.allclose(b - a, rb - ra):
                pygame.draw.line(surf, colour, screen(a), screen(b), width)

    if route is not None:
        points, half = route
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        half = _check_number("route half-width", half)
        if points.shape[0] >= 2 and np.all(np.isfinite(points)):
            for edge in _route_edges(points, half):
                polyline(edge, ROUTE, 1)
            polyline(points, ROUTE, 2)
    if track is not None:
        polyline(track, TRACK, 2)
    centre = hull.mean(axis=0)
    shift = np.mod(centre, box) - centre
    points = [screen(p) for p in hull + shift]
    pygame.draw.polygon(surf, HULL, points)
    pygame.draw.polygon(surf, (0, 0, 0), points, 1)
    return _to_array(surf, pygame)


# -- a window of a channel, to scale, with axes --------------------------------------------

#: the views of a ship environment's frames (:func:`view_window`)
VIEWS = ("follow", "overview")
#: colours of the thickness classes of the floes, thinnest first (:func:`thickness_colours`)
THICKNESS_COLOURS = (
    (222, 232, 242),    # ice white: the thinnest class
    (238, 186, 84),     # amber: the next (e.g. multi-year or ridged ice)
    (200, 120, 214),    # orchid: a third
)
FLOE_EDGE = (70, 92, 120)       # outline of a floe
LEAD = (36, 104, 156)           # a lead's open water, lighter than the sea
LEAD_EDGE = (110, 205, 240)     # its outline
OUTSIDE = (62, 64, 70)          # beyond a wall of the box
WALL = (200, 200, 200)          # a wall of the box
AXES = (210, 212, 218)          # axes, ticks and their labels (on the panel background)
#: the picture's margins round the plot [px]: left (y ticks), top (title),
#: right and bottom (x ticks and the x label)
VIEW_MARGINS = (58, 30, 18, 46)


class ViewBox:
    """A window ``x0 ≤ x ≤ x1``, ``y0 ≤ y ≤ y1`` [m] of the world drawn to
    scale (``scale`` pixels per metre along both axes, y up) in a plot
    whose top-left corner lies at pixel (``left``, ``top``) of a picture
    with the margins :data:`VIEW_MARGINS` round the plot."""

    def __init__(self, x0: float, x1: float, y0: float, y1: float, scale: float):
        for name, v in (("x0", x0), ("x1", x1), ("y0", y0), ("y1", y1), ("scale", scale)):
            _check_number(name, v)
        if not (x1 > x0 and y1 > y0 and scale > 0):
            raise ValueError(f"a view box needs x0 < x1, y0 < y1 and scale > 0, got "
                             f"x {x0!r}..{x1!r}, y {y0!r}..{y1!r}, scale {scale!r}")
        self.x0, self.x1, self.y0, self.y1 = float(x0), float(x1), float(y0), float(y1)
        self.scale = float(scale)
        self.left, self.top = VIEW_MARGINS[0], VIEW_MARGINS[1]
        #: the plot's size [px]
        self.width = max(1, int(round((self.x1 - self.x0) * self.scale)))
        self.height = max(1, int(round((self.y1 - self.y0) * self.scale)))

    @property
    def picture_size(self) -> tuple[int, int]:
        """(width, height) [px] of the picture of :func:`draw_view`, margins included."""
        return (self.left + self.width + VIEW_MARGINS[2],
                self.top + self.height + VIEW_MARGINS[3])

    @property
    def plot(self) -> tuple[slice, slice]:
        """(rows, columns) of the plot in the picture (index a frame with it)."""
        return (slice(self.top, self.top + self.height),
                slice(self.left, self.left + self.width))

    def pixels(self, points) -> np.ndarray:
        """(N, 2) pixel coordinates (column, row), as floats, of world
        points ``points`` (N, 2) [m]."""
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        return np.column_stack([self.left + (p[:, 0] - self.x0) * self.scale,
                                self.top + (self.y1 - p[:, 1]) * self.scale])

    def __repr__(self):
        return (f"ViewBox(x {self.x0:g}..{self.x1:g} m, y {self.y0:g}..{self.y1:g} m, "
                f"{self.scale:.3g} px/m)")


def view_box(window, *, max_width: int = 960, max_height: int = 600) -> ViewBox:
    """The :class:`ViewBox` of ``window`` ``(x0, x1, y0, y1)`` [m] at the
    largest scale at which its plot fits ``max_width`` × ``max_height``
    pixels (one scale along both axes: no distortion)."""
    try:
        x0, x1, y0, y1 = (float(v) for v in window)
    except (TypeError, ValueError):
        raise ValueError(f"window must be (x0, x1, y0, y1) [m], got {window!r}") from None
    if not (np.isfinite([x0, x1, y0, y1]).all() and x1 > x0 and y1 > y0):
        raise ValueError(f"window must be finite with x0 < x1 and y0 < y1, got {window!r}")
    w = _check_size(max_width, "max_width")
    h = _check_size(max_height, "max_height")
    return ViewBox(x0, x1, y0, y1, min(w / (x1 - x0), h / (y1 - y0)))


def view_window(view: str, box_size, ship_x: float, *, behind: float = 100.0,
                ahead: float = 300.0) -> tuple:
    """The window ``(x0, x1, y0, y1)`` [m] of a view of a channel along
    +x of ``box_size`` (lx, ly) [m]: ``"follow"``, from ``behind`` [m]
    behind ``ship_x`` to ``ahead`` [m] ahead of it across the whole width
    (it may reach beyond the box's ends: the ship keeps its place in the
    frame); ``"overview"``, the whole box."""
    if view not in VIEWS:
        raise ValueError(f"view must be one of {VIEWS}, got {view!r}")
    lx, ly = (float(v) for v in box_size)
    if view == "overview":
        return 0.0, lx, 0.0, ly
    behind, ahead = _check_number("behind", behind), _check_number("ahead", ahead)
    if behind < 0 or ahead < 0 or behind + ahead <= 0:
        raise ValueError(f"behind and ahead must be >= 0 with a positive sum, got {behind!r} "
                         f"and {ahead!r}")
    x = _check_number("ship_x", ship_x)
    return x - behind, x + ahead, 0.0, ly


def thickness_colours(thickness, classes=None) -> tuple[np.ndarray, list]:
    """Colours of floes by thickness class, and the legend of the classes present.

    Parameters
    ----------
    thickness : (N,) array of float
        The floes' thicknesses [m].
    classes : sequence of float, optional
        The thicknesses [m] of the field's classes (e.g. the task's thin and
        thick ice); each floe takes the class nearest its thickness. Default:
        the distinct thicknesses of the floes (to the millimetre).

    Returns
    -------
    (colours, legend)
        ``(N, 3)`` uint8 colours, :data:`THICKNESS_COLOURS` from the thinnest
        class up, and ``[(colour, "ice 1.2 m thick"), ...]`` of the classes
        that floes fall in. With more classes than colours, the colormap of
        :func:`draw_floes` from the thinnest to the thickest, and a legend of
        the two ends.
    """
    h = _vector("thickness", thickness)
    if classes is None:
        levels = np.unique(np.round(h, 3))
    else:
        levels = np.unique(_vector("classes", classes))
        if levels.size == 0 or np.any(levels <= 0):
            raise ValueError(f"classes must be positive thicknesses, got {classes!r}")
    if levels.size == 0:
        return np.empty((0, 3), dtype=np.uint8), []
    if levels.size > len(THICKNESS_COLOURS):
        lo, hi = float(levels[0]), float(levels[-1])
        colours = _colormap((h - lo) / (hi - lo))
        ends = _colormap(np.array([0.0, 1.0]))
        return colours, [(tuple(int(v) for v in ends[0]), f"ice {_metres(lo)} thick"),
                         (tuple(int(v) for v in ends[1]), f"ice {_metres(hi)} thick")]
    nearest = np.argmin(np.abs(h[:, None] - levels[None, :]), axis=1) if h.size else \
        np.zeros(0, dtype=np.int64)
    palette = np.array(THICKNESS_COLOURS[:levels.size], dtype=np.uint8)
    legend = [(THICKNESS_COLOURS[k], f"ice {_metres(levels[k])} thick")
              for k in np.unique(nearest)]
    return palette[nearest], legend


def _metres(h: float) -> str:
    """A thickness [m] as text: one decimal ("3.0 m"), or two significant digits below 0.1 m."""
    return f"{h:.1f} m" if abs(round(h, 1) - h) < 1e-9 and h >= 0.1 else f"{h:.2g} m"


def _image_shifts(lo, hi, window_lo: float, window_hi: float, period: float | None) -> list:
    """Shifts k·period of the periodic images of items spanning [lo, hi]
    (arrays, over all items) that can meet [window_lo, window_hi]; ``[0.0]``
    along an axis that is not periodic."""
    if period is None or np.size(lo) == 0:
        return [0.0]
    k0 = int(np.ceil((window_lo - np.max(hi)) / period))
    k1 = int(np.floor((window_hi - np.min(lo)) / period))
    return [k * period for k in range(k0, k1 + 1)]


def _unwrapped(points, periods) -> np.ndarray:
    """A path of ``points`` (M, 2) with its jumps across periodic edges undone."""
    p = np.asarray(points, dtype=float).reshape(-1, 2).copy()
    for axis, period in enumerate(periods):
        if period is not None and p.shape[0] > 1:
            d = np.diff(p[:, axis])
            d -= period * np.round(d / period)
            p[1:, axis] = p[0, axis] + np.cumsum(d)
    return p


def _nice_length(target: float) -> float:
    """The largest of 1, 2 and 5 times a power of ten not above ``target`` (> 0)."""
    power = 10.0 ** np.floor(np.log10(target))
    return max(m * power for m in (1.0, 2.0, 5.0) if m * power <= target * (1 + 1e-9))


def _tick_step(span: float, pixels: float, spacing: float) -> float:
    """A round tick step (1, 2 or 5 times a power of ten) with ticks at
    least ``spacing`` pixels apart along ``pixels`` for ``span`` metres."""
    most = max(1.0, pixels / spacing)
    step = _nice_length(span / most)
    return step if span / step <= most + 1e-9 else 2.0 * step


def draw_view(box: ViewBox, positions, radii, box_size, *, periodic=(False, True),
              floe_colours=None, contact_i=None, contact_j=None, contact_force=None,
              hull_vertices=None, track=None, goal_x=None, channel=None, route=None,
              leads=(), ice_band=None, title=None) -> np.ndarray:
    """RGB picture ``(H, W, 3)`` uint8 of the window ``box`` of a box of
    floes, to scale, with axes in metres and a scale bar.

    Parameters
    ----------
    box : ViewBox
        The window and its scale (:func:`view_box`); the picture is
        ``box.picture_size``, the plot at ``box.plot``.
    positions, radii : (N, 2), (N,) arrays of float
        Floe centres and radii [m]; each floe a disc at its true size,
        clipped at the plot's edge, with its periodic images.
    box_size : (lx, ly)
        The box [m], spanning ``[0, lx] × [0, ly]``.
    periodic : (bool, bool)
        Which axes are periodic; a wall closes each other axis at 0 and at
        its length, and what lies beyond it is shaded (:data:`OUTSIDE`).
    floe_colours : (N, 3) uint8, optional
        The floes' colours (e.g. :func:`thickness_colours`); default all
        the thinnest class's.
    contact_i, contact_j, contact_force : (K,) arrays, optional
        Contact forces [N] as dark-red lines between the centres (nearest
        images), 1 to 4 px wide in proportion to force / the largest force.
    hull_vertices : (K, 2) array of float, optional
        The ship's hull [m] (with its periodic images).
    track : (M, 2) array of float, optional
        The ship's past positions [m], a white line.
    goal_x : float, optional
        The goal line x = goal_x [m], green.
    channel : (y0, y1), optional
        The channel's edges [m], light-blue lines.
    route : ((K, 2) array, float), optional
        A planned route [m] and the half-width [m] of its swath: a magenta
        line and thin lines at the swath's edges.
    leads : sequence of lead-like objects, optional
        Bands of open water with ``x``, ``y``, ``angle``, ``width`` and
        ``length`` [m, rad] (:class:`physics.ice_fields.Lead`): each is
        shaded (:data:`LEAD`) and outlined (:data:`LEAD_EDGE`) where floes
        could not be placed, within half its width of its centre line,
        wrapping round a periodic y, and within ``ice_band``.
    ice_band : (x0, x1), optional
        The band of ice [m] along x that the leads cut (e.g. a
        :class:`physics.ice_fields.TransitBox`'s ``band``); default the whole box
        (inside its walls).
    title : str, optional
        A line of text over the plot.

    Returns
    -------
    np.ndarray
        The picture: the plot (sea blue) in a dark frame with tick labels
        along x and y at round values in the box's coordinates [m], the
        axis names, and a scale bar in the plot's lower right corner.
    """
    if not isinstance(box, ViewBox):
        raise ValueError(f"box must be a ViewBox, got {type(box).__name__}")
    pos = np.asarray(positions, dtype=float)
    if pos.ndim != 2 or pos.shape[1] != 2 or not np.all(np.isfinite(pos)):
        raise ValueError(f"positions must be a finite (N, 2) array, got shape {pos.shape}")
    n = pos.shape[0]
    rad = _vector("radii", radii, n)
    if np.any(rad <= 0):
        raise ValueError("radii must be positive")
    size = np.asarray(box_size, dtype=float)
    if size.shape != (2,) or not np.all(np.isfinite(size)) or np.any(size <= 0):
        raise ValueError(f"box_size must be two positive finite lengths, got {box_size!r}")
    if len(periodic) != 2 or not all(isinstance(p, (bool, np.bool_)) for p in periodic):
        raise ValueError(f"periodic must be two booleans, got {periodic!r}")
    periods = tuple(float(size[a]) if periodic[a] else None for a in range(2))
    if floe_colours is None:
        colours = np.tile(np.array(THICKNESS_COLOURS[0], dtype=np.uint8), (n, 1))
    else:
        colours = np.asarray(floe_colours)
        if colours.shape != (n, 3) or colours.dtype.kind not in "iu":
            raise ValueError(f"floe_colours must be an ({n}, 3) integer array, got shape "
                             f"{colours.shape}")
    given = [c is not None for c in (contact_i, contact_j, contact_force)]
    if any(given) and not all(given):
        raise ValueError("contact_i, contact_j and contact_force must be given together")
    if all(given):
        ci = _vector("contact_i", contact_i, dtype=np.int64)
        cj = _vector("contact_j", contact_j, ci.shape[0], np.int64)
        cf = np.abs(_vector("contact_force", contact_force, ci.shape[0]))
        for name, idx in (("contact_i", ci), ("contact_j", cj)):
            if np.any((idx < 0) | (idx >= n)):
                raise ValueError(f"{name} must index floes in [0, {n})")
    hull = None
    if hull_vertices is not None:
        hull = np.asarray(hull_vertices, dtype=float)
        if hull.ndim != 2 or hull.shape[1] != 2 or hull.shape[0] < 3 \
                or not np.all(np.isfinite(hull)):
            raise ValueError(f"hull_vertices must be a finite (K >= 3, 2) array, got "
                             f"{hull.shape}")
    for k, lead in enumerate(leads):
        try:
            values = [float(getattr(lead, name)) for name in ("x", "y", "angle", "width")]
            length = float(lead.length)
        except (AttributeError, TypeError, ValueError):
            raise ValueError(f"lead {k} must have numbers x, y, angle, width and length "
                             f"(physics.ice_fields.Lead), got {lead!r}") from None
        if not (np.all(np.isfinite(values)) and values[3] > 0 and length > 0):
            raise ValueError(f"lead {k} must have finite x, y, angle, a positive width and a "
                             f"positive length, got {lead!r}")
    if ice_band is None:
        band = (-np.inf, np.inf) if periods[0] is not None else (0.0, float(size[0]))
    else:
        try:
            band = tuple(float(b) for b in ice_band)
        except (TypeError, ValueError):
            band = ()
        if len(band) != 2 or not np.all(np.isfinite(band)) or not band[0] < band[1]:
            raise ValueError(f"ice_band must be (x0, x1) with x0 < x1, got {ice_band!r}")
    if title is not None and not isinstance(title, str):
        raise ValueError(f"title must be a string, got {title!r}")

    pygame = _pygame()
    writer = _Writer(pygame)
    width, height = box.picture_size
    surf = pygame.Surface((width, height))
    surf.fill(PANEL_BACKGROUND)
    plot = pygame.Rect(box.left, box.top, box.width, box.height)
    surf.set_clip(plot)
    surf.fill(BACKGROUND)
    lo = np.array([box.x0, box.y0])
    hi = np.array([box.x1, box.y1])

    def px(p):
        q = box.pixels(p)
        return [(int(round(c)), int(round(r))) for c, r in q]

    def shifts(points_lo, points_hi):
        """(dx, dy) shifts of the periodic images meeting the window."""
        sx = _image_shifts(points_lo[..., 0], points_hi[..., 0], box.x0, box.x1, periods[0])
        sy = _image_shifts(points_lo[..., 1], points_hi[..., 1], box.y0, box.y1, periods[1])
        return [np.array([dx, dy]) for dx in sx for dy in sy]

    # beyond the walls
    for axis in (0, 1):
        if periods[axis] is None:
            for a, b in ((lo[axis], min(0.0, hi[axis])), (max(size[axis], lo[axis]), hi[axis])):
                if b > a:
                    corner = lo.copy(), hi.copy()
                    corner[0][axis], corner[1][axis] = a, b
                    (c0, r1), (c1, r0) = px(corner[0])[0], px(corner[1])[0]
                    pygame.draw.rect(surf, OUTSIDE, (c0, r0, c1 - c0 + 1, r1 - r0 + 1))

    # leads: open water within half the width of the centre line, in the band of ice
    cut = (max(band[0], box.x0), min(band[1], box.x1),
           box.y0 if periods[1] is not None else max(0.0, box.y0),
           box.y1 if periods[1] is not None else min(float(size[1]), box.y1))
    if leads and cut[1] > cut[0] and cut[3] > cut[2]:
        (c0, r0), (c1, r1) = px([(cut[0], cut[3]), (cut[1], cut[2])])
        surf.set_clip(plot.clip(pygame.Rect(c0, r0, c1 - c0 + 1, r1 - r0 + 1)))
    else:
        leads = ()
    for lead in leads:
        half_w = 0.5 * float(lead.width)
        c, s = np.cos(lead.angle), np.sin(lead.angle)
        length = float(lead.length)
        if not np.isfinite(length):          # a line across: long enough to cross the window
            length = 2.0 * (np.hypot(*(hi - lo)) + np.hypot(lead.x - 0.5 * (lo[0] + hi[0]),
                                                               lead.y - 0.5 * (lo[1] + hi[1])))
        u = np.array([c, s]) * 0.5 * length
        ends = np.array([[lead.x, lead.y]]) + np.stack([-u, u])
        nrm = np.array([-s, c]) * half_w
        corners = np.stack([ends[0] + nrm, ends[1] + nrm, ends[1] - nrm, ends[0] - nrm])
        for d in shifts(corners.min(axis=0) - half_w, corners.max(axis=0) + half_w):
            outline = px(corners + d)
            caps = px(ends + d)
            r_px = max(1, int(round(half_w * box.scale)))
            pygame.draw.polygon(surf, LEAD, outline)
            for cx, cy in caps:
                pygame.draw.circle(surf, LEAD, (cx, cy), r_px)
            for k in (0, 2):
                pygame.draw.aaline(surf, LEAD_EDGE, outline[k], outline[k + 1])
            for (cx, cy), out in zip(caps, (-u, u)):
                # the round ends: the outer half of each circle (angles y up, as on screen)
                phi = float(np.arctan2(out[1], out[0]))
                rect = pygame.Rect(cx - r_px, cy - r_px, 2 * r_px, 2 * r_px)
                pygame.draw.arc(surf, LEAD_EDGE, rect, phi - 0.5 * np.pi, phi + 0.5 * np.pi)

    surf.set_clip(plot)

    # floes, with their periodic images
    wrapped = pos.copy()
    for axis, period in enumerate(periods):
        if period is not None:
            wrapped[:, axis] = np.mod(wrapped[:, axis], period)
    edge_px = 3
    if n:
        for d in shifts(wrapped - rad[:, None], wrapped + rad[:, None]):
            p = wrapped + d
            inside = np.all((p + rad[:, None] >= lo) & (p - rad[:, None] <= hi), axis=1)
            for k in np.nonzero(inside)[0]:
                (x, y), = px(p[k])
                r_px = max(1, int(round(rad[k] * box.scale)))
                colour = tuple(int(v) for v in colours[k])
                pygame.gfxdraw.filled_circle(surf, x, y, r_px, colour)
                pygame.gfxdraw.aacircle(surf, x, y, r_px,
                                        FLOE_EDGE if r_px >= edge_px else colour)

    # contact forces
    if all(given) and ci.size and cf.max() > 0:
        a = wrapped[ci]
        b = wrapped[cj] - wrapped[ci]
        for axis, period in enumerate(periods):
            if period is not None:
                b[:, axis] -= period * np.round(b[:, axis] / period)
        b += a
        line_w = 1 + np.rint(3.0 * cf / cf.max()).astype(int)
        for d in shifts(np.minimum(a, b), np.maximum(a, b)):
            for k in np.nonzero(cf > 0)[0]:
                pygame.draw.line(surf, CHAIN, px(a[k] + d)[0], px(b[k] + d)[0], int(line_w[k]))

    # lines of the task: the goal, the channel's edges
    if goal_x is not None:
        gx = _check_number("goal_x", goal_x)
        for d in shifts(np.array([gx, box.y0]), np.array([gx, box.y0])):
            x = gx + d[0]
            pygame.draw.line(surf, GOAL, px((x, box.y0))[0], px((x, box.y1))[0], 3)
    if channel is not None:
        for y in channel:
            y = _check_number("channel edge", y)
            for d in shifts(np.array([box.x0, y]), np.array([box.x0, y])):
                pygame.draw.line(surf, CHANNEL, px((box.x0, y + d[1]))[0],
                                 px((box.x1, y + d[1]))[0], 1)

    def path(points, colour, line_width):
        t = _unwrapped(points, periods)
        if t.shape[0] < 2 or not np.all(np.isfinite(t)):
            return
        for d in shifts(t.min(axis=0), t.max(axis=0)):
            pygame.draw.lines(surf, colour, False, px(t + d), line_width)

    if route is not None:
        points, half = route
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        half = _check_number("route half-width", half)
        if points.shape[0] >= 2 and np.all(np.isfinite(points)):
            points = _unwrapped(points, periods)
            for edge in _route_edges(points, half):
                path(edge, ROUTE, 1)
            path(points, ROUTE, 3)
    if track is not None:
        path(track, TRACK, 2)
    if hull is not None:
        for d in shifts(hull.min(axis=0), hull.max(axis=0)):
            points = px(hull + d)
            pygame.draw.polygon(surf, HULL, points)
            pygame.draw.polygon(surf, (0, 0, 0), points, 1)

    # the walls
    for axis in (0, 1):
        if periods[axis] is None:
            for at in (0.0, float(size[axis])):
                if lo[axis] <= at <= hi[axis]:
                    a, b = lo.copy(), hi.copy()
                    a[axis] = b[axis] = at
                    pygame.draw.line(surf, WALL, px(a)[0], px(b)[0], 3)

    _scale_bar(surf, pygame, writer, box)
    surf.set_clip(None)
    pygame.draw.rect(surf, AXES, plot.inflate(2, 2), 1)
    _axes(surf, pygame, writer, box)
    if title:
        writer.write(surf, title, 18, PANEL_TEXT, "midleft", (box.left, box.top / 2),
                     box.width)
    return _to_array(surf, pygame)


def _axes(surf, pygame, writer, box: ViewBox) -> None:
    """Ticks and labels [m] under the plot (x) and left of it (y), and the axis names."""
    font_px = 16
    bottom = box.top + box.height
    step = _tick_step(box.x1 - box.x0, box.width, 80.0)
    for k in range(int(np.ceil(box.x0 / step - 1e-9)), int(np.floor(box.x1 / step + 1e-9)) + 1):
        x = int(round(box.pixels((k * step, box.y0))[0, 0]))
        pygame.draw.line(surf, AXES, (x, bottom), (x, bottom + 5))
        writer.write(surf, f"{k * step:g}", font_px, AXES, "midtop", (x, bottom + 7))
    writer.write(surf, "x [m] (along the route)", font_px, AXES, "midtop",
                 (box.left + box.width / 2, bottom + 9 + font_px))
    step = _tick_step(box.y1 - box.y0, box.height, 40.0)
    for k in range(int(np.ceil(box.y0 / step - 1e-9)), int(np.floor(box.y1 / step + 1e-9)) + 1):
        y = int(round(box.pixels((box.x0, k * step))[0, 1]))
        pygame.draw.line(surf, AXES, (box.left - 5, y), (box.left, y))
        writer.write(surf, f"{k * step:g}", font_px, AXES, "midright", (box.left - 7, y),
                     box.left - 22)
    label = writer.render("y [m]", font_px, AXES)
    if label is not None:
        label = pygame.transform.rotate(label, 90)
        surf.blit(label, label.get_rect(center=(font_px // 2 + 2, box.top + box.height / 2)))


def _scale_bar(surf, pygame, writer, box: ViewBox) -> None:
    """A bar of a round length (about a sixth of the plot) in its lower right corner."""
    length = _nice_length((box.x1 - box.x0) / 6.0)
    bar = int(round(length * box.scale))
    font_px = 16
    pad = 6
    w, h = bar + 2 * pad, font_px + 16
    x0 = box.left + box.width - w - 8
    y0 = box.top + box.height - h - 8
    if x0 < box.left or y0 < box.top:
        return
    shade = pygame.Surface((w, h), pygame.SRCALPHA)
    shade.fill((*PANEL_BACKGROUND, 190))
    surf.blit(shade, (x0, y0))
    y = y0 + h - pad - 2
    pygame.draw.line(surf, PANEL_TEXT, (x0 + pad, y), (x0 + pad + bar, y), 3)
    for x in (x0 + pad, x0 + pad + bar):
        pygame.draw.line(surf, PANEL_TEXT, (x, y - 4), (x, y + 1), 2)
    writer.write(surf, f"{length:g} m", font_px, PANEL_TEXT, "midbottom",
                 (x0 + pad + bar / 2, y - 3))


def _arrow_entries(arrow, arrow_label) -> list:
    """``[(vector, label, colour), ...]`` from the ``arrow`` and ``arrow_label`` of annotate."""
    if arrow is None:
        if arrow_label is not None:
            raise ValueError("arrow_label needs an arrow")
        return []
    try:
        vec = np.asarray(arrow, dtype=float)
    except (TypeError, ValueError):
        vec = None
    if vec is not None:                            # one vector
        if vec.shape != (2,):
            raise ValueError("arrow must be a 2-vector (ax, ay) or a sequence of one or two "
                             f"(vector, label[, colour]) entries, got shape {vec.shape}")
        raw = [(vec, arrow_label)]
    else:
        if arrow_label is not None:
            raise ValueError("arrow_label is only for a single arrow vector; put the labels "
                             "in the (vector, label[, colour]) entries")
        if isinstance(arrow, (str, bytes)) or not isinstance(arrow, Sequence) \
                or not 1 <= len(arrow) <= 2:
            raise ValueError("arrow must be a 2-vector (ax, ay) or a sequence of one or two "
                             "(vector, label[, colour]) entries")
        raw = list(arrow)
    entries = []
    for k, entry in enumerate(raw):
        if isinstance(entry, (str, bytes)) or not isinstance(entry, Sequence) \
                or len(entry) not in (2, 3):
            raise ValueError(f"arrow entry {k} must be (vector, label[, colour]), got {entry!r}")
        vector, label = entry[0], entry[1]
        colour = entry[2] if len(entry) == 3 else None
        try:
            v = np.asarray(vector, dtype=float)
        except (TypeError, ValueError):
            v = np.empty(0)
        if v.shape != (2,):
            raise ValueError(f"arrow vector {k} must be a 2-vector (ax, ay), got {vector!r}")
        if not np.all(np.isfinite(v)):
            raise ValueError(f"arrow vector {k} must be finite, got {vector!r}")
        norm = float(np.hypot(*v))
        if norm > 1.0:
            v = v / norm                           # longer than full length: clipped
        if label is not None and not isinstance(label, str):
            raise ValueError(f"arrow label {k} must be a string or None, got {label!r}")
        colour = ARROW_COLOURS[k] if colour is None else _check_colour(f"arrow colour {k}",
                                                                        colour)
        entries.append((v, label, colour))
    return entries


def _draw_arrow(surf, pygame, centre, vector, radius: float, colour) -> None:
    """An arrow of length ``|vector| * radius`` [px] from ``centre`` (vector y up)."""
    cx, cy = centre
    length = float(np.hypot(*vector)) * radius
    half = max(1.5, 0.06 * radius)                 # half the shaft width
    if length < 1.0:                               # calm: a dot
        pygame.gfxdraw.filled_circle(surf, int(cx), int(cy), int(round(half)), colour)
        return
    u = np.array([vector[0], -vector[1]]) / np.hypot(*vector)   # screen direction
    n = np.array([-u[1], u[0]])
    head = min(0.4 * radius, length)
    head_half = max(3.0, 0.18 * radius)
    c = np.array([cx, cy], dtype=float)
    tip = c + u * length
    neck = tip - u * head
    shapes = [[tip, neck + n * head_half, neck - n * head_half]]
    if head < length:
        shapes.append([c + n * half, neck + n * half, neck - n * half, c - n * half])
    for shape in shapes:
        points = [(int(round(x)), int(round(y))) for x, y in shape]
        pygame.gfxdraw.aapolygon(surf, points, colour)
        pygame.gfxdraw.filled_polygon(surf, points, colour)


#: where :func:`annotate` puts its panel
SIDES = ("right", "bottom")
#: the shapes of a legend's swatch: a disc (a floe), a line, a band (an area)
LEGEND_KINDS = ("disc", "line", "band")


def _legend_entries(legend) -> list:
    """``[(colour, text, kind), ...]`` of the ``legend`` of :func:`annotate`."""
    if legend is None:
        return []
    if isinstance(legend, (str, bytes)) or not isinstance(legend, Sequence):
        raise ValueError(f"legend must be a sequence of (colour, text[, kind]), got {legend!r}")
    swatches = []
    for k, entry in enumerate(legend):
        if isinstance(entry, (str, bytes)) or not isinstance(entry, Sequence) \
                or len(entry) not in (2, 3) or not isinstance(entry[1], str):
            raise ValueError(f"legend entry {k} must be (colour, text[, kind]), got {entry!r}")
        kind = entry[2] if len(entry) == 3 else "disc"
        if kind not in LEGEND_KINDS:
            raise ValueError(f"legend entry {k}: kind must be one of {LEGEND_KINDS}, "
                             f"got {kind!r}")
        swatches.append((_check_colour(f"legend colour {k}", entry[0]), entry[1], kind))
    return swatches


def _swatch(surf, pygame, colour, kind: str, x: int, y: int, size: int) -> None:
    """A legend swatch ``size`` px wide, its left at ``x``, centred on row ``y``."""
    if kind == "line":
        pygame.draw.line(surf, colour, (x, y), (x + size - 1, y), 3)
    elif kind == "band":
        half = max(2, size // 3)
        pygame.draw.rect(surf, colour, (x, y - half, size, 2 * half))
    else:
        r = max(3, size // 2)
        pygame.gfxdraw.aacircle(surf, x + r, y, r, colour)
        pygame.gfxdraw.filled_circle(surf, x + r, y, r, colour)


def annotate(picture, *, colour_bar=None, legend=None, arrow=None, arrow_label=None, text=(),
             panel_width=None, side="right") -> np.ndarray:
    """A new RGB frame: ``picture`` unchanged at the top left and a panel on
    its right (``side="right"``) or under it (``side="bottom"``).

    The right panel (dark background) holds, top to bottom, the lines of
    ``text``, the arrow(s), the colour bar and the legend; any of them may be
    left out. The bottom panel, a strip for a wide picture, holds them left to
    right, the text and the legend in columns of up to four lines.

    Parameters
    ----------
    picture : (H, W, 3) array of uint8
        The frame to annotate, e.g. from :func:`draw_floes` or :func:`draw_itd`.
    colour_bar : (label, low, high), optional
        A vertical colour bar of the colormap of :func:`draw_floes`, from
        ``low`` (bottom) to ``high`` (top), in the units written in ``label``
        (e.g. ``("speed [m/s]", 0.0, SPEED_SCALE)``), with ticks and values at
        low, middle and high. ``low < high``, both finite.
    legend : sequence of (colour, text) or (colour, text, kind), optional
        Colour swatches (RGB triples of ints in [0, 255]) with their text, one
        a line, e.g. :data:`CLUSTER_LEGEND`; ``kind`` (:data:`LEGEND_KINDS`)
        is the swatch's shape: ``"disc"`` (default), ``"line"`` or ``"band"``.
    arrow : (ax, ay) or sequence of (vector, label[, colour]), optional
        A direction, drawn as an arrow from the centre of a small circle whose
        radius is the full length: ``(ax, ay)`` is dimensionless, y up, with
        ``hypot(ax, ay) <= 1`` the fraction of the full length (longer vectors
        are clipped to 1), e.g. ``wind / 20`` for the wind [m/s] on a 20 m/s
        scale. A zero vector draws a dot. To show two directions in the same
        circle (e.g. the wind and a target heading), pass one or two entries
        ``(vector, label)`` or ``(vector, label, colour)``; a missing or None
        colour is taken from :data:`ARROW_COLOURS` (white, then orange) and
        each label is written under the circle in its arrow's colour.
    arrow_label : str, optional
        Text under the circle (e.g. ``"wind 14.1 m/s"``); only with a single
        ``(ax, ay)`` arrow.
    text : str or sequence of str, optional
        Short lines of text (e.g. ``"t = 300 s"``, ``"A = 0.812"``); a single
        string is one line. Lines too long for the right panel are written
        smaller.
    panel_width : int, optional
        Width [px] of the right panel; default ``max(PANEL_MIN_WIDTH,
        round(PANEL_FRACTION * W))``, i.e. 0.3 W and at least 150 px. Not
        with ``side="bottom"``.
    side : str, optional
        ``"right"`` (default) or ``"bottom"`` (:data:`SIDES`).

    Returns
    -------
    np.ndarray
        Right: ``(H', W + panel_width, 3)`` uint8 RGB frame, ``H' = max(H,
        height the panel needs)``; below a picture shorter than the panel the
        frame is filled with the panel background. Bottom: ``(H + strip
        height, W', 3)``, ``W' = max(W, width the strip needs)``. Text is left
        out when pygame fonts are unavailable.
    """
    pic = np.asarray(picture)
    if pic.ndim != 3 or pic.shape[2] != 3 or pic.dtype != np.uint8 or 0 in pic.shape[:2]:
        raise ValueError(f"picture must be an (H, W, 3) uint8 array, got shape {pic.shape} "
                         f"and dtype {pic.dtype}")
    if not isinstance(side, str) or side not in SIDES:
        raise ValueError(f"side must be one of {SIDES}, got {side!r}")
    h0, w0 = pic.shape[:2]
    if side == "bottom" and panel_width is not None:
        raise ValueError("panel_width is for side='right'; the bottom strip is as wide as "
                         "the picture")
    pw = (max(PANEL_MIN_WIDTH, round(PANEL_FRACTION * w0)) if panel_width is None
          else _check_size(panel_width, "panel_width"))
    lines = [text] if isinstance(text, str) else text
    if lines is None:
        lines = []
    if not isinstance(lines, Sequence) or not all(isinstance(s, str) for s in lines):
        raise ValueError(f"text must be a string or a sequence of strings, got {text!r}")
    arrows = _arrow_entries(arrow, arrow_label)
    bar = None
    if colour_bar is not None:
        if isinstance(colour_bar, (str, bytes)) or not isinstance(colour_bar, Sequence) \
                or len(colour_bar) != 3 or not isinstance(colour_bar[0], str):
            raise ValueError(f"colour_bar must be (label, low, high), got {colour_bar!r}")
        low = _check_number("colour_bar low", colour_bar[1])
        high = _check_number("colour_bar high", colour_bar[2])
        if not low < high:
            raise ValueError(f"colour_bar needs low < high, got {low!r} and {high!r}")
        bar = (colour_bar[0], low, high)
    swatches = _legend_entries(legend)
    pygame = _pygame()
    if side == "bottom":
        return _annotate_bottom(pic, pygame, lines, arrows, bar, swatches)

    # -- layout [px] -------------------------------------------------------------------
    font_px = int(np.clip(round(pw / 9), 12, 22))
    line_h = int(round(1.3 * font_px))
    margin = int(round(0.7 * font_px))
    gap = font_px
    inner = pw - 2 * margin
    radius = int(np.clip(round(0.25 * pw), 16, 64))
    bar_h = int(np.clip(round(0.3 * h0), 60, 220))
    bar_w = int(np.clip(round(0.12 * pw), 12, 28))
    sections = []                                  # (height, draw(y0))
    writer = _Writer(pygame)

    def draw_text(y0):
        for k, line in enumerate(lines):
            writer.write(panel, line, font_px, PANEL_TEXT, "midleft",
                         (margin, y0 + (k + 0.5) * line_h), inner)

    def draw_arrows(y0):
        centre = (pw // 2, y0 + radius)
        _arrow_circle(panel, pygame, centre, radius, arrows)
        y = y0 + 2 * radius + 4
        for _, label, colour in arrows:
            if label:
                writer.write(panel, label, font_px, colour, "midtop", (pw / 2, y), inner)
                y += line_h

    def draw_colour_bar(y0):
        writer.write(panel, bar[0], font_px, PANEL_TEXT, "midleft",
                     (margin, y0 + 0.5 * line_h), inner)
        _colour_bar(panel, pygame, writer, bar, margin, y0 + line_h + line_h // 2, bar_w,
                    bar_h, font_px, pw - margin // 2)

    def draw_legend(y0):
        size = max(6, int(0.64 * line_h))
        for k, (colour, label, kind) in enumerate(swatches):
            y = int(round(y0 + (k + 0.5) * line_h))
            _swatch(panel, pygame, colour, kind, margin, y, size)
            writer.write(panel, label, font_px, PANEL_TEXT, "midleft", (margin + size + 8, y),
                         inner - size - 8)

    if lines:
        sections.append((len(lines) * line_h, draw_text))
    if arrows:
        n_labels = sum(1 for _, label, _ in arrows if label)
        sections.append((2 * radius + 4 + n_labels * line_h, draw_arrows))
    if bar is not None:
        sections.append((2 * line_h + bar_h, draw_colour_bar))
    if swatches:
        sections.append((len(swatches) * line_h, draw_legend))
    needed = 2 * margin + sum(s[0] for s in sections) + gap * max(0, len(sections) - 1)
    height = max(h0, needed)

    panel = pygame.Surface((pw, height))
    panel.fill(PANEL_BACKGROUND)
    y = margin
    for section_height, draw in sections:
        draw(y)
        y += section_height + gap

    frame = np.empty((height, w0 + pw, 3), dtype=np.uint8)
    frame[:] = PANEL_BACKGROUND
    frame[:h0, :w0] = pic
    frame[:, w0:] = _to_array(panel, pygame)
    return frame


def _arrow_circle(surf, pygame, centre, radius: int, arrows) -> None:
    """The circle of the arrows, its ticks at E, W, S and N, and the arrows."""
    pygame.gfxdraw.aacircle(surf, centre[0], centre[1], radius, ARROW_CIRCLE)
    for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        pygame.draw.line(surf, ARROW_CIRCLE,
                         (centre[0] + dx * (radius - 4), centre[1] + dy * (radius - 4)),
                         (centre[0] + dx * radius, centre[1] + dy * radius))
    for v, _, colour in arrows:
        _draw_arrow(surf, pygame, centre, v, radius, colour)


def _colour_bar(surf, pygame, writer, bar, x0: int, top: int, bar_w: int, bar_h: int,
                font_px: int, x_end: int) -> None:
    """The colour bar ``(label, low, high)`` from ``top``, with ticks at low, middle and high."""
    _, low, high = bar
    colours = _colormap(1.0 - np.arange(bar_h) / max(bar_h - 1, 1))   # high on top
    for row, c in enumerate(colours):
        pygame.draw.line(surf, tuple(int(v) for v in c), (x0, top + row),
                         (x0 + bar_w - 1, top + row))
    pygame.draw.rect(surf, ARROW_CIRCLE, (x0 - 1, top - 1, bar_w + 2, bar_h + 2), 1)
    span = high - low
    digits = max(3, int(np.ceil(np.log10(max(abs(low), abs(high)) / span))) + 2) \
        if max(abs(low), abs(high)) > 0 else 3
    for q in (0.0, 0.5, 1.0):
        y = top + int(round((1.0 - q) * (bar_h - 1)))
        x = x0 + bar_w
        pygame.draw.line(surf, PANEL_TEXT, (x, y), (x + 5, y))
        writer.write(surf, f"{low + q * span:.{digits}g}", font_px, PANEL_TEXT, "midleft",
                     (x + 8, y), x_end - x - 8)


def _annotate_bottom(pic, pygame, lines, arrows, bar, swatches) -> np.ndarray:
    """The frame of :func:`annotate` with ``side="bottom"``."""
    h0, w0 = pic.shape[:2]
    writer = _Writer(pygame)
    font_px = int(np.clip(round(w0 / 60), 13, 18))
    line_h = int(round(1.35 * font_px))
    margin = int(round(0.8 * font_px))
    gap = 2 * font_px
    rows = 4
    size = max(6, int(0.64 * line_h))          # legend swatch

    def text_width(s):
        label = writer.render(s, font_px, PANEL_TEXT)
        return label.get_width() if label is not None else int(0.55 * font_px * len(s))

    columns = []                                   # (width, draw(x0, y0))

    def text_column(chunk):
        def draw(x0, y0):
            for k, line in enumerate(chunk):
                writer.write(strip, line, font_px, PANEL_TEXT, "midleft",
                             (x0, y0 + (k + 0.5) * line_h))
        return max(text_width(s) for s in chunk), draw

    def legend_column(chunk):
        def draw(x0, y0):
            for k, (colour, label, kind) in enumerate(chunk):
                y = int(round(y0 + (k + 0.5) * line_h))
                _swatch(strip, pygame, colour, kind, x0, y, size)
                writer.write(strip, label, font_px, PANEL_TEXT, "midleft", (x0 + size + 8, y))
        return size + 8 + max(text_width(s) for _, s, _ in chunk), draw

    for k in range(0, len(lines), rows):
        columns.append(text_column(lines[k:k + rows]))
    if arrows:
        labels = [label for _, label, _ in arrows if label]
        radius = max(12, (rows * line_h - 4 - len(labels) * line_h) // 2)
        width = max([2 * radius + 2] + [text_width(s) for s in labels])

        def draw_arrows(x0, y0, radius=radius, width=width):
            centre = (int(x0 + width / 2), y0 + radius)
            _arrow_circle(strip, pygame, centre, radius, arrows)
            y = y0 + 2 * radius + 4
            for _, label, colour in arrows:
                if label:
                    writer.write(strip, label, font_px, colour, "midtop", (centre[0], y))
                    y += line_h
        columns.append((width, draw_arrows))
    if bar is not None:
        bar_w = 14
        ticks = max(text_width(f"{v:.3g}") for v in (bar[1], bar[2], 0.5 * (bar[1] + bar[2])))
        width = max(text_width(bar[0]), bar_w + 8 + ticks)

        def draw_bar(x0, y0, width=width):
            writer.write(strip, bar[0], font_px, PANEL_TEXT, "midleft", (x0, y0 + 0.5 * line_h))
            _colour_bar(strip, pygame, writer, bar, x0, y0 + line_h + 4, bar_w,
                        rows * line_h - line_h - 8, font_px, x0 + width)
        columns.append((width, draw_bar))
    for k in range(0, len(swatches), rows):
        columns.append(legend_column(swatches[k:k + rows]))

    if not columns:
        return pic.copy()
    height = 2 * margin + rows * line_h
    width = max(w0, 2 * margin + sum(c[0] for c in columns) + gap * (len(columns) - 1))
    strip = pygame.Surface((width, height))
    strip.fill(PANEL_BACKGROUND)
    x = margin
    for column_width, draw in columns:
        draw(x, margin)
        x += column_width + gap
    frame = np.empty((h0 + height, width, 3), dtype=np.uint8)
    frame[:] = PANEL_BACKGROUND
    frame[:h0, :w0] = pic
    frame[h0:] = _to_array(strip, pygame)
    return frame


def season(day: float) -> str:
    """Season of a model day: day 0 is mid-winter in a 360-day year, seasons 90 days long.

    Parameters
    ----------
    day : float
        Model day [d] (any real number, taken modulo 360).

    Returns
    -------
    str
        ``"winter"`` for days [-45, 45) modulo 360, then ``"spring"``,
        ``"summer"`` (centred on day 180) and ``"autumn"``.
    """
    return _SEASONS[int(((float(day) + 45.0) % 360.0) // 90.0) % 4]


def draw_itd(h, g, *, target=None, day=None, size=600) -> np.ndarray:
    """RGB frame ``(H, W, 3)`` uint8 (``W = size``, ``H = round(0.6 size)``): a bar
    chart of the ice-thickness distribution.

    Parameters
    ----------
    h : (M,) array of float
        Class thicknesses [m]; ``h[0] = 0`` is the open-water class.
    g : (M,) array of float
        Area fractions (dimensionless), non-negative (they sum to 1).
    target : (M,) array of float, optional
        Target fractions, drawn as an orange step line, with a legend of the
        bars and the line above the plot.
    day : float, optional
        Model day [d] (day 0 is mid-winter, 360-day year), written with its
        season as a title, e.g. ``"day 123 (spring)"``.
    size : int, optional
        Image width [px].

    Returns
    -------
    np.ndarray
        ``(H, W, 3)`` uint8 RGB picture: one bar per class (open water in a
        darker blue), heights scaled to the largest of ``g`` and ``target``, on
        a baseline with a tick under each bar and ticks with values up the left
        axis at round values. The text (thickness under each bar, "ice thickness h [m]" under
        the axis, "area fraction" over the y axis, title and legend) is left out
        when pygame fonts are unavailable or the frame is too small for it.
    """
    hh = _vector("h", h)
    m = hh.shape[0]
    if m == 0:
        raise ValueError("h must have at least one class")
    gg = _vector("g", g, m)
    if np.any(gg < 0):
        raise ValueError("g must be non-negative")
    tt = None
    if target is not None:
        tt = _vector("target", target, m)
        if np.any(tt < 0):
            raise ValueError("target must be non-negative")
    if day is not None:
        day = _check_number("day", day)
    size = _check_size(size)

    pygame = _pygame()
    writer = _Writer(pygame)
    width, height = size, max(1, round(size * 0.6))
    font_px = int(round(0.05 * height))            # 18 px at the default size
    left, right = round(0.1 * width), round(0.03 * width)
    top, bottom = round(0.17 * height), round(0.17 * height)
    base = height - bottom                       # baseline row
    plot_w, plot_h = max(1, width - left - right), max(1, base - top)
    slot = plot_w / m
    top_value = max(gg.max(), tt.max() if tt is not None else 0.0)
    if top_value <= 0:
        top_value = 1.0

    def bar_top(v):
        return base - int(round(v / top_value * plot_h))

    surf = pygame.Surface((width, height))
    surf.fill(ITD_BACKGROUND)
    for c in range(m):
        x0 = left + c * slot
        bar = pygame.Rect(int(round(x0 + 0.1 * slot)), bar_top(gg[c]),
                          max(1, int(round(0.8 * slot))), base - bar_top(gg[c]))
        if bar.height > 0:
            pygame.draw.rect(surf, ITD_OPEN_WATER if c == 0 else ITD_ICE, bar)
        tick_x = int(round(x0 + 0.5 * slot))
        pygame.draw.line(surf, ITD_AXES, (tick_x, base), (tick_x, base + 4))

    pygame.draw.line(surf, ITD_AXES, (left, base), (left + plot_w, base), 2)
    pygame.draw.line(surf, ITD_AXES, (left, base), (left, top), 2)
    tick_px = int(round(0.9 * font_px))
    step = _nice_step(top_value)
    decimals = next(d for d in range(12) if abs(round(step, d) - step) <= 1e-9 * step)
    for k in range(int(np.floor(top_value / step + 1e-9)) + 1):
        y = bar_top(k * step)
        pygame.draw.line(surf, ITD_AXES, (left - 5, y), (left, y))
        writer.write(surf, "0" if k == 0 else f"{k * step:.{decimals}f}", tick_px, ITD_AXES,
                     "midright", (left - 8, y), left - 10)

    if tt is not None:
        points = []
        for c in range(m):
            y = bar_top(tt[c])
            points += [(int(round(left + c * slot)), y), (int(round(left + (c + 1) * slot)), y)]
        pygame.draw.lines(surf, ITD_TARGET, False, points, 2)

    class_px = int(min(font_px, 0.45 * slot))
    for c, hc in enumerate(hh):
        writer.write(surf, "open" if c == 0 and hc == 0 else f"{hc:.2g}", class_px, ITD_AXES,
                     "midtop", (left + (c + 0.5) * slot, base + 6), int(0.95 * slot))
    writer.write(surf, "ice thickness h [m]", font_px, ITD_AXES, "midtop",
                 (left + plot_w / 2, base + 10 + font_px), plot_w)

    row1 = 0.25 * top                              # title row centre
    row2 = top - 0.6 * font_px - 4                 # y-label / legend row centre
    if day is not None:
        writer.write(surf, f"day {day:.0f} ({season(day)})", int(round(1.1 * font_px)),
                     ITD_AXES, "center", (left + plot_w / 2, row1), plot_w)
    writer.write(surf, "area fraction", font_px, ITD_AXES, "midleft", (4, row2))
    if tt is not None:
        _itd_legend(surf, pygame, writer, font_px, width - right, row2)
    return _to_array(surf, pygame)


def _nice_step(top: float) -> float:
    """A round tick step (1, 2, 2.5 or 5 times a power of ten) giving 3 to 6 ticks up to ``top``."""
    power = 10.0 ** np.floor(np.log10(top / 4.0))
    for mult in (1.0, 2.0, 2.5, 5.0, 10.0):
        if top / (mult * power) <= 5.0:
            return mult * power
    return 10.0 * power


def _itd_legend(surf, pygame, writer, font_px, x_right, y) -> None:
    """Swatches "fractions g" (bar) and "target" (orange line), right-aligned at x_right."""
    entries = []
    for label in ("fractions g", "target"):
        text = writer.render(label, font_px, ITD_AXES)
        entries.append((label, text))
    key = max(10, int(1.4 * font_px))              # swatch width [px]
    x = x_right
    for label, text in reversed(entries):
        if text is not None:
            x -= text.get_width()
            surf.blit(text, text.get_rect(midleft=(x, int(round(y)))))
        x -= key + 6
        y0 = int(round(y))
        if label == "target":
            pygame.draw.line(surf, ITD_TARGET, (x, y0), (x + key, y0), 2)
        else:
            half = max(3, int(0.35 * font_px))
            pygame.draw.rect(surf, ITD_ICE, (x, y0 - half, key, 2 * half))
        x -= 16


class Window:
    """A pygame window showing frames for ``render_mode="human"``.

    ``show(frame)`` draws an ``(H, W, 3)`` uint8 frame (the window takes a
    new frame's size), handles window events, updates the display and waits
    to keep ``fps`` frames per second;
    ``close()`` closes the window (calling it again does nothing).
    """

    def __init__(self, title: str, width: int, height: int, fps: int):
        pygame = _pygame()
        self._pygame = pygame
        self.fps = int(fps)
        pygame.display.init()
        pygame.display.set_caption(title)
        self.screen = pygame.display.set_mode((int(width), int(height)))
        self.clock = pygame.time.Clock()

    def show(self, frame: np.ndarray) -> None:
        if self.screen is None:
            raise RuntimeError("the window is closed")
        frame = np.asarray(frame)
        if frame.ndim != 3 or frame.shape[2] != 3:
            raise ValueError(f"frame must have shape (H, W, 3), got {frame.shape}")
        pygame = self._pygame
        surf = pygame.surfarray.make_surface(np.transpose(frame.astype(np.uint8), (1, 0, 2)))
        if self.screen.get_size() != surf.get_size():     # e.g. another view: fit the window
            self.screen = pygame.display.set_mode(surf.get_size())
        pygame.event.pump()
        self.screen.blit(surf, (0, 0))
        pygame.display.flip()
        self.clock.tick(self.fps)

    def close(self) -> None:
        if self.screen is None:
            return
        self.screen = None
        self._pygame.display.quit()
        self._pygame.quit()
