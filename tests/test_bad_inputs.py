"""Issue 26: every wrong input gets one clear ``error:`` line naming the file and the
place, exit status 2, never a traceback nor an internal error."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from tanktool.cli.main import cli
from tanktool.errors import TanktoolError

ROOT = Path(__file__).resolve().parents[1]


def run(*args: str):
    return CliRunner().invoke(cli, list(args), prog_name="tanktool")


def one_error_line(res, *needles: str) -> str:
    """The result is exit 2 with exactly one ``error:`` line holding every needle."""
    assert res.exit_code == 2, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("error: ")]
    assert len(errors) == 1, res.output
    assert "Traceback" not in res.output and "internal error" not in res.output, res.output
    assert "Usage:" not in res.output, res.output
    for n in needles:
        assert n in errors[0], errors[0]
    return errors[0]


@pytest.fixture
def box_copy(tmp_path) -> Path:
    target = tmp_path / "box"
    shutil.copytree(ROOT / "arenas" / "box", target)
    return target


# ----------------------------------------------------------------- coordinates beyond the limits

@pytest.mark.parametrize("value", ["1e308", "-1e308"])
def test_a_far_spawn_is_refused_at_load_naming_the_spawn(box_copy, value):
    from tanktool.arena import load_arena

    toml = box_copy / "arena.toml"
    toml.write_text(toml.read_text().replace("[6.142, 6.142, 0.785398]", f"[{value}, 6.142, 0.785398]"))
    with pytest.raises(TanktoolError, match=r"arena.toml: spawns\[1\] .*beyond 1e\+06 m"):
        load_arena(box_copy)
    one_error_line(run("play", "--headless", "--arena", str(box_copy), "--seconds", "1"), "arena.toml: spawns[1]")
    res = run("check", str(box_copy))
    assert "X001" not in res.output and "internal error" not in res.output, res.output
    assert "B102" in res.output and "spawn 1 must be" in res.output, res.output


def test_far_bounds_and_floor_are_refused(box_copy):
    from tanktool.arena import load_arena

    toml = box_copy / "arena.toml"
    text = toml.read_text()
    toml.write_text(text.replace("[60.0, 60.0]", "[1e308, 60.0]"))
    with pytest.raises(TanktoolError, match="arena.toml: 'bounds'.*beyond"):
        load_arena(box_copy)
    toml.write_text(text.replace("floor_y = 0.0", "floor_y = -1e308"))
    with pytest.raises(TanktoolError, match="arena.toml: 'floor_y' must be a finite number within 1e\\+06 m"):
        load_arena(box_copy)


def test_a_far_wall_is_refused_with_its_line(box_copy):
    walls = box_copy / "walls.txt"
    lines = walls.read_text().splitlines()
    k = next(i for i, ln in enumerate(lines) if ln.strip() and not ln.startswith("#"))
    lines[k] = "0 0 1e308 0 1"
    walls.write_text("\n".join(lines) + "\n")
    from tanktool.formats.walls_txt import read_walls

    with pytest.raises(TanktoolError, match=rf"walls.txt:{k + 1}: coordinates must lie within 1e\+06 m"):
        read_walls(walls)
    bare = box_copy.parent / "far_walls.txt"          # a bare walls file: build-navgrid reads it
    bare.write_text(walls.read_text())
    one_error_line(run("build-navgrid", str(bare)), f"far_walls.txt:{k + 1}:", "within 1e+06 m")


# ----------------------------------------------------------------- usage errors: the README's promise

def test_readme_promises_one_error_line():
    text = (ROOT / "README.md").read_text()
    assert "one `error:` line" in text


@pytest.mark.parametrize("args, needle", [
    (["play", "--headless", "--size", "abc"], "--size"),
    (["play", "--headless", "--bots", "0"], "--bots"),
    (["play", "--frames", "1", "--screenshot", "DIR"], "--screenshot"),
    (["play", "--no-such-option"], "--no-such-option"),
    (["no-such-command"], "no-such-command"),
    (["--bogus"], "--bogus"),
])
def test_usage_errors_are_one_error_line(args, needle, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "DIR").mkdir()
    line = one_error_line(run(*args), needle)
    assert re.search(r"see `tanktool( play)? --help`", line), line


# ----------------------------------------------------------------- model files

def _damaged_texture_glb(tmp_path) -> Path:
    """The bundled box's model.glb with one byte changed inside its first PNG's pixels."""
    import json
    import struct

    data = bytearray((ROOT / "arenas" / "box" / "model.glb").read_bytes())
    jlen = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(bytes(data[20:20 + jlen]))
    view = doc["bufferViews"][doc["images"][0]["bufferView"]]
    start = 20 + jlen + 8 + view.get("byteOffset", 0)
    assert data[start:start + 4] == b"\x89PNG"
    data[start + 100] ^= 0xFF                      # inside IDAT: the header still reads
    out = tmp_path / "model.glb"
    out.write_bytes(bytes(data))
    return out


@pytest.mark.parametrize("command", ["import-arena", "import-vehicle"])
def test_a_damaged_png_inside_a_glb_names_the_file_and_the_image(tmp_path, command):
    glb = _damaged_texture_glb(tmp_path)
    one_error_line(run(command, str(glb), "-o", str(tmp_path / "out")),
                   f"{glb}: images[0]", "image/png", "damaged")
    assert not (tmp_path / "out").exists()


def test_an_obj_with_a_latin1_comment_reads(tmp_path):
    from tanktool.formats.models import load_scene

    obj = tmp_path / "room.obj"
    obj.write_bytes(b"# caf\xe9 cr\xe9\xe9 par l'\xe9quipe\no sal\xf3n\nv 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n")
    scene = load_scene(obj)
    assert sum(len(g.faces) for g in scene.geometry.values()) == 1


def test_a_bad_face_index_names_the_line(tmp_path):
    from tanktool.errors import FormatError
    from tanktool.formats.models import load_scene

    obj = tmp_path / "room.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 0 1\nv 1 0 1\nf 1 2 3\n# a comment\nf 1 2 9\n")
    with pytest.raises(FormatError, match=rf"{obj}:7: face names vertex 9, but the file defines 4 vertices"):
        load_scene(obj)
    obj.write_text("v 0 0 0\nv 1 0 0\nf 1 2 -3\n")
    with pytest.raises(FormatError, match=rf"{obj}:3: face names vertex -3"):
        load_scene(obj)


# ----------------------------------------------------------------- a model where a bundle is expected

@pytest.mark.parametrize("args, kind", [
    (["build-navgrid", "{m}"], "arena"),
    (["play", "--headless", "--seconds", "1", "--arena", "{m}"], "arena"),
    (["play", "--headless", "--seconds", "1", "--vehicle", "{m}"], "vehicle"),
])
def test_a_model_where_a_bundle_is_expected_says_import_it(tmp_path, args, kind):
    model = tmp_path / "room.obj"
    shutil.copy(ROOT / "arenas" / "box" / "box.obj", model)
    one_error_line(run(*[a.format(m=model) for a in args]),
                   f"{model} is a model: import it first with `tanktool import-{kind} {model}`")


def test_check_of_a_model_and_of_missing_names(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    shutil.copy(ROOT / "arenas" / "box" / "box.obj", tmp_path / "room.obj")
    res = run("check", "room.obj")
    assert res.exit_code == 2 and "room.obj is a model: import it first" in res.output, res.output
    assert "A101" not in res.output
    res = run("check", "fort", "mytank")
    assert res.exit_code == 2, res.output
    assert "error: fort: no such file or folder (the bundled arena fort is " in res.output
    assert "error: mytank: no such file or folder\n" in res.output
    assert "0 errors" not in res.output and "in 0 files" not in res.output, res.output
    assert "nothing checked: 2 paths could not be read" in res.output


# ----------------------------------------------------------------- bounded work: cells

def _stretched_dxf(tmp_path) -> Path:
    """tests/data/plans/room.dxf with one coordinate changed from 10 to 65535 (the fuzzer's case)."""
    lines = (ROOT / "tests" / "data" / "plans" / "room.dxf").read_text().split("\n")
    k = next(i for i in range(len(lines) - 1) if lines[i].strip() == "20" and lines[i + 1].strip() == "10")
    lines[k + 1] = "65535"
    out = tmp_path / "stretched.dxf"
    out.write_text("\n".join(lines))
    return out


def test_a_stretched_plan_is_refused_before_the_work_in_cells(tmp_path):
    from tanktool.formats.limits import cell_budget

    dxf = _stretched_dxf(tmp_path)
    line = one_error_line(run("import-arena", str(dxf), "-o", str(tmp_path / "out")),
                          f"{dxf}: the model is", "cells of 0.5 m", "--max-cells")
    cells = int(re.search(r"m: ([\d,]+) cells", line).group(1).replace(",", ""))
    assert cells > 10_000_000 and cells > cell_budget(dxf.stat().st_size)
    assert not (tmp_path / "out").exists()


def _terrain_obj(path: Path, size: float = 2000.0, samples: int = 101) -> Path:
    """A real 2 km terrain: a height field sampled every 20 m, as an exporter writes it."""
    import numpy as np

    t = np.linspace(0.0, size, samples)
    x, z = np.meshgrid(t, t)
    y = 15.0 * np.sin(x / 170.0) * np.cos(z / 230.0)
    rows = [f"v {a:.3f} {b:.3f} {c:.3f}" for a, b, c in zip(x.ravel(), y.ravel(), z.ravel())]
    n = samples
    for i in range(n - 1):
        for j in range(n - 1):
            a = i * n + j + 1
            rows += [f"f {a} {a + n} {a + 1}", f"f {a + 1} {a + n} {a + n + 1}"]
    path.write_text("\n".join(rows) + "\n")
    return path


def _town_dxf(path: Path, size: float = 2000.0, blocks: int = 20) -> Path:
    """A real 4 km^2 town plan: a ring road and 20 x 20 blocks of houses, each a closed polyline."""
    out = ["0", "SECTION", "2", "ENTITIES"]

    def poly(pts):
        out.extend(["0", "LWPOLYLINE", "8", "WALLS", "90", str(len(pts)), "70", "1"])
        for px, py in pts:
            out.extend(["10", f"{px:.2f}", "20", f"{py:.2f}"])

    poly([(0, 0), (size, 0), (size, size), (0, size)])
    step = size / blocks
    for i in range(blocks):
        for j in range(blocks):
            x0, y0 = i * step + 15, j * step + 15
            for hx in range(3):      # three houses a block
                a, b = x0 + hx * 25, y0
                poly([(a, b), (a + 18, b), (a + 18, b + 14), (a, b + 14)])
    out.extend(["0", "ENDSEC", "0", "EOF"])
    path.write_text("\n".join(out) + "\n")
    return path


def test_the_cell_limits_admit_real_levels(tmp_path):
    """The defaults admit an 800 m BZFlag world, a 2 km terrain and a 4 km^2 town at 0.5 m
    (asked of the same check import-arena runs, in cells: no import is run here)."""
    from tanktool.formats.limits import check_cells

    bzw = ROOT / "tests" / "data" / "bzw"
    world = max(bzw.glob("*.bzw"), key=lambda p: p.stat().st_size)
    assert check_cells(str(world), 800.0, 800.0, 0.5, world.stat().st_size) > 2_560_000
    terrain = _terrain_obj(tmp_path / "terrain.obj")
    assert check_cells(str(terrain), 2000.0, 2000.0, 0.5, terrain.stat().st_size) > 16_000_000
    town = _town_dxf(tmp_path / "town.dxf")
    assert check_cells(str(town), 2000.0, 2000.0, 0.5, town.stat().st_size) > 16_000_000
    # --max-cells raises the limit for the stretched plan
    dxf = _stretched_dxf(tmp_path)
    with pytest.raises(TanktoolError, match="--max-cells"):
        check_cells(str(dxf), 40.5, 65535.2, 0.5, dxf.stat().st_size)
    assert check_cells(str(dxf), 40.5, 65535.2, 0.5, dxf.stat().st_size, max_cells=12_000_000) > 10_000_000


def test_bench_walkable_over_the_column_limit_is_one_line(tmp_path):
    import subprocess
    import sys

    big = tmp_path / "huge.obj"
    big.write_text("v 0 0 0\nv 30000 0 0\nv 0 0 30000\nf 1 3 2\n")
    res = subprocess.run([sys.executable, str(ROOT / "bench" / "walkable.py"), str(big), "--repeat", "1"],
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 2, res.stderr
    assert "Traceback" not in res.stderr and res.stderr.startswith(f"error: {big}: ") and "limit" in res.stderr


def _random_lines_svg(path: Path, n: int = 12_000) -> Path:
    import random

    r = random.Random(1)
    els = "".join(f'<line x1="{r.uniform(0, 100):.2f}" y1="{r.uniform(0, 100):.2f}" '
                  f'x2="{r.uniform(0, 100):.2f}" y2="{r.uniform(0, 100):.2f}"/>\n' for _ in range(n))
    path.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">\n{els}</svg>\n')
    return path


def test_a_plan_of_crossing_lines_is_refused_in_overlaps_and_a_town_is_not(tmp_path):
    """12,000 random lines (the fuzzer had 30,000: 10^8 crossings, minutes and 2 GB in GEOS) are refused while
    counting, before the union; a town plan of 1,200 houses is far below the limit."""
    from tanktool.formats.floorplan import check_overlaps, overlap_budget, read_plan

    svg = _random_lines_svg(tmp_path / "lines.svg")
    one_error_line(run("import-arena", str(svg), "-o", str(tmp_path / "out")),
                   f"{svg}: the drawing's 12,000 segments cross or overlap more than", "the limit")
    town = read_plan(_town_dxf(tmp_path / "town.dxf"))
    segments = sum(len(ln) - 1 for ln in town)
    assert check_overlaps(town) < overlap_budget(segments) / 4


# ----------------------------------------------------------------- glTF from the wild

def _gltf_with_external_files(folder: Path) -> Path:
    """The box arena's model.glb as a .gltf with its buffer in data/my scene.bin and its
    first image in textures/brick one.png, both named by percent-encoded URIs."""
    import json
    import struct

    data = (ROOT / "arenas" / "box" / "model.glb").read_bytes()
    jlen = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + jlen])
    blen = struct.unpack_from("<I", data, 20 + jlen)[0]
    binary = data[28 + jlen:28 + jlen + blen]
    (folder / "data").mkdir(parents=True)
    (folder / "data" / "my scene.bin").write_bytes(binary)
    doc["buffers"][0]["uri"] = "data/my%20scene.bin"
    image = doc["images"][0]
    view = doc["bufferViews"][image.pop("bufferView")]
    (folder / "textures").mkdir()
    start = view.get("byteOffset", 0)
    (folder / "textures" / "brick one.png").write_bytes(binary[start:start + view["byteLength"]])
    image["uri"] = "textures%2Fbrick%20one.png"
    model = folder / "scene.gltf"
    model.write_text(json.dumps(doc))
    return model


def test_a_gltf_with_percent_encoded_uris_imports_and_its_bundle_imports_again(tmp_path):
    from tanktool.formats.materials import model_textures

    model = _gltf_with_external_files(tmp_path / "src")
    found = model_textures(model)
    assert not found.missing and len(found.found) >= 1
    res = run("import-arena", str(model), "-o", str(tmp_path / "bundle"), "-q")
    assert res.exit_code == 0, res.output
    copied = tmp_path / "bundle" / "data" / "my scene.bin"
    assert copied.read_bytes() == (tmp_path / "src" / "data" / "my scene.bin").read_bytes()
    res = run("import-arena", str(tmp_path / "bundle" / "scene.gltf"), "-o", str(tmp_path / "again"), "-q")
    assert res.exit_code == 0, res.output
    # the bundle is one tanktool wrote: --force may replace it (its data/ is accounted for)
    res = run("import-arena", str(model), "-o", str(tmp_path / "bundle"), "-q", "--force")
    assert res.exit_code == 0, res.output


# ----------------------------------------------------------------- BZFlag worlds from the wild

def test_a_bzflag_world_as_bzflag_reads_it():
    """_wallHeight 0 and a teleporter of border 0 are valid BZFlag; a mesh and a group
    (an instance of a define) are built; a sphere is counted by name in what is left out."""
    from tanktool.formats.bzw import load_scene, parse_bzw

    path = ROOT / "tests" / "data" / "bzw" / "wild_world.bzw"
    world = parse_bzw(path)
    assert world.walls is False and world.wall_height == 0
    assert [o.kind for o in world.objects] == ["box"]          # the frameless teleporter has nothing solid
    assert len(world.meshes) == 2 and len(world.meshes[0][1]) == 10   # the mesh: 5 quads
    assert world.meshes[0][0][:, 1].min() == 40.0                      # shifted by 100 in y
    house = world.meshes[1][0]                                         # define house's box, group shift 50 50 0
    assert house.min(axis=0).tolist() == [46.0, 46.0, 0.0] and house.max(axis=0).tolist() == [54.0, 54.0, 4.0]
    assert sorted(world.left_out) == ["sphere"]
    assert load_scene(path).metadata["left_out"] == ["1 sphere (line 57)"]


def test_groups_nest_and_errors_in_a_definition_name_their_own_line(tmp_path):
    from tanktool.errors import FormatError
    from tanktool.formats.bzw import parse_bzw

    text = ("define post\n  box\n    size 1 1 3\n  end\nenddef\n"
            "define pair\n  group post\n    shift -5 0 0\n  end\n  group post\n    shift 5 0 0\n  end\nenddef\n"
            "group pair\n  spin 90 0 0 1\n  shift 0 0 1\nend\ngroup nothing\nend\n")
    w = parse_bzw(tmp_path / "g.bzw", text=text)
    centres = sorted(tuple(np.round(v.mean(axis=0), 6)) for v, _ in w.meshes)
    assert centres == [(0.0, -5.0, 2.5), (0.0, 5.0, 2.5)]      # x -5 / +5 spun 90 deg to y, lifted 1
    assert w.left_out == {"group of no definition": [18]}
    with pytest.raises(FormatError, match=r"g\.bzw:3: 'size' expects 3 numbers"):
        parse_bzw(tmp_path / "g.bzw", text=text.replace("size 1 1 3", "size 1 x 3"))
    loop = "define a\n  group a\n  end\nenddef\ngroup a\nend\n"
    with pytest.raises(FormatError, match="nested more than 8 deep"):
        parse_bzw(tmp_path / "loop.bzw", text=loop)


def test_import_never_says_left_out_nothing_when_objects_were_skipped(tmp_path):
    world = tmp_path / "w.bzw"
    world.write_text("world\n  size 60\nend\nwall\n  position 0 0 0\n  size 0 10 4\nend\n"
                     "cone\n  position 30 30 0\n  size 4 4 8\nend\n")
    res = run("import-arena", str(world), "-o", str(tmp_path / "out"))
    assert res.exit_code == 0, res.output
    left = [ln for ln in res.output.splitlines() if ln.strip().startswith("left out:")]
    assert left == ["  left out: 1 cone (line 8) of w.bzw not built"], res.output


def test_zero_area_faces_raise_no_numpy_warning(tmp_path):
    """Degenerate triangles (13 of 24 third-party models had some) gave 'invalid value
    in divide' from the heightfield: now the import is silent."""
    import warnings

    from tanktool.importer import import_arena

    obj = tmp_path / "floor.obj"
    obj.write_text("v 0 0 0\nv 40 0 0\nv 40 0 40\nv 0 0 40\nv 20 0 20\nv 20 3 20\nv 20 0 0\n"
                   "f 1 3 2\nf 1 4 3\nf 5 5 5\nf 1 5 3\nf 5 6 6\nf 1 7 2\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = import_arena(obj, tmp_path / "out")
    assert len(result.walls) >= 4
    # a vehicle model with the same kind of faces
    tank = tmp_path / "tank.obj"
    tank.write_text("v -3 0 -2\nv 3 0 -2\nv 3 0 2\nv -3 0 2\nv -3 2 -2\nv 3 2 -2\nv 3 2 2\nv -3 2 2\nv 0 2 0\n"
                    "f 1 2 3\nf 1 3 4\nf 5 7 6\nf 5 8 7\nf 1 5 6\nf 1 6 2\nf 2 6 7\nf 2 7 3\n"
                    "f 3 7 8\nf 3 8 4\nf 4 8 5\nf 4 5 1\nf 9 9 9\nf 5 9 7\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = run("import-vehicle", str(tank), "-o", str(tmp_path / "tank"), "-q")
    assert res.exit_code == 0, res.output


def test_no_arguments_still_shows_the_help():
    res = run()
    assert "Usage: tanktool" in res.output and "Commands:" in res.output and "error:" not in res.output
    res = run("import-arena")
    one_error_line(res, "Missing argument 'MODEL'", "tanktool import-arena --help")


def test_a_model_far_from_the_origin_is_refused_naming_the_model(tmp_path):
    """A level 10,000 km out used to be written and then refused while checking its own
    staged walls.txt, in a temporary folder's name; now the model is refused up front."""
    model = tmp_path / "far.obj"
    model.write_text("v 1e7 0 1e7\nv 1.00005e7 0 1e7\nv 1.00005e7 0 1.00005e7\nv 1e7 0 1.00005e7\n"
                     "f 1 3 2\nf 1 4 3\n")
    r = run("import-arena", str(model), "-o", str(tmp_path / "far"))
    assert r.exit_code == 2
    assert r.output.count("error:") == 1 and "far.obj: the model reaches 10,000,500 m from the origin" in r.output
    assert ".tanktool-" not in r.output and not (tmp_path / "far").exists()


def test_a_floor_wound_the_wrong_way_says_flip_the_normals(tmp_path):
    """A floor whose faces face down is not walkable (as in Recast); the refusal says
    so instead of only asking about the up axis and the scale."""
    model = tmp_path / "flipped.obj"
    model.write_text("v 0 0 0\nv 50 0 0\nv 50 0 50\nv 0 0 50\nf 1 2 3\nf 1 3 4\n")
    r = run("import-arena", str(model), "-o", str(tmp_path / "flipped"))
    assert r.exit_code == 2 and r.output.count("error:") == 1
    assert "2,500 m^2 of level faces face down and 0 m^2 up" in r.output and "flip the normals" in r.output
    model.write_text("v 0 0 0\nv 50 0 0\nv 50 0 50\nv 0 0 50\nf 1 3 2\nf 1 4 3\n")
    assert run("import-arena", str(model), "-o", str(tmp_path / "right")).exit_code == 0
