"""Author the source models of the bundled arenas and import each one.

    .venv/bin/python tools/make_arena_models.py [--only NAME] [--models-only]

Every arena is built from boxes (trimesh) on a floor slab, with one colour per kind
of part, in the world frame (metres, Y up), and written where its bundle keeps its
source model:

* ``arenas/box/box.obj``        -- a 60 x 60 m walled yard with four crates for cover
* ``arenas/maze/maze.obj``      -- a 104 x 104 m maze of 13 m cells (12 m passages),
                                   a seeded depth-first maze with extra openings so it
                                   has loops
* ``arenas/hills/hills.obj``    -- 120 x 120 m of rolling terrain inside a wall, rocks
* ``arenas/fort/fort.obj``      -- a walled yard with a fort whose roof is a second floor
                                   on ramps, a gate passage under it, a bridged sunken road
  (both from tools/make_levels.py)
* ``arenas/paper2002/paper2002.3ds`` -- the 2002 paper's arena (table 3.4.4.1 starts
  ``0 0 0 200 / 0 200 50 200 / 50 200 50 300 / 50 300 0 300 / 0 300 0 450 /
  0 450 50 500 / 50 500 200 500``), completed symmetrically into a closed 250 x 500
  outline with five blocks inside, at 0.2 m per paper unit (50 x 100 m).  Walls are
  thick boxes placed outside each outline edge; stored as .3ds (Z up), so it is
  imported with ``--up z``.

Each material gets a texture of tools/make_textures.py (its ``ARENA_TEXTURES``): the
.obj sources are given texture coordinates by ``make_textures.texture_obj`` after they
are written, the .3ds one is written with them (box projection, in metres).

Then each is run through ``import-arena`` (tanktool.importer.import_arena) into
``arenas/<name>/``.  ``make arenas`` (tools/build_arenas.py) rebuilds the derived
files of the bundles from these sources later without re-authoring them.
"""

from __future__ import annotations

import argparse
import random
import sys
from pathlib import Path

import numpy as np
import trimesh

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))
import make_levels  # noqa: E402

WALL_H = 3.0  # m, well above the 1 m cut
SLAB = 0.5  # floor slab thickness (m)

COLOURS = {
    "floor": (0.42, 0.45, 0.38),
    "wall": (0.62, 0.36, 0.27),
    "crate": (0.55, 0.42, 0.22),
    "block": (0.45, 0.47, 0.55),
}
COLOURS.update({k: v for k, v in make_levels.COLOURS.items() if k not in COLOURS})   # the generated levels' kinds

#: the 2002 paper's free-space outline, completed (paper units); x right, z up
PAPER_OUTLINE = [
    (0, 0), (0, 200), (50, 200), (50, 300), (0, 300), (0, 450), (50, 500), (200, 500),
    (250, 450), (250, 300), (200, 300), (200, 200), (250, 200), (250, 0),
]
#: blocks inside it (paper units): a central pillar and two pairs
PAPER_BLOCKS = [(100, 225, 150, 275), (50, 75, 100, 100), (150, 75, 200, 100),
                (50, 400, 100, 425), (150, 400, 200, 425)]
PAPER_SCALE = 0.2  # m per paper unit
PAPER_WALL = 10  # paper units of wall thickness (2 m)


def box(x0: float, z0: float, x1: float, z1: float, y0: float, y1: float) -> trimesh.Trimesh:
    b = trimesh.creation.box(extents=[x1 - x0, y1 - y0, z1 - z0])
    b.apply_translation([(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2])
    return b


def edge_box(p: np.ndarray, q: np.ndarray, thick: float, ext0: float, ext1: float, h: float) -> trimesh.Trimesh:
    """A wall box on the right-hand side of the edge p -> q (outside a CCW
    outline), lengthened by ext0 / ext1 beyond p / q to close outer corners."""
    d = q - p
    length = float(np.hypot(*d))
    u = d / length
    right = np.array([u[1], -u[0]])
    b = trimesh.creation.box(extents=[length + ext0 + ext1, h, thick])
    # box local x along the edge, local z across it
    centre = p + u * (length + ext1 - ext0) / 2 + right * thick / 2
    angle = np.arctan2(u[1], u[0])
    rot = trimesh.transformations.rotation_matrix(-angle, [0, 1, 0])  # x -> (cos, sin) in (x, z)
    b.apply_transform(rot)
    b.apply_translation([centre[0], h / 2, centre[1]])
    return b


def outline_walls(outline: list[tuple[float, float]], thick: float, h: float) -> list[trimesh.Trimesh]:
    """Thick wall boxes around a closed free-space outline (any orientation)."""
    pts = np.asarray(outline, dtype=np.float64)
    area = 0.5 * np.sum(pts[:, 0] * np.roll(pts[:, 1], -1) - np.roll(pts[:, 0], -1) * pts[:, 1])
    if area < 0:
        pts = pts[::-1]
    n = len(pts)
    convex = np.zeros(n, dtype=bool)
    for i in range(n):
        a, b, c = pts[i - 1], pts[i], pts[(i + 1) % n]
        convex[i] = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]) > 0
    parts = []
    for i in range(n):
        p, q = pts[i], pts[(i + 1) % n]
        # at a convex corner of the free space the outer corner is open: lengthen
        parts.append(edge_box(p, q, thick, thick if convex[i] else 0.0, thick if convex[(i + 1) % n] else 0.0, h))
    return parts


def model_box() -> list[tuple[str, str, trimesh.Trimesh]]:
    s, t = 60.0, 1.0
    out = [("floor", "floor", box(0, 0, s, s, -SLAB, 0))]
    out += [("wall_s", "wall", box(0, 0, s, t, 0, WALL_H)), ("wall_n", "wall", box(0, s - t, s, s, 0, WALL_H)),
            ("wall_w", "wall", box(0, t, t, s - t, 0, WALL_H)), ("wall_e", "wall", box(s - t, t, s, s - t, 0, WALL_H))]
    for k, (cx, cz) in enumerate([(20, 20), (40, 20), (20, 40), (40, 40)]):
        out.append((f"crate{k}", "crate", box(cx - 2, cz - 2, cx + 2, cz + 2, 0, 2.0)))
    return out


def _runs(flags: list[bool]) -> list[tuple[int, int]]:
    """(start, stop) of each run of True in ``flags``: one wall per run of wall pieces."""
    out, k = [], 0
    while k < len(flags):
        if flags[k]:
            k0 = k
            while k < len(flags) and flags[k]:
                k += 1
            out.append((k0, k))
        else:
            k += 1
    return out


def model_maze(cells: int = 8, cell: float = 13.0, t: float = 1.0, seed: int = 2002) -> list[tuple[str, str, trimesh.Trimesh]]:
    rng = random.Random(seed)
    # walls between cells: h[i][j] the wall south of cell (i, j); v[i][j] west of it
    h = [[True] * cells for _ in range(cells + 1)]
    v = [[True] * (cells + 1) for _ in range(cells)]
    seen = [[False] * cells for _ in range(cells)]
    stack = [(0, 0)]
    seen[0][0] = True
    while stack:
        i, j = stack[-1]
        nxt = [(di, dj) for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1))
               if 0 <= i + di < cells and 0 <= j + dj < cells and not seen[i + di][j + dj]]
        if not nxt:
            stack.pop()
            continue
        di, dj = rng.choice(nxt)
        if di == 1:
            h[i + 1][j] = False
        elif di == -1:
            h[i][j] = False
        elif dj == 1:
            v[i][j + 1] = False
        else:
            v[i][j] = False
        seen[i + di][j + dj] = True
        stack.append((i + di, j + dj))
    # extra openings so there are loops to flank through
    for _ in range(cells // 2):
        if rng.random() < 0.5:
            i, j = rng.randrange(1, cells), rng.randrange(cells)
            h[i][j] = False
        else:
            i, j = rng.randrange(cells), rng.randrange(1, cells)
            v[i][j] = False
    size = cells * cell
    out = [("floor", "floor", box(-t / 2, -t / 2, size + t / 2, size + t / 2, -SLAB, 0))]
    k = 0
    for i in range(cells + 1):  # runs of horizontal walls
        z = i * cell
        for j0, j in _runs(h[i]):
            out.append((f"h{k}", "wall", box(j0 * cell - t / 2, z - t / 2, j * cell + t / 2, z + t / 2, 0, WALL_H)))
            k += 1
    for j in range(cells + 1):  # runs of vertical walls
        x = j * cell
        for i0, i in _runs([v[i][j] for i in range(cells)]):
            out.append((f"v{k}", "wall", box(x - t / 2, i0 * cell - t / 2, x + t / 2, i * cell + t / 2, 0, WALL_H)))
            k += 1
    return out


def model_paper2002() -> list[tuple[str, str, trimesh.Trimesh]]:
    s = PAPER_SCALE
    outline = [(x * s, z * s) for x, z in PAPER_OUTLINE]
    w = PAPER_WALL * s
    x1 = max(x for x, _ in outline)
    z1 = max(z for _, z in outline)
    out = [("floor", "floor", box(-w, -w, x1 + w, z1 + w, -SLAB, 0))]
    for k, b in enumerate(outline_walls(outline, w, WALL_H)):
        out.append((f"wall{k:02d}", "wall", b))
    for k, (a, b, c, d) in enumerate(PAPER_BLOCKS):
        out.append((f"block{k}", "block", box(a * s, b * s, c * s, d * s, 0, WALL_H)))
    return out


def write_obj(path: Path, parts: list[tuple[str, str, trimesh.Trimesh]]) -> None:
    """A plain OBJ with one object per part and a material library of diffuse colours."""
    mtl = path.with_suffix(".mtl")
    lines = [f"# {path.name}: authored by tools/make_arena_models.py (metres, Y up)", f"mtllib {mtl.name}"]
    base = 1
    for name, kind, mesh in parts:
        lines.append(f"o {name}")
        lines.append(f"usemtl {kind}")
        lines += [f"v {x:.6g} {y:.6g} {z:.6g}" for x, y, z in mesh.vertices]
        lines += [f"f {a + base} {b + base} {c + base}" for a, b, c in mesh.faces]
        base += len(mesh.vertices)
    path.write_text("\n".join(lines) + "\n")
    used = sorted({kind for _, kind, _ in parts})
    mtl.write_text("".join(f"newmtl {k}\nKd {COLOURS[k][0]:.3f} {COLOURS[k][1]:.3f} {COLOURS[k][2]:.3f}\n\n"
                           for k in used))


def write_3ds_model(path: Path, parts: list[tuple[str, str, trimesh.Trimesh]], textures: dict[str, str]) -> None:
    """A .3ds of the parts, each with texture coordinates (box projection) and its
    material's texture map when ``textures`` names one."""
    from make_textures import TILE, box_uv

    from tanktool.formats.threeds_write import write_3ds

    to_z_up = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], dtype=np.float64)  # (x, y, z) -> (x, -z, y)
    objects = []
    for name, kind, mesh in parts:
        if kind not in textures:
            objects.append((name, mesh.vertices @ to_z_up.T, mesh.faces, COLOURS[kind]))
            continue
        verts, faces, uv = box_uv(mesh.vertices, mesh.faces, TILE[textures[kind]])
        objects.append((name, verts @ to_z_up.T, faces, COLOURS[kind], uv, f"textures/{textures[kind]}.png"))
    write_3ds(path, objects)


def _generated(name: str):
    """A level of tools/make_levels.py as named parts."""
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        import make_levels
    finally:
        sys.path.remove(str(ROOT / "tools"))

    def parts() -> list[tuple[str, str, trimesh.Trimesh]]:
        return [(f"{kind}{k:02d}", kind, mesh) for k, (kind, mesh) in enumerate(make_levels.LEVELS[name]())]
    return parts


#: name -> (author function, source file name, import-arena parameters)
ARENAS = {
    "box": (model_box, "box.obj", {"up": "y"}),
    "maze": (model_maze, "maze.obj", {"up": "y"}),
    "paper2002": (model_paper2002, "paper2002.3ds", {"up": "z"}),
    "hills": (_generated("hills"), "hills.obj", {"up": "y"}),
    "fort": (_generated("fort"), "fort.obj", {"up": "y"}),
}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", choices=sorted(ARENAS), action="append")
    ap.add_argument("--models-only", action="store_true", help="write the source models, do not import")
    args = ap.parse_args(argv)
    from make_textures import ARENA_TEXTURES, texture_obj

    from tanktool.importer import import_arena

    for name in args.only or list(ARENAS):
        make, file_name, params = ARENAS[name]
        folder = ROOT / "arenas" / name
        folder.mkdir(parents=True, exist_ok=True)
        parts = make()
        src = folder / file_name
        if src.suffix == ".obj":
            write_obj(src, parts)
            texture_obj(src, ARENA_TEXTURES.get(name, {}))
        else:
            write_3ds_model(src, parts, ARENA_TEXTURES.get(name, {}))
        faces = sum(len(m.faces) for _, _, m in parts)
        print(f"{name}: wrote {src.relative_to(ROOT)} ({len(parts)} parts, {faces} faces)")
        if args.models_only:
            continue
        r = import_arena(src, folder, name=name, up=params["up"], force=True)
        print(f"{name}: {len(r.walls)} walls, {len(r.spawns)} spawns -> {folder.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
