"""Large heightfields built in tiles, on every core, with the same result.

A tile is a band of grid rows (all the columns).  Its spans are rasterised from the
triangles that reach it, at the grid's own coordinates (the same arithmetic as the
whole build: a column's spans depend only on the triangles over it), merged, and
filtered with one row more on each side: Recast's filters look at a span's own column
and its four neighbours only, so the band's inner rows come out exactly as in the
whole build (the border rows are rasterised again by the next band and dropped here).
Bands are concatenated in order, which keeps the spans sorted by column.

Bands run on worker threads, one per core: the compiled rasteriser and filters
(tanktool/_kernels*.c) let go of the GIL, so the threads share the model and hand
back their spans without copies (forked worker processes, before, cost 4.8-5.6 s of
CPU on the 2 km terrain where threads take 3.7-4.0: the fork and the spans pickled
back).  The work in flight -- the (triangle, cell) pieces, the keys sorted for
merging -- is one band per worker, not the whole level.  Without the kernels the
numpy path runs the same way (numpy lets go of the GIL in its large operations).

    hf = build_heightfield(vertices, faces, 0.5, 0.1, 35, 2.35, 0.9)   # tiles by itself when large
    hf = build_heightfield(vertices, faces, 0.5, 0.1, 35, 2.35, 0.9, band_rows=256, workers=2)   # bands of 256 rows on 2 threads
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from functools import partial
from typing import Any, Callable

import numpy as np

from ..memory import give_back
from .span_filters import filter_masks

#: levels with more columns than this are built in bands (by build_heightfield)
TILE_COLUMNS = 4_000_000
#: columns a band holds, about (its rows: this over the grid's width)
BAND_COLUMNS = 1_000_000

def bands(nz: int, nx: int, band_rows: int | None = None) -> list[tuple[int, int]]:
    """[first, last) rows of each band."""
    rows = band_rows or max(1, BAND_COLUMNS // max(nx, 1))
    return [(a, min(a + rows, nz)) for a in range(0, nz, rows)]


def _band(j: dict[str, Any], lo: int, hi: int) -> tuple:
    """The spans of rows [lo, hi) of the level ``j``, filtered, and their counts (see
    the module docstring)."""
    from .heightfield import rasterize

    nz, nx = j["shape"]
    b_lo, b_hi = max(lo - 1, 0), min(hi + 1, nz)
    # rows [b_lo, lo), [lo, hi), [hi, b_hi) rasterised apart: the pieces of the inner
    # rows are counted as the whole build counts them
    parts, pairs = [], 0
    for a, b in ((b_lo, lo), (lo, hi), (hi, b_hi)):
        if b <= a:
            continue
        tri = j["tri_of_rows"](a, b)
        # the band's triangles with their own corners: rasterize works out grid units for
        # every vertex it is given (the whole model's, 46 times on the 2 km terrain: 0.6 s)
        corners = j["vertices"][j["faces"][tri].ravel()]
        spans, n = rasterize(corners, np.arange(len(corners)).reshape(-1, 3), j["cs"], j["ch"], j["walk_f"][tri],
                             j["flat_f"][tri], j["origin"], j["shape"], j["climb"], rows=(a, b))
        parts.append(spans)
        if a == lo:
            pairs = n
    col, smin, smax, walk, flat, top_walk = (np.concatenate(v) for v in zip(*parts))
    local = col - b_lo * nx  # the band as a grid of its own (its edges off the grid only at the level's)
    w3, lifted, ledge, steep, low = filter_masks(local, smin, smax, walk, (b_hi - b_lo, nx), j["head"], j["climb"])
    inner = (col >= lo * nx) & (col < hi * nx)
    counts = {"pairs": pairs, "spans": int(inner.sum()), "walkable_raw": int((walk & inner).sum()),
              "lifted": int((lifted & inner).sum()), "ledge": int((ledge & inner).sum()),
              "steep": int((steep & inner).sum()), "low": int((low & inner).sum())}
    return (col[inner], smin[inner], smax[inner], w3[inner], flat[inner], top_walk[inner], low[inner]), counts


def _triangles_by_row(vertices: np.ndarray, faces: np.ndarray, origin: np.ndarray, cs: float):
    """A function (first, last) -> the triangles whose z range reaches rows [first, last):
    triangles sorted by their first row, each band a binary search (a triangle is in a
    band when its rows overlap it; the rasteriser drops what falls outside)."""
    gz = (vertices[:, 2] - origin[2]) / cs
    z = gz[faces]
    r0 = np.floor(z.min(axis=1))
    r1 = np.ceil(z.max(axis=1))  # one past the last row, or the row itself for a flat-in-z triangle
    order = np.argsort(r0, kind="stable")
    r0s = r0[order]
    # the widest triangle bounds how far back a band must look
    reach = float((r1 - r0).max()) if len(r0) else 0.0

    def of_rows(first: int, last: int) -> np.ndarray:
        a = np.searchsorted(r0s, first - reach - 1, side="left")
        b = np.searchsorted(r0s, last, side="right")
        cand = order[a:b]
        keep = (r1[cand] >= first) & (r0[cand] <= last)
        return np.sort(cand[keep])

    return of_rows


def build_tiled(vertices: np.ndarray, faces: np.ndarray, cs: float, ch: float, walk_f: np.ndarray,
                flat_f: np.ndarray, origin: np.ndarray, shape: tuple[int, int], head: int, climb: int,
                band_rows: int | None = None, workers: int | None = None) -> tuple[tuple, dict]:
    """The filtered spans of the whole grid, band by band (build_heightfield's arrays
    and counts, identical to its single pass)."""
    nz, nx = shape
    todo = bands(nz, nx, band_rows)
    job = dict(vertices=vertices, faces=faces, cs=cs, ch=ch, walk_f=walk_f, flat_f=flat_f, origin=origin,
               shape=shape, head=head, climb=climb, tri_of_rows=_triangles_by_row(vertices, faces, origin, cs))
    if workers is None:
        workers = min(len(todo), os.cpu_count() or 1)
    results = _run(partial(_band, job), todo, workers)
    counts: dict[str, int] = {}
    for _, c in results:
        for k, v in c.items():
            counts[k] = counts.get(k, 0) + v
    # one array at a time, the bands' pieces of it let go as soon as it is joined: the
    # bands and the whole level were both alive (2 x 28 bytes a span: +0.45 GB on 2 km)
    fields = [list(r[0]) for r in results]
    del results
    spans = []
    for k in range(len(fields[0]) if fields else 0):
        # columns, bottoms and tops joined as the int32 the Heightfield keeps (they fit:
        # MAX_COLUMNS, MAX_HEIGHT_STEPS), not as int64 then copied: the same values
        dtype = np.int32 if k < 3 and fields[0][k].dtype.kind == "i" else None
        spans.append(np.concatenate([f[k] for f in fields], dtype=dtype, casting="unsafe" if dtype else "same_kind"))
        for f in fields:
            f[k] = None
    # the bands' pieces came back from the workers between other arrays: the heap keeps
    # their pages (2 km terrain: ~0.5 GB over the live arrays, under the surface's peak)
    give_back(30 * (len(spans[0]) if spans else 0))
    return tuple(spans), counts


def _run(band: Callable[[int, int], tuple], todo: list[tuple[int, int]], workers: int) -> list:
    """``band`` of each [first, last) in ``todo``, in order, on ``workers`` threads."""
    if workers <= 1 or len(todo) <= 1:
        return [band(a, b) for a, b in todo]
    with ThreadPoolExecutor(workers, thread_name_prefix="tanktool-band") as pool:
        return list(pool.map(band, *zip(*todo)))
