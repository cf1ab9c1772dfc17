"""Panels beside a picture (:func:`annotate`): on its right or under it,
lines of text, one or two direction arrows in a circle (wind, heading), a
colour bar of the speed colormap and a legend of colour swatches."""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ._canvas import Writer, check_colour, check_number, check_size, import_pygame, to_array
from .colours import ARROW_CIRCLE, ARROW_COLOURS, PANEL_BACKGROUND, PANEL_TEXT, colormap

#: Default panel width of :func:`annotate`, as a fraction of the picture width,
#: and its minimum [px].
PANEL_FRACTION = 0.3
PANEL_MIN_WIDTH = 150
#: where :func:`annotate` puts its panel
SIDES = ("right", "bottom")
#: the shapes of a legend's swatch: a disc (a floe), a line, a band (an area)
LEGEND_KINDS = ("disc", "line", "band")


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
        The frame to annotate, e.g. from :func:`~iceenvs.rendering.ice.draw_floes`
        or :func:`~iceenvs.rendering.thickness_chart.draw_itd`.
    colour_bar : (label, low, high), optional
        A vertical colour bar of the colormap of
        :func:`~iceenvs.rendering.ice.draw_floes`, from ``low`` (bottom) to
        ``high`` (top), in the units written in ``label`` (e.g.
        ``("speed [m/s]", 0.0, SPEED_SCALE)``), with ticks and values at low,
        middle and high. ``low < high``, both finite.
    legend : sequence of (colour, text) or (colour, text, kind), optional
        Colour swatches (RGB triples of ints in [0, 255]) with their text, one
        a line, e.g. :data:`~iceenvs.rendering.colours.CLUSTER_LEGEND`;
        ``kind`` (:data:`LEGEND_KINDS`) is the swatch's shape: ``"disc"``
        (default), ``"line"`` or ``"band"``.
    arrow : (ax, ay) or sequence of (vector, label[, colour]), optional
        A direction, drawn as an arrow from the centre of a small circle whose
        radius is the full length: ``(ax, ay)`` is dimensionless, y up, with
        ``hypot(ax, ay) <= 1`` the fraction of the full length (longer vectors
        are clipped to 1), e.g. ``wind / 20`` for the wind [m/s] on a 20 m/s
        scale. A zero vector draws a dot. To show two directions in the same
        circle (e.g. the wind and a target heading), pass one or two entries
        ``(vector, label)`` or ``(vector, label, colour)``; a missing or None
        colour is taken from :data:`~iceenvs.rendering.colours.ARROW_COLOURS`
        (white, then orange) and each label is written under the circle in
        its arrow's colour.
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
    w0 = pic.shape[1]
    if side == "bottom" and panel_width is not None:
        raise ValueError("panel_width is for side='right'; the bottom strip is as wide as "
                         "the picture")
    pw = (max(PANEL_MIN_WIDTH, round(PANEL_FRACTION * w0)) if panel_width is None
          else check_size(panel_width, "panel_width"))
    lines = [text] if isinstance(text, str) else text
    if lines is None:
        lines = []
    if not isinstance(lines, Sequence) or not all(isinstance(s, str) for s in lines):
        raise ValueError(f"text must be a string or a sequence of strings, got {text!r}")
    arrows = _arrow_entries(arrow, arrow_label)
    bar = _colour_bar_entry(colour_bar)
    swatches = _legend_entries(legend)
    pygame = import_pygame()
    if side == "bottom":
        return _annotate_bottom(pic, pygame, lines, arrows, bar, swatches)
    return _annotate_right(pic, pygame, lines, arrows, bar, swatches, pw)


def _annotate_right(pic, pygame, lines, arrows, bar, swatches, pw: int) -> np.ndarray:
    """The frame of :func:`annotate` with ``side="right"``, its panel ``pw`` px wide."""
    h0, w0 = pic.shape[:2]

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
    writer = Writer(pygame)

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
    frame[:, w0:] = to_array(panel, pygame)
    return frame


def _annotate_bottom(pic, pygame, lines, arrows, bar, swatches) -> np.ndarray:
    """The frame of :func:`annotate` with ``side="bottom"``."""
    h0, w0 = pic.shape[:2]
    writer = Writer(pygame)
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
    frame[h0:] = to_array(strip, pygame)
    return frame


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
        colour = ARROW_COLOURS[k] if colour is None else check_colour(f"arrow colour {k}",
                                                                        colour)
        entries.append((v, label, colour))
    return entries


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
        swatches.append((check_colour(f"legend colour {k}", entry[0]), entry[1], kind))
    return swatches


def _colour_bar_entry(colour_bar):
    """``(label, low, high)`` of the ``colour_bar`` of :func:`annotate`, or None."""
    if colour_bar is None:
        return None
    if isinstance(colour_bar, (str, bytes)) or not isinstance(colour_bar, Sequence) \
            or len(colour_bar) != 3 or not isinstance(colour_bar[0], str):
        raise ValueError(f"colour_bar must be (label, low, high), got {colour_bar!r}")
    low = check_number("colour_bar low", colour_bar[1])
    high = check_number("colour_bar high", colour_bar[2])
    if not low < high:
        raise ValueError(f"colour_bar needs low < high, got {low!r} and {high!r}")
    return (colour_bar[0], low, high)


def _arrow_circle(surf, pygame, centre, radius: int, arrows) -> None:
    """The circle of the arrows, its ticks at E, W, S and N, and the arrows."""
    pygame.gfxdraw.aacircle(surf, centre[0], centre[1], radius, ARROW_CIRCLE)
    for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        pygame.draw.line(surf, ARROW_CIRCLE,
                         (centre[0] + dx * (radius - 4), centre[1] + dy * (radius - 4)),
                         (centre[0] + dx * radius, centre[1] + dy * radius))
    for v, _, colour in arrows:
        _draw_arrow(surf, pygame, centre, v, radius, colour)


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


def _colour_bar(surf, pygame, writer, bar, x0: int, top: int, bar_w: int, bar_h: int,
                font_px: int, x_end: int) -> None:
    """The colour bar ``(label, low, high)`` from ``top``, with ticks at low, middle and high."""
    _, low, high = bar
    colours = colormap(1.0 - np.arange(bar_h) / max(bar_h - 1, 1))   # high on top
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
