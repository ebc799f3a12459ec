"""Free space of a wall list, built from the walls alone (shapely + numpy).

The walls cut the plane into faces: :func:`analyse` nodes the wall segments (so a T
junction splits the wall it touches) and polygonizes them.  Every bounded face is a
polygon whose whole boundary is walls; everything outside all faces is the unbounded
face, index ``-1``.  Each wall then looks at the faces on its two sides: a point a
hair along its normal lies in its *front* face, a point a hair behind it in its
*back* face.  A face is free space when the walls around it mostly (by length) turn
their normals towards it; callers holding spawn points may overrule that vote.

Nothing here relies on the normals being right, which is the point: the rules use
these faces to find the walls whose normals are wrong.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import shapely
from shapely import STRtree

from ..formats.walls_txt import WallList

MAX_GAP_ENDS = 1000
UNBOUNDED = -1
NO_FACE = -2  # the "face" of a zero-length wall, which has no sides


@dataclass
class FreeSpace:
    """Faces of the wall arrangement and how each wall sits between them.

    front, back : (n,) int, face index on the normal side / behind each wall
                  (``UNBOUNDED`` outside every face, ``NO_FACE`` for zero-length walls)
    free : (m,) bool per bounded face, by the normals' vote (callers may change it)
    dangling : (k, 2) wall end points joined to no other wall; ``dangling_wall`` (k,)
               the wall each belongs to
    """

    walls: WallList
    faces: list                      # shapely Polygons, bounded faces
    front: np.ndarray
    back: np.ndarray
    free: np.ndarray
    dangling: np.ndarray
    dangling_wall: np.ndarray
    grid: float                      # snapping grid, metres
    lines: object                    # (n,) shapely LineStrings of the walls (None for zero-length)
    noded: object                    # the walls as one noded geometry
    # the noded pieces of the walls: the wall each lies along, its sides, length, line
    piece_wall: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64), repr=False)
    piece_front: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64), repr=False)
    piece_back: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64), repr=False)
    piece_length: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    piece_lines: object = field(default=None, repr=False)
    _wall_tree: STRtree | None = field(default=None, repr=False)
    _wall_ids: np.ndarray | None = field(default=None, repr=False)

    # ------------------------------------------------------------------ lookups
    def face_of(self, points: np.ndarray) -> np.ndarray:
        """(n,) face index holding each (x, z) point; ``UNBOUNDED`` outside every face."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        out = np.full(len(pts), UNBOUNDED, dtype=np.int64)
        if not self.faces or not len(pts):
            return out
        # the faces are the query side: shapely prepares each one once, so a face with
        # thousands of vertices answers its candidate points in log time each
        fi, pi = STRtree(shapely.points(pts)).query(self.faces, predicate="contains_properly")
        out[pi] = fi
        return out

    def nearest_wall(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Distance from each point to the nearest wall, and that wall's index."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        dist = np.full(len(pts), np.inf)
        idx = np.full(len(pts), -1, dtype=np.int64)
        if self._wall_tree is None or not len(pts):
            return dist, idx
        (pi, ti), d = self._wall_tree.query_nearest(shapely.points(pts), return_distance=True, all_matches=False)
        dist[pi] = d
        idx[pi] = self._wall_ids[ti]
        return dist, idx

    def passage(self, point: np.ndarray, reach: float) -> tuple[float, np.ndarray]:
        """Width and centre of the passage around ``point``: from the nearest wall to the
        nearest wall on the opposite side (within ``reach``); twice the distance to the
        nearest wall when no wall faces it."""
        m = np.asarray(point, dtype=np.float64).reshape(2)
        if self._wall_tree is None:
            return math.inf, m
        pt = shapely.points(m)
        cand = self._wall_tree.query(pt, predicate="dwithin", distance=float(reach))
        if not len(cand):
            return math.inf, m
        near = shapely.get_coordinates(shapely.shortest_line(pt, self._wall_tree.geometries[cand]))[1::2]
        off = near - m
        d = np.hypot(off[:, 0], off[:, 1])
        k = int(np.argmin(d))
        opposite = (off @ off[k]) < 0
        if not opposite.any():
            return 2.0 * float(d[k]), m
        j = int(np.flatnonzero(opposite)[np.argmin(d[opposite])])
        return float(np.hypot(*(near[j] - near[k]))), 0.5 * (near[j] + near[k])

    def region(self, face_ids) -> object:
        """The union of the given bounded faces (one shapely geometry)."""
        faces = [self.faces[i] for i in sorted(set(int(f) for f in face_ids)) if i >= 0]
        if not faces:
            return shapely.Polygon()
        return shapely.union_all(faces)

    def clear_region(self, face_ids, radius: float) -> object:
        """Where the centre of a disc of ``radius`` can stand in those faces without
        touching any wall (walls inside a face, like a lone fence, count too)."""
        ids = sorted(set(int(f) for f in face_ids if f >= 0))
        region = self.region(ids)
        if radius <= 0 or region.is_empty or self.noded is None:
            return region
        # the faces' own boundaries are walls: shrinking the polygons handles them, far
        # faster than buffering every wall; only walls lying inside a face (both sides
        # in it, e.g. a fence or a loose end) need their own buffer
        clear = shapely.buffer(region, -float(radius), quad_segs=8)
        inner = np.flatnonzero((self.piece_front == self.piece_back) & np.isin(self.piece_front, ids))
        if len(inner):
            clear = shapely.difference(clear, shapely.buffer(shapely.union_all(self.piece_lines[inner]),
                                                             float(radius), quad_segs=8))
        return clear

    def flipped(self) -> np.ndarray:
        """(n,) bool: walls with a piece whose normal points into solid (or the outside)
        while its back faces free space."""
        free = np.append(self.free, False)  # index -1 (unbounded) is never free
        f, b = self.piece_front, self.piece_back
        bad = (f != b) & ~free[f] & free[b]
        out = np.zeros(len(self.front), dtype=bool)
        out[self.piece_wall[bad]] = True
        return out


def snap_grid(segments: np.ndarray) -> float:
    """A snapping grid far below any feature an arena has, and far above rounding noise."""
    m = float(np.max(np.abs(segments))) if segments.size else 1.0
    return 1e-7 * max(1.0, m)


def near_copies(seg: np.ndarray, direction: np.ndarray, live: np.ndarray, tol: float) -> np.ndarray:
    """For each wall of ``live`` (indices into ``seg`` (n, 2, 2), ``direction`` (n,)),
    the wall it repeats: the first wall (in file order) of its group of copies, or itself.

    A copy has both ends within ``tol`` of the other's (in either order), lies along
    it (both ends within ``tol`` of its line) and has the same free side: the A202
    rule of the pair search; copies of copies are one group.  Checking every pair of
    walls pasted 1,000 times with tiny offsets is 500,000 pairs; here the walls are
    first binned by the cells of size ``tol / 2`` holding their two ends (oriented by
    cell, so a copy written backwards lands in the same bin): the walls of a bin are
    copies of its first wall by construction.  Only one wall per bin then meets the
    others, and at most 3^4 bins hold copies of any one wall, so the pairs left are
    few whatever the number of copies.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    live = np.asarray(live, dtype=np.int64)
    if len(live) < 2:
        return live.copy()
    s = seg[live]
    cell = np.floor(s / (0.5 * tol))
    flip = (cell[:, 0, 0] > cell[:, 1, 0]) | ((cell[:, 0, 0] == cell[:, 1, 0]) & (cell[:, 0, 1] > cell[:, 1, 1]))
    oriented = np.where(flip[:, None, None], s[:, ::-1], s)
    side = np.where(flip, -direction[live], direction[live]).astype(np.float64)
    keys = np.column_stack([np.where(flip[:, None, None], cell[:, ::-1], cell).reshape(-1, 4), side])
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    f = first[inverse.reshape(-1)]
    # same cells: ends within tol/2 per axis, so within tol of the first's line; the
    # same free side also needs the same way along (a wall shorter than a cell may not)
    along = np.einsum("ij,ij->i", oriented[:, 1] - oriented[:, 0], oriented[f, 1] - oriented[f, 0]) > 0
    f = np.where(along, f, np.arange(len(live)))
    heads = np.flatnonzero(f == np.arange(len(live)))
    # copies in neighbouring bins: the pair test among the bins' first walls only
    lines = shapely.linestrings(s[heads])
    i, j = STRtree(lines).query(lines, predicate="dwithin", distance=tol)
    keep = i < j
    a, b = heads[i[keep]], heads[j[keep]]
    dup = copy_pairs(s[a], s[b], direction[live[a]], direction[live[b]], tol)
    n = len(live)
    graph = coo_matrix((np.ones(int(dup.sum()) + n), (np.r_[a[dup], np.arange(n)], np.r_[b[dup], f])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    lowest = np.full(label.max() + 1, n, dtype=np.int64)
    np.minimum.at(lowest, label, np.arange(n))
    return live[lowest[label]]


def copy_pairs(sa: np.ndarray, sb: np.ndarray, da: np.ndarray, db: np.ndarray, tol: float) -> np.ndarray:
    """(k,) bool: wall ``sb[k]`` (2, 2) repeats wall ``sa[k]`` (the A202 test): both ends
    within ``tol`` of the other's in either order, both within ``tol`` of its line, the
    same free side (normals ``direction * (-dz, dx)`` agreeing)."""
    P, Q, R, S = sa[:, 0], sa[:, 1], sb[:, 0], sb[:, 1]
    u, v = Q - P, S - R
    with np.errstate(all="ignore"):
        u = u / np.hypot(u[:, 0], u[:, 1])[:, None]
        v = v / np.hypot(v[:, 0], v[:, 1])[:, None]

        def side(o, t, p):
            return t[:, 0] * (p[:, 1] - o[:, 1]) - t[:, 1] * (p[:, 0] - o[:, 0])

        collinear = (np.abs(side(P, u, R)) <= tol) & (np.abs(side(P, u, S)) <= tol)
        same_side = np.einsum("ij,ij->i", u * da[:, None], v * db[:, None]) > 0
    same_ends = (((np.abs(P - R) <= tol).all(1) & (np.abs(Q - S) <= tol).all(1))
                 | ((np.abs(P - S) <= tol).all(1) & (np.abs(Q - R) <= tol).all(1)))
    return collinear & same_ends & same_side

def analyse(walls: WallList) -> FreeSpace:
    """Faces, wall sides, the normals' vote and the dangling wall ends of ``walls``."""
    seg = np.asarray(walls.segments, dtype=np.float64).reshape(-1, 2, 2)
    n = len(seg)
    g = snap_grid(seg)
    snapped = np.round(seg / g) * g
    length = np.hypot(*(snapped[:, 1] - snapped[:, 0]).T)
    live = np.flatnonzero(length > 0)
    front = np.full(n, NO_FACE, dtype=np.int64)
    back = np.full(n, NO_FACE, dtype=np.int64)
    lines = np.full(n, None, dtype=object)
    if len(live) == 0:
        return FreeSpace(walls, [], front, back, np.zeros(0, bool), np.zeros((0, 2)), np.zeros(0, np.int64),
                         g, lines, None)
    lines[live] = shapely.linestrings(snapped[live])
    # copies of a wall (A202) add nothing to the arrangement but slivers and cost: the
    # first of each is noded and looked up, the others take its pieces' sides below
    origin = near_copies(snapped, walls.direction, live, 4.0 * g)
    reps = live[origin == live]
    # snap-rounding noder: robust against nearly collinear and nearly touching walls
    noded = shapely.union_all(lines[reps], grid_size=g)
    parts = shapely.get_parts(noded)
    faces = list(shapely.get_parts(shapely.polygonize(parts))) if len(parts) else []
    faces = [f for f in faces if f.area > 0]

    fs = FreeSpace(walls, faces, front, back, np.zeros(len(faces), bool), np.zeros((0, 2)),
                   np.zeros(0, np.int64), g, lines, noded)
    fs._wall_tree = STRtree(lines[reps])
    fs._wall_ids = reps

    # Sides are sampled per noded piece, not per wall: a long wall split by T
    # junctions borders a different face along each piece, and each piece must vote
    # for its own faces.  A piece maps back to every wall lying along it (duplicates
    # and the two coincident walls of touching solids give several).
    pieces = parts[shapely.get_type_id(parts) == 1] if len(parts) else np.zeros(0, object)
    # every segment of every noded linestring (GEOS may chain segments through
    # vertices where nothing else meets)
    xy, owner = shapely.get_coordinates(pieces, return_index=True)
    same = owner[1:] == owner[:-1]
    pa, pb = xy[:-1][same], xy[1:][same]
    pl = np.hypot(*(pb - pa).T)
    ok = pl > 0
    pa, pb, pl = pa[ok], pb[ok], pl[ok]
    # a point a little off the piece's middle, so it does not land on a T junction
    # placed exactly at the middle of a wall
    pmid = pa + (0.5 + 1.0 / 128.0) * (pb - pa)
    pi, ti = fs._wall_tree.query(shapely.points(pmid), predicate="dwithin", distance=2.0 * g)
    w = reps[ti]
    d = snapped[w, 1] - snapped[w, 0]
    normal = np.stack([-d[:, 1], d[:, 0]], axis=1) / length[w, None] * walls.direction[w, None]
    eps = np.minimum(100.0 * g, 0.05 * pl[pi])
    m = pmid[pi]
    sides = fs.face_of(np.concatenate([m + eps[:, None] * normal, m - eps[:, None] * normal]))
    pf, pbk = sides[: len(pi)], sides[len(pi):]
    pi, w, pf, pbk = _with_copies(pi, w, pf, pbk, live, origin)
    fs.piece_wall, fs.piece_front, fs.piece_back, fs.piece_length = w, pf, pbk, pl[pi]
    fs.piece_lines = shapely.linestrings(np.stack([pa[pi], pb[pi]], axis=1)) if len(pi) else np.zeros(0, object)

    vote = np.zeros(len(faces) + 1)
    weight = np.zeros(len(faces) + 1)
    np.add.at(vote, pf, pl[pi])   # index -1 (unbounded) lands in the extra last slot
    np.add.at(vote, pbk, -pl[pi])
    np.add.at(weight, pf, pl[pi])
    np.add.at(weight, pbk, pl[pi])
    # a tie is no claim of free space: a solid walled in by other solids (every edge a
    # cancelling pair) sums to zero up to rounding, and must stay solid
    fs.free = vote[: len(faces)] > 1e-9 * (1.0 + weight[: len(faces)])

    # each wall's own sides: those of its longest piece
    order = np.lexsort((-pl[pi], w))
    first = order[np.r_[True, w[order][1:] != w[order][:-1]]] if len(order) else order
    front[w[first]] = pf[first]
    back[w[first]] = pbk[first]
    fs.dangling, fs.dangling_wall = _dangling_ends(snapped, live, origin, lines, g)
    return fs


def _with_copies(pi: np.ndarray, w: np.ndarray, pf: np.ndarray, pb: np.ndarray,
                 live: np.ndarray, origin: np.ndarray) -> tuple[np.ndarray, ...]:
    """The (piece, wall, front, back) rows of the first copies repeated for every other
    copy of the same wall: a copy lies along the same pieces with the same free side."""
    copies = live[origin != live]
    if not len(copies) or not len(w):
        return pi, w, pf, pb
    of = origin[origin != live]
    order = np.argsort(of, kind="stable")
    of, copies = of[order], copies[order]
    lo = np.searchsorted(of, w, side="left")
    n = np.searchsorted(of, w, side="right") - lo           # copies of each row's wall
    rows = np.repeat(np.arange(len(w)), n)
    # the k-th copy of a row: lo[row] + k
    k = np.arange(len(rows)) - np.repeat(np.cumsum(n) - n, n)
    extra = copies[lo[rows] + k]
    return (np.concatenate([pi, pi[rows]]), np.concatenate([w, extra]),
            np.concatenate([pf, pf[rows]]), np.concatenate([pb, pb[rows]]))


def _dangling_ends(snapped: np.ndarray, live: np.ndarray, origin: np.ndarray, lines,
                   g: float) -> tuple[np.ndarray, np.ndarray]:
    """Wall ends touching no other wall (neither its ends nor its length).

    Copies of a wall (``origin``: :func:`near_copies`) are looked up once: both ends of
    a repeated wall touch its copy, and a wall pasted 2,000 times would otherwise make
    8 million end-wall pairs (seconds of work for a 60 KB file)."""
    ends = np.concatenate([snapped[live, 0], snapped[live, 1]])
    owner = np.concatenate([live, live])
    first, group, count = np.unique(origin, return_inverse=True, return_counts=True)
    group = group.reshape(-1)
    tree = STRtree(lines[first])
    pi, ti = tree.query(shapely.points(ends), predicate="dwithin", distance=2.0 * g)
    other = ti != np.concatenate([group, group])[pi]
    joined = np.zeros(len(ends), dtype=bool)
    joined[pi[other]] = True
    joined |= np.concatenate([count[group] > 1, count[group] > 1])   # touches its own copy
    return ends[~joined], owner[~joined]


def gaps(fs: FreeSpace) -> list[tuple[int, int, np.ndarray, np.ndarray]]:
    """The gaps at loose wall ends, narrowest first: ``(wall_a, wall_b, end_a, point_b)``.

    Each loose end is joined to the nearest point of any other wall (another loose
    end, or the middle of a wall the end stops short of).  A gap whose far point is
    itself a loose end uses that end up, so the two sides of one gap are reported once
    and an end that merely overshoots a corner does not count as a second gap.  Only
    the first MAX_GAP_ENDS loose ends are looked at: a file with more is broken beyond
    what a list of gaps can help with.
    """
    k = min(len(fs.dangling), MAX_GAP_ENDS)
    if k == 0 or fs._wall_tree is None:
        return []
    seg = fs.walls.segments.reshape(-1, 2)
    reach = 0.25 * float(np.hypot(*np.ptp(seg, axis=0)))
    cand = []
    for e in range(k):
        p = fs.dangling[e]
        own = int(fs.dangling_wall[e])
        pt = shapely.points(p)
        near_ids = fs._wall_tree.query(pt, predicate="dwithin", distance=reach)
        near_ids = near_ids[fs._wall_ids[near_ids] != own]
        if not len(near_ids):
            continue
        near = shapely.get_coordinates(shapely.shortest_line(pt, fs._wall_tree.geometries[near_ids]))[1::2]
        d = np.hypot(*(near - p).T)
        j = int(np.argmin(d))
        cand.append((float(d[j]), e, int(fs._wall_ids[near_ids[j]]), near[j]))
    cand.sort(key=lambda c: (c[0], c[1]))
    used = np.zeros(k, dtype=bool)
    out = []
    tol = 4.0 * fs.grid
    for _, e, wall_b, q in cand:
        if used[e]:
            continue
        at_end = np.flatnonzero(np.abs(fs.dangling[:k] - q).max(axis=1) <= tol)
        if used[at_end].any():
            continue
        used[e] = True
        used[at_end] = True
        out.append((int(fs.dangling_wall[e]), wall_b, fs.dangling[e], q))
    return out
