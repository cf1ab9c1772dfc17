"""A view of a channel (:func:`draw_view`): a window of the box to scale,
assembled from the layers of :mod:`iceenvs.rendering.ice` and
:mod:`iceenvs.rendering.course`, in a frame of its own: what lies beyond the
box's walls shaded, the walls, axes in metres, a scale bar and a title."""
from __future__ import annotations

import numpy as np

from ._canvas import Writer, check_box_size, check_radii, import_pygame, to_array
from .colours import (AXES, BACKGROUND, OUTSIDE, PANEL_BACKGROUND, PANEL_TEXT,
                      THICKNESS_COLOURS, WALL)
from .course import check_hull, draw_course, draw_task_lines
from .ice import check_contacts, check_leads, draw_contact_forces, draw_floe_discs, draw_leads
from .viewport import ViewBox, ViewCanvas, wrap_into_box


def draw_view(box: ViewBox, positions, radii, box_size, *, periodic=(False, True),
              floe_colours=None, contact_i=None, contact_j=None, contact_force=None,
              hull_vertices=None, track=None, goal_x=None, channel=None, route=None,
              leads=(), ice_band=None, title=None) -> np.ndarray:
    """RGB picture ``(H, W, 3)`` uint8 of the window ``box`` of a box of
    floes, to scale, with axes in metres and a scale bar.

    Parameters
    ----------
    box : ViewBox
        The window and its scale (:func:`~iceenvs.rendering.viewport.view_box`);
        the picture is ``box.picture_size``, the plot at ``box.plot``.
    positions, radii : (N, 2), (N,) arrays of float
        Floe centres and radii [m]; each floe a disc at its true size,
        clipped at the plot's edge, with its periodic images.
    box_size : (lx, ly)
        The box [m], spanning ``[0, lx] × [0, ly]``.
    periodic : (bool, bool)
        Which axes are periodic; a wall closes each other axis at 0 and at
        its length, and what lies beyond it is shaded
        (:data:`~iceenvs.rendering.colours.OUTSIDE`).
    floe_colours : (N, 3) uint8, optional
        The floes' colours (e.g. :func:`~iceenvs.rendering.colours.thickness_colours`);
        default all the thinnest class's.
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
        shaded (:data:`~iceenvs.rendering.colours.LEAD`) and outlined
        (:data:`~iceenvs.rendering.colours.LEAD_EDGE`) where floes could not
        be placed, within half its width of its centre line, wrapping round
        a periodic y, and within ``ice_band``.
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
    rad = check_radii(radii, n)
    size = check_box_size(box_size)
    periods = _periods(periodic, size)
    colours = _floe_colours(floe_colours, n)
    contacts = check_contacts(contact_i, contact_j, contact_force, n)
    hull = None if hull_vertices is None else check_hull(hull_vertices)
    check_leads(leads)
    band = _ice_band(ice_band, periods, size)
    if title is not None and not isinstance(title, str):
        raise ValueError(f"title must be a string, got {title!r}")

    pygame = import_pygame()
    canvas = _new_canvas(pygame, box, periods)
    _shade_outside(canvas, size)
    draw_leads(canvas, leads, band, size)
    wrapped = wrap_into_box(pos, periods)
    if n:
        draw_floe_discs(canvas, wrapped, rad, colours)
    draw_contact_forces(canvas, wrapped, contacts)
    draw_task_lines(canvas, goal_x, channel)
    draw_course(canvas, route, track, hull)
    _draw_walls(canvas, size)
    _draw_frame(canvas, Writer(pygame), title)
    return to_array(canvas.surf, pygame)


# -- the arguments ---------------------------------------------------------------------------

def _periods(periodic, size: np.ndarray) -> tuple:
    """The period [m] of each axis of the box ``size``, None where a wall closes it."""
    if len(periodic) != 2 or not all(isinstance(p, (bool, np.bool_)) for p in periodic):
        raise ValueError(f"periodic must be two booleans, got {periodic!r}")
    return tuple(float(size[a]) if periodic[a] else None for a in range(2))


def _floe_colours(floe_colours, n: int) -> np.ndarray:
    """The colours (N, 3) of the floes: those given, or all the thinnest class's."""
    if floe_colours is None:
        return np.tile(np.array(THICKNESS_COLOURS[0], dtype=np.uint8), (n, 1))
    colours = np.asarray(floe_colours)
    if colours.shape != (n, 3) or colours.dtype.kind not in "iu":
        raise ValueError(f"floe_colours must be an ({n}, 3) integer array, got shape "
                         f"{colours.shape}")
    return colours


def _ice_band(ice_band, periods, size: np.ndarray) -> tuple:
    """The band of ice (x0, x1) [m] that the leads cut: the one given, else
    the whole box (inside its walls)."""
    if ice_band is None:
        return (-np.inf, np.inf) if periods[0] is not None else (0.0, float(size[0]))
    try:
        band = tuple(float(b) for b in ice_band)
    except (TypeError, ValueError):
        band = ()
    if len(band) != 2 or not np.all(np.isfinite(band)) or not band[0] < band[1]:
        raise ValueError(f"ice_band must be (x0, x1) with x0 < x1, got {ice_band!r}")
    return band


# -- the frame round the layers --------------------------------------------------------------

def _new_canvas(pygame, box: ViewBox, periods) -> ViewCanvas:
    """A picture of ``box.picture_size`` in the panels' colour with the
    plot, sea blue, drawing clipped to it."""
    surf = pygame.Surface(box.picture_size)
    surf.fill(PANEL_BACKGROUND)
    canvas = ViewCanvas(pygame, surf, box, periods)
    surf.set_clip(canvas.plot)
    surf.fill(BACKGROUND)
    return canvas


def _shade_outside(canvas: ViewCanvas, size: np.ndarray) -> None:
    """Shade what the window shows beyond the walls of the box ``size``."""
    lo, hi = canvas.lo, canvas.hi
    for axis in (0, 1):
        if canvas.periods[axis] is None:
            for a, b in ((lo[axis], min(0.0, hi[axis])), (max(size[axis], lo[axis]), hi[axis])):
                if b > a:
                    corner = lo.copy(), hi.copy()
                    corner[0][axis], corner[1][axis] = a, b
                    (c0, r1), (c1, r0) = canvas.px(corner[0])[0], canvas.px(corner[1])[0]
                    canvas.pygame.draw.rect(canvas.surf, OUTSIDE,
                                            (c0, r0, c1 - c0 + 1, r1 - r0 + 1))


def _draw_walls(canvas: ViewCanvas, size: np.ndarray) -> None:
    """The walls of the box ``size`` that the window shows."""
    lo, hi = canvas.lo, canvas.hi
    for axis in (0, 1):
        if canvas.periods[axis] is None:
            for at in (0.0, float(size[axis])):
                if lo[axis] <= at <= hi[axis]:
                    a, b = lo.copy(), hi.copy()
                    a[axis] = b[axis] = at
                    canvas.pygame.draw.line(canvas.surf, WALL, canvas.px(a)[0],
                                            canvas.px(b)[0], 3)


def _draw_frame(canvas: ViewCanvas, writer: Writer, title) -> None:
    """The scale bar in the plot, then the plot's border, the axes and the title round it."""
    pygame, surf, box = canvas.pygame, canvas.surf, canvas.box
    _scale_bar(surf, pygame, writer, box)
    surf.set_clip(None)
    pygame.draw.rect(surf, AXES, canvas.plot.inflate(2, 2), 1)
    _axes(surf, pygame, writer, box)
    if title:
        writer.write(surf, title, 18, PANEL_TEXT, "midleft", (box.left, box.top / 2),
                     box.width)


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
