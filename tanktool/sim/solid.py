"""The model's solid as voxels, for many lines of sight at once (``SolidField``).

Split from sim/ground.py (the ground's heights and links, the model's triangles),
which builds it on first use (``Ground.solids``) and re-exports it.
"""

from __future__ import annotations

import math

import numpy as np


#: up to this many lines of sight from one point are walked one by one (SolidField.visible_from)
FEW_LINES = 4


class SolidField:
    """The model's solid as voxels (the spans of ``geometry.heightfield`` at ``cs``
    metres across and ``ch`` up, everything below a column's lowest span counted as
    under the ground), for many lines of sight at once: a point is in the solid when
    its voxel is.  Coarser than :class:`MeshIndex` (a span fills its whole cell), but
    a line costs an array lookup per sample: the agents' map of which places see which
    (many thousand lines) is built in well under a second."""

    #: refuse to make more voxels than this (a huge, finely detailed model): coarsen
    MAX_VOXELS = 60_000_000
    #: a point is in the solid when the point this much above it is: a span fills its
    #: cell up to the highest point of the faces in it, so a line skimming a slope (or
    #: a crest) would otherwise be cut by the rise of the slope within a cell
    MARGIN = 0.3
    #: columns per side of the blocks a line of sight skips when it passes above them
    BLOCK = 8
    #: voxels filled at a time (a band of rows): bounds the rasteriser's temporaries
    BAND_VOXELS = 4_000_000

    def __init__(self, vertices: np.ndarray, faces: np.ndarray, cs: float = 0.5, ch: float = 0.1) -> None:
        from ..geometry.heightfield import grid_for

        v = np.asarray(vertices, dtype=np.float64)
        f = np.asarray(faces, dtype=np.int64)
        span = float(np.ptp(v[:, 1])) if len(v) else 0.0
        while True:
            origin, shape = grid_for(v, cs)
            ny = int(math.ceil(span / ch)) + 2
            if shape[0] * shape[1] * ny <= self.MAX_VOXELS:
                break
            cs, ch = cs * 1.5, ch * 1.5
        nz, nx = shape
        # filled band by band of rows (rasterize's ``rows``: the whole build's spans
        # there), so the rasteriser's temporaries and the running sum are a band's,
        # not the model's (+878 MB at its peak on a 2 km terrain in one go)
        self._bytes = bytearray(nz * nx * ny)   # the scalar walk indexes bytes: no numpy per sample
        solid = np.frombuffer(self._bytes, dtype=bool)
        col_top = np.full(nz * nx, -np.inf)
        gz = (v[:, 2] - origin[2]) / cs
        fz = gz[f] if len(f) else np.zeros((0, 3))
        zlo, zhi = np.floor(fz.min(axis=1)) - 1, np.floor(fz.max(axis=1)) + 1
        del fz
        band = max(self.BAND_VOXELS // max(nx * ny, 1), 1)
        for r0 in range(0, nz, band):
            r1 = min(r0 + band, nz)
            sel = np.flatnonzero((zhi >= r0) & (zlo < r1))
            self._fill_band(v, f[sel], origin, (nz, nx), cs, ch, ny, (r0, r1), solid, col_top)
        solid.flags.writeable = False
        self.solid = solid   # the same memory as _bytes, read-only
        # the highest solid of each block of BLOCK x BLOCK columns (world y; -inf: none)
        B = self.BLOCK
        bz, bx = -(-nz // B), -(-nx // B)
        col_top = np.where(np.isfinite(col_top), origin[1] + col_top * ch, -np.inf)
        pad = np.full((bz * B, bx * B), -np.inf)
        pad[:nz, :nx] = col_top.reshape(nz, nx)
        self._tops = pad.reshape(bz, B, bx, B).max(axis=(1, 3)).ravel().tolist()
        self._bw = bx
        self.ox, self.y0, self.oz = float(origin[0]), float(origin[1]), float(origin[2])
        self.cs, self.ch, self.shape, self.ny = float(cs), float(ch), (nz, nx), ny

    @staticmethod
    def _fill_band(v: np.ndarray, f: np.ndarray, origin: np.ndarray, shape: tuple[int, int], cs: float,
                   ch: float, ny: int, rows: tuple[int, int], solid: np.ndarray, col_top: np.ndarray) -> None:
        """The voxels of rows [r0, r1) into ``solid`` and each column's highest solid
        voxel + 1 into ``col_top`` (the faces ``f`` cover at least those rows)."""
        from ..geometry.heightfield import rasterize

        nz, nx = shape
        r0, r1 = rows
        none = np.zeros(len(f), dtype=bool)
        (col, smin, smax, *_), _ = rasterize(v, f, cs, ch, none, none, origin, shape, 0, rows=rows)
        first = np.ones(len(col), dtype=bool)
        first[1:] = col[1:] != col[:-1]
        smin = np.where(first, 0, smin)            # under the ground is solid
        smax = np.minimum(np.maximum(smax, smin + 1), ny)
        # voxels [smin, smax) of each span: +1 at a span's bottom, -1 past its top, summed
        # up the columns (merged spans do not overlap: 0 or 1); the voxels' indices
        # took 16 bytes a solid voxel (+1.4 GB on a 2 km terrain)
        lo, hi = r0 * nx * ny, r1 * nx * ny
        delta = np.zeros(hi - lo + 1, dtype=np.int8)
        local = col - r0 * nx
        np.add.at(delta, local * ny + smin, 1)
        np.add.at(delta, local * ny + smax, -1)
        np.cumsum(delta, dtype=np.int8, out=delta)
        np.greater(delta[:-1], 0, out=solid[lo:hi])
        # a column's top: its last span's top (spans come sorted by column and height)
        last = np.ones(len(col), dtype=bool)
        last[:-1] = col[1:] != col[:-1]
        col_top[col[last]] = smax[last]

    def inside(self, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
        """Whether each point lies in the solid (``MARGIN`` deep; off the grid or above
        the model: no; below the model: where the column has anything)."""
        nz, nx = self.shape
        j = np.floor((x - self.ox) / self.cs).astype(np.int64)
        i = np.floor((z - self.oz) / self.cs).astype(np.int64)
        y = y + self.MARGIN
        k = np.clip(np.floor((y - self.y0) / self.ch).astype(np.int64), 0, self.ny - 1)
        on = (i >= 0) & (i < nz) & (j >= 0) & (j < nx) & (y < self.y0 + (self.ny - 1) * self.ch)
        c = np.where(on, (i * nx + j) * self.ny + k, 0)
        return self.solid[c] & on

    def blocked(self, a: tuple[float, float, float], b: tuple[float, float, float]) -> bool:
        """Whether the segment a -> b passes through the solid (sampled every half
        cell, as :meth:`visible`).  Plain Python: the segment goes block by block
        (``BLOCK`` cells square) and only where it comes lower than the block's
        highest solid are its samples looked up; an early exit at the first hit."""
        ax, ay, az = a
        dx, dy, dz = b[0] - ax, b[1] - ay, b[2] - az
        k = int(math.ceil(math.sqrt(dx * dx + dy * dy + dz * dz) / (0.5 * self.cs)))
        if k < 2:
            return False
        nz, nx = self.shape
        ny, solid = self.ny, self._bytes
        cs, ch, margin = self.cs, self.ch, self.MARGIN
        ox, oz, y0 = self.ox, self.oz, self.y0
        top = ny - 1
        tops, bw, bs = self._tops, self._bw, self.BLOCK * self.cs
        m = 1
        while m < k:
            t = m / k
            x, z = ax + dx * t, az + dz * t
            bi, bj = math.floor((z - oz) / bs), math.floor((x - ox) / bs)
            # the samples up to where the segment leaves this block
            t_end = 1.0
            if dx > 0:
                t_end = min(t_end, (ox + (bj + 1) * bs - ax) / dx)
            elif dx < 0:
                t_end = min(t_end, (ox + bj * bs - ax) / dx)
            if dz > 0:
                t_end = min(t_end, (oz + (bi + 1) * bs - az) / dz)
            elif dz < 0:
                t_end = min(t_end, (oz + bi * bs - az) / dz)
            m_end = min(max(math.ceil(t_end * k - 1e-9), m + 1), k)  # samples before the block's edge
            if 0 <= bi < len(tops) // bw and 0 <= bj < bw and \
                    min(ay + dy * t, ay + dy * ((m_end - 1) / k)) + margin <= tops[bi * bw + bj] + ch:
                for mm in range(m, m_end):   # the same arithmetic as inside(), to the last bit
                    tt = mm / k
                    j = math.floor((ax + dx * tt - ox) / cs)
                    i = math.floor((az + dz * tt - oz) / cs)
                    if i < 0 or i >= nz or j < 0 or j >= nx:
                        continue
                    kk = math.floor(((ay + dy * tt) + margin - y0) / ch)
                    if kk >= top:
                        continue
                    if solid[(i * nx + j) * ny + (kk if kk > 0 else 0)]:
                        return True
            m = m_end
        return False

    def visible_from(self, a: tuple[float, float, float], points: np.ndarray) -> np.ndarray:
        """(n,) bool: whether the segment from ``a`` to each point keeps out of the
        solid (the samples of :meth:`blocked`, all lines in one array lookup)."""
        q = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if len(q) == 0:
            return np.zeros(0, dtype=bool)
        if len(q) <= FEW_LINES:
            # a few lines: walked one by one, block by block (the same samples), which
            # skips what passes above the solid and beats the arrays' set-up cost
            return np.array([not self.blocked(a, tuple(b)) for b in q.tolist()], dtype=bool)
        p = np.asarray(a, dtype=np.float64)
        d = q - p
        k = np.maximum(np.ceil(np.sqrt((d * d).sum(axis=1)) / (0.5 * self.cs)).astype(np.int64), 1)
        cnt = k - 1
        owner = np.repeat(np.arange(len(q)), cnt)
        t = (np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt) + 1) / k[owner]
        s = p + d[owner] * t[:, None]
        hit = np.bincount(owner, weights=self.inside(s[:, 0], s[:, 1], s[:, 2]), minlength=len(q))
        return hit == 0

    def visible(self, points: np.ndarray, max_range: float = math.inf) -> np.ndarray:
        """(n, n) bool: whether the segment between each two points keeps out of the
        solid (sampled every half cell; the ends themselves stand in open air); pairs
        farther apart than ``max_range`` in (x, z) are not visible; a point sees itself."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        n = len(p)
        step = 0.5 * self.cs
        from ..geometry.kernels import active

        kern = active()
        if getattr(kern, "solid_visible", None) is not None:   # the same samples in C, a line left at its first hit
            out = np.zeros((n, n), dtype=np.uint8)
            nz, nx = self.shape
            kern.solid_visible(self._bytes, np.ascontiguousarray(p), out, nz, nx, self.ny, self.ox, self.oz, self.y0,
                               self.cs, self.ch, self.MARGIN, step, float(max_range))
            return out.view(bool)
        vis = np.eye(n, dtype=bool)
        for a in range(n - 1):
            b = np.arange(a + 1, n)
            d = p[b] - p[a]
            keep = d[:, 0] ** 2 + d[:, 2] ** 2 <= max_range * max_range
            b, d = b[keep], d[keep]
            if len(b) == 0:
                continue
            k = np.maximum(np.ceil(np.sqrt((d * d).sum(axis=1)) / step).astype(np.int64), 1)
            cnt = k - 1
            owner = np.repeat(np.arange(len(b)), cnt)
            t = (np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt) + 1) / k[owner]
            q = p[a] + d[owner] * t[:, None]
            hit = np.bincount(owner, weights=self.inside(q[:, 0], q[:, 1], q[:, 2]), minlength=len(b))
            vis[a, b] = hit == 0
            vis[b, a] = hit == 0
        return vis
