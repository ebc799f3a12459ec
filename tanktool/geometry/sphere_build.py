"""Building sphere trees: each part of the model is split into children by the
candidate (slabs or grids along the vehicle and principal axes, or k-means) that
makes the union of the new spheres smallest; every sphere is the exact minimum
sphere of its part's points.  Also the octree baseline (Hubbard) the bench compares
against, and the Monte Carlo excess volume that measures tightness."""

from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np

from .min_sphere import DIRECTIONS, quick_sphere, min_enclosing_sphere
from .spheres import SphereTree

def surface_samples(vertices: np.ndarray, faces: np.ndarray, count: int, seed: int = 0) -> np.ndarray:
    """(count, 3) points spread over the triangles by area, reproducibly."""
    tri = vertices[faces]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    total = area.sum()
    if count <= 0 or not total > 0:
        return np.zeros((0, 3))
    rng = np.random.default_rng(seed)
    pick = rng.choice(len(faces), size=count, p=area / total)
    u, v = rng.random(count), rng.random(count)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    t = tri[pick]
    return t[:, 0] + u[:, None] * (t[:, 1] - t[:, 0]) + v[:, None] * (t[:, 2] - t[:, 0])


def build_points(vertices: np.ndarray, faces: np.ndarray, samples: int = 4000, seed: int = 0) -> np.ndarray:
    """The point set a tree must enclose: every vertex plus area-weighted surface samples."""
    vertices = np.asarray(vertices, dtype=np.float64)
    extra = surface_samples(vertices, np.asarray(faces, dtype=np.int64), samples, seed)
    return np.vstack([vertices, extra])


def _kmeans_split(points: np.ndarray, k: int, seed: int) -> list[np.ndarray]:
    """k-means (k-means++ seeding) pieces, then a few Lloyd rounds in which a point
    goes to the piece whose sphere it enlarges least, trimming the largest spheres."""
    from scipy.cluster.vq import kmeans2

    scale = points.std(axis=0).max() or 1.0
    rng = np.random.default_rng(seed)
    _, labels = kmeans2(points / scale, k, minit="++", seed=rng, iter=20)
    for _ in range(4):
        pieces = [p for p in (np.flatnonzero(labels == j) for j in range(labels.max() + 1)) if len(p)]
        if len(pieces) < 2:
            break
        cs = np.array([points[p].mean(axis=0) for p in pieces])
        rs = np.array([np.sqrt(np.max(np.sum((points[p] - c) ** 2, axis=1))) for p, c in zip(pieces, cs)])
        d = np.sqrt(((points[:, None, :] - cs[None]) ** 2).sum(axis=2))
        new = np.argmin(np.maximum(d - rs[None], 0) + 0.5 * d, axis=1)
        if np.array_equal(new, labels):
            break
        labels = new
    return [p for p in (np.flatnonzero(labels == j) for j in range(labels.max() + 1)) if len(p)]


def _grid_splits(points: np.ndarray, k: int) -> list[np.ndarray]:
    """Label arrays cutting a part into ``k`` cells of equal width along its axes.

    Frames: the vehicle axes and the part's principal axes (when they differ).  In
    each: ``k`` slabs along one axis, and ``a x b = k`` grids over two axes — so a
    plate is cut along its length and width, a column of a room keeps its two facing
    walls together, a barrel is cut into lengths.
    """
    frames = [np.eye(3)]
    if len(points) >= 3:
        try:
            _, _, vt = np.linalg.svd(points - points.mean(axis=0), full_matrices=False)
            if vt.shape == (3, 3) and np.abs(vt).max(axis=1).min() < 0.999:
                frames.append(vt)
        except np.linalg.LinAlgError:
            pass
    out = []
    for axes in frames:
        x = points @ axes.T
        lo, span = x.min(axis=0), np.ptp(x, axis=0)
        cache: dict[tuple[int, int], np.ndarray] = {}

        def cut(u: int, n: int) -> np.ndarray:
            if (u, n) not in cache:
                edges = lo[u] + span[u] * np.arange(1, n) / n
                cache[(u, n)] = np.searchsorted(edges, x[:, u], side="right")
            return cache[(u, n)]

        for u in range(3):
            if span[u] > 0:
                out.append(cut(u, k))
        for a in range(2, k // 2 + 1):
            b = k // a
            if a * b != k:
                continue
            for u in range(3):
                for v in range(3):
                    if u != v and span[u] > 0 and span[v] > 0 and not (a == b and u > v):
                        out.append(cut(u, a) * b + cut(v, b))
    return out


@dataclass
class _Option:
    """One way to split a part: its pieces (index arrays) and their quick spheres."""

    pieces: list[np.ndarray]
    centers: np.ndarray
    radii: np.ndarray
    mask: np.ndarray | None = None  # which volume samples the spheres cover


def _options(points: np.ndarray, proj: np.ndarray, idx: np.ndarray, k: int, seed: int) -> list[_Option]:
    """The candidate splits of part ``idx`` into ``k`` pieces (none if it cannot split).

    Candidates: the equal-width grids and slabs of :func:`_grid_splits` and k-means
    trimmed by sphere growth (:func:`_kmeans_split`); only those with the most
    pieces are kept, duplicates once.
    """
    P = points[idx]
    if k < 2 or len(idx) < 2 or not np.ptp(P, axis=0).any():
        return []
    labels = _grid_splits(P, k)
    splits = [[p for p in (np.flatnonzero(lab == j) for j in range(k)) if len(p)] for lab in labels]
    splits.append(_kmeans_split(P, min(k, len(idx)), seed))
    most = max(len(s) for s in splits)
    if most < 2:
        return []
    out, seen = [], set()
    for s in splits:
        if len(s) != most:
            continue
        key = frozenset(hash(p[:8].tobytes() + p[-8:].tobytes() + bytes(len(p))) for p in s)
        if key in seen:
            continue
        seen.add(key)
        parts = [idx[p] for p in s]
        balls = [quick_sphere(points[g], proj[g]) for g in parts]
        out.append(_Option(parts, np.array([b[0] for b in balls]), np.array([b[1] for b in balls])))
    return out


def _samples(lo: np.ndarray, hi: np.ndarray, n: int) -> np.ndarray:
    """``n`` evenly spread points in the box lo..hi (the R2 low-discrepancy sequence)."""
    g = 1.2207440846057596  # the root of x^4 = x + 1: R2 in three dimensions
    alpha = 1.0 / g ** np.arange(1, 4)
    u = (0.5 + np.arange(1, n + 1)[:, None] * alpha[None]) % 1.0
    return lo + u * (hi - lo)


def _cover(samples: np.ndarray, centers: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """(n,) bool: samples inside any of the spheres."""
    d2 = (np.sum(samples**2, axis=1)[:, None] - 2.0 * samples @ centers.T + np.sum(centers**2, axis=1)[None])
    return (d2 <= radii[None] ** 2).any(axis=1)


def _choose(samples: np.ndarray, options: list[list[_Option]], fixed: np.ndarray,
            passes: int = 3) -> tuple[list[int], int]:
    """Pick one option per part so the union of all the new spheres is smallest.

    Coordinate descent: start from each part's own best, then let each part change
    its choice while the others stay, until nothing improves.  The union is counted
    on ``samples`` (plus ``fixed``: spheres that stay).  Returns the choices (-1 for
    a part without options) and the covered sample count.
    """
    for opts in options:
        for o in opts:
            if o.mask is None:
                o.mask = _cover(samples, o.centers, o.radii)
    choice = [int(np.argmin([np.count_nonzero(o.mask) for o in opts])) if opts else -1 for opts in options]

    def rest(skip: int) -> np.ndarray:
        m = fixed.copy()
        for j, opts in enumerate(options):
            if j != skip and opts:
                m |= opts[choice[j]].mask
        return m

    for _ in range(passes):
        changed = False
        for i, opts in enumerate(options):
            if len(opts) < 2:
                continue
            others = rest(i)
            counts = [np.count_nonzero(others | o.mask) for o in opts]
            best = int(np.argmin(counts))
            if counts[best] < counts[choice[i]]:
                choice[i], changed = best, True
        if not changed:
            break
    return choice, int(np.count_nonzero(rest(-1)))


def _representatives(points: np.ndarray, most: int) -> tuple[np.ndarray, np.ndarray]:
    """At most about ``most`` points standing for ``points``: the distinct points, or
    when there are more, the means of the occupied cells of a grid.  Returns
    (reps (m, 3), inverse (n,)) with points[i] represented by reps[inverse[i]]."""
    lo = points.min(axis=0)
    span = float(np.ptp(points, axis=0).max()) or 1.0
    cells = 1024
    while True:
        q = np.floor((points - lo) / span * cells).astype(np.int64)
        key = (q[:, 0] * (cells + 1) + q[:, 1]) * (cells + 1) + q[:, 2]
        _, inverse, counts = np.unique(key, return_inverse=True, return_counts=True)
        if len(counts) <= most or cells <= 4:
            break
        cells = max(4, int(cells * (most / len(counts)) ** 0.5 * 0.9))
    inverse = inverse.reshape(-1)
    reps = np.column_stack([np.bincount(inverse, points[:, j]) for j in range(3)]) / counts[:, None]
    return reps, inverse


_REPS = 2048  # decisions are made on at most about this many representative points


def _first_split(U: np.ndarray, fixed: np.ndarray, reps: np.ndarray, proj: np.ndarray, opts: list[_Option],
                 branching: int, seed: int, lookahead: int) -> tuple[list[int], list[list[_Option]]]:
    """The root's split, chosen with lookahead: the ``lookahead`` candidates claiming
    least of the samples ``U`` (``fixed``: claimed already) are each scored by the
    best level below them.  Returns ([the candidate chosen], the options chosen below
    it: the next level, planned)."""
    for o in opts:
        o.mask = _cover(U, o.centers, o.radii)
    best = None
    for j in np.argsort([np.count_nonzero(o.mask) for o in opts], kind="stable")[:lookahead]:
        below = [_options(reps, proj, g, branching, seed + 1 + t) for t, g in enumerate(opts[j].pieces)]
        keep = fixed.copy()
        for o2, c, r in zip(below, opts[j].centers, opts[j].radii):
            if not o2:
                keep |= _cover(U, c[None], np.array([r]))
        choice_below, total = _choose(U, below, keep)
        if best is None or total < best[0]:
            best = (total, int(j), below, choice_below)
    planned = [[opts2[c2]] if c2 >= 0 else [] for opts2, c2 in zip(best[2], best[3])]
    for opts2 in planned:
        for o in opts2:
            o.mask = None
    return [best[1]], planned


def build_sphere_tree(points: np.ndarray, levels: int = 3, branching: int = 4, seed: int = 0,
                      lookahead: int = 4, samples: int = 8192) -> SphereTree:
    """Top-down sphere tree over ``points`` (vertices plus surface samples).

    Each sphere is the minimum enclosing sphere of its part; its children split that
    part, so every point lies in a leaf and in every ancestor of that leaf by
    construction.  A part with fewer distinct points than ``branching`` gets fewer
    children; a single-point part is a leaf.

    The splits are chosen for the volume the spheres claim, a level at a time: each
    part has candidate splits (grids and slabs along its axes, k-means), and the
    choice per part minimises the volume of the union of all the level's new spheres
    (counted on low-discrepancy samples), so neighbouring parts' spheres may share
    space — in a hollow model, columns spanning two facing walls beat plates cut in
    halves.  The first split looks one level ahead: its ``lookahead`` best candidates
    are each scored by the union of the best level below them.  Decisions are made
    on representatives of the points (grid-cell means, see
    :func:`_representatives`); the spheres themselves are exact over all points.
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(points) == 0:
        raise ValueError("no points to wrap")
    if levels < 1 or branching < 1:
        raise ValueError("levels and branching must be at least 1")
    reps, inverse = _representatives(points, _REPS)
    proj = reps @ DIRECTIONS.T
    # the partition of the representatives, level by level: (parent node, rep indices)
    parts: list[list[tuple[int, np.ndarray]]] = [[(-1, np.arange(len(reps)))]]
    planned: list[_Option] | None = None  # the level below the root, chosen with lookahead
    for depth in range(2, levels + 1):
        frontier = parts[-1]
        if planned is None:
            options_per = [_options(reps, proj, idx, branching, seed + j) for j, (_, idx) in enumerate(frontier)]
        else:
            options_per, planned = planned, None
        balls = [(o.centers, o.radii) for opts in options_per for o in opts]
        if not balls:
            break
        C = np.vstack([b[0] for b in balls])
        R = np.concatenate([b[1] for b in balls])
        U = _samples((C - R[:, None]).min(axis=0), (C + R[:, None]).max(axis=0), samples)
        fixed = np.zeros(len(U), dtype=bool)
        for (_, idx), opts in zip(frontier, options_per):
            if not opts and len(idx):  # a part that stays a leaf keeps its sphere
                c, r = quick_sphere(reps[idx], proj[idx])
                fixed |= _cover(U, c[None], np.array([r]))
        if len(frontier) == 1 and depth < levels and len(options_per[0]) > 1:
            choice, planned = _first_split(U, fixed, reps, proj, options_per[0], branching, seed, lookahead)
        else:
            choice, _ = _choose(U, options_per, fixed)
        nxt = []
        for j, ((_, idx), opts, c) in enumerate(zip(frontier, options_per, choice)):
            if c >= 0:
                nxt.extend((j, piece) for piece in opts[c].pieces)
        if not nxt:
            break
        parts.append(nxt)
    # the same partition of the points themselves
    point_parts = [[(par, np.flatnonzero(np.isin(inverse, idx))) for par, idx in row] for row in parts]
    tree = _exact_tree(points, point_parts, seed)
    # the plain k-means tree (the previous construction) as a whole alternative: keep
    # whichever claims less volume with the exact spheres
    if levels > 1 and branching > 1:
        other = _exact_tree(points, _kmeans_parts(points, levels, branching, seed), seed)
        if len(other.leaves()) >= len(tree.leaves()) and _union_count(other) < _union_count(tree):
            tree = other
    return tree


def _kmeans_parts(points: np.ndarray, levels: int, branching: int, seed: int) -> list[list[tuple[int, np.ndarray]]]:
    """The partition of plain top-down k-means (:func:`_kmeans_split` at every part)."""
    parts = [[(-1, np.arange(len(points)))]]
    first = 0  # tree index of the first part of the level (the seed of each split as before)
    for _ in range(2, levels + 1):
        nxt = []
        for j, (_, idx) in enumerate(parts[-1]):
            if len(idx) < 2 or not np.ptp(points[idx], axis=0).any():
                continue
            k = min(branching, len(np.unique(points[idx], axis=0)))
            pieces = _kmeans_split(points[idx], k, seed + first + j) if k > 1 else []
            if len(pieces) >= 2:
                nxt.extend((j, idx[p]) for p in pieces)
        if not nxt:
            break
        first += len(parts[-1])
        parts.append(nxt)
    return parts


def _exact_tree(points: np.ndarray, parts: list[list[tuple[int, np.ndarray]]], seed: int) -> SphereTree:
    """The tree of exact minimum spheres over a partition given level by level as
    (index of the parent in the level above, point indices), parents first."""
    centers, radii, parent, level = [], [], [], []
    ids: list[list[int]] = []
    for depth, row in enumerate(parts, start=1):
        here = []
        for par, idx in row:
            c, r = min_enclosing_sphere(points[idx], seed)
            here.append(len(radii))
            centers.append(c), radii.append(r), level.append(depth)
            parent.append(-1 if depth == 1 else ids[-1][par])
        ids.append(here)
    return SphereTree(np.array(centers), np.array(radii), np.array(parent), np.array(level))


def _union_count(tree: SphereTree, samples: int = 65536) -> float:
    """Volume of the union of the leaf spheres (low-discrepancy samples in their box)."""
    leaves = tree.leaves()
    C, R = tree.centers[leaves], tree.radii[leaves]
    lo, hi = (C - R[:, None]).min(axis=0), (C + R[:, None]).max(axis=0)
    U = _samples(lo, hi, samples)
    covered = sum(np.count_nonzero(_cover(U[s:s + 16384], C, R)) for s in range(0, samples, 16384))
    return covered / samples * float(np.prod(hi - lo))


def octree_spheres(points: np.ndarray, leaves: int) -> tuple[np.ndarray, np.ndarray]:
    """Hubbard's baseline: spheres circumscribing occupied octree cells.

    Starts from the cube around the points and splits the occupied cell with the
    largest sphere, best first, until there are at least ``leaves`` occupied cells
    (so the baseline never has fewer spheres than the tree it is compared with).
    Returns (centres (m, 3), radii (m,)).
    """
    points = np.asarray(points, dtype=np.float64)
    lo, hi = points.min(axis=0), points.max(axis=0)
    half = max(float((hi - lo).max()) / 2, 1e-9)
    heap: list[tuple[float, int, np.ndarray, float, np.ndarray]] = [(-half, 0, (lo + hi) / 2, half, np.arange(len(points)))]
    done: list[tuple[np.ndarray, float]] = []
    counter = 0
    while heap and len(heap) + len(done) < leaves:
        _, _, c, h, idx = heapq.heappop(heap)
        if len(np.unique(points[idx], axis=0)) < 2:
            done.append((c, h))  # one point: nothing to split
            continue
        octant = ((points[idx] >= c).astype(np.int64) * np.array([1, 2, 4])).sum(axis=1)
        for o in range(8):
            k = idx[octant == o]
            if len(k):
                sign = np.array([1 if o & 1 else -1, 1 if o & 2 else -1, 1 if o & 4 else -1])
                counter += 1
                heapq.heappush(heap, (-h / 2, counter, c + sign * h / 2, h / 2, k))
    cells = done + [(c, h) for _, _, c, h, _ in heap]
    return np.array([c for c, _ in cells]), np.array([h * np.sqrt(3.0) for _, h in cells])


def solid_inside(mesh):
    """A vectorised inside test for a model: ``f((n, 3)) -> (n,) bool``.

    Each connected part counts as solid: a closed part by ray parity (trimesh), an
    open one by its convex hull — open shells have no inside of their own, and the
    hull is what a collision would treat as the part.
    """
    m = mesh.copy()
    m.merge_vertices()
    parts = m.split(only_watertight=False) if len(m.faces) else []
    tests = []
    for part in parts:
        if part.is_watertight and part.is_winding_consistent and part.volume > 0:
            tests.append(part)
        else:
            try:
                tests.append(part.convex_hull)
            except Exception:  # a flat or tiny part encloses nothing
                continue

    def inside(points: np.ndarray) -> np.ndarray:
        out = np.zeros(len(points), dtype=bool)
        for part in tests:
            lo, hi = part.bounds
            cand = np.flatnonzero(~out & np.all((points >= lo) & (points <= hi), axis=1))
            if len(cand):
                out[cand] = part.contains(points[cand])
        return out

    return inside


def excess_volume(centers: np.ndarray, radii: np.ndarray, inside, samples: int = 100_000,
                  seed: int = 0) -> float:
    """Volume of the union of spheres outside the model, over the model's volume.

    Monte Carlo over the spheres' bounding box, which holds the whole model when the
    spheres enclose its surface; ``inside`` is the model's inside test
    (:func:`solid_inside`).
    """
    lo = (centers - radii[:, None]).min(axis=0)
    hi = (centers + radii[:, None]).max(axis=0)
    rng = np.random.default_rng(seed)
    p = lo + rng.random((samples, 3)) * (hi - lo)
    in_spheres = np.zeros(samples, dtype=bool)
    for c, r in zip(centers, radii):
        in_spheres |= np.sum((p - c) ** 2, axis=1) <= r * r
    in_model = inside(p)
    solid = int(in_model.sum())
    if solid == 0:
        return float("inf")
    return float(np.sum(in_spheres & ~in_model)) / solid


#: a triangle no leaf holds is halved until it is at most this fraction of the
#: smallest leaf's radius long
_COVER_EDGE = 0.25
#: ... or until the halving has made this many vertices (a bound on time and memory)
_COVER_VERTICES = 2_000_000


def _halve(v: np.ndarray, f: np.ndarray, first: int) -> tuple[np.ndarray, np.ndarray]:
    """Triangles ``f`` of vertices ``v`` halved across their longest edge: the midpoints
    (new vertices, numbered from ``first``) and the 2 x len(f) halves."""
    t = v[f]
    edges = np.linalg.norm(np.roll(t, -1, axis=1) - t, axis=2)      # edge i: corner i -> i+1
    i = np.argmax(edges, axis=1)
    rows = np.arange(len(f))
    a, b, c = f[rows, i], f[rows, (i + 1) % 3], f[rows, (i + 2) % 3]
    m = first + np.arange(len(f))
    return (v[a] + v[b]) / 2, np.concatenate([np.stack([a, m, c], axis=1), np.stack([m, b, c], axis=1)])


def cover_surface(tree: SphereTree, vertices: np.ndarray, faces: np.ndarray, seed: int = 0) -> SphereTree:
    """The tree refitted to hold the model's whole surface, not only the points it was
    built on (vertices and surface samples: a triangle whose corners fall in different
    leaves may bulge out between them).

    Each triangle is given to one leaf: among the leaves whose sphere holds its three
    corners the one whose centre is nearest; a triangle no leaf holds is halved across
    its longest edge, again and again, down to a quarter of the smallest leaf's radius,
    and a piece still held by none goes to the leaf it sticks out of least.  Then every
    sphere becomes the minimum sphere of the corners of the triangles given to its
    subtree.  A ball is convex, so holding a triangle's corners is holding the triangle:
    every point of the surface is in a leaf and in all the leaf's ancestors.  A leaf
    given no triangle (its part lies wholly in its neighbours) keeps its sphere.  The
    tree's shape (ids, parents, levels) does not change.
    """
    leaves = tree.leaves()
    C, R = tree.centers[leaves], tree.radii[leaves]
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    pending = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    span = (float(np.ptp(v, axis=0).max()) if len(v) else 1.0) or 1.0
    positive = R[R > 1e-9 * span]
    edge = max(_COVER_EDGE * (float(positive.min()) if len(positive) else span), 1e-9 * span)
    rr = np.maximum(R, 1e-12 * span)

    def distances(points: np.ndarray) -> np.ndarray:
        return np.sqrt(((points[:, None, :] - C[None]) ** 2).sum(axis=2))     # (n, L)

    verts, dist = [v], [distances(v)]
    given_f, given_to = [], []
    step = max(1, 3_000_000 // max(3 * len(leaves), 1))
    for _ in range(64):
        allv = verts[0] if len(verts) == 1 else np.concatenate(verts)
        alld = dist[0] if len(dist) == 1 else np.concatenate(dist)
        verts, dist = [allv], [alld]
        left = []
        for s0 in range(0, len(pending), step):
            f = pending[s0:s0 + step]
            d = alld[f]                                            # (k, 3, L)
            out = (d - R[None, None]).max(axis=1)                  # (k, L) how far it sticks out
            holds = out <= 1e-12 * span
            held = holds.any(axis=1)
            near = np.where(holds, d.mean(axis=1) / rr[None], np.inf)
            given_f.append(f[held])
            given_to.append(np.argmin(near[held], axis=1))
            t = allv[f[~held]]
            long = np.linalg.norm(np.roll(t, -1, axis=1) - t, axis=2).max(axis=1) > edge
            given_f.append(f[~held][~long])                        # short enough: the least bad leaf
            given_to.append(np.argmin(out[~held][~long], axis=1))
            left.append(f[~held][long])
        pending = np.concatenate(left) if left else np.zeros((0, 3), dtype=np.int64)
        if not len(pending) or len(allv) > _COVER_VERTICES:
            break
        mids, pending = _halve(allv, pending, len(allv))
        verts.append(mids)
        dist.append(distances(mids))
    allv = verts[0] if len(verts) == 1 else np.concatenate(verts)
    if len(pending):                                               # the vertex budget ran out
        d = (np.concatenate(dist) if len(dist) > 1 else dist[0])[pending]
        given_f.append(pending)
        given_to.append(np.argmin((d - R[None, None]).max(axis=1), axis=1))
    f = np.concatenate(given_f)
    owner = np.concatenate(given_to)
    # the vertices given to each sphere: a leaf's own, and every node's through its leaves
    given: dict[int, np.ndarray] = {}
    for k, leaf in enumerate(leaves):
        mine = f[owner == k]
        if not len(mine):
            continue
        for node in tree.ancestors(int(leaf)):
            mask = given.setdefault(int(node), np.zeros(len(allv), dtype=bool))
            mask[mine.ravel()] = True
    centers, radii = tree.centers.copy(), tree.radii.copy()
    for node, mask in given.items():
        centers[node], radii[node] = min_enclosing_sphere(allv[mask], seed)
    return SphereTree(centers, radii, tree.parent.copy(), tree.level.copy())
