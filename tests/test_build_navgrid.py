import numpy as np
import pytest
from click.testing import CliRunner

from tanktool import grid_files
from tanktool.cli import build_navgrid as cmd
from tanktool.cli.main import cli
from tanktool.formats.bundle import read_toml, sha256_file, write_toml
from tanktool.formats.walls_txt import write_walls
from tanktool.nav.navgrid import NavGrid, build_navgrid
from tanktool.nav.quadtree import WallQuadtree
from tanktool.nav.synthetic import assemble, random_arena, rect


def _two_rooms():
    # a big room with a spawn, and a closed room nobody spawns in
    loops = [(rect(0, 0, 20, 12), True), (rect(24, 0, 30, 12), True), (rect(8, 4, 11, 7), False)]
    return assemble(loops, (-1, -1, 31, 13))


@pytest.fixture
def bundle(tmp_path, monkeypatch):
    monkeypatch.setattr(grid_files, "VEHICLES_DIR", tmp_path / "no-vehicles")
    d = tmp_path / "arenas" / "rooms"
    d.mkdir(parents=True)
    walls = _two_rooms()
    write_walls(d / "walls.txt", walls)
    write_toml(d / "arena.toml", {
        "name": "rooms", "tool_version": "0.1.0", "bounds": walls.bounds.tolist(), "floor_y": 0.0,
        "spawns": [[3.0, 3.0, 0.0], [17.0, 9.0, 3.14159]],
        "source": {"file": "rooms.obj", "sha256": "0" * 64},
        "walls": {"file": "walls.txt", "height": 1.0, "tolerance": 0.01, "count": len(walls)},
        "navgrid": {"cell": 0.5, "clearance": 1.5, "quadtree_depth": 3},
        "derived": {"walls.txt": sha256_file(d / "walls.txt")},
    })
    return d


def run(*args):
    return CliRunner().invoke(cli, ["build-navgrid", *map(str, args)])


def test_bundle_outputs_and_hashes(bundle):
    r = run(bundle, "--cell", 0.5, "--clearance", 1.0, "--annotate", "none")
    assert r.exit_code == 0, r.output
    assert "rooms: 28 x 64 nodes at 0.5 m, clearance 1 m" in r.output
    doc = read_toml(bundle / "arena.toml")
    for name in ("navgrid.npz", "quadtree.npz", "navgrid.png"):
        assert doc["derived"][name] == sha256_file(bundle / name)
    assert doc["derived"]["walls.txt"] == sha256_file(bundle / "walls.txt")  # kept
    assert doc["navgrid"] == {"cell": 0.5, "clearance": 1.0, "quadtree_depth": 3}
    assert doc["source"]["file"] == "rooms.obj" and doc["spawns"][1][0] == 17.0
    g = NavGrid.load(bundle / "navgrid.npz")
    expect = build_navgrid(_two_rooms(), 0.5, 1.0, spawns=np.array(doc["spawns"]))
    assert np.array_equal(g.valid, expect.valid) and np.array_equal(g.reachable, expect.reachable)
    # the closed room on the right is valid but unreachable from the spawns
    right = g.node_x[None, :] > 22
    assert (g.valid & right).any() and not (g.reachable & right).any()
    unreachable = int((g.valid & ~g.reachable).sum())
    assert f"{unreachable:,} unreachable" in r.output
    t = WallQuadtree.load(bundle / "quadtree.npz")
    assert len(t.leaves) == 64
    assert (bundle / "navgrid.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_defaults_come_from_the_bundle_and_vehicles(bundle, tmp_path, monkeypatch):
    r = run(bundle, "--annotate", "none")
    assert r.exit_code == 0, r.output
    assert "clearance 1.5 m (arena.toml [navgrid] clearance)" in r.output
    vehicles = tmp_path / "vehicles"
    for name, radius in (("small", 0.9), ("big", 2.25)):
        (vehicles / name).mkdir(parents=True)
        write_toml(vehicles / name / "vehicle.toml", {"name": name, "footprint_radius": radius})
    monkeypatch.setattr(grid_files, "VEHICLES_DIR", vehicles)
    r = run(bundle, "--quadtree-depth", 2, "--annotate", "none")
    assert r.exit_code == 0, r.output
    assert "clearance 2.25 m (footprint radius of vehicle 'big')" in r.output
    doc = read_toml(bundle / "arena.toml")
    assert doc["navgrid"] == {"cell": 0.5, "clearance": 2.25, "quadtree_depth": 2}
    assert len(WallQuadtree.load(bundle / "quadtree.npz").leaves) == 16


def test_bare_walls_file_svg_table_and_region(tmp_path, monkeypatch):
    monkeypatch.setattr(grid_files, "VEHICLES_DIR", tmp_path / "none")
    w = random_arena(2, size=20.0)
    write_walls(tmp_path / "yard.txt", w)
    r = run(tmp_path / "yard.txt", "--cell", 0.5, "--clearance", 0.6, "--plot", tmp_path / "yard.svg",
            "--table", tmp_path / "yard.tab", "--region", "2,2,8,6", "--annotate", "rows")
    assert r.exit_code == 0, r.output
    assert (tmp_path / "yard.navgrid.npz").exists() and (tmp_path / "yard.quadtree.npz").exists()
    assert b"<svg" in (tmp_path / "yard.svg").read_bytes()[:400]
    lines = [ln for ln in (tmp_path / "yard.tab").read_text().splitlines() if not ln.startswith("#")]
    assert len(lines) == 12 * 8  # nodes with 2 <= x <= 8 and 2 <= z <= 6 at 0.5 m
    g = NavGrid.load(tmp_path / "yard.navgrid.npz")
    i, j, x, z, v, reach, ri, ci, rt, ct = lines[0].split()
    assert float(x) >= 2 and float(z) >= 2 and int(ri) == g.row_index[0, int(i), int(j)]
    # walls.txt itself keeps the plain names
    write_walls(tmp_path / "walls.txt", w)
    assert run(tmp_path / "walls.txt", "--clearance", 0.6, "--annotate", "none").exit_code == 0
    assert (tmp_path / "navgrid.npz").exists() and (tmp_path / "navgrid.png").exists()


@pytest.mark.parametrize("args,message", [
    (["{b}", "--cell", "0"], "--cell must be > 0, got 0"),
    (["{b}", "--cell", "-1"], "--cell must be > 0"),
    (["{b}", "--clearance", "-0.5"], "--clearance must be >= 0"),
    (["{b}", "--cell", "0.001"], "nodes (limit 25,000,000); use a larger --cell"),
    (["{b}", "--region", "1,2,3"], "--region: expected four numbers"),
    (["{b}", "--region", "5,5,1,1"], "--region: need x0 < x1"),
    (["{b}", "--region", "100,100,200,200"], "lies outside the arena bounds"),
    (["{b}", "--plot", "x.jpg"], "must be .png or .svg"),
    (["{b}", "--quadtree-depth", "11"], "--quadtree-depth must be 0..10"),
    (["{b}/nowhere"], "no such arena folder or walls file"),
])
def test_bad_input_is_one_line_and_writes_nothing(bundle, args, message):
    before = (bundle / "arena.toml").read_bytes()
    r = run(*[a.format(b=bundle) for a in args])
    assert r.exit_code == 2
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0], r.output
    assert not (bundle / "navgrid.npz").exists() and not (bundle / "navgrid.png").exists()
    assert (bundle / "arena.toml").read_bytes() == before


def test_bad_files(tmp_path, bundle):
    (tmp_path / "empty").mkdir()
    r = run(tmp_path / "empty")
    assert r.exit_code == 2 and "not an arena bundle (no arena.toml)" in r.output
    (bundle / "walls.txt").write_text("0 0 1 1 1\n0 0 1\n")
    r = run(bundle, "--clearance", 1)
    assert r.exit_code == 2 and "walls.txt:2: expected 5 fields" in r.output
    assert not (bundle / "navgrid.npz").exists()


def test_picture_labels_small_grids_and_regions(tmp_path):
    from tanktool.nav.synthetic import box_arena
    from tanktool.plots.navgrid import render_navgrid

    w = box_arena(6, 4, margin=1)
    sp = np.array([[3.0, 2.0, 0.0]])
    g = build_navgrid(w, 1.0, 0.9, spawns=sp)
    svg = render_navgrid(g, w, fmt="svg", quadtree=WallQuadtree.build(w.segments, w.bounds), spawns=sp,
                         annotate="both").decode()
    # nodes at x = 1.5 .. 4.5 and z = 1.5, 2.5 keep 0.9 m: rows of 4, columns of 2
    assert g.valid.sum() == 8 and ">3/4<" in svg and ">2/2<" in svg and "spawn point" in svg
    assert "quadtree leaves (64, depth 3)" in svg
    rows_only = render_navgrid(g, w, fmt="svg", annotate="rows").decode()
    assert ">3/4<" in rows_only and ">2/2<" not in rows_only
    assert ">3/4<" not in render_navgrid(g, w, fmt="svg", annotate="none").decode()
    # a big grid is not labelled as a whole, but a region of it is
    big = build_navgrid(random_arena(1), 0.25, 0.5)
    whole = render_navgrid(big, random_arena(1), fmt="svg", annotate="cols").decode()
    assert "labels:" not in whole
    part = render_navgrid(big, random_arena(1), fmt="svg", annotate="cols", region=np.array([[10, 10], [14, 13.0]])).decode()
    assert "labels: columna/total" in part


def test_progress_bar_on_large_grids(bundle, monkeypatch):
    monkeypatch.setattr(cmd, "PROGRESS_NODES", 100)
    r = run(bundle, "--clearance", 1, "--annotate", "none")
    assert r.exit_code == 0, r.output
    assert "classifying 1,792 nodes" in r.output
    r = CliRunner().invoke(cli, ["-q", "build-navgrid", str(bundle), "--clearance", "1", "--annotate", "none"])
    assert r.exit_code == 0 and r.output == ""


@pytest.mark.parametrize("table,message", [
    ({"cell": "half"}, "[navgrid] cell must be a number > 0, got 'half'"),
    ({"cell": -1.0}, "[navgrid] cell must be a number > 0"),
    ({"quadtree_depth": 2.5}, "[navgrid] quadtree_depth must be an integer 0..10"),
])
def test_bad_navgrid_table_in_arena_toml(bundle, table, message):
    doc = read_toml(bundle / "arena.toml")
    doc["navgrid"].update(table)
    write_toml(bundle / "arena.toml", doc)
    r = run(bundle, "--clearance", 1)
    assert r.exit_code == 2 and r.output.startswith("error: ") and message in r.output, r.output
    assert "arena.toml" in r.output and not (bundle / "navgrid.npz").exists()
