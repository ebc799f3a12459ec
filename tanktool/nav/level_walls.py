"""Walls of a layered arena: the boundaries of walkable space, per level and region.

The walkable surface (:mod:`tanktool.nav.walkable`) says where a tank can stand, cell
by cell.  Its walls are drawn per *region*: a connected piece of one level (cells of
the level joined by links that stay on the level).  For each region:

* ``V``: the outline of its cells, simplified as Recast simplifies contours (at most
  ``EDGE_ERROR`` cells off the cells' outline, edges over a curve no longer than
  ``EDGE_MAX_LEN``: :mod:`tanktool.geometry.contours`) so that a staircase of cells
  along a slanted edge or a hillside becomes a few straight walls;
* where the region is flat (cells whose surface is a horizontal face at a height
  ``h`` shared by horizontal faces of the model), the exact free space ``E_h`` of
  today's 2002 cut replaces the cells near them (``M_h``: those cells grown by
  ``MARGIN`` cells, less the region's other cells: terrain or a ramp rising from the
  floor or coming up to a deck is no obstacle of it): the outline of the faces on the floor minus the model's cross
  sections at ``h`` plus the cut height and at steps up to the headroom (overhangs);
  so a flat one-floor arena keeps exactly the walls of the cut, and a flat deck of a
  multi-level arena gets exact walls too;
* the region's polygon is ``R = (U_h E_h & M_h) | (V - U_h (M_h - E_h))``;
* its boundary, oriented with free space on the left (Direction +1), is cut into
  pieces of half a cell; a piece across which the region's cells link to a cell of
  another level (the top of a ramp onto a deck) is a *portal*, not a wall;
* open chains of the exact cut (zero-thickness walls) inside ``E_h & M_h`` are thin
  walls, both ways;
* so are *ledges*: edges between two cells of the region that do not link (a ramp's
  side high above the ground beside it, a step too high across terrain), which the
  outline passes by because both cells are in the region.  A drop-off is a wall.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import shapely

from ..formats.walls_txt import WallList, aux_rectangle
from ..geometry import contours, slivers
from ..geometry import walls as cut
from ..geometry.wall_pairs import Repairs, pair_tolerance, repair_walls
from ..geometry.heightfield import FLAT_GAP, flat_heights
from .walkable import DIRS, Surface, surface_layers

#: simplification of cell outlines as Recast does: the maximum edge error (cells) and
#: the maximum edge length (m) of :func:`tanktool.geometry.contours.simplify_contour`
EDGE_ERROR = contours.EDGE_ERROR
EDGE_MAX_LEN = contours.EDGE_MAX_LEN
#: exact free space replaces the cells' outline this far (cells) around flat cells:
#: the foot of a steep obstacle (free below the cut, too low for a tank in the cells)
#: can be two cells wide
MARGIN = 2.5
#: a thin wall of a higher cut within this of one already found is the same wall (m)
THIN_MERGE = 0.15
#: flat floors smaller than this (m^2) keep the cells' outline (stair treads)
MIN_EXACT_AREA = 4.0
#: a floor the exact cut replaces is mostly (by area) of faces horizontal to within
#: 0.1 deg, as a modelled floor is: the tops and bottoms of smooth terrain, flat to
#: within a few degrees, keep the cells' outline
EXACT_FLAT_NY = 0.999999
#: gap between the walls' extent and the auxiliary rectangle (m)
AUX_MARGIN = 1.0


@dataclass
class RegionWalls:
    level: int
    region: int
    free: object  # shapely (Multi)Polygon: the region's free space
    y_lo: float
    y_hi: float
    area: float
    flat_heights: list[tuple[float, float]] = field(default_factory=list)  # (height, area) of exact floors


@dataclass
class LevelWalls:
    """The walls of every region, and the free space they bound."""

    walls: WallList
    regions: list[RegionWalls]
    thin_walls: int = 0
    portals: float = 0.0  # metres of region boundary left open to another level
    repairs: Repairs = field(default_factory=Repairs)  # walls joined or turned, problems left

    def free(self, level: int | None = None):
        parts = [r.free for r in self.regions if level is None or r.level == level]
        return shapely.union_all(parts) if parts else shapely.Polygon()


def cells_polygon(mask: np.ndarray, origin: np.ndarray, cell: float, tolerance: float):
    """The union of the cells of a 2-D mask (row i: z, column j: x) as a polygon."""
    m = np.zeros((mask.shape[0] + 2, mask.shape[1] + 2), dtype=bool)
    m[1:-1, 1:-1] = mask
    segs = []
    # horizontal edges at z line i (between rows i - 1 and i): free above -> +x
    diff = m[1:, 1:-1].astype(np.int8) - m[:-1, 1:-1].astype(np.int8)
    for sign in (1, -1):
        i, j = np.nonzero(diff == sign)
        a = np.stack([j, i], axis=1).astype(np.float64)
        b = a + [1.0, 0.0]
        segs.append(np.stack([a, b] if sign > 0 else [b, a], axis=1))
    # vertical edges at x line j (between columns j - 1 and j): free to the right -> -z
    diff = m[1:-1, 1:].astype(np.int8) - m[1:-1, :-1].astype(np.int8)
    for sign in (1, -1):
        i, j = np.nonzero(diff == sign)
        a = np.stack([j, i], axis=1).astype(np.float64)
        b = a + [0.0, 1.0]
        segs.append(np.stack([b, a] if sign > 0 else [a, b], axis=1))
    seg = np.concatenate(segs) if segs else np.zeros((0, 2, 2))
    if len(seg) == 0:
        return shapely.Polygon()
    seg = np.asarray(origin, dtype=np.float64) + seg * cell

    def in_cells(p: np.ndarray) -> np.ndarray:
        # the faces of the cells' outline are unions of whole cells: a point inside one
        # is in the region when its cell is (no crossing count over every edge)
        ij = np.floor((p - origin) / cell).astype(np.int64)
        return m[ij[:, 1] + 1, ij[:, 0] + 1]

    return cut._winding_region(seg, tolerance, in_cells)


class ExactCuts:
    """Exact free space ``E_h`` at floor heights ``h`` (computed once per height)."""

    def __init__(self, vertices: np.ndarray, faces: np.ndarray, cut_height: float, headroom: float,
                 tolerance: float, min_ny: float, climb: float = 0.0) -> None:
        self.vertices = vertices
        self.climb = climb
        self.faces = faces
        self.tolerance = tolerance
        self.merge = cut.merge_distance(vertices)
        # the first cut is today's (--height); one just under the headroom and one
        # half-way catch overhangs a tank would hit
        top = headroom - 0.05
        self.steps = [cut_height] + ([(cut_height + top) / 2] if top - cut_height > 0.6 else []) + \
            ([top] if top > cut_height else [])
        up, self.up_height, _, _ = cut._upward_faces(vertices, faces)
        tri = vertices[faces[up]]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        ny = n[:, 1] / np.maximum(np.linalg.norm(n, axis=1), 1e-300)
        keep = ny >= min_ny
        self.up = up[keep]
        # the faces a cut may meet: not the walkable slopes (a cut through a hillside or
        # a ramp is a contour line, not a wall: the tank drives up it)
        walk = np.zeros(len(faces), dtype=bool)
        walk[self.up] = True
        self.cut_faces = faces[~walk]
        self.low = tri[keep, :, 1].min(axis=1)
        self.cache: dict[float, tuple] = {}

    def at(self, h: float, box: tuple[float, float, float, float], base: float | None = None):
        """(free polygon, thin-wall chains per cut, lowest cut first) of a floor at height ``h``, exact inside
        ``box`` (xmin, zmin, xmax, zmax): only the floor faces overlapping it and the
        cut loops reaching into it are used (a multi-storey model has many floors).

        The floor is every walkable face from ``climb`` below ``h`` (the ground a tank
        steps down to from a low platform) up to the first cut; that cut lies
        ``cut_height`` above ``base`` (the lowest floor in that band, so a platform and
        the ground around it see the same obstacles), the others above ``h``."""
        base = h if base is None else min(base, h)
        key = (round(h, 4), round(base, 4), tuple(round(b, 3) for b in box))
        if key in self.cache:
            return self.cache[key]
        v, f, tol = self.vertices, self.faces, self.tolerance
        x0, z0, x1, z1 = box
        band = (self.low >= h - self.climb - FLAT_GAP) & (self.low < base + self.steps[0])
        tri = v[f[self.up]]
        over = band & (tri[:, :, 0].max(axis=1) >= x0) & (tri[:, :, 0].min(axis=1) <= x1) & \
            (tri[:, :, 2].max(axis=1) >= z0) & (tri[:, :, 2].min(axis=1) <= z1)
        ground = self.up[over]
        floor_poly = cut.floor_region(v, f[ground], tol) if len(ground) else shapely.Polygon()
        solids, chains = [], []
        for k, dh in enumerate(self.steps):
            y = cut._plane_clear_of_vertices(v, (base if k == 0 else h) + dh, self.merge)
            seg, nrm, nodes = cut.slice_mesh(v, self.cut_faces, y, self.merge)
            if len(seg):
                # whole loops only: the components of the cut with a segment in the box
                comp = cut._components(nodes)
                inside = (seg[:, :, 0].max(axis=1) >= x0) & (seg[:, :, 0].min(axis=1) <= x1) & \
                    (seg[:, :, 1].max(axis=1) >= z0) & (seg[:, :, 1].min(axis=1) <= z1)
                keep = np.isin(comp, np.unique(comp[inside]))
                seg, nrm = seg[keep], nrm[keep]
                _, nodes = np.unique(nodes[keep], return_inverse=True)
                nodes = nodes.reshape(-1, 2)
            solid, ch, _ = cut.cross_sections(seg, nrm, nodes, tol, floor_poly)
            solids.append(solid)
            chains.append(ch)
        solid = shapely.union_all(solids)
        free = shapely.set_precision(shapely.difference(floor_poly, solid), tol)
        self.cache[key] = (free, chains)
        return self.cache[key]


def modelled_floors(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Heights of the model's flat floors (``flat_heights``) made mostly of faces level
    to within EXACT_FLAT_NY: not a hilltop of terrain triangles a degree or two off."""
    flat_h, flat_a = flat_heights(vertices, faces)
    if len(flat_h) == 0:
        return flat_h
    level_h, level_a = flat_heights(vertices, faces, EXACT_FLAT_NY)
    share = np.zeros(len(flat_h))
    if len(level_h):
        np.add.at(share, np.abs(level_h[:, None] - flat_h[None, :]).argmin(axis=1), level_a)
    return flat_h[share >= 0.5 * flat_a]


def _pieces(walls: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Each wall cut into pieces of at most ``step``: (pieces (m, 2, 2), wall of each)."""
    length = np.hypot(*(walls[:, 1] - walls[:, 0]).T)
    n = np.maximum(1, np.ceil(length / step)).astype(np.int64)
    owner = np.repeat(np.arange(len(walls)), n)
    k = np.arange(len(owner)) - np.repeat(np.cumsum(n) - n, n)
    t0 = (k / n[owner])[:, None]
    t1 = ((k + 1) / n[owner])[:, None]
    a, b = walls[owner, 0], walls[owner, 1]
    return np.stack([a + (b - a) * t0, a + (b - a) * t1], axis=1), owner


def _rejoin(pieces: np.ndarray, owner: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """Consecutive kept pieces of the same wall joined back into one segment."""
    if not keep.any():
        return np.zeros((0, 2, 2))
    idx = np.flatnonzero(keep)
    new = np.ones(len(idx), dtype=bool)
    new[1:] = (owner[idx[1:]] != owner[idx[:-1]]) | (idx[1:] != idx[:-1] + 1)
    starts = np.flatnonzero(new)
    ends = np.append(starts[1:], len(idx)) - 1
    return np.stack([pieces[idx[starts], 0], pieces[idx[ends], 1]], axis=1)


def _portal_pieces(pieces: np.ndarray, level: int, region_cells: np.ndarray, surface: Surface,
                   span_of: np.ndarray, origin: np.ndarray, cell: float) -> np.ndarray:
    """Which pieces of a region's outline open onto a linked cell of another level."""
    if len(pieces) == 0:
        return np.zeros(0, dtype=bool)
    nz, nx = region_cells.shape
    mid = pieces.mean(axis=1)
    d = pieces[:, 1] - pieces[:, 0]
    ln = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-12)
    inward = np.stack([-d[:, 1], d[:, 0]], axis=1) / ln[:, None]  # free space on the left
    out = np.zeros(len(pieces), dtype=bool)
    cand_i, cand_j = np.nonzero(region_cells)
    if len(cand_i) == 0:
        return out
    from scipy.spatial import cKDTree

    centres = np.stack([origin[0] + (cand_j + 0.5) * cell, origin[1] + (cand_i + 0.5) * cell], axis=1)
    tree = cKDTree(centres)
    _, near = tree.query(mid + inward * (0.5 * cell))
    ci, cj = cand_i[near], cand_j[near]
    # the step from that cell across the piece: the outward normal's main axis
    ox, oz = -inward[:, 0], -inward[:, 1]
    dirs = np.where(np.abs(ox) >= np.abs(oz), np.where(ox > 0, 0, 2), np.where(oz > 0, 1, 3))
    spans = span_of[level, ci, cj]
    tgt = surface.link[spans, dirs]
    ok = (spans >= 0) & (tgt >= 0)
    lv = np.where(ok, surface.level[np.maximum(tgt, 0)], -1)
    out = ok & (lv >= 0) & (lv != level)
    return out


def level_walls(surface: Surface, vertices: np.ndarray, faces: np.ndarray, cut_height: float,
                headroom: float, climb_m: float, tolerance: float, max_slope: float,
                edge_error: float = EDGE_ERROR, edge_max_len: float | None = EDGE_MAX_LEN,
                smooth_margin: bool = True) -> LevelWalls:
    """Walls of every region of the surface's main region (see the module docstring).
    ``edge_error`` (cells) and ``edge_max_len`` (m, None: no limit) simplify the
    cells' outlines; ``smooth_margin`` simplifies the margins ``M_h`` so too (False,
    with ``edge_error=0.6, edge_max_len=None``: the walls before Recast's
    simplification, for bench/walls.py)."""
    from scipy import ndimage

    hf = surface.hf
    cell = hf.cs
    origin = hf.origin[[0, 2]]
    exists, height, _, span_of = surface_layers(surface)
    L, nz, nx = exists.shape
    cuts = ExactCuts(vertices, faces, cut_height, headroom, tolerance, math.cos(math.radians(max_slope)), climb_m)
    flat_h = modelled_floors(vertices, faces)
    span_flat = np.zeros((L, nz, nx), dtype=bool)
    span_rim = np.zeros((L, nz, nx), dtype=bool)
    m = span_of >= 0
    w_idx = np.flatnonzero(hf.walkable)  # surface spans are the walkable spans, in order
    span_flat[m] = hf.flat[w_idx[span_of[m]]]
    span_rim[m] = ~hf.top_walkable[w_idx[span_of[m]]]
    lev = np.arange(L)[:, None, None]
    same = np.stack([surface_link_level(surface, span_of, d) == lev for d in range(4)], axis=-1) & exists[..., None]
    out_seg, out_dir, out_lev, out_reg = [], [], [], []
    regions: list[RegionWalls] = []
    thin_total = 0
    portal_len = 0.0
    repairs = Repairs()
    pair_tol = pair_tolerance(np.array([origin, origin + [nx * cell, nz * cell]]))
    rid = 0
    for level in range(L):
        labels, n = _region_labels(exists[level], same[level])
        for k in range(1, n + 1):
            cells = labels == k
            ys = height[level][cells]
            V = cells_polygon(cells, origin, cell, tolerance)
            V = contours.simplify_contour(V, edge_error * cell, edge_max_len)
            exact_parts, removed, chains_in = [], [], []
            used_h = []
            floor = np.zeros_like(cells)  # cells of the exact floors (their walls are the cut's)
            flat_cells = cells & span_flat[level]
            if flat_cells.any() and len(flat_h):
                hy = height[level][flat_cells]
                # the cluster whose height the span's top rounds up from (within a cell height)
                pos = np.searchsorted(flat_h, hy + 1e-6, side="right") - 1
                okc = (pos >= 0) & (hy - flat_h[np.maximum(pos, 0)] <= hf.ch + 1e-6)
                fi, fj = np.nonzero(flat_cells)
                rim = cells & span_rim[level]
                for c in np.unique(pos[okc]):
                    sel = okc & (pos == c)
                    mask = np.zeros_like(cells)
                    mask[fi[sel], fj[sel]] = True
                    # small patches (stair treads, bumps) keep the cells' outline
                    lab, nlab = ndimage.label(mask)
                    big = np.bincount(lab.ravel())[1:] * cell * cell >= MIN_EXACT_AREA
                    if not big.any():
                        continue
                    mask = np.isin(lab, np.flatnonzero(big) + 1)
                    present = flat_h[np.unique(pos[okc])]
                    base = float(present[present >= flat_h[c] - climb_m - 1e-9].min())
                    # the rims of steep obstacles standing on this floor (walkable only
                    # because they rise less than the climb) belong to it too
                    mask |= rim & (np.abs(height[level] - flat_h[c]) <= climb_m)
                    floor |= mask
                    sub, sub_origin = _crop(mask, _mask_box(mask, origin, cell, MARGIN + 1), origin, cell)
                    # simplified as V is: where the exact floor reaches past the region's cells
                    # (a walkable face beside a steep one in the same cell), M's outline is
                    # the region's, and a staircase there is voxel steps again
                    M = cells_polygon(sub, sub_origin, cell, tolerance)
                    M = shapely.buffer(contours.simplify_contour(M, edge_error * cell, edge_max_len)
                                       if smooth_margin else M, MARGIN * cell, join_style="mitre")
                    box = M.bounds
                    # the region's other cells (terrain, ramps rising from the floor or
                    # coming up to a deck) are no obstacle of this floor: their outline stays
                    rising = _crop(cells & ~mask, box, origin, cell)
                    if rising is not None:
                        up = cells_polygon(rising[0], rising[1], cell, tolerance)
                        if smooth_margin:
                            up = contours.simplify_contour(up, edge_error * cell, edge_max_len)
                        M = shapely.difference(M, up)
                    E, chains = cuts.at(float(flat_h[c]), box, base)
                    exact_parts.append(shapely.intersection(E, M))
                    removed.append(shapely.difference(M, E))
                    for step in chains:
                        if step:
                            near = shapely.intersects(np.array(step, dtype=object), shapely.box(*box))
                            chains_in.append(([ch for ch, k in zip(step, near) if k], exact_parts[-1]))
                    used_h.append((float(flat_h[c]), float(mask.sum() * cell * cell)))
            R = shapely.difference(V, shapely.union_all(removed)) if removed else V
            if exact_parts:
                R = shapely.union_all([R, *exact_parts])
            R = shapely.set_precision(R, tolerance)
            R = slivers.drop_slivers(R, tolerance)
            R = slivers.fill_sliver_holes(R, tolerance, cell)
            if R.is_empty:
                continue
            R = shapely.simplify(R, tolerance, preserve_topology=True)
            outline = cut.outline_walls(R, tolerance)
            if len(outline):
                pieces, owner = _pieces(outline, cell / 2)
                portal = _portal_pieces(pieces, level, cells, surface, span_of, origin, cell) if L > 1 else \
                    np.zeros(len(pieces), dtype=bool)
                portal_len += float(np.hypot(*(pieces[portal, 1] - pieces[portal, 0]).T).sum())
                outline = _rejoin(pieces, owner, ~portal)
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
            ledges = ledge_walls(cells, same[level], origin, cell, cells & ~floor)
            if smooth_margin:  # a ledge across terrain is cell steps too: simplified as outlines are
                ledges = contours.simplify_chains(ledges, edge_error * cell)
            if len(ledges):
                thin = np.concatenate([thin, ledges])
            thin = _split_crossings(_clip_crossings(thin, outline, R, tolerance), tolerance)
            # what check would find (repeats, overlaps, normals into solid) repaired here
            segs, n_thin = repair_walls(outline, thin, R, pair_tol, repairs)
            thin_total += n_thin
            out_seg.append(segs)
            out_dir.append(np.ones(len(segs), dtype=np.int8))
            out_lev.append(np.full(len(segs), level))
            out_reg.append(np.full(len(segs), rid))
            regions.append(RegionWalls(level, rid, R, float(np.nanmin(ys)), float(np.nanmax(ys)),
                                       float(cells.sum() * cell * cell), used_h))
            rid += 1
    seg = np.concatenate(out_seg) if out_seg else np.zeros((0, 2, 2))
    walls = WallList(seg, np.concatenate(out_dir) if out_dir else np.zeros(0, dtype=np.int8), None, None, None,
                     np.concatenate(out_lev) if out_lev else None, np.concatenate(out_reg) if out_reg else None,
                     {r.region: (r.level, r.y_lo, r.y_hi) for r in regions})
    pts = seg.reshape(-1, 2) if len(seg) else np.array([origin, origin + [nx * cell, nz * cell]])
    lo = pts.min(axis=0) - AUX_MARGIN
    hi = pts.max(axis=0) + AUX_MARGIN
    walls.aux = aux_rectangle(lo[0], lo[1], hi[0], hi[1])
    return LevelWalls(walls, regions, thin_total, portal_len, repairs)


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


def _mask_box(mask: np.ndarray, origin: np.ndarray, cell: float, grow: float) -> tuple[float, float, float, float]:
    """World box of a mask's cells, grown by ``grow`` cells."""
    i, j = np.nonzero(mask)
    return (origin[0] + (j.min() - grow) * cell, origin[1] + (i.min() - grow) * cell,
            origin[0] + (j.max() + 1 + grow) * cell, origin[1] + (i.max() + 1 + grow) * cell)


def _crop(mask: np.ndarray, box, origin: np.ndarray, cell: float):
    """The part of a cell mask inside ``box`` as (sub-mask, its origin), None if empty."""
    nz, nx = mask.shape
    j0 = max(0, int(math.floor((box[0] - origin[0]) / cell)) - 1)
    i0 = max(0, int(math.floor((box[1] - origin[1]) / cell)) - 1)
    j1 = min(nx, int(math.ceil((box[2] - origin[0]) / cell)) + 1)
    i1 = min(nz, int(math.ceil((box[3] - origin[1]) / cell)) + 1)
    sub = mask[i0:i1, j0:j1]
    if not sub.any():
        return None
    return sub, np.array([origin[0] + j0 * cell, origin[1] + i0 * cell])


def surface_link_level(surface: Surface, span_of: np.ndarray, d: int) -> np.ndarray:
    """(L, nz, nx): the level of the span each node's span links to in direction d (-1)."""
    lv = np.append(surface.level, -1)
    t = np.where(span_of >= 0, surface.link[np.maximum(span_of, 0), d], -1)
    return np.where(span_of >= 0, lv[t], -1)


def _region_labels(cells: np.ndarray, same: np.ndarray) -> tuple[np.ndarray, int]:
    """Components of a level's cells joined by links that stay on the level."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    nz, nx = cells.shape
    idx = np.full(cells.shape, -1, dtype=np.int64)
    ci, cj = np.nonzero(cells)
    idx[ci, cj] = np.arange(len(ci))
    src, dst = [], []
    for d, (di, dj) in enumerate(DIRS):
        ok = same[ci, cj, d]
        ii, jj = ci[ok] + di, cj[ok] + dj
        src.append(idx[ci[ok], cj[ok]])
        dst.append(idx[ii, jj])
    s = np.concatenate(src)
    t = np.concatenate(dst)
    good = t >= 0
    g = coo_matrix((np.ones(int(good.sum()), dtype=np.int8), (s[good], t[good])), shape=(len(ci), len(ci)))
    n, lab = connected_components(g, directed=False)
    labels = np.zeros(cells.shape, dtype=np.int64)
    labels[ci, cj] = lab + 1
    return labels, int(n)
