"""The arena preview (plots/arena.py): the free space filled as one path with its
holes left empty, the walls and their normal ticks drawn as one path each
(bench/preview.py compares the picture and the time with the previous drawing)."""

from __future__ import annotations

import io

import matplotlib
import numpy as np
import shapely

from tanktool.formats.walls_txt import WallList, aux_rectangle
from tanktool.geometry.walls import outline_walls
from tanktool.plots.arena import FREE_COLOUR, fill_region, render_preview

matplotlib.use("Agg", force=False)


def _png_pixels(png: bytes) -> np.ndarray:
    import matplotlib.image

    return (matplotlib.image.imread(io.BytesIO(png), format="png")[..., :3] * 255).round().astype(int)


def _axes_image(draw) -> tuple[np.ndarray, object]:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 2), dpi=50)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(0, 10)
    ax.set_ylim(0, 10)
    ax.axis("off")
    draw(ax)
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return _png_pixels(buf.getvalue()), ax


def _at(img: np.ndarray, x: float, z: float) -> tuple:
    h, w = img.shape[:2]
    return tuple(img[int(round((1 - z / 10) * (h - 1))), int(round(x / 10 * (w - 1)))])


def test_fill_region_leaves_holes_empty_and_fills_an_island_in_a_hole():
    green = tuple(int(round(c * 255)) for c in matplotlib.colors.to_rgb(FREE_COLOUR))
    outer = shapely.Polygon([(1, 1), (9, 1), (9, 9), (1, 9)], [[(3, 3), (3, 7), (7, 7), (7, 3)][::-1]])
    island = shapely.box(4.5, 4.5, 5.5, 5.5)
    # either winding given: the outline and holes are oriented before filling
    geom = shapely.MultiPolygon([shapely.Polygon(outer.exterior.coords[::-1], [outer.interiors[0].coords]), island])
    img, ax = _axes_image(lambda ax: fill_region(ax, geom, FREE_COLOUR))
    assert _at(img, 2, 2) == green                    # the free space
    assert _at(img, 3.8, 5) == (255, 255, 255)        # the hole
    assert _at(img, 5, 5) == green                    # the island standing in it
    assert _at(img, 0.4, 0.4) == (255, 255, 255)      # outside
    assert ax.get_xlim() == (0, 10)                   # the caller's limits are kept
    fill_region(ax, shapely.Polygon(), FREE_COLOUR)   # nothing to draw: no error
    fill_region(ax, None, FREE_COLOUR)


def test_preview_of_a_hall_with_pillars_draws_walls_holes_and_spawns():
    free = shapely.difference(shapely.box(0, 0, 40, 40),
                              shapely.union_all(shapely.buffer(shapely.points([[10, 10], [30, 30], [10, 30]]), 2.0)))
    seg = outline_walls(free, 1e-6)          # free space on their left, as import writes them
    walls = WallList(seg, np.ones(len(seg), np.int8), aux_rectangle(-1, -1, 41, 41))
    png = render_preview(walls, np.array([[20.0, 20.0, 0.0]]), "hall", free, size_px=400)
    img = _png_pixels(png)
    colours = {tuple(c) for c in img.reshape(-1, 3)[::7]}
    green = tuple(int(round(c * 255)) for c in matplotlib.colors.to_rgb(FREE_COLOUR))
    assert green in colours                                            # the free space
    dark = (img.sum(axis=-1) < 200).mean()
    assert 0.002 < dark < 0.2                                          # walls (and text) drawn, not a blot
    red = ((img[..., 0] > 150) & (img[..., 1] < 110) & (img[..., 2] < 90)).sum()
    assert red >= 10                                                   # the normals' ticks


def test_the_levels_picture_reuses_the_reports_masks_and_has_no_empty_bands(monkeypatch):
    """The picture paints what the report left out from the same masks (worked out once
    per surface), and its panels fill the figure: a two-level arena's PNG is as tall as
    its two panels side by side need, not the old fixed height with white above and below."""
    import sys
    from pathlib import Path

    import tanktool.nav.surface_report as sr
    from tanktool.fleet import Fleet
    from tanktool.nav.arena_levels import analyse_arena
    from tanktool.nav.walkable import WalkableParams
    from tanktool.plots.arena import _LevelsLayout, render_levels

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))
    import make_levels

    calls = {"unreachable": 0, "low_headroom": 0}
    for name in calls:
        work = getattr(sr, "_" + name)

        def counted(*a, _work=work, _name=name):
            calls[_name] += 1
            return _work(*a)
        monkeypatch.setattr(sr, "_" + name, counted)
    m = make_levels.level("bridge")
    r = analyse_arena(np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64),
                      WalkableParams(cell=0.5, cell_height=0.1, max_slope=35.0, climb=0.9, headroom=2.35),
                      Fleet(radius=3.0, length=6.0, height=2.3))
    assert len(r.levels) == 2
    png = render_levels(r, "bridge", size_px=800)
    assert calls == {"unreachable": 1, "low_headroom": 1}
    h, w = _png_pixels(png).shape[:2]
    (x0, z0), (x1, z1) = r.walls.walls.bounds
    layout = _LevelsLayout.of(2, (z1 - z0) / (x1 - x0), bar=True)
    assert w == 800 and abs(h - 800 * layout.height / layout.width) <= 1
    # the last row of the picture is no more than the legend's band below the panels: not white for a tenth of it
    pixels = _png_pixels(png)
    drawn_rows = np.flatnonzero((pixels < 250).any(axis=(1, 2)))
    assert drawn_rows.max() >= 0.8 * h and drawn_rows.min() <= 0.1 * h
