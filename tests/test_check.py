"""tanktool check: the broken corpus (one case per rule), clean content, output and exit codes."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from tanktool.check import RULES, run_check
from tanktool.check.diagnostics import ERROR, WARNING
from tanktool.check.freespace import UNBOUNDED, analyse
from tanktool.check.walls_scan import scan_walls_text
from tanktool.cli.main import cli
from tanktool.formats.walls_txt import WallList, aux_rectangle

DATA = Path(__file__).resolve().parent / "data"
BROKEN = DATA / "broken"
CLEAN = DATA / "check_clean"
CASES = sorted(p.name for p in BROKEN.iterdir() if (p / "expect.json").is_file())


def _rel(path: str, base: Path) -> str:
    return Path(path).resolve().relative_to(base.resolve()).as_posix()


def test_every_rule_has_a_case():
    covered = {c.split("_", 1)[0] for c in CASES}
    # X001 is the checker's own safety net, not a content rule
    assert covered == set(RULES) - {"X001"}


@pytest.mark.parametrize("case", CASES)
def test_broken_case_reports_its_rule_at_its_place(case):
    base = BROKEN / case
    exp = json.loads((base / "expect.json").read_text())
    report = run_check([base / exp["target"]])
    codes = {d.code for d in report.diagnostics}
    assert codes == {exp["code"]}, [d.format() for d in report.diagnostics]
    places = {(_rel(d.path, base), d.line) for d in report.diagnostics}
    assert any((exp["path"], line) in places for line in exp["lines"]), (places, exp)
    assert not report.unreadable
    want = 1 if RULES[exp["code"]].severity == ERROR else 0
    assert report.exit_code() == want
    assert report.exit_code(strict=True) == 1


def test_clean_content_passes_strict():
    report = run_check([CLEAN])
    assert report.diagnostics == []
    assert len(report.files) == 2
    assert report.exit_code(strict=True) == 0


def test_bundled_content_passes_strict(root_dir):
    paths = [root_dir / "arenas", root_dir / "vehicles"]
    paths = [p for p in paths if p.is_dir()]
    report = run_check(paths)
    assert [d.format() for d in report.diagnostics] == []
    assert report.exit_code(strict=True) == 0


# ------------------------------------------------------------------ the CLI
def test_cli_text_output_and_summary():
    case = BROKEN / "A205_flipped_normal"
    res = CliRunner().invoke(cli, ["check", str(case / "walls.txt")])
    assert res.exit_code == 1
    lines = res.output.strip().splitlines()
    assert lines[0].startswith(f"{case / 'walls.txt'}:4: A205 error: ")
    assert lines[0].endswith("(flip the wall's Direction (1 <-> -1))")
    assert lines[-1] == "1 error, 0 warnings in 1 file"


def test_cli_json_document():
    case = BROKEN / "A305_few_spawns"
    res = CliRunner().invoke(cli, ["check", "--json", str(case)])
    assert res.exit_code == 0  # a warning only
    doc = json.loads(res.output)
    assert doc["summary"] == {"errors": 0, "warnings": 1}
    assert doc["files"] == [str(case / "arenas" / "few_spawns")]
    (d,) = doc["diagnostics"]
    assert set(d) == {"path", "line", "code", "severity", "message", "hint"}
    assert d["code"] == "A305" and d["severity"] == WARNING and d["line"] > 0


def test_cli_strict_turns_warnings_into_failure():
    case = BROKEN / "A305_few_spawns"
    assert CliRunner().invoke(cli, ["check", str(case)]).exit_code == 0
    assert CliRunner().invoke(cli, ["check", "--strict", str(case)]).exit_code == 1


def test_cli_unreadable_path_exits_2(tmp_path):
    res = CliRunner().invoke(cli, ["check", str(tmp_path / "nope"), str(CLEAN)])
    assert res.exit_code == 2
    assert "no such file or folder" in res.output
    assert "in 2 files" in res.output  # the readable paths are still checked


def test_cli_without_a_path_checks_the_bundled_content_and_lists_rules(root_dir):
    res = CliRunner().invoke(cli, ["check", "--strict"])
    assert res.exit_code == 0, res.output
    assert "note: no PATH given: checking the bundled content" in res.output
    n = len(list((root_dir / "arenas").glob("*/arena.toml"))) + len(list((root_dir / "vehicles").glob("*/vehicle.toml")))
    assert res.output.strip().splitlines()[-1] == f"0 errors, 0 warnings in {n} files"
    res = CliRunner().invoke(cli, ["check", "--rules"])
    assert res.exit_code == 0
    assert all(code in res.output for code in RULES)


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root reads everything")
def test_unreadable_file_exits_2(tmp_path):
    w = tmp_path / "walls.txt"
    w.write_text("0 0 1 0 1\n")
    w.chmod(0)
    try:
        assert run_check([w]).exit_code() == 2
    finally:
        w.chmod(0o644)


def test_folder_walk_finds_every_case_once():
    report = run_check([BROKEN])
    assert not report.unreadable
    assert len(report.files) == len(set(report.files))
    assert len(report.files) >= len(CASES)
    assert {d.code for d in report.diagnostics} >= set(RULES) - {"X001"}


# ------------------------------------------------------------------ rule details
def test_scanner_reports_every_bad_line_not_only_the_first():
    text = "0 0 10 0 1\nfoo\n0 0 0 nan 1\n10 0 10 10 3\n1 2 3\n"
    walls, diags = scan_walls_text(text, "w.txt")
    got = [(d.line, d.code) for d in diags if d.code != "A104"]
    assert got == [(2, "A101"), (3, "A102"), (4, "A103"), (5, "A101")]
    assert len(walls) == 1 and walls.lines.tolist() == [1]


def test_touching_solids_share_a_wall_without_complaint():
    from tanktool.check.walls_rules import check_walls

    def block(x0, x1):  # a solid square, normals outwards (clockwise with Direction +1)
        p = np.array([[x0, 3], [x0, 6], [x1, 6], [x1, 3]], float)
        return np.stack([p, np.roll(p, -1, axis=0)], axis=1)

    a, b = block(2, 5), block(5, 8)  # share the edge x = 5 with opposite normals
    walls = _room(np.concatenate([a, b]), [1] * 8)
    fs = analyse(walls)
    assert check_walls(walls, fs, "w.txt") == []


def _room(extra_segs=(), extra_dirs=()):
    pts = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)
    seg = np.stack([pts, np.roll(pts, -1, axis=0)], axis=1)
    segs = np.concatenate([seg, np.array(extra_segs, float).reshape(-1, 2, 2)])
    dirs = np.concatenate([np.ones(4, np.int8), np.array(extra_dirs, np.int8)])
    return WallList(segs, dirs, aux_rectangle(-1, -1, 11, 11), np.arange(1, len(segs) + 1))


def test_free_space_faces_and_sides():
    fs = analyse(_room())
    assert len(fs.faces) == 1 and fs.free.tolist() == [True]
    assert (fs.front == 0).all() and (fs.back == UNBOUNDED).all()
    assert fs.face_of(np.array([[5, 5], [20, 5]])).tolist() == [0, UNBOUNDED]
    assert len(fs.dangling) == 0


def test_t_junction_is_not_a_crossing_but_an_x_is():
    from tanktool.check.walls_rules import pair_rules
    t = _room([[[5, 0], [5, 4]]], [1])       # ends on the bottom wall: a T
    x = _room([[[5, -1], [5, 4]]], [1])      # passes through it: an X
    assert [d.code for d in pair_rules(t, 1e-7)] == []
    assert [d.code for d in pair_rules(x, 1e-7)] == ["A204"]


def test_passage_width_is_measured_wall_to_wall():
    # a 3 m door between a partition's end (7, 5) and the right wall x = 10
    fs = analyse(_room([[[0, 5], [7, 5]]], [1]))
    width, centre = fs.passage(np.array([8.0, 5.2]), 5.0)
    assert width == pytest.approx(3.0, abs=0.01)
    assert centre == pytest.approx([8.5, 5.1], abs=0.01)


def test_spawn_clearance_uses_the_footprint_and_heading():
    from tanktool.check.arena_rules import VehicleSize, blocked_spawns

    # a 4 x 2 m tank 1.5 m from the bottom wall: fine side-on, not facing the wall
    tank = VehicleSize("t", float(np.hypot(2, 1)), footprint=np.array([[2, 1], [-2, 1], [-2, -1], [2, -1]], float))
    assert tank.width == pytest.approx(2.0)
    fs = analyse(_room())
    spawns = np.array([[5, 1.5, 0.0], [5, 1.5, np.pi / 2]])
    assert blocked_spawns(fs, spawns, np.array([True, True]), tank) == [1]


def test_a_gap_to_the_middle_of_a_wall_is_measured():
    # the right wall stops 0.5 m short of the top wall, which runs on past it
    segs = [[[0, 0], [10, 0]], [[10, 0], [10, 9.5]], [[12, 10], [0, 10]], [[0, 10], [0, 0]]]
    walls = WallList(np.array(segs, float), np.ones(4), aux_rectangle(-1, -1, 13, 11), np.arange(1, 5))
    from tanktool.check.walls_rules import bare_walls_leaks

    (d,) = bare_walls_leaks(analyse(walls), "w.txt")
    assert d.code == "A301" and d.line == 2
    assert "0.50 m wide at (10.00, 9.75)" in d.message


def test_glb_reader_matches_trimesh():
    from tanktool.check.glb import read_glb_triangles
    from tanktool.formats.models import load_model

    for path in sorted(CLEAN.glob("*/*/model.glb")):
        v, f = read_glb_triangles(path)
        mesh = load_model(path, up="y")
        mine = np.sort(v[f].sum(axis=1), axis=0)
        theirs = np.sort(np.asarray(mesh.vertices)[np.asarray(mesh.faces)].sum(axis=1), axis=0)
        assert np.allclose(mine, theirs, atol=1e-6)


def test_glb_reader_refuses_what_it_does_not_read(tmp_path):
    from tanktool.check.glb import read_glb_triangles

    bad = tmp_path / "x.glb"
    bad.write_bytes(b"glTF\x02\x00\x00\x00\x10\x00\x00\x00garbage")
    assert read_glb_triangles(bad) is None
    bad.write_bytes(b"not a glb at all")
    assert read_glb_triangles(bad) is None


def test_vehicles_meet_only_their_own_arenas_and_the_checked_ones():
    fit = BROKEN / "V401_does_not_fit" / "vehicles" / "tank"
    other = BROKEN / "V302_restitution" / "vehicles" / "tank"
    report = run_check([other, fit])
    v401 = [d for d in report.diagnostics if d.code == "V401"]
    assert [Path(d.path).parent for d in v401] == [fit]  # not the vehicle of another collection
    # checked together with the narrow arena, the other vehicle meets it too (and the
    # arena, checked, reports its narrow passage)
    report = run_check([other, BROKEN / "V401_does_not_fit" / "arenas"])
    assert {(d.code, Path(d.path).parent.parent.parent.name) for d in report.diagnostics} == {
        ("V302", "V302_restitution"), ("V401", "V302_restitution"), ("A306", "V401_does_not_fit")}


def test_toml_lines_find_keys_and_array_items():
    from tanktool.check.manifest import TomlLines

    text = ('name = "a[1]"\nspawns = [[1, 2, 3], [4, 5, 6]]\n\n[source]\nfile = "x.obj"\n'
            'sha256 = "ab"\n\n[derived]\n"walls.txt" = "cd"\n'
            'more = [\n  [1, 2, 3],\n  [4, 5, 6],\n]\n')
    t = TomlLines(text)
    assert t.key("", "spawns") == 2 and t.key("source", "file") == 5
    assert t.key("derived", "walls.txt") == 9
    assert t.items("", "spawns", 2) == [2, 2]
    assert t.items("derived", "more", 2) == [11, 12]
    assert t.key("source", "nope") == 4  # falls back to the table's line
    assert t.key("nope", "nope") == 0


def test_vehicle_with_a_missing_hull_file_is_reported(tmp_path):
    shutil.copytree(CLEAN / "vehicles" / "tank", tmp_path / "tank")
    toml = tmp_path / "tank" / "vehicle.toml"
    toml.write_text(toml.read_text().replace('file = "hull.txt"', 'file = "elsewhere.txt"'))
    report = run_check([tmp_path / "tank"])
    assert [(d.code, d.line) for d in report.diagnostics] == [
        ("B202", next(i for i, ln in enumerate(toml.read_text().splitlines(), 1) if "elsewhere" in ln))]


def test_spawns_keep_their_manifest_index_when_one_is_malformed(tmp_path):
    arena = tmp_path / "arenas" / "a"
    shutil.copytree(BROKEN / "A302_spawn_in_block" / "arenas" / "spawn_in_block", arena)
    toml = arena / "arena.toml"
    text = toml.read_text()
    head, rest = text.split("spawns = [\n", 1)
    toml.write_text(head + 'spawns = [\n    "not a spawn",\n' + rest)
    codes = sorted((d.code, d.message.split(" at ")[0]) for d in run_check([arena]).diagnostics)
    assert codes == [("A302", "spawn 9"), ("B102", "spawn 0 must be [x, z, heading_rad] or [x, z, heading_rad, y] with finite numbers (coordinates within 1e+06 m of the origin), got 'not a spawn'")]


def test_a_spawn_behind_a_narrow_door_is_unreachable(tmp_path):
    import tomli_w

    from tanktool.check.manifest import tomllib

    case = tmp_path / "case"
    shutil.copytree(BROKEN / "A306_narrow_door", case)
    toml = case / "arenas" / "narrow_door" / "arena.toml"
    doc = tomllib.loads(toml.read_text())
    doc["spawns"].append([35.0, 35.0, 0.0])  # in the corner room behind the 2 m door
    toml.write_text(tomli_w.dumps(doc))
    report = run_check([case / "arenas" / "narrow_door"])
    got = {(d.code, d.message.split(":")[-1].strip()) for d in report.diagnostics if d.code == "A304"}
    assert got == {("A304", "a passage on the way is too narrow for vehicle 'tank'")}
    assert {d.code for d in report.diagnostics} == {"A304", "A306"}


@pytest.mark.parametrize("seed", range(4))
def test_synthetic_arenas_lint_clean(seed):
    """Mazes of touching square blocks (shared edges, solids walled in by solids) and
    rooms with random obstacles and courtyards are valid wall lists."""
    from tanktool.check.walls_rules import bare_walls_leaks, check_walls
    from tanktool.nav.synthetic import block_maze, random_arena

    for walls in (block_maze(seed, n=6), random_arena(seed)):
        fs = analyse(walls)
        assert [d.format() for d in check_walls(walls, fs, "w") + bare_walls_leaks(fs, "w")] == []


def test_a_long_wall_votes_for_every_face_along_it():
    # the bottom and top walls run along two rooms split by a one-sided partition:
    # each of their pieces votes for its own room, so both rooms come out free
    from tanktool.check.walls_rules import check_walls

    walls = _room([[[5, 0], [5, 10]]], [1])
    fs = analyse(walls)
    assert len(fs.faces) == 2 and fs.free.all()
    assert (fs.piece_wall == 0).sum() == 2  # the bottom wall is two pieces, one per room
    assert check_walls(walls, fs, "w") == []


# ------------------------------------------------------------------ always against vehicles
def _small_room(tmp_path: Path, monkeypatch=None) -> Path:
    """A 4.7 x 4.2 m room imported outside any arenas/ folder: no vehicle beside it.

    import-arena refuses a model where no bundled tank fits; the room is made for a
    1 m scout (a fleet of one small vehicle) so that check has something to refuse."""
    import trimesh

    import tanktool.fleet as fleet_mod

    if monkeypatch is not None:
        monkeypatch.setattr(fleet_mod, "bundled_fleet", lambda *a, **k: fleet_mod.Fleet(1.0, 2.0, 1.5, "scout",
                                                                                          "scout", "scout"))

    w, d, t, h = 4.7, 4.2, 0.2, 2.0
    parts = [trimesh.creation.box(extents=[w + 2 * t, 0.1, d + 2 * t]).apply_translation([w / 2, -0.05, d / 2])]
    for ext, c in (([w + 2 * t, h, t], [w / 2, h / 2, -t / 2]), ([w + 2 * t, h, t], [w / 2, h / 2, d + t / 2]),
                   ([t, h, d], [-t / 2, h / 2, d / 2]), ([t, h, d], [w + t / 2, h / 2, d / 2])):
        parts.append(trimesh.creation.box(extents=ext).apply_translation(c))
    trimesh.util.concatenate(parts).export(tmp_path / "room.obj")
    res = CliRunner().invoke(cli, ["import-arena", str(tmp_path / "room.obj"), "-o", str(tmp_path / "room")])
    assert res.exit_code == 0, res.output
    if monkeypatch is not None:
        monkeypatch.undo()
    return tmp_path / "room"


def test_an_arena_alone_is_checked_against_the_bundled_vehicles(tmp_path, root_dir, monkeypatch):
    # it used to pass, checked against no vehicle at all; then tanks left it in `play`
    room = _small_room(tmp_path, monkeypatch)
    report = run_check([room])
    # too small for the bundled tanks (A303); made for a scout, it has few spawns (A305)
    # and its surface was found for the scout's headroom (A312)
    assert {d.code for d in report.diagnostics} == {"A303", "A305", "A312"}
    assert all("vehicle 'heavy'" in d.message for d in report.diagnostics if d.code == "A303")
    (note,) = report.notes
    assert note.startswith("note: arena 'room' checked against the bundled vehicles 'heavy', 'light' in ")
    assert "no vehicle named or beside it" in note
    res = CliRunner().invoke(cli, ["check", str(room)])
    assert res.exit_code == 1 and note in res.output
    assert note not in CliRunner().invoke(cli, ["check", "-q", str(room)]).output
    doc = json.loads(CliRunner().invoke(cli, ["check", "--json", str(room)]).output)
    assert doc["notes"] == [note]
    # a vehicle named with it replaces the bundled ones (and no note is needed)
    small = tmp_path / "small"
    shutil.copytree(BROKEN / "V107_tiny" / "vehicles" / "tank", small)
    report = run_check([room, small])
    assert {d.code for d in report.diagnostics} == {"V107", "A305"} and report.notes == []
    # a vehicle alone meets the bundled arenas
    report = run_check([small])
    assert report.notes and report.notes[0].startswith("note: vehicle 'small' checked against the bundled arenas")


def test_the_sphere_tree_must_hold_the_surface_not_only_the_vertices(tmp_path):
    """A tree built on the 8 corners of a box holds every vertex, but its spheres leave
    parts of the faces between the corners out: V202 finds them on surface samples."""
    from tanktool.formats.bundle import dumps_toml, sha256_file
    from tanktool.geometry.sphere_build import build_sphere_tree
    from tanktool.geometry.spheres import write_spheres

    tank = tmp_path / "tank"
    shutil.copytree(CLEAN / "vehicles" / "tank", tank)
    from tanktool.check.glb import load_triangles

    v, _ = load_triangles(tank / "model.glb")
    corners = np.unique(v, axis=0)
    assert len(corners) == 8
    write_spheres(tank / "spheres.txt", build_sphere_tree(corners, levels=2, branching=4))
    from tanktool.check.manifest import tomllib

    doc = tomllib.loads((tank / "vehicle.toml").read_text())
    doc["derived"]["spheres.txt"] = sha256_file(tank / "spheres.txt")
    (tank / "vehicle.toml").write_text(dumps_toml(doc))
    report = run_check([tank])
    (d,) = [d for d in report.diagnostics if d.code == "V202"]
    assert "model vertices" not in d.message            # every vertex is held
    assert "% of the model's surface" in d.message and "points sampled over it" in d.message
    # the same samples every run
    assert run_check([tank]).diagnostics[0].message == report.diagnostics[0].message
    assert {x.code for x in report.diagnostics} <= {"V202", "V203"}


def _block(x0, x1, z0=3.0, z1=6.0):
    """A solid rectangle, normals outwards (clockwise with Direction +1)."""
    p = np.array([[x0, z0], [x0, z1], [x1, z1], [x1, z0]], float)
    return np.stack([p, np.roll(p, -1, axis=0)], axis=1)


def test_a_wall_pasted_thousands_of_times_with_tiny_offsets_is_one_a202_per_copy():
    """Near-duplicates (every end moved by up to a quarter of the tolerance) are copies
    of the first: one A202 each against it, nothing else (no A205 from slivers between
    the copies), the same faces as with the wall written once, and no pair of copies
    examined (the pair search was quadratic: 1,000 copies took seconds)."""
    from tanktool.check.walls_rules import check_walls

    base = _block(2, 5)
    once = _room(base, [1] * 4)
    fs_once = analyse(once)
    tol = 4 * fs_once.grid
    rng = np.random.default_rng(3)
    copies = base[0] + rng.uniform(-tol / 4, tol / 4, (3000, 2, 2))
    copies[::2] = copies[::2, ::-1]                    # half of them written backwards...
    dirs = np.ones(3000, np.int8)
    dirs[::2] = -1                                      # ...with the Direction that keeps the free side
    walls = _room(np.concatenate([base, copies]), [1] * 4 + dirs.tolist())
    fs = analyse(walls)
    out = check_walls(walls, fs, "w.txt")
    assert {d.code for d in out} == {"A202"}
    assert sorted(d.line for d in out) == list(range(9, 3009))
    assert all(d.message == "this wall repeats the wall on line 5" for d in out)
    assert len(fs.faces) == len(fs_once.faces) and fs.free.tolist() == fs_once.free.tolist()
    assert len(fs.dangling) == 0
    assert (fs.front[8:] == fs.front[4]).all() and (fs.back[8:] == fs.back[4]).all()


def test_what_is_and_is_not_a_copy():
    from tanktool.check.walls_rules import pair_rules

    base = _block(2, 5)
    g = analyse(_room(base, [1] * 4)).grid
    cases = {
        "a hair off, parallel, not touching": ([base[0] + [[2 * g, 0], [2 * g, 0]]], [1], ["A202"]),
        "backwards, the same free side": ([base[0][::-1]], [-1], ["A202"]),
        "backwards, the other side (two touching solids)": ([base[0][::-1]], [1], []),
        "a centimetre off, parallel": ([base[0] + [[0.01, 0], [0.01, 0]]], [1], []),
        "half of it (an overlap)": ([[base[0][0], 0.5 * (base[0][0] + base[0][1])]], [1], ["A203"]),
    }
    for what, (segs, dirs, codes) in cases.items():
        walls = _room(np.concatenate([base, np.array(segs, float)]), [1] * 4 + dirs)
        assert [d.code for d in pair_rules(walls, g)] == codes, what
