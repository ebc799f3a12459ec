"""What the import lets go of before its grid stage, and the report's blocked loops
(docs/speed.md, "Memory of large imports"): same results, less held at once."""

from __future__ import annotations

import numpy as np
import pytest

from tanktool.importer import import_arena
from tanktool.nav import surface_report
from tests.test_import_arena import write_room


def _steep_whole(vertices: np.ndarray, faces: np.ndarray, max_slope: float) -> tuple[np.ndarray, np.ndarray]:
    """steep_faces as it was before the blocks: the whole model at once."""
    tri = vertices[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(n, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        ny = np.where(norm > 0, n[:, 1] / norm, 0.0)
    sel = np.flatnonzero((ny > surface_report.WALL_NY) & (ny <= np.cos(np.radians(max_slope))))
    return sel, 0.5 * n[sel, 1]


def test_steep_faces_in_blocks_are_the_whole_models(monkeypatch):
    import tanktool.geometry.heightfield as heightfield

    rng = np.random.default_rng(7)
    vertices = rng.normal(size=(500, 3))
    faces = rng.integers(0, 500, size=(5000, 3))
    monkeypatch.setattr(heightfield, "FACE_BLOCK", 333)   # blocks that do not divide the faces
    for f in (faces, faces[:0], faces[:7]):
        got, want = surface_report.steep_faces(vertices, f, 35.0), _steep_whole(vertices, f, 35.0)
        assert len(want[0]) or len(f) < 10
        for a, b in zip(got, want):
            assert a.dtype == b.dtype and np.array_equal(a, b)


def test_import_lets_go_of_the_analysis_before_the_grid(tmp_path):
    model = write_room(tmp_path / "room.obj")
    r = import_arena(model, tmp_path / "room")
    assert r.grid is not None and r.grid.grid.valid.any()
    lv = r.levels
    assert lv.surface is None and lv.vertices is None and lv.faces is None and lv.grid is None
    assert r.faces == 12 * 6 and len(lv.levels) == 1
    # without the grid stage the analysis grid is what the import has: kept
    r = import_arena(model, tmp_path / "room2", grid=False)
    assert r.grid is None and r.levels.grid is not None and r.levels.surface is None


@pytest.mark.parametrize("bucket", [8.0, 0.5])   # 0.5: faces over 4096 buckets, tested by every point
def test_faces_above_for_a_few_points_counts_as_the_bucket_index(monkeypatch, bucket):
    from tanktool.geometry import segments

    rng = np.random.default_rng(11)
    for trial in range(6):
        vertices = rng.uniform(-50, 50, size=(300, 3))
        if trial % 2:
            vertices = np.round(vertices)   # shared edges and corners: the half-open edges matter
        faces = rng.integers(0, 300, size=(2000, 3))
        points = np.concatenate([rng.uniform(-60, 60, size=(12, 3)), vertices[:4]])
        monkeypatch.setattr(segments, "FEW_POINTS", 0)
        want = segments.faces_above(points, vertices, faces, bucket)
        monkeypatch.setattr(segments, "FEW_POINTS", 32)
        monkeypatch.setattr(segments, "FEW_BLOCK", 97)
        assert np.array_equal(segments.faces_above(points, vertices, faces, bucket), want)


def test_member_is_isin():
    rng = np.random.default_rng(5)
    labels = rng.integers(0, 40, size=1000).astype(np.int32)
    for keep in (np.array([3, 7, 39]), np.array([], dtype=np.int64), np.array([-1, 0, 100])):
        assert np.array_equal(surface_report._member(labels, keep), np.isin(labels, keep))
    neg = labels - 5   # negative labels: isin itself
    assert np.array_equal(surface_report._member(neg, np.array([-5, 2])), np.isin(neg, [-5, 2]))


def test_focus_box_in_blocks_is_the_whole_models(monkeypatch):
    import tanktool.geometry.heightfield as heightfield
    from tanktool.nav.arena_levels import focus_box

    plane = [[-1000, 0, -1000], [1000, 0, -1000], [1000, 0, 1000], [-1000, 0, 1000]]
    rng = np.random.default_rng(2)
    vertices = np.concatenate([plane, rng.uniform(-50, 50, size=(50, 3))])
    faces = np.concatenate([[[0, 1, 2], [0, 2, 3]], rng.integers(4, 54, size=(25, 3))])
    want = focus_box(vertices, faces, 3.0)
    monkeypatch.setattr(heightfield, "FACE_BLOCK", 4)
    got = focus_box(vertices, faces, 3.0)
    rest = vertices[faces[2:]].reshape(-1, 3)[:, [0, 2]]
    assert np.array_equal(got, want) and np.array_equal(got, [rest.min(axis=0) - 3.0, rest.max(axis=0) + 3.0])
    assert focus_box(vertices, faces[:2], 3.0) is None   # nothing but the plane


def test_one_placed_mesh_is_analysed_without_a_copy(tmp_path):
    from pathlib import Path

    from tanktool.formats.models import load_scene
    from tanktool.importer import _one_mesh

    model = write_room(tmp_path / "room.obj")
    scene = load_scene(model)
    mesh = _one_mesh(Path(model), scene, 0.5, None)
    assert mesh is next(iter(scene.geometry.values()))   # the scene's own mesh, not dump()'s copy
    (dumped,) = scene.dump()
    assert np.array_equal(mesh.vertices, dumped.vertices) and np.array_equal(mesh.faces, dumped.faces)


@pytest.mark.parametrize("name", ["two_storeys", "fort", "bridge"])
def test_the_analysis_after_letting_go_is_the_whole_surfaces(name):
    """keep_for_analysis (the heightfield's spans and the ceilings let go), the report's
    answers kept with the surface and the tank grid without its runs: the same walls,
    report, spawns and grid nodes as from the whole surface."""
    import copy

    from tanktool.nav import arena_levels
    from tanktool.nav.level_walls import level_walls
    from tanktool.nav.walkable import walkable_surface
    from tests.test_walkable import PARAMS, TANK, mesh_of

    V, F = mesh_of(name)
    p = PARAMS
    whole = walkable_surface(V, F, p, TANK.radius)
    kept = copy.copy(whole)
    kept.derived = {}
    arena_levels.keep_for_analysis(kept)
    assert len(kept.hf.col) == int(whole.hf.low_headroom.sum()) and len(kept.ceil) == 0
    a = level_walls(whole, V, F, 1.0, p.headroom, p.climb, 0.01, p.max_slope)
    b = level_walls(kept, V, F, 1.0, p.headroom, p.climb, 0.01, p.max_slope)
    assert np.array_equal(a.walls.segments, b.walls.segments) and np.array_equal(a.walls.level, b.walls.level)
    want = surface_report.left_out(whole, V, F, p, TANK.radius)
    assert surface_report.left_out(kept, V, F, p, TANK.radius) == want
    assert surface_report.asked(kept, TANK.radius, (V, F))
    unreach = surface_report.unreachable(kept, TANK.radius, V, F)
    kept.clearance, kept.region = None, kept.region[:0]   # as the import does before its picture
    assert np.array_equal(surface_report.unreachable(kept, TANK.radius, V, F), unreach)
    full = arena_levels.analyse_arena(V, F, p, TANK)
    lean = arena_levels.analyse_arena(V, F, p, TANK, keep_runs=False)
    assert np.array_equal(full.spawns, lean.spawns) and full.left_out == lean.left_out
    assert np.array_equal(full.grid.valid, lean.grid.valid) and lean.grid.row_index.size == 0
    assert full.grid.row_index.shape == full.grid.valid.shape


def test_a_smaller_vehicles_grid_of_the_same_levels_shares_and_equals_its_own(tmp_path):
    """The grid stage's smaller vehicle, whose reseed finds the larger grid's levels
    again, shares that grid's heights and links (the surface let go before it is built):
    the same grid as build-navgrid builds for it alone from the model."""
    import dataclasses

    from tanktool.grid_files import build_grid, open_target
    from tanktool.formats.vehicle_grids import vehicle_grids
    from tests.level_helpers import import_level

    bundle = import_level(tmp_path, "fort")
    target = open_target(bundle)
    built = build_grid(target)
    (name, (c, spawns)), = vehicle_grids(target.toml, target.manifest).items()
    shared, big = built.vehicles[name].grid, built.grid
    assert shared.height is big.height and shared.link is big.link
    own = build_grid(dataclasses.replace(target, spawns=spawns, toml={**target.toml, "grids": {}}),
                     cell=built.cell, clearance=c)
    assert not own.vehicles   # built from the model, by grid_from_surface
    alone = own.grid
    for k in ("valid", "row_index", "row_total", "col_index", "col_total", "reachable", "height", "link"):
        assert np.array_equal(getattr(shared, k), getattr(alone, k), equal_nan=k == "height"), k
    assert shared.spawn_nodes == alone.spawn_nodes


def test_label_sizes_in_blocks_are_bincounts(monkeypatch):
    from tanktool.nav import level_walls

    rng = np.random.default_rng(3)
    lab = rng.integers(0, 50, size=(37, 41)).astype(np.int32)
    monkeypatch.setattr(level_walls, "BLOCK", 97)   # blocks that do not divide the cells
    got = level_walls._label_sizes(lab, 60)
    assert np.array_equal(got, np.bincount(lab.ravel(), minlength=61))


@pytest.mark.parametrize("name", ["two_storeys", "fort"])
def test_walls_in_small_blocks_are_the_walls(monkeypatch, name):
    """level_walls' blocked passes (_same_level_links' rows, _exact_floors' flat cells,
    _label_sizes) with blocks far smaller than the level: the same walls."""
    from tanktool.nav import level_walls as lw
    from tanktool.nav.walkable import walkable_surface
    from tests.test_walkable import PARAMS, TANK, mesh_of

    V, F = mesh_of(name)
    s = walkable_surface(V, F, PARAMS, TANK.radius)
    args = (V, F, 1.0, PARAMS.headroom, PARAMS.climb, 0.01, PARAMS.max_slope)
    want = lw.level_walls(s, *args)
    monkeypatch.setattr(lw, "BLOCK", 61)
    got = lw.level_walls(s, *args)
    assert np.array_equal(got.walls.segments, want.walls.segments)
    assert [r.flat_heights for r in got.regions] == [r.flat_heights for r in want.regions]


def test_a_read_obj_keeps_no_copy_of_its_file(tmp_path):
    """trimesh's LoadSource kept the file's bytes (file_obj) with the scene through the
    import; the scene is let go of it, and reads the same."""
    from tanktool.formats.models import load_scene

    model = write_room(tmp_path / "room.obj")
    scene = load_scene(model)
    assert getattr(scene.source, "file_obj", None) is None
    (mesh,) = scene.geometry.values()
    assert len(mesh.faces) == 12 * 6 and getattr(mesh.source, "file_obj", None) is None


def test_walls_too_close_in_bands_is_the_whole_grids(monkeypatch):
    from tanktool.nav import arena_levels
    from tanktool.nav.navgrid import on_wall_tolerance, too_close

    rng = np.random.default_rng(9)
    a = rng.uniform(0, 40, size=(30, 2))
    seg = np.stack([a, a + rng.uniform(-6, 6, size=(30, 2))], axis=1)

    class Walls:
        segments, level, bounds = seg, np.arange(30) % 2, np.array([[0.0, 0.0], [40.0, 40.0]])

    origin, shape = np.array([-1.0, -2.0]), (83, 79)
    monkeypatch.setattr(arena_levels, "BAND_NODES", 500)   # bands of 6 rows, the last shorter
    got = arena_levels.walls_too_close(Walls, origin, 0.5, shape, 2, 1.3)
    for lv in range(2):
        want = too_close(seg[Walls.level == lv], origin, 0.5, shape, 1.3, tol=on_wall_tolerance(Walls.bounds))
        assert np.array_equal(got[lv], want) and want.any() and not want.all()
