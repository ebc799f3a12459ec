"""2D floor plans (.dxf, .svg): lines become walls of a height and thickness."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import shapely
import trimesh
from click.testing import CliRunner

from tanktool.arena import load_arena
from tanktool.importer import import_arena
from tanktool.cli.main import cli
from tanktool.errors import ArenaError, FormatError
from tanktool.formats.floorplan import extrude, load_scene, plan_walls, read_plan
from tanktool.formats.models import load_scene as load_world_scene

PLANS = Path(__file__).resolve().parent / "data" / "plans"


def _same(line: np.ndarray, ref: list) -> bool:
    ref_a = np.asarray(ref, dtype=float)
    return line.shape == ref_a.shape and np.allclose(line, ref_a)


def test_dxf_entities_become_polylines_text_is_ignored():
    lines = read_plan(PLANS / "room.dxf")
    assert len(lines) == 5                       # polyline, 3 lines, circle; not the TEXT
    closed = [ln for ln in lines if np.allclose(ln[0], ln[-1])]
    assert len(closed) == 2                      # the outer polyline and the circle
    assert any(_same(ln, [[15, 0], [15, 18]]) for ln in lines)


def test_svg_elements_become_polylines_in_the_files_own_numbers():
    lines = read_plan(PLANS / "yard.svg")
    assert len(lines) == 4
    assert any(_same(ln, [[40, 40], [40, 15], [50, 15]]) for ln in lines)
    pts = np.concatenate(lines)
    assert np.allclose(pts.min(axis=0), [0, 0]) and np.allclose(pts.max(axis=0), [60, 40])


def test_corners_are_mitred_whether_drawn_as_one_polyline_or_separate_lines():
    t = 0.5
    one = plan_walls([np.array([[0, 0], [10, 0], [10, 10]], float)], t)
    two = plan_walls([np.array([[0, 0], [10, 0]], float), np.array([[10, 0], [10, 10]], float)], t)
    assert one.geom_type == two.geom_type == "Polygon"
    assert one.symmetric_difference(two).area < 1e-9
    # flat ends, mitred corner: exactly two 10 x 0.5 strips sharing a 0.25 x 0.25 corner
    assert one.area == pytest.approx(2 * 10.25 * t - t * t)
    assert one.bounds == pytest.approx((0, -0.25, 10.25, 10))


def test_closed_polyline_is_a_ring_of_wall():
    ring = plan_walls([np.array([[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]], float)], 1.0)
    assert ring.geom_type == "Polygon" and len(ring.interiors) == 1
    assert ring.area == pytest.approx(11 * 11 - 9 * 9)


def test_extrusion_is_a_closed_solid_of_area_times_height():
    fp = shapely.difference(shapely.box(0, 0, 6, 4), shapely.box(1, 1, 5, 3))   # a ring with a hole
    v, f = extrude(fp, 2.5)
    m = trimesh.Trimesh(v, f, process=True)
    assert m.is_watertight and m.is_winding_consistent
    assert m.volume == pytest.approx(fp.area * 2.5)           # positive: faces point outwards


def test_plan_scene_is_z_up_with_plan_y_stored_negated():
    scene = load_scene(PLANS / "yard.svg", wall_height=2.0, wall_thickness=0.4)
    walls = scene.geometry["walls"]
    assert walls.bounds[1][2] == pytest.approx(2.0) and walls.bounds[0][2] == pytest.approx(0.0)
    assert walls.bounds[0][1] == pytest.approx(-40.2) and walls.bounds[1][1] == pytest.approx(0.2)
    # in the world frame (Y up) the plan's (x, y) are the arena's (x, z)
    world = load_world_scene(PLANS / "yard.svg", wall_height=2.0, wall_thickness=0.4)
    b = trimesh.util.concatenate(world.dump()).bounds
    assert np.allclose(b[:, 1], [0.0, 2.0]) and np.allclose(b[:, 2], [-0.2, 40.2])


@pytest.fixture(scope="module")
def room(tmp_path_factory):
    return import_arena(PLANS / "room.dxf", tmp_path_factory.mktemp("plan") / "room",
                        wall_height=3.0, wall_thickness=0.5)


def test_dxf_plan_imports_to_a_bundle_with_the_drawings_coordinates(room):
    a = load_arena(room.path)
    assert a.toml["source"]["wall_height"] == 3.0 and a.toml["source"]["wall_thickness"] == 0.5
    assert a.toml["source"]["up"] == "z"
    assert np.allclose(a.bounds, [[-0.75, -0.75], [40.75, 30.75]])  # inner faces 0.25 in, grown 1 m
    seg = a.walls.segments
    # the T wall off the south wall, both faces at x = 15 +- 0.25, up to z = 18 (+ nothing: flat end)
    t_wall = seg[np.all(np.isclose(seg[:, :, 0], 14.75), axis=1) | np.all(np.isclose(seg[:, :, 0], 15.25), axis=1)]
    assert len(t_wall) == 2
    assert np.allclose(sorted(t_wall[:, :, 1].ravel()), [0.25, 0.25, 18, 18])
    # the inner faces of the outer polyline
    assert np.isclose(seg[:, :, 0], 0.25).all(axis=1).any() and np.isclose(seg[:, :, 1], 29.75).all(axis=1).any()
    # the L drawn as two lines is mitred: its outer corner is at (24.75, 22.25)
    assert np.isclose(seg.reshape(-1, 2), [24.75, 22.25]).all(axis=1).any()
    assert 2 <= len(a.spawns) <= 8  # where the largest tank fits, a tank's length apart


def test_svg_plan_on_the_command_line(tmp_path):
    out = tmp_path / "yard"
    res = CliRunner().invoke(cli, ["import-arena", str(PLANS / "yard.svg"), "-o", str(out),
                                   "--wall-height", "2.5", "--wall-thickness", "0.5"])
    assert res.exit_code == 0, res.output
    assert "arena 'yard': 1 level, 18 walls + 4 auxiliary, 8 spawns" in res.output
    a = load_arena(out)
    # the wall from (20, 0) to (20, 25) in the SVG: faces at x = 19.75 and 20.25 up to z = 25
    seg = a.walls.segments
    face = seg[np.all(np.isclose(seg[:, :, 0], 19.75), axis=1)]
    assert len(face) == 1 and np.allclose(sorted(face[0, :, 1]), [0.25, 25])


@pytest.mark.parametrize("name, args, message", [
    ("broken_number.dxf", [], "broken_number.dxf:62: group code 20 expects a number, got 'ten'"),
    ("broken_xml.svg", [], "broken_xml.svg:3: not well-formed SVG/XML"),
    ("broken_points.svg", [], "broken_points.svg:4: <polyline> points expects numbers, got 'five'"),
    ("room.dxf", ["--wall-height", "0.5"], "--wall-height (0.5) must be above the cut --height (1)"),
    ("room.dxf", ["--wall-thickness", "-1"], "--wall-thickness must be a positive number"),
    ("room.dxf", ["--up", "y"], "--up does not apply to a floor plan"),
])
def test_bad_plans_are_one_line_exit_2_and_nothing_written(tmp_path, name, args, message):
    out = tmp_path / "bad"
    res = CliRunner().invoke(cli, ["import-arena", str(PLANS / name), "-o", str(out), *args])
    assert res.exit_code == 2, res.output
    assert message in res.output and "Traceback" not in res.output
    assert not out.exists()


def test_wall_options_are_refused_for_meshes(tmp_path, data_dir):
    with pytest.raises(FormatError, match="apply only to .dxf/.svg floor plans"):
        import_arena(data_dir / "bzw" / "simple.bzw", tmp_path / "x", wall_thickness=1.0)
    with pytest.raises(ArenaError, match="must be above the cut"):
        import_arena(PLANS / "yard.svg", tmp_path / "y", wall_height=1.0)


def test_empty_and_binary_dxf(tmp_path):
    empty = tmp_path / "e.dxf"
    empty.write_text("0\nSECTION\n2\nENTITIES\n0\nENDSEC\n0\nEOF\n")
    with pytest.raises(FormatError, match="no lines or polylines"):
        read_plan(empty)
    binary = tmp_path / "b.dxf"
    binary.write_bytes(b"AutoCAD Binary DXF\r\n\x1a\x00")
    with pytest.raises(FormatError, match="byte 0: binary DXF is not supported"):
        read_plan(binary)


def test_closed_shapes_with_nothing_inside_are_filled_but_the_outer_wall_stays_a_ring():
    outer = np.array([[0, 0], [20, 0], [20, 20], [0, 20], [0, 0]], float)
    pillar = np.array([[5, 5], [7, 5], [7, 7], [5, 7], [5, 5]], float)
    yard = np.array([[10, 10], [18, 10], [18, 18], [10, 18], [10, 10]], float)
    post = np.array([[13, 13], [15, 13]], float)                   # a line inside the yard
    fp = plan_walls([outer, pillar, yard, post], 0.5)
    assert fp.covers(shapely.Point(6, 6))                         # the pillar is solid
    assert not fp.covers(shapely.Point(12, 12))                   # the yard (it encloses a wall) is not
    assert not fp.covers(shapely.Point(3, 15))                    # nor the arena inside the outer wall
    assert not plan_walls([outer], 0.5).covers(shapely.Point(10, 10))   # a lone closed shape is a ring


def test_round_pillar_of_the_room_is_solid(room):
    seg = room.walls.segments
    r = np.hypot(seg[:, :, 0] - 8, seg[:, :, 1] - 22)
    near = r.max(axis=1) < 3
    assert near.any() and (r[near] > 2.1).all()                   # only the pillar's outside face
