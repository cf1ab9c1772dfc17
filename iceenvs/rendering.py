"""Pictures of the environments, drawn with pygame.

* :func:`draw_floes` — the floes of a periodic box as discs coloured by speed
  (frozen floes grey), with their periodic images across the box edges and,
  optionally, the contact force chains;
* :func:`draw_itd` — the ice-thickness distribution as a bar chart, with an
  optional target distribution drawn over it;
* :class:`Window` — a window that shows such frames for ``render_mode="human"``.

The drawing functions return RGB arrays ``(H, W, 3)`` of ``uint8`` and need no
display. pygame is an optional dependency (the ``render`` extra); it is imported
only when something is drawn, and a missing pygame raises
:class:`gymnasium.error.DependencyNotInstalled`.
"""
from __future__ import annotations

import numpy as np
from gymnasium.error import DependencyNotInstalled

__all__ = ["draw_floes", "draw_itd", "Window"]

BACKGROUND = (22, 62, 112)      # sea blue
FROZEN = (150, 150, 150)        # grey
CHAIN = (140, 20, 20)           # dark red
ITD_BACKGROUND = (245, 247, 250)
ITD_AXES = (40, 40, 40)
ITD_OPEN_WATER = (40, 110, 190)
ITD_ICE = (120, 170, 210)
ITD_TARGET = (225, 110, 20)

# A few samples of the viridis colormap, interpolated linearly in between.
_VIRIDIS = np.array([
    (68, 1, 84), (71, 44, 122), (59, 82, 139), (44, 113, 142), (33, 145, 140),
    (39, 173, 129), (92, 200, 99), (170, 220, 50), (253, 231, 37),
], dtype=float)


def _pygame():
    """Import pygame (with gfxdraw) or say how to install it."""
    try:
        import pygame
        import pygame.gfxdraw  # noqa: F401
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


def _check_size(size) -> int:
    if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size < 1:
        raise ValueError(f"size must be a positive integer, got {size!r}")
    return int(size)


def draw_floes(positions, radii, box_size, speeds, *, frozen=None, contact_i=None,
               contact_j=None, contact_force=None, speed_scale=None, size=600) -> np.ndarray:
    """RGB frame ``(H, W, 3)`` uint8 of the floes in a periodic box.

    Parameters
    ----------
    positions : (N, 2) floe centres [m]; the box spans ``[0, lx] x [0, ly]``.
    radii : (N,) floe radii [m], positive.
    box_size : (lx, ly) [m], positive.
    speeds : (N,) floe speeds [m/s], mapped to a viridis-like colormap.
    frozen : (N,) bool, optional — floes drawn grey.
    contact_i, contact_j, contact_force : (K,) int, int, float, optional —
        force chains, drawn as dark-red segments between the centres (minimum
        image), 1 to 5 px wide in proportion to force / max force; contacts with
        zero force are skipped.
    speed_scale : speed [m/s] mapped to the top of the colormap
        (default ``max(speeds.max(), 1e-6)``).
    size : image width [px]; the height is ``round(size * ly / lx)``.

    The picture has y pointing up and ``size / lx`` pixels per metre. A floe
    crossing a box edge is drawn also on the opposite side so the picture tiles.
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
    if speed_scale is None:
        speed_scale = max(float(spd.max()) if n else 0.0, 1e-6)
    elif not np.isfinite(speed_scale) or speed_scale <= 0:
        raise ValueError(f"speed_scale must be positive and finite, got {speed_scale!r}")
    size = _check_size(size)

    pygame = _pygame()
    lx, ly = box
    scale = size / lx
    width, height = size, max(1, round(size * ly / lx))

    colours = _colormap(np.abs(spd) / speed_scale)
    colours[frz] = FROZEN
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


def draw_itd(h, g, *, target=None, size=600) -> np.ndarray:
    """RGB frame ``(H, W, 3)`` uint8 (``W = size``, ``H = round(0.6 size)``): a bar
    chart of the ice-thickness distribution.

    Parameters
    ----------
    h : (M,) class thicknesses [m]; ``h[0] = 0`` is the open-water class.
    g : (M,) area fractions, non-negative (they sum to 1).
    target : (M,) optional target fractions, drawn as an orange step line.
    size : image width [px].

    One bar per class (open water in a darker blue), heights scaled to the
    largest of ``g`` and ``target``, on a baseline with a tick under each bar
    and a few ticks up the left axis. Thickness labels are added when pygame
    fonts are available.
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
    size = _check_size(size)

    pygame = _pygame()
    width, height = size, max(1, round(size * 0.6))
    left, right = round(0.08 * width), round(0.03 * width)
    top, bottom = round(0.06 * height), round(0.14 * height)
    base = height - bottom                       # baseline row
    plot_w, plot_h = max(1, width - left - right), max(1, base - top)
    slot = plot_w / m
    top_value = max(gg.max(), tt.max() if tt is not None else 0.0, 1e-12)

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
    for q in (0.25, 0.5, 0.75, 1.0):
        y = base - int(round(q * plot_h))
        pygame.draw.line(surf, ITD_AXES, (left - 5, y), (left, y))

    if tt is not None:
        points = []
        for c in range(m):
            y = bar_top(tt[c])
            points += [(int(round(left + c * slot)), y), (int(round(left + (c + 1) * slot)), y)]
        pygame.draw.lines(surf, ITD_TARGET, False, points, 2)

    _label_classes(surf, pygame, hh, left, slot, base, bottom)
    return _to_array(surf, pygame)


def _label_classes(surf, pygame, h, left, slot, base, bottom) -> None:
    """Thickness labels under the bars, skipped when fonts are unavailable or too small."""
    font_px = int(min(0.6 * bottom, 0.45 * slot))
    if font_px < 8:
        return
    try:
        pygame.font.init()
        font = pygame.font.Font(None, font_px)
    except (ImportError, NotImplementedError, OSError, RuntimeError, pygame.error):
        return
    for c, hc in enumerate(h):
        text = font.render("open" if c == 0 and hc == 0 else f"{hc:.2g}", True, ITD_AXES)
        x = int(round(left + (c + 0.5) * slot - text.get_width() / 2))
        surf.blit(text, (x, base + 6))


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
