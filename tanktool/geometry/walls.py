"""Wall extraction: from a 3D arena model to the 2002 top-view wall list.

The pipeline, each step a function below:

1. :func:`find_floor` -- the floor is the lowest *large* horizontal surface.  Faces
   whose normal points up (``n_y >= 0.9``, within ~25 degrees of vertical) are
   grouped into height levels (sorted by centroid height, a new level wherever two
   consecutive heights differ by more than 5 cm); a level is *large* when its area
   is at least a quarter of the largest level's area.  Small low pieces (stair
   treads, a sunken pit, the bottom of a basement ramp) are thereby skipped, and on
   a multi-storey model the ground storey wins over a bigger upper one only when it
   is at least a quarter of its size.
2. :func:`slice_mesh` -- cut every triangle with the plane ``y = floor + height``
   (numpy, all crossing triangles at once).  Vertices closer than
   :func:`merge_distance` are merged and the plane is moved off every vertex, so a
   shared edge always yields the same cut point and loops close.
   Each cut segment keeps the horizontal part of its face normal: it says which
   side is solid.
3. :func:`cross_sections` (:mod:`.cross_section`) -- group the segments into components (connected
   through shared cut points).  Segments are ordered "face normal on the right", so
   a closed component with consistent normals that point out of it runs
   counter-clockwise and bounds solid; the solid cross-section is the set of points
   of positive winding number over all such components (:func:`winding_region`),
   so overlapping or nested boxes are one solid and no wall is left buried inside
   solid material.  A closed component whose normals point into it is a hole when
   it lies wholly in solid (a room inside a thick wall ring), a box wound inside
   out when floor surrounds it, and otherwise a one-sided shell seen from inside.
4. :func:`floor_region` + :func:`free_space` -- the free space is the floor's
   outline (the upward faces from the floor level up to the cut, from their
   boundary edges and winding numbers) minus the solid.  If the largest region is
   walled in, regions touching the floor's bounding rectangle (strips outside the
   outer walls) are dropped; regions narrower than MIN_FREE_WIDTH everywhere
   (ledges, sills) too.  Coordinates are snapped to the tolerance grid.
5. :func:`outline_walls` -- the walls are the boundary of the free space, free
   space on their left so that Direction +1 makes each normal point into it,
   collinear pieces merged, pieces shorter than the tolerance dropped.
   :func:`thin_walls` -- open chains (single-quad walls, zero-thickness fences,
   non-watertight pieces), one-sided shells and loops with inconsistent normals do
   not say which side is solid: where they cross free space they become *thin
   walls*, two walls on the same segment with opposite normals, so a vehicle meets
   them from either side.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import shapely

from ..errors import ArenaError
from ..formats.walls_txt import WallList, aux_rectangle
from .cross_section import cross_sections, winding_region
from .thin_walls import line_segments, thin_walls, thin_walls_reference  # noqa: F401

#: an upward face has a normal within ~25 degrees of +y
UP_NORMAL_MIN = 0.9
#: heights closer than this belong to the same floor level (m)
LEVEL_GAP = 0.05
#: a level is "large" at this fraction of the largest level's area
LARGE_LEVEL_FRACTION = 0.25
#: free regions narrower than this everywhere (ledges, sills) are dropped (m)
MIN_FREE_WIDTH = 1.0


@dataclass
class FloorLevel:
    """The chosen floor: its height and the faces that make it up."""

    y: float
    area: float
    faces: np.ndarray  # (k,) indices of the floor level's upward faces
    levels: list[tuple[float, float]] = field(default_factory=list)  # (height, area) per level
    up: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))  # every upward face
    up_height: np.ndarray = field(default_factory=lambda: np.zeros(0))  # their centroid heights


@dataclass
class WallExtraction:
    """Everything :func:`extract_walls` found; ``walls`` is what ``walls.txt`` holds."""

    walls: WallList
    floor_y: float
    cut_y: float
    free: Any  # shapely (Multi)Polygon: the free space at the cut height
    solid: Any  # shapely geometry: the solid cross-section
    thin_walls: int  # how many of the walls are halves of thin (zero-thickness) walls
    rings: int
    chains: int
    raw_segments: int
    timings: dict[str, float] = field(default_factory=dict)


# ---------------------------------------------------------------------------
# 0. the input


def triangle_mesh(vertices: Any, faces: Any) -> tuple[np.ndarray, np.ndarray]:
    """``vertices`` (n, 3) float64 and ``faces`` (m, 3) int64, checked.

    Every function here indexes vertices by faces: a face of two vertices, an index
    past the vertices, a negative index (numpy counts it from the end: silently the
    wrong vertex) or a fractional one (silently truncated) is refused with one clear
    ArenaError instead of an IndexError deep inside, whoever the caller is.
    """
    try:
        v = np.asarray(vertices, dtype=np.float64)
        f = np.asarray(faces)
    except (TypeError, ValueError) as e:
        raise ArenaError(f"the model's vertices or faces are not numeric arrays ({e})") from None
    if v.ndim != 2 or v.shape[1] != 3:
        raise ArenaError(f"the model's vertices must be an (n, 3) array of x y z, got shape {v.shape}")
    if f.size == 0:
        return v, np.zeros((0, 3), dtype=np.int64)
    if f.ndim != 2 or f.shape[1] != 3:
        raise ArenaError(f"the model's faces must be triangles, an (m, 3) array of vertex indices; got shape {f.shape}")
    if f.dtype.kind == "f":
        if not np.isfinite(f).all() or (f != np.round(f)).any():
            raise ArenaError("the model's faces hold vertex indices that are not whole numbers")
    elif f.dtype.kind not in "iub":
        raise ArenaError(f"the model's faces must hold integer vertex indices, got {f.dtype}")
    lo, hi = f.min(), f.max()
    if lo < 0 or hi >= len(v):
        bad = int(lo) if lo < 0 else int(hi)
        raise ArenaError(f"a face of the model uses vertex {bad}, outside 0..{len(v) - 1} ({len(v)} vertices)")
    return v, f.astype(np.int64, copy=False)


# ---------------------------------------------------------------------------
# 1. the floor


def _upward_faces(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """Faces whose normal is within ~25 degrees of +y.

    Returns (indices, centroid heights, areas, any_downward).  The cross product is
    written out per component: on a million faces this is several times faster
    than gathering (m, 3, 3) triangles and calling ``np.cross``.
    """
    vertices, faces = triangle_mesh(vertices, faces)
    # contiguous coordinate and index columns gather much faster than (m, 3) rows
    X, Y, Z = (np.ascontiguousarray(vertices[:, k]) for k in range(3))
    f0, f1, f2 = (np.ascontiguousarray(faces[:, k]) for k in range(3))
    x0, z0 = X[f0], Z[f0]
    e1x, e1z, e2x, e2z = X[f1] - x0, Z[f1] - z0, X[f2] - x0, Z[f2] - z0
    ny = e1z * e2x - e1x * e2z
    # only faces leaning up or down can be steep: the rest is computed on those alone
    cand = np.flatnonzero(ny != 0)
    y0 = Y[f0[cand]]
    e1y = Y[f1[cand]] - y0
    e2y = Y[f2[cand]] - y0
    e1x, e1z, e2x, e2z, nyc = e1x[cand], e1z[cand], e2x[cand], e2z[cand], ny[cand]
    nx = e1y * e2z - e1z * e2y
    nz = e1x * e2y - e1y * e2x
    n2 = nx * nx + nyc * nyc + nz * nz
    steep = nyc * nyc >= UP_NORMAL_MIN ** 2 * n2
    is_up = steep & (nyc > 0)
    up = cand[is_up]
    down = bool(np.any(steep & (nyc < 0)))
    height = (Y[f0[up]] + Y[f1[up]] + Y[f2[up]]) / 3
    return up, height, np.sqrt(n2[is_up]) / 2, down


def find_floor(vertices: np.ndarray, faces: np.ndarray) -> FloorLevel:
    """The lowest large horizontal upward surface (rule in the module docstring).

    vertices (n, 3) world frame (Y up), faces (m, 3) int.  Raises ArenaError when
    the model has no upward-facing faces at all.
    """
    up, height, area, down = _upward_faces(vertices, faces)
    if len(up) == 0:
        if down:
            raise ArenaError("no upward-facing floor: the model's faces seem wound inside out "
                             "(or its up axis is wrong: try --up)")
        raise ArenaError("no horizontal surface to stand on (no face has a vertical normal; try --up)")
    order = np.argsort(height, kind="stable")
    h = height[order]
    split = np.flatnonzero(np.diff(h) > LEVEL_GAP) + 1
    starts = np.concatenate([[0], split])
    level_area = np.add.reduceat(area[order], starts)
    level_h = np.add.reduceat(area[order] * h, starts) / np.maximum(level_area, 1e-300)
    large = np.flatnonzero(level_area >= LARGE_LEVEL_FRACTION * level_area.max())
    k = int(large[0])
    stop = starts[k + 1] if k + 1 < len(starts) else len(h)
    levels = [(float(a), float(b)) for a, b in zip(level_h, level_area)]
    return FloorLevel(float(level_h[k]), float(level_area[k]), up[order[starts[k]:stop]], levels, up, height)


def floor_faces(floor: FloorLevel, cut_y: float) -> np.ndarray:
    """Indices of the upward faces from the floor level up to the cut height."""
    return floor.up[(floor.up_height >= floor.y - LEVEL_GAP) & (floor.up_height < cut_y)]


# ---------------------------------------------------------------------------
# 2. the cut


def merge_distance(vertices: np.ndarray) -> float:
    """Vertices closer than this are one vertex: a few float32 ulps of the model's
    largest coordinate (5e-5 m on a 100 m arena), far below any wall tolerance."""
    return 5e-7 * max(1.0, float(np.abs(vertices).max()) if len(vertices) else 1.0)


def _cluster_points(pos: np.ndarray, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """Group points closer than ``eps`` (transitively).

    Returns (label per point, index of one representative point per label).
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    pairs = cKDTree(pos).query_pairs(eps, output_type="ndarray")
    n = len(pos)
    if len(pairs) == 0:
        return np.arange(n), np.arange(n)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    _, rep = np.unique(label, return_index=True)
    return label, rep


def slice_mesh(vertices: np.ndarray, faces: np.ndarray, y: float,
               merge: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cut triangles with the plane ``Y = y``.

    ``merge``: vertices closer than this are joined (default :func:`merge_distance`);
    the plane must keep more than twice that from every vertex
    (:func:`extract_walls` moves it so).

    Returns ``segments`` (s, 2, 2) in (x, z), ``normals`` (s, 2) the horizontal part
    of each face normal (not normalised) and ``nodes`` (s, 2) int, an id per cut
    point shared by every segment through it (same mesh edge, or same position).
    Each segment is ordered so that its face normal lies on its right-hand side,
    i.e. for outward normals the solid is on the left.
    """
    vertices, faces = triangle_mesh(vertices, faces)
    d = vertices[:, 1] - y
    above = (d >= 0.0).view(np.uint8)  # on the plane counts as above: shared edges cut identically
    # per-column gathers: several times faster than above[faces].sum(axis=1)
    count = above[faces[:, 0]] + above[faces[:, 1]] + above[faces[:, 2]]
    crossing = np.flatnonzero((count == 1) | (count == 2))
    f = faces[crossing]
    fa = above[f].astype(bool)
    if len(f) == 0:
        return np.zeros((0, 2, 2)), np.zeros((0, 2)), np.zeros((0, 2), dtype=np.int64)
    # the lone vertex (the one on its own side) goes first; the cyclic order is kept
    lone = np.where(count[crossing] == 1, np.argmax(fa, axis=1), np.argmin(fa, axis=1))
    rows = np.arange(len(f))[:, None]
    f = f[rows, (lone[:, None] + np.arange(3)) % 3]
    # merge vertices within ``merge`` of each other (split seams of .3ds/.obj files,
    # float32 round-off between objects) so that neighbouring triangles share edge
    # ids; only the crossing triangles' vertices, so this stays cheap
    used, inv = np.unique(f, return_inverse=True)
    merged, rep = _cluster_points(vertices[used], merge if merge is not None else merge_distance(vertices))
    g = merged[inv.reshape(f.shape)]
    P = vertices[used][rep]  # one representative position per merged vertex
    # edges (lone, next) and (lone, prev): canonical (low id, high id) order so the
    # arithmetic, and hence the cut point, is identical in both adjacent triangles
    ends = []
    keys = []
    for other in (1, 2):
        a = np.minimum(g[:, 0], g[:, other])
        b = np.maximum(g[:, 0], g[:, other])
        pa = P[a]
        pb = P[b]
        da = pa[:, 1] - y
        db = pb[:, 1] - y
        t = da / (da - db)
        p = pa + t[:, None] * (pb - pa)
        ends.append(p[:, [0, 2]])
        keys.append(a.astype(np.int64) * (len(P) + 1) + b)
    p0, p1 = ends
    tri = vertices[f]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, [0, 2]]
    seg = np.stack([p0, p1], axis=1)
    # the normal must be on the right of p0 -> p1: right of (dx, dz) is (dz, -dx)
    dx = p1 - p0
    flip = (dx[:, 1] * n[:, 0] - dx[:, 0] * n[:, 1]) < 0
    seg[flip] = seg[flip][:, ::-1]
    k0, k1 = keys
    _, node = np.unique(np.concatenate([k0, k1]), return_inverse=True)
    node = node.reshape(2, -1).T
    node[flip] = node[flip][:, ::-1]
    keep = np.any(seg[:, 0] != seg[:, 1], axis=1)  # a triangle touching the plane at a vertex
    return seg[keep], n[keep], node[keep]


# ---------------------------------------------------------------------------
# 4-5. free space and its outline


def _merge_positions(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Faces re-indexed so that vertices at the same position share one id."""
    used, inv = np.unique(faces, return_inverse=True)
    pos = np.ascontiguousarray(vertices[used], dtype=np.float64)
    _, merged = np.unique(pos.view(np.dtype((np.void, pos.itemsize * 3))).reshape(-1), return_inverse=True)
    return merged.reshape(-1)[inv.reshape(faces.shape)]


def floor_region(vertices: np.ndarray, faces: np.ndarray, tolerance: float):
    """The top-view outline of upward faces: a shapely (Multi)Polygon.

    Uses only the faces' boundary edges, directed so the floor is on their left, and
    the winding number of the faces of their arrangement; overlapping floor pieces and
    T-junctions come out right, and no polygon per triangle is ever built.  An edge is
    on the boundary as many times as its uses one way outnumber its uses the other
    way: two faces side by side cancel, and a floor modelled twice over (duplicate
    faces, common in exported models) keeps its outline, each edge twice.
    """
    vertices, faces = triangle_mesh(vertices, faces)
    g = _merge_positions(vertices, faces)
    # upward faces are clockwise in (x, z); reversing them puts the face on the left
    e = np.stack([g[:, [0, 2]], g[:, [2, 1]], g[:, [1, 0]]], axis=1).reshape(-1, 2)
    ev = np.stack([faces[:, [0, 2]], faces[:, [2, 1]], faces[:, [1, 0]]], axis=1).reshape(-1, 2)
    key = np.minimum(e[:, 0], e[:, 1]) * (int(g.max()) + 1) + np.maximum(e[:, 0], e[:, 1])
    _, inv = np.unique(key, return_inverse=True)
    inv = inv.reshape(-1)
    way = np.where(e[:, 0] < e[:, 1], 1, -1)
    net = np.bincount(inv, weights=way).astype(np.int64)
    # one use of each edge the way its net count goes, repeated |net| times
    along = np.flatnonzero((net[inv] != 0) & (way == np.sign(net[inv])))
    _, first = np.unique(inv[along], return_index=True)
    pick = np.sort(along[first])   # in the faces' order, as the chains have always been merged
    seg = vertices[np.repeat(ev[pick], np.abs(net[inv[pick]]), axis=0)][:, :, [0, 2]]
    return winding_region(seg, tolerance)


def free_space(solid, floor):
    """The free space: the floor minus the solid, without what lies outside the
    outer walls (see the module docstring)."""
    region = shapely.difference(floor, solid)
    parts = shapely.get_parts(region)
    if len(parts) == 0:
        return shapely.Polygon()
    x0, z0, x1, z1 = shapely.bounds(floor)
    b = shapely.bounds(parts)
    eps = 1e-6 * max(1.0, x1 - x0, z1 - z0)
    touches = (b[:, 0] <= x0 + eps) | (b[:, 1] <= z0 + eps) | (b[:, 2] >= x1 - eps) | (b[:, 3] >= z1 - eps)
    area = shapely.area(parts)
    if not touches[int(np.argmax(area))]:
        parts = parts[~touches]  # the main space is walled in: drop the strips outside
    return shapely.union_all(parts)


def _ring_walls(ring: np.ndarray, tolerance: float = 0.0) -> np.ndarray:
    """(k, 2, 2) walls along a closed ring (last point == first), starting at its
    lowest-left vertex.  A vertex closer than ``tolerance`` to the one kept before it is
    dropped, so no wall is shorter than that and the walls still close up (dropping the
    short walls themselves would leave gaps)."""
    pts = ring[:-1]
    if tolerance > 0.0 and len(pts) > 3:
        keep = [0]
        for k in range(1, len(pts)):
            if np.hypot(*(pts[k] - pts[keep[-1]])) >= tolerance:
                keep.append(k)
        while len(keep) > 3 and np.hypot(*(pts[keep[-1]] - pts[keep[0]])) < tolerance:
            keep.pop()
        if len(keep) < 3:
            return np.zeros((0, 2, 2))
        pts = pts[keep]
    start = int(np.lexsort((pts[:, 1], pts[:, 0]))[0])
    pts = np.roll(pts, -start, axis=0)
    return np.stack([pts, np.roll(pts, -1, axis=0)], axis=1)


def outline_walls(free, tolerance: float) -> np.ndarray:
    """Walls along the boundary of ``free`` with free space on their left, so that
    Direction +1 gives normals into free space.  (n, 2, 2)."""
    free = shapely.orient_polygons(free, exterior_cw=False)  # exterior CCW, holes CW
    out = []
    for poly in shapely.get_parts(free):
        for ring in [poly.exterior, *poly.interiors]:
            out.append(_ring_walls(np.asarray(ring.coords), tolerance))
    if not out:
        return np.zeros((0, 2, 2))
    return np.concatenate(out)


#: gap between the walls' extent and the auxiliary rectangle (m)
AUX_MARGIN = 1.0


def _plane_clear_of_vertices(vertices: np.ndarray, y: float, merge: float) -> float:
    """Nudge the cut plane down until no vertex lies within 2 x ``merge`` of it:
    no on-plane special cases, and no merged vertex straddles the plane."""
    step = 4 * merge
    ys = vertices[:, 1]
    for _ in range(64):
        if np.abs(ys - y).min() > 2 * merge:
            return y
        y -= step
    return y


def extract_walls(vertices: np.ndarray, faces: np.ndarray, height: float = 1.0, tolerance: float = 0.01,
                  progress: Callable[[str], None] | None = None) -> WallExtraction:
    """Extract the wall list of an arena model (world frame, Y up, metres).

    vertices (n, 3) float, faces (m, 3) int.  ``height`` is the cut height above
    the floor, ``tolerance`` the shortest wall kept and the snapping grid.  Raises
    ArenaError when no free space remains at that height.
    """
    if not (math.isfinite(height) and height > 0):
        raise ArenaError(f"--height must be a positive number of metres, got {height}")
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise ArenaError(f"--tolerance must be a positive number of metres, got {tolerance}")
    vertices, faces = triangle_mesh(vertices, faces)
    if len(faces) == 0:
        raise ArenaError("the model has no triangles")
    if not np.isfinite(vertices).all():
        raise ArenaError("the model has non-finite vertices (NaN or inf)")
    step = progress or (lambda _name: None)
    t = {}
    t0 = time.perf_counter()
    floor = find_floor(vertices, faces)
    merge = merge_distance(vertices)
    cut_y = _plane_clear_of_vertices(vertices, floor.y + height, merge)
    t["floor"] = time.perf_counter() - t0
    step("floor")
    t0 = time.perf_counter()
    seg, nrm, nodes = slice_mesh(vertices, faces, cut_y, merge)
    t["cut"] = time.perf_counter() - t0
    step("cut")
    t0 = time.perf_counter()
    # everything horizontal from the floor level up to the cut is ground a tank
    # stands on (kerbs, low platforms); higher surfaces are tops of walls
    ground = floor_faces(floor, cut_y)
    floor_poly = floor_region(vertices, faces[ground], tolerance)
    solid, chains, nrings = cross_sections(seg, nrm, nodes, tolerance, floor_poly)
    t["sections"] = time.perf_counter() - t0
    step("sections")
    t0 = time.perf_counter()
    free = shapely.set_precision(free_space(solid, floor_poly), tolerance)
    parts = shapely.get_parts(free)
    # ledges and sills narrower than MIN_FREE_WIDTH everywhere are not arena space
    wide = ~shapely.is_empty(shapely.buffer(parts, -MIN_FREE_WIDTH / 2, quad_segs=2))
    free = shapely.union_all(parts[wide]) if wide.any() else shapely.Polygon()
    if free.is_empty:
        raise ArenaError(
            f"no free space at {height:g} m above the floor (floor at y={floor.y:.3f}): "
            "the cut lies inside solid material everywhere there is floor"
        )
    # merge collinear pieces; the free space kept is exactly what the walls outline
    free = shapely.simplify(free, tolerance, preserve_topology=True)
    outline = outline_walls(free, tolerance)
    thin = thin_walls(chains, free, tolerance)
    t["free"] = time.perf_counter() - t0
    step("free")
    segments = np.concatenate([outline, thin, thin[:, ::-1]]) if len(thin) else outline
    # thin walls: the same segment twice, the copy reversed, both with Direction +1,
    # i.e. one normal on each side
    direction = np.ones(len(segments), dtype=np.int8)
    pts = segments.reshape(-1, 2)
    lo = pts.min(axis=0) - AUX_MARGIN
    hi = pts.max(axis=0) + AUX_MARGIN
    walls = WallList(segments, direction, aux_rectangle(lo[0], lo[1], hi[0], hi[1]))
    return WallExtraction(walls, floor.y, float(floor.y + height), free, solid, 2 * len(thin), nrings,
                          len(chains), len(seg), t)
