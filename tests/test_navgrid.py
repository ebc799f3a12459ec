import io
from pathlib import Path

import numpy as np
import pytest
import shapely

from tanktool.errors import ArenaError, FormatError
from tanktool.formats.walls_txt import WallList, aux_rectangle, read_walls
from tanktool.geometry.segments import point_segment_dist2
from tanktool.nav.navgrid import (
    MAX_NODES,
    NavGrid,
    build_navgrid,
    classify,
    format_table,
    free_space,
    grid_from_mask,
    grid_shape,
    node_coords,
    open_ends,
    runs,
    too_close,
)
from tanktool.nav.reference2002 import classify_reference
from tanktool.nav.synthetic import assemble, block_maze, box_arena, random_arena, rect

ROOT = Path(__file__).resolve().parent.parent
BUNDLED = sorted(ROOT.glob("arenas/*/walls.txt"))


def _nodes(walls, cell):
    b = walls.bounds
    shape = grid_shape(b, cell)
    xs = node_coords(b[0, 0], cell, shape[1])
    zs = node_coords(b[0, 1], cell, shape[0])
    X, Z = np.meshgrid(xs, zs)
    return b[0], shape, X, Z


def _min_dist2(walls, X, Z):
    P = np.stack([X.ravel(), Z.ravel()], axis=1)
    s = walls.segments
    return point_segment_dist2(P[:, None], s[None, :, 0], s[None, :, 1]).min(axis=1).reshape(X.shape)


# ------------------------------------------------------------- geometry
def test_node_positions_and_lookup():
    g = build_navgrid(box_arena(10, 6, margin=1), cell=0.5, clearance=0.6)
    assert g.shape == (16, 24)  # 8 m x 12 m of auxiliary rectangle at 0.5 m
    assert g.centre(0, 0) == (-0.75, -0.75)
    assert g.centre(3, 5) == (-1 + 5.5 * 0.5, -1 + 3.5 * 0.5)
    for i, j in [(0, 0), (3, 5), (15, 23)]:
        assert g.node_of(*g.centre(i, j)) == (i, j)
    assert g.node_of(-100, 100) == (15, 0)  # clamped
    assert np.array_equal(g.nodes_of(g.centres(np.array([[2, 3], [7, 9]]))), [[2, 3], [7, 9]])
    i, j = 8, 12
    assert set(g.neighbours4(i, j)) == {(8, 13), (9, 12), (8, 11), (7, 12)}
    # next to the wall: the node beyond is invalid, so it is not a neighbour
    row = np.flatnonzero(g.valid[0][8])
    assert (8, row[0] - 1) not in g.neighbours4(8, row[0])


def test_grid_shape_limits():
    with pytest.raises(ArenaError, match="cell must be a positive"):
        grid_shape(np.array([[0, 0], [10, 10.0]]), 0.0)
    with pytest.raises(ArenaError, match="limit"):
        grid_shape(np.array([[0, 0], [1e4, 1e4]]), 1.0)
    assert grid_shape(np.array([[0, 0], [20, 10.0]]), 0.5) == (20, 40)
    assert 1e4 * 1e4 > MAX_NODES


# ------------------------------------------------------------- classifiers
ARENAS = [("box", box_arena()), ("maze", block_maze(4, n=5)), *[(f"random{s}", random_arena(s)) for s in range(4)]]


@pytest.mark.parametrize("name,walls", ARENAS, ids=[a[0] for a in ARENAS])
def test_fast_classifier_equals_2002_reference(name, walls):
    cell = 0.9 if name != "box" else 0.45
    origin, shape, X, Z = _nodes(walls, cell)
    for clearance in (0.0, 0.7):
        fast = classify(walls, origin, cell, shape, clearance)
        ref = classify_reference(walls, origin, cell, shape, clearance)
        assert np.array_equal(fast, ref)
        assert fast.sum() > 0.2 * fast.size


@pytest.mark.parametrize("path", BUNDLED, ids=[p.parent.name for p in BUNDLED])
def test_bundled_arenas_both_classifiers_agree(path):
    walls = read_walls(path)
    if walls.layered:
        # walls in blocks per level open onto each other (a ramp onto a deck): the 2002
        # free-space count is not defined there; the surface decides (tests/test_walkable.py)
        pytest.skip("a layered arena: its walls do not close up")
    span = float(np.max(walls.bounds[1] - walls.bounds[0]))
    cell = span / 60  # a coarse grid: the reference is slow
    origin, shape, X, Z = _nodes(walls, cell)
    fast = classify(walls, origin, cell, shape, 0.5)
    assert np.array_equal(fast, classify_reference(walls, origin, cell, shape, 0.5))


def test_banded_classification_equals_one_pass():
    w = random_arena(11)
    origin, shape, X, Z = _nodes(w, 0.3)
    rows = []
    one = classify(w, origin, 0.3, shape, 0.5)
    banded = classify(w, origin, 0.3, shape, 0.5, progress=rows.append, band_nodes=5000)
    assert np.array_equal(one, banded)
    assert sum(rows) == shape[0] and len(rows) > 3


def _free_polygon(seed):
    """The free space of random_arena(seed) rebuilt independently with shapely."""
    w = random_arena(seed)
    geoms = []
    # walls come loop by loop; a loop closes where a wall ends at its first vertex
    start = 0
    for k in range(len(w.segments)):
        if np.array_equal(w.segments[k, 1], w.segments[start, 0]):
            pts = w.segments[start:k + 1, 0]
            geoms.append((shapely.Polygon(pts), int(w.direction[start])))
            start = k + 1
    free = geoms[0][0]
    obstacles = [g for g, _ in geoms[1:]]
    # random_arena: courtyards follow their obstacle; a polygon inside another is a courtyard
    for k, g in enumerate(obstacles):
        inside_other = any(o.contains(g) for m, o in enumerate(obstacles) if m != k)
        free = free.union(g) if inside_other else free.difference(g)
    return w, free


@pytest.mark.parametrize("seed", [0, 3, 7])
def test_free_space_matches_shapely(seed):
    w, poly = _free_polygon(seed)
    origin, shape, X, Z = _nodes(w, 0.37)
    fast = free_space(w, origin, 0.37, shape)
    inside = shapely.contains_xy(poly, X, Z)
    # compare away from the boundary, where "inside" is unambiguous
    far = np.sqrt(_min_dist2(w, X, Z)) > 1e-6
    assert np.array_equal(fast[far], inside[far])
    assert inside.sum() > 100


def test_clearance_is_exact_distance():
    w = random_arena(4)
    cell, r = 0.31, 1.234
    origin, shape, X, Z = _nodes(w, cell)
    d2 = _min_dist2(w, X, Z)
    assert np.array_equal(too_close(w.segments, origin, cell, shape, r), d2 < r * r)
    g = build_navgrid(w, cell, r)
    assert np.array_equal(g.valid[0], free_space(w, origin, cell, shape) & (d2 >= r * r))
    # nodes exactly at the clearance count as valid: distance >= clearance
    box = box_arena(10, 10, margin=1)
    g = build_navgrid(box, cell=0.5, clearance=0.75)
    i = g.shape[0] // 2
    xs = g.node_x[g.valid[0][i]]
    assert xs.min() == pytest.approx(0.75) and xs.max() == pytest.approx(9.25)


def test_shared_edges_cancel_and_courtyards_are_free():
    # two touching squares in a room: one solid; a courtyard inside a third block
    loops = [
        (rect(0, 0, 30, 30), True),
        (rect(5, 5, 10, 10), False), (rect(10, 5, 15, 10), False),
        (rect(18, 18, 28, 28), False), (rect(21, 21, 25, 25), True),
    ]
    w = assemble(loops, (-1, -1, 31, 31))
    assert len(open_ends(w)) == 0
    g = build_navgrid(w, cell=0.5, clearance=0.0)
    assert not g.valid[0][g.node_of(9.9, 7.3)] and not g.valid[0][g.node_of(10.2, 7.3)]
    assert g.valid[0][g.node_of(23.1, 23.3)]       # courtyard
    assert not g.valid[0][g.node_of(19.3, 19.6)]   # the block around it
    assert g.valid[0][g.node_of(2.2, 2.3)] and not g.valid[0][g.node_of(-0.6, 5.1)]


def test_open_ends_find_loose_and_flipped_walls():
    w = box_arena(10, 10)
    assert len(open_ends(w)) == 0
    cut = WallList(w.segments[:3], w.direction[:3], w.aux)
    assert sorted(map(tuple, open_ends(cut))) == [(0.0, 0.0), (0.0, 10.0)]
    flipped = WallList(w.segments, np.array([1, -1, 1, 1], dtype=np.int8), w.aux)
    assert len(open_ends(flipped)) == 2


# -------------------------------------------------------------------- runs
def _naive_runs(valid):
    nz, nx = valid.shape
    ri, rt = np.zeros((nz, nx), int), np.zeros((nz, nx), int)
    for i in range(nz):
        j = 0
        while j < nx:
            if valid[i, j]:
                k = j
                while k < nx and valid[i, k]:
                    k += 1
                ri[i, j:k] = np.arange(1, k - j + 1)
                rt[i, j:k] = k - j
                j = k
            else:
                j += 1
    return ri, rt


def test_runs_equal_a_naive_count():
    rng = np.random.default_rng(0)
    valid = rng.random((23, 31)) < 0.7
    ri, rt, ci, ct = runs(valid)
    nri, nrt = _naive_runs(valid)
    nci, nct = _naive_runs(valid.T)
    assert np.array_equal(ri, nri) and np.array_equal(rt, nrt)
    assert np.array_equal(ci, nci.T) and np.array_equal(ct, nct.T)


def test_runs_paper_example():
    # "in each row count the valid nodes between two invalid ones (five), and number them"
    row = np.array([[0, 1, 1, 1, 1, 1, 0, 1, 1]], dtype=bool)
    ri, rt, ci, ct = runs(row)
    assert ri[0].tolist() == [0, 1, 2, 3, 4, 5, 0, 1, 2]
    assert rt[0].tolist() == [0, 5, 5, 5, 5, 5, 0, 2, 2]
    assert ci[0].tolist() == row[0].astype(int).tolist() and ct[0].tolist() == ci[0].tolist()


# ----------------------------------------------------------------- regions
def test_unreachable_regions_from_spawns():
    # two rooms that do not connect, and a spawn in the left one only
    loops = [(rect(0, 0, 10, 10), True), (rect(12, 0, 22, 10), True)]
    w = assemble(loops, (-1, -1, 23, 11))
    spawns = np.array([[5.0, 5.0, 0.0]])
    g = build_navgrid(w, cell=0.5, clearance=1.0, spawns=spawns)
    left = g.valid[0] & (g.node_x[None, :] < 11)
    assert np.array_equal(g.reachable[0], left)
    assert g.valid[0].sum() > left.sum() > 0
    # a spawn inside the clearance band snaps to the nearest valid node
    g2 = build_navgrid(w, cell=0.5, clearance=1.0, spawns=np.array([[21.7, 5.0, 0.0]]))
    assert g2.reachable[0].sum() == g.valid[0].sum() - left.sum()
    # no spawns: every valid node is reachable
    assert np.array_equal(build_navgrid(w, 0.5, 1.0).reachable, g.valid)


def test_reference_build_equals_default_build():
    w = block_maze(2, n=4)
    spawns = np.array([[6.0, 6.0]])
    a = build_navgrid(w, 1.0, 0.8, spawns=spawns)
    b = build_navgrid(w, 1.0, 0.8, spawns=spawns, reference=True)
    for f in ("valid", "row_index", "row_total", "col_index", "col_total", "reachable"):
        assert np.array_equal(getattr(a, f), getattr(b, f))


# -------------------------------------------------------------- save/load
def test_save_load_round_trip(tmp_path):
    g = build_navgrid(random_arena(1), 0.5, 0.6, spawns=np.array([[10.0, 10.0]]))
    g.save(tmp_path / "navgrid.npz")
    with np.load(tmp_path / "navgrid.npz") as z:
        assert {"origin", "cell", "shape", "valid", "row_index", "row_total", "col_index", "col_total", "reachable"} <= set(z.files)
        assert tuple(z["shape"]) == g.shape
    h = NavGrid.load(tmp_path / "navgrid.npz")
    assert h.shape == g.shape and h.cell == g.cell and np.array_equal(h.origin, g.origin)
    for f in ("valid", "row_index", "row_total", "col_index", "col_total", "reachable"):
        assert np.array_equal(getattr(h, f), getattr(g, f))


def test_one_level_grid_is_layered_in_memory_and_two_dimensional_on_file(tmp_path):
    """In memory every grid is (L, nz, nx), L = 1 here; the file keeps (nz, nx) arrays
    (bundled arenas' bytes and hashes do not change), and a (nz, nx) file reads as L = 1."""
    g = build_navgrid(random_arena(1), 0.5, 0.6, spawns=np.array([[10.0, 10.0]]))
    assert g.levels == 1 and g.valid.shape == (1, *g.shape) and g.heights().shape == g.valid.shape
    assert g.links().shape == (1, *g.shape, 4) and all(len(n) == 3 and n[0] == 0 for n in g.spawn_nodes)
    data = g.to_bytes()
    with np.load(io.BytesIO(data)) as z:
        for f in ("valid", "row_index", "row_total", "col_index", "col_total", "reachable", "height"):
            assert z[f].shape == g.shape, f
    p = tmp_path / "g.npz"
    g.save(p)
    h = NavGrid.load(p)
    assert h.valid.shape == (1, *g.shape) and h.to_bytes() == data
    hand = grid_from_mask(np.ones((3, 4), bool))
    assert hand.valid.shape == hand.row_index.shape == hand.reachable.shape == (1, 3, 4)


def test_load_rejects_bad_files(tmp_path):
    p = tmp_path / "x.npz"
    np.savez(p, origin=np.zeros(2))
    with pytest.raises(FormatError, match="x.npz: not a navgrid file"):
        NavGrid.load(p)
    g = build_navgrid(box_arena(), 1.0, 0.5)
    np.savez(p, origin=g.origin, cell=g.cell, shape=np.array(g.shape), valid=g.valid, row_index=g.row_index,
             row_total=g.row_total, col_index=g.col_index, col_total=g.col_total[:-1])
    with pytest.raises(FormatError, match="col_total has shape"):
        NavGrid.load(p)
    with pytest.raises(FormatError, match="no such file"):
        NavGrid.load(tmp_path / "none.npz")


def test_table_one_node_a_line():
    g = build_navgrid(box_arena(4, 3, margin=1), cell=1.0, clearance=0.4)
    text = format_table(g)
    body = [ln for ln in text.splitlines() if not ln.startswith("#")]
    assert len(body) == g.valid.size
    i, j, x, z, v, r, ri, ci, rt, ct = body[g.nx * 2 + 3].split()
    assert (int(i), int(j)) == (2, 3) and float(x) == g.centre(2, 3)[0]
    assert int(v) == g.valid[0, 2, 3] and (int(ri), int(rt)) == (g.row_index[0, 2, 3], g.row_total[0, 2, 3])
    region = format_table(g, np.array([[0, 0], [2, 1.0]]))
    assert len([ln for ln in region.splitlines() if not ln.startswith("#")]) == 2


def test_table_of_a_layered_grid_has_every_level():
    from tanktool.nav.navgrid import layered_runs, links_from_valid

    v = np.zeros((2, 3, 4), dtype=bool)
    v[0] = True
    v[1, 1, 1:3] = True   # a deck of two nodes over the middle row
    link = links_from_valid(v)
    g = NavGrid(np.zeros(2), 1.0, (3, 4), v, *layered_runs(v, link), v.copy(), link=link)
    text = format_table(g)
    assert "levels 2" in text and "# level i j x z valid" in text
    body = [ln.split() for ln in text.splitlines() if not ln.startswith("#")]
    assert len(body) == v.size and [b[0] for b in body] == ["0"] * 12 + ["1"] * 12
    deck = [b for b in body if b[0] == "1" and b[5] == "1"]
    assert [(b[1], b[2], b[7], b[9]) for b in deck] == [("1", "1", "1", "2"), ("1", "2", "2", "2")]
    one = format_table(build_navgrid(box_arena(4, 3, margin=1), cell=1.0, clearance=0.4))
    assert "levels" not in one and "# i j x z valid" in one


def test_walls_without_aux_use_their_extent():
    w = box_arena(8, 8)
    bare = WallList(w.segments, w.direction, None)
    g = build_navgrid(bare, 0.5, 0.5)
    assert np.array_equal(g.origin, [0, 0]) and g.shape == (16, 16)
    assert g.valid.sum() == 14 * 14
    assert aux_rectangle(0, 0, 1, 1).shape == (4, 2, 2)


@pytest.mark.parametrize("cell", [2.0, 1.0, 0.5])
def test_rows_through_vertices_and_along_walls(cell):
    # origin -1 and cell 2: node rows and columns pass exactly through the maze's
    # vertices and along its walls, and many lines to the origin pass through vertices
    w = block_maze(6, n=4)
    origin, shape, X, Z = _nodes(w, cell)
    for clearance in (0.0, 1.0):
        fast = classify(w, origin, cell, shape, clearance)
        assert np.array_equal(fast, classify_reference(w, origin, cell, shape, clearance))
    inside_free = free_space(w, origin, cell, shape)
    d2 = _min_dist2(w, X, Z)
    # nodes exactly on a wall are never valid, even with no clearance
    assert not classify(w, origin, cell, shape, 0.0)[d2 == 0].any()
    assert inside_free.sum() > 0


def _fuzz(seed):
    rng = np.random.default_rng(seed)
    w = random_arena(seed, size=float(rng.uniform(20, 60)), cells=int(rng.integers(2, 6)))
    cell = float(rng.uniform(0.6, 1.4))
    shift = rng.uniform(-3, 3, size=2)
    bounds = w.bounds + shift  # grids need not start at the auxiliary corner
    clearance = float(rng.uniform(0, 2))
    a = build_navgrid(w, cell, clearance, bounds=bounds)
    b = build_navgrid(w, cell, clearance, bounds=bounds, reference=True)
    assert np.array_equal(a.valid, b.valid), seed


@pytest.mark.parametrize("seed", range(2))
def test_fuzz_fast_equals_reference_short(seed):
    _fuzz(100 + seed)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(40))
def test_fuzz_fast_equals_reference(seed):
    _fuzz(seed)
