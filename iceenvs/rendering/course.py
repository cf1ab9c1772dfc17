"""The ship and its course: the hull, its track, a planned route with its
swath, the goal line and the channel's edges, over a picture of the whole
box (:func:`draw_ship`) or as layers of a view
(:func:`~iceenvs.rendering.view.draw_view`)."""
from __future__ import annotations

import numpy as np

from ._canvas import check_box_size, check_number, import_pygame, to_array
from .colours import CHANNEL, GOAL, HULL, ROUTE, TRACK
from .viewport import ViewCanvas, unwrap_path


def check_hull(hull_vertices) -> np.ndarray:
    """The hull's corners [m]: a finite (K ≥ 3, 2) array."""
    hull = np.asarray(hull_vertices, dtype=float)
    if hull.ndim != 2 or hull.shape[1] != 2 or hull.shape[0] < 3 or not np.all(np.isfinite(hull)):
        raise ValueError(f"hull_vertices must be a finite (K >= 3, 2) array, got {hull.shape}")
    return hull


def route_edges(points: np.ndarray, half: float) -> tuple[np.ndarray, np.ndarray]:
    """The two edges of a route's swath: ``points`` (M ≥ 2, 2) moved
    ``half`` [m] to either side along the route's normal."""
    d = np.gradient(points, axis=0)
    normal = np.column_stack([-d[:, 1], d[:, 0]])
    normal /= np.maximum(np.hypot(normal[:, 0], normal[:, 1]), 1e-12)[:, None]
    return points - half * normal, points + half * normal


def _route_points(route):
    """The route's points (M, 2) [m] and its swath's half-width [m], or
    None for a route too short or not finite to draw."""
    points, half = route
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    half = check_number("route half-width", half)
    if points.shape[0] >= 2 and np.all(np.isfinite(points)):
        return points, half
    return None


def draw_ship(picture, box_size, hull_vertices, track=None, *, goal_x=None,
              channel=None, route=None) -> np.ndarray:
    """The picture of :func:`~iceenvs.rendering.ice.draw_floes` with a ship drawn over it.

    Parameters
    ----------
    picture : (H, W, 3) uint8
        A frame of :func:`~iceenvs.rendering.ice.draw_floes` of the box ``box_size``.
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
    box = check_box_size(box_size)
    hull = check_hull(hull_vertices)
    pygame = import_pygame()
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
        drawn = _route_points(route)
        if drawn is not None:
            points, half = drawn
            for edge in route_edges(points, half):
                polyline(edge, ROUTE, 1)
            polyline(points, ROUTE, 2)
    if track is not None:
        polyline(track, TRACK, 2)
    centre = hull.mean(axis=0)
    shift = np.mod(centre, box) - centre
    points = [screen(p) for p in hull + shift]
    pygame.draw.polygon(surf, HULL, points)
    pygame.draw.polygon(surf, (0, 0, 0), points, 1)
    return to_array(surf, pygame)


# -- the ship and its course in a view -------------------------------------------------------

def draw_task_lines(canvas: ViewCanvas, goal_x=None, channel=None) -> None:
    """The lines of the task: the goal line x = ``goal_x`` [m] and the
    channel's edges ``channel`` (y0, y1) [m], with their periodic images."""
    box, pygame, surf = canvas.box, canvas.pygame, canvas.surf
    if goal_x is not None:
        gx = check_number("goal_x", goal_x)
        for d in canvas.shifts(np.array([gx, box.y0]), np.array([gx, box.y0])):
            x = gx + d[0]
            pygame.draw.line(surf, GOAL, canvas.px((x, box.y0))[0], canvas.px((x, box.y1))[0], 3)
    if channel is not None:
        for y in channel:
            y = check_number("channel edge", y)
            for d in canvas.shifts(np.array([box.x0, y]), np.array([box.x0, y])):
                pygame.draw.line(surf, CHANNEL, canvas.px((box.x0, y + d[1]))[0],
                                 canvas.px((box.x1, y + d[1]))[0], 1)


def draw_course(canvas: ViewCanvas, route=None, track=None, hull=None) -> None:
    """The planned ``route`` (points [m], swath half-width [m]) with its
    swath's edges, the ship's ``track`` [m] and its ``hull``
    (:func:`check_hull`) [m], each with its periodic images."""
    if route is not None:
        drawn = _route_points(route)
        if drawn is not None:
            points, half = drawn
            points = unwrap_path(points, canvas.periods)
            for edge in route_edges(points, half):
                canvas.path(edge, ROUTE, 1)
            canvas.path(points, ROUTE, 3)
    if track is not None:
        canvas.path(track, TRACK, 2)
    if hull is not None:
        for d in canvas.shifts(hull.min(axis=0), hull.max(axis=0)):
            points = canvas.px(hull + d)
            canvas.pygame.draw.polygon(canvas.surf, HULL, points)
            canvas.pygame.draw.polygon(canvas.surf, (0, 0, 0), points, 1)
