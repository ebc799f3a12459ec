"""The grid's memory-bounded paths give the same results as the whole-array ones."""

from __future__ import annotations

import numpy as np
import pytest

from tanktool.nav import navgrid


@pytest.mark.parametrize("seed", range(4))
def test_runs_in_blocks_of_rows_are_the_runs_of_the_whole_grid(seed, monkeypatch):
    rng = np.random.default_rng(seed)
    L, nz, nx = int(rng.integers(1, 4)), int(rng.integers(5, 60)), int(rng.integers(5, 70))
    valid = rng.random((L, nz, nx)) < 0.75
    link = rng.integers(-1, L, size=(L, nz, nx, 4)).astype(np.int8)
    from tanktool.geometry.kernels import use_kernels

    with use_kernels(False):  # the numpy code's blocks (the compiled runs go a line at a time)
        whole = navgrid.layered_runs(valid, link)
        for block in (1, 7, nx + 3, 3 * nx):  # one row a block, a row per block, several rows, uneven ends
            monkeypatch.setattr(navgrid, "RUN_BLOCK", block)
            for a, b in zip(navgrid.layered_runs(valid, link), whole):
                assert a.dtype == b.dtype
                np.testing.assert_array_equal(a, b)
    assert whole[1].max() > 1  # runs longer than one node were found


def test_a_grid_image_samples_every_kth_cell_beyond_the_picture_size():
    from tanktool.plots.arena import MAX_IMAGE_SIDE, image_step

    step, extent = image_step((10, 20), np.array([-1.0, 2.0]), 0.5)
    assert step == 1 and extent == (-1.0, 9.0, 2.0, 7.0)  # small grids: every cell, the grid's own extent
    n = 2 * MAX_IMAGE_SIDE + 1
    step, extent = image_step((7, n), np.array([0.0, 0.0]), 0.5)
    assert step == 3 and -(-n // step) <= MAX_IMAGE_SIDE
    assert extent[1] >= n * 0.5 and extent[1] - n * 0.5 < step * 0.5  # covers the grid, less than a sample over


@pytest.mark.skipif(not __import__("tanktool.geometry.kernels", fromlist=["x"]).available(),
                    reason="the compiled kernels are not built")
@pytest.mark.parametrize("seed", range(4))
def test_a_levels_regions_are_labelled_alike_compiled_and_by_scipy(seed):
    from tanktool.geometry.kernels import use_kernels
    from tanktool.nav.level_walls import _region_labels

    rng = np.random.default_rng(200 + seed)
    nz, nx = int(rng.integers(3, 50)), int(rng.integers(3, 60))
    cells = rng.random((nz, nx)) < 0.7
    same = rng.random((nz, nx, 4)) < 0.6
    same[:, -1, 0] = same[-1, :, 1] = same[:, 0, 2] = same[0, :, 3] = False  # no link off the grid
    with use_kernels(True):
        a, na = _region_labels(cells, same)
    with use_kernels(False):
        b, nb = _region_labels(cells, same)
    assert na == nb > 1
    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("name", ["bridge", "two_storeys", "rolling_terrain"])
def test_same_level_links_from_the_table_are_the_per_direction_ones(name):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))
    import make_levels

    from tanktool.nav.level_walls import _same_level_links, surface_link_level
    from tanktool.nav.walkable import WalkableParams, surface_layers, walkable_surface

    mesh = make_levels.level(name)
    s = walkable_surface(np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64),
                         WalkableParams(0.3, 0.2, 45.0, 0.9, 2.0), 0.6)
    exists, _, _, span_of = surface_layers(s, clearance=False)
    lev = np.arange(exists.shape[0])[:, None, None]
    want = np.stack([surface_link_level(s, span_of, d) == lev for d in range(4)], axis=-1) & exists[..., None]
    np.testing.assert_array_equal(_same_level_links(s, span_of, exists), want)
    assert want.any()


@pytest.mark.skipif(not __import__("tanktool.geometry.kernels", fromlist=["x"]).available(),
                    reason="the compiled kernels are not built")
@pytest.mark.parametrize("seed", range(4))
def test_compiled_runs_are_numpys(seed):
    from tanktool.geometry.kernels import use_kernels

    rng = np.random.default_rng(300 + seed)
    L, nz, nx = int(rng.integers(1, 4)), int(rng.integers(1, 60)), int(rng.integers(1, 70))
    valid = rng.random((L, nz, nx)) < 0.8
    link = rng.integers(-1, L, size=(L, nz, nx, 4)).astype(np.int8)
    with use_kernels(True):
        a = navgrid.layered_runs(valid, link)
    with use_kernels(False):
        b = navgrid.layered_runs(valid, link)
    for x, y in zip(a, b):
        assert x.dtype == y.dtype == np.int32
        np.testing.assert_array_equal(x, y)
