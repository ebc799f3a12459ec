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

from typing import Sequence

import numpy as np

from ..formats.spheres_txt import SphereTree, format_spheres, read_spheres, write_spheres  # noqa: F401  (re-exported: spheres.txt is read and written in formats/spheres_txt.py)

# ---------------------------------------------------------------------------
# the tree


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


def contains_points(tree: SphereTree, points: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """(n,) bool: is each point inside some leaf and inside every ancestor of it?"""
    points = np.asarray(points, dtype=np.float64)
    inside = np.sum((points[:, None, :] - tree.centers[None]) ** 2, axis=2) <= (tree.radii[None] + tol) ** 2
    ok = np.zeros(len(points), dtype=bool)
    for leaf in tree.leaves():
        chain = tree.ancestors(leaf)
        ok |= inside[:, chain].all(axis=1)
    return ok
