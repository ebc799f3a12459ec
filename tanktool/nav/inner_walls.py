"""Walls inside a region's outline (:mod:`tanktool.nav.level_walls`): the thin walls
of the exact cut (zero-thickness fences, both ways) and the *ledges* between cells of
the region that do not link, crossings split so walls meet at their ends and thin
walls that cross the outline clipped to it, so they meet it in a T, never an X."""

from __future__ import annotations

import numpy as np
import shapely

from ..geometry import contours
from ..geometry import walls as cut

#: a thin wall of a higher cut within this of one already found is the same wall (m)
THIN_MERGE = 0.15


def inner_walls(chains_in: list, outline: np.ndarray, R, cells: np.ndarray, same: np.ndarray,
                loose: np.ndarray, origin: np.ndarray, cell: float, tolerance: float,
                ledge_error: float | None) -> np.ndarray:
    """The thin walls of one region, (k, 2, 2) one way: ``chains_in`` the cut's open
    chains near each exact floor with the floor's free space, ``outline`` and ``R`` the
    region's walls and free space, ``cells`` its cells, ``same`` their links on the
    level, ``loose`` its cells off the exact floors; ``ledge_error`` (m) simplifies
    the ledges as outlines are (None: kept as cell steps)."""
    thin = []
    taken = None  # thin walls so far: a higher cut through the same slanted face
    for chains, free in chains_in:  # finds them again a few cm aside
        if taken is not None:
            free = shapely.difference(free, taken)
        t = cut.thin_walls(chains, free, tolerance)
        if len(t):
            thin.append(t)
            near = shapely.buffer(shapely.multilinestrings(list(t)), THIN_MERGE, cap_style="flat")
            taken = near if taken is None else shapely.union(taken, near)
    thin = _unique_segments(np.concatenate(thin), tolerance) if thin else np.zeros((0, 2, 2))
    ledges = ledge_walls(cells, same, origin, cell, loose)
    if ledge_error is not None:  # a ledge across terrain is cell steps too
        ledges = contours.simplify_chains(ledges, ledge_error)
    if len(ledges):
        thin = np.concatenate([thin, ledges])
    return _split_crossings(_clip_crossings(thin, outline, R, tolerance), tolerance)


#: thin walls cut where they cross the outline end this far inside it [m]
CLIP_INSET = 0.001


def _crossings(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Proper crossings (an X, ends excluded) of the segments of ``a`` with those of
    ``b``, both (n, 2, 2): (index in a, index in b, parameter along the a segment).
    Candidate pairs come from an STR tree, so the cost follows the crossings found."""
    if len(a) == 0 or len(b) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0)
    tree = shapely.STRtree(shapely.linestrings(b))
    i, j = tree.query(shapely.linestrings(a), predicate="intersects")
    p, r = a[i, 0], a[i, 1] - a[i, 0]
    q, s = b[j, 0], b[j, 1] - b[j, 0]
    den = r[:, 0] * s[:, 1] - r[:, 1] * s[:, 0]
    qp = q - p
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (qp[:, 0] * s[:, 1] - qp[:, 1] * s[:, 0]) / den
        u = (qp[:, 0] * r[:, 1] - qp[:, 1] * r[:, 0]) / den
    eps = 1e-6
    hit = (np.abs(den) > 1e-12) & (t > eps) & (t < 1 - eps) & (u > eps) & (u < 1 - eps)
    return i[hit], j[hit], t[hit]


def _split_crossings(seg: np.ndarray, tolerance: float) -> np.ndarray:
    """Walls that cross each other (two cuts or a cut and a ledge through the same
    steps) split at the crossing: they then meet at a point, an X becomes four walls
    ending there."""
    i, _, t = _crossings(seg, seg)
    if len(i) == 0:
        return seg
    out = [seg[np.setdiff1d(np.arange(len(seg)), i)]]
    for k in np.unique(i):
        ts = np.concatenate([[0.0], np.sort(t[i == k]), [1.0]])
        a, d = seg[k, 0], seg[k, 1] - seg[k, 0]
        pts = a + ts[:, None] * d
        pieces = np.stack([pts[:-1], pts[1:]], axis=1)
        out.append(pieces[np.hypot(*(pieces[:, 1] - pieces[:, 0]).T) >= tolerance / 2])
    return np.concatenate(out)


def _clip_crossings(thin: np.ndarray, outline: np.ndarray, R, tolerance: float) -> np.ndarray:
    """Thin walls that cross the region's outline (a fence found by the cut a few cm
    past where the simplified outline runs) end on it instead: the part inside the
    region is kept, so the two meet in a T, never an X."""
    bad = np.zeros(len(thin), dtype=bool)
    bad[_crossings(thin, outline)[0]] = True
    if not bad.any():
        return thin
    # a millimetre inside: the written coordinates (0.1 mm) stay on this side of it
    inside = shapely.intersection(shapely.linestrings(thin[bad]),
                                  shapely.buffer(shapely.set_precision(R, 0.0), -CLIP_INSET, join_style="mitre"))
    if shapely.is_empty(inside).all():
        return thin[~bad]
    return np.concatenate([thin[~bad], cut.line_segments(shapely.get_parts(shapely.line_merge(inside)), tolerance)])


def ledge_walls(cells: np.ndarray, same: np.ndarray, origin: np.ndarray, cell: float,
                loose: np.ndarray | None = None) -> np.ndarray:
    """Walls across the *ledges* of a region: between two of its cells side by side
    that do not link (a ramp's side high above the ground beside it, a step too high
    across terrain), and along the middle of a one-cell gap between two of its cells
    (Recast's ledge filter takes the rim of a ramp's side off the surface).  The
    region's outline misses both, as the cells on either side are in it and the exact
    floor beside a ramp reaches up to its side.  Only where one side at least is in
    ``loose`` (cells off the exact floors, whose cut draws their walls; default all).
    Runs along a row or column are one segment each; (k, 2, 2), one way."""
    out = []
    loose = cells if loose is None else loose
    for axis in (1, 0):  # lines across +x (x = const), then across +z (z = const)
        c = cells if axis == 1 else cells.T
        lo_ = loose if axis == 1 else loose.T
        sm = same if axis == 1 else same.transpose(1, 0, 2)
        fwd_d, back_d = (0, 2) if axis == 1 else (1, 3)
        n = c.shape[1]
        edges = []
        if n >= 2:   # neighbours not linked: the line between column k and k + 1
            e = c[:, :-1] & c[:, 1:] & ~(sm[:, :-1, fwd_d] & sm[:, 1:, back_d]) & (lo_[:, :-1] | lo_[:, 1:])
            edges.append((e, 1.0))
        if n >= 3:   # a one-cell gap: the line through the middle of column k + 1
            e = c[:, :-2] & ~c[:, 1:-1] & c[:, 2:] & (lo_[:, :-2] | lo_[:, 2:])
            edges.append((e, 1.5))
        for e, shift in edges:
            if not e.any():
                continue
            lines = e.T                                 # rows: the lines, along them the runs
            pad = np.zeros((lines.shape[0], lines.shape[1] + 2), dtype=np.int8)
            pad[:, 1:-1] = lines
            dif = np.diff(pad, axis=1)
            line, start = np.nonzero(dif == 1)
            _, stop = np.nonzero(dif == -1)
            pos = (line + shift) * cell
            lo, hi = start * cell, stop * cell
            a = np.column_stack([pos, lo]) if axis == 1 else np.column_stack([lo, pos])
            b = np.column_stack([pos, hi]) if axis == 1 else np.column_stack([hi, pos])
            out.append(np.stack([a, b], axis=1) + origin)
    return np.concatenate(out) if out else np.zeros((0, 2, 2))


def _unique_segments(seg: np.ndarray, tolerance: float) -> np.ndarray:
    """Segments snapped to the tolerance grid, each kept once whichever way it runs (the
    cuts at several heights meet the same vertical face)."""
    q = np.round(seg / tolerance).astype(np.int64)
    a, b = q[:, 0], q[:, 1]
    swap = (a[:, 0] > b[:, 0]) | ((a[:, 0] == b[:, 0]) & (a[:, 1] > b[:, 1]))
    key = np.where(swap[:, None], np.concatenate([b, a], axis=1), np.concatenate([a, b], axis=1))
    _, first = np.unique(key, axis=0, return_index=True)
    return seg[np.sort(first)]
