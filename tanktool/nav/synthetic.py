"""Synthetic wall lists with known free space, for tests and benchmarks.

Every arena here is made of closed loops whose normals point into free space: an
outer room (counter-clockwise, normals inwards) and obstacles (normals outwards),
optionally with a courtyard cut into an obstacle.  Closed, consistently oriented loops
are what the navigation grid's classifiers assume (see :mod:`tanktool.nav.navgrid`).
"""

from __future__ import annotations

import numpy as np

from ..formats.walls_txt import WallList, aux_rectangle


def loop_walls(points: np.ndarray, free_inside: bool) -> tuple[np.ndarray, np.ndarray]:
    """Walls of a closed polygon and the Direction making normals point into free space.

    points : (k, 2) vertices in order (either orientation).  ``free_inside`` says
    whether the free space is inside the polygon (a room) or outside (an obstacle).
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    seg = np.stack([p, np.roll(p, -1, axis=0)], axis=1)
    area2 = float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))
    ccw = area2 > 0
    # Direction +1 puts the normal on the left of the wall: inside a CCW loop
    d = 1 if ccw == free_inside else -1
    return seg, np.full(len(seg), d, dtype=np.int8)


def assemble(loops: list[tuple[np.ndarray, bool]], bounds: tuple[float, float, float, float]) -> WallList:
    """A WallList from ``(polygon, free_inside)`` loops plus the auxiliary rectangle."""
    segs, dirs = [], []
    for pts, free_inside in loops:
        s, d = loop_walls(pts, free_inside)
        segs.append(s)
        dirs.append(d)
    return WallList(np.concatenate(segs), np.concatenate(dirs), aux_rectangle(*bounds))


def rect(x0: float, z0: float, x1: float, z1: float) -> np.ndarray:
    return np.array([[x0, z0], [x1, z0], [x1, z1], [x0, z1]], dtype=np.float64)


def box_arena(width: float = 20.0, depth: float = 20.0, margin: float = 1.0) -> WallList:
    """One rectangular room, its walls ``margin`` inside the auxiliary rectangle."""
    return assemble([(rect(0, 0, width, depth), True)], (-margin, -margin, width + margin, depth + margin))


def random_arena(seed: int, size: float = 60.0, cells: int = 4, courtyard: bool = True) -> WallList:
    """A room with one random obstacle per cell of a ``cells x cells`` layout.

    Obstacles are rotated rectangles, triangles or irregular convex polygons, kept
    inside their cell so they never overlap; one of them may hold a free courtyard.
    Vertex coordinates are random floats, so nothing is aligned with any grid.
    """
    rng = np.random.default_rng(seed)
    loops: list[tuple[np.ndarray, bool]] = [(rect(0, 0, size, size), True)]
    step = size / cells
    for a in range(cells):
        for b in range(cells):
            if rng.random() < 0.2:
                continue
            cx, cz = (a + 0.5) * step, (b + 0.5) * step
            rad = step * rng.uniform(0.15, 0.35)
            k = int(rng.choice([3, 4, 5, 7]))
            # jittered but ordered angles with gaps < pi: a simple, star-shaped polygon
            jitter = rng.uniform(0, 0.8, k) if k > 4 else np.zeros(k)
            ang = rng.uniform(0, 2 * np.pi) + (np.arange(k) + jitter) * 2 * np.pi / k
            r = rad * rng.uniform(0.7, 1.0, k)
            pts = np.stack([cx + r * np.cos(ang), cz + r * np.sin(ang)], axis=1)
            loops.append((pts, False))
            if courtyard and k == 4 and rng.random() < 0.5:
                inner = np.stack([cx + 0.5 * r * np.cos(ang), cz + 0.5 * r * np.sin(ang)], axis=1)
                loops.append((inner, True))
    return assemble(loops, (-1.0, -1.0, size + 1.0, size + 1.0))


def block_maze(seed: int, n: int = 7, block: float = 4.0) -> WallList:
    """A maze carved in an ``(2n+1) x (2n+1)`` block grid; each solid block a square obstacle.

    Adjacent blocks share edges with opposite normals, which cancel: the classifiers
    must see the union as one solid.
    """
    rng = np.random.default_rng(seed)
    m = 2 * n + 1
    solid = np.ones((m, m), dtype=bool)
    stack = [(0, 0)]
    seen = {(0, 0)}
    solid[1, 1] = False
    while stack:
        a, b = stack[-1]
        nxt = [(a + da, b + db) for da, db in ((1, 0), (-1, 0), (0, 1), (0, -1))
               if 0 <= a + da < n and 0 <= b + db < n and (a + da, b + db) not in seen]
        if not nxt:
            stack.pop()
            continue
        c = nxt[rng.integers(len(nxt))]
        seen.add(c)
        solid[2 * c[0] + 1, 2 * c[1] + 1] = False
        solid[a + c[0] + 1, b + c[1] + 1] = False
        stack.append(c)
    loops: list[tuple[np.ndarray, bool]] = [(rect(0, 0, m * block, m * block), True)]
    for a, b in zip(*np.nonzero(solid)):
        loops.append((rect(a * block, b * block, (a + 1) * block, (b + 1) * block), False))
    return assemble(loops, (-1.0, -1.0, m * block + 1.0, m * block + 1.0))
