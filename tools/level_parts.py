"""Building blocks of the generated levels (tools/make_levels.py): boxes, wedges,
height-field grids, single faces and fences, painted by kind and joined into one mesh.

Every function returns a trimesh.Trimesh (Y up, metres) or ``(kind, mesh)`` parts.
"""

from __future__ import annotations

import math

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


def quad(a, b, c, d) -> trimesh.Trimesh:
    """One single-sided quad (two triangles) over the 3-D corners a b c d, in that
    order: its face normal follows the right-hand rule (a model's one-sided wall)."""
    v = np.array([a, b, c, d], dtype=np.float64)
    return trimesh.Trimesh(v, [[0, 1, 2], [0, 2, 3]], process=False)


def fence(x0: float, z0: float, x1: float, z1: float, y0: float, y1: float) -> trimesh.Trimesh:
    """A zero-thickness fence from (x0, z0) to (x1, z1): one quad, one side only."""
    return quad((x0, y0, z0), (x1, y0, z1), (x1, y1, z1), (x0, y1, z0))


def inverted(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """The mesh with every face wound the other way (normals inward): an exporter's
    flipped object, or a room's shell meant to be seen from inside."""
    return trimesh.Trimesh(mesh.vertices.copy(), mesh.faces[:, ::-1].copy(), process=False)


def room_shell(x0: float, z0: float, x1: float, z1: float, y0: float, y1: float) -> list:
    """A room made of single faces seen from inside: a floor facing up, four walls
    facing in, a ceiling facing down (no thickness anywhere)."""
    c = [(x0, z0), (x1, z0), (x1, z1), (x0, z1)]
    parts = [("ground", quad((x0, y0, z0), (x0, y0, z1), (x1, y0, z1), (x1, y0, z0))),
             ("wall", quad((x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1)))]
    for k in range(4):
        (ax, az), (bx, bz) = c[k], c[(k + 1) % 4]
        # the corners run counter-clockwise seen from above: the normal points into the room
        parts.append(("wall", quad((ax, y0, az), (bx, y0, bz), (bx, y1, bz), (ax, y1, az))))
    return parts
