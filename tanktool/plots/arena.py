"""Top view of an arena: walls with their normals, the auxiliary rectangle, spawns.

preview.png (:func:`render_levels`) is drawn with Pillow (plots/raster.py), imported
inside the functions, so importing this module costs little and works without a display.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from .colourmaps import lut


#: the free space's fill, the walls, their normals' ticks
FREE_COLOUR = "#e8efe6"
#: a grid image has at most this many samples a side: more than a panel has pixels (so
#: the picture looks the same), while matplotlib's copies of a 4000 x 4000 grid (float
#: RGBA at several stages) took gigabytes on a 2 km terrain
MAX_IMAGE_SIDE = 1200
WALL_COLOUR = "#202020"
NORMAL_COLOUR = "#d04020"

#: colours of what the walkable surface left out
LEFT_OUT_COLOURS = {"unreachable": "#9a9a9a", "headroom": "#f0a030", "small": "#b060c0", "steep": "#d03030"}


@dataclass(frozen=True)
class _LevelsLayout:
    """Where :func:`render_levels` puts its panels, in inches: laid out by hand from the
    arena's aspect so the figure has no empty bands (a subplot grid with equal-aspect
    panels leaves them, and a tight save costs a second draw)."""

    cols: int
    rows: int
    panel_w: float
    panel_h: float
    bar: bool                       # a colour bar of heights on the right (not on a flat arena)
    LEFT: ClassVar[float] = 0.8     # the z ticks and label
    GAP_X: ClassVar[float] = 0.9
    BELOW: ClassVar[float] = 1.15   # the x ticks and label, and the left-out legend under the first panel
    TOP: ClassVar[float] = 0.75     # the title (two lines on one level)
    RIGHT: ClassVar[float] = 1.3    # the colour bar and its label (0.3 without)

    @classmethod
    def of(cls, levels: int, aspect: float, bar: bool) -> "_LevelsLayout":
        cols = 1 if levels == 1 else 2
        panel_w = 9.0 if cols == 1 else 6.0
        # a very long or very tall arena keeps a readable panel: the axes shrink inside it
        return cls(cols, (levels + cols - 1) // cols, panel_w, float(np.clip(panel_w * aspect, 1.2, 12.0)), bar)

    @property
    def panels_right(self) -> float:
        """The right edge of the last column of panels."""
        return self.LEFT + self.cols * self.panel_w + (self.cols - 1) * self.GAP_X

    @property
    def width(self) -> float:
        return self.panels_right + (self.RIGHT if self.bar else 0.3)

    @property
    def top(self) -> float:
        """Above the first row: its titles, and the figure's title when there are two panels or more."""
        return self.TOP + (0.3 if self.rows * self.cols > 1 else 0.0)

    @property
    def height(self) -> float:
        return self.top + self.rows * (self.panel_h + self.BELOW)

    def panel(self, i: int) -> tuple[float, float, float, float]:
        """Level ``i``'s axes as a figure fraction (left, bottom, width, height)."""
        r, c = divmod(i, self.cols)
        x = self.LEFT + c * (self.panel_w + self.GAP_X)
        y = self.height - self.top - (r + 1) * self.panel_h - r * self.BELOW
        return (x / self.width, y / self.height, self.panel_w / self.width, self.panel_h / self.height)

    def colour_bar(self) -> tuple[float, float, float, float]:
        """The colour bar's axes beside the panels, as a figure fraction."""
        x = self.panels_right + 0.3
        return (x / self.width, self.BELOW / self.height, 0.22 / self.width,
                (self.height - self.BELOW - self.top) / self.height)


def render_levels(result: Any, title: str, size_px: int = 1100) -> bytes:
    """PNG bytes of an arena's levels: a panel per level (one on a one-level arena),
    walkable cells coloured by height (a flat floor in light green), that level's walls
    with their normals and its spawns; the first panel also shows what was left out
    (unreachable surfaces, too little headroom, too small for a tank, too steep faces),
    with a legend of their areas.  Drawn with Pillow (plots/raster.py), no matplotlib."""
    from PIL import Image, ImageDraw

    from ..nav.walkable import surface_layers
    from . import raster

    surface = result.surface
    hf = surface.hf
    walls = result.walls.walls
    (xmin, zmin), (xmax, zmax) = walls.bounds
    L = max(len(result.levels), 1)
    w = max(xmax - xmin, 1e-6)
    h = max(zmax - zmin, 1e-6)
    exists, height = _played_layers(result, surface_layers)
    step, extent = image_step(hf.shape, hf.origin[[0, 2]], hf.cs)
    ys = height[exists]
    lo, hi = (float(ys.min()), float(ys.max())) if len(ys) else (0.0, 1.0)
    flat = hi - lo <= 2 * hf.ch
    layout = _LevelsLayout.of(L, h / w, bar=not flat)
    dpi = size_px / layout.width
    W, H = size_px, int(round(layout.height * dpi))
    img = Image.new("RGB", (W, H), raster.WHITE)
    pt = dpi / 72.0   # pixels a point, the sizes matplotlib drew with
    pad = 0.03 * max(w, h)
    view = (xmin - pad, xmax + pad, zmin - pad, zmax + pad)
    hi = max(hi, lo + 1e-6)
    for lv in range(L):
        fl, fb, fw, fh = layout.panel(lv)
        panel = raster.Panel.fit(img, (fl * W, (1 - fb - fh) * H, fw * W, fh * H), view)
        if flat:
            fill_free(panel, result.walls.free(lv), raster.rgb(FREE_COLOUR))
        which, colours, keys, steep = _left_out_layers(result, hf, surface, step) if lv == 0 else (None, [], [], [])
        if not flat:   # the heights with what was left out over them: one lookup, one image
            hidx = height_index(exists[lv, ::step, ::step], height[lv, ::step, ::step], lo, hi)
            panel.image(compose(hidx, which, colours), extent)
        elif colours:
            panel.image(overlay(which, colours), extent)
        if len(steep):
            panel.mask_fill(steep, raster.rgb(LEFT_OUT_COLOURS["steep"]), 0.6)
        ticks = panel.ticks(10 * pt)
        panel.grid_lines(*ticks)
        _walls_and_spawns(panel, result, lv, 0.012 * max(w, h), 0.03 * max(w, h), pt)
        panel.finish("x (m)", "z (m)", 10 * pt, ticks)
        info = result.levels[lv] if lv < len(result.levels) else None
        sub = f"level {lv}" + (f": {info.area:,.0f} m^2, y {info.y_lo:.2f}..{info.y_hi:.2f}" if info else "")
        lines = [sub] if L > 1 else [title, sub]
        d = ImageDraw.Draw(img)
        for k, s in enumerate(lines[::-1]):
            raster.text(d, (panel.left + panel.width / 2, panel.top - 6 * pt - k * 12 * pt), s, 9 * pt, anchor="md")
        if keys:   # below the panel, past the ticks and the x label, where it hides no spawn or wall
            kw, _ = raster.legend_size(keys, 7.5 * pt, cols=2)
            raster.legend(img, (panel.left + panel.width / 2 - kw / 2, panel.top + panel.height + 30 * pt), keys,
                          7.5 * pt, cols=2, frame=True)
    if not flat:
        bl, bb, bw, bh = layout.colour_bar()
        box = (int(round(bl * W)), int(round((1 - bb - bh) * H)), int(round(bw * W)), int(round(bh * H)))
        raster.colour_bar(img, box, lut("viridis"), lo, hi, "surface height y (m)", 10 * pt)
    if L > 1:
        raster.text(ImageDraw.Draw(img), (W / 2, 0.2 * dpi), title, 10 * pt, anchor="ma")
    return raster.png_bytes(img)


def fill_free(panel: Any, geom: Any, colour: tuple[int, ...]) -> None:
    """Fill a shapely (Multi)Polygon on a raster panel, its holes left as they were:
    parts from the largest down, each outline filled and then its holes in white, so an
    island standing in a hole (a smaller part) is filled again after the hole."""
    import shapely

    from .raster import WHITE

    if geom is None or geom.is_empty:
        return
    polys = [p for p in shapely.get_parts(geom) if p.geom_type == "Polygon" and not p.is_empty]
    for p in sorted(polys, key=lambda q: -q.area):
        panel.polygons([shapely.get_coordinates(p.exterior)], colour)
        panel.polygons([shapely.get_coordinates(r) for r in p.interiors], WHITE)


def _played_layers(result: Any, surface_layers: Any) -> tuple[np.ndarray, np.ndarray]:
    """(exists, height) (L, nz, nx) of the played region: the tank grid's heights when it
    has them (grid_from_surface scattered these very layers; a node where the height is
    finite), else surface_layers' (not its span indices)."""
    s, g = result.surface, result.grid
    if g is not None and g.height is not None and g.height.shape == (max(s.levels, 1), *s.hf.shape):
        return np.isfinite(g.height), g.height
    return surface_layers(s, clearance=False)[:2]


def _walls_and_spawns(panel: Any, result: Any, lv: int, tick: float, arrow: float, pt: float) -> None:
    """Level ``lv``'s walls with their normals' ticks (``tick`` m), the auxiliary
    rectangle dashed, and its spawns as numbered arrows ``arrow`` m long."""
    from . import raster

    walls = result.walls.walls
    sel = walls.level == lv
    seg = walls.segments[sel]
    if walls.aux is not None:
        panel.segments(walls.aux, raster.rgb("#4060c0"), 0.9 * pt, dash=(3.7 * pt, 1.6 * pt))
    panel.segments(seg, raster.rgb(WALL_COLOUR), 1.2 * pt)
    if len(seg):
        mid = seg.mean(axis=1)
        panel.segments(np.stack([mid, mid + walls.normals[sel] * tick], axis=1), raster.rgb(NORMAL_COLOUR), 0.72 * pt)
    spawns = np.asarray(result.spawns, dtype=np.float64)
    green = raster.rgb("#1a7a1a")
    for k in np.flatnonzero(_spawns_on_level(result, lv)):
        x, z, th = spawns[k, :3]
        u = np.array([np.cos(th), np.sin(th)])
        a, b, n = panel.px(np.array([[x, z], [x + arrow * u[0], z + arrow * u[1]],
                                     [x - 0.45 * arrow * u[0], z - 0.45 * arrow * u[1]]]))
        raster.arrow(panel.draw, a, b, green, 1.5 * pt, 6 * pt, halo=1.0 * pt)
        r = 2.5 * pt
        panel.draw.ellipse((a[0] - r, a[1] - r, a[0] + r, a[1] + r), fill=green, outline=raster.WHITE, width=1)
        raster.text(panel.draw, tuple(n), str(k + 1), 8 * pt, fill=green, anchor="mm", bold=True,
                    halo=max(1, int(round(1.2 * pt))))


def image_step(shape: tuple[int, int], origin: np.ndarray, cell: float) -> tuple[int, tuple[float, ...]]:
    """(step, extent) of a grid's image: every step-th cell each way (1 up to
    MAX_IMAGE_SIDE cells a side), and the (x0, x1, z0, z1) those samples cover, each
    drawn step cells wide."""
    nz, nx = shape
    step = max(1, -(-max(nz, nx) // MAX_IMAGE_SIDE))
    w = step * float(cell)
    return step, (float(origin[0]), float(origin[0]) + -(-nx // step) * w,
                  float(origin[1]), float(origin[1]) + -(-nz // step) * w)


def _spawns_on_level(result: Any, level: int) -> np.ndarray:
    """Which spawns stand on ``level`` (by the tank grid's node under them)."""
    sp = np.asarray(result.spawns, dtype=np.float64)
    if len(sp) == 0:
        return np.zeros(0, dtype=bool)
    grid = result.grid
    if grid.levels == 1:
        return np.full(len(sp), level == 0)
    node = grid.nodes_of(sp[:, :2])
    hts = grid.heights()[:, node[:, 0], node[:, 1]]  # (L, k)
    y = sp[:, 3]
    best = np.nanargmin(np.where(np.isfinite(hts), np.abs(hts - y[None]), np.inf), axis=0)
    return best == level


def _left_out_layers(result: Any, hf: Any, surface: Any, step: int) -> tuple[np.ndarray, list, list, list]:
    """What the surface left out, for the first panel: (which: the sampled cells' 1 +
    colour index, 0 none, every ``step``-th cell as the image samples them; their
    colours; the legend's keys; the too steep faces' triangles (k, 3, 2) in x, z)."""
    from ..nav.surface_report import low_headroom, steep_faces, too_small, unreachable
    from .raster import Key, rgb

    nz, nx = hf.shape
    keys = []
    which = np.zeros((-(-nz // step), -(-nx // step)), dtype=np.int8)
    colours: list[tuple[float, ...]] = []

    def paint(cols, colour, label, area):
        if len(cols) == 0:
            return
        # the cells the image samples: a mask of every column, sliced as the image is
        # (a scatter, where dividing each column's index by nx and step cost hix ~25 ms)
        mask = np.zeros(nz * nx, dtype=bool)
        mask[cols] = True
        colours.append(matplotlib_rgba(colour))
        which[mask.reshape(nz, nx)[::step, ::step]] = len(colours)
        keys.append(Key("patch", f"{label}: {area:,.0f} m^2", rgb(colour)))

    cell2 = hf.cs ** 2
    other = unreachable(surface, result.grid.clearance, result.vertices, result.faces)
    paint(surface.col[other], LEFT_OUT_COLOURS["unreachable"], "unreachable", other.sum() * cell2)
    low = low_headroom(surface, result.vertices, result.faces)
    paint(hf.col[low], LEFT_OUT_COLOURS["headroom"], "too little headroom", low.sum() * cell2)
    small = too_small(surface, result.grid.clearance)
    paint(surface.col[small], LEFT_OUT_COLOURS["small"], "too small for a tank", small.sum() * cell2)
    if not any(x.reason.startswith("too steep") for x in result.left_out) or result.vertices is None:
        return which, colours, keys, []
    vertices = result.vertices
    sel, area = steep_faces(vertices, result.faces, result.params.max_slope)
    keys.append(Key("patch", f"too steep: {area.sum():,.0f} m^2", rgb(LEFT_OUT_COLOURS["steep"])))
    return which, colours, keys, list(vertices[result.faces[sel]][:, :, [0, 2]])


def height_index(exists: np.ndarray, height: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Each sample's entry of viridis from ``lo`` to ``hi`` (a value x is entry int(x *
    256), as matplotlib looks it up), 256 where there is no surface."""
    x = np.where(exists, height, lo)
    x -= lo
    x *= 256.0 / (hi - lo)
    idx = x.astype(np.intp)
    np.clip(idx, 0, 255, out=idx)
    idx[~exists] = 256
    return idx


def _height_table() -> np.ndarray:
    """(257, 4) RGBA bytes: viridis' 256 entries, then clear."""
    table = np.zeros((257, 4), dtype=np.uint8)
    table[:256, :3] = lut("viridis")
    table[:256, 3] = 255
    return table


def height_image(exists: np.ndarray, height: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """(nz, nx, 4) RGBA bytes of the heights through viridis, clear where there is no surface."""
    return _height_table()[height_index(exists, height, lo, hi)]


#: the left-out cells' opacity over the heights
LEFT_OUT_ALPHA = 0.75


def compose(hidx: np.ndarray, which: np.ndarray | None, colours: list) -> np.ndarray:
    """RGBA bytes of the heights (``hidx``: :func:`height_index`) with the left-out
    cells (``which``) over them at LEFT_OUT_ALPHA, by one lookup in a table of every
    (left-out colour, height entry) pair blended once: a*c + (1 - a)*under on a height,
    c at alpha a where there is none.  (Composing two images of ~1M samples cost hix ~20 ms.)"""
    base = _height_table()
    if which is None or not colours:
        return base[hidx]
    under = base[:256, :3] / 255.0
    parts = [base]
    for c in colours:
        part = np.empty((257, 4))
        part[:256, :3] = LEFT_OUT_ALPHA * np.asarray(c[:3]) + (1 - LEFT_OUT_ALPHA) * under
        part[:256, 3] = 1.0
        part[256] = (*c[:3], LEFT_OUT_ALPHA)
        parts.append((part * 255).astype(np.uint8))
    idx = which.astype(np.intp)
    idx *= 257
    idx += hidx
    return np.concatenate(parts)[idx]


def overlay(which: np.ndarray, colours: list) -> np.ndarray:
    """RGBA bytes of the left-out cells (``which``: 1 + their colour's index, 0 none)
    at LEFT_OUT_ALPHA, to draw over a flat level's panel."""
    table = np.array([(0.0, 0.0, 0.0, 0.0)] + [(*c[:3], LEFT_OUT_ALPHA) for c in colours])
    return (table * 255).astype(np.uint8)[which]


def matplotlib_rgba(colour: str) -> tuple[float, float, float, float]:
    """``"#rrggbb"`` as matplotlib's RGBA floats (alpha 1)."""
    from .raster import rgb

    r, g, b = rgb(colour)[:3]
    return (r / 255.0, g / 255.0, b / 255.0, 1.0)
