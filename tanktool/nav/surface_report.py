"""What an arena's walkable surface left out, and why: the import report's numbers.

* too steep: upward faces steeper than the maximum slope (and not walls: within
  80 degrees of horizontal), their area seen from above;
* too little headroom: walkable spans with less than the headroom above them;
* unreachable: walkable surfaces not connected to the played region;
* too small for a tank: parts of the played region no tank footprint (the largest
  bundled vehicle's) can ever cover.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .walkable import Surface, WalkableParams

#: areas under this (m^2) are not worth a line of the report
MIN_REPORTED = 1.0
#: faces steeper than this are walls, not slopes (n_y below cos 80 degrees)
WALL_NY = math.cos(math.radians(80.0))


@dataclass
class LeftOut:
    reason: str
    area: float  # m^2
    count: int = 0  # separate surfaces (unreachable) or faces (too steep)
    where: tuple[float, float] | None = None
    y: float | None = None

    def describe(self) -> str:
        at = f" near ({self.where[0]:.1f}, {self.where[1]:.1f})" if self.where is not None else ""
        height = f" at y {self.y:.2f}" if self.y is not None else ""
        if self.reason == "unreachable":
            return f"{self.area:,.0f} m^2 unreachable ({self.count} surface{'s' if self.count != 1 else ''}; largest{height}{at})"
        return f"{self.area:,.0f} m^2 {self.reason}{at}"


def steep_faces(vertices: np.ndarray, faces: np.ndarray, max_slope: float) -> tuple[np.ndarray, np.ndarray]:
    """(indices, projected areas) of upward faces too steep to drive on but not walls.

    A block of FACE_BLOCK faces at a time: the whole model's corners and normals took
    ~170 bytes a face of temporaries (0.35 GB on a 2 km terrain); each face's arithmetic
    is the same, so are the results."""
    from ..geometry.heightfield import FACE_BLOCK

    cos_max = math.cos(math.radians(max_slope))
    sels, areas = [], []
    for a in range(0, max(len(faces), 1), FACE_BLOCK):   # one (empty) block for no faces
        tri = vertices[faces[a:a + FACE_BLOCK]]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        norm = np.linalg.norm(n, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            ny = np.where(norm > 0, n[:, 1] / norm, 0.0)
        sel = np.flatnonzero((ny > WALL_NY) & (ny <= cos_max))
        sels.append(sel + a)
        areas.append(0.5 * n[sel, 1])
    return np.concatenate(sels), np.concatenate(areas)


def _spot(points: np.ndarray, weights: np.ndarray | None = None) -> tuple[float, float] | None:
    """A representative point of a set: the member nearest their weighted centre."""
    if len(points) == 0:
        return None
    c = np.average(points, axis=0, weights=weights)
    k = int(np.argmin(((points - c) ** 2).sum(axis=1)))
    return float(points[k, 0]), float(points[k, 1])


def left_out(surface: Surface, vertices: np.ndarray, faces: np.ndarray, params: WalkableParams,
             radius: float) -> list[LeftOut]:
    """Every reason with a non-zero area (see the module docstring)."""
    hf = surface.hf
    cell2 = hf.cs * hf.cs
    nz, nx = hf.shape
    out: list[LeftOut] = []

    def centres(col):
        i, j = np.divmod(col, nx)
        return np.stack([hf.origin[0] + (j + 0.5) * hf.cs, hf.origin[2] + (i + 0.5) * hf.cs], axis=1)

    sel, area = steep_faces(vertices, faces, params.max_slope)
    if len(sel) and area.sum() >= MIN_REPORTED:
        c = vertices[faces[sel]].mean(axis=1)[:, [0, 2]]
        out.append(LeftOut(f"too steep (over {params.max_slope:g} deg)", float(area.sum()), len(sel), _spot(c, area)))
    low = low_headroom(surface, vertices, faces)
    if low.sum() * cell2 >= MIN_REPORTED:
        out.append(LeftOut(f"under too little headroom (below {params.headroom:g} m)", float(low.sum() * cell2),
                           int(low.sum()), _spot(centres(hf.col[low]))))
    lost = unreachable(surface, radius, vertices, faces)
    if lost.sum() * cell2 >= MIN_REPORTED:
        labels, sizes = np.unique(surface.region[lost], return_counts=True)
        big = labels[int(np.argmax(sizes))]
        m = surface.region == big
        out.append(LeftOut("unreachable", float(lost.sum() * cell2), len(labels), _spot(centres(surface.col[m])),
                           float(np.median(surface.y[m]))))
    small = too_small(surface, radius)
    if small.sum() * cell2 >= MIN_REPORTED:
        out.append(LeftOut(f"too small for a tank (footprint radius {radius:.2f} m)", float(small.sum() * cell2),
                           int(small.sum()), _spot(centres(surface.col[small]))))
    return out


#: at most this many spans get the inside-a-solid test (a sample beyond)
MAX_PARITY_TESTS = 4000


def _remembered(surface: Surface, key: tuple, model: tuple, work: Callable[[], np.ndarray]) -> np.ndarray:
    """``work()`` once per surface, key and model (the report and the picture both ask,
    with the same arrays): a copy of the remembered mask.  The model's arrays are kept
    with it, so their ids in the key cannot be taken by other arrays meanwhile."""
    key = _key(key, model)
    if key not in surface.derived:
        surface.derived[key] = (work(), model)
    return surface.derived[key][0].copy()


def _key(key: tuple, model: tuple) -> tuple:
    """Where :func:`_remembered` keeps ``key``'s answer for the model's arrays."""
    return (*key, *(id(a) for a in model))


def low_headroom(surface: Surface, vertices: np.ndarray | None = None, faces: np.ndarray | None = None) -> np.ndarray:
    """Spans (of the heightfield) the headroom filter took away next to the played
    region: a tank would drive there but for the ceiling.  Given the model, spans
    inside a closed solid (the floor under a box or a ramp's wedge, which has no
    headroom either) are not counted."""
    return _remembered(surface, ("low_headroom",), (vertices, faces),
                       lambda: _low_headroom(surface, vertices, faces))


def _low_headroom(surface: Surface, vertices: np.ndarray | None, faces: np.ndarray | None) -> np.ndarray:
    from ..geometry.heightfield import neighbour_columns

    hf = surface.hf
    low = np.flatnonzero(hf.low_headroom)
    out = np.zeros(len(hf.col), dtype=bool)
    if len(low) == 0 or not surface.main.any():
        return out
    nz, nx = hf.shape
    mcol, mfloor = surface.col[surface.main], surface.floor[surface.main]
    climb = int(math.floor(surface.stats.get("climb_steps", 0))) if surface.stats else 0
    near = np.zeros(len(low), dtype=bool)
    for ncol in neighbour_columns(hf.col[low], hf.shape):
        ok = ncol >= 0
        c = np.where(ok, ncol, 0)
        # column_starts(mcol)[c] and [c + 1] of the few columns asked (mcol is sorted),
        # not counted over every column (0.07 s on hix for ~6,000 low spans)
        a, b = np.searchsorted(mcol, c), np.searchsorted(mcol, c, side="right")
        has = ok & (b > a)
        # the first main span of that column (a column rarely holds two)
        k = np.minimum(a, max(len(mfloor) - 1, 0))
        near |= has & (np.abs(mfloor[k] - hf.smax[low]) <= max(climb, 1))
    cand = low[near]
    if vertices is not None and len(cand):
        from ..geometry.segments import faces_above

        test = cand[:MAX_PARITY_TESTS] if len(cand) > MAX_PARITY_TESTS else cand
        i, j = np.divmod(hf.col[test], nx)
        pts = np.column_stack([hf.origin[0] + (j + 0.5) * hf.cs, hf.origin[1] + (hf.smax[test] - 0.5) * hf.ch,
                               hf.origin[2] + (i + 0.5) * hf.cs])
        inside = faces_above(pts, vertices, faces) % 2 == 1
        cand = np.concatenate([test[~inside], cand[len(test):]])
    out[cand] = True
    return out


def unreachable(surface: Surface, radius: float, vertices: np.ndarray | None = None,
                faces: np.ndarray | None = None) -> np.ndarray:
    """Walkable spans outside the played region, of surfaces where a tank would fit
    (the tops of walls and boxes, too narrow for any tank, are not worth a word), and,
    given the model, not inside a closed solid (the floor under a box: an odd number
    of faces above it)."""
    return _remembered(surface, ("unreachable", float(radius)), (vertices, faces),
                       lambda: _unreachable(surface, radius, vertices, faces))


def asked(surface: Surface, radius: float, model: tuple) -> bool:
    """Whether the report's per-span answers for ``radius`` (unreachable given the
    model's arrays ``(vertices, faces)``, too_small) are kept with the surface: the
    picture no longer needs its clearance and regions then."""
    return (_key(("unreachable", float(radius)), model) in surface.derived
            and _key(("too_small", float(radius)), ()) in surface.derived)


def _unreachable(surface: Surface, radius: float, vertices: np.ndarray | None, faces: np.ndarray | None) -> np.ndarray:
    from ..geometry.segments import faces_above

    other = ~surface.main
    if not other.any():
        return other
    fits = other & (surface.clearance >= radius)
    idx = np.flatnonzero(fits)
    regs = surface.region[idx]
    good = np.unique(regs)
    if vertices is not None and len(good):
        nz, nx = surface.shape
        hf = surface.hf
        # each surface's spans in span order, once: a pass over every span per surface
        # took 0.15 s on hix (74 surfaces)
        order = np.argsort(regs, kind="stable")
        idx, regs = idx[order], regs[order]
        bounds = zip(np.searchsorted(regs, good), np.searchsorted(regs, good, side="right"))
        # one point per surface: its span farthest from the edge
        pts = []
        for a, b in bounds:
            m = idx[a:b]
            k = m[int(np.argmax(surface.clearance[m]))]
            i, j = divmod(int(surface.col[k]), nx)
            pts.append([hf.origin[0] + (j + 0.5) * hf.cs, surface.y[k] + 0.5 * hf.ch, hf.origin[2] + (i + 0.5) * hf.cs])
        good = good[faces_above(np.array(pts), vertices, faces) % 2 == 0]
    return other & _member(surface.region, good)


def _member(labels: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """``np.isin(labels, keep)`` through a table over the labels' range: isin sorted the
    labels with ``keep`` (~36 bytes a span of temporaries: 0.55 GB on a 2 km terrain, the
    preview's and the report's peak); the table takes a byte a label."""
    if len(labels) == 0 or len(keep) == 0:
        return np.zeros(len(labels), dtype=bool)
    lo, hi = int(labels.min()), int(labels.max())
    if lo < 0 or hi > 4 * len(labels) + (1 << 20):   # sparse or negative labels: isin as before
        return np.isin(labels, keep)
    table = np.zeros(hi + 1, dtype=bool)
    table[keep[(keep >= 0) & (keep <= hi)]] = True
    return table[labels]


def too_small(surface: Surface, radius: float) -> np.ndarray:
    """Parts of the played region no tank footprint of ``radius`` ever covers: farther
    than the radius (along the links) from every span where a tank fits, in patches of
    at least MIN_SMALL_AREA radius-squared (a room's corners are not "too small").
    Worked out once per surface and radius (the report and the picture both ask)."""
    return _remembered(surface, ("too_small", float(radius)), (), lambda: _too_small(surface, radius))


def _too_small(surface: Surface, radius: float) -> np.ndarray:
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    main = surface.main
    fits = main & (surface.clearance >= radius)
    if not main.any():
        return main.copy()
    cell = surface.hf.cs
    limit = int(math.ceil(2 * radius / cell)) + 2
    dist = _distance_from(fits, surface.link, limit)
    bare = main & (dist > 2 * radius / cell + 1)
    if not bare.any():
        return bare
    idx = np.flatnonzero(bare)
    pos = np.full(len(main), -1)
    pos[idx] = np.arange(len(idx))
    src, dst = [], []
    for d in range(4):
        t = surface.link[idx, d]
        ok = (t >= 0) & bare[np.maximum(t, 0)]
        src.append(pos[idx[ok]])
        dst.append(pos[t[ok]])
    s, t = np.concatenate(src), np.concatenate(dst)
    _, lab = connected_components(coo_matrix((np.ones(len(s)), (s, t)), shape=(len(idx), len(idx))), directed=False)
    sizes = np.bincount(lab) * cell * cell
    keep = sizes[lab] >= MIN_SMALL_AREA * radius * radius
    out = np.zeros(len(main), dtype=bool)
    out[idx[keep]] = True
    return out


#: uncovered patches smaller than this many radius-squared are corners, not places
MIN_SMALL_AREA = 0.8


def _distance_from(sources: np.ndarray, link: np.ndarray, limit: int) -> np.ndarray:
    """Chamfer-like distance (half cells, straight steps only) from the source spans."""
    from ..geometry.kernels import active

    n = len(sources)
    dist = np.where(sources, 0, limit).astype(np.int32)
    kern = active()
    if kern is not None and link.dtype == np.int32 and n:  # the same fixed point, no int64 copies of the links
        kern.reach(np.ascontiguousarray(link), dist)
        return dist
    safe = [np.where(link[:, d] < 0, n, link[:, d]) for d in range(4)]
    ext = np.full(n + 1, limit, dtype=np.int32)
    for _ in range(limit // 2 + 2):
        ext[:n] = dist
        new = dist.copy()
        for a in safe:
            np.minimum(new, ext[a] + 2, out=new)
        new = np.minimum(new, limit)
        if np.array_equal(new, dist):
            break
        dist = new
    return dist
