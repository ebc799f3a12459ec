"""The voxel heightfield of a level, as Recast computes it, in numpy.

A column of cells stands on every (row, column) of a grid in the (x, z) plane:
column ``j`` covers ``x`` in ``[ox + j cs, ox + (j+1) cs)``, row ``i`` covers ``z`` in
``[oz + i cs, oz + (i+1) cs)``.  Each triangle is clipped against every cell it
touches; the clipped polygon's lowest and highest ``y`` make a *span* of solid,
quantised to the cell height ``ch`` (floor below, ceiling above, at least one step).
Spans of one column that overlap or touch are merged.  A span is *walkable* when the
triangle that gives it its top faces up no steeper than the maximum slope (spans
whose tops lie within the climb of each other share the flag, as Recast's
``flagMergeThr``).

Then Recast's three filters (tanktool/geometry/span_filters.py: ``rcFilterLowHangingWalkableObstacles``,
``rcFilterLedgeSpans``, ``rcFilterWalkableLowHeightSpans``):

* a non-walkable span whose top is within the climb of the walkable span below it in
  its column becomes walkable (kerbs, stair steps);
* a walkable span with a neighbour column where a tank could stand more than the climb
  lower (or no neighbour: the edge of the grid) is a ledge: not walkable; nor is one
  whose reachable neighbours' floors differ by more than the climb among themselves
  (too steep across a cell);
* a walkable span with less than the headroom free above it is not walkable.

Everything is a flat numpy array over triangles, (triangle, row) pairs, (triangle,
cell) pairs or spans: there is no loop over triangles or cells in Python.  The clipped
polygon of a triangle and a cell is never built: its vertices are the triangle's
vertices inside the cell and the ends of the triangle's chords along the cell's four
sides, and the ``y`` range over those is all a span needs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ArenaError
from .kernels import active
from . import triangle_passes
from .span_filters import OPEN, _next_in_column, column_starts, filter_spans, neighbour_columns  # noqa: F401

#: refuse heightfields larger than this (columns) or spans beyond this many cells high
MAX_COLUMNS = 40_000_000
MAX_HEIGHT_STEPS = (1 << 15) - 1


@dataclass
class Heightfield:
    """Solid spans sorted by (column, bottom).

    origin : (x, y, z) of the grid's low corner (y: the lowest vertex)
    shape : (nz, nx) columns; a span's column is ``i * nx + j``
    smin, smax : span bottom and top in steps of ``ch`` above ``origin[1]``
    walkable : the span's top may be stood on (after the filters)
    flat : a horizontal face (within FLAT_NY) gives the span's top
    top_walkable : the face at the very top is a walkable slope (False on the rim of a
        steep obstacle that is walkable only because it rises less than the climb)
    """

    origin: np.ndarray
    cs: float
    ch: float
    shape: tuple[int, int]
    col: np.ndarray
    smin: np.ndarray
    smax: np.ndarray
    walkable: np.ndarray
    flat: np.ndarray
    top_walkable: np.ndarray
    counts: dict
    low_headroom: np.ndarray  # spans the headroom filter took away

    @property
    def start(self) -> np.ndarray:
        """(nz * nx + 1,) index of each column's first span."""
        return column_starts(self.col, self.shape[0] * self.shape[1])

    def ceiling(self) -> np.ndarray:
        """Bottom of the next span up in the same column (OPEN above the top one)."""
        return _next_in_column(self.col, self.smin, OPEN)

    def top_y(self) -> np.ndarray:
        """World y of each span's top."""
        return self.origin[1] + self.smax * self.ch

    def __post_init__(self) -> None:
        # int32 (columns < MAX_COLUMNS, steps <= MAX_HEIGHT_STEPS): 12 bytes a span less (0.2 GB on 2 km)
        self.col, self.smin, self.smax = (np.asarray(a, dtype=np.int32) for a in (self.col, self.smin, self.smax))

    def geometry(self) -> "Heightfield":
        """The grid alone (origin, cells, shape, counts) without its spans: what a
        lean walkable surface keeps of it (walkable.walkable_surface(lean=True))."""
        none = [np.zeros(0, dtype=a.dtype) for a in (self.col, self.smin, self.smax, self.walkable, self.flat,
                                                    self.top_walkable)]   # not a[:0]: views keep the spans
        return Heightfield(self.origin, self.cs, self.ch, self.shape, *none, dict(self.counts), np.zeros(0, bool))


#: a horizontal face: |n_y| at least this (within ~2.6 degrees)
FLAT_NY = 0.999


def _ramp(cnt: np.ndarray) -> np.ndarray:
    """0, 1, .., cnt[0]-1, 0, 1, .., cnt[1]-1, ...: positions inside repeated blocks."""
    total = int(cnt.sum())
    return np.arange(total) - np.repeat(np.cumsum(cnt) - cnt, cnt)


def grid_for(vertices: np.ndarray, cs: float, origin_xz=None, shape=None) -> tuple[np.ndarray, tuple[int, int]]:
    """Origin (x, y, z) and (nz, nx) of a grid of ``cs`` cells over the vertices
    (or over ``origin_xz`` / ``shape`` when given)."""
    # column by column: numpy's reduction over axis 0 of an (n, 3) array is ~8x slower
    lo, hi = (np.array([f(vertices[:, k]) for k in range(3)]) for f in (np.min, np.max))
    if origin_xz is None:
        origin = lo.astype(np.float64).copy()
    else:
        origin = np.array([origin_xz[0], lo[1], origin_xz[1]], dtype=np.float64)
    if shape is None:
        nx = max(1, int(math.ceil((hi[0] - origin[0]) / cs - 1e-9)))
        nz = max(1, int(math.ceil((hi[2] - origin[2]) / cs - 1e-9)))
        shape = (nz, nx)
    if shape[0] * shape[1] > MAX_COLUMNS:
        raise ArenaError(
            f"cell {cs:g} m over {shape[1] * cs:g} x {shape[0] * cs:g} m makes {shape[0] * shape[1]:,} columns "
            f"(limit {MAX_COLUMNS:,}); use a larger --cell"
        )
    return origin, (int(shape[0]), int(shape[1]))


#: horizontal faces within this of each other share a height cluster (m)
FLAT_GAP = 0.05


FACE_BLOCK = 1 << 17  #: faces per block of flat_heights


def flat_heights(vertices: np.ndarray, faces: np.ndarray, flat_ny: float = 0.999) -> tuple[np.ndarray, np.ndarray]:
    """Heights of the model's horizontal upward faces, clustered (gaps over FLAT_GAP):
    (cluster height, cluster area) sorted by height."""
    from .walls import _upward_faces, triangle_mesh

    from .walls import UP_NORMAL_MIN

    vertices, faces = triangle_mesh(vertices, faces)
    kern = active()
    got = triangle_passes.flat_faces(kern, vertices, faces, UP_NORMAL_MIN ** 2, flat_ny) if kern is not None else None
    hs, areas = ([got[0]], [got[1]]) if got is not None else ([], [])
    # a block of faces at a time: _upward_faces and the normals take ~190 bytes a face
    # of temporaries (~0.4 GB on 2 million faces), and every value is the face's own
    # (the same heights and areas, in the same order)
    for b in range(0, len(faces) if got is None else 0, FACE_BLOCK):
        fb = faces[b:b + FACE_BLOCK]
        up, height, area, _ = _upward_faces(vertices, fb)
        if len(up) == 0:
            continue
        tri = vertices[fb[up]]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        ny = n[:, 1] / np.maximum(np.linalg.norm(n, axis=1), 1e-300)
        flat = ny >= flat_ny
        hs.append(height[flat])
        areas.append(area[flat])
    h, a = (np.concatenate(x) if x else np.zeros(0) for x in (hs, areas))
    if len(h) == 0:
        return np.zeros(0), np.zeros(0)
    order = np.argsort(h, kind="stable")
    h, a = h[order], a[order]
    starts = np.concatenate([[0], np.flatnonzero(np.diff(h) > FLAT_GAP) + 1])
    total = np.add.reduceat(a, starts)
    mean = np.add.reduceat(a * h, starts) / np.maximum(total, 1e-300)
    return mean, total


def walkable_faces(vertices: np.ndarray, faces: np.ndarray, max_slope_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """(walkable, flat) per face: the normal's y within the slope of +y (Recast's
    rcMarkWalkableTriangles: n_y > cos(slope)), and within FLAT_NY of +y."""
    kern = active()
    if kern is not None and np.asarray(vertices).dtype == np.float64:  # one pass (geometry/triangle_passes.py)
        got = triangle_passes.walkable_faces(kern, vertices, faces, math.cos(math.radians(max_slope_deg)), FLAT_NY)
        if got is not None:
            return got
    X, Y, Z = (np.ascontiguousarray(vertices[:, k], dtype=np.float64) for k in range(3))
    f0, f1, f2 = (np.ascontiguousarray(faces[:, k]) for k in range(3))
    e1x, e1y, e1z = X[f1] - X[f0], Y[f1] - Y[f0], Z[f1] - Z[f0]
    e2x, e2y, e2z = X[f2] - X[f0], Y[f2] - Y[f0], Z[f2] - Z[f0]
    nx = e1y * e2z - e1z * e2y
    ny = e1z * e2x - e1x * e2z
    nz = e1x * e2y - e1y * e2x
    n = np.sqrt(nx * nx + ny * ny + nz * nz)
    with np.errstate(invalid="ignore", divide="ignore"):
        cy = np.where(n > 0, ny / n, 0.0)
    return cy > math.cos(math.radians(max_slope_deg)), cy >= FLAT_NY


def _sections(u: list, v: list, y: list, a: np.ndarray, valid: np.ndarray | None = None):
    """The section of each triangle by the line ``u = a`` in the (u, v) plane.

    ``u``, ``v``, ``y``: the three vertices' coordinates (three arrays, one entry per
    (triangle, line) pair).  Returns the section's ends ``(v_lo, y at v_lo, v_hi, y at
    v_hi)``, the lowest and highest ``y`` on it (a vertical triangle's section is a
    vertical segment: one ``v``, a range of ``y``) and whether the line meets the
    triangle at all.
    """
    n = len(a)
    vlo = np.full(n, np.inf)
    vhi = np.full(n, -np.inf)
    ylo = np.zeros(n)
    yhi = np.zeros(n)
    ymn = np.full(n, np.inf)
    ymx = np.full(n, -np.inf)

    def take(ok, vv, yy):
        np.copyto(ylo, yy, where=ok & (vv < vlo))
        np.copyto(yhi, yy, where=ok & (vv > vhi))
        np.minimum(vlo, vv, out=vlo, where=ok)
        np.maximum(vhi, vv, out=vhi, where=ok)
        np.minimum(ymn, yy, out=ymn, where=ok)
        np.maximum(ymx, yy, out=ymx, where=ok)

    for k in range(3):  # vertices on the line (axis-aligned models have many)
        ok = u[k] == a
        if ok.any():
            take(ok, v[k], y[k])
    with np.errstate(invalid="ignore", divide="ignore"):
        for i, j in ((0, 1), (1, 2), (2, 0)):
            du = u[j] - u[i]
            ok = (u[i] - a) * (u[j] - a) < 0
            t = (a - u[i]) / du
            take(ok, v[i] + t * (v[j] - v[i]), y[i] + t * (y[j] - y[i]))
    return vlo, ylo, vhi, yhi, ymn, ymx, np.isfinite(vlo)


def _line_ranges(lo: np.ndarray, hi: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Cells [first, last] a range [lo, hi] of grid units covers: a range that only
    touches a cell's low line is not in it; a degenerate one (lo == hi) is in the
    cell it starts; clipped to [0, n - 1]."""
    first = np.floor(lo)
    last = np.where(hi > lo, np.ceil(hi) - 1, first)
    return np.maximum(first, 0), np.minimum(last, n - 1)


@dataclass
class _Rows:
    """(triangle, row) pairs: the polygon Q of the triangle inside the row's slab.

    Q's vertices are the points of the triangle's long edge (lowest to highest z) and
    of its short side at the slab's clipped ends z0 and z1, and the middle vertex when
    it lies between them: ``qx``, ``qy`` (5, n), NaN where absent.
    """

    tri: np.ndarray
    row: np.ndarray
    z0: np.ndarray
    z1: np.ndarray
    qx: np.ndarray
    qy: np.ndarray
    j0: np.ndarray
    ncell: np.ndarray
    qlo: np.ndarray  # Q's x range and y range
    qhi: np.ndarray
    ylo: np.ndarray
    yhi: np.ndarray


def _nanreduce(fn, rows: np.ndarray) -> np.ndarray:
    """fmin / fmax over the first axis, NaN ignored (a chain of elementwise calls: much
    faster than np.nanmin on a few long rows)."""
    out = rows[0].copy()
    for r in rows[1:]:
        fn(out, r, out=out)
    return out


def _sort3(Z: list, *others: list) -> tuple[list, ...]:
    """The three vertices of each triangle reordered by z (a sorting network of three
    compare-and-swaps), ``others`` reordered alike."""
    arrs = [list(Z)] + [list(o) for o in others]
    for a, b in ((0, 1), (1, 2), (0, 1)):
        swap = arrs[0][a] > arrs[0][b]
        for v in arrs:
            va, vb = v[a], v[b]
            v[a], v[b] = np.where(swap, vb, va), np.where(swap, va, vb)
    return tuple(arrs)


def _rows(X: list, Z: list, Y: list, nz: int, nx: int, rows: tuple[int, int] | None = None) -> _Rows:
    """(triangle, row) pairs and their polygons Q (see :class:`_Rows`).

    Per triangle the vertices a, b, c by z; per z line strictly inside a triangle its
    section's two ends (on the long edge a-c and on the short side a-b-c); per pair Q's
    vertices: the section at the slab's low line (or vertex a, in the triangle's first
    row), at its high line (or c, in the last row), and b when it lies between.
    """
    (za, zb, zc), (xa, xb, xc), (ya, yb, yc) = _sort3(Z, X, Y)
    with np.errstate(invalid="ignore", divide="ignore"):
        inv_ac = np.where(zc > za, 1.0 / (zc - za), 0.0)
        inv_ab = np.where(zb > za, 1.0 / (zb - za), 0.0)
        inv_bc = np.where(zc > zb, 1.0 / (zc - zb), 0.0)
    # the triangle's own rows [r0t, r1t], and the part of them on the grid [r0, r1]
    r0t = np.floor(za)
    r1t = np.where(zc > za, np.ceil(zc) - 1, r0t)
    lo_row, hi_row = rows if rows is not None else (0, nz)
    r0 = np.maximum(r0t, lo_row)
    r1 = np.minimum(r1t, hi_row - 1)
    nrow = np.maximum(r1 - r0 + 1, 0).astype(np.int64)
    # sections at the lines r0 .. r1 + 1 of each triangle (those past its ends unused)
    nline = np.where(nrow > 0, nrow + 1, 0)
    tl = np.repeat(np.arange(len(za)), nline)
    L = np.repeat(r0, nline) + _ramp(nline)
    t = (L - za[tl]) * inv_ac[tl]
    lx = xa[tl] + t * (xc - xa)[tl]
    ly = ya[tl] + t * (yc - ya)[tl]
    lower = L <= zb[tl]
    zs = np.where(lower, za[tl], zb[tl])
    inv = np.where(lower, inv_ab[tl], inv_bc[tl])
    t = (L - zs) * inv
    sx = np.where(lower, xa[tl], xb[tl]) + t * np.where(lower, (xb - xa)[tl], (xc - xb)[tl])
    sy = np.where(lower, ya[tl], yb[tl]) + t * np.where(lower, (yb - ya)[tl], (yc - yb)[tl])
    # pairs: row r's low line is section (r - r0) of its triangle, its high line the next;
    # the triangle's first row has vertex a for its low line, its last row vertex c
    tri = np.repeat(np.arange(len(za)), nrow)
    k = _ramp(nrow)
    row = np.repeat(r0.astype(np.int64), nrow) + k
    lo_i = np.repeat(np.cumsum(nline) - nline, nrow) + k
    hi_i = lo_i + 1
    first = row == r0t[tri]
    last = row == r1t[tri]
    if len(L) == 0:
        lx = ly = sx = sy = np.zeros(1)
        lo_i = hi_i = np.zeros(len(tri), dtype=np.int64)
    A = (xa[tri], ya[tri])
    Cv = (xc[tri], yc[tri])
    qx = np.empty((5, len(tri)))
    qy = np.empty((5, len(tri)))
    qx[0] = np.where(first, A[0], lx[lo_i])
    qy[0] = np.where(first, A[1], ly[lo_i])
    qx[1] = np.where(first, A[0], sx[lo_i])
    qy[1] = np.where(first, A[1], sy[lo_i])
    qx[2] = np.where(last, Cv[0], lx[hi_i])
    qy[2] = np.where(last, Cv[1], ly[hi_i])
    qx[3] = np.where(last, Cv[0], sx[hi_i])
    qy[3] = np.where(last, Cv[1], sy[hi_i])
    c = row.astype(np.float64)
    zbt = zb[tri]
    flat_z = za[tri] == zc[tri]  # the whole triangle lies in one z line: Q is the triangle
    mid = ((zbt > c) & (zbt < c + 1.0)) | flat_z
    qx[4] = np.where(mid, xb[tri], np.nan)
    qy[4] = np.where(mid, yb[tri], np.nan)
    z0 = np.maximum(c, za[tri])
    z1 = np.minimum(c + 1.0, zc[tri])
    lo = _nanreduce(np.fmin, qx)
    hi = _nanreduce(np.fmax, qx)
    j0, j1 = _line_ranges(lo, hi, nx)
    # a triangle that only touches the slab's line (z0 == z1) is not in the row
    keep = ((z1 > z0) | flat_z) & (j1 >= j0)
    ncell = np.where(keep, j1 - j0 + 1, 0).astype(np.int64)
    return _Rows(tri, row, z0, z1, qx, qy, np.where(keep, j0, 0).astype(np.int64), ncell, lo, hi,
                 _nanreduce(np.fmin, qy), _nanreduce(np.fmax, qy))


def _quantise(ymin: np.ndarray, ymax: np.ndarray, ch: float) -> tuple[np.ndarray, np.ndarray]:
    """Span bottom and top in cell-height steps: floor below, ceiling above, at least one."""
    smin = np.clip(np.floor(ymin / ch), 0, MAX_HEIGHT_STEPS).astype(np.int64)
    smax = np.clip(np.ceil(ymax / ch), smin + 1, MAX_HEIGHT_STEPS).astype(np.int64)
    return smin, smax


def _cells_plane(rows: _Rows, A: np.ndarray, B: np.ndarray, C: np.ndarray, ch: float):
    """Spans of gentle triangles (y = A + B x + C z): the plane's range over the cell's
    part of Q's bounding box, clipped to Q's own y range.

    A row whose whole y range lies within one cell height (floors, gentle slopes) gives
    every one of its cells the same one-step span: no per-cell arithmetic.
    """
    band = np.floor(rows.ylo / ch)
    uniform = band == np.floor(rows.yhi / ch)
    n = rows.ncell
    nu = np.where(uniform, n, 0)
    pu = np.repeat(np.arange(len(n)), nu)
    ju = np.repeat(rows.j0, nu) + _ramp(nu)
    su = np.clip(band, 0, MAX_HEIGHT_STEPS - 1).astype(np.int64)[pu]
    n = np.where(uniform, 0, n)
    p = np.repeat(np.arange(len(n)), n)
    j = (np.repeat(rows.j0, n) + _ramp(n)).astype(np.float64)
    t = rows.tri
    Bt, Ct = B[t], C[t]
    base = A[t]
    zlo = base + np.minimum(Ct * rows.z0, Ct * rows.z1)
    zhi = base + np.maximum(Ct * rows.z0, Ct * rows.z1)
    xa = np.maximum(j, rows.qlo[p])
    xb = np.minimum(j + 1.0, rows.qhi[p])
    bp = Bt[p]
    ba, bb = bp * xa, bp * xb
    ymin = np.maximum(zlo[p] + np.minimum(ba, bb), rows.ylo[p])
    ymax = np.minimum(zhi[p] + np.maximum(ba, bb), rows.yhi[p])
    smin, smax = _quantise(ymin, np.maximum(ymax, ymin), ch)
    return (np.concatenate([pu, p]), np.concatenate([ju, j.astype(np.int64)]),
            np.concatenate([su, smin]), np.concatenate([su + 1, smax]))


def _cells_exact(rows: _Rows, X: list, Z: list, Y: list, ch: float):
    """Spans of steep triangles: the y range over Q's vertices in the cell and the
    triangle's sections by the cell's two x lines, clipped to the slab."""
    ncell = rows.ncell
    tri = rows.tri
    nt = len(X[0])
    cell_off = np.cumsum(ncell) - ncell
    ncells = int(ncell.sum())
    # sections by the x lines crossing each triangle (computed once per triangle)
    xlo = np.minimum(np.minimum(X[0], X[1]), X[2])
    xhi = np.maximum(np.maximum(X[0], X[1]), X[2])
    a0 = np.ceil(xlo)
    nxl = np.maximum(np.floor(xhi) - a0 + 1, 0).astype(np.int64)
    tx = np.repeat(np.arange(nt), nxl)
    xline = np.repeat(a0, nxl) + _ramp(nxl)
    xs = _sections([a[tx] for a in X], [a[tx] for a in Z], [a[tx] for a in Y], xline)
    xoff = np.cumsum(nxl) - nxl
    nlines = np.where(ncell > 0, ncell + 1, 0)  # lines j0 .. j1 + 1 of each pair
    p = np.repeat(np.arange(len(tri)), nlines)
    a = np.repeat(rows.j0, nlines) + _ramp(nlines)
    t_p = tri[p]
    li = a - a0[t_p].astype(np.int64)
    on = (li >= 0) & (li < nxl[t_p])
    if len(tx) == 0:  # no triangle reaches an x line
        xs = tuple(np.zeros(1, dtype=s.dtype) for s in xs)
        on[:] = False
    idx = np.where(on, xoff[t_p] + li, 0)
    vlo, ylo, vhi, yhi, ymn, ymx, ok = (s[idx] for s in xs)
    z0, z1 = rows.z0[p], rows.z1[p]
    with np.errstate(invalid="ignore", divide="ignore"):
        za = np.maximum(vlo, z0)
        zb = np.minimum(vhi, z1)
        slope = (yhi - ylo) / (vhi - vlo)
        ya = ylo + (za - vlo) * slope
        yb = ylo + (zb - vlo) * slope
    vertical = vhi == vlo
    ok &= on & np.where(vertical, (vlo >= z0) & (vlo <= z1), za <= zb)
    lo_l = np.where(ok, np.where(vertical, ymn, np.minimum(ya, yb)), np.inf)
    hi_l = np.where(ok, np.where(vertical, ymx, np.maximum(ya, yb)), -np.inf)
    # cell k of pair q has lines k + (q's rank among pairs with cells) and the next one
    prank = np.cumsum(ncell > 0) - 1
    L = np.arange(ncells) + np.repeat(prank, ncell)
    ymin = np.minimum(lo_l[L], lo_l[L + 1])
    ymax = np.maximum(hi_l[L], hi_l[L + 1])
    # Q's vertices: each in the cell of its column (one cell per pair and vertex)
    j0 = rows.j0
    for sx, sy in zip(rows.qx, rows.qy):
        with np.errstate(invalid="ignore"):
            jj = np.floor(sx) - j0
            sel = np.flatnonzero((jj >= 0) & (jj < ncell))
        k = cell_off[sel] + jj[sel].astype(np.int64)
        ymin[k] = np.minimum(ymin[k], sy[sel])
        ymax[k] = np.maximum(ymax[k], sy[sel])
    pc = np.repeat(np.arange(len(tri)), ncell)
    jc = np.repeat(j0, ncell) + _ramp(ncell)
    hit = np.isfinite(ymin)
    smin, smax = _quantise(ymin[hit], ymax[hit], ch)
    return pc[hit], jc[hit], smin, smax


#: triangles whose normal is at least this close to vertical (|n_y|, ~60 degrees of
#: slope) are rasterised by the plane; steeper ones (walls) by their exact sections
GENTLE_NY = 0.5


def rasterize(vertices: np.ndarray, faces: np.ndarray, cs: float, ch: float, walkable: np.ndarray,
              flat: np.ndarray, origin: np.ndarray, shape: tuple[int, int], merge_steps: int,
              rows: tuple[int, int] | None = None):
    """Spans of every (triangle, cell) pair, merged per column (of the rows
    ``[rows[0], rows[1])`` only when given: the same spans there as the whole build's).

    Per (triangle, row) the polygon Q of the triangle inside the row's slab and the
    columns it covers; per (triangle, cell): for gentle triangles the range of their
    plane over the cell's part of Q's bounding box, clipped to Q's y range (exact
    inside the triangle, at most a cell's rise above it at its edges); for steep ones
    the exact range over the clipped polygon's vertices (Q's vertices in the cell and
    the ends of the triangle's sections by the cell's x lines).

    Returns sorted (col, smin, smax, walkable, flat) arrays and the number of
    (triangle, cell) pairs.
    """
    nz, nx = shape
    V = np.asarray(vertices, dtype=np.float64)
    gx = (V[:, 0] - origin[0]) / cs  # grid units: cell j covers [j, j + 1)
    gz = (V[:, 2] - origin[2]) / cs
    gy = V[:, 1] - origin[1]
    f = [np.ascontiguousarray(faces[:, k]) for k in range(3)]
    X = [gx[fk] for fk in f]
    Z = [gz[fk] for fk in f]
    Y = [gy[fk] for fk in f]
    # the plane y = A + B x + C z through each triangle (grid units in x and z)
    e1 = [X[1] - X[0], Z[1] - Z[0], Y[1] - Y[0]]
    e2 = [X[2] - X[0], Z[2] - Z[0], Y[2] - Y[0]]
    n_x = e1[1] * e2[2] - e1[2] * e2[1]  # normal in (x, z, y) order
    n_z = e1[2] * e2[0] - e1[0] * e2[2]
    n_y = e1[0] * e2[1] - e1[1] * e2[0]
    # |n_y| / |n| in world units (the grid scales x and z by 1 / cs)
    # (a zero-area triangle, n = 0, is not gentle: its plane would divide 0 by 0)
    gentle = (n_y != 0) & (np.abs(n_y) >= GENTLE_NY * np.sqrt((n_x * cs) ** 2 + (n_z * cs) ** 2 + n_y * n_y))
    kern = active()
    if kern is not None:  # every triangle's pieces, merged, in one call (geometry/triangle_passes.py)
        return triangle_passes.raster_merge(kern, X, Z, Y, (n_x, n_z, n_y), gentle, walkable, flat, shape, ch, rows,
                            (merge_steps, MAX_HEIGHT_STEPS))
    out = []
    for group in (np.flatnonzero(gentle), np.flatnonzero(~gentle)):
        if len(group) == 0:
            continue
        Xg, Zg, Yg = ([a[group] for a in arr] for arr in (X, Z, Y))
        steep = not gentle[group[0]]
        if steep:
            A = B = C = np.zeros(len(group))
        else:
            ny_ = n_y[group]
            B, C = -n_x[group] / ny_, -n_z[group] / ny_
            A = Yg[0] - B * Xg[0] - C * Zg[0]
        pairs = _rows(Xg, Zg, Yg, nz, nx, rows)
        if steep:
            p, j, smin, smax = _cells_exact(pairs, Xg, Zg, Yg, ch)
        else:
            p, j, smin, smax = _cells_plane(pairs, A, B, C, ch)
        out.append((pairs.row[p] * nx + j, group[pairs.tri[p]], smin, smax))
    if not out:
        return _merge(*(np.zeros(0, dtype=np.int64) for _ in range(5)), merge_steps), 0
    # one group (a terrain: all gentle): its arrays, not copies of them
    col, t_of_cell, smin, smax = out[0] if len(out) == 1 else (np.concatenate(v) for v in zip(*out))
    spans = _merge(col, smin, smax, walkable[t_of_cell], flat[t_of_cell], merge_steps)
    return spans, len(col)


def _merge(col, smin, smax, walk, flat, thr):
    """Merge the overlapping or touching spans of each column (Recast's addSpan).

    The merged span's flags are those of the pieces whose tops lie within ``thr``
    of its top.  One sort of packed int64 keys (column, bottom, top, flags): a
    value sort is several times faster than an argsort.
    """
    if len(col) == 0:
        e = np.zeros(0, dtype=np.int64)
        b = np.zeros(0, dtype=bool)
        return e, e, e, b, b, b
    key = (col.astype(np.int64, copy=False) << 34) | (smin << 18) | (smax << 2) | (walk.astype(np.int64) << 1) | flat
    key.sort()
    col = key >> 34
    smin = (key >> 18) & 0xFFFF
    smax = (key >> 2) & 0xFFFF
    # running top of each column's spans so far: packed so one cumulative max serves
    # every column at once (a new column's keys are all larger than the last one's)
    run = np.maximum.accumulate((col << 17) | smax) & 0x1FFFF
    new = np.empty(len(col), dtype=bool)
    new[:1] = True
    new[1:] = (col[1:] != col[:-1]) | (smin[1:] > run[:-1])
    starts = np.flatnonzero(new)
    ends = np.append(starts[1:], len(col)) - 1
    top = run[ends]  # earlier groups of the column all end below this one's start
    g = np.cumsum(new) - 1
    near = smax >= top[g] - thr

    def any_in_group(flag):
        c = np.cumsum(flag)
        return (c[ends] - c[starts] + flag[starts]) > 0

    walk = (key & 2) > 0
    at_top = smax == top[g]
    return (col[starts], smin[starts], top, any_in_group(walk & near), any_in_group(((key & 1) > 0) & near),
            any_in_group(walk & at_top))


def build_heightfield(vertices: np.ndarray, faces: np.ndarray, cs: float, ch: float, max_slope: float,
                      headroom: float, climb: float, origin_xz=None, shape=None, band_rows: int | None = None,
                      workers: int | None = None) -> Heightfield:
    """Rasterise, merge and filter (see the module docstring).

    ``headroom`` and ``climb`` in metres become ``ceil(headroom / ch)`` and
    ``floor(climb / ch)`` steps, as in Recast.  A grid of more than TILE_COLUMNS
    columns (or any grid, given ``band_rows``) is built in bands of rows on
    ``workers`` processes (default: every core), with the same result
    (tanktool/geometry/tiles.py).
    """
    from .tiles import TILE_COLUMNS, build_tiled

    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    origin, shape = grid_for(vertices, cs, origin_xz, shape)
    if (vertices[:, 1].max() - origin[1]) / ch > MAX_HEIGHT_STEPS:
        raise ArenaError(f"the model is {vertices[:, 1].max() - origin[1]:g} m high: more than "
                         f"{MAX_HEIGHT_STEPS} cell heights of {ch:g} m")
    walk_f, flat_f = walkable_faces(vertices, faces, max_slope)
    climb_steps = int(math.floor(climb / ch + 1e-9))
    head_steps = int(math.ceil(headroom / ch - 1e-9))
    if band_rows is not None or shape[0] * shape[1] > TILE_COLUMNS:
        (col, smin, smax, walk2, flat, top_walk, low), counts = build_tiled(
            vertices, faces, cs, ch, walk_f, flat_f, origin, shape, head_steps, climb_steps, band_rows, workers)
        counts["walkable_faces"] = int(walk_f.sum())
        return Heightfield(origin, float(cs), float(ch), shape, col, smin, smax, walk2, flat, top_walk, counts, low)
    (col, smin, smax, walk, flat, top_walk), pairs = rasterize(vertices, faces, cs, ch, walk_f, flat_f, origin, shape,
                                                               climb_steps)
    walk2, counts, low = filter_spans(col, smin, smax, walk, shape, head_steps, climb_steps)
    counts = {"pairs": pairs, "spans": len(col), "walkable_faces": int(np.count_nonzero(walk_f)),
              "walkable_raw": int(np.count_nonzero(walk)), **counts}
    return Heightfield(origin, float(cs), float(ch), shape, col, smin, smax, walk2, flat, top_walk, counts, low)
