"""The ice-thickness distribution as a bar chart (:func:`draw_itd`), the
frames of ThicknessDistribution-v0: one bar per thickness class, a target
distribution over them, the model day and its season (:func:`season`)."""
from __future__ import annotations

import numpy as np

from ._canvas import Writer, check_number, check_size, import_pygame, to_array, vector
from .colours import ITD_AXES, ITD_BACKGROUND, ITD_ICE, ITD_OPEN_WATER, ITD_TARGET

_SEASONS = ("winter", "spring", "summer", "autumn")


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
    hh = vector("h", h)
    m = hh.shape[0]
    if m == 0:
        raise ValueError("h must have at least one class")
    gg = vector("g", g, m)
    if np.any(gg < 0):
        raise ValueError("g must be non-negative")
    tt = None
    if target is not None:
        tt = vector("target", target, m)
        if np.any(tt < 0):
            raise ValueError("target must be non-negative")
    if day is not None:
        day = check_number("day", day)
    size = check_size(size)

    pygame = import_pygame()
    writer = Writer(pygame)
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
    return to_array(surf, pygame)


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
