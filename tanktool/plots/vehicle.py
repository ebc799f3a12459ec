"""Vehicle preview: top and side views with the hull points and each sphere level.

One column for the hull (footprint polygon and hull points over the model) and one
column per sphere-tree level; the top row looks down from +y (x right, z down, so a
tank facing +x has its right side, +z, at the bottom of the picture), the bottom row
looks from the vehicle's right side (+z: x right, y up).
"""

from __future__ import annotations

import os

import numpy as np

LEVEL_COLOURS = ["#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"]


def _faces_2d(ax, vertices: np.ndarray, faces: np.ndarray, colours: np.ndarray, axes: tuple[int, int],
              depth: int, towards_viewer: bool) -> None:
    """Draw the triangles projected on ``axes``, far ones first (painter's order)."""
    from matplotlib.collections import PolyCollection

    tri = vertices[faces]
    key = tri[:, :, depth].mean(axis=1)
    order = np.argsort(key if towards_viewer else -key)
    polys = tri[order][:, :, list(axes)]
    # shade by how squarely a face looks at the viewer, a light from the eye
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(n, axis=1)
    facing = np.abs(n[:, depth]) / np.where(length > 0, length, 1.0)
    shaded = np.clip(colours * (0.6 + 0.4 * facing)[:, None], 0, 1)[order]
    ax.add_collection(PolyCollection(polys, facecolors=shaded, edgecolors=shaded,
                                     linewidths=0.3, zorder=1))


def _render_view(vertices: np.ndarray, faces: np.ndarray, colours: np.ndarray, axes: tuple[int, int],
                 depth: int, xlim: tuple[float, float], ylim: tuple[float, float], width_px: int) -> np.ndarray:
    """The model seen along ``depth`` as an RGBA image covering xlim x ylim.

    Drawn once per view and shown in every panel of that row, so a 30,000-face model
    costs two renders instead of one per panel.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    aspect = abs(ylim[1] - ylim[0]) / abs(xlim[1] - xlim[0])
    dpi = 100
    fig = Figure(figsize=(width_px / dpi, max(width_px * aspect, 1) / dpi), dpi=dpi)
    fig.patch.set_alpha(0)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_axis_off()
    ax.patch.set_alpha(0)
    _faces_2d(ax, vertices, faces, colours, axes, depth, True)
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba()).copy()


def _hull_panel(ax, hull: np.ndarray, axes: tuple[int, int], top: bool, label: str) -> None:
    """The hull's footprint (top view) or its bounding box (side view) and its points."""
    from matplotlib.patches import Polygon

    pts2 = hull[:, list(axes)]
    if top:  # the first half of the hull points is the bottom ring: the footprint
        ax.add_patch(Polygon(pts2[:len(hull) // 2], closed=True, fill=False, ec="black", lw=1.4, zorder=3))
    else:
        ylo, yhi = hull[:, 1].min(), hull[:, 1].max()
        xlo, xhi = hull[:, 0].min(), hull[:, 0].max()
        ax.add_patch(Polygon([[xlo, ylo], [xhi, ylo], [xhi, yhi], [xlo, yhi]], closed=True,
                             fill=False, ec="black", lw=1.4, zorder=3))
    ax.plot(pts2[:, 0], pts2[:, 1], "o", ms=4, mfc="#ffdd00", mec="black", zorder=4)
    ax.set_title(f"hull: {len(hull)} points — {label}", fontsize=9)


def _level_panel(ax, tree, lev: int, axes: tuple[int, int], label: str) -> None:
    """The spheres of one sphere-tree level, filled lightly and outlined."""
    from matplotlib.patches import Circle

    idx = np.flatnonzero(tree.level == lev)
    colour = LEVEL_COLOURS[(lev - 1) % len(LEVEL_COLOURS)]
    for i in idx:
        c = tree.centers[i]
        ax.add_patch(Circle((c[axes[0]], c[axes[1]]), tree.radii[i], fill=True, fc=colour,
                            alpha=0.10, ec="none", zorder=2))
        ax.add_patch(Circle((c[axes[0]], c[axes[1]]), tree.radii[i], fill=False, ec=colour,
                            lw=1.1, zorder=3))
        ax.plot(c[axes[0]], c[axes[1]], "+", color=colour, ms=5, zorder=4)
    ax.set_title(f"level {lev}: {len(idx)} sphere{'s' if len(idx) != 1 else ''} — {label}", fontsize=9)


#: the picture's layout in inches: panel width, the margins around and between panels
PANEL_W, LEFT, GAP_X, RIGHT, TITLE, TICKS, BOTTOM, SUPTITLE = 3.6, 0.6, 0.45, 0.15, 0.3, 0.25, 0.5, 0.45
DPI = 100


def plot_vehicle(path: str | os.PathLike, mesh, hull: np.ndarray, tree, title: str = "") -> None:
    """Write the preview PNG for a vehicle-frame ``mesh`` with its hull and sphere tree."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from ..formats.bundle import atomic_write_bytes

    v = np.asarray(mesh.vertices, dtype=np.float64)
    f = np.asarray(mesh.faces, dtype=np.int64)
    try:
        colours = np.asarray(mesh.visual.face_colors, dtype=np.float64)[:, :3] / 255.0
    except Exception:  # no colour information: a neutral grey
        colours = np.full((len(f), 3), 0.6)
    colours = 0.35 + 0.65 * colours  # lighten so the outlines on top stay readable

    levels = int(tree.level.max())
    ncol = 1 + levels
    lo = np.minimum(v.min(axis=0), (tree.centers - tree.radii[:, None]).min(axis=0))
    hi = np.maximum(v.max(axis=0), (tree.centers + tree.radii[:, None]).max(axis=0))
    pad = 0.05 * float((hi - lo).max())
    lo, hi = lo - pad, hi + pad
    width_x, width_z, height_y = hi[0] - lo[0], hi[2] - lo[2], hi[1] - lo[1]
    # laid out by hand: each panel as tall as its view at the panel's width (no
    # tight_layout, which draws the whole figure once more to measure it)
    rows_h = [PANEL_W * width_z / width_x, PANEL_W * height_y / width_x]
    fig_w = LEFT + ncol * PANEL_W + (ncol - 1) * GAP_X + RIGHT
    top = SUPTITLE if title else 0.1
    fig_h = top + 2 * TITLE + rows_h[0] + TICKS + rows_h[1] + BOTTOM
    fig = Figure(figsize=(fig_w, fig_h), dpi=DPI)
    bottoms = [fig_h - top - TITLE - rows_h[0], BOTTOM]
    axs = np.array([[fig.add_axes(((LEFT + c * (PANEL_W + GAP_X)) / fig_w, bottoms[r] / fig_h, PANEL_W / fig_w,
                                   rows_h[r] / fig_h)) for c in range(ncol)] for r in range(2)])
    views = [((0, 2), 1, True, "top (from +y)", "z (m, right side down)"),
             ((0, 1), 2, True, "side (from the right, +z)", "y (m)")]
    for row, (axes, depth, toward, label, ylabel) in enumerate(views):
        xlim = (lo[axes[0]], hi[axes[0]])
        # top view: z grows downwards (looking down from +y); side view: y up
        ylim = (hi[2], lo[2]) if row == 0 else (lo[1], hi[1])
        # at the panels' own resolution, so drawing it is a copy, not a filtered resampling
        image = _render_view(v, f, colours, axes, depth, xlim, ylim, width_px=int(round(PANEL_W * DPI)))
        for col in range(ncol):
            ax = axs[row, col]
            # extent is (left, right, bottom, top) in data units, matching ylim's order
            ax.imshow(image, extent=(xlim[0], xlim[1], ylim[0], ylim[1]), origin="upper",
                      interpolation="nearest", zorder=1)
            ax.set_aspect("equal")
            ax.set_xlim(*xlim)
            ax.set_ylim(*ylim)
            ax.tick_params(labelsize=7)
            ax.grid(True, lw=0.3, alpha=0.5, zorder=0)
            if col == 0:
                ax.set_ylabel(ylabel, fontsize=8)
            if row == 1:
                ax.set_xlabel("x (m, forward)", fontsize=8)
            if col == 0:
                _hull_panel(ax, hull, axes, row == 0, label)
            else:
                _level_panel(ax, tree, col, axes, label)
    if title:
        fig.suptitle(title, fontsize=11, y=1 - 0.12 / fig_h, va="top")
    import io

    buf = io.BytesIO()
    # no timestamps in the PNG so that rebuilding gives the same bytes
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    atomic_write_bytes(path, buf.getvalue())
