"""What every picture of the package is drawn with: pygame, imported only
when something is drawn (:func:`import_pygame`), its default font
(:class:`Writer`), a surface read back as an RGB array (:func:`to_array`)
and the checks of the drawing functions' arguments, which raise
:class:`ValueError` naming the argument."""
from __future__ import annotations

import numpy as np
from gymnasium.error import DependencyNotInstalled

#: what pygame raises when its fonts are unavailable (besides ``pygame.error``)
FONT_ERRORS = (ImportError, NotImplementedError, OSError, RuntimeError)


def import_pygame():
    """Import pygame (with gfxdraw) or say how to install it."""
    try:
        import pygame
        import pygame.gfxdraw
    except ImportError as exc:
        raise DependencyNotInstalled(
            'pygame is needed for rendering; install it with pip install "seaice-gym[render]" '
            "(or pip install pygame)") from exc
    return pygame


def to_array(surf, pygame) -> np.ndarray:
    """The pixels of the surface ``surf``, an ``(H, W, 3)`` uint8 array."""
    return np.transpose(np.array(pygame.surfarray.pixels3d(surf)), axes=(1, 0, 2))


class Writer:
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
            except FONT_ERRORS + (self.pygame.error,):
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
        except FONT_ERRORS + (self.pygame.error,):
            return None
        return surf

    def write(self, surf, text: str, px: int, colour, anchor: str, at,
              max_width: int | None = None) -> None:
        """Blit the text with its rectangle's ``anchor`` (e.g. "midleft") at ``at``."""
        label = self.render(text, px, colour, max_width)
        if label is not None:
            rect = label.get_rect(**{anchor: (int(round(at[0])), int(round(at[1])))})
            surf.blit(label, rect)


# -- the checks of the arguments ------------------------------------------------------------

def vector(name: str, x, n: int | None = None, dtype=float) -> np.ndarray:
    """``x`` as a 1-D array (of ``n`` entries if given), finite if it is of floats."""
    a = np.asarray(x, dtype=dtype)
    if a.ndim != 1 or (n is not None and a.shape[0] != n):
        want = f"({n},)" if n is not None else "1-D"
        raise ValueError(f"{name} must have shape {want}, got {a.shape}")
    if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite")
    return a


def check_size(size, name: str = "size") -> int:
    """A size [px]: a positive integer."""
    if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size < 1:
        raise ValueError(f"{name} must be a positive integer, got {size!r}")
    return int(size)


def check_colour(name: str, colour) -> tuple:
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


def check_number(name: str, x) -> float:
    """A finite number, as a float."""
    if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)) \
            or not np.isfinite(x):
        raise ValueError(f"{name} must be a finite number, got {x!r}")
    return float(x)


def check_box_size(box_size) -> np.ndarray:
    """The box's side lengths (lx, ly) [m], positive and finite."""
    box = np.asarray(box_size, dtype=float)
    if box.shape != (2,) or not np.all(np.isfinite(box)) or np.any(box <= 0):
        raise ValueError(f"box_size must be two positive finite lengths, got {box_size!r}")
    return box


def check_radii(radii, n: int) -> np.ndarray:
    """The radii [m] of ``n`` floes, positive."""
    rad = vector("radii", radii, n)
    if np.any(rad <= 0):
        raise ValueError("radii must be positive")
    return rad

