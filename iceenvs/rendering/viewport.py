"""A window of the world drawn to scale: which part of a channel a view
shows (:func:`view_window`), at which scale and where in the picture
(:class:`ViewBox`, :func:`view_box`), and the plot being drawn
(:class:`ViewCanvas`): where a point lands and which periodic images of an
item meet the window."""
from __future__ import annotations

import numpy as np

from ._canvas import check_number, check_size

#: the views of a ship environment's frames (:func:`view_window`)
VIEWS = ("follow", "overview")
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
            check_number(name, v)
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
        """(width, height) [px] of the picture of
        :func:`~iceenvs.rendering.view.draw_view`, margins included."""
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
    w = check_size(max_width, "max_width")
    h = check_size(max_height, "max_height")
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
    behind, ahead = check_number("behind", behind), check_number("ahead", ahead)
    if behind < 0 or ahead < 0 or behind + ahead <= 0:
        raise ValueError(f"behind and ahead must be >= 0 with a positive sum, got {behind!r} "
                         f"and {ahead!r}")
    x = check_number("ship_x", ship_x)
    return x - behind, x + ahead, 0.0, ly


# -- periodic images -----------------------------------------------------------------------

def image_shifts(lo, hi, window_lo: float, window_hi: float, period: float | None) -> list:
    """Shifts k·period of the periodic images of items spanning [lo, hi]
    (arrays, over all items) that can meet [window_lo, window_hi]; ``[0.0]``
    along an axis that is not periodic."""
    if period is None or np.size(lo) == 0:
        return [0.0]
    k0 = int(np.ceil((window_lo - np.max(hi)) / period))
    k1 = int(np.floor((window_hi - np.min(lo)) / period))
    return [k * period for k in range(k0, k1 + 1)]


def wrap_into_box(points, periods) -> np.ndarray:
    """A copy of ``points`` (N, 2) [m] taken into the box along its periodic
    axes (``periods``: the period of each axis, None where it is not periodic)."""
    wrapped = np.asarray(points, dtype=float).copy()
    for axis, period in enumerate(periods):
        if period is not None:
            wrapped[:, axis] = np.mod(wrapped[:, axis], period)
    return wrapped


def unwrap_path(points, periods) -> np.ndarray:
    """A path of ``points`` (M, 2) with its jumps across periodic edges undone."""
    p = np.asarray(points, dtype=float).reshape(-1, 2).copy()
    for axis, period in enumerate(periods):
        if period is not None and p.shape[0] > 1:
            d = np.diff(p[:, axis])
            d -= period * np.round(d / period)
            p[1:, axis] = p[0, axis] + np.cumsum(d)
    return p


class ViewCanvas:
    """The plot of a :class:`ViewBox` on a pygame surface ``surf``, in a box
    whose axes repeat with ``periods`` (the period [m] of each axis, None
    where a wall closes it): what the layers of
    :func:`~iceenvs.rendering.view.draw_view` draw with."""

    def __init__(self, pygame, surf, box: ViewBox, periods):
        self.pygame, self.surf, self.box, self.periods = pygame, surf, box, periods
        #: the plot's rectangle on the surface
        self.plot = pygame.Rect(box.left, box.top, box.width, box.height)
        #: the window's lower-left and upper-right corners [m]
        self.lo = np.array([box.x0, box.y0])
        self.hi = np.array([box.x1, box.y1])

    def px(self, p) -> list:
        """The pixels (column, row) of the points ``p`` [m], rounded."""
        q = self.box.pixels(p)
        return [(int(round(c)), int(round(r))) for c, r in q]

    def shifts(self, points_lo, points_hi) -> list:
        """(dx, dy) shifts of the periodic images meeting the window."""
        box = self.box
        sx = image_shifts(points_lo[..., 0], points_hi[..., 0], box.x0, box.x1, self.periods[0])
        sy = image_shifts(points_lo[..., 1], points_hi[..., 1], box.y0, box.y1, self.periods[1])
        return [np.array([dx, dy]) for dx in sx for dy in sy]

    def path(self, points, colour, line_width) -> None:
        """The path ``points`` (M, 2) [m], unwrapped, with its periodic images."""
        t = unwrap_path(points, self.periods)
        if t.shape[0] < 2 or not np.all(np.isfinite(t)):
            return
        for d in self.shifts(t.min(axis=0), t.max(axis=0)):
            self.pygame.draw.lines(self.surf, colour, False, self.px(t + d), line_width)
