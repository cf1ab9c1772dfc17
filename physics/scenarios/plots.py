"""Figure helpers shared by the scenarios (matplotlib, Agg backend).

* :func:`draw_snapshot` — floes of one snapshot as discs coloured by speed
  (frozen floes grey), with the force network drawn as lines between the
  centres of touching floes, width ∝ normal force (Herman 2013, Figs 2, 4).
* :func:`snapshot_panels` — a row of such panels from a dataset.
* :func:`savefig` — tight layout, fixed dpi, closes the figure.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np


def pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def savefig(fig, path: Path, dpi: int = 120, palette: bool = False) -> Path:
    """Save ``fig`` as ``path`` and close it. With ``palette`` a PNG is
    stored with 256 colours (an adaptive palette, no dithering): a third to
    a quarter of the size for line plots, which hold few colours anyway."""
    plt = pyplot()
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    if palette and Path(path).suffix.lower() == ".png":
        to_palette(path)
    return Path(path)


def to_palette(path: Path) -> Path:
    """Rewrite the PNG ``path`` with an adaptive palette of 256 colours."""
    from PIL import Image

    with Image.open(path) as image:
        picture = np.asarray(image.convert("RGB"))
    return save_palette_png(picture, path)


def save_palette_png(picture: np.ndarray, path: Path, *, fast: bool = False) -> Path:
    """The RGB ``picture`` (H, W, 3) written to ``path`` as a PNG of an
    adaptive palette of 256 colours, without dithering (median cut, or
    ``fast`` octree quantisation)."""
    from PIL import Image

    method = Image.Quantize.FASTOCTREE if fast else Image.Quantize.MEDIANCUT
    small = Image.fromarray(np.ascontiguousarray(picture)).quantize(
        colors=256, method=method, dither=Image.Dither.NONE)
    small.save(path, optimize=True)
    return Path(path)


def draw_snapshot(ax, snap, *, forces: bool = True, colour: str = "speed", vmax=None,
                  title: str | None = None):
    """Draw one snapshot (a dataset indexed down to one snapshot, with floe_x,
    floe_y, floe_radius, floe_u, floe_v, floe_frozen, snapshot_lx/ly and optionally contact_i/j/force)
    on ``ax``. ``colour``: "speed" or "none". Returns the collection."""
    from matplotlib.collections import EllipseCollection, LineCollection

    x = np.asarray(snap["floe_x"]).ravel()
    ok = np.isfinite(x)
    x = x[ok]
    y = np.asarray(snap["floe_y"]).ravel()[ok]
    r = np.asarray(snap["floe_radius"]).ravel()[ok]
    u = np.asarray(snap["floe_u"]).ravel()[ok]
    v = np.asarray(snap["floe_v"]).ravel()[ok]
    frozen = np.asarray(snap["floe_frozen"]).ravel()[ok].astype(bool) if "floe_frozen" in snap else \
        np.zeros(len(x), bool)
    lx = float(snap["snapshot_lx"]) if "snapshot_lx" in snap else float(np.nanmax(x + r))
    ly = float(snap["snapshot_ly"]) if "snapshot_ly" in snap else float(np.nanmax(y + r))
    speed = np.hypot(u, v)
    coll = EllipseCollection(2 * r, 2 * r, np.zeros_like(r), units="xy",
                             offsets=np.column_stack([x, y]), offset_transform=ax.transData,
                             linewidths=0.2, edgecolors="0.3")
    if colour == "speed":
        coll.set_array(np.where(frozen, np.nan, speed))
        coll.set_cmap("viridis")
        coll.set_clim(0.0, vmax if vmax is not None else max(float(np.nanmax(speed)), 1e-12))
        coll.cmap.set_bad("0.6")
    else:
        coll.set_facecolor(np.where(frozen[:, None], [[0.6, 0.6, 0.6, 1]], [[0.8, 0.9, 1, 1]]))
    ax.add_collection(coll)
    if forces and "contact_i" in snap:
        ci = np.asarray(snap["contact_i"]).ravel()
        cj = np.asarray(snap["contact_j"]).ravel()
        cf = np.asarray(snap["contact_force"]).ravel()
        keep = (ci >= 0) & (cj >= 0) & np.isfinite(cf)
        ci, cj, cf = ci[keep].astype(int), cj[keep].astype(int), cf[keep]
        if len(cf):
            xs = np.asarray(snap["floe_x"]).ravel()
            ys = np.asarray(snap["floe_y"]).ravel()
            p0 = np.column_stack([xs[ci], ys[ci]])
            d = np.column_stack([xs[cj], ys[cj]]) - p0
            d[:, 0] -= lx * np.round(d[:, 0] / lx)       # minimum image (periodic sides)
            d[:, 1] -= ly * np.round(d[:, 1] / ly)
            width = 0.3 + 2.5 * np.sqrt(cf / cf.max())
            ax.add_collection(LineCollection(np.stack([p0, p0 + d], axis=1), linewidths=width,
                                             colors="crimson", alpha=0.8))
    ax.set_xlim(0, lx)
    ax.set_ylim(0, ly)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    if title:
        ax.set_title(title, fontsize=9)
    return coll


def snapshot_panels(ds, path: Path, *, title: str, labels, forces: bool = True,
                    select=None) -> Path:
    """One panel per entry of ``select`` (a list of dicts for ``ds.isel``,
    e.g. ``[{"case": 0, "member": 0, "snapshot": 1}]``), titled by
    ``labels``; a shared speed colour bar."""
    plt = pyplot()
    k = len(select)
    fig, axes = plt.subplots(1, k, figsize=(4.8 * k + 0.8, 4.4), squeeze=False,
                             layout="constrained")
    vmax = 0.0
    snaps = [ds.isel(s) for s in select]
    for s in snaps:
        sp = np.hypot(np.asarray(s["floe_u"]), np.asarray(s["floe_v"]))
        mobile = np.asarray(s["floe_frozen"]) == 0 if "floe_frozen" in s else np.ones(sp.shape, bool)
        if np.isfinite(sp[mobile]).any():
            vmax = max(vmax, float(np.nanpercentile(sp[mobile], 99)))
    coll = None
    for ax, s, lab in zip(axes[0], snaps, labels):
        coll = draw_snapshot(ax, s, forces=forces, vmax=vmax or None, title=lab)
    for ax in axes[0][1:]:
        ax.set_ylabel("")
    if coll is not None:
        fig.colorbar(coll, ax=axes[0].tolist(), shrink=0.9, label="speed [m/s]")
    fig.suptitle(title, fontsize=9)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return Path(path)
