"""The colours of the pictures, in one place: the colour scales of the
floes (speed on a viridis-like colormap, :func:`colormap`; the clusters;
the thickness classes, :func:`thickness_colours`) and the fixed colours of
the sea, the ship and its course, the view's frame, the panels and the
ice-thickness chart."""
from __future__ import annotations

import numpy as np

from ._canvas import vector

# -- the sea and the floes ---------------------------------------------------------------

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
#: Legend entries ``(colour, text)`` of the cluster colouring, for
#: :func:`~iceenvs.rendering.panels.annotate`.
CLUSTER_LEGEND = (
    (LARGEST_CLUSTER, "largest cluster"),
    (CLUSTER_PALETTE[0], "other clusters"),
    (SINGLE_FLOE, "single floes"),
    (FROZEN, "frozen"),
)

#: colours of the thickness classes of the floes, thinnest first (:func:`thickness_colours`)
THICKNESS_COLOURS = (
    (222, 232, 242),    # ice white: the thinnest class
    (238, 186, 84),     # amber: the next (e.g. multi-year or ridged ice)
    (200, 120, 214),    # orchid: a third
)
FLOE_EDGE = (70, 92, 120)       # outline of a floe
LEAD = (36, 104, 156)           # a lead's open water, lighter than the sea
LEAD_EDGE = (110, 205, 240)     # its outline

# -- the ship and its course ---------------------------------------------------------------

HULL = (235, 90, 40)            # orange
TRACK = (250, 250, 250)         # white
GOAL = (60, 220, 90)            # green
CHANNEL = (120, 160, 200)       # light blue
ROUTE = (255, 60, 200)          # magenta: a planner's route and swath

# -- the frame of a view -------------------------------------------------------------------

OUTSIDE = (62, 64, 70)          # beyond a wall of the box
WALL = (200, 200, 200)          # a wall of the box
AXES = (210, 212, 218)          # axes, ticks and their labels (on the panel background)

# -- the panels ----------------------------------------------------------------------------

PANEL_BACKGROUND = (28, 30, 36)  # dark grey
PANEL_TEXT = (232, 232, 232)
ARROW_CIRCLE = (110, 116, 128)
#: Default colours of the first and second arrow of :func:`~iceenvs.rendering.panels.annotate`.
ARROW_COLOURS = ((255, 255, 255), (255, 140, 30))

# -- the ice-thickness chart ---------------------------------------------------------------

ITD_BACKGROUND = (245, 247, 250)
ITD_AXES = (40, 40, 40)
ITD_OPEN_WATER = (40, 110, 190)
ITD_ICE = (120, 170, 210)
ITD_TARGET = (225, 110, 20)

# -- the colour scales ---------------------------------------------------------------------

# A few samples of the viridis colormap, interpolated linearly in between.
_VIRIDIS = np.array([
    (68, 1, 84), (71, 44, 122), (59, 82, 139), (44, 113, 142), (33, 145, 140),
    (39, 173, 129), (92, 200, 99), (170, 220, 50), (253, 231, 37),
], dtype=float)


def colormap(values: np.ndarray) -> np.ndarray:
    """Viridis-like RGB colours ``(N, 3)`` uint8 of values in [0, 1] (clipped)."""
    v = np.clip(np.asarray(values, dtype=float), 0.0, 1.0)
    knots = np.linspace(0.0, 1.0, len(_VIRIDIS))
    rgb = np.stack([np.interp(v, knots, _VIRIDIS[:, c]) for c in range(3)], axis=-1)
    return np.rint(rgb).astype(np.uint8)


def speed_or_cluster_colours(rad: np.ndarray, spd: np.ndarray, frz: np.ndarray, labels,
                             speed_scale):
    """Colours ``(N, 3)`` uint8 of the floes, by speed or, given labels, by cluster
    (as :func:`~iceenvs.rendering.ice.draw_floes` describes them)."""
    if labels is None:
        colours = colormap(np.abs(spd) / speed_scale)
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
        :func:`~iceenvs.rendering.ice.draw_floes` from the thinnest to the
        thickest, and a legend of the two ends.
    """
    h = vector("thickness", thickness)
    if classes is None:
        levels = np.unique(np.round(h, 3))
    else:
        levels = np.unique(vector("classes", classes))
        if levels.size == 0 or np.any(levels <= 0):
            raise ValueError(f"classes must be positive thicknesses, got {classes!r}")
    if levels.size == 0:
        return np.empty((0, 3), dtype=np.uint8), []
    if levels.size > len(THICKNESS_COLOURS):
        lo, hi = float(levels[0]), float(levels[-1])
        colours = colormap((h - lo) / (hi - lo))
        ends = colormap(np.array([0.0, 1.0]))
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
