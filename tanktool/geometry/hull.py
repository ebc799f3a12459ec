"""Hull points: the 8 to 16 points that stand for a vehicle against the walls (§3.4.4.2).

The footprint — the model seen from above, in the (x, z) plane — is wrapped in a
convex polygon with N/2 corners, and the polygon is extruded from the model's lowest
to its highest point: N/2 bottom corners then the same N/2 top corners.  With N = 8
the polygon is the minimum-area oriented rectangle; with more points it is a k-gon
built from supporting lines, so every vertex of the model is inside by construction.

A convex polygon here is a list of k outward edge normals at angles θ_j (ascending,
each turn < π) with offsets h(θ_j) = max over the points of n(θ_j)·p, the support
function.  Each edge line touches the point set, so the polygon contains every point
whatever the angles are; choosing the angles only decides the area.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Footprint:
    """A convex footprint polygon in the (x, z) plane.

    Attributes
    ----------
    polygon : (k, 2) counter-clockwise corners (x, z) — counter-clockwise in the
        plane with x right and z up, i.e. turning from +x towards +z
    area : its area, m^2
    convex_area : area of the 2D convex hull of the points, m^2
    """

    polygon: np.ndarray
    area: float
    convex_area: float

    @property
    def ratio(self) -> float:
        return self.area / self.convex_area if self.convex_area > 0 else 1.0


def convex_hull_2d(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise corners of the convex hull of (n, 2) points (Andrew's chain)."""
    pts = np.unique(np.asarray(points, dtype=np.float64), axis=0)
    if len(pts) < 3:
        return pts
    # np.unique sorted by x then y, which is the order the monotone chain needs
    def chain(seq: np.ndarray) -> list[np.ndarray]:
        out: list[np.ndarray] = []
        for p in seq:
            while len(out) >= 2:
                a, b = out[-2], out[-1]
                if (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) <= 0:
                    out.pop()
                else:
                    break
            out.append(p)
        return out

    if len(pts) > 2000:
        # Andrew's loop is Python; thin the input with qhull first when it is large
        from scipy.spatial import ConvexHull

        try:
            pts = pts[np.sort(ConvexHull(pts).vertices)]
        except Exception:
            pass
    lower = chain(pts)
    upper = chain(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def polygon_area(poly: np.ndarray) -> float:
    """Signed area (positive counter-clockwise) of a (k, 2) polygon."""
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def min_width(poly: np.ndarray) -> float:
    """Narrowest extent of a convex polygon: over its edge directions, the largest
    distance of a vertex from the edge's line (rotating calipers, all edges at once)."""
    p = np.asarray(poly, dtype=np.float64)
    e = np.roll(p, -1, axis=0) - p
    L = np.hypot(e[:, 0], e[:, 1])
    ok = L > 0
    if not ok.any():
        return 0.0
    e, a = e[ok] / L[ok, None], p[ok]
    d = np.abs(e[:, None, 0] * (p[None, :, 1] - a[:, None, 1]) - e[:, None, 1] * (p[None, :, 0] - a[:, None, 0]))
    return float(d.max(axis=1).min())


def _support(hull: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """h(θ) = max over hull corners of (cos θ, sin θ)·p, for each θ."""
    n = np.stack([np.cos(theta), np.sin(theta)], axis=-1)
    return (n @ hull.T).max(axis=-1)


def _corners(theta: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Corners where consecutive edge lines n_j·p = h_j and n_{j+1}·p = h_{j+1} meet."""
    t1, t2 = theta, np.roll(theta, -1)
    h1, h2 = h, np.roll(h, -1)
    det = np.sin(t2 - t1)
    x = (h1 * np.sin(t2) - h2 * np.sin(t1)) / det
    y = (h2 * np.cos(t1) - h1 * np.cos(t2)) / det
    return np.column_stack([x, y])


def _area_of(theta: np.ndarray, h: np.ndarray) -> float:
    return polygon_area(_corners(theta, h))


def min_area_rectangle(hull: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Edge angles and offsets of the minimum-area enclosing rectangle.

    One of its sides lies on a hull edge (Freeman & Shapira), so trying each edge
    direction is exact; all directions are tried at once.
    """
    edges = np.roll(hull, -1, axis=0) - hull
    # outward normal of a counter-clockwise edge (dx, dy) is (dy, -dx)
    base = np.arctan2(-edges[:, 0], edges[:, 1])
    cand = base[:, None] + np.arange(4)[None, :] * (np.pi / 2)
    h = _support(hull, cand)
    area = (h[:, 0] + h[:, 2]) * (h[:, 1] + h[:, 3])
    best = int(np.argmin(area))
    return np.unwrap(cand[best]), h[best]


def _edge_removal(hull: np.ndarray, k: int) -> np.ndarray:
    """Angles of a k-gon from the hull's own edges, greedily dropping the cheapest edge.

    Dropping edge j extends its neighbours to their meeting point, adding the
    triangle cut off; the edge whose triangle is smallest goes first.  Edges whose
    neighbours turn π or more cannot be dropped (the polygon would open).
    """
    edges = np.roll(hull, -1, axis=0) - hull
    theta = np.unwrap(np.arctan2(-edges[:, 0], edges[:, 1]))
    h = _support(hull, theta)
    while len(theta) > k:
        m = len(theta)
        prev_t, next_t = np.roll(theta, 1), np.roll(theta, -1)
        # unwrapped angles: the turn from prev to next across j
        turn = np.mod(next_t - prev_t, 2 * np.pi)
        turn[turn == 0] = 2 * np.pi
        ok = turn < np.pi - 1e-9
        cost = np.full(m, np.inf)
        idx = np.flatnonzero(ok)
        if len(idx) == 0:
            break
        before = _corners(theta, h)  # corner j sits between edge j and j+1
        for j in idx:
            # corners j-1 (prev, j) and j (j, j+1) become one: prev x next
            tp, tn = theta[j - 1], theta[(j + 1) % m]
            hp, hn = h[j - 1], h[(j + 1) % m]
            det = np.sin(tn - tp)
            x = (hp * np.sin(tn) - hn * np.sin(tp)) / det
            y = (hn * np.cos(tp) - hp * np.cos(tn)) / det
            a, b = before[j - 1], before[j]
            cost[j] = 0.5 * abs((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]))
        j = int(np.argmin(cost))
        theta = np.delete(theta, j)
        h = np.delete(h, j)
    return theta


def _refine(hull: np.ndarray, theta: np.ndarray, sweeps: int = 6, tries: int = 48) -> np.ndarray:
    """Coordinate descent on the edge angles: turn each edge, keeping it supporting,
    to wherever between its neighbours the polygon's area is least."""
    theta = np.sort(np.mod(theta, 2 * np.pi))
    k = len(theta)
    area = _area_of(theta, _support(hull, theta))
    for _ in range(sweeps):
        improved = False
        for j in range(k):
            lo = theta[j - 1] if j > 0 else theta[-1] - 2 * np.pi
            hi = theta[j + 1] if j < k - 1 else theta[0] + 2 * np.pi
            cand = np.linspace(lo, hi, tries + 2)[1:-1]
            # the neighbours' turn must stay below π on both sides
            cand = cand[(cand - lo < np.pi - 1e-6) & (hi - cand < np.pi - 1e-6)]
            if len(cand) == 0:
                continue
            trial = np.repeat(theta[None], len(cand), axis=0)
            trial[:, j] = cand
            hs = _support(hull, trial)
            areas = np.array([_area_of(t, hh) for t, hh in zip(trial, hs)])
            best = int(np.argmin(areas))
            if areas[best] < area * (1 - 1e-12):
                theta = trial[best]
                area = areas[best]
                improved = True
        if not improved:
            break
    return theta


def footprint_polygon(points_xz: np.ndarray, corners: int) -> Footprint:
    """The footprint polygon of (n, 2) points (x, z) with ``corners`` corners (>= 4).

    4 corners: the minimum-area oriented rectangle.  More: the greedy edge-removal
    k-gon, then refined; a convex hull with no more corners than asked is used as it
    is.  Every point is inside in every case.
    """
    if corners < 4:
        raise ValueError("a footprint needs at least 4 corners")
    hull = convex_hull_2d(points_xz)
    if len(hull) < 3:
        # a line or a point seen from above: pad to a thin rectangle around it
        pts = np.asarray(points_xz, dtype=np.float64)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        pad = max(1e-3, 1e-3 * float((hi - lo).max()))
        lo, hi = lo - pad, hi + pad
        rect = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
        return Footprint(rect, polygon_area(rect), polygon_area(rect))
    convex_area = polygon_area(hull)
    if corners == 4 or len(hull) < 4:
        theta, h = min_area_rectangle(hull)
        poly = _corners(theta, h)
    elif len(hull) <= corners:
        poly = hull
    else:
        theta = _edge_removal(hull, corners)
        if len(theta) > corners:  # could not drop more edges (never for convex input)
            theta, h = min_area_rectangle(hull)
        else:
            theta = _refine(hull, theta)
            h = _support(hull, theta)
        poly = _corners(np.asarray(theta), h)
    poly = _outset(poly)
    return Footprint(poly, polygon_area(poly), convex_area)


#: how far (m) the footprint's edges are pushed out: more than hull.txt's rounding to
#: 0.1 mm can move an edge inwards (0.5e-4 * sqrt(2)), so the written hull still encloses
MARGIN = 1e-4


def _outset(poly: np.ndarray, margin: float = MARGIN) -> np.ndarray:
    """Move every edge of a convex polygon outwards by ``margin``."""
    if polygon_area(poly) < 0:
        poly = poly[::-1]
    e = np.roll(poly, -1, axis=0) - poly
    keep = np.hypot(e[:, 0], e[:, 1]) > 1e-12
    poly, e = poly[keep], e[keep]
    theta = np.arctan2(-e[:, 0], e[:, 1])
    h = poly[:, 0] * np.cos(theta) + poly[:, 1] * np.sin(theta) + margin
    # corner j of _corners joins edge j and j+1; the input's corner j+1 does
    return np.roll(_corners(theta, h), 1, axis=0)


def hull_points(vertices: np.ndarray, count: int = 16) -> tuple[np.ndarray, Footprint]:
    """The ``count`` hull points (8..16, even) of (n, 3) vertices, vehicle frame.

    Returns ((2k, 3) points: k bottom corners at the lowest y then the same k corners
    at the highest y, and the footprint).  ``count`` is an upper bound: a footprint
    whose convex hull has fewer corners than count/2 uses those corners.
    """
    if not (8 <= count <= 16) or count % 2:
        raise ValueError(f"hull points must be an even number from 8 to 16, got {count}")
    v = np.asarray(vertices, dtype=np.float64)
    fp = footprint_polygon(v[:, [0, 2]], count // 2)
    y0, y1 = float(v[:, 1].min()), float(v[:, 1].max())
    k = len(fp.polygon)
    bottom = np.column_stack([fp.polygon[:, 0], np.full(k, y0), fp.polygon[:, 1]])
    top = np.column_stack([fp.polygon[:, 0], np.full(k, y1), fp.polygon[:, 1]])
    return np.vstack([bottom, top]), fp


def points_in_prism(hull: np.ndarray, points: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """(n,) bool: is each (x, y, z) point inside the extruded footprint of ``hull``?

    ``hull`` is a hull.txt point list: k bottom corners then k top corners.
    """
    hull = np.asarray(hull, dtype=np.float64)
    k = len(hull) // 2
    poly = hull[:k][:, [0, 2]]
    if polygon_area(poly) < 0:
        poly = poly[::-1]
    p = np.asarray(points, dtype=np.float64)
    a = poly
    b = np.roll(poly, -1, axis=0)
    e = b - a
    cross = e[None, :, 0] * (p[:, None, 2] - a[None, :, 1]) - e[None, :, 1] * (p[:, None, 0] - a[None, :, 0])
    lens = np.linalg.norm(e, axis=1)
    inside_xz = (cross / lens[None] >= -tol).all(axis=1)
    ylo, yhi = hull[:, 1].min(), hull[:, 1].max()
    return inside_xz & (p[:, 1] >= ylo - tol) & (p[:, 1] <= yhi + tol)
