"""Walkable surfaces: the voxel heightfield, open spans, levels, the layered grid, walls
per level, on levels tools/make_levels.py generates (terrain, ramps, decks, bridges)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
import shapely
import trimesh
from click.testing import CliRunner

from tanktool.cli.main import cli
from tanktool.formats.walls_txt import format_walls, parse_walls
from tanktool.geometry.heightfield import _merge, build_heightfield, rasterize, walkable_faces
from tanktool.geometry.walls import extract_walls
from tanktool.nav.arena_levels import analyse_arena
from tanktool.nav.level_walls import level_walls
from tanktool.nav.navgrid import NavGrid
from tanktool.nav.path import astar_layered
from tanktool.nav.walkable import WalkableParams, grid_from_surface, stack_levels, walkable_surface
from tanktool.fleet import Fleet

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
import make_levels  # noqa: E402

PARAMS = WalkableParams(cell=0.5, cell_height=0.1, max_slope=35.0, climb=0.9, headroom=2.35)
TANK = Fleet(radius=3.0, length=6.0, height=2.3)


def mesh_of(name: str, **kw):
    m = make_levels.level(name, **kw)
    return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64)


def box(x0, z0, x1, z1, y0, y1):
    return make_levels.box(x0, z0, x1, z1, y0, y1)


# ---------------------------------------------------------------- rasterisation
def _clip_y_range(tri: np.ndarray, x0: float, z0: float, cs: float) -> tuple[float, float] | None:
    """The reference: Sutherland-Hodgman clipping of a triangle to a cell column, one
    plane at a time, then the y range of what is left (None: fewer than 3 vertices)."""
    poly = [tuple(p) for p in tri]
    for axis, lo, keep_above in ((0, x0, True), (0, x0 + cs, False), (2, z0, True), (2, z0 + cs, False)):
        out = []
        for k in range(len(poly)):
            a, b = poly[k - 1], poly[k]
            da = (a[axis] - lo) if keep_above else (lo - a[axis])
            db = (b[axis] - lo) if keep_above else (lo - b[axis])
            if (da >= 0) != (db >= 0):
                t = da / (da - db)
                out.append(tuple(a[i] + t * (b[i] - a[i]) for i in range(3)))
            if db >= 0:
                out.append(b)
        poly = out
        if len(poly) < 3:
            return None
    ys = [p[1] for p in poly]
    return min(ys), max(ys)


@pytest.mark.parametrize("seed", range(6))
def test_rasterised_spans_hold_the_clipped_triangles(seed):
    rng = np.random.default_rng(seed)
    cs, ch = 0.5, 0.1
    tri = []
    for _ in range(25):
        c = rng.uniform(1, 9, 3) * [1, 0.5, 1]
        t = c + rng.normal(0, 1.5, (3, 3))
        if rng.random() < 0.4:  # a wall: a vertical triangle
            t[:, 2] = t[0, 2] + (t[:, 0] - t[0, 0]) * rng.uniform(-1, 1)
        tri.append(t)
    V = np.concatenate(tri)
    F = np.arange(len(V)).reshape(-1, 3)
    origin = np.array([0.0, V[:, 1].min() - 1, 0.0])
    shape = (24, 24)
    walk, flat = walkable_faces(V, F, 45)
    # the spans of each triangle alone, before merging, against the reference clip
    for k in range(len(F)):
        (col, smin, smax, *_), _ = rasterize(V, F[k:k + 1], cs, ch, walk[k:k + 1], flat[k:k + 1], origin, shape, 0)
        got = {int(c): (int(a), int(b)) for c, a, b in zip(col, smin, smax)}
        want = {}
        for i in range(shape[0]):
            for j in range(shape[1]):
                r = _clip_y_range(V[F[k]], origin[0] + j * cs, origin[2] + i * cs, cs)
                if r is not None and r[1] - r[0] >= 0:
                    lo = int(math.floor((r[0] - origin[1]) / ch))
                    want[i * shape[1] + j] = (lo, max(int(math.ceil((r[1] - origin[1]) / ch)), lo + 1))
        # every cell the triangle really covers has a span holding its range
        area = {c for c in want if c in got}
        assert len(area) >= 0.95 * len(want), (seed, k)
        for c in area:
            assert got[c][0] <= want[c][0] + 1 and got[c][1] >= want[c][1] - 1, (seed, k, c)
        # and no span where it does not (but along its edges: touching, rounding)
        extra = set(got) - set(want)
        assert len(extra) <= max(2, 0.15 * len(want)), (seed, k)


def test_spans_of_one_column_merge_and_keep_the_top_flags():
    col = np.array([5, 5, 5, 7])
    smin = np.array([0, 3, 20, 1])
    smax = np.array([4, 6, 25, 2])
    walk = np.array([0, 1, 0, 1])
    flat = np.array([0, 1, 0, 0])
    c, lo, hi, w, f, top = _merge(col, smin, smax, walk, flat, 2)
    assert c.tolist() == [5, 5, 7]
    assert lo.tolist() == [0, 20, 1] and hi.tolist() == [6, 25, 2]
    assert w.tolist() == [True, False, True] and f.tolist() == [True, False, False]


# ---------------------------------------------------------------- filters
def test_a_platform_edge_is_a_ledge_and_a_low_ceiling_is_no_headroom():
    parts = [box(0, 0, 20, 20, -0.5, 0), box(5, 5, 10, 10, 0, 3.0),   # a 3 m platform
             box(12, 0, 14, 20, 1.5, 1.7)]                             # a beam 1.5 m up
    m = trimesh.util.concatenate(parts)
    hf = build_heightfield(m.vertices, m.faces, 0.5, 0.1, 35, 2.35, 0.9)
    top = hf.top_y()
    # the platform's top is walkable inside and not on its edge cells (drop of 3 m)
    i, j = np.divmod(hf.col, hf.shape[1])
    x = hf.origin[0] + (j + 0.5) * 0.5
    z = hf.origin[2] + (i + 0.5) * 0.5
    on = np.isclose(top, 3.0, atol=0.11)
    inner = on & (x > 5.6) & (x < 9.4) & (z > 5.6) & (z < 9.4)
    # the low edges' cells see the 3 m drop; at the high edges the walls' faces, on the
    # cells' boundary lines, are rasterised into the next cells (as Recast does), so
    # the drop is one cell further out -- but never walkable beyond the platform
    edge = on & ((x < 5.5) | (z < 5.5))
    beyond = on & ((x > 10.0) | (z > 10.0))
    assert hf.walkable[inner].all() and not hf.walkable[edge].any() and not hf.walkable[beyond].any()
    # the floor under the beam has 1.5 m of headroom: not walkable, counted
    under = np.isclose(top, 0.0, atol=0.11) & (x > 12.2) & (x < 13.8) & (z > 0.5) & (z < 19.5)
    assert under.any() and not hf.walkable[under].any() and hf.low_headroom[under].all()


def test_a_kerb_within_the_climb_is_walkable_and_linked():
    parts = [box(0, 0, 20, 20, -0.5, 0), box(8, 0, 20, 20, 0, 0.3)]  # a 30 cm kerb
    m = trimesh.util.concatenate(parts)
    s = walkable_surface(m.vertices, m.faces, PARAMS, 1.0)
    assert s.levels == 1 and s.main.all()  # one region: the kerb does not split it
    assert set(np.round(s.y, 2)) == {0.0, 0.3}


# ---------------------------------------------------------------- generated levels
def test_rolling_terrain_is_one_surface_without_walls_across_it():
    V, F = mesh_of("rolling_terrain")
    assert len(F) >= 5000
    r = analyse_arena(V, F, PARAMS, TANK)
    assert len(r.levels) == 1
    s = r.surface
    # nearly all of the terrain (all but the ridge too steep to climb) is the played region
    assert s.main.sum() * 0.25 > 0.8 * 90 * 90
    # the walls follow the ridge and the terrain's rim, not its hills: none crosses
    # the inner terrain far from the ridge
    seg = r.walls.walls.segments
    mid = seg.mean(axis=1)
    ridge = np.abs((mid[:, 0] - 67.5) + (mid[:, 1] - 67.5)) < 12
    rim = (mid < 1.5).any(axis=1) | (mid > 88.5).any(axis=1)
    assert (ridge | rim).all()
    assert len(r.spawns) == 8
    d = np.hypot(*(r.spawns[:, None, :2] - r.spawns[None, :, :2]).transpose(2, 0, 1))
    assert d[np.triu_indices(8, 1)].min() >= TANK.length


def test_a_bridge_over_a_passage_gives_two_levels_joined_across_them():
    V, F = mesh_of("bridge")
    r = analyse_arena(V, F, PARAMS, TANK)
    assert len(r.levels) == 2
    surface = r.surface
    grid = grid_from_surface(surface, 1.0, surface.hf.origin[[0, 2]])
    assert grid.valid.ndim == 3 and grid.height.shape == grid.valid.shape
    node = grid.node_of(40.0, 30.0)  # the middle of the bridge: the passage below, the deck above
    hts = grid.height[:, node[0], node[1]]
    assert np.allclose(sorted(hts), [0.0, 5.0], atol=0.06)
    lv_pass, lv_deck = int(np.argmin(hts)), int(np.argmax(hts))
    # from the passage under the bridge to the bridge deck: up a ramp, across a plateau
    path = astar_layered(grid, (lv_pass, *node), (lv_deck, *node))
    assert path and path[0] == (lv_pass, *node) and path[-1] == (lv_deck, *node)
    ys = np.array([grid.height[n] for n in path])
    assert (np.abs(np.diff(ys)) <= PARAMS.climb + 1e-9).all()  # every step within the climb
    # the run numbers are per level: a row run on the deck ends where its level ends, the
    # deck and the plateaus' edges beside it (lifted to the deck's level: nav/level_lift.py),
    # not across the whole yard
    from tanktool.nav.level_lift import LIFT

    assert grid.row_total[lv_deck][node] <= (46 - 34 + 2 * (LIFT + 0.5)) / 0.5
    # and the passage under the deck has walls at the rock faces, not a run through them
    assert grid.row_total[lv_pass][node] <= (46 - 34) / 0.5


@pytest.mark.parametrize("name", ["stacked_floors", "two_storeys"])
def test_a_ramp_up_to_a_deck_over_the_ground_reaches_the_deck(name):
    # the ramp's top ends beside the ground under the deck (its own level, 4-5 m below):
    # on one level that edge walled the ramp off from the deck for every tank; the top
    # of the ramp now joins the deck's level, so a tank's grid reaches every deck
    from tanktool.nav.arena_levels import grid_components, tank_grid

    V, F = mesh_of(name)
    r = analyse_arena(V, F, PARAMS, TANK)
    assert len(r.levels) >= 2
    g = tank_grid(r.surface, r.walls, TANK.radius)
    labels, _ = grid_components(g)
    big = np.bincount(labels[labels > 0]).argmax()
    for lv in range(g.valid.shape[0]):
        assert (labels[lv] == big).sum() > 1000, (name, lv)


def test_a_deck_over_pillars_stays_one_level_and_the_ground_under_it_another():
    V, F = mesh_of("two_storeys")
    r = analyse_arena(V, F, PARAMS, TANK)
    s = r.surface
    deck = np.isclose(s.y, 5.0, atol=0.06) & (s.level >= 0)
    i, j = s.ij()
    x = s.hf.origin[0] + (j + 0.5) * s.hf.cs
    over = deck & (x > 11) & (x < 49)  # the slab, over ground and over pillars alike
    assert len(np.unique(s.level[over])) == 1 and s.level[over][0] == 1
    assert (s.level[s.main & np.isclose(s.y, 0.0, atol=0.06) & (x > 16) & (x < 42)] == 0).all()


def test_ten_centimetre_bumps_leave_the_yard_one_flat_room():
    V, F = mesh_of("bumpy_floor")
    r = analyse_arena(V, F, PARAMS, TANK)
    assert len(r.levels) == 1 and len(r.walls.walls) == 4
    assert not [x for x in r.left_out if x.reason.startswith("too steep")]


def test_a_room_too_small_for_any_tank_is_refused(tmp_path):
    src = make_levels.write_obj(make_levels.level("tiny_room"), tmp_path / "tiny.obj")
    out = tmp_path / "tiny"
    res = CliRunner().invoke(cli, ["import-arena", str(src), "-o", str(out)])
    assert res.exit_code == 2 and "no place where any bundled tank fits" in res.output
    assert not out.exists()


def test_an_overhang_below_the_headroom_is_walled_off():
    # a beam 1.5 m up in the room: the 2002 cut 1 m above the floor passes under it
    parts = make_levels.walled_yard(40, 30) + [("wall", box(18, 8, 22, 22, 1.5, 2.0))]
    m = make_levels.join(parts)
    r = analyse_arena(m.vertices, m.faces, PARAMS, TANK)
    old = extract_walls(m.vertices, m.faces)
    assert len(old.walls) == 4  # the cut does not see the beam
    free = r.walls.free()
    assert not free.contains(shapely.Point(20, 15))
    assert free.contains(shapely.Point(10, 15)) and free.contains(shapely.Point(30, 15))


def test_a_floor_a_few_centimetres_below_its_neighbour_is_kept():
    # two floor pieces 6 cm apart (the 2002 floor finder kept only one level)
    parts = make_levels.walled_yard(40, 30) + [("ground", box(20, 1, 39, 29, 0, 0.06))]
    m = make_levels.join(parts)
    r = analyse_arena(m.vertices, m.faces, PARAMS, TANK)
    assert len(r.levels) == 1 and r.walls.free().area > 0.9 * 38 * 28


@pytest.mark.parametrize("seed", range(4))
def test_flat_arenas_keep_the_walls_of_the_2002_cut(seed):
    rng = np.random.default_rng(seed)
    parts = make_levels.walled_yard(60, 50)
    for _ in range(6):
        x, z = rng.uniform(6, 50, 2)
        w, d = rng.uniform(1, 6, 2)
        parts.append(("rock", box(x, z, x + w, z + d, 0, rng.uniform(1.2, 4))))
    m = make_levels.join(parts)
    old = extract_walls(m.vertices, m.faces)
    r = analyse_arena(m.vertices, m.faces, PARAMS, TANK)
    new = r.walls.walls
    a = shapely.multilinestrings(list(old.walls.segments))
    b = shapely.multilinestrings(list(new.segments))
    assert shapely.hausdorff_distance(a, b) < 0.02


# ---------------------------------------------------------------- levels
def test_levels_count_spans_below_and_move_a_patch_to_its_neighbours_level():
    # columns 0..4 in a row; column 2 has a second span; a patch over "pillars"
    col = np.array([0, 1, 2, 2, 3, 4])
    keep = np.ones(6, dtype=bool)
    assert stack_levels(col, keep).tolist() == [0, 0, 0, 1, 0, 0]


# ---------------------------------------------------------------- files
def test_walls_txt_marks_levels_and_regions_and_reads_them_back():
    V, F = mesh_of("bridge")
    r = analyse_arena(V, F, PARAMS, TANK)
    text = format_walls(r.walls.walls, header="test")
    assert "# level 1 region" in text
    back = parse_walls(text)
    assert np.allclose(back.segments, r.walls.walls.segments[np.lexsort(
        (np.arange(len(r.walls.walls)), r.walls.walls.region, r.walls.walls.level))])
    assert back.layered and back.levels == 2
    # the five columns read as before by a reader that ignores comments
    plain = [ln for ln in text.splitlines() if ln and not ln.startswith("#")]
    assert all(len(ln.split()) == 5 for ln in plain)


def test_a_five_column_file_from_before_reads_as_one_block():
    w = parse_walls("0 0 10 0 1\n10 0 10 10 1\n# level design notes\n")
    assert not w.layered and w.level.tolist() == [0, 0] and w.region.tolist() == [0, 0]


def test_layered_navgrid_round_trips_and_one_level_file_keeps_two_dimensions(tmp_path):
    V, F = mesh_of("bridge")
    s = walkable_surface(V, F, PARAMS, 1.0)
    g = grid_from_surface(s, 1.0, s.hf.origin[[0, 2]])
    g.save(tmp_path / "g.npz")
    back = NavGrid.load(tmp_path / "g.npz")
    assert back.levels == 2 and back.valid.shape == g.valid.shape
    assert np.array_equal(back.link, g.link) and np.allclose(back.height, g.height, equal_nan=True, atol=1e-5)
    V, F = mesh_of("bumpy_floor")
    s = walkable_surface(V, F, PARAMS, 1.0)
    g = grid_from_surface(s, 1.0, s.hf.origin[[0, 2]])
    # in memory one level is (1, nz, nx); its file keeps (nz, nx)
    assert g.valid.shape == (1, *g.shape) and g.height.shape == g.valid.shape and g.link.shape == g.valid.shape + (4,)
    g.save(tmp_path / "one.npz")
    with np.load(tmp_path / "one.npz") as z:
        assert {"origin", "cell", "shape", "valid", "height", "link", "row_index"} <= set(z.files)
        assert z["valid"].shape == g.shape and z["link"].shape == (*g.shape, 4)
    back = NavGrid.load(tmp_path / "one.npz")
    assert back.levels == 1 and np.array_equal(back.link, g.link) and np.array_equal(back.valid, g.valid)


def test_import_and_build_navgrid_on_a_two_level_model(tmp_path):
    src = make_levels.write_obj(make_levels.level("bridge"), tmp_path / "bridge.obj")
    out = tmp_path / "bridge"
    res = CliRunner().invoke(cli, ["import-arena", str(src), "-o", str(out), "--max-slope", "30",
                                   "--climb", "0.6", "--headroom", "2.5"])
    assert res.exit_code == 0, res.output
    assert "2 levels" in res.output and "level 1:" in res.output and "max slope 30 deg" in res.output
    res = CliRunner().invoke(cli, ["build-navgrid", str(out)])
    assert res.exit_code == 0, res.output
    assert "on 2 levels" in res.output
    g = NavGrid.load(out / "navgrid.npz")
    assert g.levels == 2 and (g.valid & g.reachable).any()
    res = CliRunner().invoke(cli, ["check", str(out)])
    assert "0 errors" in res.output, res.output


@pytest.mark.parametrize("name", ["bridge", "two_storeys", "islands"])
def test_a_reseeded_surface_is_the_surface_built_again_with_that_clearance_and_seeds(name):
    from tanktool.nav.walkable import reseed

    V, F = mesh_of(name)
    big = walkable_surface(V, F, PARAMS, 3.0)
    lo, hi = V.min(axis=0), V.max(axis=0)
    rng = np.random.default_rng(0)
    seeds = np.column_stack([rng.uniform(lo[0], hi[0], 3), rng.uniform(lo[2], hi[2], 3), [0.0, 5.0, np.nan]])
    for clearance, sd in ((1.2, seeds), (3.0, seeds[:, :2]), (4.5, None), (0.25, seeds[:1])):
        want = walkable_surface(V, F, PARAMS, clearance, seeds=sd)
        got = reseed(big, clearance, sd)
        assert got.max_clearance == want.max_clearance
        for k in ("col", "floor", "ceil", "link", "clearance", "region", "main", "level", "y"):
            a, b = getattr(got, k), getattr(want, k)
            assert a.dtype == b.dtype and np.array_equal(a, b), k


@pytest.mark.parametrize("name", ["bridge", "islands"])
def test_a_lean_surface_makes_the_same_grid_and_reseeds_alike(name):
    from tanktool.nav.arena_levels import walls_too_close
    from tanktool.nav.walkable import reseed

    V, F = mesh_of(name)
    full = walkable_surface(V, F, PARAMS, 3.0)
    lean = walkable_surface(V, F, PARAMS, 3.0, lean=True)
    assert lean.clearance is None and len(lean.hf.col) == 0 and len(lean.ceil) == 0
    walls = analyse_arena(V, F, PARAMS, TANK).walls.walls
    origin = full.hf.origin[[0, 2]]
    for c, a, b in ((3.0, full, lean), (1.5, reseed(full, 1.5), reseed(lean, 1.5))):
        for k in ("col", "floor", "link", "region", "main", "level", "y"):
            assert np.array_equal(getattr(a, k), getattr(b, k)), k
        tc = walls_too_close(walls, origin, PARAMS.cell, full.shape, max(a.levels, 1), c)
        ga = grid_from_surface(a, c, origin, too_close=tc)
        gb = grid_from_surface(b, c, origin, too_close=tc)
        assert ga.to_bytes() == gb.to_bytes()


def test_heights_and_layers_built_in_blocks_are_the_same(monkeypatch):
    from tanktool.nav import walkable

    V, F = mesh_of("bridge")
    whole = walkable_surface(V, F, PARAMS, 2.0)
    g_whole = grid_from_surface(whole, 2.0, whole.hf.origin[[0, 2]])
    monkeypatch.setattr(walkable, "BLOCK", 7)   # many blocks, the last one short
    blocks = walkable_surface(V, F, PARAMS, 2.0)
    assert np.array_equal(blocks.height, whole.height)
    g_blocks = grid_from_surface(blocks, 2.0, blocks.hf.origin[[0, 2]])
    assert g_blocks.to_bytes() == g_whole.to_bytes()
    for a, b in zip(walkable.surface_layers(blocks), walkable.surface_layers(whole)):
        assert np.array_equal(a, b, equal_nan=True)
    exists = walkable.surface_layers(whole)[0]
    for level in range(len(exists)):
        assert np.array_equal(walkable.level_nodes(blocks, level), exists[level])


def test_flat_heights_in_blocks_of_faces_are_the_same(monkeypatch):
    from tanktool.geometry import heightfield
    from tanktool.geometry.heightfield import flat_heights

    V, F = mesh_of("two_storeys")
    whole = flat_heights(V, F)
    assert len(whole[0]) >= 2
    monkeypatch.setattr(heightfield, "FACE_BLOCK", 5)
    for a, b in zip(flat_heights(V, F), whole):
        assert np.array_equal(a, b)


def test_the_walls_exact_cuts_in_blocks_of_faces_are_the_same(monkeypatch):
    from tanktool.nav import level_walls as lw_mod

    V, F = mesh_of("two_storeys")
    whole = lw_mod.ExactCuts(V, F, 1.0, PARAMS.headroom, 0.01, 0.999, PARAMS.climb)
    monkeypatch.setattr(lw_mod, "FACE_BLOCK", 7)
    blocks = lw_mod.ExactCuts(V, F, 1.0, PARAMS.headroom, 0.01, 0.999, PARAMS.climb)
    for k in ("up", "up_height", "low", "cut_faces"):
        a, b = getattr(blocks, k), getattr(whole, k)
        assert a.dtype == b.dtype and np.array_equal(a, b), k
    assert len(whole.up) > 0


def test_the_move_table_made_row_by_row_is_layered_moves_table():
    from tanktool.nav.path import _LazyMoves, layered_moves

    V, F = mesh_of("bridge")
    s = walkable_surface(V, F, PARAMS, 1.0)
    grids = [grid_from_surface(s, 1.0, s.hf.origin[[0, 2]])]
    rng = np.random.default_rng(5)
    valid = rng.random((2, 9, 11)) < 0.7
    link = rng.integers(-1, 2, size=(2, 9, 11, 4)).astype(np.int8)
    grids.append(NavGrid(np.zeros(2), 1.0, (9, 11), valid, *(np.zeros(valid.shape, np.int32),) * 4,
                         valid.copy(), 1.0, link=link))
    for g in grids:
        table, _ = layered_moves(g)
        lazy = _LazyMoves(g)
        lazy.MAX_KEPT = 50                       # dropped and made again on the way
        for m in list(range(len(table))) + [3, 0, len(table) - 1]:
            assert lazy[m] == tuple(table[m]), m
        assert (table >= 0).sum() > 50
