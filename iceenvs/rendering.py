"""Pictures of the environments, drawn with pygame.

* :func:`draw_floes` — the floes of a periodic box as discs coloured by speed on
  a fixed scale (:data:`SPEED_SCALE`, frozen floes grey) or by cluster (the
  largest cluster highlighted), with their periodic images across the box edges
  and, optionally, the contact force chains;
* :func:`draw_ship` — a ship over such a picture: the hull, its track, the
  goal line and the channel's edges;
* :func:`annotate` — a frame with a side panel on its right: lines of text
  (time, concentration, target...), one or two direction arrows (wind,
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

__all__ = ["draw_floes", "draw_ship", "annotate", "draw_itd", "season", "Window", "SPEED_SCALE",
           "LARGEST_CLUSTER", "CLUSTER_PALETTE", "SINGLE_FLOE", "FROZEN", "CLUSTER_LEGEND"]

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
            d = np.gradient(points, axis=0)
            normal = np.column_stack([-d[:, 1], d[:, 0]])
            normal /= np.maximum(np.hypot(normal[:, 0], normal[:, 1]), 1e-12)[:, None]
            for side in (-1.0, 1.0):
                polyline(points + side * half * normal, ROUTE, 1)
            polyline(points, ROUTE, 2)
    if track is not None:
        polyline(track, TRACK, 2)
    centre = hull.mean(axis=0)
    shift = np.mod(centre, box) - centre
    points = [screen(p) for p in hull + shift]
    pygame.draw.polygon(surf, HULL, points)
    pygame.draw.polygon(surf, (0, 0, 0), points, 1)
    return _to_array(surf, pygame)


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


def annotate(picture, *, colour_bar=None, legend=None, arrow=None, arrow_label=None, text=(),
             panel_width=None) -> np.ndarray:
    """A new RGB frame: ``picture`` unchanged on the left and a side panel on its right.

    The panel (dark background) holds, top to bottom, the lines of ``text``, the
    arrow(s), the colour bar and the legend; any of them may be left out.

    Parameters
    ----------
    picture : (H, W, 3) array of uint8
        The frame to annotate, e.g. from :func:`draw_floes` or :func:`draw_itd`.
    colour_bar : (label, low, high), optional
        A vertical colour bar of the colormap of :func:`draw_floes`, from
        ``low`` (bottom) to ``high`` (top), in the units written in ``label``
        (e.g. ``("speed [m/s]", 0.0, SPEED_SCALE)``), with ticks and values at
        low, middle and high. ``low < high``, both finite.
    legend : sequence of (colour, text), optional
        Colour swatches (RGB triples of ints in [0, 255]) with their text, one
        a line, e.g. :data:`CLUSTER_LEGEND`.
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
        string is one line. Lines too long for the panel are written smaller.
    panel_width : int, optional
        Panel width [px]; default ``max(PANEL_MIN_WIDTH, round(PANEL_FRACTION
        * W))``, i.e. 0.3 W and at least 150 px.

    Returns
    -------
    np.ndarray
        ``(H', W + panel_width, 3)`` uint8 RGB frame, ``H' = max(H, height the
        panel needs)``; below a picture shorter than the panel the frame is
        filled with the panel background. Text is left out when pygame fonts
        are unavailable.
    """
    pic = np.asarray(picture)
    if pic.ndim != 3 or pic.shape[2] != 3 or pic.dtype != np.uint8 or 0 in pic.shape[:2]:
        raise ValueError(f"picture must be an (H, W, 3) uint8 array, got shape {pic.shape} "
                         f"and dtype {pic.dtype}")
    h0, w0 = pic.shape[:2]
    pw = (max(PANEL_MIN_WIDTH, round(PANEL_FRACTION * w0)) if panel_width is None
          else _check_size(panel_width, "panel_width"))
    lines = [text] if isinstance(text, str) else text
    if lines is None:
        lines = []
    if not isinstance(lines, Sequence) or not all(isinstance(s, str) for s in lines):
        raise ValueError(f"text must be a string or a sequence of strings, got {text!r}")
    arrows = _arrow_entries(arrow, arrow_label)
    if colour_bar is not None:
        if isinstance(colour_bar, (str, bytes)) or not isinstance(colour_bar, Sequence) \
                or len(colour_bar) != 3 or not isinstance(colour_bar[0], str):
            raise ValueError(f"colour_bar must be (label, low, high), got {colour_bar!r}")
        bar_label = colour_bar[0]
        low = _check_number("colour_bar low", colour_bar[1])
        high = _check_number("colour_bar high", colour_bar[2])
        if not low < high:
            raise ValueError(f"colour_bar needs low < high, got {low!r} and {high!r}")
    swatches = []
    if legend is not None:
        if isinstance(legend, (str, bytes)) or not isinstance(legend, Sequence):
            raise ValueError(f"legend must be a sequence of (colour, text), got {legend!r}")
        for k, entry in enumerate(legend):
            if isinstance(entry, (str, bytes)) or not isinstance(entry, Sequence) \
                    or len(entry) != 2 or not isinstance(entry[1], str):
                raise ValueError(f"legend entry {k} must be (colour, text), got {entry!r}")
            swatches.append((_check_colour(f"legend colour {k}", entry[0]), entry[1]))

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
    pygame = _pygame()
    writer = _Writer(pygame)

    def draw_text(y0):
        for k, line in enumerate(lines):
            writer.write(panel, line, font_px, PANEL_TEXT, "midleft",
                         (margin, y0 + (k + 0.5) * line_h), inner)

    def draw_arrows(y0):
        centre = (pw // 2, y0 + radius)
        pygame.gfxdraw.aacircle(panel, centre[0], centre[1], radius, ARROW_CIRCLE)
        for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):   # ticks at E, W, S, N
            pygame.draw.line(panel, ARROW_CIRCLE,
                             (centre[0] + dx * (radius - 4), centre[1] + dy * (radius - 4)),
                             (centre[0] + dx * radius, centre[1] + dy * radius))
        for v, _, colour in arrows:
            _draw_arrow(panel, pygame, centre, v, radius, colour)
        y = y0 + 2 * radius + 4
        for _, label, colour in arrows:
            if label:
                writer.write(panel, label, font_px, colour, "midtop", (pw / 2, y), inner)
                y += line_h

    def draw_colour_bar(y0):
        writer.write(panel, bar_label, font_px, PANEL_TEXT, "midleft",
                     (margin, y0 + 0.5 * line_h), inner)
        top = y0 + line_h + line_h // 2
        colours = _colormap(1.0 - np.arange(bar_h) / (bar_h - 1))   # high on top
        for row, c in enumerate(colours):
            pygame.draw.line(panel, tuple(int(v) for v in c),
                             (margin, top + row), (margin + bar_w - 1, top + row))
        pygame.draw.rect(panel, ARROW_CIRCLE, (margin - 1, top - 1, bar_w + 2, bar_h + 2), 1)
        span = high - low
        digits = max(3, int(np.ceil(np.log10(max(abs(low), abs(high)) / span))) + 2) \
            if max(abs(low), abs(high)) > 0 else 3
        for q in (0.0, 0.5, 1.0):
            y = top + int(round((1.0 - q) * (bar_h - 1)))
            x = margin + bar_w
            pygame.draw.line(panel, PANEL_TEXT, (x, y), (x + 5, y))
            writer.write(panel, f"{low + q * span:.{digits}g}", font_px, PANEL_TEXT, "midleft",
                         (x + 8, y), pw - x - 8 - margin // 2)

    def draw_legend(y0):
        r = max(3, int(0.32 * line_h))
        for k, (colour, label) in enumerate(swatches):
            y = int(round(y0 + (k + 0.5) * line_h))
            pygame.gfxdraw.aacircle(panel, margin + r, y, r, colour)
            pygame.gfxdraw.filled_circle(panel, margin + r, y, r, colour)
            writer.write(panel, label, font_px, PANEL_TEXT, "midleft", (margin + 2 * r + 8, y),
                         inner - 2 * r - 8)

    if lines:
        sections.append((len(lines) * line_h, draw_text))
    if arrows:
        n_labels = sum(1 for _, label, _ in arrows if label)
        sections.append((2 * radius + 4 + n_labels * line_h, draw_arrows))
    if colour_bar is not None:
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

    ``show(frame)`` draws an ``(H, W, 3)`` uint8 frame, handles window events,
    updates the display and waits to keep ``fps`` frames per second;
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
