"""BZFlag worlds (.bzw): the parser, the meshes it builds, and import-arena on them."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import trimesh
from click.testing import CliRunner

from tanktool.arena import load_arena
from tanktool.importer import import_arena
from tanktool.cli.main import cli
from tanktool.errors import FormatError
from tanktool.formats.bzw import (
    OUTER_WALL_HEIGHT,
    WORLD_SIZE,
    BzwObject,
    object_mesh,
    parse_bzw,
    world_meshes,
)

BZW = Path(__file__).resolve().parent / "data" / "bzw"


def _segments(walls) -> np.ndarray:
    return np.asarray(walls.segments, dtype=float).reshape(-1, 2, 2)


def _inner(walls, half: float) -> np.ndarray:
    """Walls that are not the world's outer edge at +-half."""
    seg = _segments(walls)
    on_edge = np.all(np.isclose(np.abs(seg[:, :, 0]), half), axis=1) | np.all(np.isclose(np.abs(seg[:, :, 1]), half), axis=1)
    return seg[~on_edge]


# ---------------------------------------------------------------- parser

def test_world_size_is_the_half_width_and_defaults_to_400(tmp_path):
    w = parse_bzw(tmp_path / "x.bzw", text="box\n position 0 0 0\n size 1 1 1\nend\n")
    assert w.size == WORLD_SIZE == 400.0
    v, f, _ = world_meshes(w)["ground"]
    assert v[:, 0].min() == -400 and v[:, 0].max() == 400          # an 800 x 800 world
    w = parse_bzw(BZW / "simple.bzw")
    assert w.size == 50.0
    assert w.counts() == {"box": 1}
    box = w.objects[0]
    assert box.size == (10.0, 5.0, 8.0) and box.line == 7 and w.warnings == []


def test_options_world_size_is_the_full_width(tmp_path):
    # `options -set _worldSize 200` used to be skipped: an 800 m world instead of 200 m
    text = "options\n  -c -j +r\n  -set _worldSize 200 -set _wallHeight 3\nend\nbox\n size 5 5 5\nend\n"
    w = parse_bzw(tmp_path / "o.bzw", text=text)
    assert w.size == 100.0 and w.wall_height == 3.0
    assert w.warnings == [f"{tmp_path / 'o.bzw'}:1: options that do not change the arena ignored: -c -j +r"]
    v, _, _ = world_meshes(w)["ground"]
    assert v[:, 0].min() == -100 and v[:, 0].max() == 100
    v, _, _ = world_meshes(w)["outer_walls"]
    assert v[:, 2].max() == 3.0
    # world size and _worldSize set one variable: the later wins, and a change is said
    text = "world\n size 60\nend\noptions -set _worldSize 300\nend\n"
    w = parse_bzw(tmp_path / "b.bzw", text=text)
    assert w.size == 150.0
    assert len(w.warnings) == 1 and ":4: options -set _worldSize 300 replaces world size 60 (line 2)" in w.warnings[0]
    w = parse_bzw(tmp_path / "c.bzw", text="options\n -set _worldSize 120\nend\nworld\n size 60\nend\n")
    assert w.size == 60.0 and w.warnings == []     # the same size twice: nothing to say
    for bad in ("-set _worldSize big", "-set _worldSize -5", "-set _wallHeight -1", "-set _worldSize 0"):
        with pytest.raises(FormatError) as e:
            parse_bzw(tmp_path / "d.bzw", text=f"options\n {bad}\nend\n")
        assert f"{tmp_path / 'd.bzw'}:2: options -set" in str(e.value) and "number" in str(e.value)
    # BZFlag accepts a zero wall height: no outer walls (issue 26)
    assert parse_bzw(tmp_path / "z.bzw", text="options\n -set _wallHeight 0\nend\n").walls is False
    with pytest.raises(FormatError) as e:
        parse_bzw(tmp_path / "e.bzw", text="options\n -set _worldSize 200\n")
    assert ":1: 'options' is never closed" in str(e.value)


def test_cli_options_world_size_gives_the_arena_its_size(tmp_path):
    src = tmp_path / "small.bzw"
    src.write_text("options\n  -set _worldSize 200\nend\nbox\n  position 20 20 0\n  size 5 5 5\nend\n")
    res = CliRunner().invoke(cli, ["import-arena", str(src), "-o", str(tmp_path / "small")])
    assert res.exit_code == 0, res.output
    assert "(202.0 x 202.0 m)" in res.output        # 200 m and the 1 m outer walls outside it
    assert "warning" not in res.output


def test_keywords_are_case_insensitive_and_comments_stripped(tmp_path):
    text = "WORLD\n Size 20 # half\nEND\nBox # a box\n POSITION 1 2 3\n Rotation 15\nEnd\n"
    w = parse_bzw(tmp_path / "c.bzw", text=text)
    assert w.size == 20.0
    assert w.objects[0].position == (1.0, 2.0, 3.0) and w.objects[0].rotation == 15.0


@pytest.mark.parametrize("text, line, what", [
    ("box\n position 0 zero 0\nend\n", 2, "'position' expects 3 numbers"),
    ("box\n size 1 2\nend\n", 2, "'size' expects 3 numbers, got 2"),
    ("world\n size -5\nend\n", 2, "must be positive"),
    ("end\n", 1, "'end' without an object"),
    ("\n\npyramid\n size 1 1 1\n", 3, "'pyramid' is never closed"),
    ("box\n rotation nan\nend\n", 2, "finite"),
    ("box\n size -1 2 3\nend\n", 1, "must not be negative"),
    ("define x\nbox\nend\n", 1, "'define' is never closed (expected 'enddef'"),
])
def test_malformed_files_name_the_line(tmp_path, text, line, what):
    p = tmp_path / "bad.bzw"
    with pytest.raises(FormatError) as e:
        parse_bzw(p, text=text)
    assert f"{p}:{line}:" in str(e.value) and what in str(e.value)


def test_unknown_objects_and_properties_are_warnings_with_their_lines():
    w = parse_bzw(BZW / "unknown.bzw")
    lines = {int(m.split(":")[1]): m for m in w.warnings}
    # the mesh at line 23 is built, the define at 37 is kept for groups (none uses it)
    assert sorted(lines) == [7, 18, 46, 55] and "pillar" in w.defines
    assert "options that do not change the arena ignored: -c -j" in lines[7]
    assert "'link'" in lines[18] and len(w.meshes) == 1
    assert "'spin'" in lines[46] and "drivethrough" in lines[55]
    # the mesh's nested drawinfo/lod/matref 'end's did not end the skip early, the
    # define's box stayed inside it, and the known objects after them were read
    assert w.counts() == {"teleporter": 1, "box": 1, "wall": 1}
    assert [o.line for o in w.objects] == [11, 43, 49]


# ---------------------------------------------------------------- meshes

@pytest.mark.parametrize("kind, size, volume", [
    ("box", (3.0, 2.0, 5.0), 2 * 3 * 2 * 2 * 5),
    ("pyramid", (3.0, 2.0, 6.0), (6 * 4) * 6 / 3),
    ("meshpyr", (3.0, 2.0, -6.0), (6 * 4) * 6 / 3),
])
def test_solids_are_closed_outward_meshes_of_the_right_volume(kind, size, volume):
    v, f = object_mesh(BzwObject(kind, 1, position=(5.0, -2.0, 1.0), size=size, rotation=37.0))
    m = trimesh.Trimesh(v, f, process=True)
    assert m.is_watertight and m.is_winding_consistent
    assert m.volume == pytest.approx(volume)                      # positive: faces wound outwards
    assert v[:, 2].min() == pytest.approx(1.0) and v[:, 2].max() == pytest.approx(1.0 + abs(size[2]))


def test_flipped_pyramid_has_its_apex_at_the_bottom():
    v, _ = object_mesh(BzwObject("pyramid", 1, size=(2.0, 2.0, 4.0), flipz=True))
    apex = v[4]
    assert apex[2] == pytest.approx(0.0) and np.allclose(v[:4, 2], 4.0)


def test_rotation_is_counter_clockwise_degrees_about_z():
    v, _ = object_mesh(BzwObject("box", 1, size=(4.0, 1.0, 1.0), rotation=90.0))
    # the long local x axis now runs along y
    assert np.ptp(v[:, 0]) == pytest.approx(2.0) and np.ptp(v[:, 1]) == pytest.approx(8.0)


def test_teleporter_is_a_frame_of_two_posts_and_a_crossbar():
    obj = BzwObject("teleporter", 1, size=(0.5, 4.0, 10.0), border=1.0)
    v, f = object_mesh(obj)
    m = trimesh.Trimesh(v, f)
    assert len(m.split(only_watertight=False)) == 3
    low = v[v[:, 2] < 5]
    assert sorted({round(y, 6) for y in low[:, 1]}) == [-6.0, -5.0, 5.0, 6.0]    # posts at +-(4 + 1.5)
    assert v[:, 2].max() == pytest.approx(11.0)


def test_outer_walls_stand_outside_the_world_edge():
    w = parse_bzw(BZW / "simple.bzw")
    v, f, _ = world_meshes(w)["outer_walls"]
    assert v[:, 2].max() == pytest.approx(OUTER_WALL_HEIGHT)
    assert np.abs(v[:, :2]).min(axis=1).max() <= 51.0 and np.abs(v[:, :2]).max() == pytest.approx(51.0)
    no = parse_bzw(BZW / "simple.bzw", text="world\n size 10\n nowalls\nend\n")
    assert "outer_walls" not in world_meshes(no)


# ---------------------------------------------------------------- import-arena

@pytest.fixture(scope="module")
def bundles(tmp_path_factory):
    out = tmp_path_factory.mktemp("bzw")
    return {name: import_arena(BZW / f"{name}.bzw", out / name)
            for name in ("simple", "rotated", "floating", "overlap")}


def test_simple_world_walls_are_the_edge_and_the_box(bundles):
    r = bundles["simple"]
    assert len(r.walls) == 8
    inner = _inner(r.walls, 50.0)
    # BZFlag (x, y) -> world (x, z = -y): the 20 x 10 box is 20 along x, 10 along z
    pts = inner.reshape(-1, 2)
    assert np.allclose(sorted(set(np.abs(pts[:, 0]))), [10.0]) and np.allclose(sorted(set(np.abs(pts[:, 1]))), [5.0])
    a = load_arena(r.path)
    assert a.toml["source"]["up"] == "z" and a.toml["source"]["file"] == "simple.bzw"
    assert (r.path / "simple.bzw").is_file() and (r.path / "model.glb").is_file()
    assert np.allclose(a.bounds, [[-51, -51], [51, 51]])


def test_rotated_box_and_pyramid_walls_follow_their_rotation(bundles):
    r = bundles["rotated"]
    inner = _inner(r.walls, 60.0)
    assert len(inner) == 12
    centre = inner.mean(axis=1)
    box = inner[np.hypot(centre[:, 0] + 20, centre[:, 1]) < 8]
    assert len(box) == 4
    d = box[:, 1] - box[:, 0]
    assert np.allclose(np.abs(d[:, 0]), np.abs(d[:, 1]), atol=0.02)           # 45 degrees
    corners = np.unique(np.round(box.reshape(-1, 2), 1), axis=0)
    want = np.array([[-20 - 6 * math.sqrt(2), 0], [-20, -6 * math.sqrt(2)], [-20, 6 * math.sqrt(2)],
                     [-20 + 6 * math.sqrt(2), 0]])
    assert np.allclose(np.sort(corners, axis=0), np.sort(np.round(want, 1), axis=0), atol=0.05)
    # the pyramid's cut at 1 m of 10 is its base shrunk by 10 %: a rectangle 14.4 x 7.2 turned 30 degrees
    pyr = inner[np.hypot(centre[:, 0] - 25, centre[:, 1] + 10) < 9]
    lengths = sorted(np.round(np.linalg.norm(pyr[:, 1] - pyr[:, 0], axis=1), 2))
    assert lengths == pytest.approx([7.2, 7.2, 14.4, 14.4], abs=0.03)
    angles = {round(math.degrees(math.atan2(s[1, 1] - s[0, 1], s[1, 0] - s[0, 0])) % 90, 0) for s in pyr}
    assert angles == {60.0}          # 30 degrees counter-clockwise in BZFlag is -30 in (x, z): mod 90, 60


def test_floating_box_makes_no_walls_and_pads_are_floor(bundles):
    r = bundles["floating"]
    inner = _inner(r.walls, 40.0)
    assert len(inner) == 4                            # only the grounded box
    pts = inner.reshape(-1, 2)
    assert np.allclose(np.sort(np.unique(pts[:, 0])), [-19, -11]) and np.allclose(np.sort(np.unique(pts[:, 1])), [11, 19])
    assert r.faces == 2 + 48 + 12 + 12 + 2            # ground, outer walls, two boxes, the base pad


def test_overlapping_boxes_make_one_solid(bundles):
    r = bundles["overlap"]
    inner = _inner(r.walls, 40.0)
    assert len(inner) == 6                            # an L: nothing buried inside the overlap
    import shapely

    solid = shapely.union(shapely.box(-10, -3, 10, 3), shapely.box(4, -17, 10, 3))
    mids = inner.mean(axis=1)
    assert all(solid.exterior.distance(shapely.Point(*m)) < 1e-6 for m in mids)


def test_cli_imports_a_world_and_prints_warnings(tmp_path):
    out = tmp_path / "u"
    res = CliRunner().invoke(cli, ["import-arena", str(BZW / "unknown.bzw"), "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert "arena 'unknown': 1 level, 18 walls (2 from thin walls) + 4 auxiliary" in res.output
    assert f"warning: {BZW / 'unknown.bzw'}:18: unknown or unsupported object 'link' skipped" in res.output
    assert res.output.count("warning:") == 4
    assert load_arena(out).toml["walls"]["count"] == 18


@pytest.mark.parametrize("name, message", [
    ("broken_number.bzw", "broken_number.bzw:5: 'position' expects 3 numbers, got '0 zero 0'"),
    ("broken_unclosed.bzw", "broken_unclosed.bzw:1: 'box' is never closed"),
])
def test_cli_bad_world_is_one_line_exit_2_and_nothing_written(tmp_path, name, message):
    out = tmp_path / "bad"
    res = CliRunner().invoke(cli, ["import-arena", str(BZW / name), "-o", str(out)])
    assert res.exit_code == 2
    assert message in res.output and "Traceback" not in res.output
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_courtyard_every_kind_together(tmp_path):
    """The docs' example map: bases are pads, the bridge floats, the teleporter is two posts."""
    w = parse_bzw(BZW / "courtyard.bzw")
    assert w.counts() == {"base": 2, "box": 6, "pyramid": 2, "wall": 1, "teleporter": 1}
    assert len(w.warnings) == 1 and ":76: unknown or unsupported object 'link'" in w.warnings[0]
    r = import_arena(BZW / "courtyard.bzw", tmp_path / "c")
    # 4 edge + 4 boxes x 4 + the central block 4 + 2 pyramids x 4 + 2 posts x 4 + the thin wall's 2 sides
    assert len(r.walls) == 4 + 16 + 4 + 8 + 8 + 2 and r.thin_walls == 2
    assert r.warnings == w.warnings
    inner = _inner(r.walls, 60.0)
    mids = inner.mean(axis=1)
    # nothing under the floating bridge at BZFlag (0, -40), i.e. world (0, 40)
    assert not ((np.abs(mids[:, 0]) < 15) & (np.abs(mids[:, 1] - 40) < 3)).any()
