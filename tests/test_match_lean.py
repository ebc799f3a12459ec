"""A match on a large terrain made leaner: what the agents' grids and sight tables
read is what they read before (run arrays made on demand, one walk for both grades,
the sight table's blocks in bands)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tanktool.nav.navgrid import layered_runs, runs
from tanktool.sim.agents.layers import GroundGrid, ground_agent_grid

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module", params=["fort", "hills"])
def ground(request):
    from tanktool.sim.match import load_match_arena

    info = load_match_arena(ROOT / "arenas" / request.param)
    spawns = [(float(s[0]), float(s[1]), None) for s in info.spawns]
    return info.ground, spawns


def test_run_arrays_on_demand_are_the_eager_ones(ground):
    g, spawns = ground
    grid = ground_agent_grid(g, 1.0, 1.9, spawns, grade=0.5)
    lay = grid.layers
    assert isinstance(grid, GroundGrid) and isinstance(lay, GroundGrid)
    assert "_runs" not in vars(lay)            # nothing made until read
    want = layered_runs(lay.valid, lay.link)
    for name, w in zip(("row_index", "row_total", "col_index", "col_total"), want):
        got = getattr(lay, name)
        assert got.dtype == np.int16 and np.array_equal(got, w)
    for name, w in zip(("row_index", "row_total", "col_index", "col_total"), runs(grid.valid[0])):
        assert np.array_equal(getattr(grid, name)[0], w) and getattr(grid, name).shape == grid.valid.shape
    lay.row_index = want[0]                   # given: kept as given
    assert lay.row_index is want[0] and np.array_equal(lay.row_total, want[1])


@pytest.mark.skipif(not __import__("tanktool.geometry.kernels", fromlist=["x"]).available(),
                    reason="compiled kernels not built")
def test_the_tilt_kernel_is_the_python_tilt_to_the_bit(ground):
    import math

    from tanktool.geometry.kernels import use_kernels

    g = ground[0]
    rng = np.random.default_rng(7)
    n = 3000
    xs = rng.uniform(g.ox - 3, g.ox + g.nx * g.cell + 3, n)
    zs = rng.uniform(g.oz - 3, g.oz + g.nz * g.cell + 3, n)
    xs[:300] = g.ox + rng.integers(-2, g.nx + 2, 300) * g.cell * 0.5     # on cell edges and centres
    zs[:300] = g.oz + rng.integers(-2, g.nz + 2, 300) * g.cell * 0.5
    args = [(int(rng.integers(-1, g.levels + 1)), float(x), float(z), math.cos(a), math.sin(a),
             float(rng.choice([0.0, 1.2, 2.9, 6.0])), float(rng.choice([0.0, 0.9, 1.6, 5.5])))
            for x, z, a in zip(xs, zs, rng.uniform(-4, 4, n))]
    with use_kernels(False):
        slow = [g.tilt(x, z, lv, c, s, hl, hw) for lv, x, z, c, s, hl, hw in args]
    with use_kernels(True):
        fast = [g.tilt(x, z, lv, c, s, hl, hw) for lv, x, z, c, s, hl, hw in args]
    assert [tuple(t) for t in fast] == [tuple(t) for t in slow]
    assert sum(p != 0.0 for _, p, _ in fast) > 100      # slopes sampled, not only level ground


@pytest.mark.skipif(not __import__("tanktool.geometry.kernels", fromlist=["x"]).available(),
                    reason="compiled kernels not built")
def test_the_height_and_follow_kernels_are_the_python_ones(ground):
    from tanktool.geometry.kernels import use_kernels

    g = ground[0]
    rng = np.random.default_rng(11)
    n = 4000
    pts = [(float(x), float(z), int(lv)) for x, z, lv in zip(
        rng.uniform(g.ox - 3, g.ox + g.nx * g.cell + 3, n), rng.uniform(g.oz - 3, g.oz + g.nz * g.cell + 3, n),
        rng.integers(-1, g.levels + 1, n))]
    moves = []
    for _ in range(n):
        i0, j0 = int(rng.integers(0, g.nz)), int(rng.integers(0, g.nx))
        span = int(rng.choice([1, 1, 1, 3]))      # mostly one cell, some jumps walked in steps
        i1 = int(np.clip(i0 + rng.integers(-span, span + 1), 0, g.nz - 1))
        j1 = int(np.clip(j0 + rng.integers(-span, span + 1), 0, g.nx - 1))
        moves.append((int(rng.integers(-1, g.levels)), i0, j0, i1, j1))   # -1: the last (a list)
    # where tanks are: on nodes, moving to their neighbours
    lv, ii, jj = np.nonzero(g.exists)
    pick = rng.integers(0, len(lv), n)
    moves += [(int(lv[k]), int(ii[k]), int(jj[k]), int(np.clip(ii[k] + a, 0, g.nz - 1)),
               int(np.clip(jj[k] + b, 0, g.nx - 1))) for k, a, b in zip(pick, rng.integers(-1, 2, n),
                                                                         rng.integers(-1, 2, n))]
    with use_kernels(False):
        slow = [g.height(*p) for p in pts], [g.follow(*m) for m in moves]
    with use_kernels(True):
        fast = [g.height(*p) for p in pts], [g.follow(*m) for m in moves]
    assert fast == slow
    assert all(type(v) is float for v in fast[0]) and all(type(v) is int for v in fast[1])
    assert sum(v >= 0 for v in fast[1]) > n // 2


def test_the_walks_in_bands_and_shared_by_two_grades_are_one_walk(ground, monkeypatch):
    from tanktool.sim.agents import layers

    g, spawns = ground
    layers._LAST_WALK.clear()
    graded = ground_agent_grid(g, 1.0, 1.9, spawns, grade=0.45)
    plain = ground_agent_grid(g, 1.0, 1.9, spawns)          # the walk above, not cut
    monkeypatch.setattr(layers, "WALK_BAND", 5)
    for grade, want in ((0.45, graded), (float("inf"), plain)):
        layers._LAST_WALK.clear()
        got = ground_agent_grid(g, 1.0, 1.9, spawns, grade=grade)
        for a, b in ((got, want), (got.layers, want.layers)):
            assert np.array_equal(a.valid, b.valid) and np.array_equal(a.reachable, b.reachable)
            assert a.link is None and b.link is None or np.array_equal(a.link, b.link)
        assert got.spawn_nodes == want.spawn_nodes
    assert (plain.layers.link >= 0).sum() >= (graded.layers.link >= 0).sum()


@pytest.mark.skipif(not __import__("tanktool.geometry.kernels", fromlist=["x"]).available(),
                    reason="compiled kernels not built")
@pytest.mark.parametrize("k", [1, 2, 3])
def test_the_walk_kernel_is_the_numpy_walk(ground, k):
    from tanktool.geometry.kernels import use_kernels
    from tanktool.sim.agents import layers

    g = ground[0]
    ok = layers.clear_enough(g, 1.4)
    ii = (k // 2 + k * np.arange((g.nz - k // 2 - 1) // k + 1)).astype(np.int32)
    jj = (k // 2 + k * np.arange((g.nx - k // 2 - 1) // k + 1)).astype(np.int32)
    got = {}
    for on in (False, True):
        layers._LAST_WALK.clear()
        with use_kernels(on):
            got[on] = layers._walked(g, 1.4, ok, ii, jj, k)
    assert np.array_equal(got[False], got[True]) and (got[True] >= 0).sum() > 1000


@pytest.mark.skipif(not __import__("tanktool.geometry.kernels", fromlist=["x"]).available(),
                    reason="compiled kernels not built")
def test_the_grade_cut_kernel_is_the_numpy_cut(ground):
    from tanktool.geometry.kernels import use_kernels
    from tanktool.sim.agents import layers

    g, spawns = ground
    plain = ground_agent_grid(g, 1.0, 1.4, spawns)
    link0, heights = plain.layers.link, plain.layers.height      # NaN off the valid nodes
    for most in (2.5, 0.9, 0.3, 0.0):
        got = {}
        for on in (False, True):
            link = link0.copy()
            with use_kernels(on):
                layers._cut_grade(link, heights, most)
            got[on] = link
        assert np.array_equal(got[False], got[True])
    assert (got[True] >= 0).sum() < (link0 >= 0).sum()      # 0.0: any rise cut


@pytest.mark.skipif(not __import__("tanktool.geometry.kernels", fromlist=["x"]).available(),
                    reason="compiled kernels not built")
def test_the_lines_of_sight_kernel_is_the_numpy_sampling(ground):
    from tanktool.geometry.kernels import use_kernels

    g = ground[0]
    sf = g.solids
    rng = np.random.default_rng(3)
    lv, i, j = np.nonzero(g.exists)
    pick = rng.integers(0, len(lv), 120)
    x, z = g.ox + (j[pick] + 0.5) * g.cell, g.oz + (i[pick] + 0.5) * g.cell
    pts = np.column_stack([x, g.h[lv[pick], i[pick], j[pick]] + rng.choice([0.2, 1.2, 3.0], len(pick)), z])
    for rng_m in (float("inf"), 40.0):
        with use_kernels(False):
            slow = sf.visible(pts, rng_m)
        with use_kernels(True):
            fast = sf.visible(pts, rng_m)
        assert fast.dtype == bool and np.array_equal(fast, slow)
    assert 0 < fast.sum() < fast.size


def test_a_navgrid_read_without_its_runs_is_the_rest_of_it():
    from tanktool.nav.navgrid import NavGrid

    path = ROOT / "arenas" / "fort" / "navgrid.npz"
    whole, lean = NavGrid.load(path), NavGrid.load(path, runs=False)
    assert lean.row_index is None and lean.col_total is None
    for k in ("valid", "reachable", "height", "link"):
        assert np.array_equal(getattr(whole, k), getattr(lean, k), equal_nan=True)
    assert np.array_equal(whole.origin, lean.origin) and whole.cell == lean.cell and whole.shape == lean.shape


@pytest.mark.skipif(not __import__("tanktool.geometry.kernels", fromlist=["x"]).available(),
                    reason="compiled kernels not built")
def test_the_path_kernel_finds_the_python_paths(ground):
    from tanktool.geometry.kernels import use_kernels
    from tanktool.nav.path import astar_layered

    g, spawns = ground
    lay = ground_agent_grid(g, 1.0, 1.9, spawns, grade=0.45).layers
    rng = np.random.default_rng(2)
    nodes = [tuple(map(int, n)) for n in np.argwhere(lay.valid)]
    pairs = [(nodes[a], nodes[b]) for a, b in rng.integers(0, len(nodes), (40, 2))] + [(nodes[0], nodes[0])]
    with use_kernels(False):
        slow = [astar_layered(lay, s, e) for s, e in pairs]
    with use_kernels(True):
        fast = [astar_layered(lay, s, e) for s, e in pairs]
    assert fast == slow and fast[-1] == [nodes[0]]
    assert all(type(v) is int for p in fast for n in p for v in n) and sum(len(p) > 2 for p in fast) > 20
