"""Walkable surfaces: from the voxel heightfield to connected, layered open spans.

After :mod:`tanktool.geometry.heightfield` has rasterised and filtered the solid spans,
this module does what Recast's compact heightfield does:

* every walkable span becomes an *open span*: its floor is the span's top, its ceiling
  the bottom of the next span up (open sky above the highest);
* two open spans of neighbouring columns are *linked* when a tank can pass from one
  to the other: the floors differ by at most the climb and the overlap of the two open
  intervals is at least the headroom (the lowest such span of the neighbour column);
* a span's *clearance* is its distance to the nearest edge of walkable space (a side
  of a span without a link), measured along the links with Recast's chamfer weights
  (2 a straight step, 3 a diagonal one, in half cells) from half a cell at the edge;
* connected *regions* are the components of the link graph; the region the arena is
  played on is the largest (or the one holding given seed points);
* the spans of that region are stacked into *levels*: a span's level is the number of
  the region's spans below it in its column (0 on the ground, 1 on a deck over a
  passage, ...), so that each level holds at most one span a column; the top of a
  ramp up to a deck over the ground joins the deck's level (:mod:`.level_stack`,
  :mod:`.level_lift`).

Everything is numpy over spans; the links are found by pairing each span with the
spans of its neighbour column.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field

import numpy as np

from ..errors import ArenaError
from ..memory import give_back
from ..geometry.kernels import active, i64
from ..geometry.heightfield import OPEN, Heightfield, build_heightfield, column_starts, neighbour_columns
from .level_lift import lift_steps
from .level_stack import stack_levels

#: the four link directions as (di, dj) on the grid: +x, +z, -x, -z (navgrid.STEPS order)
DIRS = ((0, 1), (1, 0), (0, -1), (-1, 0))

#: defaults for tanks: slopes a tank climbs, steps it drives over; headroom defaults to
#: the tallest bundled vehicle (tanktool.fleet)
MAX_SLOPE = 35.0
CLIMB = 0.9
CELL_HEIGHT = 0.1


@dataclass
class WalkableParams:
    """How walkable surfaces are found (metres and degrees).

    cell : voxel and navigation-grid cell size;  cell_height : voxel height
    max_slope : steepest walkable face;  climb : highest step between neighbours
    headroom : free height a span needs above it
    """

    cell: float = 0.5
    cell_height: float = CELL_HEIGHT
    max_slope: float = MAX_SLOPE
    climb: float = CLIMB
    headroom: float = 2.0

    def check(self) -> "WalkableParams":
        """Raise ArenaError naming the option when a value is absurd."""
        def bad(name: str, value: float, lo: float, hi: float, open_lo: bool = True) -> None:
            ok = math.isfinite(value) and (value > lo if open_lo else value >= lo) and value <= hi
            if not ok:
                raise ArenaError(f"--{name} must be {'>' if open_lo else '>='} {lo:g} and <= {hi:g}, got {value:g}")
        bad("cell", self.cell, 0.0, 50.0)
        bad("cell-height", self.cell_height, 0.0, 10.0)
        bad("max-slope", self.max_slope, 0.0, 89.0)
        bad("climb", self.climb, 0.0, 100.0, open_lo=False)
        bad("headroom", self.headroom, 0.0, 1000.0)
        if self.cell_height > max(self.headroom, 1e-9) / 3:
            raise ArenaError(f"--cell-height {self.cell_height:g} is too coarse for a headroom of "
                             f"{self.headroom:g} m (at most a third of it)")
        return self

    def as_toml(self) -> dict[str, float]:
        return {"cell": float(self.cell), "cell_height": float(self.cell_height), "max_slope": float(self.max_slope),
                "climb": float(self.climb), "headroom": float(self.headroom)}

    def describe(self) -> str:
        return (f"cell {self.cell:g} m, cell height {self.cell_height:g} m, max slope {self.max_slope:g} deg, "
                f"climb {self.climb:g} m, headroom {self.headroom:g} m")


@dataclass
class Surface:
    """Open spans (one per walkable span) of a heightfield, sorted by (column, floor).

    col : (n,) column ``i * nx + j``;  floor / ceil : (n,) in cell-height steps (int32)
    link : (n, 4) index of the linked span in each direction (DIRS), -1 for none (int32, link_dtype)
    clearance : (n,) metres to the nearest edge (capped at ``max_clearance``); None in a
        lean surface (``walkable_surface(lean=True)``: its grid reads the walls' distance)
    region : (n,) component label (int32 below 2**31 spans);  main : (n,) in the played region
    level : (n,) the span's level among the main region's spans (-1 outside it)
    """

    hf: Heightfield
    col: np.ndarray
    floor: np.ndarray
    ceil: np.ndarray
    link: np.ndarray
    clearance: np.ndarray | None
    region: np.ndarray
    main: np.ndarray
    level: np.ndarray
    max_clearance: float
    stats: dict = field(default_factory=dict)
    height: np.ndarray | None = None
    #: what is derived from the finished surface and asked for twice (the import's
    #: report and its picture: surface_report.too_small by radius), kept with it
    derived: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def shape(self) -> tuple[int, int]:
        return self.hf.shape

    @property
    def levels(self) -> int:
        # one pass over the spans, asked ~11 times an import (hix: ~30 ms in all): kept
        # while ``level`` is the same array, weakly (a level let go is not kept alive)
        memo = self.__dict__.get("_levels_of")
        if memo is not None and memo[0]() is self.level:
            return memo[1]
        top = int(self.level.max()) if len(self.level) else -1
        self.__dict__["_levels_of"] = (weakref.ref(self.level), top + 1 if top >= 0 else 0)
        return self.__dict__["_levels_of"][1]

    @property
    def y(self) -> np.ndarray:
        """World height of each span's floor: the height of the horizontal faces it
        stands on where there are any (exact), else the middle of its top voxel step
        (within half a cell height)."""
        if self.height is not None:
            return self.height
        return self.hf.origin[1] + (self.floor - 0.5) * self.hf.ch

    def ij(self) -> tuple[np.ndarray, np.ndarray]:
        return np.divmod(self.col, self.hf.shape[1])


def link_dtype(n: int) -> type:
    """The dtype of the links of ``n`` spans: int32 (16 bytes a span where int64 took
    32: the largest array of a surface) unless the indices need more."""
    return np.int32 if n < 2**31 - 1 else np.int64


def link_spans(col: np.ndarray, floor: np.ndarray, ceil: np.ndarray, shape: tuple[int, int],
               headroom: int, climb: int) -> np.ndarray:
    """(n, 4) links between open spans (see the module docstring); steps in cells.

    The spans of each neighbour column are tried k-th by k-th, lowest first; a span's
    link is the first that fits.
    """
    nz, nx = shape
    n = len(col)
    start = column_starts(col, nz * nx)
    kern = active()
    if kern is not None and link_dtype(n) == np.int32:   # the kernel writes every link: no fill first
        link = np.empty((n, 4), dtype=np.int32)
        narrow = floor.dtype == ceil.dtype == np.int32   # the kernel reads them as they are
        fc = [np.ascontiguousarray(a) if narrow else i64(a) for a in (floor, ceil)]
        kern.link_spans(i64(col), *fc, start, nz, nx, int(headroom), int(climb), link)
        return link
    link = np.full((n, 4), -1, dtype=link_dtype(n))
    count = np.diff(start)
    for d, ncol in enumerate(neighbour_columns(col, shape)):
        off = ncol < 0
        nc = np.where(off, 0, ncol)
        cnt = np.where(off, 0, count[nc])
        first = start[nc]
        out = link[:, d]
        idx = np.arange(n)
        k = 0
        while True:
            idx = idx[cnt[idx] > k]
            if not len(idx):
                break
            kk = first[idx] + k
            f0, f1 = floor[idx], floor[kk]
            ok = (np.minimum(ceil[idx], ceil[kk]) - np.maximum(f0, f1) >= headroom) & (np.abs(f1 - f0) <= climb)
            out[idx[ok]] = kk[ok]
            idx = idx[~ok]
            k += 1
    return link


def chamfer_clearance(link: np.ndarray, limit: int, col: np.ndarray | None = None,
                      shape: tuple[int, int] | None = None) -> np.ndarray:
    """Chamfer distance (half cells) from each span to the nearest edge of walkable space.

    A span with a side lacking a link is half a cell (1) from the edge; a straight step
    costs 2, a diagonal one 3 (through either of its two straight paths, both links
    present).  Values stop growing at ``limit``: only whether a span is that far
    matters, and the relaxation needs about limit / 2 rounds.  ``col`` and ``shape``:
    the spans' columns, when every link leads to a neighbour column (:func:`link_spans`'
    links): the compiled sweeps then relax only spans near the last changes.
    """
    n = len(link)
    # int32 from the start; a span's four "no link" flags read as one 4-byte word, where
    # numpy's any(axis=1) took 1.2 ms on 84 k spans
    edge = np.ascontiguousarray(link < 0).view(np.uint32).ravel() != 0
    dist = np.where(edge, np.int32(1), np.int32(limit))
    if n == 0:
        return dist
    kern = active()
    if kern is not None and link.dtype != np.int32 and n < 2**31 - 1:
        # int64 links (the agents' surface graph, layers.surface_clearance): an int32 copy
        # for the kernel, where numpy's relaxation takes ~130 bytes a span of temporaries
        link = link.astype(np.int32)
    if kern is not None and link.dtype == np.int32:  # sweeps to the same fixed point (tanktool/_kernels.c)
        if col is not None and shape is not None:
            # on open ground most spans are far from any edge and never change: a sweep
            # skips the columns around which nothing changed (bridge 86 k spans: 3.7 -> 1.0 ms)
            kern.chamfer_near(np.ascontiguousarray(link), dist, int(limit), i64(col), int(shape[1]),
                              int(shape[0] * shape[1]))
        else:
            kern.chamfer(np.ascontiguousarray(link), dist, int(limit))
        return dist
    # index n is a sentinel at distance 0: a missing link leads off the edge
    safe = [np.ascontiguousarray(np.where(link[:, d] < 0, n, link[:, d])) for d in range(4)]
    ext_safe = [np.append(a, n) for a in safe]
    diag = []
    for d in range(4):
        e = (d + 1) % 4
        diag.append(np.minimum(ext_safe[e][safe[d]], n) if True else None)
        diag.append(ext_safe[d][safe[e]])
    ext = np.zeros(n + 1, dtype=np.int32)
    for _ in range(limit // 2 + 2):
        ext[:n] = dist
        new = dist.copy()
        for a in safe:
            np.minimum(new, ext[a] + 2, out=new)
        for a in diag:
            np.minimum(new, ext[a] + 3, out=new)
        if np.array_equal(new, dist):
            break
        dist = new
    return dist


def components(link: np.ndarray) -> np.ndarray:
    """Connected-component label of each span over its links (the smallest span index
    in its component), a link counting both ways (it need not have its reverse):
    scipy's linear-time graph components over the (span, neighbour) pairs."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(link)
    if n == 0:
        return np.arange(0, dtype=np.int64)
    kern = active()
    if kern is not None and link.dtype == np.int32:  # union-find, the smaller index the root: the same labels
        label = np.empty(n, dtype=np.int64)
        kern.components(np.ascontiguousarray(link), label)
        return label
    ok = link >= 0
    dst = link[ok]                                   # row by row: the rows come sorted
    indptr = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(ok.sum(axis=1), out=indptr[1:])
    graph = csr_matrix((np.ones(len(dst), dtype=np.int8), dst, indptr), shape=(n, n))
    k, comp = connected_components(graph, directed=True, connection="weak")
    # the smallest span of each component: written from the last span to the first,
    # so the smallest index is written last
    first = np.empty(k, dtype=np.int64)
    first[comp[::-1]] = np.arange(n - 1, -1, -1, dtype=np.int64)
    return first[comp]


def walkable_surface(vertices: np.ndarray, faces: np.ndarray, params: WalkableParams, clearance: float,
                     origin_xz=None, shape=None, seeds: np.ndarray | None = None, lean: bool = False) -> Surface:
    """Triangles to surface in one call: :func:`build_heightfield` then
    :func:`build_surface`.

    ``lean``: only what a grid judged by the walls' exact distance needs
    (``grid_from_surface(too_close=...)``): no clearance (the chamfer distance is not
    run), and the heightfield's spans and the ceilings are let go once the heights
    are known (a third of the surface's memory: ~0.8 GB on a 2 km terrain)."""
    from ..geometry.heightfield import flat_heights

    hf = build_heightfield(vertices, faces, params.cell, params.cell_height, params.max_slope, params.headroom,
                           params.climb, origin_xz, shape)
    surface = build_surface(hf, params.headroom, params.climb, clearance, seeds, distance=not lean)
    surface.height = snap_heights(surface, flat_heights(np.asarray(vertices, dtype=np.float64), faces)[0])
    if lean:
        surface.hf = hf.geometry()
        surface.ceil = np.zeros(0, dtype=surface.ceil.dtype)
    give_back(200 * len(surface.col))   # the rasteriser's pieces and the surface's temporaries
    return surface


#: spans per block of the passes that would otherwise make several temporaries of 8
#: bytes a span at once (snap_heights, surface_layers): ~50 MB of them at a time, where
#: a 2 km terrain's 16 M spans took +0.7 GB; blocks give the same values element by element
BLOCK = 1 << 20


def snap_heights(surface: Surface, flat: np.ndarray) -> np.ndarray:
    """Span floors as heights: a flat span's top voxel step [top - ch, top) holds the
    height of the horizontal faces it stands on, found among ``flat`` (sorted cluster
    heights); other spans get the middle of that step."""
    hf = surface.hf
    n = len(surface.floor)
    out = np.empty(n)
    walk = hf.walkable
    kern = active()
    if kern is not None and surface.floor.dtype == np.int32:   # one pass, no blocks of temporaries
        kern.snap_heights(np.ascontiguousarray(surface.floor), np.ascontiguousarray(walk, dtype=bool),
                          np.ascontiguousarray(hf.flat, dtype=bool), np.ascontiguousarray(flat, dtype=np.float64),
                          float(hf.origin[1]), float(hf.ch), out)
        return out
    pos = 0
    for a in range(0, max(len(walk), 1), BLOCK):  # the surface's spans are the walkable ones, in order
        w = a + np.flatnonzero(walk[a:a + BLOCK])
        sl = slice(pos, pos + len(w))
        pos += len(w)
        top = hf.origin[1] + surface.floor[sl] * hf.ch
        y = top - 0.5 * hf.ch
        if len(flat) == 0 or len(top) == 0:
            out[sl] = y
            continue
        is_flat = hf.flat[w]
        k = np.searchsorted(flat, top + 1e-9, side="right") - 1  # the highest cluster at or below the top
        ok = is_flat & (k >= 0)
        h = flat[np.maximum(k, 0)]
        ok &= h >= top - hf.ch - 1e-9
        out[sl] = np.where(ok, h, y)
    return out


def build_surface(hf: Heightfield, headroom: float, climb: float, max_clearance: float,
                  seeds: np.ndarray | None = None, distance: bool = True) -> Surface:
    """Open spans, links, clearance, regions and levels of a filtered heightfield.

    ``seeds`` (k, 2) world (x, z) points: the played region is the one holding the
    span nearest each (all such regions); default the largest region.  ``distance``
    False: no clearance (None; the chamfer distance is not run).
    """
    head = int(math.ceil(headroom / hf.ch - 1e-9))
    clim = int(math.floor(climb / hf.ch + 1e-9))
    col, floor, ceil = open_spans(hf)
    link = link_spans(col, floor, ceil, hf.shape, head, clim)
    clearance = _clearance(link, max_clearance, hf.cs, col, hf.shape) if distance else None
    region = components(link) if len(col) else np.zeros(0, dtype=np.int64)
    if len(col) < 2**31 - 1:
        region = region.astype(np.int32)
    main = _main_region(hf, col, floor, region, seeds)
    level = stack_levels(col, main, link, lift=lift_steps(hf.cs))
    return Surface(hf, col, floor, ceil, link, clearance, region, main, level, float(max_clearance),
                   {"climb_steps": clim, "headroom_steps": head})


def open_spans(hf: Heightfield) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The walkable spans' columns (int64), floors (their tops) and ceilings (the next
    span's bottom in the column, OPEN above the top one): the floors and ceilings int32
    (steps up to OPEN: 12 bytes a span less while the surface lives, ~0.2 GB on a 2 km
    terrain)."""
    w = hf.walkable
    kern = active()
    if kern is not None and all(a.dtype == np.int32 for a in (hf.col, hf.smin, hf.smax)):
        m = int(np.count_nonzero(w))   # one pass, where numpy's masks and ceilings took 1-2 ms on 100 k spans
        col, floor, ceil = np.empty(m, dtype=np.int64), np.empty(m, dtype=np.int32), np.empty(m, dtype=np.int32)
        kern.open_spans(*(np.ascontiguousarray(a) for a in (hf.col, hf.smin, hf.smax)),
                        np.ascontiguousarray(w, dtype=bool), col, floor, ceil)
        return col, floor, ceil
    ceil_all = hf.ceiling()
    col, floor, ceil = hf.col[w].astype(np.int64), hf.smax[w], np.minimum(ceil_all[w], OPEN)
    del ceil_all
    return col, floor.astype(np.int32), ceil.astype(np.int32)


def _clearance(link: np.ndarray, max_clearance: float, cs: float, col: np.ndarray | None = None,
               shape: tuple[int, int] | None = None) -> np.ndarray:
    """Metres from each span to the nearest edge, inf from ``max_clearance`` on
    (``col``, ``shape``: as :func:`chamfer_clearance`)."""
    limit = int(math.ceil(2 * max_clearance / cs)) + 2
    dist = chamfer_clearance(link, limit, col, shape)
    clearance = dist * (cs / 2)  # the same values as dist * cs / 2 (halving is exact), one array
    clearance[dist >= limit] = np.inf
    return clearance


def reseed(surface: Surface, max_clearance: float, seeds: np.ndarray | None = None) -> Surface:
    """The surface :func:`build_surface` would build from the same heightfield with
    another ``max_clearance`` and ``seeds``, without building it again: the open spans,
    links, regions and heights do not depend on them and are shared; the played
    region and its levels are found anew.  A smaller vehicle's grid needs this of the
    larger one's surface (one heightfield for every vehicle where each rebuilt it:
    ~15 s and +0.9 GB apiece on a 2 km terrain)."""
    hf = surface.hf
    limit = int(math.ceil(2 * max_clearance / hf.cs)) + 2
    old = int(math.ceil(2 * surface.max_clearance / hf.cs)) + 2
    if surface.clearance is None:  # a lean surface's
        clearance = None
    elif limit <= old:
        # the chamfer capped at ``limit`` is min(distance, limit): the same fixed point,
        # so the larger cap's values give the smaller cap's exactly (dist * cs / 2 is exact)
        clearance = surface.clearance.copy()
        clearance[surface.clearance >= limit * (hf.cs / 2)] = np.inf
    else:
        clearance = _clearance(surface.link, max_clearance, hf.cs, surface.col, hf.shape)
    main = _main_region(hf, surface.col, surface.floor, surface.region, seeds)
    level = stack_levels(surface.col, main, surface.link, lift=lift_steps(hf.cs))
    return Surface(hf, surface.col, surface.floor, surface.ceil, surface.link, clearance, surface.region, main,
                   level, float(max_clearance), dict(surface.stats), surface.height)


def _main_region(hf: Heightfield, col, floor, region, seeds) -> np.ndarray:
    """The played region: the regions of the spans under the seed points (``[x, z]``
    or ``[x, z, y]``: the span nearest across, then nearest in height; without a height
    the largest region among the column's spans), else the largest region."""
    if len(col) == 0:
        return np.zeros(0, dtype=bool)
    # counted only when asked: labels run up to the span count (hix: 20 ms a count), and
    # seeds with their heights (a bundle's spawns) never ask
    sizes = np.zeros(0, dtype=np.int64)
    if seeds is not None and len(seeds):
        nz, nx = hf.shape
        s = np.asarray(seeds, dtype=np.float64).reshape(len(seeds), -1)
        sj = np.clip(np.floor((s[:, 0] - hf.origin[0]) / hf.cs), 0, nx - 1).astype(np.int64)
        si = np.clip(np.floor((s[:, 1] - hf.origin[2]) / hf.cs), 0, nz - 1).astype(np.int64)
        ij = None
        picked = []
        for k, (a, b) in enumerate(zip(si, sj)):
            # the seed's own column when it has spans (col is sorted): the nearest at
            # distance 0, found without a pass over every span (~0.1 s a seed on 1 km)
            lo, hi = np.searchsorted(col, [a * nx + b, a * nx + b + 1])
            if hi > lo:
                near = np.arange(lo, hi)
            else:
                if ij is None:
                    ij = np.divmod(col, nx)
                d = (ij[0] - a) ** 2 + (ij[1] - b) ** 2
                near = np.flatnonzero(d == d.min())
            if s.shape[1] >= 3 and np.isfinite(s[k, -1]):
                y = hf.origin[1] + floor[near] * hf.ch
                pick = near[int(np.argmin(np.abs(y - s[k, -1])))]
            else:
                sizes = sizes if len(sizes) else np.bincount(region)
                pick = near[int(np.argmax(sizes[region[near]]))]
            picked.append(region[pick])
        # the seeds' few regions a compare each: isin's table pass took ~10 of them (hix)
        picked = np.unique(picked)
        return np.isin(region, picked) if len(picked) > 4 else np.logical_or.reduce([region == p for p in picked])
    return region == int(np.argmax(np.bincount(region)))


def surface_layers(surface: Surface, clearance: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray | None,
                                                                       np.ndarray]:
    """The main region's spans as ``(L, nz, nx)`` layers: (node exists, height, voxel
    clearance in metres (None when not asked for), span index or -1; int32 when the
    spans' indices fit, as they do but on levels of billions of spans)."""
    nz, nx = surface.shape
    L = max(surface.levels, 1)
    exists = np.zeros(L * nz * nx, dtype=bool)
    height = np.full(L * nz * nx, np.nan)
    span = np.full(L * nz * nx, -1, dtype=np.int32 if len(surface.col) < 2**31 else np.int64)
    clear = np.zeros(L * nz * nx) if clearance else None  # 8 bytes a node: only for those who read it
    kern = active()
    if (kern is not None and span.dtype == np.int32 and surface.height is not None
            and (clear is None or surface.clearance is not None)):  # one pass (_kernels_surface.c)
        empty = np.zeros(0)
        kern.scatter_layers(i64(surface.level), i64(surface.col), np.ascontiguousarray(surface.height, dtype=float),
                            empty if clear is None else np.ascontiguousarray(surface.clearance, dtype=float),
                            nz * nx, exists, height, span, empty if clear is None else clear)
    else:
        _scatter_layers(surface, exists, height, span, clear)
    shape = (L, nz, nx)
    if clear is not None:
        clear = clear.reshape(shape)
    return exists.reshape(shape), height.reshape(shape), clear, span.reshape(shape)


def _scatter_layers(surface: Surface, exists: np.ndarray, height: np.ndarray, span: np.ndarray,
                    clear: np.ndarray | None) -> None:
    """surface_layers' scatter in numpy: each span of a level into its node's arrays."""
    nz, nx = surface.shape
    hf = surface.hf
    for a in range(0, len(surface.level), BLOCK):  # the scatter's indices a block at a time
        m = a + np.flatnonzero(surface.level[a:a + BLOCK] >= 0)
        at = surface.level[m] * (nz * nx) + surface.col[m]  # flat index into (L, nz, nx)
        exists[at] = True
        # surface.y of these spans (the same arithmetic, on the block only)
        if surface.height is not None:
            height[at] = surface.height[m]
        else:
            height[at] = hf.origin[1] + (surface.floor[m] - 0.5) * hf.ch
        span[at] = m
        if clear is not None:
            clear[at] = surface.clearance[m]


def level_nodes(surface: Surface, level: int = 0) -> np.ndarray:
    """``(nz, nx)`` mask of the nodes of one level: ``surface_layers(surface)[0][level]``
    without the layers' heights and span indices (13 bytes a node of every level)."""
    nz, nx = surface.shape
    out = np.zeros(nz * nx, dtype=bool)
    for a in range(0, len(surface.level), BLOCK):
        out[surface.col[a:a + BLOCK][surface.level[a:a + BLOCK] == level]] = True
    return out.reshape(nz, nx)


def _grid_links(surface: Surface, exists: np.ndarray, span: np.ndarray) -> np.ndarray:
    """(L * nz * nx, 4) int8: the level each node's span links to in each direction
    when that span is a node too, else -1 (flat indices throughout)."""
    L, nz, nx = exists.shape
    per = nz * nx
    link = np.full((L * per, 4), -1, dtype=np.int8)
    kern = active()
    if kern is not None and span.dtype == np.int32 and surface.link.dtype == np.int32:
        # one pass, where numpy's takes ~40 bytes a node of temporaries per direction
        kern.grid_links(np.ascontiguousarray(span), np.ascontiguousarray(surface.link), i64(surface.level),
                        i64(surface.col), np.ascontiguousarray(exists), per, link)
        return link
    node = np.flatnonzero(exists)
    sp = span.ravel()[node]
    vflat = exists.ravel()
    lv_of = np.append(surface.level, -1)  # span -1 (no link) -> level -1
    col_of = np.append(surface.col, 0)
    for d in range(4):
        t = surface.link[sp, d]
        tl = lv_of[t]
        target = tl * per + col_of[t]
        ok = tl >= 0
        ok[ok] = vflat[target[ok]]
        link[node[ok], d] = tl[ok]
    return link


def grid_from_surface(surface: Surface, clearance: float, origin_xz: np.ndarray, seeds: np.ndarray | None = None,
                      too_close: np.ndarray | None = None, runs: bool = True, window=None):
    """The layered navigation grid of a surface (cell = the heightfield's cell).

    There is a node wherever the main region has a span (its height and links are
    kept); it is valid where that span's clearance (the voxel chamfer distance, or, when
    ``too_close`` (L, nz, nx) is given, the exact distance to the level's walls) is at
    least ``clearance``.  ``seeds`` (k, 2+) spawn points
    ``[x, z, ...]`` mark the reachable nodes (all valid nodes when None); ``runs``:
    see :func:`grid_from_layers`.  ``window`` (a ``grid_window.Window`` of the surface's
    lattice): the nodes cut to it, at its origin (``origin_xz`` unused; ``too_close``
    on the window), as a bundle's grid is (nav/grid_window.py).
    """
    exists, height, clear, span = surface_layers(surface, clearance=too_close is None)
    L, nz, nx = exists.shape
    # each node's span, and the node its link reaches: flat indices throughout.  Links
    # and heights are kept for every node of the surface, valid (a tank fits) or not:
    # the simulation drives on all of it; runs, reachability and paths use valid nodes.
    link = _grid_links(surface, exists, span).reshape(L, nz, nx, 4)
    del span
    if window is not None:
        from .grid_window import crop, crop_links

        link, exists, height = crop_links(link, window), crop(exists, window, False), crop(height, window, np.nan)
        clear = None if clear is None else crop(clear, window, 0.0)
        origin_xz = window.origin
    valid = exists & (clear >= clearance) if too_close is None else exists & ~too_close
    del clear, exists
    return grid_from_layers(valid, height, link, clearance, origin_xz, surface.hf.cs, seeds, runs)


def grid_from_layers(valid: np.ndarray, height: np.ndarray, link: np.ndarray, clearance: float,
                     origin_xz: np.ndarray, cell: float, seeds: np.ndarray | None = None, runs: bool = True):
    """The layered grid of its nodes' layers (:func:`grid_from_surface`'s valid,
    heights and links, kept as they are): runs and the nodes reachable from ``seeds``.
    Two vehicles' grids of one surface with the same levels share heights and links.
    ``runs`` False: the run arrays are left empty, for a caller that reads only the
    nodes, links and heights (the analysis' spawns: ``arena_levels.tank_grid``)."""
    from .navgrid import NavGrid, layered_reachable, layered_runs, nearest_valid_node3

    L, nz, nx = valid.shape
    ri = rt = ci = ct = np.zeros((0, 0, 0), dtype=np.int32)
    if runs:
        ri, rt, ci, ct = layered_runs(valid, link)
    seeds_n: list = []
    if seeds is not None and len(seeds):
        reach = int(math.ceil(clearance / cell)) + 2
        for sp in np.asarray(seeds, dtype=np.float64).reshape(len(seeds), -1):
            node = (int(np.clip(math.floor((sp[1] - origin_xz[1]) / cell), 0, nz - 1)),
                    int(np.clip(math.floor((sp[0] - origin_xz[0]) / cell), 0, nx - 1)))
            y = float(sp[3]) if len(sp) > 3 and math.isfinite(sp[3]) else None
            n = nearest_valid_node3(valid, height, node, y, reach)
            if n is not None:
                seeds_n.append(n)
        reachable = layered_reachable(valid, link, seeds_n) if seeds_n else np.zeros_like(valid)
    else:
        reachable = valid.copy()
    give_back(60 * valid.size)   # the layers' temporaries
    return NavGrid(np.asarray(origin_xz, dtype=np.float64), float(cell), (nz, nx), valid, ri, rt, ci, ct, reachable,
                   float(clearance), spawn_nodes=seeds_n, height=height, link=link)
