"""The Pillow drawing of the import's pictures (plots/raster.py, plots/colourmaps.py,
plots/navgrid_png.py): ticks, the PNG writer, a panel's images and fills, the colour
tables against matplotlib's, navgrid.png's sampled node states."""

from __future__ import annotations

import io

import numpy as np
import pytest
import shapely
from PIL import Image

from tanktool.plots import raster
from tanktool.plots.arena import FREE_COLOUR, compose, fill_free, height_image, overlay
from tanktool.plots.colourmaps import apply, lut


def _pixels(png: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))


def test_nice_ticks_and_their_labels():
    assert raster.nice_ticks(0, 100, 9).tolist() == [0, 20, 40, 60, 80, 100]
    assert raster.nice_ticks(-412, 412, 9).tolist() == [-400, -300, -200, -100, 0, 100, 200, 300, 400]
    t = raster.nice_ticks(0.0, 1.0, 4)
    assert t.tolist() == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert [raster.tick_label(v, t) for v in t] == ["0.00", "0.25", "0.50", "0.75", "1.00"]
    assert raster.tick_label(-200.0, np.array([-200.0, 0.0])) == "\u2212200"
    assert raster.tick_label(-0.0, np.array([0.0, 1.0])) == "0"
    # nothing to divide: no error, at most the one value
    assert len(raster.nice_ticks(3.0, 3.0, 5)) <= 1
    assert len(raster.nice_ticks(float("nan"), 1.0, 5)) == 0


@pytest.mark.parametrize("shape", [(1, 1), (37, 53), (300, 200)])
def test_png_bytes_round_trip_the_pixels(shape):
    rng = np.random.default_rng(len(shape) + shape[0])
    a = rng.integers(0, 256, (*shape, 3), dtype=np.uint8)
    a[: shape[0] // 2] = 200       # flat rows as well as noise
    png = raster.png_bytes(Image.fromarray(a))
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert np.array_equal(_pixels(png), a)
    assert raster.png_bytes(Image.fromarray(a)) == png     # no metadata: equal drawings, equal files


def test_a_panel_places_an_image_and_cuts_it_to_the_view():
    img = Image.new("RGB", (120, 120), raster.WHITE)
    panel = raster.Panel.fit(img, (10, 10, 100, 100), (0.0, 10.0, 0.0, 10.0))
    assert (panel.width, panel.height) == (100, 100)
    # a 4 x 4 grid over [0, 20] x [0, 20]: only its lower-left quarter is in view
    grid = np.zeros((4, 4, 3), dtype=np.uint8)
    grid[0, 0] = (255, 0, 0)       # row 0 is the bottom (z from 0 to 5), column 0 the left
    grid[1, 1] = (0, 0, 255)
    panel.image(grid, (0.0, 20.0, 0.0, 20.0))
    tile = np.asarray(panel.tile)
    assert tuple(tile[75, 25]) == (255, 0, 0)      # x 2.5, z 2.5: the bottom-left sample
    assert tuple(tile[25, 75]) == (0, 0, 255)      # x 7.5, z 7.5
    assert tuple(tile[25, 25]) == (0, 0, 0)
    panel.finish("x (m)", "z (m)", 10)
    assert tuple(np.asarray(img)[85, 35]) == (255, 0, 0)   # pasted at the panel's corner
    # a zoom on a huge grid resizes only the samples in view
    big = raster.Panel.fit(Image.new("RGB", (50, 50)), (0, 0, 50, 50), (0.0, 1.0, 0.0, 1.0))
    big.image(np.zeros((2000, 2000, 3), dtype=np.uint8), (0.0, 2000.0, 0.0, 2000.0))
    assert np.asarray(big.tile).shape == (50, 50, 3)


def test_fill_free_leaves_holes_empty_and_fills_an_island_in_a_hole():
    green = raster.rgb(FREE_COLOUR)
    outer = shapely.Polygon([(1, 1), (9, 1), (9, 9), (1, 9)], [[(3, 3), (3, 7), (7, 7), (7, 3)][::-1]])
    island = shapely.box(4.5, 4.5, 5.5, 5.5)
    geom = shapely.MultiPolygon([island, shapely.Polygon(outer.exterior.coords[::-1], [outer.interiors[0].coords])])
    panel = raster.Panel.fit(Image.new("RGB", (100, 100)), (0, 0, 100, 100), (0.0, 10.0, 0.0, 10.0))
    fill_free(panel, geom, green)
    tile = np.asarray(panel.tile)

    def at(x, z):
        return tuple(tile[int((10 - z) * 10), int(x * 10)])
    assert at(2, 2) == green and at(5, 5) == green          # the free space, the island
    assert at(3.8, 5) == raster.WHITE and at(0.4, 0.4) == raster.WHITE
    fill_free(panel, shapely.Polygon(), green)               # nothing to draw: no error
    fill_free(panel, None, green)


def test_colour_tables_are_matplotlibs():
    from matplotlib import colormaps

    x = np.linspace(0.0, 1.0, 1001)
    for name in ("viridis", "summer"):
        assert np.array_equal(apply(name, x), colormaps[name](x, bytes=True)[:, :3])
    assert lut("viridis").shape == (256, 3)


def test_the_heights_and_left_out_cells_in_one_lookup_blend_as_drawn_over():
    exists = np.array([[True, True, False]])
    height = np.array([[0.0, 1.0, np.nan]])
    which = np.array([[0, 1, 1]], dtype=np.int8)
    colours = [(1.0, 0.0, 0.0, 1.0)]
    hidx = np.array([[0, 255, 256]])
    out = compose(hidx, which, colours)
    plain = height_image(exists, height, 0.0, 1.0)
    assert tuple(out[0, 0]) == tuple(plain[0, 0])                 # no left-out cell: the height
    blended = (0.75 * np.array([1.0, 0, 0]) + 0.25 * plain[0, 1, :3] / 255.0) * 255
    assert np.abs(out[0, 1, :3].astype(int) - blended.astype(int)).max() <= 1 and out[0, 1, 3] == 255
    assert tuple(out[0, 2]) == (255, 0, 0, 191)                   # over no surface: the colour at 0.75
    assert tuple(overlay(which, colours)[0, 2]) == (255, 0, 0, 191)
    assert tuple(compose(hidx, None, [])[0, 2]) == (0, 0, 0, 0)


def test_navgrids_sampled_states_are_the_states_sliced():
    from tanktool.nav.navgrid import NavGrid
    from tanktool.plots.navgrid import node_states
    from tanktool.plots.navgrid_png import sampled_states

    rng = np.random.default_rng(3)
    shape = (23, 31)
    valid = rng.random((1, *shape)) < 0.5
    reach = rng.random((1, *shape)) < 0.7
    free = rng.random(shape) < 0.6
    z = np.zeros((1, *shape), dtype=np.int32)
    g = NavGrid(np.array([0.0, 0.0]), 0.5, shape, valid, z, z, z, z, reach, 1.0)
    for k in (1, 2, 3):
        for mask in (free, None):
            assert np.array_equal(sampled_states(g, mask, k), node_states(g, mask)[::k, ::k])


def test_segments_are_cut_to_the_tile_before_drawing():
    p = np.array([[[-10, 5], [20, 5]], [[-10, -10], [-5, -5]], [[5, -100], [5, 100]], [[-1e6, 3], [1e6, 3]]], float)
    cut = raster.clip_segments(p, 10, 10)
    assert np.allclose(cut, [[[0, 5], [10, 5]], [[5, 0], [5, 10]], [[0, 3], [10, 3]]], atol=1e-6)
    # a dashed line a million pixels long outside the tile costs nothing (it is dropped first)
    panel = raster.Panel.fit(Image.new("RGB", (50, 50)), (0, 0, 50, 50), (0.0, 1.0, 0.0, 1.0))
    panel.segments(np.array([[[-1e5, -1e5], [1e5, -1e5]]]), raster.BLACK, 1, dash=(3, 2))


def test_a_navgrid_picture_of_a_region_beside_the_grid_is_refused_in_words():
    from tanktool.formats.walls_txt import WallList, aux_rectangle
    from tanktool.nav.navgrid import NavGrid
    from tanktool.plots.navgrid import render_navgrid

    shape = (20, 30)
    v = np.ones((1, *shape), dtype=bool)
    z = np.zeros((1, *shape), dtype=np.int32)
    g = NavGrid(np.array([0.0, 0.0]), 0.5, shape, v, z, z, z, z, v.copy(), 1.0)
    walls = WallList(np.array([[[1.0, 1.0], [5.0, 1.0]]]), np.ones(1, np.int8), aux_rectangle(0, 0, 15, 10))
    with pytest.raises(ValueError, match="no node"):
        render_navgrid(g, walls, region=np.array([[100.0, 100.0], [103.0, 103.0]]))
    assert render_navgrid(g, walls, region=np.array([[1.0, 1.0], [2.0, 2.0]]))[:4] == b"\x89PNG"
