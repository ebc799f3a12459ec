"""Contours of cell regions simplified as Recast's ``rcSimplifyContour`` does.

A region drawn from voxel cells has a staircase for an outline: along a smooth
hillside's edge (where the slope passes the maximum) every cell is a step, and a
300 m terrain wrote thousands of walls half a cell long.  Recast keeps a contour's
raw vertices only where they stray more than a *maximum edge error* from the
simplified line (Douglas-Peucker), then puts raw vertices back into edges longer
than a *maximum edge length*, so that a long edge still follows the curve it stands
for.  The same two steps here, on shapely polygons:

1. ``shapely.simplify(poly, max_error, preserve_topology=True)`` keeps a subset of
   the raw vertices and the rings valid (a hole never crosses its exterior);
2. every simplified edge longer than ``max_edge_len`` whose raw path between its two
   ends has vertices gets the middle one of them back, again and again.  A raw run
   that is one straight line (a cell-aligned wall) has no vertex between its ends and
   stays one edge.

Example: a 45 degree staircase of 0.5 m cells lies 0.35 m off its diagonal at every
corner; at Recast's default error of 1.3 cells (0.65 m) it is one wall, at 0.6 cells
(0.3 m) it stays a staircase.
"""

from __future__ import annotations

import numpy as np
import shapely

#: Recast's default maximum edge error, in cells (RecastDemo: edgeMaxError 1.3)
EDGE_ERROR = 1.3
#: Recast's default maximum edge length, in metres (RecastDemo: edgeMaxLen 12)
EDGE_MAX_LEN = 12.0


def simplify_contour(poly, max_error: float, max_edge_len: float | None = None):
    """``poly`` (a shapely (Multi)Polygon of cell outlines) simplified within
    ``max_error`` metres, no edge over a curved raw path longer than ``max_edge_len``
    metres (None: no limit).  Returns a valid shapely geometry."""
    simple = shapely.simplify(poly, max_error, preserve_topology=True)
    if max_edge_len is None or simple.is_empty:
        return simple
    raw_parts = shapely.get_parts(poly)
    simple_parts = shapely.get_parts(simple)
    if len(raw_parts) != len(simple_parts):
        return simple
    out = []
    for raw, s in zip(raw_parts, simple_parts):
        raw_rings = [raw.exterior, *raw.interiors]
        s_rings = [s.exterior, *s.interiors]
        if len(raw_rings) != len(s_rings):
            out.append(s)
            continue
        rings, changed = [], False
        for r, q in zip(raw_rings, s_rings):
            qc = np.asarray(q.coords)
            # most rings (a pillar's square, a short contour) have no edge to split
            if len(qc) < len(r.coords) and np.hypot(*np.diff(qc, axis=0).T).max() > max_edge_len:
                qc = split_long_edges(np.asarray(r.coords), qc, max_edge_len)
                changed = True
            rings.append(qc)
        p = shapely.Polygon(rings[0], rings[1:]) if changed else s
        out.append(p if p.is_valid else s)
    return shapely.union_all(out) if len(out) > 1 else out[0]


def split_long_edges(raw: np.ndarray, simple: np.ndarray, max_len: float) -> np.ndarray:
    """The closed ring ``simple`` (k + 1, 2), a subset of the closed ring ``raw``
    (n + 1, 2), with raw vertices put back until no edge longer than ``max_len`` has
    raw vertices between its ends (Recast: the middle one each time)."""
    n = len(raw) - 1
    if n < 3 or len(simple) < 4:
        return simple
    where = {tuple(p): i for i, p in enumerate(raw[:-1].tolist())}
    try:
        kept = [where[tuple(p)] for p in simple[:-1].tolist()]
    except KeyError:  # not a subset (a vertex moved): leave it as simplified
        return simple
    out: list[int] = []
    for a, b in zip(kept, kept[1:] + kept[:1]):
        out.extend(_split(raw, n, a, b, max_len))
    pts = raw[out]
    return np.concatenate([pts, pts[:1]])


def _split(raw: np.ndarray, n: int, a: int, b: int, max_len: float) -> list[int]:
    """Raw indices from ``a`` (included) up to ``b`` (excluded) along the ring, with
    middle vertices added while an edge is too long."""
    stack = [(a, b)]
    out = []
    while stack:
        i, j = stack.pop()
        gap = (j - i) % n
        if gap > 1 and np.hypot(*(raw[j] - raw[i])) > max_len:
            m = (i + gap // 2) % n
            stack.append((m, j))  # the later half is popped after the earlier one
            stack.append((i, m))
        else:
            out.append(i)
    return out


def simplify_chains(seg: np.ndarray, max_error: float) -> np.ndarray:
    """Wall segments (k, 2, 2) along cell edges (ledges across terrain: runs along rows
    and columns meeting at cell corners) joined into chains and simplified within
    ``max_error`` (Douglas-Peucker), as (m, 2, 2) segments.  Chains that lose no
    vertex come back as they were, in their order."""
    if len(seg) < 2:
        return seg
    lines = shapely.linestrings(seg.reshape(-1, 2), indices=np.repeat(np.arange(len(seg)), 2))
    chains = shapely.get_parts(shapely.line_merge(shapely.multilinestrings(lines)))
    simple = shapely.simplify(chains, max_error, preserve_topology=False)
    if shapely.get_num_coordinates(simple).sum() == shapely.get_num_coordinates(chains).sum():
        return seg
    coords, index = shapely.get_coordinates(simple, return_index=True)
    same = index[1:] == index[:-1]
    out = np.stack([coords[:-1][same], coords[1:][same]], axis=1)
    return out[np.any(out[:, 0] != out[:, 1], axis=1)]
