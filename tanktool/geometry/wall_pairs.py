"""Pairs of walls that repeat, overlap or cross each other; the importer's repairs.

:func:`classify_pairs` is the pair test behind ``check``'s A202 (the same wall twice),
A203 (two walls overlapping along their length, same free side) and A204 (an X
crossing): candidate pairs from an STR tree, classified all at once with numpy.
``import-arena`` runs the same test on the walls it is about to write
(:func:`repair_walls`): what it can repair it repairs -- repeated and overlapping
walls on one line become one wall per stretch, a wall whose normal points away
from the free space it bounds is turned round, thin walls facing into a pocket closed
by thin walls alone (which check takes as solid) are left out -- and it reports what
is left, so an
import never hands over walls that fail their own check without saying so.

Walls here are (n, 2, 2) segments with Direction +1 (the free space on their left),
as the importer writes them; ``direction`` (n,) gives the sign otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import shapely
from shapely import STRtree


@dataclass
class Pairs:
    """Classified wall pairs: indices ``a < b`` into the walls (as given)."""

    repeat: tuple[np.ndarray, np.ndarray]
    overlap: tuple[np.ndarray, np.ndarray, np.ndarray]  # (a, b, length of the overlap)
    cross: tuple[np.ndarray, np.ndarray, np.ndarray]    # (a, b, (k, 2) crossing point)


def _empty_pairs() -> Pairs:
    e = np.zeros(0, dtype=np.int64)
    return Pairs((e, e), (e, e, np.zeros(0)), (e, e, np.zeros((0, 2))))


def classify_pairs(seg: np.ndarray, direction: np.ndarray, live: np.ndarray, tol: float) -> Pairs:
    """Repeats, overlaps and X crossings among the walls ``live`` (indices into
    ``seg``, no zero-length wall among them), ends and lines compared within ``tol``."""
    if len(live) < 2:
        return _empty_pairs()
    d = seg[:, 1] - seg[:, 0]
    length = np.hypot(d[:, 0], d[:, 1])
    lines = shapely.linestrings(seg[live])
    # within the tolerance, not only touching: a copy moved off its wall by a hair
    # (parallel, not meeting it) is a copy all the same
    i, j = STRtree(lines).query(lines, predicate="dwithin", distance=tol)
    keep = i < j
    a, b = live[i[keep]], live[j[keep]]
    if not len(a):
        return _empty_pairs()
    P, Q = seg[a, 0], seg[a, 1]
    R, S = seg[b, 0], seg[b, 1]
    u = d[a] / length[a, None]
    v = d[b] / length[b, None]

    def side(o, t, p):  # signed distance of p from the line through o along unit t
        return t[:, 0] * (p[:, 1] - o[:, 1]) - t[:, 1] * (p[:, 0] - o[:, 0])

    with np.errstate(all="ignore"):
        collinear = (np.abs(side(P, u, R)) <= tol) & (np.abs(side(P, u, S)) <= tol)
        # overlap of b's projection onto a
        r0 = np.einsum("ij,ij->i", R - P, u)
        s0 = np.einsum("ij,ij->i", S - P, u)
        overlap = np.minimum(np.maximum(r0, s0), length[a]) - np.maximum(np.minimum(r0, s0), 0.0)
        normal_a = np.stack([-u[:, 1], u[:, 0]], axis=1) * direction[a, None]
        normal_b = np.stack([-v[:, 1], v[:, 0]], axis=1) * direction[b, None]
        same_side = np.einsum("ij,ij->i", normal_a, normal_b) > 0
        same_ends = (((np.abs(P - R) <= tol).all(1) & (np.abs(Q - S) <= tol).all(1))
                     | ((np.abs(P - S) <= tol).all(1) & (np.abs(Q - R) <= tol).all(1)))
        # proper crossing: each wall's ends strictly on both sides of the other, away from its ends
        ca1, ca2 = side(P, u, R), side(P, u, S)
        cb1, cb2 = side(R, v, P), side(R, v, Q)
        cross = ((ca1 > tol) & (ca2 < -tol) | (ca1 < -tol) & (ca2 > tol)) & \
                ((cb1 > tol) & (cb2 < -tol) | (cb1 < -tol) & (cb2 > tol))
        t = ca1 / (ca1 - ca2)
    # two coincident walls with opposite normals are the shared face of two touching
    # solids (both normals point into solid, they cancel): legal, so only same-side pairs count
    dup = collinear & same_ends & same_side
    over = collinear & ~same_ends & same_side & (overlap > tol)
    x = cross & ~collinear
    point = R[x] + t[x, None] * (S[x] - R[x])
    return Pairs((a[dup], b[dup]), (a[over], b[over], overlap[over]), (a[x], b[x], point))


def merge_overlaps(seg: np.ndarray, tol: float) -> tuple[np.ndarray, int]:
    """Walls (Direction +1) lying on one line with the same free side and overlapping
    by more than ``tol`` (or repeating each other) joined into one wall per stretch;
    walls that only meet end to end stay apart.  Returns (walls, how many fewer)."""
    if len(seg) < 2:
        return seg, 0
    d = seg[:, 1] - seg[:, 0]
    length = np.hypot(d[:, 0], d[:, 1])
    live = np.flatnonzero(length > 0)
    pairs = classify_pairs(seg, np.ones(len(seg)), live, tol)
    a = np.concatenate([pairs.repeat[0], pairs.overlap[0]])
    b = np.concatenate([pairs.repeat[1], pairs.overlap[1]])
    if not len(a):
        return seg, 0
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(seg)
    _, label = connected_components(coo_matrix((np.ones(len(a)), (a, b)), shape=(n, n)), directed=False)
    grouped = np.unique(np.concatenate([a, b]))
    keep = np.ones(n, dtype=bool)
    keep[grouped] = False
    out = [seg[keep]]
    for g in np.unique(label[grouped]):
        members = grouped[label[grouped] == g]
        out.append(_union_on_line(seg[members], tol))
    merged = np.concatenate(out)
    return merged, n - len(merged)


def _union_on_line(seg: np.ndarray, tol: float) -> np.ndarray:
    """Collinear same-way walls (k, 2, 2) as the union of their stretches along the
    line of the longest, in its direction; stretches overlapping by more than ``tol``
    join, stretches merely meeting stay two walls."""
    d = seg[:, 1] - seg[:, 0]
    k = int(np.argmax(np.hypot(d[:, 0], d[:, 1])))
    o, u = seg[k, 0], d[k] / np.hypot(*d[k])
    t = np.sort(np.einsum("kij,j->ki", seg - o, u), axis=1)
    t = t[np.argsort(t[:, 0])]
    runs = [[t[0, 0], t[0, 1]]]
    for lo, hi in t[1:]:
        if lo < runs[-1][1] - tol:
            runs[-1][1] = max(runs[-1][1], hi)
        else:
            runs.append([lo, hi])
    r = np.array(runs)
    return np.stack([o + r[:, :1] * u, o + r[:, 1:] * u], axis=1)


def orient_to_free(seg: np.ndarray, free, probe: float) -> tuple[np.ndarray, int]:
    """Walls (Direction +1) of the outline of ``free`` whose normal side lies outside
    it while their back lies inside, turned round.  Returns (walls, how many)."""
    if len(seg) == 0 or free is None or free.is_empty:
        return seg, 0
    mid = seg.mean(axis=1)
    d = seg[:, 1] - seg[:, 0]
    n = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-300)[:, None]
    front = shapely.contains_xy(free, *(mid + probe * n).T)
    back = shapely.contains_xy(free, *(mid - probe * n).T)
    bad = ~front & back
    if not bad.any():
        return seg, 0
    seg = seg.copy()
    seg[bad] = seg[bad][:, ::-1]
    return seg, int(bad.sum())


@dataclass
class Repairs:
    """What :func:`repair_walls` did and what it left."""

    merged: int = 0      # walls fewer after joining repeats and overlaps
    turned: int = 0      # walls turned round to face their free space
    crossings: list[np.ndarray] = field(default_factory=list)  # X crossings left, a point each
    overlaps: int = 0    # repeats / overlaps left (rounding beyond the tolerance)
    sealed: int = 0      # thin walls facing into pockets closed by thin walls, left out

    def remarks(self) -> list[str]:
        """One line per kind of repair done or problem left, for import-arena to print."""
        out = []
        if self.merged:
            out.append(f"{self.merged} repeated or overlapping wall(s) joined into one")
        if self.turned:
            out.append(f"{self.turned} wall(s) turned round to face their free space")
        if self.sealed:
            out.append(f"{self.sealed} thin wall(s) facing into pockets closed by thin walls left out "
                       "(the pockets are taken as solid)")
        if self.overlaps:
            out.append(f"{self.overlaps} pair(s) of walls still repeat or overlap each other "
                       "(check reports them as A202/A203)")
        if self.crossings:
            x, z = self.crossings[0]
            out.append(f"{len(self.crossings)} pair(s) of walls cross each other, the first at ({x:.2f}, {z:.2f}) "
                       "(check reports them as A204)")
        return out


def repair_walls(outline: np.ndarray, thin: np.ndarray, free, tol: float,
                 repairs: Repairs) -> tuple[np.ndarray, int]:
    """One region's walls as written (``outline`` (n, 2, 2) with free space on their
    left, ``thin`` (m, 2, 2) written both ways), repaired; ``repairs`` is updated
    with what was done and what is left.  Returns (the walls, how many are thin)."""
    outline, turned = orient_to_free(outline, free, max(4 * tol, 1e-3))
    outline, merged = merge_overlaps(outline, tol)
    if len(thin) > 1:
        # a thin wall stands both ways: one way each (+x first) so that copies written
        # in opposite directions are seen as copies
        d = thin[:, 1] - thin[:, 0]
        back = (d[:, 0] < 0) | ((d[:, 0] == 0) & (d[:, 1] < 0))
        one_way = np.where(back[:, None, None], thin[:, ::-1], thin)
        joined, merged_thin = merge_overlaps(one_way, tol)
        if merged_thin:
            thin = joined
            repairs.merged += 2 * merged_thin
    both = np.concatenate([thin, thin[:, ::-1]]) if len(thin) else thin
    both, sealed = _seal_pockets(both, max(4 * tol, 1e-3))
    n_thin = len(both)
    segs = np.concatenate([outline, both]) if len(both) else outline
    repairs.turned += turned
    repairs.sealed += sealed
    repairs.merged += merged
    live = np.flatnonzero(np.hypot(*(segs[:, 1] - segs[:, 0]).T) > 0)
    left = classify_pairs(segs, np.ones(len(segs)), live, tol)
    repairs.overlaps += len(left.repeat[0]) + len(left.overlap[0])
    repairs.crossings.extend(left.cross[2])
    return segs, n_thin


def _seal_pockets(both: np.ndarray, probe: float) -> tuple[np.ndarray, int]:
    """Thin walls (written both ways) that face into a pocket closed by thin walls
    alone (three fences meeting in a small triangle) left out: nothing says such a
    pocket is free space, ``check`` counts it as solid (its walls' normals cancel
    out) and no tank gets in.  Returns (walls, how many were left out)."""
    if len(both) < 6:
        return both, 0
    noded = shapely.union_all(shapely.linestrings(both))
    pockets = shapely.get_parts(shapely.polygonize(shapely.get_parts(noded)))
    if len(pockets) == 0:
        return both, 0
    d = both[:, 1] - both[:, 0]
    n = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-300)[:, None]
    front = shapely.points(both.mean(axis=1) + probe * n)
    into = np.zeros(len(both), dtype=bool)
    _, hit = shapely.STRtree(front).query(pockets, predicate="contains_properly")
    into[hit] = True
    return both[~into], int(into.sum())


def pair_tolerance(seg: np.ndarray) -> float:
    """The distance within which ``check`` takes wall ends and lines for the same (its
    layered arenas' A202-A204 tolerance, 4 x 1e-6 of the largest coordinate)."""
    m = float(np.max(np.abs(seg))) if seg.size else 1.0
    return 4e-6 * max(1.0, m)
