"""The solid cross-section of a model cut by a plane, and the chains that bound no
solid (step 3 of :mod:`tanktool.geometry.walls`; the layered arenas' exact floors,
:mod:`tanktool.nav.level_walls`, cut this way too).

Cut segments come ordered "face normal on the right": around a solid with outward
normals they run counter-clockwise, so the solid is the region of positive winding
number (:func:`winding_region`) of the closed, consistent components
(:func:`cross_sections`).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np
import shapely


def winding_region(seg: np.ndarray, tolerance: float, inside: Callable[[np.ndarray], np.ndarray] | None = None):
    """Points of positive winding number about directed segments (region on their left).

    ``inside``, when given, says for (k, 2) points strictly inside the faces of the
    segments' arrangement which are in the region, instead of counting crossings with
    every segment (a mask of cells knows it by looking a point's cell up)."""
    if len(seg) == 0:
        return shapely.Polygon()
    lines = shapely.linestrings(seg.reshape(-1, 2), indices=np.repeat(np.arange(len(seg)), 2))
    chains = shapely.get_parts(shapely.line_merge(shapely.multilinestrings(lines), directed=True))
    chains = shapely.simplify(chains, tolerance / 2)
    coords, index = shapely.get_coordinates(chains, return_index=True)
    same = index[1:] == index[:-1]
    a = coords[:-1][same]
    b = coords[1:][same]
    noded = shapely.union_all(chains)
    faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(noded)))
    if len(faces) == 0:
        return shapely.Polygon()
    rep = shapely.get_coordinates(shapely.point_on_surface(faces))
    if inside is not None:
        return shapely.union_all(faces[inside(rep)])
    winding = np.zeros(len(rep))
    # crossing number with signs, a block of faces at a time to bound memory
    block = max(1, 2_000_000 // max(1, len(a)))
    for s in range(0, len(rep), block):
        p = rep[s:s + block, None, :]
        up = (a[None, :, 1] <= p[..., 1]) & (b[None, :, 1] > p[..., 1])
        down = (a[None, :, 1] > p[..., 1]) & (b[None, :, 1] <= p[..., 1])
        side = (b[None, :, 0] - a[None, :, 0]) * (p[..., 1] - a[None, :, 1]) - \
               (p[..., 0] - a[None, :, 0]) * (b[None, :, 1] - a[None, :, 1])
        winding[s:s + block] = (up & (side > 0)).sum(axis=1) - (down & (side < 0)).sum(axis=1)
    return shapely.union_all(faces[winding > 0])


def _oriented_runs(line: np.ndarray, along: np.ndarray, rise: np.ndarray, across: bool) -> list[np.ndarray]:
    """The runs of unit edges on grid lines ``line`` (cell indices ``along`` them) as
    (k, 2, 2) segments in (x, z) cell units, each run the way its free side asks:
    ``rise`` edges one way and the others the opposite way.  ``across``: the lines are
    x lines (vertical edges), whose forward way is the reverse of the z lines'."""
    out = []
    for forward, sel in ((not across, rise), (across, ~rise)):
        at, s0, s1 = _edge_runs(line[sel], along[sel])
        pair = (lambda s: [at, s]) if across else (lambda s: [s, at])
        a = np.stack(pair(s0), axis=1).astype(np.float64)
        b = np.stack(pair(s1), axis=1).astype(np.float64)
        out.append(np.stack([a, b] if forward else [b, a], axis=1))
    return out


def cells_polygon(mask: np.ndarray, origin: np.ndarray, cell: float, tolerance: float):
    """The union of the cells of a 2-D mask (row i: z, column j: x) as a polygon
    (:func:`winding_region` of the cells' outline, a face looked up by its cell).

    The outline goes in as one segment per run of cell edges on a line (one
    orientation, no other edge meeting it between its ends: two edges in line with
    the same free side leave no cell change across the point between them), not one
    per unit edge: line_merge and simplify took most of the time over unit edges
    (hix: 74 -> 25 ms a call) and dropped the runs' inner points anyway."""
    m = np.zeros((mask.shape[0] + 2, mask.shape[1] + 2), dtype=bool)
    m[1:-1, 1:-1] = mask
    # horizontal edges at z line i (rows i - 1, i): free above -> +x (split by side, in rows)
    hi = m[1:, 1:-1]
    i, j = np.nonzero(hi != m[:-1, 1:-1])
    segs = _oriented_runs(i, j, hi[i, j], across=False)
    # vertical edges at x line j (between columns j - 1 and j): free to the right -> -z;
    # found column by column, so a run's edges come one after the other
    right = m[1:-1, 1:]
    j, i = np.nonzero((right != m[1:-1, :-1]).T)
    segs += _oriented_runs(j, i, right[i, j], across=True)
    seg = np.concatenate(segs)
    if len(seg) == 0:
        return shapely.Polygon()
    seg = np.asarray(origin, dtype=np.float64) + seg * cell

    def in_cells(p: np.ndarray) -> np.ndarray:
        # the faces of the cells' outline are unions of whole cells: a point inside one
        # is in the region when its cell is (no crossing count over every edge)
        ij = np.floor((p - origin) / cell).astype(np.int64)
        return m[ij[:, 1] + 1, ij[:, 0] + 1]

    return winding_region(seg, tolerance, in_cells)


def _edge_runs(line: np.ndarray, k: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(line, first, past the last) of each run of consecutive unit edges ``k`` on one
    line, the edges given sorted by line, then k."""
    if len(line) == 0:
        return line, k, k
    new = np.ones(len(line), dtype=bool)
    new[1:] = (line[1:] != line[:-1]) | (k[1:] != k[:-1] + 1)
    starts = np.flatnonzero(new)
    ends = np.append(starts[1:], len(line)) - 1
    return line[starts], k[starts], k[ends] + 1


def components(nodes: np.ndarray) -> np.ndarray:
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    m = int(nodes.max()) + 1 if len(nodes) else 0
    graph = coo_matrix((np.ones(len(nodes)), (nodes[:, 0], nodes[:, 1])), shape=(m, m))
    _, label = connected_components(graph, directed=False)
    return label[nodes[:, 0]]


def cross_sections(segments: np.ndarray, normals: np.ndarray, nodes: np.ndarray, tolerance: float,
                   floor: Any = None):
    """Solid cross-section and thin-wall chains from oriented cut segments.

    The segments come ordered "face normal on the right", so around a solid with
    outward normals they run counter-clockwise: the solid is where the winding
    number of the segments is positive.  Segments are grouped into components
    (connected through shared cut points):

    * closed (every cut point used an even number of times) and *consistent*
      (as many segments enter each cut point as leave it) with positive area: the
      boundary of solid material;
    * the same with negative area (normals point into the loop): free space inside
      solid when it lies within a positive solid (a room inside a thick wall ring),
      otherwise, with floor all around its outside, a solid wound inside out
      (taken as solid), and without, a one-sided shell seen from inside (levels
      built of single faces): thin walls;
    * open, or closed with inconsistent normals: thin walls, since nothing says
      which side is solid.

    Returns ``(solid, chains, n_closed)``: a shapely geometry, a list of shapely
    LineStrings (thin walls before clipping) and the number of closed components.
    """
    if len(segments) == 0:
        return shapely.Polygon(), [], 0
    comp = components(nodes)
    ncomp = int(comp.max()) + 1
    closed, positive, negative = _component_kinds(segments, nodes, comp, ncomp)
    solid = winding_region(segments[positive[comp]], tolerance) if positive.any() else shapely.Polygon()
    hole = np.zeros(ncomp, dtype=bool)
    if negative.any() and not solid.is_empty:
        hole = _holes(segments, comp, negative, solid, tolerance)
        if hole.any():
            solid = winding_region(segments[(positive | hole)[comp]], tolerance)
    lone = negative & ~hole
    if lone.any() and floor is not None and not floor.is_empty:
        inverted = _inverted(segments, normals, comp, lone, floor, tolerance)
        if inverted.any():
            flip = inverted[comp]
            segments = segments.copy()
            segments[flip] = segments[flip][:, ::-1]
            positive = positive | inverted
            solid = winding_region(segments[(positive | hole)[comp]], tolerance)
    thin = ~(positive | hole)
    return solid, _chains(segments, comp, thin) if thin.any() else [], int(closed.sum())


def _component_kinds(segments: np.ndarray, nodes: np.ndarray, comp: np.ndarray,
                     ncomp: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per component: closed (every cut point used an even number of times), and
    consistent with positive or with negative area."""
    nn = int(nodes.max()) + 1
    out_deg = np.bincount(nodes[:, 0], minlength=nn)
    in_deg = np.bincount(nodes[:, 1], minlength=nn)
    odd = (out_deg + in_deg) % 2 == 1
    unbalanced = out_deg != in_deg
    comp_odd = np.bincount(comp, weights=odd[nodes].any(axis=1), minlength=ncomp) > 0
    comp_unbal = np.bincount(comp, weights=unbalanced[nodes].any(axis=1), minlength=ncomp) > 0
    x0, z0 = segments[:, 0, 0], segments[:, 0, 1]
    x1, z1 = segments[:, 1, 0], segments[:, 1, 1]
    signed = np.bincount(comp, weights=(x0 * z1 - x1 * z0) / 2, minlength=ncomp)
    consistent = ~comp_odd & ~comp_unbal
    return ~comp_odd, consistent & (signed > 0), consistent & (signed < 0)


def _votes(comp: np.ndarray, sel: np.ndarray, hits: np.ndarray, ncomp: int) -> tuple[np.ndarray, np.ndarray]:
    """Per component, how many of its selected segments (``sel``) ``hits``, and of how
    many (at least 1)."""
    votes = np.bincount(comp[sel], weights=hits, minlength=ncomp)
    return votes, np.maximum(np.bincount(comp[sel], minlength=ncomp), 1)


def _holes(segments: np.ndarray, comp: np.ndarray, negative: np.ndarray, solid: Any,
           tolerance: float) -> np.ndarray:
    """The negative loops lying within ``solid`` (up to their own outline): holes in it."""
    seg_neg = negative[comp]
    mid = segments[seg_neg].mean(axis=1)
    near = shapely.dwithin(solid, shapely.points(mid), tolerance)
    # all of it (but round-off): an inverted box overlapping a solid one is no hole
    votes, total = _votes(comp, seg_neg, near, len(negative))
    return negative & (votes >= 0.95 * total)


def _inverted(segments: np.ndarray, normals: np.ndarray, comp: np.ndarray, lone: np.ndarray, floor: Any,
              tolerance: float) -> np.ndarray:
    """The lone inward loops with floor all around their outside: solids whose faces
    are wound inside out (with no floor outside, a loop is a room's shell)."""
    sel = lone[comp]
    n = normals[sel]
    n = n / np.maximum(np.hypot(n[:, 0], n[:, 1]), 1e-300)[:, None]
    probe = segments[sel].mean(axis=1) - 4 * tolerance * n
    outside = shapely.contains_xy(floor, probe[:, 0], probe[:, 1])
    votes, total = _votes(comp, sel, outside, len(lone))
    return lone & (votes > 0.5 * total)


def _chains(segments: np.ndarray, comp: np.ndarray, thin: np.ndarray) -> list:
    """The segments of the ``thin`` components merged into lines, component by component."""
    sel = thin[comp]
    order = np.argsort(comp[sel], kind="stable")
    s = segments[sel][order]
    lines = shapely.linestrings(s.reshape(-1, 2), indices=np.repeat(np.arange(len(s)), 2))
    groups = shapely.multilinestrings(lines, indices=np.unique(comp[sel][order], return_inverse=True)[1])
    return list(shapely.get_parts(shapely.line_merge(groups)))
