"""Top view of a navigation grid: nodes by state, walls with their normals, the
quadtree's leaves, spawn points, and the run numbers on the nodes when they fit.

z points up the picture (as in the other tanktool pictures), x to the right.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

#: node states, drawn in this order of colours
STATE_COLOURS = {
    "solid / outside": "#4a4a4a",
    "too close to a wall": "#d9cfc1",
    "valid": "#8fd18b",
    "valid, unreachable": "#f0a14a",
}
WALL_COLOUR = "#1b1b1b"
QUADTREE_COLOUR = "#2f6db5"
SPAWN_COLOUR = "#d62728"
#: shades of valid nodes on a grid with relief
HEIGHT_CMAP = "summer"
#: annotate nodes only when a node is at least this many points wide
MIN_LABEL_PT = {"rows": 15.0, "cols": 15.0, "both": 20.0}


def level_view(grid: Any, level: int) -> Any:
    """One level of a grid as a one-level NavGrid."""
    from ..nav.navgrid import NavGrid

    if grid.levels == 1:
        return grid
    lv = slice(level, level + 1)
    arrays = [getattr(grid, k)[lv] for k in ("valid", "row_index", "row_total", "col_index", "col_total", "reachable")]
    links = np.where(grid.links()[lv] == level, 0, -1).astype(np.int8)   # steps to other levels leave this view
    return NavGrid(grid.origin, grid.cell, grid.shape, *arrays, grid.clearance, height=grid.heights()[lv], link=links)


def node_states(grid: Any, free: np.ndarray | None = None) -> np.ndarray:
    """(nz, nx) int codes 0..3 of a one-level grid's nodes, in the order of :data:`STATE_COLOURS`."""
    s = np.zeros(grid.shape, dtype=np.int8)
    if free is not None:
        s[free] = 1
    else:  # without the free mask, invalid nodes are all one colour
        s[:] = 1
    valid = grid.valid[0]
    s[valid] = 3
    s[grid.reachable[0] & valid] = 2
    return s


@dataclass
class _Frame:
    """What every panel of one picture shares: the view, the cells it touches and the
    figure's size (they decide whether run numbers fit)."""

    view: np.ndarray            # [[x0, z0], [x1, z1]] of the axes
    j0: int                     # the cells the view touches: columns j0..j1, rows i0..i1
    j1: int
    i0: int
    i1: int
    view_span: float            # the view's larger side [m]
    width_in: float             # the figure's width, legend included [in]
    height_in: float            # one panel's height [in]
    relief: tuple[float, float] | None    # the heights of a grid with relief, else None

    @property
    def cell_pt(self) -> float:
        """How many points wide a cell is drawn."""
        return (self.width_in - 2.6) * 0.92 * 72.0 / max(1, self.j1 - self.j0)


def _frame(grid: Any, region: np.ndarray | None, annotate: str) -> _Frame:
    """The view of ``grid`` (the whole of it, padded, or ``region`` widened to whole
    cells) and a figure big enough for ``annotate``'s labels when they can fit."""
    b = grid.bounds
    view = b.copy() if region is None else np.asarray(region, dtype=np.float64).reshape(2, 2)
    # the cells the view touches; they decide how big the figure must be for labels
    j0 = max(0, int(math.floor((view[0, 0] - grid.origin[0]) / grid.cell)))
    j1 = min(grid.nx, int(math.ceil((view[1, 0] - grid.origin[0]) / grid.cell)))
    i0 = max(0, int(math.floor((view[0, 1] - grid.origin[1]) / grid.cell)))
    i1 = min(grid.nz, int(math.ceil((view[1, 1] - grid.origin[1]) / grid.cell)))
    if region is not None:  # widen a region to whole cells, so no label is cut
        view = grid.origin + grid.cell * np.array([[j0, i0], [j1, i1]], dtype=np.float64)
    view_span = float(np.max(view[1] - view[0]))
    if region is None:
        pad = 0.02 * view_span
        view = view + np.array([[-pad], [pad]])
    across = max(1, j1 - j0)
    tall = max(1, i1 - i0)
    aspect = (view[1, 1] - view[0, 1]) / max(view[1, 0] - view[0, 0], 1e-9)
    want_pt = MIN_LABEL_PT.get(annotate, 0.0) * 1.45
    width_in = 10.0
    if annotate != "none" and across <= 80 and tall <= 80:
        width_in = min(max(width_in, across * want_pt / 72.0), 22.0)
    height_in = min(max(width_in * aspect, 3.0), 22.0)
    width_in = min(width_in, 22.0) + 2.6  # room for the legend
    heights = grid.heights()
    # fmin / fmax pass over the NaNs (no node) without the finite heights' copy (hix: 20 MB)
    lo, hi = float(np.fmin.reduce(heights, axis=None)), float(np.fmax.reduce(heights, axis=None))
    if not (math.isfinite(lo) and math.isfinite(hi)):   # no node at all, or an infinite height: as it was
        hv = heights[np.isfinite(heights)]
        lo, hi = (float(hv.min()), float(hv.max())) if len(hv) else (0.0, 0.0)
    relief = (lo, hi) if hi - lo > 0.25 else None
    return _Frame(view, j0, j1, i0, i1, view_span, width_in, height_in, relief)


def _draw_nodes(ax, grid: Any, states: np.ndarray, fr: _Frame, labelling: bool) -> None:
    """Node states (shaded by height on a grid with relief), and node centres and cell
    edges when cells are big enough to show them."""
    from matplotlib import colormaps
    from matplotlib.colors import to_rgba_array

    from .arena import image_step

    b = grid.bounds
    extent = (b[0, 0], b[1, 0], b[0, 1], b[1, 1])
    k, sampled = image_step(states.shape, grid.origin, grid.cell)
    if k > 1:  # a grid of more cells than the picture has pixels: every k-th node
        extent = sampled
    shown = states[::k, ::k]
    colours = to_rgba_array(list(STATE_COLOURS.values()))
    # bytes, as matplotlib turns a float image into (x * 255 truncated): a float RGBA
    # image of hix's 1604 x 1604 nodes was 82 MB to fill, resample and convert
    rgba = (colours * 255).astype(np.uint8)[shown]
    relief = fr.relief
    if relief is not None:  # reachable nodes shaded by their height, over their state's colour
        reach = shown == 2
        lo, hi = relief[0], max(relief[1], relief[0] + 1e-6)
        # the colour map's own lookup (a value x is entry int(x * N), 1.0 the last),
        # blended once per entry and not once per node
        cmap = colormaps[HEIGHT_CMAP]
        lut = ((0.85 * cmap(np.arange(cmap.N)) + 0.15 * colours[2]) * 255).astype(np.uint8)
        x = (grid.heights()[0, ::k, ::k][reach] - lo) / (hi - lo)
        rgba[reach] = lut[np.clip((x * cmap.N).astype(np.intp), 0, cmap.N - 1)]
    # one image, composed here: two (states, then the heights at alpha 0.85) cost
    # matplotlib a second resampling and colour mapping of the whole grid
    ax.imshow(rgba, origin="lower", interpolation="nearest", extent=extent, zorder=0)
    cell_pt = fr.cell_pt
    if cell_pt < 6:  # node centres and cell edges would turn into a smear
        return
    i0, i1, j0, j1 = fr.i0, fr.i1, fr.j0, fr.j1
    xs, zs = np.meshgrid(grid.node_x[j0:j1], grid.node_z[i0:i1])
    # no dots on solid ground (clutter) nor under labels (the label marks the node)
    dot = states[i0:i1, j0:j1] > 0
    if labelling:
        dot &= ~grid.valid[0, i0:i1, j0:j1]
    ax.scatter(xs[dot], zs[dot], s=min(max(1.0, (cell_pt * 0.12) ** 2), 9.0), c="#00000055", lw=0, zorder=1)
    gx = grid.origin[0] + np.arange(j0, j1 + 1) * grid.cell
    gz = grid.origin[1] + np.arange(i0, i1 + 1) * grid.cell
    ax.vlines(gx, gz[0], gz[-1], colors="#ffffff", lw=0.4, alpha=0.7, zorder=1)
    ax.hlines(gz, gx[0], gx[-1], colors="#ffffff", lw=0.4, alpha=0.7, zorder=1)


def _draw_quadtree(ax, quadtree: Any) -> None:
    """The quadtree's leaves as boxes."""
    from matplotlib.collections import LineCollection

    lb = quadtree.box[quadtree.leaves]
    lines = []
    for (x0, z0), (x1, z1) in lb.tolist():
        lines += [[(x0, z0), (x1, z0)], [(x1, z0), (x1, z1)], [(x1, z1), (x0, z1)], [(x0, z1), (x0, z0)]]
    ax.add_collection(LineCollection(lines, colors=QUADTREE_COLOUR, lw=0.8, alpha=0.55, zorder=2))


def _draw_walls(ax, walls: Any, view_span: float) -> None:
    """Walls, auxiliary rectangles dashed, and the walls' normals."""
    from matplotlib.collections import LineCollection

    seg = walls.segments
    ax.add_collection(LineCollection(seg, colors=WALL_COLOUR, lw=1.8, capstyle="round", zorder=3))
    if walls.aux is not None:
        ax.add_collection(LineCollection(walls.aux, colors=WALL_COLOUR, lw=0.8, linestyles="dashed", zorder=3))
    # normals as short ticks into free space, when there are few enough to read
    if 0 < len(seg) <= 400:
        mid = seg.mean(axis=1)
        tick = walls.normals * (0.012 * view_span)
        ax.add_collection(LineCollection(np.stack([mid, mid + tick], axis=1), colors=WALL_COLOUR, lw=1.0, zorder=3))


def _draw_spawns(ax, spawns: Any, view_span: float) -> None:
    """Spawn points as stars, with an arrow along their heading when they have one."""
    sp = np.asarray(spawns, dtype=np.float64).reshape(len(spawns), -1)
    ax.scatter(sp[:, 0], sp[:, 1], marker="*", s=200, c=SPAWN_COLOUR, edgecolors="white", linewidths=0.8, zorder=6)
    if sp.shape[1] >= 3:
        L = 0.04 * view_span
        ax.quiver(sp[:, 0], sp[:, 1], np.cos(sp[:, 2]) * L, np.sin(sp[:, 2]) * L, angles="xy",
                  scale_units="xy", scale=1, color=SPAWN_COLOUR, width=0.004, zorder=5)


def _draw_labels(ax, grid: Any, fr: _Frame, annotate: str) -> int:
    """Run numbers on the valid nodes inside the view; how many were written."""
    # "12/34" is five characters of about 0.6 em: fill most of the cell's width
    font = min(11.0, fr.cell_pt / 4.0)
    view = fr.view
    ii, jj = np.nonzero(grid.valid[0, fr.i0:fr.i1, fr.j0:fr.j1])
    ii, jj = ii + fr.i0, jj + fr.j0
    labelled = 0
    for i, j in zip(ii.tolist(), jj.tolist()):
        x, z = grid.centre(i, j)
        if not (view[0, 0] <= x <= view[1, 0] and view[0, 1] <= z <= view[1, 1]):
            continue  # a label must not spill over the axes
        r = f"{grid.row_index[0, i, j]}/{grid.row_total[0, i, j]}"
        c = f"{grid.col_index[0, i, j]}/{grid.col_total[0, i, j]}"
        text = {"rows": r, "cols": c, "both": f"{r}\n{c}"}[annotate]
        ax.text(x, z, text, ha="center", va="center", fontsize=font, color="#10301a", linespacing=0.95,
                zorder=4, clip_on=True)
        labelled += 1
    return labelled


def _panel_title(grid: Any, title: str, whole: Any) -> str:
    """A panel's title: the grid's size and settings and its count of valid nodes
    (``whole``: the grid of which ``grid`` is a level, on the first panel only)."""
    n_valid = int(grid.valid.sum())
    n_reach = int((grid.valid & grid.reachable).sum())
    total = whole if whole is not None else grid
    levels = f", {whole.levels} levels" if whole is not None and whole.levels > 1 else ""
    return (f"{title}: {grid.nz} x {grid.nx} nodes{levels}, cell {grid.cell:g} m, clearance {grid.clearance:g} m\n"
            f"{n_valid:,} valid ({n_reach:,} reachable, {n_valid - n_reach:,} unreachable)"
            + (f" of {total.valid.size:,}" if whole is not None or total is grid else ""))


def _draw_panel(ax, grid: Any, walls: Any, fr: _Frame, annotate: str, title: str, whole: Any, *,
                free: np.ndarray | None, quadtree: Any, spawns: Any) -> int:
    """Draw one level's nodes, walls, leaves, spawns and run numbers on ``ax``; how many
    run numbers were written."""
    states = node_states(grid, free)
    labelling = annotate != "none" and fr.cell_pt >= MIN_LABEL_PT.get(annotate, 99)
    _draw_nodes(ax, grid, states, fr, labelling)
    if quadtree is not None:
        _draw_quadtree(ax, quadtree)
    _draw_walls(ax, walls, fr.view_span)
    if spawns is not None and len(spawns):
        _draw_spawns(ax, spawns, fr.view_span)
    labelled = _draw_labels(ax, grid, fr, annotate) if labelling else 0
    view = fr.view
    ax.set_xlim(view[0, 0], view[1, 0])
    ax.set_ylim(view[0, 1], view[1, 1])
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_title(_panel_title(grid, title, whole), fontsize=10)
    return labelled


def _legend(fig, walls: Any, quadtree: Any, spawns: Any, annotate: str, labelled: int,
            relief: tuple[float, float] | None) -> None:
    """The legend (only what the picture shows) and, on a grid with relief, the height bar."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [Patch(fc=c, ec="#888888", label=k) for k, c in STATE_COLOURS.items()]
    if relief is not None:
        handles[2] = Patch(fc="#6fb36b", ec="#888888", label="valid (shade: height)")
    handles.append(Line2D([], [], color=WALL_COLOUR, lw=1.8, label="wall (tick: free side)"))
    if walls.aux is not None:
        handles.append(Line2D([], [], color=WALL_COLOUR, lw=0.8, ls="--", label="auxiliary rectangle"))
    if quadtree is not None:
        handles.append(Line2D([], [], color=QUADTREE_COLOUR, lw=0.8, alpha=0.7,
                              label=f"quadtree leaves ({len(quadtree.leaves)}, depth {quadtree.max_depth})"))
    if spawns is not None and len(spawns):
        handles.append(Line2D([], [], marker="*", color=SPAWN_COLOUR, lw=0, ms=12, label="spawn point"))
    if labelled:
        handles.append(Patch(fc="none", ec="none", label={
            "rows": "labels: renglón/total", "cols": "labels: columna/total",
            "both": "labels: renglón/total\n            columna/total"}[annotate]))
    fig.legend(handles=handles, loc="upper right", fontsize=8, frameon=False, bbox_to_anchor=(0.995, 0.93))
    if relief is not None:
        import matplotlib.cm as cm
        from matplotlib.colors import Normalize

        cax = fig.add_axes((0.90, 0.08, 0.015, 0.25))
        fig.colorbar(cm.ScalarMappable(Normalize(*relief), HEIGHT_CMAP), cax=cax, label="surface y [m]")


def render_navgrid(
    grid: Any,
    walls: Any,
    *,
    fmt: str = "png",
    quadtree: Any = None,
    free: np.ndarray | None = None,
    spawns: np.ndarray | None = None,
    annotate: str = "both",
    region: np.ndarray | None = None,
    title: str | None = None,
    dpi: int = 120,
) -> bytes:
    """The picture as PNG or SVG bytes (``fmt``).

    grid : NavGrid; walls : WallList; quadtree : WallQuadtree (its leaves are drawn);
    free : free-space mask, to tell "too close to a wall" from "solid / outside";
    spawns : (k, 3) ``[x, z, heading]``; region : ``[[x0, z0], [x1, z1]]`` to zoom in;
    annotate : "rows" (renglón/total), "cols" (columna/total), "both" or "none".
    """
    fr = _frame(grid, region, annotate)
    if fr.j1 <= fr.j0 or fr.i1 <= fr.i0:
        raise ValueError(f"region {np.asarray(region).tolist()} holds no node of the grid")
    if fmt == "png":   # Pillow: a fraction of matplotlib's cost (plots/navgrid_png.py)
        from .navgrid_png import render_png

        return render_png(grid, walls, fr, quadtree=quadtree, free=free, spawns=spawns, annotate=annotate,
                          title=title, dpi=dpi)
    import matplotlib
    from matplotlib.figure import Figure

    L = grid.levels
    # a Figure of its own, not pyplot's (0.3 s to import, and a figure manager to close)
    fig = Figure(figsize=(fr.width_in, (fr.height_in + 0.8) * L))
    labelled = 0
    for lv in range(L):
        top = 1.0 - lv / L
        ax = fig.add_axes((0.06, top - (0.94 / L), (fr.width_in - 2.6) / fr.width_in * 0.92, 0.86 / L))
        w = walls.on_level(lv) if getattr(walls, "layered", False) else walls
        head = f"{title or 'navigation grid'}" + (f", level {lv}" if L > 1 else "")
        labelled += _draw_panel(ax, level_view(grid, lv), w, fr, annotate, head, grid if lv == 0 else None,
                                free=free if L == 1 else None, quadtree=quadtree,
                                spawns=spawns if lv == 0 else None)
    _legend(fig, walls, quadtree, spawns, annotate, labelled, fr.relief)
    buf = io.BytesIO()
    # SVG keeps its text as text, so run numbers can be searched and selected
    with matplotlib.rc_context({"svg.fonttype": "none"}):
        fig.savefig(buf, format=fmt, dpi=dpi)
    return buf.getvalue()
