"""Generated levels for the walkable-surface pipeline: terrain, ramps, decks, bridges.

    .venv/bin/python tools/make_levels.py OUT_DIR [--seed N]

writes one .obj (Y up, metres) per kind into OUT_DIR; the tests and bench/walkable.py
call the functions directly (each returns its parts, ``(kind, mesh)`` pairs; ``level(name)``
joins them into one mesh).  Every level is built from trimesh primitives and
height-field grids, seeded, so a seed gives the same file:

* ``rolling_terrain``  hills and hollows (5,000+ triangles), some slopes too steep
* ``ramps_and_decks``  a walled yard, a raised deck on a solid block, two ramps up to it
* ``bridge``           two plateaus with ramps, a bridge deck over the passage between
* ``bumpy_floor``      a walled yard strewn with 10 cm bumps (all drivable)
* ``tiny_room``        a 3 x 3 m room: too small for any bundled tank
* ``two_storeys``      a building whose upper floor covers the ground floor, stairs of ramps
* ``hills`` / ``fort`` the bundled arenas of the same names (tools/make_arena_models.py)
* ``corridor``, ``islands``, ``narrow_deck``: degenerate arenas (one corridor, platforms
  apart from each other, a catwalk in the air) the agents must cope with
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
import trimesh

COLOURS = {
    "ground": (0.42, 0.45, 0.38),
    "grass": (0.38, 0.52, 0.30),
    "rock": (0.50, 0.48, 0.45),
    "wall": (0.62, 0.36, 0.27),
    "deck": (0.55, 0.42, 0.22),
    "ramp": (0.60, 0.55, 0.40),
}


def box(x0: float, z0: float, x1: float, z1: float, y0: float, y1: float) -> trimesh.Trimesh:
    """An axis-aligned box from its (x, z) corners and its y range."""
    b = trimesh.creation.box(extents=[x1 - x0, y1 - y0, z1 - z0])
    b.apply_translation([(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2])
    return b


def ramp(x0: float, z0: float, x1: float, z1: float, y_low: float, y_high: float, along: str = "+x",
         base: float = 0.0) -> trimesh.Trimesh:
    """A solid wedge over the rectangle, rising from ``y_low`` to ``y_high`` in the
    direction ``along`` (+x, -x, +z, -z), its bottom at ``base``."""
    corners = np.array([[x0, z0], [x1, z0], [x1, z1], [x0, z1]], dtype=np.float64)
    axis = {"+x": (0, 1), "-x": (0, -1), "+z": (1, 1), "-z": (1, -1)}[along]
    lo, hi = (x0, x1) if axis[0] == 0 else (z0, z1)
    t = (corners[:, axis[0]] - lo) / (hi - lo)
    if axis[1] < 0:
        t = 1 - t
    top = y_low + t * (y_high - y_low)
    v = np.concatenate([np.column_stack([corners[:, 0], np.full(4, base), corners[:, 1]]),
                        np.column_stack([corners[:, 0], top, corners[:, 1]])])
    return trimesh.convex.convex_hull(v)


def heightfield_mesh(xs: np.ndarray, zs: np.ndarray, h: np.ndarray) -> trimesh.Trimesh:
    """A terrain surface: a grid of quads (two triangles each), faces up."""
    X, Z = np.meshgrid(xs, zs)
    v = np.column_stack([X.ravel(), h.ravel(), Z.ravel()])
    nx = len(xs)
    i, j = np.meshgrid(np.arange(len(zs) - 1), np.arange(nx - 1), indexing="ij")
    a = (i * nx + j).ravel()
    b, c, d = a + 1, a + nx, a + nx + 1
    # (a, c, b) and (b, c, d) face +y in the (x, y, z) right-handed frame
    f = np.concatenate([np.column_stack([a, c, b]), np.column_stack([b, c, d])])
    return trimesh.Trimesh(v, f, process=False)


def paint(mesh: trimesh.Trimesh, kind: str) -> trimesh.Trimesh:
    mesh.visual.face_colors = (np.array(COLOURS[kind]) * 255).astype(np.uint8).tolist() + [255]
    return mesh


def join(parts: list[tuple[str, trimesh.Trimesh]]) -> trimesh.Trimesh:
    return trimesh.util.concatenate([paint(m, k) for k, m in parts])


def walled_yard(w: float, d: float, wall_h: float = 3.0, t: float = 1.0, slab: float = 0.5) -> list:
    """A floor slab from (0, 0) to (w, d) with a wall of thickness ``t`` around it."""
    return [("ground", box(0, 0, w, d, -slab, 0)),
            ("wall", box(0, 0, w, t, 0, wall_h)), ("wall", box(0, d - t, w, d, 0, wall_h)),
            ("wall", box(0, t, t, d - t, 0, wall_h)), ("wall", box(w - t, t, w, d - t, 0, wall_h))]


def sine_waves(rng: np.random.Generator, X: np.ndarray, Z: np.ndarray, count: int, k: tuple[float, float],
               weight_min: float) -> np.ndarray:
    """A sum of ``count`` seeded waves sin(kx x + a) cos(kz z + b) over the grid X, Z,
    wave numbers in ``k``, each weighted between ``weight_min`` and 1."""
    h = np.zeros_like(X)
    for _ in range(count):
        kx, kz = rng.uniform(k[0], k[1], 2)
        ph = rng.uniform(0, 2 * math.pi, 2)
        h += rng.uniform(weight_min, 1.0) * np.sin(kx * X + ph[0]) * np.cos(kz * Z + ph[1])
    return h


def rolling_terrain(size: float = 90.0, n: int = 52, amp: float = 3.5, seed: int = 1) -> list:
    """Hills and hollows over ``size`` x ``size`` m: ``2 (n - 1)^2`` triangles of a sum of
    seeded sine waves, plus a ridge steeper than a tank climbs."""
    rng = np.random.default_rng(seed)
    xs = np.linspace(0, size, n)
    X, Z = np.meshgrid(xs, xs)
    h = sine_waves(rng, X, Z, 5, (0.03, 0.12), 0.4)
    h *= amp / max(np.abs(h).max(), 1e-9)
    # a steep ridge across one corner (about 50 degrees)
    ridge = np.clip(8.0 - np.abs((X - 0.75 * size) + (Z - 0.75 * size)) * 1.2, 0, None)
    return [("grass", heightfield_mesh(xs, xs, h + ridge))]


def ramps_and_decks(seed: int = 0) -> list:
    """A 70 x 50 m walled yard; a 24 x 20 m deck 4 m up on a solid block; two 16 m ramps
    (14 degrees) lead up to it from the yard; a low crate on the deck."""
    parts = walled_yard(70, 50)
    parts += [("deck", box(40, 15, 64, 35, 0, 4.0)),
              ("ramp", ramp(24, 17, 40, 24, 0.0, 4.0, "+x")),
              ("ramp", ramp(52, 35, 60, 49, 0.0, 4.0, "-z")),
              ("wall", box(48, 22, 52, 26, 4.0, 6.0))]
    return parts


def bridge(seed: int = 0) -> list:
    """An 80 x 60 m yard cut by a 12 m passage at ground level (x 34 - 46); a 5 m
    plateau on each side, each with a ramp up from the ground; a bridge deck (top 5 m,
    0.5 m thick) joins the plateaus over the passage: under it the passage, on it the
    crossing -- two levels in the same columns."""
    parts = walled_yard(80, 60)
    parts += [("rock", box(1, 16, 34, 59, 0, 5.0)), ("rock", box(46, 1, 79, 44, 0, 5.0)),
              ("deck", box(34, 26, 46, 34, 4.5, 5.0)),
              ("ramp", ramp(3, 1, 13, 16, 0.0, 5.0, "+z")),
              ("ramp", ramp(67, 44, 77, 59, 0.0, 5.0, "-z"))]
    return parts


def bumpy_floor(seed: int = 3, bumps: int = 120) -> list:
    """A 60 x 60 m walled yard with ``bumps`` seeded boxes 10 cm high, 0.5 - 2 m wide."""
    rng = np.random.default_rng(seed)
    parts = walled_yard(60, 60)
    for _ in range(bumps):
        x, z = rng.uniform(4, 56, 2)
        w, d = rng.uniform(0.5, 2.0, 2)
        parts.append(("rock", box(x, z, x + w, z + d, 0, 0.1)))
    return parts


def tiny_room() -> list:
    """A 3 x 3 m room with 2.5 m walls: no bundled tank fits in it."""
    return [("ground", box(0, 0, 3.6, 3.6, -0.2, 0)), ("wall", box(0, 0, 3.6, 0.3, 0, 2.5)),
            ("wall", box(0, 3.3, 3.6, 3.6, 0, 2.5)), ("wall", box(0, 0.3, 0.3, 3.3, 0, 2.5)),
            ("wall", box(3.3, 0.3, 3.6, 3.3, 0, 2.5))]


def two_storeys(seed: int = 0) -> list:
    """A 60 x 40 m walled ground floor under a 0.5 m slab at 5 m (40 x 40 m, on four
    pillars), a long ramp up to it from the open end: the upper floor lies over the
    ground floor."""
    parts = walled_yard(90, 40)
    parts += [("deck", box(10, 1, 50, 39, 4.5, 5.0))]
    for x, z in ((14, 5), (14, 33), (44, 5), (44, 33)):
        parts.append(("wall", box(x, z, x + 2, z + 2, 0, 4.5)))
    parts.append(("ramp", ramp(50, 10, 80, 30, 0.0, 5.0, "-x")))
    return parts


def hills(seed: int = 7) -> list:
    """The bundled 'hills': 120 x 120 m of rolling terrain inside a wall, with rocks."""
    rng = np.random.default_rng(seed)
    size, n = 120.0, 61
    xs = np.linspace(0, size, n)
    X, Z = np.meshgrid(xs, xs)
    h = sine_waves(rng, X, Z, 6, (0.025, 0.08), 0.5)
    h = (h - h.min()) / max(h.max() - h.min(), 1e-9) * 6.0  # 0 .. 6 m
    edge = np.minimum.reduce([X, Z, size - X, size - Z])
    e = np.clip(edge / 25.0, 0, 1)
    h *= e * e * (3 - 2 * e)  # flat along the wall, easing in over 25 m: slopes under 20 degrees
    parts = [("grass", heightfield_mesh(xs, xs, h)),
             ("wall", box(-1, -1, size + 1, 0, -1, 4)), ("wall", box(-1, size, size + 1, size + 1, -1, 4)),
             ("wall", box(-1, 0, 0, size, -1, 4)), ("wall", box(size, 0, size + 1, size, -1, 4))]
    for _ in range(9):
        x, z = rng.uniform(15, size - 20, 2)
        w, d = rng.uniform(3, 6, 2)
        y = float(np.interp(x, xs, h[int(z / size * (n - 1))]))
        parts.append(("rock", box(x, z, x + w, z + d, y - 1.0, y + 3.0)))
    return parts


def fort(seed: int = 0) -> list:
    """The bundled 'fort': a 100 x 100 m walled yard; in it a 40 x 40 m fort 5 m high
    whose roof is a second floor with a parapet, reached by two ramps; a gate passage
    runs through the fort at ground level under the roof; a bridge crosses a sunken
    road (2.5 m deep, 7 m wide) west of the fort."""
    parts = walled_yard(100, 100)
    # the fort: four corner blocks around a cross-shaped gate passage, a roof slab on top
    fx0, fz0, fx1, fz1, top = 50.0, 30.0, 90.0, 70.0, 5.0
    gate = 14.0  # passage width
    cx, cz = (fx0 + fx1) / 2, (fz0 + fz1) / 2
    for x0, x1 in ((fx0, cx - gate / 2), (cx + gate / 2, fx1)):
        for z0, z1 in ((fz0, cz - gate / 2), (cz + gate / 2, fz1)):
            parts.append(("rock", box(x0, z0, x1, z1, 0, top - 0.5)))
    parts.append(("deck", box(fx0, fz0, fx1, fz1, top - 0.5, top)))
    # parapet on the roof's north and south edges
    parts += [("wall", box(fx0, fz1 - 0.8, fx1, fz1, top, top + 1.2)), ("wall", box(fx0, fz0, fx1, fz0 + 0.8, top, top + 1.2))]
    # two wide ramps up to the roof along its west side, from the yard
    parts += [("ramp", ramp(24, 30, 50, 44, 0.0, top, "+x")), ("ramp", ramp(24, 56, 50, 70, 0.0, top, "+x"))]
    # a sunken road west of the fort, across the whole yard, bridged in the middle
    parts = [p for p in parts if p[0] != "ground"]
    # (the yard's ground is solid down to the road's bottom: the road's sides are earth)
    parts += [("ground", box(0, 0, 12, 100, -3.0, 0)), ("ground", box(19, 0, 100, 100, -3.0, 0)),
              ("ground", box(12, 0, 19, 100, -3.0, -2.5)),
              ("wall", box(12, 0, 19, 1, -3.0, 0)), ("wall", box(12, 99, 19, 100, -3.0, 0)),   # the yard wall's footing
              ("deck", box(12, 44, 19, 56, -0.5, 0))]
    return parts


def corridor(length: float = 80.0, width: float = 7.5) -> list:
    """One walled corridor ``width`` m wide (the light tank fits, the heavy one does not)."""
    return [("ground", box(0, 0, length, width + 2, -0.5, 0)),
            ("wall", box(0, 0, length, 1, 0, 3)), ("wall", box(0, width + 1, length, width + 2, 0, 3)),
            ("wall", box(0, 1, 1, width + 1, 0, 3)), ("wall", box(length - 1, 1, length, width + 1, 0, 3))]


def islands(seed: int = 2, count: int = 7) -> list:
    """Flat platforms 3 m up in the air, seeded, 8 - 16 m across, at least 4 m apart,
    nothing else: the largest is the arena, the others are left out."""
    rng = np.random.default_rng(seed)
    parts: list = []
    placed: list = []
    while len(placed) < count:
        w, d = rng.uniform(8, 16, 2)
        x, z = rng.uniform(0, 90 - w), rng.uniform(0, 90 - d)
        if all(x > a1 + 4 or x + w < a0 - 4 or z > b1 + 4 or z + d < b0 - 4 for a0, b0, a1, b1 in placed):
            placed.append((x, z, x + w, z + d))
            parts.append(("deck", box(x, z, x + w, z + d, 2.5, 3.0)))
    return parts


def narrow_deck(length: float = 60.0, width: float = 7.5) -> list:
    """Only a deck ``width`` m wide, 5 m up in the air (a catwalk): nothing else to
    drive on."""
    return [("deck", box(0, 0, length, width, 4.5, 5.0))]


def level(name: str, **kw) -> trimesh.Trimesh:
    """One generated level as a single mesh (parts painted by kind)."""
    return join(LEVELS[name](**kw))


LEVELS = {
    "rolling_terrain": rolling_terrain, "ramps_and_decks": ramps_and_decks, "bridge": bridge,
    "bumpy_floor": bumpy_floor, "tiny_room": tiny_room, "two_storeys": two_storeys, "hills": hills, "fort": fort,
    "corridor": corridor, "islands": islands, "narrow_deck": narrow_deck,
}


def write_obj(mesh: trimesh.Trimesh, path: Path) -> Path:
    """The mesh as Wavefront OBJ (positions and faces; colours in a .mtl beside it)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    mesh.export(path)
    return path


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path)
    ap.add_argument("--seed", type=int, default=None)
    a = ap.parse_args(argv)
    for name, fn in LEVELS.items():
        mesh = join(fn(seed=a.seed) if a.seed is not None and name != "tiny_room" else fn())
        p = write_obj(mesh, a.out / f"{name}.obj")
        print(f"{p}: {len(mesh.faces)} triangles")
    return 0


if __name__ == "__main__":
    sys.exit(main())
