"""The ice: the floes of a periodic box coloured by speed or by cluster
(:func:`draw_floes`, the whole box), and the layers of the ice in a view
(:func:`~iceenvs.rendering.view.draw_view`): the floes at their true size,
the contact forces between them and the leads of open water."""
from __future__ import annotations

import numpy as np

from ._canvas import check_box_size, check_radii, check_size, import_pygame, to_array, vector
from .colours import (BACKGROUND, CHAIN, FLOE_EDGE, LEAD, LEAD_EDGE, SPEED_SCALE,
                      speed_or_cluster_colours)
from .viewport import ViewCanvas


def check_contacts(contact_i, contact_j, contact_force, n: int):
    """The contacts ``(i, j, |force|)`` as arrays among ``n`` floes, or None
    when none is given; the three are given together or not at all."""
    given = [c is not None for c in (contact_i, contact_j, contact_force)]
    if any(given) and not all(given):
        raise ValueError("contact_i, contact_j and contact_force must be given together")
    if not all(given):
        return None
    ci = vector("contact_i", contact_i, dtype=np.int64)
    k = ci.shape[0]
    cj = vector("contact_j", contact_j, k, np.int64)
    cf = np.abs(vector("contact_force", contact_force, k))
    for name, idx in (("contact_i", ci), ("contact_j", cj)):
        if np.any((idx < 0) | (idx >= n)):
            raise ValueError(f"{name} must index floes in [0, {n})")
    return ci, cj, cf


def _shifts(c: float, r: float, length: float) -> tuple:
    """Shifts along one axis at which a disc (centre c, radius r) is drawn."""
    if c - r < 0:
        return (0.0, length)
    if c + r > length:
        return (0.0, -length)
    return (0.0,)


def draw_floes(positions, radii, box_size, speeds, *, frozen=None, contact_i=None,
               contact_j=None, contact_force=None, speed_scale=SPEED_SCALE, labels=None,
               size=600) -> np.ndarray:
    """RGB frame ``(H, W, 3)`` uint8 of the floes in a periodic box.

    Parameters
    ----------
    positions : (N, 2) array of float
        Floe centres [m]; the box spans ``[0, lx] x [0, ly]``.
    radii : (N,) array of float
        Floe radii [m], positive.
    box_size : (lx, ly)
        Box side lengths [m], positive.
    speeds : (N,) array of float
        Floe speeds [m/s], mapped to a viridis-like colormap on the fixed scale
        ``[0, speed_scale]`` (unused for the colour when ``labels`` is given).
    frozen : (N,) array of bool, optional
        Floes drawn grey (:data:`~iceenvs.rendering.colours.FROZEN`) whatever
        the colouring.
    contact_i, contact_j, contact_force : (K,) arrays of int, int, float, optional
        Force chains [N], drawn as dark-red segments between the centres
        (minimum image), 1 to 5 px wide in proportion to force / max force;
        contacts with zero force are skipped. Given all three or none.
    speed_scale : float, optional
        Speed [m/s] mapped to the top of the colormap, default
        :data:`~iceenvs.rendering.colours.SPEED_SCALE` (0.5 m/s); faster
        floes saturate at the top colour. The same speed has the same colour
        in every frame.
    labels : (N,) array of int, optional
        Cluster label of each floe. When given, floes are coloured by cluster
        instead of speed: the largest cluster of two floes or more (by total
        disc area, the sum of r²; ties go to the smaller label) in
        :data:`~iceenvs.rendering.colours.LARGEST_CLUSTER`, every other
        cluster of two floes or more in
        ``CLUSTER_PALETTE[label % len(CLUSTER_PALETTE)]`` (so floes of one
        cluster share a colour), floes alone in their cluster in
        :data:`~iceenvs.rendering.colours.SINGLE_FLOE`.
        :data:`~iceenvs.rendering.colours.CLUSTER_LEGEND` describes these
        colours.
    size : int, optional
        Image width [px]; the height is ``round(size * ly / lx)``.

    Returns
    -------
    np.ndarray
        ``(H, W, 3)`` uint8 RGB picture with y pointing up and ``size / lx``
        pixels per metre. A floe crossing a box edge is drawn also on the
        opposite side so the picture tiles.
    """
    pos = np.asarray(positions, dtype=float)
    if pos.ndim != 2 or pos.shape[1] != 2:
        raise ValueError(f"positions must have shape (N, 2), got {pos.shape}")
    if not np.all(np.isfinite(pos)):
        raise ValueError("positions must be finite")
    n = pos.shape[0]
    rad = check_radii(radii, n)
    spd = vector("speeds", speeds, n)
    box = check_box_size(box_size)
    frz = np.zeros(n, dtype=bool) if frozen is None else vector("frozen", frozen, n, bool)
    contacts = check_contacts(contact_i, contact_j, contact_force, n)
    if labels is not None:
        lab = np.asarray(labels)
        if lab.ndim != 1 or lab.shape[0] != n:
            raise ValueError(f"labels must have shape ({n},), got {lab.shape}")
        if lab.dtype.kind not in "iu":
            raise ValueError(f"labels must be integers, got dtype {lab.dtype}")
        labels = lab.astype(np.int64)
    if speed_scale is None:
        speed_scale = SPEED_SCALE
    if isinstance(speed_scale, bool) or not np.isfinite(speed_scale) or speed_scale <= 0:
        raise ValueError(f"speed_scale must be positive and finite, got {speed_scale!r}")
    size = check_size(size)

    pygame = import_pygame()
    lx, ly = box
    scale = size / lx
    width, height = size, max(1, round(size * ly / lx))

    colours = speed_or_cluster_colours(rad, spd, frz, labels, float(speed_scale))
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

    if contacts is not None and contacts[0].shape[0] and contacts[2].max() > 0:
        ci, cj, cf = contacts
        fmax = cf.max()
        for i, j, f in zip(ci, cj, cf):
            if f == 0:
                continue
            d = pos[j] - pos[i]
            d -= box * np.round(d / box)          # minimum image
            line_width = 1 + int(round(4 * f / fmax))
            pygame.draw.line(surf, CHAIN, screen(pos[i]), screen(pos[i] + d), line_width)

    return to_array(surf, pygame)


# -- the ice in a view -----------------------------------------------------------------------

def check_leads(leads) -> None:
    """Each lead has numbers ``x``, ``y``, ``angle``, a positive ``width``
    and a positive ``length`` (:class:`physics.ice_fields.Lead`)."""
    for k, lead in enumerate(leads):
        try:
            values = [float(getattr(lead, name)) for name in ("x", "y", "angle", "width")]
            length = float(lead.length)
        except (AttributeError, TypeError, ValueError):
            raise ValueError(f"lead {k} must have numbers x, y, angle, width and length "
                             f"(physics.ice_fields.Lead), got {lead!r}") from None
        if not (np.all(np.isfinite(values)) and values[3] > 0 and length > 0):
            raise ValueError(f"lead {k} must have finite x, y, angle, a positive width and a "
                             f"positive length, got {lead!r}")


def draw_leads(canvas: ViewCanvas, leads, band, size) -> None:
    """The leads: open water within half the width of the centre line, in
    the band of ice ``band`` (x0, x1) [m] of the box ``size`` (lx, ly)."""
    box, periods, pygame, surf = canvas.box, canvas.periods, canvas.pygame, canvas.surf
    cut = (max(band[0], box.x0), min(band[1], box.x1),
           box.y0 if periods[1] is not None else max(0.0, box.y0),
           box.y1 if periods[1] is not None else min(float(size[1]), box.y1))
    if leads and cut[1] > cut[0] and cut[3] > cut[2]:
        (c0, r0), (c1, r1) = canvas.px([(cut[0], cut[3]), (cut[1], cut[2])])
        surf.set_clip(canvas.plot.clip(pygame.Rect(c0, r0, c1 - c0 + 1, r1 - r0 + 1)))
        for lead in leads:
            _draw_lead(canvas, lead)
    surf.set_clip(canvas.plot)


def _draw_lead(canvas: ViewCanvas, lead) -> None:
    """One lead, shaded and outlined, with its periodic images."""
    pygame, surf, lo, hi = canvas.pygame, canvas.surf, canvas.lo, canvas.hi
    half_w = 0.5 * float(lead.width)
    c, s = np.cos(lead.angle), np.sin(lead.angle)
    length = float(lead.length)
    if not np.isfinite(length):          # a line across: long enough to cross the window
        length = 2.0 * (np.hypot(*(hi - lo)) + np.hypot(lead.x - 0.5 * (lo[0] + hi[0]),
                                                           lead.y - 0.5 * (lo[1] + hi[1])))
    u = np.array([c, s]) * 0.5 * length
    ends = np.array([[lead.x, lead.y]]) + np.stack([-u, u])
    nrm = np.array([-s, c]) * half_w
    corners = np.stack([ends[0] + nrm, ends[1] + nrm, ends[1] - nrm, ends[0] - nrm])
    for d in canvas.shifts(corners.min(axis=0) - half_w, corners.max(axis=0) + half_w):
        outline = canvas.px(corners + d)
        caps = canvas.px(ends + d)
        r_px = max(1, int(round(half_w * canvas.box.scale)))
        pygame.draw.polygon(surf, LEAD, outline)
        for cx, cy in caps:
            pygame.draw.circle(surf, LEAD, (cx, cy), r_px)
        for k in (0, 2):
            pygame.draw.aaline(surf, LEAD_EDGE, outline[k], outline[k + 1])
        for (cx, cy), out in zip(caps, (-u, u)):
            # the round ends: the outer half of each circle (angles y up, as on screen)
            phi = float(np.arctan2(out[1], out[0]))
            rect = pygame.Rect(cx - r_px, cy - r_px, 2 * r_px, 2 * r_px)
            pygame.draw.arc(surf, LEAD_EDGE, rect, phi - 0.5 * np.pi, phi + 0.5 * np.pi)


def draw_floe_discs(canvas: ViewCanvas, wrapped: np.ndarray, rad: np.ndarray,
                    colours: np.ndarray) -> None:
    """The floes at ``wrapped`` (in the box) as discs at their true size in
    ``colours``, outlined where they are wide enough, with their periodic images."""
    pygame, surf, lo, hi = canvas.pygame, canvas.surf, canvas.lo, canvas.hi
    edge_px = 3
    for d in canvas.shifts(wrapped - rad[:, None], wrapped + rad[:, None]):
        p = wrapped + d
        inside = np.all((p + rad[:, None] >= lo) & (p - rad[:, None] <= hi), axis=1)
        for k in np.nonzero(inside)[0]:
            (x, y), = canvas.px(p[k])
            r_px = max(1, int(round(rad[k] * canvas.box.scale)))
            colour = tuple(int(v) for v in colours[k])
            pygame.gfxdraw.filled_circle(surf, x, y, r_px, colour)
            pygame.gfxdraw.aacircle(surf, x, y, r_px,
                                    FLOE_EDGE if r_px >= edge_px else colour)


def draw_contact_forces(canvas: ViewCanvas, wrapped: np.ndarray, contacts) -> None:
    """The contacts ``(i, j, |force|)`` (:func:`check_contacts`) between the
    floes at ``wrapped`` as lines between the nearest images, 1 to 4 px
    wide in proportion to force / the largest force."""
    if contacts is None:
        return
    ci, cj, cf = contacts
    if not (ci.size and cf.max() > 0):
        return
    a = wrapped[ci]
    b = wrapped[cj] - wrapped[ci]
    for axis, period in enumerate(canvas.periods):
        if period is not None:
            b[:, axis] -= period * np.round(b[:, axis] / period)
    b += a
    line_w = 1 + np.rint(3.0 * cf / cf.max()).astype(int)
    for d in canvas.shifts(np.minimum(a, b), np.maximum(a, b)):
        for k in np.nonzero(cf > 0)[0]:
            canvas.pygame.draw.line(canvas.surf, CHAIN, canvas.px(a[k] + d)[0],
                                    canvas.px(b[k] + d)[0], int(line_w[k]))
