"""Write tests/data/broken/: for every `tanktool check` rule, one small case that
breaks that rule and nothing else, plus tests/data/check_clean/ (a clean arena and
vehicle every case is made from).

    python tools/make_broken_corpus.py

Each case is a folder ``tests/data/broken/<CODE>_<what>/`` holding a bare walls.txt or
``arenas/<name>/`` and/or ``vehicles/<name>/`` bundles, and ``expect.json``:
``{"code", "target" (what to check, relative to the case), "path" (the file the
diagnostic names, relative to the case), "lines" (acceptable line numbers)}``.
Manifests record the sha256 of the files as broken, so a case breaks only its rule
(except the stale-file case, B203, whose point is the mismatch).
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tanktool.formats.bundle import dumps_toml, sha256_file  # noqa: E402
from tanktool.formats.vehicle_bundle import format_hull  # noqa: E402
from tanktool.formats.walls_txt import WallList, aux_rectangle, format_walls  # noqa: E402
from tanktool.geometry.mass import drive_defaults  # noqa: E402
from tanktool.geometry.sphere_build import build_points, build_sphere_tree, cover_surface  # noqa: E402
from tanktool.geometry.spheres import format_spheres  # noqa: E402

BROKEN = ROOT / "tests" / "data" / "broken"
CLEAN = ROOT / "tests" / "data" / "check_clean"

# -------------------------------------------------------------------- the clean arena
ROOM = 40.0
BLOCK = (15.0, 15.0, 25.0, 25.0)  # a solid obstacle in the middle
SPAWNS = [[5, 5, 0], [35, 5, 1.5708], [5, 35, -1.5708], [20, 5, 0], [20, 35, 3.1416],
          [5, 20, 0], [35, 20, 3.1416], [10, 10, 0.7854]]


def loop(pts: list[tuple[float, float]], free_inside: bool) -> tuple[list, list]:
    """Walls of a closed polygon, normals into free space (see nav/synthetic.py)."""
    p = np.asarray(pts, dtype=np.float64)
    seg = np.stack([p, np.roll(p, -1, axis=0)], axis=1)
    area2 = float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))
    d = 1 if (area2 > 0) == free_inside else -1
    return seg.tolist(), [d] * len(seg)


def rect(x0, z0, x1, z1):
    return [(x0, z0), (x1, z0), (x1, z1), (x0, z1)]


def base_walls() -> tuple[list, list]:
    s1, d1 = loop(rect(0, 0, ROOM, ROOM), True)
    s2, d2 = loop(rect(*BLOCK), False)
    return s1 + s2, d1 + d2


def walls_text(segs, dirs, aux=(-1.0, -1.0, ROOM + 1, ROOM + 1)) -> str:
    wl = WallList(np.array(segs, dtype=np.float64), np.array(dirs), aux_rectangle(*aux))
    return format_walls(wl, header="check corpus")


def arena_mesh(segs, bump: bool = False):
    """Floor quad at y = 0 plus a 3 m high vertical quad per wall (plus a 0.3 m bump)."""
    import trimesh

    verts = [[-1, 0, -1], [ROOM + 1, 0, -1], [ROOM + 1, 0, ROOM + 1], [-1, 0, ROOM + 1]]
    faces = [[0, 2, 1], [0, 3, 2]]  # counter-clockwise seen from +y: normal up
    for (x1, z1), (x2, z2) in segs:
        b = len(verts)
        verts += [[x1, 0, z1], [x2, 0, z2], [x2, 3, z2], [x1, 3, z1]]
        faces += [[b, b + 1, b + 2], [b, b + 2, b + 3]]
    mesh = trimesh.Trimesh(np.array(verts, float), np.array(faces), process=False)
    if bump:
        box = trimesh.creation.box(extents=[2, 0.3, 2])
        box.apply_translation([8, 0.15, 30])
        mesh = trimesh.util.concatenate([mesh, box])
    return mesh


def write_arena(out: Path, segs=None, dirs=None, spawns=None, toml_edit=None, bump=False,
                walls_txt: str | None = None, aux=(-1.0, -1.0, ROOM + 1, ROOM + 1)) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if segs is None:
        segs, dirs = base_walls()
    out.mkdir(parents=True, exist_ok=True)
    (out / "walls.txt").write_text(walls_txt if walls_txt is not None else walls_text(segs, dirs, aux))
    mesh = arena_mesh(segs, bump)
    (out / "arena.obj").write_text(mesh.export(file_type="obj"))
    (out / "model.glb").write_bytes(mesh.export(file_type="glb"))
    plt.imsave(out / "preview.png", np.zeros((2, 2)))
    doc = {
        "name": out.name, "tool_version": "corpus",
        "bounds": [[aux[0], aux[1]], [aux[2], aux[3]]], "floor_y": 0.0,
        "spawns": spawns if spawns is not None else SPAWNS,
        "source": {"file": "arena.obj", "sha256": sha256_file(out / "arena.obj"), "up": "y", "scale": 1.0},
        "model": {"file": "model.glb"},
        "walls": {"file": "walls.txt", "height": 1.0, "tolerance": 0.01, "count": len(segs)},
        "navgrid": {"cell": 1.0, "clearance": 2.5, "quadtree_depth": 5},
        "derived": {f: sha256_file(out / f) for f in ("model.glb", "walls.txt", "preview.png")},
    }
    if toml_edit:
        toml_edit(doc)
    (out / "arena.toml").write_text(dumps_toml(doc))


# ------------------------------------------------------------------- the clean vehicle
SIZE = (4.0, 2.0, 2.4)  # length (x), height (y), width (z): footprint radius 2.33 m


def write_vehicle(out: Path, hull_edit=None, spheres_edit=None, toml_edit=None, size=SIZE,
                  mass: float | None = None) -> None:
    """A box tank of ``size`` (x, y, z) and ``mass`` (default 2000 kg/m^3), its sphere
    tree refitted to hold the whole surface as import-vehicle does."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import trimesh

    out.mkdir(parents=True, exist_ok=True)
    lx, ly, lz = size
    mesh = trimesh.creation.box(extents=size)
    mesh.apply_translation([0, ly / 2, 0])
    (out / "tank.obj").write_text(mesh.export(file_type="obj"))
    (out / "model.glb").write_bytes(mesh.export(file_type="glb"))
    plt.imsave(out / "preview.png", np.zeros((2, 2)))
    corners = np.array([[lx / 2, lz / 2], [-lx / 2, lz / 2], [-lx / 2, -lz / 2], [lx / 2, -lz / 2]])[::-1]
    hull = np.vstack([np.column_stack([corners[:, 0], np.full(4, y), corners[:, 1]]) for y in (0.0, ly)])
    hull_text = format_hull(hull, "check corpus")
    v, f = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    tree = cover_surface(build_sphere_tree(build_points(v, f, 400), 2, 4), v, f)
    spheres_text = format_spheres(tree, "check corpus")
    (out / "hull.txt").write_text(hull_edit(hull_text) if hull_edit else hull_text)
    (out / "spheres.txt").write_text(spheres_edit(spheres_text) if spheres_edit else spheres_text)
    mass = 2000.0 * lx * ly * lz if mass is None else mass
    inertia = mass * (lx * lx + lz * lz) / 12.0
    doc = {
        "name": out.name, "tool_version": "corpus",
        "footprint_radius": round(float(np.hypot(lx / 2, lz / 2)), 4),
        "source": {"file": "tank.obj", "sha256": sha256_file(out / "tank.obj"), "up": "y", "scale": 1.0},
        "model": {"file": "model.glb"},
        "mass": {"mass": mass, "inertia": round(inertia, 3), "centre_of_mass": [0.0, ly / 2, 0.0],
                 "method": "mesh", "volume": lx * ly * lz},
        "drive": drive_defaults(mass, inertia),
        "hull": {"file": "hull.txt", "points": 8, "footprint_area": lx * lz, "convex_area": lx * lz},
        "spheres": {"file": "spheres.txt", "levels": int(tree.levels), "branching": 4, "count": len(tree)},
        "derived": {f: sha256_file(out / f) for f in ("model.glb", "hull.txt", "spheres.txt", "preview.png")},
    }
    if toml_edit:
        toml_edit(doc)
    (out / "vehicle.toml").write_text(dumps_toml(doc))


# ------------------------------------------------------------------------- helpers
def line_of(path: Path, needle: str) -> int:
    for no, line in enumerate(path.read_text().splitlines(), 1):
        if needle in line:
            return no
    raise ValueError(f"{needle!r} not in {path}")


def wall_line(path: Path, seg) -> int:
    """Line of the wall with these end points in a walls.txt."""
    (x1, z1), (x2, z2) = seg
    want = [float(x1), float(z1), float(x2), float(z2)]
    for no, line in enumerate(path.read_text().splitlines(), 1):
        f = line.split("#", 1)[0].split()
        if len(f) == 5 and [float(v) for v in f[:4]] == want:
            return no
    raise ValueError(f"wall {seg} not in {path}")


def spawn_line(path: Path, i: int) -> int:
    """Line where spawn ``i`` starts in a manifest written by dumps_toml (a spawn a line,
    or one number a line as tomli_w alone writes them)."""
    lines = path.read_text().splitlines()
    start = next(no for no, ln in enumerate(lines, 1) if ln.startswith("spawns = "))
    items = []
    for no, ln in enumerate(lines[start:], start + 1):  # "    [" (one number a line) or "    [x, z, h],"
        if not ln.startswith("    ["):
            break
        items.append(no)
    return items[i]


def first_field_line(path: Path, first: str, nfields: int) -> int:
    """Line of the first data line with ``nfields`` fields starting with ``first``."""
    for no, line in enumerate(path.read_text().splitlines(), 1):
        f = line.split("#", 1)[0].split()
        if len(f) == nfields and f[0] == first:
            return no
    raise ValueError(f"no line starting {first!r} with {nfields} fields in {path}")


def expect(case: Path, code: str, target: str, path: str, lines: list[int]) -> None:
    (case / "expect.json").write_text(json.dumps(
        {"code": code, "target": target, "path": path, "lines": lines}, indent=1) + "\n")


def edit_lines(text: str, fn) -> str:
    return "\n".join(fn(text.splitlines())) + "\n"


# --------------------------------------------------------------------------- cases
def walls_case(name: str, code: str, segs, dirs, mutate=None, aux=(-1.0, -1.0, ROOM + 1, ROOM + 1)):
    case = BROKEN / f"{code}_{name}"
    case.mkdir(parents=True)
    text = walls_text(segs, dirs, aux)
    if mutate:
        text = mutate(text)
    (case / "walls.txt").write_text(text)
    return case


#: a corner room behind a 2 m door: the 2.4 m wide tank cannot get in (no spawn is there)
DOOR_PART = [[[28, 40], [28, 30]], [[28, 30], [38, 30]]]


def make_cases() -> None:
    """Every case of the rules on walls.txt, arenas, bundle files and vehicles."""
    segs, dirs = base_walls()
    _walls_cases(segs, dirs)
    _arena_cases(segs, dirs)
    _bundle_cases()
    _vehicle_cases(segs, dirs)


def _walls_cases(segs, dirs) -> None:
    """A101-A105 (walls.txt syntax) and A201-A205 (wall geometry), bare walls files."""
    def replace_wall(text, seg, new):
        (x1, z1), (x2, z2) = seg
        out = []
        for line in text.splitlines():
            f = line.split()
            if len(f) == 5 and not line.startswith("#") and [float(v) for v in f[:4]] == [x1, z1, x2, z2]:
                line = new
            out.append(line)
        return "\n".join(out) + "\n"

    def insert_line(text, new):  # an extra bad line among the walls: the walls stay closed
        return text.replace("# auxiliary", new + "\n# auxiliary")

    c = walls_case("bad_fields", "A101", segs, dirs, lambda t: insert_line(t, "12 3 12 4.5"))
    expect(c, "A101", "walls.txt", "walls.txt", [line_of(c / "walls.txt", "12 3 12 4.5")])
    c = walls_case("nan", "A102", segs, dirs, lambda t: insert_line(t, "12 3 nan 4.5 1"))
    expect(c, "A102", "walls.txt", "walls.txt", [line_of(c / "walls.txt", "nan")])
    c = walls_case("direction", "A103", segs, dirs, lambda t: insert_line(t, "12 3 12 4.5 2"))
    expect(c, "A103", "walls.txt", "walls.txt", [line_of(c / "walls.txt", "12 3 12 4.5 2")])
    c = walls_case("no_aux", "A104", segs, dirs, lambda t: t.split("# auxiliary")[0])
    expect(c, "A104", "walls.txt", "walls.txt", [len((c / "walls.txt").read_text().splitlines())])
    c = walls_case("aux_not_enclosing", "A105", segs, dirs, aux=(-1.0, -1.0, 30.0, 41.0))
    expect(c, "A105", "walls.txt", "walls.txt", [line_of(c / "walls.txt", "# auxiliary") + 1])

    # --- wall geometry
    c = walls_case("zero_length", "A201", segs + [[[10, 10], [10, 10]]], dirs + [1])
    expect(c, "A201", "walls.txt", "walls.txt", [wall_line(c / "walls.txt", [[10, 10], [10, 10]])])
    c = walls_case("duplicate", "A202", segs + [segs[1]], dirs + [dirs[1]])
    n = [no for no, ln in enumerate((c / "walls.txt").read_text().splitlines(), 1) if ln.startswith("40 0 40 40")]
    expect(c, "A202", "walls.txt", "walls.txt", [n[-1]])
    c = walls_case("overlap", "A203", segs + [[[10, 0], [30, 0]]], dirs + [dirs[0]])
    expect(c, "A203", "walls.txt", "walls.txt", [wall_line(c / "walls.txt", [[10, 0], [30, 0]])])
    c = walls_case("crossing", "A204", segs + [[[12, 20], [20, 20]]], dirs + [1])
    expect(c, "A204", "walls.txt", "walls.txt",
           [wall_line(c / "walls.txt", [[12, 20], [20, 20]]), wall_line(c / "walls.txt", [[15, 25], [15, 15]])])
    flipped = list(dirs)
    flipped[1] = -flipped[1]
    c = walls_case("flipped_normal", "A205", segs, flipped)
    expect(c, "A205", "walls.txt", "walls.txt", [wall_line(c / "walls.txt", segs[1])])


def _arena_cases(segs, dirs) -> None:
    """A301-A308: free space and spawn points (arena bundles)."""
    leaky = [[[0, 0], [18, 0]], [[22, 0], [40, 0]]] + segs[1:]
    c = BROKEN / "A301_leak"
    write_arena(c / "arenas" / "leaky", leaky, [dirs[0]] + dirs)
    w = c / "arenas" / "leaky" / "walls.txt"
    expect(c, "A301", "arenas/leaky", "arenas/leaky/walls.txt", [wall_line(w, leaky[0]), wall_line(w, leaky[1])])

    def spawn_case(code, name, spawns, vehicle=False, segs_=segs, dirs_=dirs, aux=(-1.0, -1.0, ROOM + 1, ROOM + 1)):
        c = BROKEN / f"{code}_{name}"
        write_arena(c / "arenas" / name, segs_, dirs_, spawns=spawns, aux=aux)
        if vehicle:
            write_vehicle(c / "vehicles" / "tank")
        return c

    c = spawn_case("A302", "spawn_in_block", SPAWNS + [[20, 20, 0]])
    expect(c, "A302", "arenas/spawn_in_block", "arenas/spawn_in_block/arena.toml",
           [spawn_line(c / "arenas/spawn_in_block/arena.toml", 8)])
    c = spawn_case("A303", "spawn_near_wall", SPAWNS + [[2, 12, 0]], vehicle=True)
    expect(c, "A303", "arenas/spawn_near_wall", "arenas/spawn_near_wall/arena.toml",
           [spawn_line(c / "arenas/spawn_near_wall/arena.toml", 8)])
    s2, d2 = loop(rect(50, 0, 60, 10), True)
    c = spawn_case("A304", "spawn_cut_off", SPAWNS + [[55, 5, 0]], segs_=segs + s2, dirs_=dirs + d2,
                   aux=(-1.0, -1.0, 61.0, 41.0))
    expect(c, "A304", "arenas/spawn_cut_off", "arenas/spawn_cut_off/arena.toml",
           [spawn_line(c / "arenas/spawn_cut_off/arena.toml", 8)])
    c = spawn_case("A305", "few_spawns", SPAWNS[:7])
    expect(c, "A305", "arenas/few_spawns", "arenas/few_spawns/arena.toml",
           [line_of(c / "arenas/few_spawns/arena.toml", "spawns = ")])
    part = DOOR_PART
    c = spawn_case("A306", "narrow_door", SPAWNS, vehicle=True, segs_=segs + part, dirs_=dirs + [1, 1])
    w = c / "arenas/narrow_door/walls.txt"
    expect(c, "A306", "arenas/narrow_door", "arenas/narrow_door/walls.txt",
           [wall_line(w, part[1]), wall_line(w, segs[1])])
    s3, d3 = loop(rect(18, 18, 22, 22), True)  # a courtyard inside the block
    c = spawn_case("A307", "island", SPAWNS, segs_=segs + s3, dirs_=dirs + d3)
    w = c / "arenas/island/walls.txt"
    expect(c, "A307", "arenas/island", "arenas/island/walls.txt", [wall_line(w, s) for s in s3])
    c = BROKEN / "A308_bumpy_floor"
    write_arena(c / "arenas" / "bumpy", bump=True)
    expect(c, "A308", "arenas/bumpy", "arenas/bumpy/arena.toml", [line_of(c / "arenas/bumpy/arena.toml", "floor_y")])


def _bundle_cases() -> None:
    """B101-B301: the files of a bundle, and what play cannot load."""
    c = BROKEN / "B101_bad_toml"
    write_arena(c / "arenas" / "a")
    t = c / "arenas/a/arena.toml"
    t.write_text(t.read_text().replace("floor_y = 0.0", "floor_y = = 0.0"))
    expect(c, "B101", "arenas/a", "arenas/a/arena.toml", [line_of(t, "floor_y")])
    c = BROKEN / "B102_bad_key"
    write_arena(c / "arenas" / "a", toml_edit=lambda d: d.update(floor_y="low"))
    expect(c, "B102", "arenas/a", "arenas/a/arena.toml", [line_of(c / "arenas/a/arena.toml", "floor_y")])
    c = BROKEN / "B201_source_missing"
    write_arena(c / "arenas" / "a")
    (c / "arenas/a/arena.obj").unlink()
    expect(c, "B201", "arenas/a", "arenas/a/arena.toml", [line_of(c / "arenas/a/arena.toml", 'file = "arena.obj"')])
    c = BROKEN / "B202_derived_missing"
    write_arena(c / "arenas" / "a")
    (c / "arenas/a/preview.png").unlink()
    expect(c, "B202", "arenas/a", "arenas/a/arena.toml", [line_of(c / "arenas/a/arena.toml", '"preview.png" = ')])
    c = BROKEN / "B203_stale"
    write_arena(c / "arenas" / "a")
    with open(c / "arenas/a/walls.txt", "a") as f:
        f.write("# edited by hand after the build\n")
    expect(c, "B203", "arenas/a", "arenas/a/arena.toml", [line_of(c / "arenas/a/arena.toml", '"walls.txt" = ')])
    c = BROKEN / "B204_source_changed"
    write_arena(c / "arenas" / "a")
    with open(c / "arenas/a/arena.obj", "a") as f:
        f.write("# edited\n")
    expect(c, "B204", "arenas/a", "arenas/a/arena.toml", [line_of(c / "arenas/a/arena.toml", "sha256")])
    c = BROKEN / "B205_texture_missing"
    write_arena(c / "arenas" / "a", toml_edit=lambda d: d["model"].update(textures=["textures/wall.png"]))
    expect(c, "B205", "arenas/a", "arenas/a/arena.toml", [line_of(c / "arenas/a/arena.toml", "textures = ")])

    # --- what play cannot load although no other rule objects: [walls] is not a table
    c = BROKEN / "B301_walls_not_a_table"
    write_arena(c / "arenas" / "a", toml_edit=lambda d: d.update(walls=1))
    expect(c, "B301", "arenas/a", "arenas/a/arena.toml", [line_of(c / "arenas/a/arena.toml", "walls = 1")])


def _vehicle_cases(segs, dirs) -> None:
    """V101-V401: vehicle bundles."""
    def vcase(code, name, **kw):
        c = BROKEN / f"{code}_{name}"
        write_vehicle(c / "vehicles" / "tank", **kw)
        return c, c / "vehicles/tank"

    c, v = vcase("V101", "hull_bad_line", hull_edit=lambda t: t.replace("-2.0000 0.0000 -1.2000", "-2.0000 0.0000"))
    expect(c, "V101", "vehicles/tank", "vehicles/tank/hull.txt", [first_field_line(v / "hull.txt", "-2.0000", 2)])
    c, v = vcase("V102", "hull_six_points", hull_edit=lambda t: edit_lines(t, lambda ls: ls[:-2]))
    expect(c, "V102", "vehicles/tank", "vehicles/tank/hull.txt", [0])

    def shrink_hull(t):
        def f(ls):
            out = []
            for ln in ls:
                p = ln.split()
                if len(p) == 3 and not ln.startswith("#"):
                    ln = f"{float(p[0]) * 0.8:.4f} {p[1]} {float(p[2]) * 0.8:.4f}"
                out.append(ln)
            return out
        return edit_lines(t, f)
    c, v = vcase("V103", "hull_too_small", hull_edit=shrink_hull)
    expect(c, "V103", "vehicles/tank", "vehicles/tank/hull.txt", [0])
    c, v = vcase("V104", "com_outside", toml_edit=lambda d: d["mass"].update(centre_of_mass=[5.0, 1.0, 0.0]))
    expect(c, "V104", "vehicles/tank", "vehicles/tank/vehicle.toml", [line_of(v / "vehicle.toml", "centre_of_mass")])
    # imported with the wrong up axis: 3 m tall, 2 m wide
    c, v = vcase("V105", "on_its_side", size=(4.0, 3.0, 2.0))
    expect(c, "V105", "vehicles/tank", "vehicles/tank/vehicle.toml", [line_of(v / "vehicle.toml", "up = ")])
    # its front along z: 2.4 m long, 4 m across
    c, v = vcase("V106", "sideways", size=(2.4, 2.0, 4.0))
    expect(c, "V106", "vehicles/tank", "vehicles/tank/vehicle.toml", [line_of(v / "vehicle.toml", "up = ")])
    # a model in decimetres imported as metres: 0.4 m long (given a plausible mass)
    c, v = vcase("V107", "tiny", size=(0.4, 0.2, 0.24), mass=150.0)
    expect(c, "V107", "vehicles/tank", "vehicles/tank/vehicle.toml", [line_of(v / "vehicle.toml", "footprint_radius")])
    c, v = vcase("V201", "spheres_bad_line", spheres_edit=lambda t: t.replace("\n1 0 2 ", "\n1 0 2 x "))
    expect(c, "V201", "vehicles/tank", "vehicles/tank/spheres.txt", [line_of(v / "spheres.txt", "1 0 2 x ")])

    def scale_sphere(t, sid, k):
        def f(ls):
            out = []
            for ln in ls:
                p = ln.split()
                if len(p) == 7 and p[0] == str(sid):
                    p[6] = f"{float(p[6]) * k:.4f}"
                    ln = " ".join(p)
                out.append(ln)
            return out
        return edit_lines(t, f)
    c, v = vcase("V202", "leaf_too_small", spheres_edit=lambda t: scale_sphere(t, 1, 0.3))
    expect(c, "V202", "vehicles/tank", "vehicles/tank/spheres.txt", [first_field_line(v / "spheres.txt", "1", 7)])
    c, v = vcase("V203", "root_too_small", spheres_edit=lambda t: scale_sphere(t, 0, 0.6))
    expect(c, "V203", "vehicles/tank", "vehicles/tank/spheres.txt", [first_field_line(v / "spheres.txt", "0", 7)])
    c, v = vcase("V301", "negative_mass", toml_edit=lambda d: d["mass"].update(mass=-5.0))
    expect(c, "V301", "vehicles/tank", "vehicles/tank/vehicle.toml", [line_of(v / "vehicle.toml", "mass = -5")])
    c, v = vcase("V302", "restitution", toml_edit=lambda d: d["drive"].update(restitution=1.5))
    expect(c, "V302", "vehicles/tank", "vehicles/tank/vehicle.toml", [line_of(v / "vehicle.toml", "restitution")])
    c, v = vcase("V303", "top_speed", toml_edit=lambda d: d["drive"].update(top_speed=80.0))
    expect(c, "V303", "vehicles/tank", "vehicles/tank/vehicle.toml", [line_of(v / "vehicle.toml", "top_speed")])
    c = BROKEN / "V401_does_not_fit"
    write_vehicle(c / "vehicles" / "tank")
    write_arena(c / "arenas" / "narrow_door", segs + DOOR_PART, dirs + [1, 1])
    expect(c, "V401", "vehicles/tank", "vehicles/tank/vehicle.toml",
           [line_of(c / "vehicles/tank/vehicle.toml", "footprint_radius")])


# ------------------------------------------------------- levels and the navigation grid
GRID_ORIGIN = (-1.0, -1.0)
GRID_CELL = 1.0
GRID_SHAPE = (42, 42)


def grid_nodes() -> tuple[np.ndarray, np.ndarray]:
    """(z, x) of every node of the corpus grid (cell centres), each (nz, nx)."""
    zs = GRID_ORIGIN[1] + (np.arange(GRID_SHAPE[0]) + 0.5) * GRID_CELL
    xs = GRID_ORIGIN[0] + (np.arange(GRID_SHAPE[1]) + 0.5) * GRID_CELL
    return np.meshgrid(zs, xs, indexing="ij")


def free_nodes(margin: float = 2.5) -> np.ndarray:
    """Nodes of the clean room at ``margin`` from its walls and block."""
    z, x = grid_nodes()
    inside = (x > margin) & (x < ROOM - margin) & (z > margin) & (z < ROOM - margin)
    b0, c0, b1, c1 = BLOCK
    block = (x > b0 - margin) & (x < b1 + margin) & (z > c0 - margin) & (z < c1 + margin)
    return inside & ~block


def write_grid(bundle: Path, valid: np.ndarray, reachable: np.ndarray | None = None,
               height: np.ndarray | None = None) -> None:
    """navgrid.npz from a hand-made (L, nz, nx) mask, its hash added to arena.toml."""
    from tanktool.formats.bundle import read_toml
    from tanktool.nav.navgrid import NavGrid, layered_runs, links_from_valid

    v = np.asarray(valid, dtype=bool)
    v = v[None] if v.ndim == 2 else v
    link = links_from_valid(v)
    ri, rt, ci, ct = layered_runs(v, link)
    reach = v.copy() if reachable is None else np.asarray(reachable, dtype=bool).reshape(v.shape)
    h = np.where(v, 0.0, np.nan) if height is None else np.where(v, height, np.nan)
    arrays = [v, ri, rt, ci, ct, reach & v]
    # to_bytes writes a one-level grid as (nz, nx), the corpus's bytes as before
    grid = NavGrid(np.array(GRID_ORIGIN), GRID_CELL, GRID_SHAPE, *arrays, 2.5, height=h, link=link)
    (bundle / "navgrid.npz").write_bytes(grid.to_bytes())
    doc = read_toml(bundle / "arena.toml")
    doc["derived"]["navgrid.npz"] = sha256_file(bundle / "navgrid.npz")
    (bundle / "arena.toml").write_text(dumps_toml(doc))


def layered_walls(segs, dirs) -> str:
    """The clean room's walls as region 0 of level 0, and a deck's edge as region 1 of
    level 1 (a walls file in blocks)."""
    deck, ddirs = loop(rect(28, 28, 36, 36), True)
    wl = WallList(np.array(segs + deck, dtype=np.float64), np.array(dirs + ddirs), aux_rectangle(-1.0, -1.0, ROOM + 1, ROOM + 1),
                  level=[0] * len(segs) + [1] * len(deck), region=[0] * len(segs) + [1] * len(deck),
                  regions={0: (0, 0.0, 0.0), 1: (1, 4.0, 4.0)})
    return format_walls(wl, header="check corpus: two levels")


def make_level_cases() -> None:
    """A309 - A315: the walkable levels and the navigation grid."""
    segs, dirs = base_walls()
    walkable = {"cell": GRID_CELL, "cell_height": 0.1, "max_slope": 35.0, "climb": 0.9, "headroom": 2.5}

    def case(code: str, name: str, spawns=None, walls_txt=None, vehicle=True, headroom=2.5):
        c = BROKEN / f"{code}_{name}"
        b = c / "arenas" / name
        write_arena(b, segs, dirs, spawns=spawns, walls_txt=walls_txt,
                    toml_edit=lambda d: d.update(walkable={**walkable, "headroom": headroom}))
        if vehicle:
            write_vehicle(c / "vehicles" / "tank")
        return c, b

    free = free_nodes()
    c, b = case("A309", "no_usable_grid")
    write_grid(b, np.zeros_like(free))
    expect(c, "A309", f"arenas/{b.name}", f"arenas/{b.name}/arena.toml", [line_of(b / "arena.toml", "[navgrid]")])
    c, b = case("A310", "unreachable_level")
    deck = np.zeros_like(free)
    deck[30:35, 30:35] = True
    write_grid(b, np.stack([free, deck]), np.stack([free, np.zeros_like(free)]), np.stack([0 * free, 4 + 0 * free]))
    expect(c, "A310", f"arenas/{b.name}", f"arenas/{b.name}/arena.toml", [line_of(b / "arena.toml", "[navgrid]")])
    c, b = case("A311", "spawn_on_island", SPAWNS[:7] + [[31.5, 31.5, 0]])
    z, x = grid_nodes()
    ring = (np.abs(x - 31.5) <= 3) & (np.abs(z - 31.5) <= 3) & ~((np.abs(x - 31.5) <= 1) & (np.abs(z - 31.5) <= 1))
    write_grid(b, free & ~ring | ((np.abs(x - 31.5) <= 1) & (np.abs(z - 31.5) <= 1)))
    expect(c, "A311", f"arenas/{b.name}", f"arenas/{b.name}/arena.toml", [spawn_line(b / "arena.toml", 7)])
    c, b = case("A312", "low_headroom", headroom=1.0)
    write_grid(b, free)   # an imported bundle has its grid (a missing one is B202)
    expect(c, "A312", f"arenas/{b.name}", f"arenas/{b.name}/arena.toml", [line_of(b / "arena.toml", "headroom = ")])
    c, b = case("A313", "spawn_on_slope")
    slope = np.where(x > 30, (x - 30) * np.tan(np.radians(28)), 0.0)  # 28 deg east of x = 30, under spawn 1
    write_grid(b, free, height=slope)
    expect(c, "A313", f"arenas/{b.name}", f"arenas/{b.name}/arena.toml", [spawn_line(b / "arena.toml", 1)])
    two = layered_walls(segs, dirs)
    c, b = case("A314", "spawn_off_grid", walls_txt=two)
    hole = (np.abs(x - 5) <= 3) & (np.abs(z - 20) <= 3)  # around spawn 5 at (5, 20)
    deck = np.zeros_like(free)
    deck[31:35, 31:35] = True
    write_grid(b, np.stack([free & ~hole, deck]), height=np.stack([0 * free, 4 + 0 * free]))
    expect(c, "A314", f"arenas/{b.name}", f"arenas/{b.name}/arena.toml", [spawn_line(b / "arena.toml", 5)])
    c, b = case("A315", "spawns_apart", walls_txt=two)
    cut = (np.abs(z - 27.5) <= 1.0)  # the grid cut in two along z = 27.5: spawns 2 and 4 beyond it
    write_grid(b, np.stack([free & ~cut, deck]), height=np.stack([0 * free, 4 + 0 * free]))
    expect(c, "A315", f"arenas/{b.name}", f"arenas/{b.name}/arena.toml",
           [spawn_line(b / "arena.toml", 2), spawn_line(b / "arena.toml", 4)])


def main() -> int:
    for d in (BROKEN, CLEAN):
        if d.exists():
            shutil.rmtree(d)
    write_arena(CLEAN / "arenas" / "yard")
    write_vehicle(CLEAN / "vehicles" / "tank")
    make_cases()
    make_level_cases()
    print(f"wrote {len(list(BROKEN.iterdir()))} cases under {BROKEN.relative_to(ROOT)} and {CLEAN.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
