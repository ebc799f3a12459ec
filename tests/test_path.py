import math

import numpy as np
import pytest
from scipy.sparse import lil_matrix
from scipy.sparse.csgraph import dijkstra

from tanktool.nav.navgrid import build_navgrid, grid_from_mask
from tanktool.nav.path import astar, grid_line_of_sight, path_length, smooth_path
from tanktool.nav.quadtree import WallQuadtree
from tanktool.nav.synthetic import block_maze, random_arena
from tanktool.geometry.segments import segment_segment_dist2


def mask(text: str) -> np.ndarray:
    return np.array([[c != "#" for c in line.strip()] for line in text.strip().splitlines()])


def _steps_ok(g, path):
    for (a, b), (c, d) in zip(path, path[1:]):
        di, dj = c - a, d - b
        assert max(abs(di), abs(dj)) == 1
        assert g.valid[0][c, d]
        if di and dj:  # no corner cutting
            assert g.valid[0][a + di, b] and g.valid[0][a, b + dj]


def _dijkstra_cost(valid, s, t):
    """Independent shortest 8-connected no-corner-cutting cost with scipy."""
    nz, nx = valid.shape
    G = lil_matrix((nz * nx, nz * nx))
    for i in range(nz):
        for j in range(nx):
            if not valid[i, j]:
                continue
            for di in (-1, 0, 1):
                for dj in (-1, 0, 1):
                    a, b = i + di, j + dj
                    if (di or dj) and 0 <= a < nz and 0 <= b < nx and valid[a, b]:
                        if di and dj and not (valid[i + di, j] and valid[i, j + dj]):
                            continue
                        G[i * nx + j, a * nx + b] = math.hypot(di, dj)
    d = dijkstra(G.tocsr(), indices=s[0] * nx + s[1])
    return d[t[0] * nx + t[1]]


def test_astar_is_optimal_and_never_cuts_corners():
    g = build_navgrid(block_maze(5, n=4), cell=1.0, clearance=0.6)
    rng = np.random.default_rng(2)
    nodes = np.argwhere(g.valid[0])
    for _ in range(6):
        s, t = (tuple(map(int, nodes[k])) for k in rng.choice(len(nodes), 2, replace=False))
        p = astar(g, s, t)
        assert p[0] == s and p[-1] == t
        _steps_ok(g, p)
        cost = sum(math.hypot(c - a, d - b) for (a, b), (c, d) in zip(p, p[1:]))
        assert cost == pytest.approx(_dijkstra_cost(g.valid[0], s, t))


def test_corner_is_not_cut():
    g = grid_from_mask(mask("""
        #####
        #..##
        #.#.#
        ##..#
        #####
    """))
    # (1,2) -> (2,3) diagonally would squeeze between two walls
    p = astar(g, (1, 1), (3, 3))
    assert p == []  # the only link is a corner: no path
    assert astar(g, (1, 1), (2, 1)) == [(1, 1), (2, 1)]


def test_no_path_and_bad_ends():
    g = grid_from_mask(mask("""
        #####
        #.#.#
        #####
    """))
    assert astar(g, (1, 1), (1, 3)) == []
    assert astar(g, (0, 0), (1, 1)) == []
    with pytest.raises(ValueError, match="outside"):
        astar(g, (9, 9), (1, 1))
    assert astar(g, (1, 1), (1, 1)) == [(1, 1)]


def test_grid_line_of_sight():
    g = grid_from_mask(mask("""
        #######
        #.....#
        #..#..#
        #.....#
        #######
    """))
    assert grid_line_of_sight(g, (1, 1), (1, 5))
    assert not grid_line_of_sight(g, (2, 1), (2, 5))
    assert not grid_line_of_sight(g, (1, 1), (3, 5))  # passes through (2, 3)
    assert grid_line_of_sight(g, (3, 1), (3, 5))
    # exactly through the corner shared by (1,2),(1,3),(2,2),(2,3): the wall cell touches
    assert not grid_line_of_sight(g, (1, 2), (2, 3)) and not grid_line_of_sight(g, (3, 4), (1, 2))


def test_smoothing_on_the_grid_keeps_line_of_sight():
    g = build_navgrid(random_arena(3), cell=0.5, clearance=1.0)
    nodes = np.argwhere(g.reachable[0])
    s, t = tuple(map(int, nodes[0])), tuple(map(int, nodes[-1]))
    p = astar(g, s, t)
    sm = smooth_path(g, p)
    assert sm[0] == s and sm[-1] == t and len(sm) < len(p)
    assert all(grid_line_of_sight(g, a, b) for a, b in zip(sm, sm[1:]))
    assert path_length(g, sm) <= path_length(g, p) + 1e-9
    assert set(sm) <= set(p)


def test_smoothing_against_the_quadtree_respects_clearance():
    w = random_arena(6)
    r = 0.9
    g = build_navgrid(w, cell=0.5, clearance=r)
    q = WallQuadtree.build(w.segments, w.bounds)
    nodes = np.argwhere(g.reachable[0])
    p = astar(g, tuple(map(int, nodes[5])), tuple(map(int, nodes[-5])))
    pts = g.centres(np.array(p))
    sm = smooth_path(q, pts, clearance=r * 0.99)
    assert np.array_equal(sm[0], pts[0]) and np.array_equal(sm[-1], pts[-1]) and len(sm) < len(p)
    s = w.segments
    for a, b in zip(sm, sm[1:]):
        d2 = segment_segment_dist2(a, b, s[:, 0], s[:, 1])
        assert d2.min() > (r * 0.99) ** 2
    as_nodes = smooth_path(q, p, grid=g, clearance=r * 0.99)
    assert np.allclose(g.centres(np.array(as_nodes)), sm)
    with pytest.raises(TypeError, match="grid="):
        smooth_path(q, p)


def test_grid_line_of_sight_equals_dense_sampling():
    rng = np.random.default_rng(4)
    valid = rng.random((14, 17)) < 0.8
    g = grid_from_mask(valid)
    t = np.linspace(0, 1, 4001)
    for _ in range(300):
        a = tuple(int(v) for v in rng.integers(0, (14, 17)))
        b = tuple(int(v) for v in rng.integers(0, (14, 17)))
        # every boundary crossing too, so that exact corner passes are sampled
        tt = np.concatenate([t] + [(np.arange(abs(d)) + 0.5) / abs(d) for d in (b[0] - a[0], b[1] - a[1]) if d])
        cells = set()
        for ez in (-1e-7, 1e-7):
            for ex in (-1e-7, 1e-7):
                zi = np.floor(a[0] + tt * (b[0] - a[0]) + ez + 0.5).astype(int)
                xj = np.floor(a[1] + tt * (b[1] - a[1]) + ex + 0.5).astype(int)
                inside = (zi >= 0) & (zi < 14) & (xj >= 0) & (xj < 17)
                cells |= set(zip(zi[inside].tolist(), xj[inside].tolist()))
        expect = all(valid[c] for c in cells)
        assert grid_line_of_sight(g, a, b) == expect, (a, b)


def test_find_path_in_world_coordinates():
    from tanktool.nav.path import find_path

    w = block_maze(3, n=4)
    g = build_navgrid(w, cell=0.5, clearance=1.0)
    q = WallQuadtree.build(w.segments, w.bounds)
    free = g.centres(np.argwhere(g.valid[0]))
    start, goal = tuple(free[0]), tuple(free[-1])
    for pts in (find_path(g, start, goal), find_path(g, start, goal, quadtree=q)):
        assert np.allclose(pts[0], start) and np.allclose(pts[-1], goal) and len(pts) >= 2
        s = w.segments
        for a, b in zip(pts, pts[1:]):  # every leg keeps (almost) the clearance
            assert segment_segment_dist2(a, b, s[:, 0], s[:, 1]).min() > 0.5 ** 2
    # starting inside the clearance band snaps to the nearest valid node
    near_wall = (free[0][0] - 0.6, free[0][1])
    assert len(find_path(g, near_wall, goal)) >= 2
    # a point deep inside solid ground (the maze's outer blocks are 4 m, 8 cells,
    # thick): no valid node within 4 cells, so no path
    from scipy.ndimage import binary_dilation

    near_valid = binary_dilation(g.valid[0], iterations=5, structure=np.ones((3, 3), bool))
    deep = np.argwhere(~near_valid)
    assert len(deep)
    assert find_path(g, g.centre(*deep[len(deep) // 2]), goal).shape == (0, 2)


def test_move_masks_equal_a_naive_check():
    from tanktool.nav.path import move_masks

    rng = np.random.default_rng(9)
    ok = rng.random((9, 11)) < 0.7
    m = move_masks(ok)
    moves = [(0, 1), (0, -1), (1, 0), (-1, 0), (1, 1), (1, -1), (-1, 1), (-1, -1)]
    cell = lambda i, j: 0 <= i < 9 and 0 <= j < 11 and ok[i, j]  # noqa: E731
    for i in range(9):
        for j in range(11):
            for k, (di, dj) in enumerate(moves):
                allowed = cell(i, j) and cell(i + di, j + dj) and (not (di and dj) or (cell(i + di, j) and cell(i, j + dj)))
                assert bool(m[i, j] >> k & 1) == allowed
