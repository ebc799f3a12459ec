"""Wall extraction on small hand-made arenas and on a real level mesh."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import shapely
import trimesh

from tanktool.errors import ArenaError
from tanktool.geometry.spawns import place_spawns
from tanktool.geometry.walls import extract_walls, find_floor, slice_mesh

DATA = Path(__file__).resolve().parent / "data"


def slab(x0, z0, x1, z1, y0=-0.5, y1=0.0):
    """An axis-aligned box from (x0, y0, z0) to (x1, y1, z1)."""
    b = trimesh.creation.box(extents=[x1 - x0, y1 - y0, z1 - z0])
    b.apply_translation([(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2])
    return b


def room(size=40.0, t=1.0, h=4.0):
    """A floor slab and four wall boxes: free inside [t, size - t]^2."""
    return [
        slab(0, 0, size, size),
        slab(0, 0, size, t, 0, h), slab(0, size - t, size, size, 0, h),
        slab(0, 0, t, size, 0, h), slab(size - t, 0, size, size, 0, h),
    ]


def join(parts):
    m = trimesh.util.concatenate(parts)
    return m.vertices, m.faces


def midpoints_inside(solid, walls, eps=1e-3):
    """Wall midpoints pushed a little against their normal must be in solid
    (or on a thin wall, nothing): used to check normals face free space."""
    mid = walls.segments.mean(axis=1)
    n = walls.normals
    into_free = mid + eps * n
    into_solid = mid - eps * n
    return into_free, into_solid


def test_room_is_four_walls_with_inward_normals():
    ex = extract_walls(*join(room()))
    w = ex.walls
    assert len(w) == 4
    assert ex.floor_y == pytest.approx(0.0)
    pts = w.segments.reshape(-1, 2)
    assert np.allclose(np.sort(np.unique(pts[:, 0])), [1, 39])
    assert np.allclose(np.sort(np.unique(pts[:, 1])), [1, 39])
    # every normal points to the centre of the room
    mid = w.segments.mean(axis=1)
    assert ((np.array([20, 20]) - mid) * w.normals).sum(axis=1).min() > 0
    # auxiliary rectangle encloses the walls with a margin
    (x0, z0), (x1, z1) = w.bounds
    assert x0 < 1 and z0 < 1 and x1 > 39 and z1 > 39
    assert shapely.area(ex.free) == pytest.approx(38 * 38, rel=1e-6)


def test_overlapping_boxes_leave_no_wall_buried_in_solid():
    parts = room() + [slab(10, 10, 20, 20, 0, 3), slab(15, 15, 25, 25, 0, 3), slab(17, 17, 19, 19, 0, 3.5)]
    ex = extract_walls(*join(parts))
    w = ex.walls
    into_free, into_solid = midpoints_inside(ex.solid, w)
    # the small box is inside the overlap: nothing of it may remain
    assert not np.any(np.all((w.segments > 16.9) & (w.segments < 19.1), axis=(1, 2)))
    # the union outline of the two pillars is 8 walls, plus the room's 4
    assert len(w) == 12
    assert shapely.contains_xy(ex.free, into_free[:, 0], into_free[:, 1]).all()
    assert not shapely.contains_xy(ex.free, into_solid[:, 0], into_solid[:, 1]).any()


def test_single_quad_wall_is_a_thin_wall_with_both_normals():
    quad = trimesh.Trimesh(vertices=[[10, 0, 20], [30, 0, 20], [30, 3, 20], [10, 3, 20]], faces=[[0, 1, 2], [0, 2, 3]])
    ex = extract_walls(*join(room() + [quad]))
    w = ex.walls
    on_line = np.all(np.isclose(w.segments[:, :, 1], 20), axis=1)
    assert on_line.sum() == 2
    assert ex.thin_walls == 2
    seg = w.segments[on_line]
    assert np.allclose(np.sort(seg[:, :, 0], axis=1), [[10, 30], [10, 30]])
    normals = w.normals[on_line]
    assert np.allclose(sorted(normals[:, 1]), [-1, 1])


def test_collinear_pieces_merge_and_floating_geometry_is_ignored():
    # the north wall made of four abutting boxes, and a box floating at 5 m
    parts = [slab(0, 0, 40, 40), slab(0, 0, 40, 1, 0, 4), slab(0, 0, 1, 40, 0, 4), slab(39, 0, 40, 40, 0, 4)]
    parts += [slab(10 * k, 39, 10 * k + 10, 40, 0, 4) for k in range(4)]
    parts += [slab(15, 15, 25, 25, 5, 6)]
    ex = extract_walls(*join(parts))
    assert len(ex.walls) == 4
    north = ex.walls.segments[np.all(np.isclose(ex.walls.segments[:, :, 1], 39), axis=1)]
    assert len(north) == 1
    assert abs(north[0, 1, 0] - north[0, 0, 0]) == pytest.approx(38)


def test_inverted_winding_and_duplicate_vertices():
    pillar = slab(18, 18, 22, 22, 0, 3)
    pillar.invert()  # normals point in: its winding alone would call it a hole
    m = trimesh.util.concatenate(room() + [pillar])
    # split every face's vertices apart, as .3ds files with seams do
    v = m.vertices[m.faces.reshape(-1)]
    f = np.arange(len(v)).reshape(-1, 3)
    ex = extract_walls(v, f)
    assert len(ex.walls) == 8
    assert not shapely.contains_xy(ex.free, 20.0, 20.0)
    assert shapely.contains_xy(ex.free, 10.0, 10.0)


def test_round_off_between_split_vertices_is_merged():
    # every face with its own vertices, each jittered by up to 1e-6 m (float32
    # round-off of a 3DS file): loops must still close and the pillar stay solid
    m = trimesh.util.concatenate(room() + [slab(18, 18, 22, 22, 0, 3)])
    v = m.vertices[m.faces.reshape(-1)]
    v = v + np.random.default_rng(1).uniform(-1e-6, 1e-6, v.shape)
    ex = extract_walls(v, np.arange(len(v)).reshape(-1, 3))
    assert len(ex.walls) == 8 and ex.thin_walls == 0
    assert not shapely.contains_xy(ex.free, 20.0, 20.0)
    # a wall whose top is exactly at the cut height is a wall (the plane moves down)
    ex = extract_walls(*join(room() + [slab(18, 18, 22, 22, 0, 1.0)]))
    assert len(ex.walls) == 8


def test_pieces_shorter_than_tolerance_are_dropped():
    # a 4 mm bump on the east wall
    parts = room() + [slab(38.996, 10, 39.0, 30, 0, 4)]
    ex = extract_walls(*join(parts), tolerance=0.01)
    assert len(ex.walls) == 4
    ex_fine = extract_walls(*join(parts), tolerance=0.001)
    assert len(ex_fine.walls) == 8


def test_floor_rule_picks_lowest_large_level():
    # a small sunken pit at -2 (4 m^2) and the big floor at 0
    pit = slab(5, 5, 7, 7, -3, -2)
    fl = find_floor(*join(room() + [pit]))
    assert fl.y == pytest.approx(0.0)
    assert [h for h, _ in fl.levels][0] == pytest.approx(-2.0)


def test_cut_inside_solid_is_an_error():
    block = slab(0, 0, 40, 40, -0.5, 5)
    with pytest.raises(ArenaError, match="no (free space|upward)"):
        extract_walls(*join([slab(0, 0, 40, 40, -1, -0.5), block]))


def test_slice_segments_close_into_rings_and_carry_normals():
    b = slab(0, 0, 2, 2, 0, 2)
    seg, nrm, nodes = slice_mesh(b.vertices, b.faces, 1.0)
    assert len(seg) == 8
    assert (np.bincount(nodes.ravel()) == 2).all()
    # normals on the right of each segment and pointing out of the box
    mid = seg.mean(axis=1)
    assert ((mid - 1.0) * nrm).sum(axis=1).min() > 0


def test_spawns_spread_and_face_the_centre():
    ex = extract_walls(*join(room(60)))
    sp = place_spawns(ex.free, ex.walls.bounds)
    assert sp.shape == (8, 3)
    d = np.hypot(*(sp[:, None, :2] - sp[None, :, :2]).transpose(2, 0, 1))
    assert d[~np.eye(8, dtype=bool)].min() > 10  # spread over a 58 m room
    wall_dist = np.min(np.abs(np.concatenate([sp[:, :2] - 1, 59 - sp[:, :2]], axis=1)), axis=1)
    assert wall_dist.min() >= 2.5 - 1e-9
    to_c = np.array([30, 30]) - sp[:, :2]
    far = np.hypot(*to_c.T) >= 1.0  # one on the centre itself faces +x
    assert np.allclose(sp[~far, 2], 0.0)
    f = np.stack([np.cos(sp[:, 2]), np.sin(sp[:, 2])], axis=1)
    assert ((f * to_c).sum(axis=1)[far] / np.hypot(*to_c[far].T)).min() > 0.999


@pytest.mark.skipif(not (DATA / "arenas_obj" / "dungeon.obj").exists(), reason="test model missing")
def test_dungeon_main_level():
    m = trimesh.load(DATA / "arenas_obj" / "dungeon.obj", force="mesh", process=False)
    ex = extract_walls(m.vertices, m.faces)
    # the big storey at y ~ 10 (1200 m^2 of floor), not the small pieces near y = 0
    assert ex.floor_y == pytest.approx(10.0, abs=0.05)
    assert 1000 < ex.free.area < 1400
    w = ex.walls
    into_free = w.segments.mean(axis=1) + 0.02 * w.normals
    assert shapely.contains_xy(ex.free, into_free[:, 0], into_free[:, 1]).mean() > 0.95
    sp = place_spawns(ex.free, w.bounds)
    assert shapely.contains_xy(ex.free, sp[:, 0], sp[:, 1]).all()


@pytest.mark.skipif(not (DATA / "arenas_obj" / "house.obj").exists(), reason="test model missing")
def test_house_ground_floor():
    m = trimesh.load(DATA / "arenas_obj" / "house.obj", force="mesh", process=False)
    ex = extract_walls(m.vertices, m.faces)
    # the ground floor at y ~ 0.3 (not the upper storey at ~ 4.5 or the roof)
    assert ex.floor_y == pytest.approx(0.3, abs=0.05)
    assert 150 < ex.free.area < 260  # a ~15 x 15 m ground floor minus its walls
    w = ex.walls
    into_free = w.segments.mean(axis=1) + 0.005 * w.normals
    assert shapely.contains_xy(ex.free, into_free[:, 0], into_free[:, 1]).mean() > 0.95


def test_single_sided_room_shell_gives_its_outline_once():
    # a level built of single faces: a floor quad and four inward-facing wall quads
    s = 20.0
    v = [[0, 0, 0], [s, 0, 0], [s, 0, s], [0, 0, s], [0, 3, 0], [s, 3, 0], [s, 3, s], [0, 3, s]]
    floor = [[0, 2, 1], [0, 3, 2]]  # wound to face +y
    walls = []
    for a, b in ((0, 1), (1, 2), (2, 3), (3, 0)):
        walls += [[a, b, b + 4], [a, b + 4, a + 4]]
    mesh = trimesh.Trimesh(v, floor + walls, process=False)
    mesh.fix_normals()  # whatever the winding, the result must be the same
    ex = extract_walls(mesh.vertices, mesh.faces)
    assert ex.floor_y == pytest.approx(0.0)
    assert len(ex.walls) == 4 and ex.thin_walls == 0
    assert shapely.area(ex.free) == pytest.approx(s * s)
    mid = ex.walls.segments.mean(axis=1)
    assert ((np.array([s / 2, s / 2]) - mid) * ex.walls.normals).sum(axis=1).min() > 0


@pytest.mark.parametrize("seed", range(8))
def test_random_overlapping_boxes_invariants(seed):
    """Random crates (overlapping, nested, some floating) in a walled room: every
    wall has free space in front, solid (or the outside) behind, and no wall lies
    inside the union of the crates.  Odd seeds make it messy: some crates wound
    inside out, every face with its own jittered vertices."""
    rng = np.random.default_rng(seed)
    messy = seed % 2 == 1
    parts = room(60)
    crates = []
    for _ in range(14):
        x, z = rng.uniform(5, 50, 2)
        w, d = rng.uniform(0.5, 9, 2)
        y0 = 0.0 if rng.random() < 0.8 else 1.5  # some float above the cut
        crates.append((x, z, x + w, z + d, y0))
        crate = slab(x, z, x + w, z + d, y0, y0 + rng.uniform(1.2, 4))
        if messy and rng.random() < 0.3:
            crate.invert()
        parts.append(crate)
    v, f = join(parts)
    if messy:
        v = v[f.reshape(-1)] + rng.uniform(-1e-6, 1e-6, (f.size, 3))
        f = np.arange(len(v)).reshape(-1, 3)
    ex = extract_walls(v, f)
    w = ex.walls
    mid = w.segments.mean(axis=1)
    front = mid + 0.004 * w.normals
    back = mid - 0.004 * w.normals
    assert shapely.contains_xy(ex.free, front[:, 0], front[:, 1]).all()
    assert not shapely.contains_xy(ex.free, back[:, 0], back[:, 1]).any()
    grounded = shapely.union_all([shapely.box(a, b, c, d) for a, b, c, d, y0 in crates if y0 == 0.0])
    inner = shapely.buffer(grounded, -0.02, join_style="mitre")
    assert not shapely.contains_xy(inner, mid[:, 0], mid[:, 1]).any()
    # the free space is the room minus the grounded crates, without pockets
    # narrower than 1 m, up to the 1 cm snapping grid along its outline
    parts = shapely.get_parts(shapely.difference(shapely.box(1, 1, 59, 59), grounded))
    expect = shapely.union_all([p for p in parts if not shapely.buffer(p, -0.5, quad_segs=2).is_empty])
    assert shapely.area(shapely.symmetric_difference(expect, ex.free)) < 0.006 * shapely.length(expect)


# ---------------------------------------------------------------------------
# malformed meshes from any caller: one clear ArenaError, never an IndexError or a wrong vertex


@pytest.mark.parametrize("bad, says", [
    ("two", "must be triangles"),      # an .obj face `f 1 2`
    ("flat", "must be triangles"),
    ("past", "vertex 99, outside 0..7"),
    ("negative", "vertex -1, outside 0..7"),   # numpy would count it from the end
    ("fraction", "not whole numbers"),          # astype(int) would truncate it
])
@pytest.mark.parametrize("fn", ["extract_walls", "find_floor", "slice_mesh", "floor_region"])
def test_malformed_faces_are_refused_by_every_entry(bad, says, fn):
    import trimesh

    from tanktool.errors import ArenaError
    from tanktool.geometry import walls as W

    box = trimesh.creation.box((10.0, 2.0, 10.0))
    v, f = np.asarray(box.vertices), np.asarray(box.faces)
    faces = {"two": f[:, :2], "flat": f.ravel(), "past": np.vstack([f, [[0, 1, 99]]]),
             "negative": np.vstack([f, [[0, 1, -1]]]), "fraction": f + 0.5}[bad]
    args = {"extract_walls": (v, faces), "find_floor": (v, faces), "slice_mesh": (v, faces, 0.0, 1e-6),
            "floor_region": (v, faces, 0.01)}[fn]
    with pytest.raises(ArenaError, match=says):
        getattr(W, fn)(*args)


def test_triangle_mesh_accepts_whole_float_indices_and_no_faces():
    from tanktool.geometry.walls import triangle_mesh

    v, f = triangle_mesh([[0, 0, 0], [1, 0, 0], [0, 0, 1]], np.array([[0.0, 1.0, 2.0]]))
    assert f.dtype == np.int64 and f.tolist() == [[0, 1, 2]] and v.dtype == np.float64
    assert triangle_mesh(v, [])[1].shape == (0, 3)


def test_a_floor_modelled_twice_keeps_its_outline_and_its_walls():
    """Duplicate faces (a floor exported twice over, decals on it) used to cancel every
    edge of the outline: no floor, no walls, and the import said no tank fits.  An edge
    is on the outline as many times as its uses one way outnumber the other way."""
    from tanktool.geometry.walls import floor_region
    from tanktool.nav.arena_levels import analyse_arena
    from tanktool.nav.walkable import WalkableParams
    from tanktool.fleet import Fleet

    v = np.array([[0, 0, 0], [50, 0, 0], [50, 0, 50], [0, 0, 50], [25, 0, 0], [25, 0, 50]], dtype=np.float64)
    f = np.array([[0, 2, 1], [0, 3, 2]])
    once = floor_region(v, f, 0.01)
    assert abs(once.area - 2500) < 1e-6
    half = np.array([[0, 5, 4], [0, 3, 5]])           # the left half laid again on top, sharing edges with it
    for faces in (np.vstack([f, f]), np.vstack([f, f[::-1], f]), np.vstack([f, half])):
        assert shapely.equals(floor_region(v, faces, 0.01), once)
    params = WalkableParams(cell=0.5, cell_height=0.1, max_slope=35.0, climb=0.9, headroom=2.35)
    tank = Fleet(radius=3.0, length=6.0, height=2.3)
    walls = [analyse_arena(v, faces, params, tank).walls.walls.segments for faces in (f, np.vstack([f, f]))]
    assert len(walls[0]) == 4 and np.allclose(walls[0], walls[1])
