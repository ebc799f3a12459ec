"""Free space and valid nodes of the 2002 grid, from the walls (out of navgrid.py).

**Free space.**  Orient every wall so that its normal (the side ``Direction`` picks)
is on its left; the auxiliary rectangle is not a wall.  Walking along any line from
outside the arena, count +1 for each wall crossed along its normal (entering free
space) and -1 for each crossed against it.  A point is in free space when this count
is positive walking from *both* ends of the line up to the point (the 2002 paper's
two pointers walking a line's crossing list from both ends).  For walls made of closed
loops with consistent normals -- the walls of any solid sliced at a height -- the count
is the winding number of the oriented walls: 1 in free space, 0 in solids and outside,
the same along every line, and shared edges of touching solids (opposite normals)
cancel.  :func:`open_ends` lists the vertices where that fails (loose ends, flipped
normals); only near those can the two classifiers below disagree.

A node is **valid** when it is in free space and its distance to every wall is at
least the clearance (and not zero: a node on a wall is never valid).

Two classifiers, which agree exactly on every node farther than rounding from a wall:

* :func:`classify_reference`, the 2002 method: the line through each node and the
  arena origin (the auxiliary rectangle's low corner), its crossings with every wall
  sorted into a list and walked from both ends; clearance by brute force.
* :func:`classify`, the vectorised default: the same count along each grid row (one
  crossing list per row, a cumulative sum per node), and clearance by rasterising each
  wall's capsule row by row: nodes well inside it are marked at once, the few near
  its edge are decided by the same exact distance kernel the reference uses.  Crossings use a half-open rule on the row's z (an end point exactly
  on the row counts as above it), so a line through a vertex is never counted twice.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..formats.walls_txt import WallList
from ..geometry.segments import point_segment_dist2


def node_coords(origin: float, cell: float, n: int) -> np.ndarray:
    """Coordinates of n node centres along one axis.  Both classifiers use these."""
    return origin + (np.arange(n) + 0.5) * cell


def on_wall_tolerance(bounds: np.ndarray) -> float:
    """Nodes closer than this to a wall count as on it (never valid)."""
    b = np.asarray(bounds, dtype=np.float64).reshape(2, 2)
    return 1e-9 * max(1.0, float(np.max(np.abs(b))))


def _oriented(walls: WallList) -> tuple[np.ndarray, np.ndarray]:
    """Wall end points (A, B) swapped where needed so free space is on the left of A->B."""
    s = walls.segments
    flip = walls.direction < 0
    A = np.where(flip[:, None], s[:, 1], s[:, 0])
    B = np.where(flip[:, None], s[:, 0], s[:, 1])
    return A, B


def open_ends(walls: WallList) -> np.ndarray:
    """(k, 2) vertices where the oriented walls do not close up.

    With free space on the left of every wall, each vertex of a closed, consistently
    oriented wall set has as many walls leaving it as arriving.  Zero-length walls
    are ignored.
    """
    A, B = _oriented(walls)
    keep = np.any(A != B, axis=1)
    A, B = A[keep], B[keep]
    if len(A) == 0:
        return np.zeros((0, 2))
    pts = np.concatenate([A, B])
    verts, inv = np.unique(pts, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    bal = np.bincount(inv[: len(A)], minlength=len(verts)) - np.bincount(inv[len(A):], minlength=len(verts))
    return verts[bal != 0]


# ================================================================ free space
def row_crossings(A: np.ndarray, B: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Crossings of oriented walls with the horizontal lines ``z`` (ascending).

    Returns ``(row, x, sign)``: for each crossing, the index into ``z``, where it
    crosses, and +1 when walking +x crosses the wall along its normal.  Half-open
    rule: a wall crosses line z when exactly one end point has ``z_end > z``.
    """
    lo = np.minimum(A[:, 1], B[:, 1])
    hi = np.maximum(A[:, 1], B[:, 1])
    # rows with lo <= z < hi, i.e. exactly one end strictly above
    r0 = np.searchsorted(z, lo, side="left")
    r1 = np.searchsorted(z, hi, side="left")
    cnt = np.maximum(r1 - r0, 0)
    w = np.repeat(np.arange(len(A)), cnt)
    row = np.repeat(r0, cnt) + _ramp(cnt)
    a, b, zz = A[w], B[w], z[row]
    x = a[:, 0] + (zz - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    # free space on the left of a->b: going up (b above) the left is -x, so walking +x
    # crosses against the normal
    sign = np.where(b[:, 1] > zz, -1, 1).astype(np.int32)
    return row, x, sign


def free_space(walls: WallList, origin: np.ndarray, cell: float, shape: tuple[int, int], rows: slice = slice(None)) -> np.ndarray:
    """Free-space mask of the nodes of ``rows`` by the row-scan count (from both ends)."""
    nz, nx = shape
    z = node_coords(origin[1], cell, nz)[rows]
    x_nodes = node_coords(origin[0], cell, nx)
    A, B = _oriented(walls)
    row, x, sign = row_crossings(A, B, z)
    # +sign for every node strictly right of the crossing: scatter at the first such
    # node and take a running sum along the row
    j = np.searchsorted(x_nodes, x, side="right")
    acc = np.bincount(row * (nx + 1) + j, weights=sign, minlength=len(z) * (nx + 1))
    acc = acc.reshape(len(z), nx + 1).astype(np.int32)
    left = np.cumsum(acc, axis=1)
    total = left[:, -1:]
    left = left[:, :nx]
    # walking in from the +x end the count is sum(-sign) over crossings right of the node
    right = left - total
    return (left > 0) & (right > 0)


# ================================================================= clearance
def _ramp(cnt: np.ndarray) -> np.ndarray:
    """0, 1, .., cnt[0]-1, 0, 1, .., cnt[1]-1, ...: positions inside repeated blocks."""
    total = int(cnt.sum())
    return np.arange(total) - np.repeat(np.cumsum(cnt) - cnt, cnt)


def _capsule_pairs(A: np.ndarray, B: np.ndarray, R: float, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(wall, row) for every row whose line may meet the wall's capsule of radius R."""
    zlo = np.minimum(A[:, 1], B[:, 1]) - R
    zhi = np.maximum(A[:, 1], B[:, 1]) + R
    r0 = np.searchsorted(z, zlo, side="left")
    r1 = np.searchsorted(z, zhi, side="right")
    cnt = np.maximum(r1 - r0, 0)
    return np.repeat(np.arange(len(A)), cnt), np.repeat(r0, cnt) + _ramp(cnt)


def _capsule_chords(a: np.ndarray, b: np.ndarray, zz: np.ndarray, R: float) -> tuple[np.ndarray, np.ndarray]:
    """x-interval [lo, hi] where the line z = zz meets the capsule of radius R around
    segment a-b (all arrays per pair); lo > hi when it misses."""
    lo = np.full(len(zz), np.inf)
    hi = np.full(len(zz), -np.inf)
    for p in (a, b):  # end discs
        dz = zz - p[:, 1]
        h2 = R * R - dz * dz
        ok = h2 >= 0
        h = np.sqrt(np.where(ok, h2, 0.0))
        lo = np.where(ok, np.minimum(lo, p[:, 0] - h), lo)
        hi = np.where(ok, np.maximum(hi, p[:, 0] + h), hi)
    # the band between: 0 <= s <= 1 along the wall and |u| <= R across it, both linear in x:
    # s = c1 + (x - ax) dx / L2,  u = c2 - (x - ax) dz / L
    d = b - a
    L2 = d[:, 0] ** 2 + d[:, 1] ** 2
    L = np.sqrt(L2)
    with np.errstate(divide="ignore", invalid="ignore"):
        c1 = (zz - a[:, 1]) * d[:, 1] / L2
        c2 = (zz - a[:, 1]) * d[:, 0] / L
        s_lo = a[:, 0] + (0 - c1) * L2 / d[:, 0]
        s_hi = a[:, 0] + (1 - c1) * L2 / d[:, 0]
        u_lo = a[:, 0] + (R - c2) * L / -d[:, 1]
        u_hi = a[:, 0] + (-R - c2) * L / -d[:, 1]
    s_a, s_b = np.minimum(s_lo, s_hi), np.maximum(s_lo, s_hi)
    s_all = (c1 >= 0) & (c1 <= 1)
    s_flat = d[:, 0] == 0
    s_a = np.where(s_flat, np.where(s_all, -np.inf, np.inf), s_a)
    s_b = np.where(s_flat, np.where(s_all, np.inf, -np.inf), s_b)
    u_a, u_b = np.minimum(u_lo, u_hi), np.maximum(u_lo, u_hi)
    u_all = np.abs(c2) <= R
    u_flat = d[:, 1] == 0
    u_a = np.where(u_flat, np.where(u_all, -np.inf, np.inf), u_a)
    u_b = np.where(u_flat, np.where(u_all, np.inf, -np.inf), u_b)
    band_lo = np.maximum(s_a, u_a)
    band_hi = np.minimum(s_b, u_b)
    band = (L > 0) & (band_lo <= band_hi)
    lo = np.where(band, np.minimum(lo, band_lo), lo)
    hi = np.where(band, np.maximum(hi, band_hi), hi)
    return lo, hi


def too_close(
    segments: np.ndarray, origin: np.ndarray, cell: float, shape: tuple[int, int], clearance: float,
    rows: slice = slice(None), tol: float = 0.0,
) -> np.ndarray:
    """Nodes of ``rows`` whose distance to some wall is < clearance (or <= tol).

    Exact with respect to the distance kernel: on each row, the nodes well inside a
    wall's capsule (its chord for a radius shrunk by 1e-7, far beyond rounding) are
    marked at once; the few nodes near the chord's ends (the chord for a radius grown
    a hair, widened by one node each side) are decided by the kernel itself.
    """
    nz, nx = shape
    z = node_coords(origin[1], cell, nz)[rows]
    x_nodes = node_coords(origin[0], cell, nx)
    out = np.zeros((len(z), nx), dtype=bool)
    seg = np.asarray(segments, dtype=np.float64).reshape(-1, 2, 2)
    R = max(float(clearance), tol)
    if len(seg) == 0 or len(z) == 0:
        return out
    w, row = _capsule_pairs(seg[:, 0], seg[:, 1], R * (1 + 1e-9) + 1e-7 * cell, z)
    a, b, zz = seg[w, 0], seg[w, 1], z[row]
    olo, ohi = _capsule_chords(a, b, zz, R * (1 + 1e-9) + 1e-7 * cell)
    ilo, ihi = _capsule_chords(a, b, zz, R * (1 - 1e-7))
    j0 = np.clip(np.searchsorted(x_nodes, olo, side="left") - 1, 0, nx)
    j1 = np.clip(np.searchsorted(x_nodes, ohi, side="right") + 1, 0, nx)
    j1 = np.maximum(j1, j0)
    # interior [k0, k1): nodes inside the shrunk chord, clipped into [j0, j1]
    k0 = np.clip(np.searchsorted(x_nodes, ilo, side="left"), j0, j1)
    k1 = np.clip(np.searchsorted(x_nodes, ihi, side="right"), j0, j1)
    inner = k1 > k0
    k0 = np.where(inner, k0, j1)
    k1 = np.where(inner, k1, j1)
    # mark interiors with a running sum of +1/-1 per row
    if inner.any():
        m = nx + 1
        acc = np.bincount(row[inner] * m + k0[inner], minlength=len(z) * m)
        acc -= np.bincount(row[inner] * m + k1[inner], minlength=len(z) * m)
        out |= np.cumsum(acc.reshape(len(z), m), axis=1)[:, :nx] > 0
    # kernel on the two edge pieces [j0, k0) and [k1, j1)
    for lo_, hi_ in ((j0, k0), (k1, j1)):
        cnt = np.maximum(hi_ - lo_, 0)
        sel = cnt > 0
        if not sel.any():
            continue
        cnt_s = cnt[sel]
        ww = np.repeat(w[sel], cnt_s)
        rr = np.repeat(row[sel], cnt_s)
        jj = np.repeat(lo_[sel], cnt_s) + _ramp(cnt_s)
        p = np.stack([x_nodes[jj], z[rr]], axis=1)
        d2 = point_segment_dist2(p, seg[ww, 0], seg[ww, 1])
        hit = (d2 < clearance * clearance) | (d2 <= tol * tol)
        out[rr[hit], jj[hit]] = True
    return out


# ================================================================ classifiers
def classify(
    walls: WallList, origin: np.ndarray, cell: float, shape: tuple[int, int], clearance: float,
    progress: Callable[[int], None] | None = None, band_nodes: int = 1_000_000,
) -> np.ndarray:
    """Valid-node mask (the fast default): row-scan free space minus the wall capsules.

    Rows are processed in bands of about ``band_nodes`` nodes; ``progress(rows_done)``
    is called after each band.
    """
    nz, nx = shape
    tol = on_wall_tolerance(walls.bounds)
    valid = np.empty(shape, dtype=bool)
    step = max(1, band_nodes // max(nx, 1))
    for r0 in range(0, nz, step):
        rows = slice(r0, min(nz, r0 + step))
        valid[rows] = free_space(walls, origin, cell, shape, rows) & ~too_close(
            walls.segments, origin, cell, shape, clearance, rows, tol
        )
        if progress is not None:
            progress(rows.stop - rows.start)
    return valid
