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
from ..memory import give_back
from ..geometry import contours, slivers
from ..geometry import cross_section as xs
from ..geometry.cross_section import cells_polygon
from ..geometry import walls as cut
from ..geometry.wall_pairs import Repairs, pair_tolerance, repair_walls
from ..geometry.heightfield import FACE_BLOCK, FLAT_GAP, flat_heights
from ..geometry.kernels import active
from .inner_walls import inner_walls
from .walkable import BLOCK, DIRS, Surface, surface_layers

#: simplification of cell outlines as Recast does: the maximum edge error (cells) and
#: the maximum edge length (m) of :func:`tanktool.geometry.contours.simplify_contour`
EDGE_ERROR = contours.EDGE_ERROR
EDGE_MAX_LEN = contours.EDGE_MAX_LEN
#: exact free space replaces the cells' outline this far (cells) around flat cells:
#: the foot of a steep obstacle (free below the cut, too low for a tank in the cells)
#: can be two cells wide
MARGIN = 2.5
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
        # a block of faces at a time (~190 bytes a face of temporaries, heightfield.flat_heights)
        ups, heights, lows = [], [], []
        for b in range(0, len(faces), FACE_BLOCK):
            fb = faces[b:b + FACE_BLOCK]
            up, height, _, _ = cut._upward_faces(vertices, fb)
            tri = vertices[fb[up]]
            n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            ny = n[:, 1] / np.maximum(np.linalg.norm(n, axis=1), 1e-300)
            keep = ny >= min_ny
            ups.append(b + up[keep])
            heights.append(height)
            lows.append(tri[keep, :, 1].min(axis=1))
        self.up = np.concatenate(ups) if ups else np.zeros(0, dtype=np.int64)
        self.up_height = np.concatenate(heights) if heights else np.zeros(0)
        # the faces a cut may meet: not the walkable slopes (a cut through a hillside or
        # a ramp is a contour line, not a wall: the tank drives up it)
        walk = np.zeros(len(faces), dtype=bool)
        walk[self.up] = True
        self.cut_faces = faces[~walk]
        self.low = np.concatenate(lows) if lows else np.zeros(0)
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
        # the upward faces' corners a block at a time: all at once took 72 bytes a face
        # (+0.15 GB on a 2 km terrain, at the walls' peak); the same faces in the same order
        parts = []
        for b in range(0, len(self.up), FACE_BLOCK):
            up = self.up[b:b + FACE_BLOCK]
            tri = v[f[up]]
            over = band[b:b + FACE_BLOCK] & (tri[:, :, 0].max(axis=1) >= x0) & (tri[:, :, 0].min(axis=1) <= x1) & \
                (tri[:, :, 2].max(axis=1) >= z0) & (tri[:, :, 2].min(axis=1) <= z1)
            parts.append(up[over])
        ground = np.concatenate(parts) if parts else self.up[:0]
        floor_poly = cut.floor_region(v, f[ground], tol) if len(ground) else shapely.Polygon()
        solids, chains = [], []
        for k, dh in enumerate(self.steps):
            y = cut._plane_clear_of_vertices(v, (base if k == 0 else h) + dh, self.merge)
            seg, nrm, nodes = cut.slice_mesh(v, self.cut_faces, y, self.merge)
            if len(seg):
                # whole loops only: the components of the cut with a segment in the box
                comp = xs.components(nodes)
                inside = (seg[:, :, 0].max(axis=1) >= x0) & (seg[:, :, 0].min(axis=1) <= x1) & \
                    (seg[:, :, 1].max(axis=1) >= z0) & (seg[:, :, 1].min(axis=1) <= z1)
                keep = np.isin(comp, np.unique(comp[inside]))
                seg, nrm = seg[keep], nrm[keep]
                _, nodes = np.unique(nodes[keep], return_inverse=True)
                nodes = nodes.reshape(-1, 2)
            solid, ch, _ = xs.cross_sections(seg, nrm, nodes, tol, floor_poly)
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


@dataclass
class _Cut:
    """What every region's walls are drawn from, prepared once by :func:`level_walls`."""

    surface: Surface
    origin: np.ndarray
    cell: float
    cell_h: float               # the height field's cell height (m)
    exists: np.ndarray          # (L, nz, nx): a cell of the level
    span_y: np.ndarray          # (n,): each surface span's height (Surface.y; the layer of
    #                             them took 8 bytes a node of every level through the walls)
    span_of: np.ndarray         # (L, nz, nx): its surface span, -1 for none
    span_flat: np.ndarray       # (L, nz, nx): its surface is a horizontal face
    span_rim: np.ndarray        # (L, nz, nx): the rim of a steep obstacle, walkable below the climb
    same: np.ndarray            # (L, nz, nx, 4): linked to the cell beside on the same level
    cuts: ExactCuts
    flat_h: np.ndarray          # heights of the model's floors (modelled_floors)
    tolerance: float
    climb_m: float
    edge_error: float
    edge_max_len: float | None
    smooth_margin: bool

    def simplify(self, poly):
        """A cell outline simplified as Recast does (the module docstring's ``V``)."""
        return contours.simplify_contour(poly, self.edge_error * self.cell, self.edge_max_len)


@dataclass
class _Floors:
    """The exact floors of one region (the module docstring's ``E_h`` and ``M_h``)."""

    exact: list = field(default_factory=list)      # E_h & M_h of each floor
    removed: list = field(default_factory=list)    # M_h - E_h of each floor
    chains: list = field(default_factory=list)     # (the cut's open chains near a floor, its E_h & M_h)
    heights: list[tuple[float, float]] = field(default_factory=list)   # (height, area) of each floor
    cells: np.ndarray | None = None                # cells of the floors (their walls are the cut's)


def _prepare(surface: Surface, vertices: np.ndarray, faces: np.ndarray, cut_height: float, headroom: float,
             climb_m: float, tolerance: float, max_slope: float, edge_error: float, edge_max_len: float | None,
             smooth_margin: bool) -> _Cut:
    hf = surface.hf
    exists, _, _, span_of = surface_layers(surface, clearance=False)   # heights: per span, below
    L, nz, nx = exists.shape
    cuts = ExactCuts(vertices, faces, cut_height, headroom, tolerance, math.cos(math.radians(max_slope)), climb_m)
    span_flat = np.zeros((L, nz, nx), dtype=bool)
    span_rim = np.zeros((L, nz, nx), dtype=bool)
    m = span_of >= 0
    sm = span_of[m]
    # surface spans are the walkable spans, in order: their flags (1 byte a span, where
    # the walkable spans' indices took 8 and stayed alive through the walls), kept
    # apart when the analysis let go of the heightfield's spans (keep_for_analysis)
    flags = surface.derived
    span_flat[m] = (flags["span_flat"] if "span_flat" in flags else hf.flat[hf.walkable])[sm]
    span_rim[m] = (flags["span_rim"] if "span_rim" in flags else ~hf.top_walkable[hf.walkable])[sm]
    del sm
    lev = np.arange(L)[:, None, None]
    same = _same_level_links(surface, span_of, exists)
    return _Cut(surface, hf.origin[[0, 2]], hf.cs, hf.ch, exists, surface.y, span_of, span_flat, span_rim, same, cuts,
                modelled_floors(vertices, faces), tolerance, climb_m, edge_error, edge_max_len, smooth_margin)


def _exact_floors(c: _Cut, level: int, cells: np.ndarray) -> _Floors:
    """The region's flat cells grouped by the model's floor they stand on; each floor
    big enough is cut exactly (:func:`_cut_floor`)."""
    from scipy import ndimage

    fl = _Floors(cells=np.zeros_like(cells))
    flat_cells = cells & c.span_flat[level]
    if not (flat_cells.any() and len(c.flat_h)):
        return fl
    flat_h, cell = c.flat_h, c.cell
    # each flat cell as one int32 index, and the cluster its span's top rounds up from
    fidx, pos = _flat_floor_of(flat_cells, c.span_of[level], c.span_y, flat_h, c.cell_h)
    del flat_cells
    # the floors present, sorted: np.unique(pos[okc]) without sorting (hix: 0.1 s)
    floors = np.flatnonzero(np.bincount(pos[pos >= 0], minlength=len(flat_h)))
    present = flat_h[floors]
    # the rims' cells and heights, once: per floor over the whole level they took two
    # float temporaries of 8 bytes a cell (and isin below ~25 sorting the labels)
    ri, rj = np.nonzero(cells & c.span_rim[level])
    rh = c.span_y[c.span_of[level][ri, rj]]
    for k in floors:
        sel = pos == k
        mask = np.zeros_like(cells)
        mask.ravel()[fidx[sel]] = True
        # small patches (stair treads, bumps) keep the cells' outline
        lab, nlab = ndimage.label(mask)
        big = _label_sizes(lab, nlab)[1:] * cell * cell >= MIN_EXACT_AREA
        if not big.any():
            continue
        table = np.zeros(nlab + 1, dtype=bool)   # np.isin(lab, the big labels), a byte a label
        table[1:] = big
        mask = table[lab]
        del lab
        base = float(present[present >= flat_h[k] - c.climb_m - 1e-9].min())
        # the rims of steep obstacles standing on this floor (walkable only
        # because they rise less than the climb) belong to it too
        near = np.abs(rh - flat_h[k]) <= c.climb_m
        mask[ri[near], rj[near]] = True
        fl.cells |= mask
        _cut_floor(c, cells, mask, float(flat_h[k]), base, fl)
        fl.heights.append((float(flat_h[k]), float(mask.sum() * cell * cell)))
    return fl


def _flat_floor_of(flat_cells: np.ndarray, span_of: np.ndarray, span_y: np.ndarray, flat_h: np.ndarray,
                   cell_h: float) -> tuple[np.ndarray, np.ndarray]:
    """(each flat cell's flat index, the floor (index into ``flat_h``) its span's
    height rounds up from, within a cell height; -1: none), a block of cells at a time:
    the heights, indices and their temporaries took ~60 bytes a flat cell (+0.25 GB on
    2 km).  The compiled kernel does it in one pass (hix: ~0.13 s in numpy)."""
    kern = active()
    spans = span_of.ravel()
    small = flat_cells.size < 2**31
    if kern is not None and small and spans.dtype == np.int32 and span_y.dtype == np.float64:
        fc = np.ascontiguousarray(flat_cells).ravel()
        fidx = np.empty(int(np.count_nonzero(fc)), dtype=np.int32)
        pos = np.empty(len(fidx), dtype=np.int32)
        kern.flat_floor_of(fc, np.ascontiguousarray(spans), np.ascontiguousarray(span_y),
                           np.ascontiguousarray(flat_h, dtype=np.float64), float(cell_h), fidx, pos)
        return fidx, pos
    fidx = np.flatnonzero(flat_cells).astype(np.int32 if small else np.int64)
    pos = np.empty(len(fidx), dtype=np.int32)
    for a in range(0, len(fidx), BLOCK):
        hy = span_y[spans[fidx[a:a + BLOCK]]]
        p = np.searchsorted(flat_h, hy + 1e-6, side="right") - 1
        ok = (p >= 0) & (hy - flat_h[np.maximum(p, 0)] <= cell_h + 1e-6)
        pos[a:a + BLOCK] = np.where(ok, p, -1)
    return fidx, pos


def _label_sizes(lab: np.ndarray, n: int) -> np.ndarray:
    """``np.bincount(lab.ravel(), minlength=n + 1)`` a block of cells at a time: bincount
    copies int32 labels as int64 (+0.13 GB on a 2 km terrain's level, the walls' peak)."""
    sizes = np.zeros(n + 1, dtype=np.int64)
    flat = lab.ravel()
    for a in range(0, len(flat), BLOCK):
        sizes += np.bincount(flat[a:a + BLOCK], minlength=n + 1)
    return sizes


def _cut_floor(c: _Cut, cells: np.ndarray, mask: np.ndarray, h: float, base: float, fl: _Floors) -> None:
    """Add the exact free space of the floor at height ``h`` (its cells ``mask``) near
    its cells, and what it takes away from the cells' outline, to ``fl``."""
    origin, cell = c.origin, c.cell
    sub, sub_origin = _crop(mask, _mask_box(mask, origin, cell, MARGIN + 1), origin, cell)
    # simplified as V is: where the exact floor reaches past the region's cells
    # (a walkable face beside a steep one in the same cell), M's outline is
    # the region's, and a staircase there is voxel steps again
    M = cells_polygon(sub, sub_origin, cell, c.tolerance)
    M = shapely.buffer(c.simplify(M) if c.smooth_margin else M, MARGIN * cell, join_style="mitre")
    box = M.bounds
    # the region's other cells (terrain, ramps rising from the floor or
    # coming up to a deck) are no obstacle of this floor: their outline stays
    rising = _crop(cells & ~mask, box, origin, cell)
    if rising is not None:
        up = cells_polygon(rising[0], rising[1], cell, c.tolerance)
        if c.smooth_margin:
            up = c.simplify(up)
        M = shapely.difference(M, up)
    E, chains = c.cuts.at(h, box, base)
    fl.exact.append(shapely.intersection(E, M))
    fl.removed.append(shapely.difference(M, E))
    for step in chains:
        if step:
            near = shapely.intersects(np.array(step, dtype=object), shapely.box(*box))
            fl.chains.append(([ch for ch, k in zip(step, near) if k], fl.exact[-1]))


def _region_free(c: _Cut, cells: np.ndarray, fl: _Floors):
    """The region's free space ``R = (U_h E_h & M_h) | (V - U_h (M_h - E_h))``, cleaned
    of slivers and simplified to the tolerance (empty when nothing is left)."""
    tolerance = c.tolerance
    V = c.simplify(cells_polygon(cells, c.origin, c.cell, tolerance))
    R = shapely.difference(V, shapely.union_all(fl.removed)) if fl.removed else V
    if fl.exact:
        R = shapely.union_all([R, *fl.exact])
    R = shapely.set_precision(R, tolerance)
    R = slivers.drop_slivers(R, tolerance)
    R = slivers.fill_sliver_holes(R, tolerance, c.cell)
    if R.is_empty:
        return R
    return shapely.simplify(R, tolerance, preserve_topology=True)


def _outline(c: _Cut, R, level: int, cells: np.ndarray) -> tuple[np.ndarray, float]:
    """The walls of ``R``'s boundary, less the portals to other levels, and the
    portals' length (m)."""
    outline = cut.outline_walls(R, c.tolerance)
    if not len(outline):
        return outline, 0.0
    pieces, owner = _pieces(outline, c.cell / 2)
    if c.exists.shape[0] > 1:
        portal = _portal_pieces(pieces, level, cells, c.surface, c.span_of, c.origin, c.cell)
    else:
        portal = np.zeros(len(pieces), dtype=bool)
    length = float(np.hypot(*(pieces[portal, 1] - pieces[portal, 0]).T).sum())
    return _rejoin(pieces, owner, ~portal), length


def level_walls(surface: Surface, vertices: np.ndarray, faces: np.ndarray, cut_height: float,
                headroom: float, climb_m: float, tolerance: float, max_slope: float,
                edge_error: float = EDGE_ERROR, edge_max_len: float | None = EDGE_MAX_LEN,
                smooth_margin: bool = True) -> LevelWalls:
    """Walls of every region of the surface's main region (see the module docstring).
    ``edge_error`` (cells) and ``edge_max_len`` (m, None: no limit) simplify the
    cells' outlines; ``smooth_margin`` simplifies the margins ``M_h`` so too (False,
    with ``edge_error=0.6, edge_max_len=None``: the walls before Recast's
    simplification, for bench/walls.py)."""
    c = _prepare(surface, vertices, faces, cut_height, headroom, climb_m, tolerance, max_slope, edge_error,
                 edge_max_len, smooth_margin)
    L, nz, nx = c.exists.shape
    give_back(40 * c.exists.size)   # _prepare's temporaries, before the regions' masks
    origin, cell = c.origin, c.cell
    out_seg, out_lev, out_reg = [], [], []
    regions: list[RegionWalls] = []
    thin_total = 0
    portal_len = 0.0
    repairs = Repairs()
    pair_tol = pair_tolerance(np.array([origin, origin + [nx * cell, nz * cell]]))
    for level in range(L):
        labels, n = _region_labels(c.exists[level], c.same[level])
        for k in range(1, n + 1):
            cells = labels == k
            fl = _exact_floors(c, level, cells)
            R = _region_free(c, cells, fl)
            if R.is_empty:
                continue
            outline, length = _outline(c, R, level, cells)
            portal_len += length
            thin = inner_walls(fl.chains, outline, R, cells, c.same[level], cells & ~fl.cells, origin, cell,
                               tolerance, edge_error * cell if smooth_margin else None)
            # what check would find (repeats, overlaps, normals into solid) repaired here
            segs, n_thin = repair_walls(outline, thin, R, pair_tol, repairs)
            thin_total += n_thin
            rid = len(regions)
            out_seg.append(segs)
            out_lev.append(np.full(len(segs), level))
            out_reg.append(np.full(len(segs), rid))
            ys = c.span_y[c.span_of[level][cells]]
            regions.append(RegionWalls(level, rid, R, float(np.nanmin(ys)), float(np.nanmax(ys)),
                                       float(cells.sum() * cell * cell), fl.heights))
    seg = np.concatenate(out_seg) if out_seg else np.zeros((0, 2, 2))
    walls = WallList(seg, np.ones(len(seg), dtype=np.int8), None, None, None,
                     np.concatenate(out_lev) if out_lev else None, np.concatenate(out_reg) if out_reg else None,
                     {r.region: (r.level, r.y_lo, r.y_hi) for r in regions})
    pts = seg.reshape(-1, 2) if len(seg) else np.array([origin, origin + [nx * cell, nz * cell]])
    lo = pts.min(axis=0) - AUX_MARGIN
    hi = pts.max(axis=0) + AUX_MARGIN
    walls.aux = aux_rectangle(lo[0], lo[1], hi[0], hi[1])
    give_back(40 * c.exists.size)   # the layers, links and cuts of _prepare
    return LevelWalls(walls, regions, thin_total, portal_len, repairs)


def _mask_box(mask: np.ndarray, origin: np.ndarray, cell: float, grow: float) -> tuple[float, float, float, float]:
    """World box of a mask's cells, grown by ``grow`` cells (by its rows and columns, not every cell's index)."""
    i, j = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    return (origin[0] + (j[0] - grow) * cell, origin[1] + (i[0] - grow) * cell,
            origin[0] + (j[-1] + 1 + grow) * cell, origin[1] + (i[-1] + 1 + grow) * cell)


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


def _same_level_links(surface: Surface, span_of: np.ndarray, exists: np.ndarray) -> np.ndarray:
    """(L, nz, nx, 4): the node's span links in direction d to a span on the node's own
    level.  Each span's four linked levels are looked up once as a small table (int8
    while the levels fit, -1 for none) and gathered per node in one pass: four gathers
    of int64 span links per node took a third of the walls' time on a 2 km terrain."""
    L, nz, nx = exists.shape
    small = np.int8 if L < 127 else np.int32
    lv = np.empty(len(surface.level) + 1, dtype=small)   # not np.append's copy of the levels as they are
    lv[:-1], lv[-1] = surface.level, -1
    # (n, 4); a missing link (-1) reads the appended -1.  One level: every link stays on it (hix: -40 ms)
    linked = lv[surface.link] if L > 1 else surface.link >= 0
    del lv
    lev = np.arange(L, dtype=small)[:, None, None, None]
    # a block of rows at a time: the whole grid's gathered levels, compare and mask
    # were four temporaries of 4 bytes a node (~0.25 GB on a 2 km terrain, the walls' peak)
    out = np.empty((L, nz, nx, 4), dtype=bool)
    rows = max(1, BLOCK // max(L * nx, 1))
    for a in range(0, nz, rows):   # take clipped: span -1 (no node) reads span 0, masked by exists (hix: 48 -> 21 ms)
        o = np.take(linked, span_of[:, a:a + rows], axis=0, mode="clip")
        out[:, a:a + rows] = (o if L == 1 else o == lev) & exists[:, a:a + rows][..., None]
    return out


def surface_link_level(surface: Surface, span_of: np.ndarray, d: int) -> np.ndarray:
    """(L, nz, nx): the level of the span each node's span links to in direction d (-1)."""
    lv = np.append(surface.level, -1)
    t = np.where(span_of >= 0, surface.link[np.maximum(span_of, 0), d], -1)
    return np.where(span_of >= 0, lv[t], -1)


def _region_labels(cells: np.ndarray, same: np.ndarray) -> tuple[np.ndarray, int]:
    """Components of a level's cells joined by links that stay on the level (labels
    1..n in the order of each one's first cell, 0 elsewhere)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from .navgrid import compiled_labels

    steps = np.where(same, np.int8(0), np.int8(-1))[None]  # a one-level grid's links, int8
    compiled = compiled_labels(cells[None], steps)
    if compiled is not None:  # the same labels in 5 bytes a cell, where the pairs below take ~70
        return compiled[0][0], compiled[1]
    del steps
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
