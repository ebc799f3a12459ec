"""navgrid.png drawn with Pillow (plots/raster.py): the same picture as
plots/navgrid.py's matplotlib one (which still writes the SVG, whose run numbers stay
text), laid out the same way, at a fraction of the cost (hix: 0.33-0.39 -> 0.06-0.07 s
of CPU, docs/speed.md).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from . import raster
from .colourmaps import lut_float


def state_table() -> np.ndarray:
    """(4, 4) RGBA bytes of the node states, as matplotlib's float colours times 255
    truncated (the bytes the matplotlib picture had)."""
    from .navgrid import STATE_COLOURS

    rows = [[c / 255.0 for c in raster.rgb(h)] + [1.0] for h in STATE_COLOURS.values()]
    return (np.array(rows) * 255).astype(np.uint8)


def sampled_states(grid: Any, free: np.ndarray | None, k: int) -> np.ndarray:
    """navgrid.node_states of every k-th node each way, worked out on those nodes only
    (hix: a quarter of the 2.6 M nodes)."""
    valid, reach = grid.valid[0, ::k, ::k], grid.reachable[0, ::k, ::k]
    base = free[::k, ::k].astype(np.int8) if free is not None else np.ones(valid.shape, dtype=np.int8)
    return np.where(valid, np.where(reach, 2, 3), base).astype(np.int8)


def node_image(grid: Any, free: np.ndarray | None, relief: tuple[float, float] | None) -> tuple[np.ndarray, tuple]:
    """(RGB bytes of the nodes, their extent): every node's state, reachable ones
    shaded by height on a grid with relief, every k-th node on a grid larger than
    MAX_IMAGE_SIDE (plots/arena.py image_step)."""
    from .arena import image_step

    b = grid.bounds
    extent = (b[0, 0], b[1, 0], b[0, 1], b[1, 1])
    k, sampled = image_step(grid.shape, grid.origin, grid.cell)
    if k > 1:
        extent = sampled
    shown = sampled_states(grid, free, k)
    table = state_table()[:, :3]   # opaque: RGB
    if relief is None:
        return table[shown], extent
    # one lookup of the states and the shaded heights together: entries 0..3 the
    # states, 4.. the colour map's entries blended once with the valid colour (not once
    # per node); a value x is entry int(x * 256), as matplotlib's colour map looks it up
    lo, hi = relief[0], max(relief[1], relief[0] + 1e-6)
    from .navgrid import HEIGHT_CMAP

    shade = ((0.85 * lut_float(HEIGHT_CMAP) + 0.15 * (table[2] / 255.0)) * 255).astype(np.uint8)
    reach = shown == 2
    x = (grid.heights()[0, ::k, ::k] - lo) * (256 / (hi - lo))
    x = np.where(reach, x, 0.0).astype(np.intp)
    np.clip(x, 0, 255, out=x)
    idx = np.where(reach, x + 4, shown)
    rgba = np.concatenate([table, shade])[idx]
    return rgba, extent


def _cells(panel: raster.Panel, grid: Any, states: np.ndarray, fr: Any, labelling: bool, pt: float) -> None:
    """Node centres and cell edges, when cells are big enough to show them."""
    i0, i1, j0, j1 = fr.i0, fr.i1, fr.j0, fr.j1
    if i1 <= i0 or j1 <= j0:   # a view beside the grid: no cell in it
        return
    xs, zs = np.meshgrid(grid.node_x[j0:j1], grid.node_z[i0:i1])
    dot = states[i0:i1, j0:j1] > 0   # no dots on solid ground (clutter) nor under labels
    if labelling:
        dot &= ~grid.valid[0, i0:i1, j0:j1]
    r = 0.5 * np.sqrt(min(max(1.0, (fr.cell_pt * 0.12) ** 2), 9.0)) * pt
    dots(panel, panel.px(np.column_stack([xs[dot], zs[dot]])), r, 85)
    gx = grid.origin[0] + np.arange(j0, j1 + 1) * grid.cell
    gz = grid.origin[1] + np.arange(i0, i1 + 1) * grid.cell
    edge = (255, 255, 255, 178)
    panel.segments(np.stack([np.column_stack([gx, np.full_like(gx, gz[0])]),
                             np.column_stack([gx, np.full_like(gx, gz[-1])])], axis=1), edge, 1)
    panel.segments(np.stack([np.column_stack([np.full_like(gz, gx[0]), gz]),
                             np.column_stack([np.full_like(gz, gx[-1]), gz])], axis=1), edge, 1)


def dots(panel: raster.Panel, c: np.ndarray, r: float, alpha: int) -> None:
    """Black discs of radius ``r`` px at pixel centres ``c`` (n, 2), ``alpha`` of 255
    over the tile: one footprint (the pixel under each centre and those within r of
    it, so every dot has the same shape) set in one mask by numpy -- an ellipse call
    per node cost a 16,000-node grid ~50 ms."""
    from PIL import Image

    w, h = panel.tile.size
    mask = np.zeros((h, w), dtype=np.uint8)
    ix, iy = np.floor(c[:, 0]).astype(np.intp), np.floor(c[:, 1]).astype(np.intp)
    R = int(np.floor(r))
    foot = [(dx, dy) for dy in range(-R, R + 1) for dx in range(-R, R + 1) if dx * dx + dy * dy <= max(r * r, 0)]
    # the disc's ink spread over its footprint, as an antialiased disc would put it
    ink = int(min(255, round(alpha * np.pi * r * r / len(foot))))
    for dx, dy in foot:
        px, py = ix + dx, iy + dy
        on = (px >= 0) & (px < w) & (py >= 0) & (py < h)
        mask[py[on], px[on]] = ink
    panel.tile.paste(Image.new("RGB", (w, h), raster.BLACK), (0, 0), Image.fromarray(mask))


def _labels(panel: raster.Panel, grid: Any, fr: Any, annotate: str, pt: float) -> int:
    """Run numbers on the valid nodes inside the view; how many were written."""
    size = min(11.0, fr.cell_pt / 4.0) * pt   # "12/34" is five characters of ~0.6 em: most of a cell
    view = fr.view
    ii, jj = np.nonzero(grid.valid[0, fr.i0:fr.i1, fr.j0:fr.j1])
    ii, jj = ii + fr.i0, jj + fr.j0
    labelled = 0
    colour = raster.rgb("#10301a")
    for i, j in zip(ii.tolist(), jj.tolist()):
        x, z = grid.centre(i, j)
        if not (view[0, 0] <= x <= view[1, 0] and view[0, 1] <= z <= view[1, 1]):
            continue
        r = f"{grid.row_index[0, i, j]}/{grid.row_total[0, i, j]}"
        c = f"{grid.col_index[0, i, j]}/{grid.col_total[0, i, j]}"
        lines = {"rows": [r], "cols": [c], "both": [r, c]}[annotate]
        px, py = panel.px(np.array([x, z]))
        for n, s in enumerate(lines):
            raster.text(panel.draw, (px, py + (n - (len(lines) - 1) / 2) * 0.95 * size), s, size, fill=colour,
                        anchor="mm")
        labelled += 1
    return labelled


def _walls(panel: raster.Panel, walls: Any, view_span: float, pt: float) -> None:
    """Walls, auxiliary rectangles dashed, and the normals' ticks when few enough to read."""
    from .navgrid import WALL_COLOUR

    colour = raster.rgb(WALL_COLOUR)
    seg = walls.segments
    panel.segments(seg, colour, 1.8 * pt)
    if walls.aux is not None:
        panel.segments(walls.aux, colour, 0.8 * pt, dash=(3.7 * pt, 1.6 * pt))
    if 0 < len(seg) <= 400:
        mid = seg.mean(axis=1)
        panel.segments(np.stack([mid, mid + walls.normals * (0.012 * view_span)], axis=1), colour, 1.0 * pt)


def _spawns(panel: raster.Panel, spawns: Any, view_span: float, pt: float) -> None:
    """Spawn points as stars, with an arrow along their heading when they have one."""
    from .navgrid import SPAWN_COLOUR

    colour = raster.rgb(SPAWN_COLOUR)
    sp = np.asarray(spawns, dtype=np.float64).reshape(len(spawns), -1)
    at = panel.px(sp[:, :2])
    if sp.shape[1] >= 3:
        L = 0.04 * view_span
        tips = panel.px(sp[:, :2] + L * np.column_stack([np.cos(sp[:, 2]), np.sin(sp[:, 2])]))
        shaft = 0.004 * panel.width   # quiver's width: a share of the axes
        for a, b in zip(at, tips):
            raster.arrow(panel.draw, a, b, colour, shaft, 5 * shaft)
    for c in at:
        raster.star(panel.draw, c, 7.0 * pt, colour)


def _keys(walls: Any, quadtree: Any, spawns: Any, annotate: str, labelled: int,
          relief: tuple[float, float] | None, pt: float) -> list:
    """The legend (only what the picture shows)."""
    from .navgrid import QUADTREE_COLOUR, SPAWN_COLOUR, STATE_COLOURS, WALL_COLOUR

    keys = [raster.Key("patch", k, raster.rgb(c)) for k, c in STATE_COLOURS.items()]
    if relief is not None:
        keys[2] = raster.Key("patch", "valid (shade: height)", raster.rgb("#6fb36b"))
    wall = raster.rgb(WALL_COLOUR)
    keys.append(raster.Key("line", "wall (tick: free side)", wall, 1.8 * pt))
    if walls.aux is not None:
        keys.append(raster.Key("line", "auxiliary rectangle", wall, 0.8 * pt, dash=True))
    if quadtree is not None:
        keys.append(raster.Key("line", f"quadtree leaves ({len(quadtree.leaves)}, depth {quadtree.max_depth})",
                               raster.rgb(QUADTREE_COLOUR, 0.7), 1.0))
    if spawns is not None and len(spawns):
        keys.append(raster.Key("star", "spawn point", raster.rgb(SPAWN_COLOUR)))
    if labelled:
        keys.append(raster.Key("text", {"rows": "labels: renglón/total", "cols": "labels: columna/total",
                                        "both": "labels: renglón/total\n            columna/total"}[annotate]))
    return keys


def render_png(grid: Any, walls: Any, fr: Any, *, quadtree: Any, free: np.ndarray | None, spawns: Any,
               annotate: str, title: str | None, dpi: int) -> bytes:
    """navgrid.png's bytes (:func:`tanktool.plots.navgrid.render_navgrid` with fmt "png")."""
    from PIL import Image

    from .navgrid import MIN_LABEL_PT, QUADTREE_COLOUR, HEIGHT_CMAP, _panel_title, level_view, node_states

    L = grid.levels
    W, H = int(round(fr.width_in * dpi)), int(round((fr.height_in + 0.8) * L * dpi))
    img = Image.new("RGB", (W, H), raster.WHITE)
    pt = dpi / 72.0
    view = fr.view
    labelled = 0
    for lv in range(L):
        top = 1.0 - lv / L
        fl, fb, fw, fh = (0.06, top - (0.94 / L), (fr.width_in - 2.6) / fr.width_in * 0.92, 0.86 / L)
        panel = raster.Panel.fit(img, (fl * W, (1 - fb - fh) * H, fw * W, fh * H),
                                 (view[0, 0], view[1, 0], view[0, 1], view[1, 1]))
        g = level_view(grid, lv)
        w = walls.on_level(lv) if getattr(walls, "layered", False) else walls
        mask = free if L == 1 else None
        labelling = annotate != "none" and fr.cell_pt >= MIN_LABEL_PT.get(annotate, 99)
        panel.image(*node_image(g, mask, fr.relief))
        if fr.cell_pt >= 6:   # else node centres and cell edges would turn into a smear
            _cells(panel, g, node_states(g, mask), fr, labelling, pt)
        if quadtree is not None:
            lb = quadtree.box[quadtree.leaves]
            x0, z0, x1, z1 = lb[:, 0, 0], lb[:, 0, 1], lb[:, 1, 0], lb[:, 1, 1]
            corners = [np.column_stack(c) for c in ((x0, z0), (x1, z0), (x1, z1), (x0, z1))]
            sides = np.concatenate([np.stack([corners[k], corners[(k + 1) % 4]], axis=1) for k in range(4)])
            panel.segments(sides, raster.rgb(QUADTREE_COLOUR, 0.55), 0.8 * pt)
        _walls(panel, w, fr.view_span, pt)
        if spawns is not None and len(spawns) and lv == 0:
            _spawns(panel, spawns, fr.view_span, pt)
        if labelling:
            labelled += _labels(panel, g, fr, annotate, pt)
        panel.finish("x [m]", "z [m]", 10 * pt)
        head = f"{title or 'navigation grid'}" + (f", level {lv}" if L > 1 else "")
        lines = _panel_title(g, head, grid if lv == 0 else None).split("\n")
        d = raster.ImageDraw.Draw(img)
        for k, s in enumerate(lines[::-1]):
            raster.text(d, (panel.left + panel.width / 2, panel.top - 6 * pt - k * 14 * pt), s, 10 * pt, anchor="md")
    keys = _keys(walls, quadtree, spawns, annotate, labelled, fr.relief, pt)
    kw, _ = raster.legend_size(keys, 8 * pt)
    raster.legend(img, (0.995 * W - kw, 0.07 * H), keys, 8 * pt)
    if fr.relief is not None:
        box = (int(0.90 * W), int(round((1 - 0.08 - 0.25) * H)), max(8, int(0.015 * W)), int(0.25 * H))
        table = (lut_float(HEIGHT_CMAP) * 255).astype(np.uint8)
        raster.colour_bar(img, box, table, fr.relief[0], max(fr.relief[1], fr.relief[0] + 1e-6), "surface y [m]",
                          10 * pt)
    return raster.png_bytes(img)
