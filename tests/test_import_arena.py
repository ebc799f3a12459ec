"""``tanktool import-arena`` end to end, bad input, and the arena bundle loader."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh
from click.testing import CliRunner

from tanktool.arena import load_arena
from tanktool.cli.main import cli
from tanktool.errors import ArenaError, FormatError
from tanktool.formats.bundle import read_toml, sha256_file
from tanktool.formats.walls_txt import read_walls

DATA = Path(__file__).resolve().parent / "data"


def _box(x0, z0, x1, z1, y0, y1):
    b = trimesh.creation.box(extents=[x1 - x0, y1 - y0, z1 - z0])
    b.apply_translation([(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2])
    return b


def write_room(path: Path, size: float = 30.0) -> Path:
    parts = [_box(0, 0, size, size, -0.5, 0), _box(0, 0, size, 1, 0, 3), _box(0, size - 1, size, size, 0, 3),
             _box(0, 0, 1, size, 0, 3), _box(size - 1, 0, size, size, 0, 3), _box(12, 12, 16, 16, 0, 3)]
    trimesh.util.concatenate(parts).export(path)
    return path


def run(*args: str):
    return CliRunner().invoke(cli, list(args), catch_exceptions=False)


def test_import_writes_a_complete_bundle(tmp_path):
    model = write_room(tmp_path / "room.obj")
    out = tmp_path / "arenas" / "room"
    r = run("import-arena", str(model), "-o", str(out))
    assert r.exit_code == 0, r.output
    assert "1 level, 8 walls" in r.output and "level 0: " in r.output and "left out:" in r.output
    for f in ("arena.toml", "room.obj", "model.glb", "walls.txt", "preview.png", "navgrid.npz", "quadtree.npz",
              "navgrid.png"):
        assert (out / f).is_file(), f
    assert "navgrid: " in r.output
    doc = read_toml(out / "arena.toml")
    assert doc["name"] == "room"
    assert doc["source"] == {"file": "room.obj", "sha256": sha256_file(model), "up": "y", "scale": 1.0}
    assert doc["walls"]["count"] == 8 and doc["walls"]["height"] == 1.0
    from tanktool.fleet import bundled_fleet

    # one step: the grid is built for the largest bundled vehicle, as build-navgrid does
    assert doc["navgrid"] == {"cell": 0.5, "clearance": pytest.approx(bundled_fleet().radius, abs=1e-4),
                              "quadtree_depth": 3}
    assert {"navgrid.npz", "quadtree.npz", "navgrid.png"} <= set(doc["derived"])
    for f, digest in doc["derived"].items():
        assert sha256_file(out / f) == digest
    assert doc["walkable"]["headroom"] > 0 and doc["levels"][0]["level"] == 0
    # spawns only where the largest bundled tank fits, a tank's length apart
    from tanktool.fleet import bundled_fleet
    from tanktool.geometry.segments import point_segment_distance

    fleet = bundled_fleet()
    sp = np.asarray(doc["spawns"])[:, :2]
    assert 2 <= len(sp) <= 8
    walls = read_walls(out / "walls.txt")
    d = point_segment_distance(sp[:, None], walls.segments[None, :, 0], walls.segments[None, :, 1]).min(axis=1)
    assert (d >= fleet.radius).all()
    gaps = np.hypot(*(sp[:, None] - sp[None]).transpose(2, 0, 1))[np.triu_indices(len(sp), 1)]
    assert (gaps >= fleet.length).all()
    assert walls.aux is not None and len(walls) == 8
    assert np.allclose(doc["bounds"], walls.bounds)
    # the glb is in the world frame: its floor top is at y = 0
    scene = trimesh.load(out / "model.glb", force="scene")
    assert scene.bounds[1][1] == pytest.approx(3.0)
    assert (out / "preview.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_one_step_import_writes_what_build_navgrid_writes(tmp_path):
    # import-arena alone makes the bundle play needs; build-navgrid afterwards, with
    # the same settings, rewrites the same bytes
    model = write_room(tmp_path / "room.obj", 40)
    out = tmp_path / "room"
    assert run("-q", "import-arena", str(model), "-o", str(out)).exit_code == 0
    before = {f: (out / f).read_bytes() for f in ("navgrid.npz", "quadtree.npz", "navgrid.png", "arena.toml")}
    r = run("-q", "build-navgrid", str(out))
    assert r.exit_code == 0, r.output
    for f, data in before.items():
        assert (out / f).read_bytes() == data, f
    r = run("check", str(out))
    assert r.exit_code == 0 and "0 errors" in r.output, r.output


def test_load_arena_reads_the_bundle(tmp_path):
    model = write_room(tmp_path / "room.obj", 40)
    out = tmp_path / "room"
    assert run("-q", "import-arena", str(model), "-o", str(out), "--name", "hall").exit_code == 0
    a = load_arena(out)
    assert a.name == "hall"
    assert a.spawns.shape == (8, 3)
    assert len(a.walls) == 8
    # spawns lie in free space: inside the room, off the pillar, facing the centre
    x, z = a.spawns[:, 0], a.spawns[:, 1]
    assert ((x > 1) & (x < 39) & (z > 1) & (z < 39)).all()
    assert not ((x > 12) & (x < 16) & (z > 12) & (z < 16)).any()
    assert load_arena(out / "arena.toml").name == "hall"
    with pytest.raises(ArenaError, match="no arena.toml"):
        load_arena(tmp_path)


def test_refuses_to_overwrite_without_force(tmp_path):
    model = write_room(tmp_path / "room.obj")
    out = tmp_path / "room"
    assert run("import-arena", str(model), "-o", str(out)).exit_code == 0
    before = sha256_file(out / "walls.txt")
    r = run("import-arena", str(model), "-o", str(out), "--height", "2")
    assert r.exit_code == 2 and "--force" in r.output
    assert sha256_file(out / "walls.txt") == before
    r = run("import-arena", str(model), "-o", str(out), "--height", "2", "--force")
    assert r.exit_code == 0
    assert read_toml(out / "arena.toml")["walls"]["height"] == 2.0


def test_default_output_is_named_after_the_model(tmp_path, monkeypatch):
    model = write_room(tmp_path / "src.obj")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    assert run("import-arena", str(model)).exit_code == 0
    assert (work / "src" / "arena.toml").is_file()


def _bad_inputs(tmp_path: Path) -> dict[str, tuple[Path, str]]:
    text = tmp_path / "notes.obj"
    text.write_text("this is not a model\n")
    nan = tmp_path / "nan.obj"
    nan.write_text("v 0 0 0\nv 1 0 0\nv nan 0 1\nf 1 2 3\n")
    empty3ds = tmp_path / "empty.3ds"
    empty3ds.write_bytes(b"")
    block = tmp_path / "block.obj"
    trimesh.util.concatenate([_box(0, 0, 4, 4, -1, 0), _box(0, 0, 4, 4, 0, 5)]).export(block)
    wall = tmp_path / "wall.obj"
    wall.write_text("v 0 0 0\nv 1 0 0\nv 1 3 0\nf 1 2 3\n")
    return {
        "missing": (tmp_path / "nope.obj", "no such file"),
        "not a model": (text, "no triangles"),
        "nan": (nan, "not finite"),
        "empty 3ds": (empty3ds, "empty"),
        "no free space": (block, "no place where any bundled tank fits"),
        "no floor": (wall, "no surface a tank can stand on"),
        "unknown kind": (tmp_path / "notes.txt", "no such file"),
    }


@pytest.mark.parametrize("case", ["missing", "not a model", "nan", "empty 3ds", "no free space", "no floor",
                                  "unknown kind"])
def test_bad_input_is_one_line_exit_2_nothing_written(tmp_path, case):
    path, expect = _bad_inputs(tmp_path)[case]
    out = tmp_path / "out"
    r = CliRunner().invoke(cli, ["import-arena", str(path), "-o", str(out)])
    assert r.exit_code == 2, r.output
    assert expect in r.output
    err = [ln for ln in r.output.splitlines() if ln.strip()]
    assert len(err) == 1 and err[0].startswith("error: ")
    assert not out.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out")]


def test_bad_options_exit_2(tmp_path):
    model = write_room(tmp_path / "room.obj")
    for opts in (["--height", "-1"], ["--tolerance", "0"], ["--height", "nan"]):
        r = CliRunner().invoke(cli, ["import-arena", str(model), "-o", str(tmp_path / "o"), *opts])
        assert r.exit_code == 2, (opts, r.output)
        assert not (tmp_path / "o").exists()


def test_3ds_model_is_read_z_up(tmp_path):
    from tanktool.formats.threeds_write import scene_to_3ds_objects, write_3ds

    room = trimesh.load(write_room(tmp_path / "room.obj"), force="mesh")
    write_3ds(tmp_path / "room.3ds", scene_to_3ds_objects(room))
    out = tmp_path / "r3"
    assert run("import-arena", str(tmp_path / "room.3ds"), "-o", str(out)).exit_code == 0
    doc = read_toml(out / "arena.toml")
    assert doc["source"]["up"] == "z"
    assert doc["walls"]["count"] == 8
    assert doc["floor_y"] == pytest.approx(0.0, abs=1e-6)


@pytest.mark.skipif(not (DATA / "arenas_obj" / "dungeon.obj").exists(), reason="test model missing")
def test_dungeon_imports(tmp_path):
    out = tmp_path / "dungeon"
    r = run("import-arena", str(DATA / "arenas_obj" / "dungeon.obj"), "-o", str(out))
    assert r.exit_code == 0, r.output
    a = load_arena(out)
    assert a.floor_y == pytest.approx(10.0, abs=0.05)
    # its floors joined by ramps are all in (about 1,700 m^2 at tank headroom), and it
    # is built for people: the heavy tank fits in few places, which import-arena says
    assert a.toml["levels"][0]["area"] > 1500
    assert a.toml["levels"][0]["y"][1] - a.toml["levels"][0]["y"][0] > 15
    assert len(a.walls) > 100 and 1 <= len(a.spawns) < 8
    assert "room for only" in r.output


def test_load_arena_rejects_broken_manifests(tmp_path):
    model = write_room(tmp_path / "room.obj")
    out = tmp_path / "room"
    assert run("-q", "import-arena", str(model), "-o", str(out)).exit_code == 0
    toml = (out / "arena.toml").read_text()
    (out / "arena.toml").write_text(toml.replace("spawns = [", "spawns = [[1, 2], ", 1))
    with pytest.raises(ArenaError, match="spawns"):
        load_arena(out)
    (out / "arena.toml").write_text(toml.replace('file = "walls.txt"', 'file = "../walls.txt"'))
    with pytest.raises(ArenaError, match="walls"):
        load_arena(out)
    (out / "arena.toml").write_text("name = \n")
    with pytest.raises(FormatError, match="invalid TOML"):
        load_arena(out)


def test_default_name_from_an_awkward_file_stem(tmp_path, monkeypatch):
    model = write_room(tmp_path / "my arena (v2).obj")
    monkeypatch.chdir(tmp_path)
    r = run("import-arena", str(model))
    assert r.exit_code == 0, r.output
    assert load_arena(tmp_path / "my_arena_v2").name == "my_arena_v2"
    r = CliRunner().invoke(cli, ["import-arena", str(model), "--name", "bad/name"])
    assert r.exit_code == 2 and "arena name" in r.output


def test_no_fit_names_a_scale_and_scale_auto_applies_it(tmp_path):
    import re
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))
    import make_levels

    mesh = make_levels.level("corridor")
    mesh.apply_scale(1 / 3.0)                       # a 2.5 m corridor: no bundled tank fits
    model = make_levels.write_obj(mesh, tmp_path / "narrow.obj")
    r = CliRunner().invoke(cli, ["import-arena", str(model), "-o", str(tmp_path / "a")])
    assert r.exit_code == 2 and not (tmp_path / "a").exists()
    (line,) = [ln for ln in r.output.splitlines() if ln.startswith("error:")]
    m = re.search(r"needs a circle of ([\d.]+) m and the widest the walkable surface takes is ([\d.]+) m "
                  r"\(at --scale ([\d.]+) light fits on (\d+) % of it\)", line)
    assert m, line
    assert float(m[2]) < float(m[1])                # never "needs 6.46, widest 6.50"
    assert float(m[3]) > 1 and int(m[4]) >= 50
    r = run("import-arena", str(model), "-o", str(tmp_path / "b"), "--scale", "auto")
    assert r.exit_code == 0, r.output
    assert f"--scale auto: no bundled tank fits at scale 1; importing at --scale {m[3]}" in r.output
    assert read_toml(tmp_path / "b" / "arena.toml")["source"]["scale"] == float(m[3])
    assert run("check", str(tmp_path / "b")).exit_code == 0


def test_spawns_stay_by_the_geometry_not_on_the_empty_plane_around_it(tmp_path):
    # a small town of blocks in the middle of a 300 m ground plane of two triangles
    plane = trimesh.Trimesh([[0, 0, 0], [300, 0, 0], [300, 0, 300], [0, 0, 300]], [[0, 2, 1], [0, 3, 2]])
    parts = [plane] + [_box(120 + 20 * k, 120 + 20 * m, 128 + 20 * k, 128 + 20 * m, 0, 6)
                       for k in range(3) for m in range(3)]
    trimesh.util.concatenate(parts).export(tmp_path / "town.obj")
    r = run("-q", "import-arena", str(tmp_path / "town.obj"), "-o", str(tmp_path / "town"))
    assert r.exit_code == 0, r.output
    sp = np.asarray(read_toml(tmp_path / "town" / "arena.toml")["spawns"])[:, :2]
    from tanktool.fleet import bundled_fleet

    margin = bundled_fleet().length + 1e-6
    assert len(sp) >= 2
    assert ((sp >= 120 - margin) & (sp <= 168 + margin)).all(), sp
