"""A window that shows the frames of ``render_mode="human"`` (:class:`Window`)."""
from __future__ import annotations

import numpy as np

from ._canvas import import_pygame


class Window:
    """A pygame window showing frames for ``render_mode="human"``.

    ``show(frame)`` draws an ``(H, W, 3)`` uint8 frame (the window takes a
    new frame's size), handles window events, updates the display and waits
    to keep ``fps`` frames per second;
    ``close()`` closes the window (calling it again does nothing).
    """

    def __init__(self, title: str, width: int, height: int, fps: int):
        pygame = import_pygame()
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
