"""The ground the tanks drive on: levels, heights and links, and the model's triangles.

An arena with relief or several levels (a deck over a passage, terrain, ramps) comes
with its navigation grid (``navgrid.npz``: a node wherever the walkable surface is,
each with its height and its links to the 4 neighbours) and its model.  The
simulation reads from them:

* **where a tank stands**: its level and the surface height under it -- a bilinear
  patch of the node heights around it, on the nodes of its own surface (of the
  neighbours' levels, the one nearest its height);
* **how it moves between levels**: from one cell to the next it follows the node's
  link (up a ramp onto the deck, down steps); a move to a cell its node does not link
  to (a drop-off, a cliff, a slope too steep, a wall's foot) is refused -- the tank
  stays where it was: no tank ever leaves the walkable space;
* **its tilt**: pitch and roll from the ground under its hull (the heights at its
  front, back, left and right);
* **what a shell or a line of sight meets**: :class:`MeshIndex`, the model's triangles
  bucketed by squares of the (x, z) plane, answers "where does this segment first cross
  a triangle".

A flat one-floor arena has a ``sim.flat_ground.FlatGround`` instead: the same
questions answered by a plane at the floor's height (the 2002 simulation: a plane
floor, walls infinitely tall); ``sim.flat_ground.load_ground`` picks the one a bundle
gets.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..geometry.kernels import active as _active
from .lazy_rows import heights_row, lazy_levels, plain_row, tuple_row
from .solid import FEW_LINES, SolidField  # noqa: F401  (here before sim/solid.py)

#: a node is "level ground" when every node this many cells around it has its height
FLAT_CELLS = 10
#: rows of each level kept as Python lists (sim/lazy_rows.py): the tanks' rows and more
ROWS_KEPT = 512
#: rows of a level filtered at a time (Ground._level_ground)
GROUND_BAND = 256
#: steps across the grid: +x, +z, -x, -z as (di, dj), the navgrid's link order
STEPS = ((0, 1), (1, 0), (0, -1), (-1, 0))


def supported(y: float, ha: float, hb: float, drop: float) -> tuple[float, float]:
    """The heights at a hull's two ends (front and back, or left and right) that it
    rests on, its centre at ``y``: an end over ground more than ``drop`` (the climb +
    1 m a metre out to it) below the centre is not under the hull -- a ramp's side, a
    plateau's edge, a cell with no surface (read as 0) -- and the hull lies on the
    slope of the other end (both: level).  Read as ground, the back of a tank parked
    at a ramp's top 0.5 m from the ramp's side pitched it 41 degrees and gravity slid
    it to the foot of the ramp (the gen-bridge's spawn, 0-0 all duel).  The compiled
    kernel does the same (_kernels_ground.c)."""
    low = y - drop
    if ha < low:
        return (y, y) if hb < low else (y + (y - hb), hb)
    if hb < low:
        return ha, y + (y - ha)
    return ha, hb


class MeshIndex:
    """Triangles in (x, z) buckets of ``bucket`` metres, for segment queries."""

    def __init__(self, vertices: np.ndarray, faces: np.ndarray, bucket: float = 4.0) -> None:
        v = np.asarray(vertices, dtype=np.float64)
        # int32 corner indices and bucket lists where they fit (24 + 18 bytes a face
        # less than int64 on a 2 km terrain's 2 M faces; the same faces, the same hits)
        small = len(v) < 2**31 and len(faces) < 2**31
        f = np.asarray(faces, dtype=np.int32 if small else np.int64)
        self.vertices, self.faces = v, f
        # the triangles' corners and edges are gathered per query (_edges): kept for every
        # face they took 72 bytes a face (+144 MB on a 2 km terrain), and as much again
        # in temporaries; the buckets' bookkeeping is int32 (a bucket or face count)
        lo = np.empty((len(f), 2))
        hi = np.empty((len(f), 2))
        for c, axis in enumerate((0, 2)):
            a, b, cc = v[f[:, 0], axis], v[f[:, 1], axis], v[f[:, 2], axis]
            lo[:, c] = np.minimum(np.minimum(a, b), cc)
            hi[:, c] = np.maximum(np.maximum(a, b), cc)
            del a, b, cc
        self.bucket = float(bucket)
        self.origin = lo.min(axis=0) if len(lo) else np.zeros(2)
        b0 = np.floor((lo - self.origin) / bucket).astype(np.int32)
        b1 = np.floor((hi - self.origin) / bucket).astype(np.int32)
        del lo, hi
        self.width = int(b1[:, 0].max()) + 1 if len(b1) else 1
        self.height = int(b1[:, 1].max()) + 1 if len(b1) else 1
        n = b1 - b0 + 1
        del b1
        cnt = n[:, 0].astype(np.int64) * n[:, 1]
        owner = np.repeat(np.arange(len(f), dtype=np.int32 if len(f) < 2**31 else np.int64), cnt)
        k = np.arange(len(owner), dtype=np.int64) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        bi = b0[owner, 0] + k % n[owner, 0]
        bj = b0[owner, 1] + k // n[owner, 0]
        del k, b0, n
        key = bj.astype(np.int64) * self.width + bi
        del bi, bj
        order = np.argsort(key, kind="stable")
        self._faces = owner[order]   # int32 where the faces' count fits (owner's type)
        del owner, order
        self._start = np.zeros(self.width * self.height + 1, dtype=np.int64)
        np.cumsum(np.bincount(key, minlength=self.width * self.height), out=self._start[1:])
        self.y_min = float(v[:, 1].min()) if len(v) else 0.0

    def _edges(self, cand: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(first corner, first edge, second edge) of faces ``cand``, (n, 3) each."""
        tri = self.vertices[self.faces[cand]]
        return tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]

    def _candidates(self, ax: float, az: float, bx: float, bz: float) -> np.ndarray:
        """Faces in the buckets the segment's (x, z) projection passes (its box of buckets,
        walked row by row along the segment)."""
        b, (ox, oz) = self.bucket, self.origin
        i0, i1 = sorted((math.floor((ax - ox) / b), math.floor((bx - ox) / b)))
        j0, j1 = sorted((math.floor((az - oz) / b), math.floor((bz - oz) / b)))
        i0, i1 = max(i0, 0), min(i1, self.width - 1)
        j0, j1 = max(j0, 0), min(j1, self.height - 1)
        if i0 > i1 or j0 > j1:
            return np.zeros(0, dtype=np.int64)
        parts = []
        st = self._start
        dx, dz = bx - ax, bz - az
        for j in range(j0, j1 + 1):
            # the x range of the segment inside this row of buckets (the whole box when flat in z)
            if abs(dz) > 1e-12:
                za, zb = oz + j * b, oz + (j + 1) * b
                ta, tb = sorted(((za - az) / dz, (zb - az) / dz))
                ta, tb = max(ta, 0.0), min(tb, 1.0)
                xa, xb = sorted((ax + ta * dx, ax + tb * dx))
                ia, ib = max(math.floor((xa - ox) / b), i0), min(math.floor((xb - ox) / b), i1)
            else:
                ia, ib = i0, i1
            if ia > ib:
                continue
            s, e = st[j * self.width + ia], st[j * self.width + ib + 1]
            if e > s:
                parts.append(self._faces[s:e])
        if not parts:
            return np.zeros(0, dtype=np.int64)
        return np.unique(np.concatenate(parts)) if len(parts) > 1 else parts[0]

    def first_hit(self, a: tuple[float, float, float], b: tuple[float, float, float]) -> float | None:
        """Fraction in [0, 1] along a -> b where it first crosses a triangle, or None."""
        cand = self._candidates(a[0], a[2], b[0], b[2])
        if len(cand) == 0:
            return None
        ax, ay, az = a
        dx, dy, dz = b[0] - ax, b[1] - ay, b[2] - az
        v0, e1, e2 = self._edges(cand)
        # Moller-Trumbore, both faces
        px = dy * e2[:, 2] - dz * e2[:, 1]
        py = dz * e2[:, 0] - dx * e2[:, 2]
        pz = dx * e2[:, 1] - dy * e2[:, 0]
        det = e1[:, 0] * px + e1[:, 1] * py + e1[:, 2] * pz
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        tx, ty, tz = ax - v0[:, 0], ay - v0[:, 1], az - v0[:, 2]
        u = (tx * px + ty * py + tz * pz) * inv
        qx = ty * e1[:, 2] - tz * e1[:, 1]
        qy = tz * e1[:, 0] - tx * e1[:, 2]
        qz = tx * e1[:, 1] - ty * e1[:, 0]
        v = (dx * qx + dy * qy + dz * qz) * inv
        t = (e2[:, 0] * qx + e2[:, 1] * qy + e2[:, 2] * qz) * inv
        hit = ok & (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0) & (t >= 0.0) & (t <= 1.0)
        if not hit.any():
            return None
        return float(t[hit].min())

    def blocked(self, a: tuple[float, float, float], b: tuple[float, float, float]) -> bool:
        return self.first_hit(a, b) is not None

    def first_hit_path(self, pts: np.ndarray) -> tuple[int, float] | None:
        """The first crossing of a polyline whose (x, z) projection is a straight line (a
        shell's flight): (segment index, fraction along it), or None.  The buckets along
        the line are gathered once and every segment tested against them together."""
        p = np.asarray(pts, dtype=np.float64)
        cand = self._candidates(p[0, 0], p[0, 2], p[-1, 0], p[-1, 2])
        if len(cand) == 0 or len(p) < 2:
            return None
        a = p[:-1, None, :]                       # (K, 1, 3)
        d = (p[1:] - p[:-1])[:, None, :]          # (K, 1, 3)
        v0, e1, e2 = (x[None] for x in self._edges(cand))
        pv = np.cross(d, e2)
        det = (e1 * pv).sum(axis=2)
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        tv = a - v0
        u = (tv * pv).sum(axis=2) * inv
        q = np.cross(tv, e1)
        v = (d * q).sum(axis=2) * inv
        t = (e2 * q).sum(axis=2) * inv
        hit = ok & (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0) & (t >= 0.0) & (t <= 1.0)
        rows = np.flatnonzero(hit.any(axis=1))
        if len(rows) == 0:
            return None
        k = int(rows[0])
        return k, float(t[k][hit[k]].min())


def active_kernels():
    """The compiled kernels with ``ground_tilt`` when built and in use, else None."""
    kern = _active()
    return kern if kern is not None and hasattr(kern, "ground_tilt") else None


class Ground:
    """Levels, heights and links of an arena's walkable surface (see the module docstring).

    grid : a layered NavGrid whose ``height`` is set at every node of the surface
    mesh : the model's MeshIndex (shells, sight), or None
    climb : the largest step between neighbours [m]
    """

    #: a surface with heights, slopes or levels (FlatGround: False)
    relief = True

    def __init__(self, grid: Any, mesh: MeshIndex | None = None, climb: float = 0.9) -> None:
        h = np.asarray(grid.heights(), dtype=np.float64)
        self.h = h                                    # (L, nz, nx), NaN: no node
        self.levels, self.nz, self.nx = h.shape
        self.link = np.asarray(grid.links())  # int8 levels (-1: none): an int64 copy took 32 bytes a node
        self.ox, self.oz = float(grid.origin[0]), float(grid.origin[1])
        self.cell = float(grid.cell)
        self.climb = float(climb)
        self.mesh = mesh
        self._solids: SolidField | None = None
        self.exists = np.isfinite(h)
        # plain nested lists: the per-tank lookups below are scalar Python (rows made on first use)
        self._h = lazy_levels(h, heights_row, ROWS_KEPT)
        self._link = lazy_levels(self.link, tuple_row, ROWS_KEPT)
        # nodes whose whole neighbourhood (FLAT_CELLS around) has their own height:
        # a tank standing there is level, no sampling needed (most of a fort's floor)
        flat = self._level_ground(h)
        self._flat = lazy_levels(flat, plain_row, ROWS_KEPT)
        # the arrays as the tilt kernel reads them (_kernels_ground.c): no copies when
        # they already are float64 and bool, C-ordered
        h64 = np.ascontiguousarray(h, dtype=np.float64)
        dims = (self.levels, self.nz, self.nx)
        self._tilt_args = (h64, np.ascontiguousarray(flat, dtype=bool), *dims, self.ox, self.oz, self.cell,
                           self.climb, FLAT_CELLS * self.cell)
        self._height_args = (h64, *dims, self.ox, self.oz, self.cell, self.climb)
        self._follow_args = (np.ascontiguousarray(self.link, dtype=np.int8), *dims)

    @property
    def solids(self) -> SolidField | None:
        """The model's :class:`SolidField` (built on first use; None without a model)."""
        if self._solids is None and self.mesh is not None:
            self._solids = SolidField(self.mesh.vertices, self.mesh.faces)
        return self._solids

    def sight_blocked(self, a: tuple[float, float, float], b: tuple[float, float, float]) -> bool:
        """Whether the model stands between two points (x, y, z): terrain, decks,
        ceilings, walls (no model: nothing does)."""
        return self.mesh is not None and self.mesh.blocked(a, b)

    @staticmethod
    def _level_ground(h: np.ndarray, reach: int = 0) -> np.ndarray:
        """Nodes whose level's other nodes within ``reach`` cells all have their height,
        with no node of another level that near (where the surface may go on across a
        level's edge): missing nodes there are walls and edges, where the tilt sampling
        falls back on the node's own height anyway."""
        from scipy import ndimage

        reach = reach or FLAT_CELLS
        size = 2 * reach + 1
        have = np.isfinite(h)
        L, nz = h.shape[:2]
        out = np.zeros(h.shape, dtype=bool)
        # in bands of rows with ``reach`` rows either side: a window never leaves its
        # band but at the grid's own edges, so the filters' values are the whole
        # grid's, with a band's float64 temporaries (five whole levels of them took
        # +640 MB on a 2 km terrain)
        for lv in range(L):
            others = have[np.arange(L) != lv]
            for r0 in range(0, nz, GROUND_BAND):
                r1 = min(r0 + GROUND_BAND, nz)
                a, b = max(r0 - reach, 0), min(r1 + reach, nz)
                hv, ok = h[lv, a:b], have[lv, a:b]
                hi = ndimage.maximum_filter(np.where(ok, hv, -np.inf), size=size, mode="nearest")
                lo = ndimage.minimum_filter(np.where(ok, hv, np.inf), size=size, mode="nearest")
                flat = ok & (hi - lo <= 1e-6)
                if L > 1:   # one level: no other level near anywhere (a third of a terrain's filtering)
                    flat &= ~(ndimage.maximum_filter(others[:, a:b].any(axis=0).astype(np.uint8), size=size,
                                                     mode="constant") > 0)
                out[lv, r0:r1] = flat[r0 - a:r1 - a]
        return out

    # ------------------------------------------------------------------ cells
    def cell_of(self, x: float, z: float) -> tuple[int, int]:
        """(i, j) of the cell holding (x, z), clamped into the grid."""
        j = int((x - self.ox) // self.cell)
        i = int((z - self.oz) // self.cell)
        if i < 0:
            i = 0
        elif i >= self.nz:
            i = self.nz - 1
        if j < 0:
            j = 0
        elif j >= self.nx:
            j = self.nx - 1
        return i, j

    def node_height(self, level: int, i: int, j: int) -> float | None:
        if 0 <= i < self.nz and 0 <= j < self.nx and 0 <= level < self.levels:
            return self._h[level][i][j]
        return None

    def locate(self, x: float, z: float, y: float | None = None) -> int:
        """The level of the node under (x, z) nearest height ``y`` (the lowest when None);
        -1 when the cell has none."""
        i, j = self.cell_of(x, z)
        best, best_d = -1, math.inf
        for lv in range(self.levels):
            hv = self._h[lv][i][j]
            if hv is None:
                continue
            d = 0.0 if y is None else abs(hv - y)
            if d < best_d:
                best, best_d = lv, d
        return best

    def near_level(self, x: float, z: float, y: float) -> int:
        """The level of a node within one cell of (x, z) nearest height ``y`` (for a
        point just off the surface's edge, a spawn on a cell boundary); -1 for none."""
        i0, j0 = self.cell_of(x, z)
        best, best_d = -1, math.inf
        for di in (0, -1, 1):
            for dj in (0, -1, 1):
                i, j = i0 + di, j0 + dj
                if not (0 <= i < self.nz and 0 <= j < self.nx):
                    continue
                for lv in range(self.levels):
                    hv = self._h[lv][i][j]
                    if hv is not None and abs(hv - y) + 0.01 * (abs(di) + abs(dj)) < best_d:
                        best, best_d = lv, abs(hv - y) + 0.01 * (abs(di) + abs(dj))
        return best

    def follow(self, level: int, i0: int, j0: int, i1: int, j1: int) -> int:
        """The level reached moving from cell (i0, j0) on ``level`` to (i1, j1) along the
        links, -1 when there is no such path (one step in i and one in j at most; a
        diagonal move may go either way round)."""
        if (i0, j0) == (i1, j1):
            return level
        kern = active_kernels()
        if kern is not None:   # on the links themselves: no rows of Python lists made
            lv = kern.ground_follow(*self._follow_args, level, i0, j0, i1, j1)
            if lv is not None:
                return lv
        di, dj = i1 - i0, j1 - j0
        if abs(di) > 1 or abs(dj) > 1:  # a jump of more than a cell: walk it in unit steps
            lv, i, j = level, i0, j0
            while (i, j) != (i1, j1) and lv >= 0:
                si = (i1 > i) - (i1 < i)
                sj = (j1 > j) - (j1 < j)
                lv = self.follow(lv, i, j, i + si, j + sj)
                i, j = i + si, j + sj
            return lv
        link = self._link
        if di == 0 or dj == 0:
            d = 0 if dj == 1 else 2 if dj == -1 else 1 if di == 1 else 3
            return link[level][i0][j0][d]
        d_i = 1 if di == 1 else 3
        d_j = 0 if dj == 1 else 2
        for first, second, mid in ((d_i, d_j, (i1, j0)), (d_j, d_i, (i0, j1))):
            lv = link[level][i0][j0][first]
            if lv >= 0:
                lv2 = link[lv][mid[0]][mid[1]][second]
                if lv2 >= 0:
                    return lv2
        return -1

    # ------------------------------------------------------------------ heights
    def height(self, x: float, z: float, level: int) -> float:
        """Surface height at (x, z) on ``level``: bilinear over the four nodes around it,
        each taken on the level nearest the node under (x, z) in height (the surface
        goes on across a level's edge onto the next one)."""
        kern = active_kernels()
        if kern is not None:   # the same values from the heights array (_kernels_ground.c)
            y = kern.ground_height(*self._height_args, level, x, z)
            if y is not None:
                return y
        u = (x - self.ox) / self.cell
        w = (z - self.oz) / self.cell
        j, i = int(u), int(w)
        if not (0 <= i < self.nz and 0 <= j < self.nx and u >= 0.0 and w >= 0.0):
            i, j = self.cell_of(x, z)
        H = self._h
        hc = H[level][i][j] if 0 <= level < self.levels else None
        if hc is None:
            lv = self.locate(x, z)
            if lv < 0:
                return 0.0
            level, hc = lv, H[lv][i][j]
        u -= 0.5
        w -= 0.5
        j0, i0 = math.floor(u), math.floor(w)
        fu, fw = u - j0, w - i0
        # the common case: the four nodes on this level, all on this surface
        if 0 <= i0 and i0 + 1 < self.nz and 0 <= j0 and j0 + 1 < self.nx:
            row0, row1 = H[level][i0], H[level][i0 + 1]
            a, b, c, d = row0[j0], row0[j0 + 1], row1[j0], row1[j0 + 1]
            if a is not None and b is not None and c is not None and d is not None:
                lim = self.climb
                if abs(a - hc) <= lim and abs(b - hc) <= lim and abs(c - hc) <= lim and abs(d - hc) <= lim:
                    return (a * (1.0 - fu) + b * fu) * (1.0 - fw) + (c * (1.0 - fu) + d * fu) * fw
        total = acc = 0.0
        for ii, wi in ((i0, 1.0 - fw), (i0 + 1, fw)):
            for jj, wj in ((j0, 1.0 - fu), (j0 + 1, fu)):
                wgt = wi * wj
                if wgt <= 0.0:
                    continue
                hv = self._nearest(ii, jj, hc)
                if hv is not None:
                    acc += wgt * hv
                    total += wgt
        return acc / total if total > 0.0 else hc

    def _nearest(self, i: int, j: int, y: float) -> float | None:
        """The node height at (i, j) nearest ``y`` within the climb (a neighbour on the
        same surface), else None."""
        if not (0 <= i < self.nz and 0 <= j < self.nx):
            return None
        best, best_d = None, self.climb + 1e-9
        for lv in range(self.levels):
            hv = self._h[lv][i][j]
            if hv is not None and abs(hv - y) <= best_d:
                best, best_d = hv, abs(hv - y)
        return best

    def tilt(self, x: float, z: float, level: int, c: float, s: float, half_length: float,
             half_width: float) -> tuple[float, float, float]:
        """(height at the centre, pitch, roll) of a hull of the given half extents facing
        (c, s) at (x, z): pitch from the heights at its front and back (positive: nose
        up), roll from those at its right and left (positive: right side down).
        The compiled kernel answers with the same values where it is built (five
        bilinear samples in Python were a fifth of a terrain match's steps)."""
        kern = active_kernels()
        if kern is not None:
            out = kern.ground_tilt(*self._tilt_args, level, x, z, c, s, half_length, half_width)
            if out is not None:
                return out
        i, j = self.cell_of(x, z)
        if 0 <= level < self.levels and self._flat[level][i][j] and half_length <= FLAT_CELLS * self.cell \
                and half_width <= FLAT_CELLS * self.cell:
            return self._h[level][i][j], 0.0, 0.0
        y = self.height(x, z, level)
        hf = self.height(x + c * half_length, z + s * half_length, level)
        hb = self.height(x - c * half_length, z - s * half_length, level)
        # the right-hand side of a facing (c, s) is (-s, c) in (x, z)
        hr = self.height(x - s * half_width, z + c * half_width, level)
        hl = self.height(x + s * half_width, z - c * half_width, level)
        hf, hb = supported(y, hf, hb, self.climb + half_length)
        hl, hr = supported(y, hl, hr, self.climb + half_width)
        pitch = math.atan2(hf - hb, 2.0 * half_length) if half_length > 0 else 0.0
        roll = math.atan2(hl - hr, 2.0 * half_width) if half_width > 0 else 0.0
        return y, pitch, roll


    # ------------------------------------------------------------------ moves
    def keep_move(self, t: Any, dx: float, dz: float) -> tuple[float, float]:
        """The part of tank ``t``'s move (dx, dz) that keeps its centre on the walkable
        surface: into a cell its node links to (the tank's level follows the link), else
        along one axis only (sliding along the edge), else not at all; velocity into a
        refused direction is taken away."""
        i0, j0 = self.cell_of(t.x, t.z)
        i1, j1 = self.cell_of(t.x + dx, t.z + dz)
        if (i0, j0) == (i1, j1):
            return dx, dz
        lv = self.follow(t.level, i0, j0, i1, j1)
        if lv >= 0:
            t.level = lv
            return dx, dz
        if self.node_height(t.level, i0, j0) is None:
            # off the surface already (placed there by hand, a spawn on its edge): any
            # move onto a node near its height is a way back, others are refused
            lv = self.locate(t.x + dx, t.z + dz, t.y)
            hv = self.node_height(lv, i1, j1) if lv >= 0 else None
            if hv is not None and abs(hv - t.y) <= self.climb:
                t.level = lv
                return dx, dz
        # refused: slide along whichever axis is still open
        for keep_x in (abs(dx) >= abs(dz), abs(dx) < abs(dz)):
            ii, jj = self.cell_of(t.x + (dx if keep_x else 0.0), t.z + (0.0 if keep_x else dz))
            lv = self.follow(t.level, i0, j0, ii, jj)
            if lv >= 0:
                t.level = lv
                if keep_x:
                    t.vz = 0.0
                    return dx, 0.0
                t.vx = 0.0
                return 0.0, dz
        t.vx = t.vz = 0.0
        return 0.0, 0.0

    def contain(self, tanks: Any, before: Any, tilt: Any) -> None:
        """After the collision pushes: a push that would carry a tank's centre off the
        walkable surface keeps only its part along the surface (containment wins over
        the push, as a wall would), and a moved tank stands at its new place
        (``tilt(t)``)."""
        for t, (x0, z0) in zip(tanks, before):
            if not t.alive or (t.x == x0 and t.z == z0):
                continue
            dx, dz = t.x - x0, t.z - z0
            t.x, t.z = x0, z0
            dx, dz = self.keep_move(t, dx, dz)
            t.x += dx
            t.z += dz
            tilt(t)

