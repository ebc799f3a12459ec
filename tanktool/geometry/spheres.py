"""Sphere trees: the 2002 simulator's hierarchy of bounding spheres (§3.4.4.2).

Level 1 is one sphere around the whole vehicle; each sphere's children wrap parts of
its part of the model, down to the leaves.  A test against another tree, a point or
a shell's path starts at the root and goes one level deeper only where the level
above overlapped, so a miss costs one sphere test.

Everything here is in the **vehicle frame** (+x forward, +y up, +z right) until a
pose moves it: pose = (position (3,) in the world, heading θ about +y) with vehicle +x
mapped to world (cos θ, 0, sin θ) and vehicle +z (right) to world (-sin θ, 0, cos θ).

File format (``spheres.txt``): one sphere a line, ``id parent level cx cy cz r``,
root first with parent -1 and level 1, parents before their children, ``#`` starts a
comment.
"""

from __future__ import annotations

import heapq
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import numpy as np

from ..errors import FormatError

# ---------------------------------------------------------------------------
# the tree


@dataclass
class SphereTree:
    """A sphere hierarchy stored as flat arrays, root at index 0, parents first.

    Attributes
    ----------
    centers : (k, 3) float, vehicle frame, metres
    radii : (k,) float, metres
    parent : (k,) int, -1 for the root
    level : (k,) int, 1 for the root
    """

    centers: np.ndarray
    radii: np.ndarray
    parent: np.ndarray
    level: np.ndarray
    _children: list[np.ndarray] = field(default_factory=list, repr=False, compare=False)

    def __post_init__(self) -> None:
        self.centers = np.asarray(self.centers, dtype=np.float64).reshape(-1, 3)
        self.radii = np.asarray(self.radii, dtype=np.float64).reshape(-1)
        self.parent = np.asarray(self.parent, dtype=np.int64).reshape(-1)
        self.level = np.asarray(self.level, dtype=np.int64).reshape(-1)
        k = len(self.radii)
        if not (len(self.centers) == len(self.parent) == len(self.level) == k) or k == 0:
            raise ValueError("sphere tree arrays must be non-empty and of equal length")
        order = np.argsort(self.parent[1:], kind="stable") + 1
        counts = np.bincount(self.parent[1:], minlength=k) if k > 1 else np.zeros(k, np.int64)
        splits = np.cumsum(counts)[:-1]
        self._children = list(np.split(order, splits)) if k > 1 else [np.zeros(0, np.int64)]
        self._leaf = np.array([len(c) == 0 for c in self._children])
        # row i: the spheres that replace i one level down (its children, or i itself
        # for a leaf), padded with -1, so a whole frontier expands in one numpy step
        width = max(1, max(len(c) for c in self._children))
        self._expand = np.full((k, width), -1, dtype=np.int64)
        for i, c in enumerate(self._children):
            row = c if len(c) else np.array([i])
            self._expand[i, : len(row)] = row

    def __len__(self) -> int:
        return len(self.radii)

    @property
    def levels(self) -> int:
        return int(self.level.max())

    def children(self, i: int) -> np.ndarray:
        """Indices of sphere ``i``'s children (empty for a leaf)."""
        return self._children[i]

    def is_leaf(self) -> np.ndarray:
        """(k,) bool: True for spheres without children."""
        return self._leaf.copy()

    def leaves(self) -> np.ndarray:
        """Indices of the leaf spheres, in file order."""
        return np.flatnonzero(self.is_leaf())

    def ancestors(self, i: int) -> list[int]:
        """``[i, parent(i), ..., root]``."""
        out = [int(i)]
        while self.parent[out[-1]] >= 0:
            out.append(int(self.parent[out[-1]]))
        return out


def to_world(tree: SphereTree, position: Sequence[float], heading: float) -> np.ndarray:
    """Sphere centres in the world for a vehicle at ``position`` facing ``heading``.

    Returns (k, 3); radii do not change under a rigid move.
    """
    return _transform(tree.centers, np.asarray(position, dtype=np.float64), float(heading))


def _transform(points: np.ndarray, position: np.ndarray, heading: float) -> np.ndarray:
    c, s = np.cos(heading), np.sin(heading)
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    return np.column_stack([position[0] + c * x - s * z, position[1] + y, position[2] + s * x + c * z])


Pose = tuple  # (position (3,), heading θ) — a plain tuple so the simulation needs no import


# ---------------------------------------------------------------------------
# queries


def tree_overlap(tA: SphereTree, poseA: Pose, tB: SphereTree, poseB: Pose) -> list[tuple[int, int]]:
    """Pairs of leaves (leafA, leafB) whose spheres overlap, found level by level.

    Starts with the two roots; a pair of overlapping spheres is replaced by the pairs
    of their children (a leaf stays paired with the other's children while the other
    tree is deeper), so a miss at any level ends that branch.  Touching counts as
    overlapping.
    """
    ca = to_world(tA, *poseA)
    cb = to_world(tB, *poseB)
    ia = np.zeros(1, np.int64)
    ib = np.zeros(1, np.int64)
    leafA, leafB = tA._leaf, tB._leaf
    found: list[tuple[int, int]] = []
    while len(ia):
        d2 = np.sum((ca[ia] - cb[ib]) ** 2, axis=1)
        hit = d2 <= (tA.radii[ia] + tB.radii[ib]) ** 2
        ia, ib = ia[hit], ib[hit]
        done = leafA[ia] & leafB[ib]
        found.extend(zip(ia[done].tolist(), ib[done].tolist()))
        ia, ib = ia[~done], ib[~done]
        # a leaf stays itself while the other side goes a level down
        ea, eb = tA._expand[ia], tB._expand[ib]
        valid = (ea >= 0)[:, :, None] & (eb >= 0)[:, None, :]
        ia = np.broadcast_to(ea[:, :, None], valid.shape)[valid]
        ib = np.broadcast_to(eb[:, None, :], valid.shape)[valid]
    return sorted(found)


def point_query(tree: SphereTree, pose: Pose, p: Sequence[float]) -> list[int]:
    """Leaves containing world point ``p`` whose every ancestor also contains it."""
    centers = to_world(tree, *pose)
    p = np.asarray(p, dtype=np.float64)
    inside = np.sum((centers - p) ** 2, axis=1) <= tree.radii**2
    return _descend(tree, inside)


def segment_query(tree: SphereTree, pose: Pose, a: Sequence[float], b: Sequence[float]) -> list[int]:
    """Leaves the world segment a-b touches, with every ancestor touched too.

    A shell's flight during one step is such a segment, so fast shells cannot jump
    through a thin vehicle between two steps.
    """
    centers = to_world(tree, *pose)
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    hit = segment_sphere_hits(a, b, centers, tree.radii)
    return _descend(tree, hit)


def segment_sphere_hits(a: np.ndarray, b: np.ndarray, centers: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """(k,) bool: does segment a-b come within ``radii`` of each centre?"""
    d = b - a
    dd = float(d @ d)
    if dd == 0.0:
        t = np.zeros(len(centers))
    else:
        t = np.clip((centers - a) @ d / dd, 0.0, 1.0)
    closest = a + t[:, None] * d
    return np.sum((centers - closest) ** 2, axis=1) <= radii**2


def _descend(tree: SphereTree, hit: np.ndarray) -> list[int]:
    """Walk down from the root through spheres marked ``hit``; return the leaves reached."""
    if not hit[0]:
        return []
    out: list[int] = []
    frontier = [0]
    while frontier:
        nxt: list[int] = []
        for i in frontier:
            kids = tree.children(i)
            if len(kids) == 0:
                out.append(i)
            else:
                nxt.extend(int(k) for k in kids[hit[kids]])
        frontier = nxt
    return sorted(out)


# ---------------------------------------------------------------------------
# minimum enclosing sphere


def _ball_from(boundary: list[np.ndarray]) -> tuple[np.ndarray, float]:
    """Smallest ball with all of ``boundary`` (1..4 points) on its surface."""
    p0 = boundary[0]
    if len(boundary) == 1:
        return p0.copy(), 0.0
    # centre = p0 + A^T x with the centre equidistant from all points, lying in their
    # affine hull: solve the (m-1)x(m-1) Gram system; degenerate sets fall back to lstsq
    A = np.array([p - p0 for p in boundary[1:]])
    G = A @ A.T
    rhs = 0.5 * np.sum(A * A, axis=1)
    try:
        x = np.linalg.solve(G, rhs)
        if not np.all(np.isfinite(x)):
            raise np.linalg.LinAlgError
    except np.linalg.LinAlgError:
        x = np.linalg.lstsq(G, rhs, rcond=None)[0]
    c = p0 + A.T @ x
    r = max(float(np.linalg.norm(p - c)) for p in boundary)
    return c, r


def _welzl(P: np.ndarray, n: int, boundary: list[np.ndarray]) -> tuple[np.ndarray, float]:
    """Minimum ball of P[:n] with ``boundary`` on its surface (Welzl, iterative over P).

    The scan for the next point outside the current ball is vectorised; recursion
    only goes as deep as the boundary set (at most 4 points in 3D).
    """
    if boundary:
        c, r = _ball_from(boundary)
    else:
        c, r = P[0].copy(), 0.0
    if len(boundary) == 4:
        return c, r
    start = 0
    while True:
        if start >= n:
            return c, r
        d2 = np.sum((P[start:n] - c) ** 2, axis=1)
        tol = (r * (1 + 1e-10) + 1e-12) ** 2
        out = np.flatnonzero(d2 > tol)
        if len(out) == 0:
            return c, r
        i = start + int(out[0])
        c, r = _welzl(P, i, boundary + [P[i]])
        start = i + 1


def min_enclosing_sphere(points: np.ndarray, seed: int = 0) -> tuple[np.ndarray, float]:
    """Exact minimum enclosing sphere of (n, 3) points (Welzl's algorithm).

    The returned radius is the true maximum distance from the
    centre, so every point is inside whatever rounding happened.
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(pts) == 0:
        raise ValueError("no points")
    # Welzl on a small core set, growing it by the points still outside: the extreme
    # points along 13 directions start it, and each round adds the farthest
    # violators.  The answer is the exact minimum sphere of the core set, which
    # encloses everything once no point is outside, i.e. the exact sphere of all.
    dirs = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [1, -1, 0], [1, 0, 1], [1, 0, -1],
                     [0, 1, 1], [0, 1, -1], [1, 1, 1], [1, 1, -1], [1, -1, 1], [-1, 1, 1]], dtype=np.float64)
    proj = pts @ dirs.T
    core = np.unique(np.concatenate([proj.argmax(axis=0), proj.argmin(axis=0)]))
    rng = np.random.default_rng(seed)
    for _ in range(100):
        cand = pts[core]
        cand = cand[rng.permutation(len(cand))]
        c, r = _welzl(cand, len(cand), [])
        d2 = np.sum((pts - c) ** 2, axis=1)
        out = np.flatnonzero(d2 > (r * (1 + 1e-9) + 1e-12) ** 2)
        if len(out) == 0:
            break
        worst = out[np.argsort(d2[out])[-16:]]
        core = np.union1d(core, worst)
    r = float(np.sqrt(np.max(np.sum((pts - c) ** 2, axis=1))))
    return c, r


# ---------------------------------------------------------------------------
# building


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


def _split(points: np.ndarray, k: int, seed: int) -> list[np.ndarray]:
    """Split a part into up to ``k`` compact pieces (index arrays).

    Each child sphere is the minimum sphere of its piece, so compact pieces mean small
    spheres: k-means clusters, trimmed by the sphere-growing rounds of
    :func:`_kmeans_split`.  (Repeated best plane cuts were tried as a second candidate
    and chosen by total sphere volume: no better on the bench models, twice slower.)
    """
    uniq = np.unique(points, axis=0)
    k = min(k, len(uniq))
    if k <= 1:
        return [np.arange(len(points))]
    return _kmeans_split(points, k, seed)


def build_sphere_tree(points: np.ndarray, levels: int = 3, branching: int = 4, seed: int = 0) -> SphereTree:
    """Top-down sphere tree over ``points`` (vertices plus surface samples).

    Each sphere is the minimum enclosing sphere of its part; its children split that
    part, so every point lies in a leaf and in every ancestor of that leaf by
    construction.  A part with fewer distinct points than ``branching`` gets fewer
    children; a single-point part is a leaf.
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(points) == 0:
        raise ValueError("no points to wrap")
    if levels < 1 or branching < 1:
        raise ValueError("levels and branching must be at least 1")
    centers, radii, parent, level = [], [], [], []
    c, r = min_enclosing_sphere(points, seed)
    centers.append(c), radii.append(r), parent.append(-1), level.append(1)
    frontier = [(0, np.arange(len(points)))]
    for depth in range(2, levels + 1):
        nxt = []
        for node, idx in frontier:
            if branching < 2:
                continue
            pieces = _split(points[idx], branching, seed + node)
            if len(pieces) < 2:
                continue
            for piece in pieces:
                part = idx[piece]
                c, r = min_enclosing_sphere(points[part], seed)
                centers.append(c), radii.append(r), parent.append(node), level.append(depth)
                nxt.append((len(radii) - 1, part))
        frontier = nxt
    return SphereTree(np.array(centers), np.array(radii), np.array(parent), np.array(level))


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


def contains_points(tree: SphereTree, points: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """(n,) bool: is each point inside some leaf and inside every ancestor of it?"""
    points = np.asarray(points, dtype=np.float64)
    inside = np.sum((points[:, None, :] - tree.centers[None]) ** 2, axis=2) <= (tree.radii[None] + tol) ** 2
    ok = np.zeros(len(points), dtype=bool)
    for leaf in tree.leaves():
        chain = tree.ancestors(leaf)
        ok |= inside[:, chain].all(axis=1)
    return ok


# ---------------------------------------------------------------------------
# spheres.txt


def format_spheres(tree: SphereTree, header: str = "") -> str:
    """``spheres.txt`` text: ``id parent level cx cy cz r`` a line, 4 decimals (0.1 mm).

    Radii are rounded up and centres to nearest so the written tree still encloses
    what the exact one did (a rounded centre moves at most 0.5e-4 * sqrt(3) m, added
    to the radius).
    """
    lines = [f"# {line}" for line in header.splitlines()] if header else []
    lines.append("# id parent level cx cy cz r   (vehicle frame: +x forward, +y up, +z right; metres)")
    slack = 0.5e-4 * np.sqrt(3.0)
    for i in range(len(tree)):
        cx, cy, cz = (float(v) for v in np.round(tree.centers[i], 4))
        r = np.ceil((tree.radii[i] + slack) * 1e4) / 1e4
        lines.append(f"{i} {int(tree.parent[i])} {int(tree.level[i])} {cx:.4f} {cy:.4f} {cz:.4f} {r:.4f}")
    return "\n".join(lines) + "\n"


def write_spheres(path: str | os.PathLike, tree: SphereTree, header: str = "") -> None:
    from ..formats.bundle import atomic_write_text

    atomic_write_text(path, format_spheres(tree, header))


def read_spheres(path: str | os.PathLike) -> SphereTree:
    """Read ``spheres.txt``; any defect is a FormatError naming the file and line."""
    from ..formats.bundle import read_input_text

    path = Path(path)
    text = read_input_text(path, "a spheres.txt file")
    rows: list[tuple[int, int, int, float, float, float, float]] = []
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        parts = line.split()
        where = f"{path}:{lineno}"
        if len(parts) != 7:
            raise FormatError(f"{where}: expected 7 fields 'id parent level cx cy cz r', got {len(parts)}")
        try:
            sid, par, lev = int(parts[0]), int(parts[1]), int(parts[2])
            cx, cy, cz, r = (float(v) for v in parts[3:])
        except ValueError:
            raise FormatError(f"{where}: expected integers id parent level then 4 numbers, got {line!r}") from None
        if not all(np.isfinite([cx, cy, cz, r])):
            raise FormatError(f"{where}: centre and radius must be finite numbers")
        if r < 0:
            raise FormatError(f"{where}: radius must not be negative, got {r}")
        n = len(rows)
        if sid != n:
            raise FormatError(f"{where}: expected sphere id {n} (ids count up from 0), got {sid}")
        if n == 0:
            if par != -1 or lev != 1:
                raise FormatError(f"{where}: the first sphere must be the root (parent -1, level 1)")
        else:
            if not (0 <= par < n):
                raise FormatError(f"{where}: parent {par} must be an earlier sphere id (0..{n - 1})")
            if lev != rows[par][2] + 1:
                raise FormatError(f"{where}: level {lev} must be one more than its parent's ({rows[par][2]})")
        rows.append((sid, par, lev, cx, cy, cz, r))
    if not rows:
        raise FormatError(f"{path}: no spheres (expected at least the root line)")
    arr = np.array(rows, dtype=np.float64)
    return SphereTree(arr[:, 3:6], arr[:, 6], arr[:, 1].astype(np.int64), arr[:, 2].astype(np.int64))


# ---------------------------------------------------------------------------
# tightness


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
