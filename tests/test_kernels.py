"""The compiled kernels (tanktool/_kernels.c) against the numpy code they replace:
identical heightfields, links, clearances and grids on generated levels and on
Recast's dungeon, and on random span graphs."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from tanktool.geometry import kernels
from tanktool.geometry.kernels import use_kernels
from tanktool.nav.walkable import (WalkableParams, chamfer_clearance, components, grid_from_surface, link_spans,
                                   walkable_surface)

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))

needs_kernels = pytest.mark.skipif(not kernels.available(), reason="tanktool._kernels not built (no C compiler)")
PARAMS = WalkableParams(0.3, 0.2, 45.0, 0.9, 2.0)


def _build(V, F, on: bool):
    with use_kernels(on):
        s = walkable_surface(V, F, PARAMS, 0.6)
        g = grid_from_surface(s, 0.6, s.hf.origin[[0, 2]])
    return s, g


def _levels():
    import make_levels
    import trimesh

    out = [(n, make_levels.level(n)) for n in ("rolling_terrain", "bridge", "two_storeys", "ramps_and_decks")]
    d = trimesh.load(ROOT / "tests" / "data" / "arenas_obj" / "dungeon.obj", force="mesh", process=False)
    out.append(("dungeon", d))
    return [(n, np.asarray(m.vertices, np.float64), np.asarray(m.faces, np.int64)) for n, m in out]


@needs_kernels
@pytest.mark.parametrize("name,V,F", [pytest.param(*lv, id=lv[0]) for lv in _levels()])
def test_compiled_and_numpy_surfaces_are_identical(name, V, F):
    a, ga = _build(V, F, True)
    b, gb = _build(V, F, False)
    assert a.hf.walkable.sum() > 100
    for key in ("walkable", "smin", "smax", "col", "flat", "low_headroom"):
        assert np.array_equal(getattr(a.hf, key), getattr(b.hf, key)), key
    assert a.hf.counts == b.hf.counts
    for key in ("col", "floor", "ceil", "link", "clearance", "region", "main", "level", "height"):
        assert np.array_equal(getattr(a, key), getattr(b, key)), key
    for key in ("valid", "row_index", "row_total", "col_index", "col_total", "reachable", "link"):
        assert np.array_equal(getattr(ga, key), getattr(gb, key)), key
    assert np.array_equal(ga.height, gb.height, equal_nan=True)


def _random_spans(rng, nz=23, nx=31):
    """Columns of 0-3 spans with random floors and ceilings (sorted per column)."""
    counts = rng.integers(0, 4, nz * nx)
    col = np.repeat(np.arange(nz * nx), counts)
    floor = rng.integers(0, 40, len(col))
    order = np.lexsort((floor, col))
    col, floor = col[order], floor[order]
    ceil = floor + rng.integers(3, 30, len(col))
    return col, floor, ceil, (nz, nx)


@needs_kernels
@pytest.mark.parametrize("seed", range(6))
def test_random_span_graphs_give_the_same_links_and_distances(seed):
    rng = np.random.default_rng(seed)
    col, floor, ceil, shape = _random_spans(rng)
    with use_kernels(True):
        la = link_spans(col, floor, ceil, shape, 5, 4)
    with use_kernels(False):
        lb = link_spans(col, floor, ceil, shape, 5, 4)
    assert np.array_equal(la, lb) and (la >= 0).sum() > 100
    for limit in (3, 8, 40):
        with use_kernels(True):
            da = chamfer_clearance(la, limit)
            assert np.array_equal(chamfer_clearance(la.astype(np.int64), limit), da)   # int64 links alike
        with use_kernels(False):
            db = chamfer_clearance(la, limit)
        assert np.array_equal(da, db), limit
    from tanktool.nav.surface_report import _distance_from

    for limit, share in ((3, 0.5), (14, 0.2), (40, 0.02)):
        sources = rng.random(len(la)) < share
        with use_kernels(True):
            ra = _distance_from(sources, la, limit)
        with use_kernels(False):
            rb = _distance_from(sources, la, limit)
        assert np.array_equal(ra, rb) and (ra == limit).any() and ((ra > 0) & (ra < limit)).any(), limit
    with use_kernels(True):
        ca = components(la)
    with use_kernels(False):
        cb = components(la)
    assert np.array_equal(ca, cb) and len(np.unique(ca)) > 10


def test_the_numpy_fallback_runs_without_the_kernels():
    with use_kernels(False):
        assert kernels.active() is None
        col, floor, ceil, shape = _random_spans(np.random.default_rng(9))
        link = link_spans(col, floor, ceil, shape, 5, 4)
        d = chamfer_clearance(link, 12)
    assert d.min() >= 1 and d.max() <= 12


@needs_kernels
@pytest.mark.parametrize("seed", range(4))
def test_a_random_triangle_soup_cropped_by_the_grid_rasterises_the_same(seed):
    """Triangles of every slope and size, some beyond the grid's edges (a grid given by
    origin and shape smaller than the soup), some flat in z or in y."""
    from tanktool.geometry.heightfield import build_heightfield

    rng = np.random.default_rng(seed)
    n = 400
    centre = rng.uniform(-5, 25, (n, 1, 3))
    tri = centre + rng.normal(0, 1.5, (n, 3, 3)) * rng.uniform(0.05, 2.0, (n, 1, 1))
    tri[: n // 8, :, 1] = tri[: n // 8, :1, 1]            # horizontal
    tri[n // 8: n // 4, :, 2] = tri[n // 8: n // 4, :1, 2]  # in one z line
    V = tri.reshape(-1, 3)
    F = np.arange(len(V)).reshape(-1, 3)
    for cell in (0.3, 0.5):
        with use_kernels(True):
            a = build_heightfield(V, F, cell, 0.1, 40.0, 2.0, 0.9, origin_xz=(0.0, 0.0), shape=(50, 60))
        with use_kernels(False):
            b = build_heightfield(V, F, cell, 0.1, 40.0, 2.0, 0.9, origin_xz=(0.0, 0.0), shape=(50, 60))
        assert len(a.col) > 1000 and a.counts == b.counts
        for key in ("col", "smin", "smax", "walkable", "flat", "top_walkable"):
            assert np.array_equal(getattr(a, key), getattr(b, key)), key


@needs_kernels
@pytest.mark.parametrize("seed", range(6))
def test_random_layered_grids_reach_the_same_nodes(seed):
    """navgrid.layered_reachable: the grid's union-find (grid_labels) and numpy + scipy's
    components keep the same nodes, links to invalid nodes, off the grid and to other
    levels included."""
    from tanktool.nav.navgrid import layered_reachable

    rng = np.random.default_rng(seed)
    L, nz, nx = int(rng.integers(1, 4)), int(rng.integers(1, 30)), int(rng.integers(1, 40))
    valid = rng.random((L, nz, nx)) < 0.7
    link = rng.integers(-1, L, size=(L, nz, nx, 4)).astype(np.int8)
    link[rng.random(link.shape) < 0.3] = -1
    nodes = np.argwhere(valid)
    seeds = [tuple(int(v) for v in nodes[k]) for k in rng.choice(len(nodes), size=min(3, len(nodes)), replace=False)]
    with use_kernels(True):
        a = layered_reachable(valid, link, seeds)
    with use_kernels(False):
        b = layered_reachable(valid, link, seeds)
    assert a.dtype == b.dtype == bool and a.any()
    np.testing.assert_array_equal(a, b)


@needs_kernels
@pytest.mark.parametrize("seed", range(6))
def test_random_layered_grids_have_the_same_components(seed):
    """arena_levels.grid_components: the compiled labels are scipy's, numbered alike."""
    from tanktool.nav.arena_levels import grid_components
    from tanktool.nav.navgrid import NavGrid

    rng = np.random.default_rng(100 + seed)
    L, nz, nx = int(rng.integers(1, 4)), int(rng.integers(2, 30)), int(rng.integers(2, 40))
    valid = rng.random((L, nz, nx)) < 0.6
    link = rng.integers(-1, L, size=(L, nz, nx, 4)).astype(np.int8)
    link[rng.random(link.shape) < 0.4] = -1
    link[:, :, -1, 0] = link[:, -1, :, 1] = link[:, :, 0, 2] = link[:, 0, :, 3] = -1  # no step off the grid
    grid = NavGrid(np.zeros(2), 1.0, (nz, nx), valid, *(np.zeros((L, nz, nx), dtype=np.int32) for _ in range(4)),
                   valid.copy(), 1.0, link=link)
    with use_kernels(True):
        a, ka = grid_components(grid)
    with use_kernels(False):
        b, kb = grid_components(grid)
    assert ka == kb > 1
    np.testing.assert_array_equal(a, b)


@needs_kernels
@pytest.mark.parametrize("seed", range(5))
def test_random_flat_cells_find_the_same_floors(seed):
    # level_walls._flat_floor_of: heights on a floor, a rounding above it, within and
    # past a cell height, below every floor; the kernel's one pass and numpy's blocks
    from tanktool.nav.level_walls import _flat_floor_of

    rng = np.random.default_rng(seed)
    floors = np.sort(rng.choice(np.arange(-20, 40) * 0.35, size=8, replace=False))
    n_spans = 5000
    base = floors[rng.integers(0, len(floors), n_spans)]
    span_y = base + rng.choice([0.0, 1e-7, 0.05, 0.1, 0.1 + 2e-6, 0.3, -0.2], n_spans)
    span_y[:50] = floors[0] - 1.0
    flat_cells = rng.random((60, 70)) < 0.6
    span_of = np.where(flat_cells, rng.integers(0, n_spans, (60, 70)), -1).astype(np.int32)
    out = {}
    for on in (True, False):
        with use_kernels(on):
            out[on] = _flat_floor_of(flat_cells, span_of, span_y, floors, 0.1)
    for a, b in zip(out[True], out[False]):
        assert a.dtype == b.dtype and np.array_equal(a, b)
    assert (out[True][1] == -1).any() and (out[True][1] >= 0).any()
