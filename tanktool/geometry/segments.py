"""Vectorised kernels on 2D segments, points and axis-aligned boxes in the (x, z) plane.

Every function takes numpy arrays that broadcast against each other and returns
arrays; a segment is given by its two end points ``a`` and ``b`` (``(..., 2)`` each),
a box by ``lo`` and ``hi`` corners.  The quadtree, the navigation grid and the
brute-force checks in the tests all call these same kernels, so that "exact" means
the same floating-point answer everywhere: a broad phase may only drop candidates
these kernels would reject.
"""

from __future__ import annotations

import numpy as np


def _xz(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    v = np.asarray(v, dtype=np.float64)
    return v[..., 0], v[..., 1]


def cross2(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """z-component of the 2D cross product ``u x v``, shape broadcast(u, v)[:-1]."""
    ux, uz = _xz(u)
    vx, vz = _xz(v)
    return ux * vz - uz * vx


def orient(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Signed doubled area of triangle (a, b, c): > 0 when c is left of a -> b."""
    ax, az = _xz(a)
    bx, bz = _xz(b)
    cx, cz = _xz(c)
    return (bx - ax) * (cz - az) - (bz - az) * (cx - ax)


def point_segment_dist2(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Squared distance from points ``p`` to closed segments ``a b`` (broadcast).

    Zero-length segments are points.  Shapes: p, a, b ``(..., 2)`` -> ``(...)``.
    """
    px, pz = _xz(p)
    ax, az = _xz(a)
    bx, bz = _xz(b)
    dx = bx - ax
    dz = bz - az
    wx = px - ax
    wz = pz - az
    len2 = dx * dx + dz * dz
    with np.errstate(invalid="ignore", divide="ignore"):
        t = (wx * dx + wz * dz) / len2
    t = np.where(len2 > 0, np.clip(t, 0.0, 1.0), 0.0)
    ex = wx - t * dx
    ez = wz - t * dz
    return ex * ex + ez * ez


def point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from points to closed segments (broadcast), ``(...)``."""
    return np.sqrt(point_segment_dist2(p, a, b))


def _on_bbox(a_x, a_z, b_x, b_z, c_x, c_z):
    # c is known to be collinear with a-b: it lies on the segment iff inside its bbox
    return (
        (np.minimum(a_x, b_x) <= c_x) & (c_x <= np.maximum(a_x, b_x))
        & (np.minimum(a_z, b_z) <= c_z) & (c_z <= np.maximum(a_z, b_z))
    )


def segments_intersect(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """True where closed segment ``a b`` crosses or touches closed segment ``c d``.

    Orientation tests with the collinear and touching cases handled explicitly
    (end point on the other segment, overlapping collinear segments).
    """
    ax, az = _xz(a)
    bx, bz = _xz(b)
    cx, cz = _xz(c)
    dx, dz = _xz(d)
    d1 = (dx - cx) * (az - cz) - (dz - cz) * (ax - cx)  # a against c->d
    d2 = (dx - cx) * (bz - cz) - (dz - cz) * (bx - cx)  # b against c->d
    d3 = (bx - ax) * (cz - az) - (bz - az) * (cx - ax)  # c against a->b
    d4 = (bx - ax) * (dz - az) - (bz - az) * (dx - ax)  # d against a->b
    proper = (((d1 > 0) & (d2 < 0)) | ((d1 < 0) & (d2 > 0))) & (
        ((d3 > 0) & (d4 < 0)) | ((d3 < 0) & (d4 > 0))
    )
    touch = (
        ((d1 == 0) & _on_bbox(cx, cz, dx, dz, ax, az))
        | ((d2 == 0) & _on_bbox(cx, cz, dx, dz, bx, bz))
        | ((d3 == 0) & _on_bbox(ax, az, bx, bz, cx, cz))
        | ((d4 == 0) & _on_bbox(ax, az, bx, bz, dx, dz))
    )
    return proper | touch


def segment_segment_dist2(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Squared distance between closed segments ``a b`` and ``c d`` (broadcast)."""
    m = np.minimum(
        np.minimum(point_segment_dist2(a, c, d), point_segment_dist2(b, c, d)),
        np.minimum(point_segment_dist2(c, a, b), point_segment_dist2(d, a, b)),
    )
    return np.where(segments_intersect(a, b, c, d), 0.0, m)


def point_box_dist2(p: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Squared distance from points to closed axis-aligned boxes (0 inside)."""
    px, pz = _xz(p)
    lx, lz = _xz(lo)
    hx, hz = _xz(hi)
    ex = np.maximum(np.maximum(lx - px, px - hx), 0.0)
    ez = np.maximum(np.maximum(lz - pz, pz - hz), 0.0)
    return ex * ex + ez * ez


def clip_segment_box(
    a: np.ndarray, b: np.ndarray, lo: np.ndarray, hi: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Liang-Barsky clipping of segments ``a b`` against closed boxes ``[lo, hi]``.

    Returns ``(hit, t0, t1)``: ``hit`` is True where the segment meets the box
    (touching counts), and then ``a + t (b - a)`` for ``t`` in ``[t0, t1]`` is the
    part inside.  A zero-length segment hits when its point is inside the box.
    """
    ax, az = _xz(a)
    bx, bz = _xz(b)
    lx, lz = _xz(lo)
    hx, hz = _xz(hi)
    shape = np.broadcast_shapes(ax.shape, bx.shape, lx.shape, hx.shape)
    t0 = np.zeros(shape)
    t1 = np.ones(shape)
    hit = np.ones(shape, dtype=bool)
    for p0, p1, lo_, hi_ in ((ax, bx, lx, hx), (az, bz, lz, hz)):
        dp = np.broadcast_to(p1 - p0, shape)
        p0b = np.broadcast_to(p0, shape)
        flat = dp == 0
        # parallel to this slab: inside it or not at all
        hit &= ~flat | ((p0b >= lo_) & (p0b <= hi_))
        with np.errstate(divide="ignore", invalid="ignore"):
            ta = (lo_ - p0b) / dp
            tb = (hi_ - p0b) / dp
        enter = np.where(flat, -np.inf, np.minimum(ta, tb))
        leave = np.where(flat, np.inf, np.maximum(ta, tb))
        t0 = np.maximum(t0, enter)
        t1 = np.minimum(t1, leave)
    hit &= t0 <= t1
    return hit, t0, t1


def segment_hits_box(a: np.ndarray, b: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """True where segment ``a b`` meets the closed box ``[lo, hi]`` (broadcast)."""
    return clip_segment_box(a, b, lo, hi)[0]


def segment_lengths(segments: np.ndarray) -> np.ndarray:
    """Lengths of segments ``(n, 2, 2) -> (n,)``."""
    d = np.asarray(segments, dtype=np.float64)[:, 1] - np.asarray(segments, dtype=np.float64)[:, 0]
    return np.hypot(d[:, 0], d[:, 1])


def faces_above(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray, bucket: float = 8.0) -> np.ndarray:
    """For each point (k, 3) ``[x, y, z]``: how many faces a vertical ray from it
    upwards crosses (odd: the point lies inside a closed solid).

    A face counts when the point's (x, z) lies inside its projection (half-open
    edges, so a ray through a shared edge counts once) and the face is above the point
    there.  Vertical faces are never crossed.  Faces are sorted into square buckets of
    ``bucket`` metres by their extent, so each point tests only the faces over it.
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if 0 < len(p) <= FEW_POINTS and len(faces):
        return _faces_above_few(p, np.asarray(vertices, dtype=np.float64), np.asarray(faces), bucket)
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)]
    out = np.zeros(len(p), dtype=np.int64)
    if len(p) == 0 or len(tri) == 0:
        return out
    ax, ay, az = tri[:, 0, 0], tri[:, 0, 1], tri[:, 0, 2]
    bx, by, bz = tri[:, 1, 0], tri[:, 1, 1], tri[:, 1, 2]
    cx, cy, cz = tri[:, 2, 0], tri[:, 2, 1], tri[:, 2, 2]
    det = (bx - ax) * (cz - az) - (cx - ax) * (bz - az)
    lo = np.minimum(np.minimum(tri[:, 0], tri[:, 1]), tri[:, 2])[:, [0, 2]]
    hi = np.maximum(np.maximum(tri[:, 0], tri[:, 1]), tri[:, 2])[:, [0, 2]]
    origin = lo.min(axis=0)
    b0 = np.floor((lo - origin) / bucket).astype(np.int64)
    b1 = np.floor((hi - origin) / bucket).astype(np.int64)
    n = (b1 - b0 + 1)
    keep = (det != 0) & (n[:, 0] * n[:, 1] <= 4096)  # a face over 4096 buckets is tested by every point
    big = np.flatnonzero((det != 0) & ~keep)
    f = np.flatnonzero(keep)
    cnt = n[f, 0] * n[f, 1]
    owner = np.repeat(f, cnt)
    k = np.arange(len(owner)) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    bi = b0[owner, 0] + k % n[owner, 0]
    bj = b0[owner, 1] + k // n[owner, 0]
    width = int(b1[:, 0].max()) + 2 if len(b1) else 1
    key = bj * width + bi
    order = np.argsort(key, kind="stable")
    key, owner = key[order], owner[order]
    pb = np.floor((p[:, [0, 2]] - origin) / bucket).astype(np.int64)
    for m, (x, y, z) in enumerate(p):
        kk = pb[m, 1] * width + pb[m, 0]
        a, b = np.searchsorted(key, kk), np.searchsorted(key, kk, side="right")
        cand = np.concatenate([owner[a:b], big]) if (pb[m] >= 0).all() and pb[m, 0] < width else big
        if len(cand) == 0:
            continue
        out[m] = _above_count((x, y, z), cand, (ax, ay, az, bx, by, bz, cx, cy, cz), det)
    return out


def _above_count(point: tuple, cand: np.ndarray, corners: tuple, det: np.ndarray) -> int:
    """How many of the candidate faces (corner coordinate arrays ax..cz) lie above
    ``point`` (x, y, z): the point's (x, z) inside the face's projection, the face's
    height there above y."""
    x, y, z = point
    ax, ay, az, bx, by, bz, cx, cy, cz = (c[cand] for c in corners)
    dd = det[cand]
    u = ((x - ax) * (cz - az) - (cx - ax) * (z - az)) / dd
    v = ((bx - ax) * (z - az) - (x - ax) * (bz - az)) / dd
    inside = (u >= 0) & (v >= 0) & (u + v < 1)
    h = ay + u * (by - ay) + v * (cy - ay)
    return int(np.count_nonzero(inside & (h > y)))


#: up to this many points faces_above scans the faces a block at a time (no bucket index)
FEW_POINTS = 32
#: faces per block of that scan
FEW_BLOCK = 1 << 17


def _faces_above_few(p: np.ndarray, vertices: np.ndarray, faces: np.ndarray, bucket: float) -> np.ndarray:
    """faces_above for a few points (the report asks for one a surface): the same
    candidates -- faces whose buckets cover the point's, and those over 4096 buckets --
    and the same test, a block of faces at a time.  The bucket index over the whole
    model took ~140 bytes a face (0.55 GB on a 2 km terrain) for a handful of rays."""
    origin = np.full(2, np.inf)
    for a in range(0, len(faces), FEW_BLOCK):   # the buckets' origin: the faces' lowest corner
        origin = np.minimum(origin, vertices[faces[a:a + FEW_BLOCK]][:, :, [0, 2]].min(axis=(0, 1)))
    pb = np.floor((p[:, [0, 2]] - origin) / bucket).astype(np.int64)
    out = np.zeros(len(p), dtype=np.int64)
    for a in range(0, len(faces), FEW_BLOCK):
        tri = vertices[faces[a:a + FEW_BLOCK]]
        ax, ay, az = tri[:, 0, 0], tri[:, 0, 1], tri[:, 0, 2]
        bx, by, bz = tri[:, 1, 0], tri[:, 1, 1], tri[:, 1, 2]
        cx, cy, cz = tri[:, 2, 0], tri[:, 2, 1], tri[:, 2, 2]
        det = (bx - ax) * (cz - az) - (cx - ax) * (bz - az)
        b0 = np.floor((np.minimum(np.minimum(tri[:, 0], tri[:, 1]), tri[:, 2])[:, [0, 2]] - origin)
                      / bucket).astype(np.int64)
        b1 = np.floor((np.maximum(np.maximum(tri[:, 0], tri[:, 1]), tri[:, 2])[:, [0, 2]] - origin)
                      / bucket).astype(np.int64)
        n = b1 - b0 + 1
        small = n[:, 0] * n[:, 1] <= 4096
        for m, (x, y, z) in enumerate(p):
            covers = (b0 <= pb[m]).all(axis=1) & (pb[m] <= b1).all(axis=1)
            cand = np.flatnonzero((det != 0) & (~small | covers))
            if len(cand) == 0:
                continue
            out[m] += _above_count((x, y, z), cand, (ax, ay, az, bx, by, bz, cx, cy, cz), det)
    return out
