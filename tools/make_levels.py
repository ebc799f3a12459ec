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
* ``town``, ``junkyard``, ``living_room``: what exporters and careless modelling write --
  objects pasted twice, overlapping boxes, faces wound inside out, zero-thickness fences
  a hair apart, rooms of single faces seen from inside, furniture on legs
* ``fence_field``: 1,500 fences and 400 pillars in a 200 m yard (thin walls' stress test)
* ``narrow_ramp``: a deck reached by one ramp 9.2 m wide, which the light tank drives up
  and the heavy one does not fit (one grid per vehicle: the deck is the light tank's only)
* ``stacked_floors`` (a car park of two decks), ``terraces`` (terrain cut into steps by
  retaining walls, a footbridge), ``big_terrain`` (a 300 m smooth hillside)
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
import trimesh

sys.path.insert(0, str(Path(__file__).resolve().parent))

from level_parts import (COLOURS, box, fence, heightfield_mesh, inverted, join, paint, quad,  # noqa: F401
                         ramp, room_shell, sine_waves, walled_yard)


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


def narrow_ramp(seed: int = 0, width: float = 9.2) -> list:
    """A 70 x 50 m walled yard; a 24 x 22 m deck 4 m up on a solid block, reached by one
    20 m ramp ``width`` m wide (11 degrees): wide enough for the light tank's agents
    (footprint radius 3.46 m + 0.5 m margin), too narrow for the heavy tank's footprint
    (4.63 m from each side)."""
    z0 = 25.0 - width / 2
    return walled_yard(70, 50) + [("deck", box(40, 14, 64, 36, 0, 4.0)),
                                  ("ramp", ramp(20, z0, 40, z0 + width, 0.0, 4.0, "+x"))]


def town(seed: int = 4) -> list:
    """A 120 x 120 m walled town as exporters write them: streets between blocks of
    houses where the same house is pasted twice on the spot, an L-shaped house made
    of two overlapping boxes, a row of houses sharing their party walls, a house with
    its faces wound inside out, a roofless shell of single faces, raised pavements
    (15 cm kerbs), zero-thickness fences (one pasted twice, two overlapping along a
    line) and seeded kiosks."""
    rng = np.random.default_rng(seed)
    parts = walled_yard(120, 120, wall_h=4.0)
    parts += [("ground", box(8, 8, 52, 52, 0, 0.15)), ("ground", box(68, 68, 112, 112, 0, 0.15))]
    house = box(12, 12, 24, 22, 0.15, 6)
    parts += [("wall", house), ("wall", house.copy())]                            # pasted twice
    parts += [("wall", box(30, 12, 48, 20, 0.15, 7)), ("wall", box(38, 14, 46, 30, 0.15, 7))]  # an L
    for k in range(4):                                                           # a row, party walls shared
        parts.append(("wall", box(12 + 9 * k, 38, 21 + 9 * k, 48, 0.15, 5 + k % 2)))
    parts.append(("wall", inverted(box(72, 72, 86, 84, 0.15, 6))))                # wound inside out
    shell = [("wall", fence(92, 74, 108, 74, 0.15, 5)), ("wall", fence(108, 74, 108, 88, 0.15, 5)),
             ("wall", fence(108, 88, 92, 88, 0.15, 5)), ("wall", fence(92, 88, 92, 74, 0.15, 5))]
    parts += shell                                                               # a roofless shell
    parts += [("wall", fence(60, 20, 60, 46, 0, 2)), ("wall", fence(60, 20, 60, 46, 0, 2)),  # pasted twice
              ("wall", fence(20, 62, 44, 62, 0, 2)), ("wall", fence(34, 62, 52, 62, 0, 2.5))]  # overlapping
    for _ in range(5):
        x, z = rng.uniform(70, 105), rng.uniform(92, 106)
        parts.append(("rock", box(x, z, x + 3, z + 3, 0.15, 3)))
    return parts


def junkyard(seed: int = 0) -> list:
    """A 100 x 100 m walled yard of what careless modelling leaves: zero-thickness fences
    pasted twice a hair (0.05 - 5 mm) apart or overlapping half their length, a fence
    written both ways, two fences crossing in an X, a block pasted 0.1 mm off itself with
    a fence along its face, a box wound inside out overlapping a normal one."""
    parts = walled_yard(100, 100)
    for x, dx, dz in ((10, 0.00005, 0), (20, 0.0002, 0), (30, 0.001, 0), (40, 0.005, 10), (50, 0.0001, 15)):
        parts += [("wall", fence(x, 10, x, 40, 0, 2)), ("wall", fence(x + dx, 10 + dz, x + dx, 40 + dz, 0, 2))]
    parts += [("wall", fence(50, 70, 90, 70, 0, 2)), ("wall", fence(70, 60, 70, 90, 0, 2)),
              ("wall", box(60, 10, 70, 20, 0, 4)), ("wall", box(60.0001, 10.0001, 70.0001, 20.0001, 0, 4)),
              ("wall", fence(58, 20.0002, 75, 20.0002, 0, 2)),
              ("wall", fence(10, 60, 10, 90, 0, 2)), ("wall", fence(10, 90, 10, 60, 0, 2)),
              ("wall", inverted(box(20, 60, 30, 70, 0, 4))), ("wall", box(25, 65, 35, 75, 0, 4))]
    return parts


def fence_field(seed: int = 3, fences: int = 1500, pillars: int = 400, size: float = 200.0) -> list:
    """A ``size`` m walled yard strewn with ``fences`` seeded zero-thickness fences 0.5 -
    4 m long at any angle and ``pillars`` square pillars: thousands of one-sided cut
    chains over a free space of thousands of vertices, as in a Sauerbraten map (the
    thin walls' stress test of bench/walls.py)."""
    rng = np.random.default_rng(seed)
    parts = walled_yard(size, size)
    for _ in range(fences):
        x, z = rng.uniform(3, size - 3, 2)
        a, n = rng.uniform(0, math.pi), rng.uniform(0.5, 4)
        parts.append(("wall", fence(x, z, x + n * math.cos(a), z + n * math.sin(a), 0, 2)))
    for _ in range(pillars):
        x, z = rng.uniform(3, size - 3, 2)
        w = rng.uniform(0.3, 1.5)
        parts.append(("rock", box(x, z, x + w, z + w, 0, 3)))
    return parts


def living_room(seed: int = 5) -> list:
    """A living room at the scale of toy tanks (60 x 48 m, 24 m high) made of single
    faces seen from inside, furnished: a sofa of overlapping boxes, a table and chairs
    on legs, a rug 5 cm thick, a bookcase against a wall, a TV cabinet pasted twice, a
    cushion lying across the sofa's arm, a standing lamp."""
    rng = np.random.default_rng(seed)
    parts = room_shell(0, 0, 60, 48, 0, 24)
    parts += [("wall", box(6, 30, 34, 38, 0, 3.5)), ("wall", box(6, 36, 34, 42, 0, 9)),   # seat, back
              ("wall", box(4, 30, 8, 42, 0, 5.5)), ("wall", box(32, 30, 36, 42, 0, 5.5)),  # arms
              ("wall", box(30, 31, 38, 35, 5.5, 6.5)),                                   # a cushion
              ("deck", box(10, 10, 40, 24, 0, 0.05))]                                    # the rug
    for x, z in ((14, 12), (36, 12), (14, 21), (36, 21)):                                 # table legs
        parts.append(("wall", box(x - 0.5, z - 0.5, x + 0.5, z + 0.5, 0.05, 7)))
    parts.append(("deck", box(12, 10, 38, 23, 7, 7.6)))
    for x0 in (44.0, 52.0):                                                               # chairs
        for x, z in ((x0, 8), (x0 + 5, 8), (x0, 13), (x0 + 5, 13)):
            parts.append(("wall", box(x - 0.3, z - 0.3, x + 0.3, z + 0.3, 0, 4)))
        parts.append(("deck", box(x0 - 0.5, 7.5, x0 + 5.5, 13.5, 4, 4.4)))
    parts.append(("wall", box(50, 44, 59.9, 47.9, 0, 18)))                              # bookcase
    cabinet = box(44, 0.2, 56, 4, 0, 5)
    parts += [("wall", cabinet), ("wall", cabinet.copy())]
    x, z = rng.uniform(44, 52), rng.uniform(26, 34)
    parts += [("wall", box(x, z, x + 2.5, z + 2.5, 0, 0.4)), ("wall", box(x + 1, z + 1, x + 1.5, z + 1.5, 0.4, 16))]
    return parts


def stacked_floors(seed: int = 0) -> list:
    """A car park on two decks over a walled 112 x 34 m ground floor: deck 1 (4 m up,
    70 x 30 m on pillars) reached by a 30 m ramp from the ground, deck 2 (8 m up, 30 x
    30 m) standing on deck 1 and reached by a ramp on it; a parapet of single faces
    along each deck's back edge."""
    parts = walled_yard(112, 34, wall_h=3.0)
    parts += [("deck", box(10, 1, 80, 31, 3.6, 4.0)), ("deck", box(10, 1, 40, 31, 7.6, 8.0)),
              ("ramp", ramp(80, 1, 110, 12, 0.0, 4.0, "-x")),
              ("ramp", ramp(40, 18, 70, 31, 4.0, 8.0, "-x", base=4.0))]
    for y in (4.0, 8.0):
        parts.append(("wall", fence(10, 1.3, 40 if y > 4 else 80, 1.3, y, y + 1.2)))
    for x, z in ((11, 2), (11, 29), (38, 2), (38, 29), (78, 2), (78, 29)):
        parts.append(("wall", box(x, z, x + 1, z + 1, 0, 3.6)))
    return parts


def terraces(seed: int = 6, size: float = 100.0) -> list:
    """A hillside of terraces: rolling terrain cut into three flat steps by retaining
    walls 3 m high, ramps between them, a pond hollow, and a footbridge over a gully."""
    rng = np.random.default_rng(seed)
    n = 61
    xs = np.linspace(0, size, n)
    X, Z = np.meshgrid(xs, xs)
    h = sine_waves(rng, X, Z, 4, (0.04, 0.1), 0.5) * 0.8
    step = np.floor(Z / (size / 3)) * 3.0
    gully = np.clip(1 - np.abs(X - 0.5 * size) / 5.0, 0, 1) * 2.0 * (Z < size / 3)
    parts = [("grass", heightfield_mesh(xs, xs, h + step - gully))]
    for k in (1, 2):
        z = k * size / 3
        parts.append(("wall", box(0, z - 0.5, 0.55 * size, z + 0.5, -3, 3.0 * k + 1)))
        parts.append(("ramp", ramp(0.6 * size, z - 14, 0.6 * size + 8, z, 3.0 * (k - 1) - 1, 3.0 * k + 0.5, "+z",
                                   base=3.0 * (k - 1) - 3)))
    parts.append(("deck", box(0.5 * size - 6, 10, 0.5 * size + 6, 16, 1.0, 1.4)))
    return parts


def big_terrain(size: float = 300.0, n: int = 151, amp: float = 12.0, seed: int = 8) -> list:
    """A smooth hillside ``size`` m across (Recast's undulating terrain scaled up): long
    gentle slopes whose contour walls must not be voxel staircases."""
    rng = np.random.default_rng(seed)
    xs = np.linspace(0, size, n)
    X, Z = np.meshgrid(xs, xs)
    h = sine_waves(rng, X, Z, 5, (0.01, 0.04), 0.4)
    h *= amp / max(np.abs(h).max(), 1e-9)
    ridge = np.clip(18.0 - np.abs((X - 0.7 * size) - 0.5 * (Z - 0.4 * size)) * 1.0, 0, None)
    return [("grass", heightfield_mesh(xs, xs, h + ridge))]


def level(name: str, **kw) -> trimesh.Trimesh:
    """One generated level as a single mesh (parts painted by kind)."""
    return join(LEVELS[name](**kw))


LEVELS = {
    "rolling_terrain": rolling_terrain, "ramps_and_decks": ramps_and_decks, "bridge": bridge,
    "bumpy_floor": bumpy_floor, "tiny_room": tiny_room, "two_storeys": two_storeys, "hills": hills, "fort": fort,
    "corridor": corridor, "islands": islands, "narrow_deck": narrow_deck, "narrow_ramp": narrow_ramp,
    "town": town, "junkyard": junkyard, "fence_field": fence_field, "living_room": living_room,
    "stacked_floors": stacked_floors, "terraces": terraces, "big_terrain": big_terrain,
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
