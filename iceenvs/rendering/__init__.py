"""Pictures of the environments, drawn with pygame.

One module per thing drawn:

* :mod:`~iceenvs.rendering.ice` — :func:`draw_floes`: the floes of a
  periodic box as discs coloured by speed on a fixed scale
  (:data:`SPEED_SCALE`, frozen floes grey) or by cluster (the largest
  cluster highlighted), with their periodic images across the box edges
  and, optionally, the contact force chains; and the ice in a view: the
  floes at their true size, the contact forces, the leads;
* :mod:`~iceenvs.rendering.course` — :func:`draw_ship`: a ship over such a
  picture: the hull, its track, a planned route, the goal line and the
  channel's edges; and the same in a view;
* :mod:`~iceenvs.rendering.viewport` — which window of a channel a view
  shows (:func:`view_window`: one that follows the ship, or the whole
  channel) and at which scale (:func:`view_box`, :class:`ViewBox`);
* :mod:`~iceenvs.rendering.view` — :func:`draw_view`: such a window to
  scale, with axes in metres and a scale bar, the floes coloured by
  thickness class (:func:`thickness_colours`), the leads, the walls, the
  contact forces, the ship, its track, its planned course and the goal line;
* :mod:`~iceenvs.rendering.panels` — :func:`annotate`: a frame with a panel
  on its right or under it: lines of text (time, concentration,
  target...), one or two direction arrows (wind, heading), a colour bar of
  the speed colormap and a legend of colour swatches;
* :mod:`~iceenvs.rendering.thickness_chart` — :func:`draw_itd`: the
  ice-thickness distribution as a bar chart with axis labels, the model day
  and season (:func:`season`) in a title, and an optional target
  distribution drawn over it;
* :mod:`~iceenvs.rendering.colours` — every colour and colour scale of the
  pictures;
* :mod:`~iceenvs.rendering.window` — :class:`Window`, a window that shows
  such frames for ``render_mode="human"``.

Every name is imported from the package itself (``from iceenvs.rendering
import draw_floes``). The drawing functions return RGB arrays ``(H, W, 3)``
of ``uint8`` and need no display. Text is written with pygame's bundled
default font; when fonts are unavailable the text is left out and
everything else is still drawn. pygame is an optional dependency (the
``render`` extra); it is imported only when something is drawn, and a
missing pygame raises :class:`gymnasium.error.DependencyNotInstalled`.
"""
from __future__ import annotations

from .colours import (ARROW_CIRCLE, ARROW_COLOURS, AXES, BACKGROUND, CHAIN, CHANNEL,
                      CLUSTER_LEGEND, CLUSTER_PALETTE, FLOE_EDGE, FROZEN, GOAL, HULL, ITD_AXES,
                      ITD_BACKGROUND, ITD_ICE, ITD_OPEN_WATER, ITD_TARGET, LARGEST_CLUSTER, LEAD,
                      LEAD_EDGE, OUTSIDE, PANEL_BACKGROUND, PANEL_TEXT, ROUTE, SINGLE_FLOE,
                      SPEED_SCALE, THICKNESS_COLOURS, TRACK, WALL, thickness_colours)
from .course import draw_ship
from .ice import draw_floes
from .panels import LEGEND_KINDS, PANEL_FRACTION, PANEL_MIN_WIDTH, SIDES, annotate
from .thickness_chart import draw_itd, season
from .view import draw_view
from .viewport import VIEW_MARGINS, VIEWS, ViewBox, view_box, view_window
from .window import Window

__all__ = ["draw_floes", "draw_ship", "draw_view", "view_box", "view_window", "ViewBox",
           "thickness_colours", "annotate", "draw_itd", "season", "Window", "SPEED_SCALE",
           "LARGEST_CLUSTER", "CLUSTER_PALETTE", "SINGLE_FLOE", "FROZEN", "CLUSTER_LEGEND",
           "VIEWS", "THICKNESS_COLOURS", "LEAD", "OUTSIDE", "SIDES", "LEGEND_KINDS",
           # the other colours and sizes, for pictures and legends of one's own
           "ARROW_CIRCLE", "ARROW_COLOURS", "AXES", "BACKGROUND", "CHAIN", "CHANNEL",
           "FLOE_EDGE", "GOAL", "HULL", "ITD_AXES", "ITD_BACKGROUND", "ITD_ICE",
           "ITD_OPEN_WATER", "ITD_TARGET", "LEAD_EDGE", "PANEL_BACKGROUND", "PANEL_TEXT",
           "ROUTE", "TRACK", "WALL", "PANEL_FRACTION", "PANEL_MIN_WIDTH", "VIEW_MARGINS"]
