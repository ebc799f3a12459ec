"""Collision detection (the 2002 simulator's stage 6, §3.4.4.3).

- Tank against walls: each hull point against the walls near the tank.  A hull point
  P is inside a wall's far side when the segment from the tank's centre of mass C to
  P crosses the wall: that works for two-sided walls without knowing which side is
  "free", because C itself never crosses a wall.  The paper only tests hull points,
  which lets the free end of a wall slide between two of them; we also test wall
  end points against the tank's footprint polygon.
- Tank against tank: sphere trees level by level, root first, deeper only where the
  level above overlapped; the contact comes from the deepest overlapping leaf pair.
- Shells: the swept segment of one step against sphere trees; against walls the whole
  flight is one straight line in (x, z) (gravity only bends it in y), so the first
  wall along it is found once, when the shell is fired, and no speed can tunnel.

Contacts are plain tuples ``(px, pz, nx, nz, depth)``: the contact point in the world,
the unit normal along which the first body must move to get out, and how far.
"""

from __future__ import annotations

import math
from typing import Protocol, Sequence

import numpy as np

from .body import Tank

Contact = tuple[float, float, float, float, float]


class WallIndex(Protocol):
    """What the simulation asks of a wall index (``nav.quadtree.WallQuadtree`` has it)."""

    def query_point(self, point: np.ndarray, radius: float) -> np.ndarray: ...

    def query_segment(self, a: np.ndarray, b: np.ndarray) -> np.ndarray: ...


class BruteWallIndex:
    """Every wall, tested with one vectorised numpy pass.  Exact, and for arenas of a
    few hundred walls about as fast as a tree for the rare queries the world makes;
    used when no quadtree is given."""

    def __init__(self, segments: np.ndarray) -> None:
        self.segments = np.asarray(segments, dtype=np.float64).reshape(-1, 2, 2)
        self._a = self.segments[:, 0]
        self._d = self.segments[:, 1] - self.segments[:, 0]
        self._l2 = np.maximum((self._d ** 2).sum(axis=1), 1e-300)

    def query_point(self, point: np.ndarray, radius: float) -> np.ndarray:
        p = np.asarray(point, dtype=np.float64).reshape(2)
        t = np.clip(((p - self._a) * self._d).sum(axis=1) / self._l2, 0.0, 1.0)
        q = self._a + t[:, None] * self._d - p
        return np.flatnonzero((q ** 2).sum(axis=1) <= radius * radius)

    def query_segment(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        a = np.asarray(a, dtype=np.float64).reshape(2)
        b = np.asarray(b, dtype=np.float64).reshape(2)
        r = b - a
        denom = r[0] * self._d[:, 1] - r[1] * self._d[:, 0]
        w = self._a - a
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (w[:, 0] * self._d[:, 1] - w[:, 1] * self._d[:, 0]) / denom
            u = (w[:, 0] * r[1] - w[:, 1] * r[0]) / denom
        hit = (denom != 0) & (t >= 0) & (t <= 1) & (u >= 0) & (u <= 1)
        return np.flatnonzero(hit)


class QuadtreeIndex:
    """The wall quadtree's leaves, queried in plain Python.

    ``nav.quadtree.WallQuadtree`` answers batches of queries with numpy; the world asks
    one small question at a time, where a numpy call costs ~100x the arithmetic.  So its
    leaves are laid onto a uniform grid at the finest leaf size (each cell keeps the
    wall list of the leaf covering it) and points and segments are looked up cell by
    cell: the same buckets as the tree, exact answers, microseconds per query.
    """

    MAX_DEPTH = 7

    def __init__(self, tree: object) -> None:
        seg = np.asarray(tree.segments, dtype=np.float64).reshape(-1, 2, 2)  # type: ignore[attr-defined]
        box = np.asarray(tree.box)  # type: ignore[attr-defined]
        child = np.asarray(tree.child)  # type: ignore[attr-defined]
        depth = np.asarray(tree.depth)  # type: ignore[attr-defined]
        offsets = np.asarray(tree.offsets)  # type: ignore[attr-defined]
        walls = np.asarray(tree.walls)  # type: ignore[attr-defined]
        self.x0, self.z0 = (float(v) for v in box[0, 0])
        x1, z1 = (float(v) for v in box[0, 1])
        d = min(int(depth.max()), self.MAX_DEPTH)
        self.n = 1 << d
        self.cw = (x1 - self.x0) / self.n
        self.ch = (z1 - self.z0) / self.n
        cells: list[list[int]] = [[] for _ in range(self.n * self.n)]
        for leaf in np.flatnonzero(child < 0).tolist():
            ws = walls[offsets[leaf]:offsets[leaf + 1]].tolist()
            if not ws:
                continue
            (bx0, bz0), (bx1, bz1) = box[leaf].tolist()
            i0 = max(int(round((bx0 - self.x0) / self.cw)), 0)
            i1 = min(max(int(round((bx1 - self.x0) / self.cw)), i0 + 1), self.n)
            j0 = max(int(round((bz0 - self.z0) / self.ch)), 0)
            j1 = min(max(int(round((bz1 - self.z0) / self.ch)), j0 + 1), self.n)
            for j in range(j0, j1):
                for i in range(i0, i1):
                    cells[j * self.n + i].extend(ws)
        self.cells = [tuple(sorted(set(c))) for c in cells]
        self.segs = [(a[0], a[1], b[0] - a[0], b[1] - a[1]) for a, b in seg.tolist()]
        self.tree = tree

    def _cell(self, x: float, z: float) -> tuple[int, int]:
        i = int((x - self.x0) // self.cw)
        j = int((z - self.z0) // self.ch)
        n1 = self.n - 1
        return (0 if i < 0 else n1 if i > n1 else i), (0 if j < 0 else n1 if j > n1 else j)

    def query_point(self, point: Sequence[float], radius: float) -> list[int]:
        """Walls within ``radius`` of the point (exact), ascending."""
        x, z = float(point[0]), float(point[1])
        i0, j0 = self._cell(x - radius, z - radius)
        i1, j1 = self._cell(x + radius, z + radius)
        seen: set[int] = set()
        for j in range(j0, j1 + 1):
            row = j * self.n
            for i in range(i0, i1 + 1):
                seen.update(self.cells[row + i])
        r2 = radius * radius
        out = []
        for k in seen:
            ax, az, ex, ez = self.segs[k]
            l2 = ex * ex + ez * ez
            t = ((x - ax) * ex + (z - az) * ez) / l2 if l2 > 0 else 0.0
            t = 0.0 if t < 0.0 else 1.0 if t > 1.0 else t
            qx, qz = ax + t * ex - x, az + t * ez - z
            if qx * qx + qz * qz <= r2:
                out.append(k)
        out.sort()
        return out

    def _cells_on_segment(self, ax: float, az: float, bx: float, bz: float) -> set[int]:
        """Walls in the cells a segment passes through (grid walk, Amanatides & Woo)."""
        dx, dz = bx - ax, bz - az
        # clip to the grid's box so that the walk is short and starts inside
        t0, t1 = 0.0, 1.0
        for p, q in ((-dx, ax - self.x0), (dx, self.x0 + self.n * self.cw - ax),
                     (-dz, az - self.z0), (dz, self.z0 + self.n * self.ch - az)):
            if p == 0.0:
                if q < 0.0:
                    return set()
            else:
                r = q / p
                if p < 0.0:
                    t0 = max(t0, r)
                else:
                    t1 = min(t1, r)
        if t0 > t1:
            return set()
        i, j = self._cell(ax + t0 * dx, az + t0 * dz)
        ie, je = self._cell(ax + t1 * dx, az + t1 * dz)
        si = 1 if dx > 0 else -1
        sj = 1 if dz > 0 else -1
        inf = math.inf
        tdx = abs(self.cw / dx) if dx != 0.0 else inf
        tdz = abs(self.ch / dz) if dz != 0.0 else inf
        nxb = self.x0 + (i + (1 if dx > 0 else 0)) * self.cw
        nzb = self.z0 + (j + (1 if dz > 0 else 0)) * self.ch
        tmx = (nxb - ax) / dx if dx != 0.0 else inf
        tmz = (nzb - az) / dz if dz != 0.0 else inf
        seen: set[int] = set(self.cells[j * self.n + i])
        for _ in range(2 * self.n + 2):
            if i == ie and j == je:
                break
            if tmx < tmz:
                i += si
                tmx += tdx
            else:
                j += sj
                tmz += tdz
            if not (0 <= i < self.n and 0 <= j < self.n):
                break
            seen.update(self.cells[j * self.n + i])
        return seen

    def query_segment(self, a: Sequence[float], b: Sequence[float]) -> list[int]:
        """Walls the segment a→b crosses or touches (exact), ascending."""
        ax, az, bx, bz = float(a[0]), float(a[1]), float(b[0]), float(b[1])
        rx, rz = bx - ax, bz - az
        out = []
        for k in self._cells_on_segment(ax, az, bx, bz):
            wx, wz, ex, ez = self.segs[k]
            wx -= ax
            wz -= az
            denom = rx * ez - rz * ex
            if denom == 0.0:
                # parallel: touching only if collinear and overlapping
                if wx * rz - wz * rx != 0.0:
                    continue
                rr = rx * rx + rz * rz
                if rr == 0.0:
                    continue
                s0 = (wx * rx + wz * rz) / rr
                s1 = ((wx + ex) * rx + (wz + ez) * rz) / rr
                if max(s0, s1) >= 0.0 and min(s0, s1) <= 1.0:
                    out.append(k)
                continue
            t = (wx * ez - wz * ex) / denom
            u = (wx * rz - wz * rx) / denom
            if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0:
                out.append(k)
        out.sort()
        return out


class WallSet:
    """Walls as plain tuples for the per-step arithmetic, plus an index for queries.

    ``segments`` (n, 2, 2): the arena's walls and its auxiliary rectangle; walls are
    two-sided for physics, so their Direction plays no part here.
    """

    def __init__(self, segments: np.ndarray, index: WallIndex | None = None) -> None:
        seg = np.asarray(segments, dtype=np.float64).reshape(-1, 2, 2)
        length = np.hypot(seg[:, 1, 0] - seg[:, 0, 0], seg[:, 1, 1] - seg[:, 0, 1])
        keep = length > 1e-9      # zero-length walls have no normal and stop nothing
        self.segments = seg
        self.index: WallIndex = index if index is not None else BruteWallIndex(seg)
        # (ax, az, ex, ez, l2, len) per wall; None for degenerate ones
        self.walls: list[tuple[float, float, float, float, float, float] | None] = []
        for (a, b), ok in zip(seg.tolist(), keep.tolist()):
            if ok:
                ex, ez = b[0] - a[0], b[1] - a[1]
                l2 = ex * ex + ez * ez
                self.walls.append((a[0], a[1], ex, ez, l2, math.sqrt(l2)))
            else:
                self.walls.append(None)

    def __len__(self) -> int:
        return len(self.walls)

    def near(self, x: float, z: float, radius: float) -> list[int]:
        """Indices of the walls within ``radius`` of (x, z), ascending."""
        return [int(k) for k in self.index.query_point((x, z), radius) if self.walls[k] is not None]

    def first_hit(self, ax: float, az: float, bx: float, bz: float) -> tuple[float, int] | None:
        """First wall the segment a→b meets: (fraction along a→b, wall index), or None."""
        cand = self.index.query_segment((ax, az), (bx, bz))
        best: tuple[float, int] | None = None
        rx, rz = bx - ax, bz - az
        for k in cand:
            w = self.walls[k]
            if w is None:
                continue
            wx, wz, ex, ez = w[0] - ax, w[1] - az, w[2], w[3]
            denom = rx * ez - rz * ex
            if denom == 0.0:      # parallel and touching: hit where the wall starts
                t = min(max(((w[0] - ax) * rx + (w[1] - az) * rz) / (rx * rx + rz * rz), 0.0), 1.0)
            else:
                t = (wx * ez - wz * ex) / denom
            if best is None or t < best[0] or (t == best[0] and k < best[1]):
                best = (t, k)
        return best

    def blocked(self, ax: float, az: float, bx: float, bz: float) -> bool:
        """Does any wall cross the segment a→b (line of sight)?"""
        return len(self.index.query_segment((ax, az), (bx, bz))) > 0


# ---------------------------------------------------------------- tank vs walls


def wall_contacts(tank: Tank, walls: WallSet, candidates: Sequence[int]) -> list[tuple[Contact, int]]:
    """Contacts of a tank with the candidate walls: ``[((px, pz, nx, nz, depth), wall)]``.

    n points away from the wall towards the tank's centre side; depth >= 0.  The work
    is done in the tank's own frame, where hull points are constants: a wall is first
    clipped against the footprint's bounding box (almost every wall near a tank misses
    it), and only then are the hull points tested.
    """
    cx, cz, c, s = tank.x, tank.z, tank.c, tank.s
    spec = tank.spec
    bx0, bz0, bx1, bz1 = spec.box
    out: list[tuple[Contact, int]] = []
    for k in candidates:
        ax, az, ex, ez, l2, ln = walls.walls[k]  # type: ignore[misc]
        dx, dz = ax - cx, az - cz
        lax, laz = dx * c + dz * s, -dx * s + dz * c        # wall start, tank frame
        lex, lez = ex * c + ez * s, -ex * s + ez * c        # wall direction, tank frame
        # slab test: does the wall cross the footprint's bounding box?
        t0, t1 = 0.0, 1.0
        if lex != 0.0:
            ta, tb = (bx0 - lax) / lex, (bx1 - lax) / lex
            if ta > tb:
                ta, tb = tb, ta
            t0 = ta if ta > t0 else t0
            t1 = tb if tb < t1 else t1
        elif lax < bx0 or lax > bx1:
            continue
        if lez != 0.0:
            ta, tb = (bz0 - laz) / lez, (bz1 - laz) / lez
            if ta > tb:
                ta, tb = tb, ta
            t0 = ta if ta > t0 else t0
            t1 = tb if tb < t1 else t1
        elif laz < bz0 or laz > bz1:
            continue
        if t0 > t1:
            continue
        # the normal points to the side of the wall the centre of mass is on
        num_s = lax * lez - laz * lex
        nx, nz = -ez / ln, ex / ln
        if ex * -dz - ez * -dx < 0.0:
            nx, nz = -nx, -nz
        for px, pz in spec.hull_local:
            denom = px * lez - pz * lex
            if denom == 0.0:
                continue
            # the segment centre → P meets the wall at fraction s of it, u of the wall
            s_ = num_s / denom
            if s_ < 0.0 or s_ > 1.0:
                continue
            u = (lax * pz - laz * px) / denom
            if u < 0.0 or u > 1.0:
                continue
            depth = abs(lex * (pz - laz) - lez * (px - lax)) / ln
            out.append(((cx + px * c - pz * s, cz + px * s + pz * c, nx, nz, depth), k))
        # the wall's end points inside the footprint (a wall end poking into the hull)
        for qx, qz, wx, wz in ((lax, laz, ax, az), (lax + lex, laz + lez, ax + ex, az + ez)):
            if bx0 < qx < bx1 and bz0 < qz < bz1:
                hit = _endpoint_contact(tank, qx, qz, wx, wz)
                if hit is not None:
                    out.append((hit, k))
    return out


def _endpoint_contact(tank: Tank, lx: float, lz: float, ex: float, ez: float) -> Contact | None:
    """A wall end point at (lx, lz) in the tank's frame, (ex, ez) in the world,
    strictly inside the tank's footprint polygon."""
    spec = tank.spec
    best = math.inf
    best_n = (0.0, 0.0)
    for (vx, vz), (nx, nz) in zip(spec.footprint, spec.footprint_normals):
        d = -((lx - vx) * nx + (lz - vz) * nz)    # distance inside this edge
        if d <= 0.0:
            return None
        if d < best:
            best, best_n = d, (nx, nz)
    nx, nz = best_n
    c, s = tank.c, tank.s
    wx, wz = nx * c - nz * s, nx * s + nz * c     # edge normal in the world
    # the point pushes the tank away: the tank moves against the edge's outward normal
    return (ex, ez, -wx, -wz, best)


# ---------------------------------------------------------------- tank vs tank


def _sphere_world(t: Tank, i: int) -> tuple[float, float, float, float]:
    sx, sy, sz, r = t.spec.spheres[i]
    return (t.x + sx * t.c - sz * t.s, t.y + sy, t.z + sx * t.s + sz * t.c, r)


def tank_contact(A: Tank, B: Tank) -> Contact | None:
    """Contact between two tanks from their sphere trees, or None.

    Level by level: the roots first; a pair that overlaps is replaced by its children
    (a leaf stays paired with the other tree's children while that one is deeper).
    Among the overlapping leaf pairs the deepest gives the contact: n is the (x, z)
    direction from B's leaf centre to A's (A moves along +n), the point lies midway
    between the two sphere surfaces.
    """
    sa, sb = A.spec, B.spec
    ka, kb = sa.sphere_children, sb.sphere_children
    cache_a: dict[int, tuple[float, float, float, float]] = {}
    cache_b: dict[int, tuple[float, float, float, float]] = {}
    frontier = [(0, 0)]
    best: tuple[float, int, int] | None = None
    while frontier:
        nxt: list[tuple[int, int]] = []
        for i, j in frontier:
            p = cache_a.get(i)
            if p is None:
                p = cache_a[i] = _sphere_world(A, i)
            q = cache_b.get(j)
            if q is None:
                q = cache_b[j] = _sphere_world(B, j)
            dx, dy, dz = p[0] - q[0], p[1] - q[1], p[2] - q[2]
            rr = p[3] + q[3]
            d2 = dx * dx + dy * dy + dz * dz
            if d2 > rr * rr:
                continue
            ci, cj = ka[i], kb[j]
            if not ci and not cj:
                pen = rr - math.sqrt(d2)
                if best is None or pen > best[0]:
                    best = (pen, i, j)
            elif not ci:
                nxt.extend((i, b) for b in cj)
            elif not cj:
                nxt.extend((a, j) for a in ci)
            else:
                nxt.extend((a, b) for a in ci for b in cj)
        frontier = nxt
    if best is None:
        return None
    pen, i, j = best
    p, q = cache_a[i], cache_b[j]
    nx, nz = p[0] - q[0], p[2] - q[2]
    ln = math.hypot(nx, nz)
    if ln < 1e-9:                       # leaves stacked: fall back to the centres of mass
        nx, nz = A.x - B.x, A.z - B.z
        ln = math.hypot(nx, nz)
        if ln < 1e-9:
            nx, nz, ln = 1.0, 0.0, 1.0
    nx, nz = nx / ln, nz / ln
    # how far apart along n the centres must be horizontally, given their height difference
    d_h = (p[0] - q[0]) * nx + (p[2] - q[2]) * nz
    dy = p[1] - q[1]
    rr = p[3] + q[3]
    depth = max(math.sqrt(max(rr * rr - dy * dy, 0.0)) - d_h, 0.0)
    mid = 0.5 * (q[3] + d_h - p[3])      # halfway between the two sphere surfaces
    return (q[0] + nx * mid, q[2] + nz * mid, nx, nz, depth)


# ---------------------------------------------------------------- shells vs tanks


def _segment_sphere(ax: float, ay: float, az: float, dx: float, dy: float, dz: float, dd: float,
                    sph: tuple[float, float, float, float]) -> float | None:
    """Entry fraction in [0, 1] of the segment a + t·d into a sphere, or None."""
    cx, cy, cz, r = sph
    mx, my, mz = ax - cx, ay - cy, az - cz
    c = mx * mx + my * my + mz * mz - r * r
    if c <= 0.0:
        return 0.0                     # starts inside
    b = mx * dx + my * dy + mz * dz
    if b >= 0.0 or dd == 0.0:
        return None                    # moving away
    disc = b * b - dd * c
    if disc < 0.0:
        return None
    t = (-b - math.sqrt(disc)) / dd
    return t if t <= 1.0 else None


def shell_hits_tank(tank: Tank, a: tuple[float, float, float], b: tuple[float, float, float]) -> float | None:
    """Fraction along a→b where the shell first enters one of the tank's leaf spheres
    (descending only through spheres the segment touches), or None."""
    ax, ay, az = a
    dx, dy, dz = b[0] - ax, b[1] - ay, b[2] - az
    dd = dx * dx + dy * dy + dz * dz
    kids = tank.spec.sphere_children
    frontier = [0]
    best: float | None = None
    while frontier:
        nxt: list[int] = []
        for i in frontier:
            t = _segment_sphere(ax, ay, az, dx, dy, dz, dd, _sphere_world(tank, i))
            if t is None:
                continue
            if kids[i]:
                nxt.extend(kids[i])
            elif best is None or t < best:
                best = t
        frontier = nxt
    return best
