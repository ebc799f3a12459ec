"""Recast's three span filters over a column-sorted span array, and the column helpers
they share with the heightfield (tanktool/geometry/heightfield.py) and the walkable
surface (tanktool/nav/walkable.py).

* a non-walkable span whose top is within the climb of the walkable span below it in
  its column becomes walkable (``rcFilterLowHangingWalkableObstacles``: kerbs, stair
  steps);
* a walkable span with a neighbour column where a tank could stand more than the climb
  lower (or no neighbour: the edge of the grid) is a ledge: not walkable; nor is one
  whose reachable neighbours' floors differ by more than the climb among themselves
  (``rcFilterLedgeSpans``);
* a walkable span with less than the headroom free above it is not walkable
  (``rcFilterWalkableLowHeightSpans``).

Each filter looks at a span's own column and its four neighbours only: a block of
rows filtered with one more row on each side gives its inner rows exactly
(tanktool/geometry/tiles.py builds large heightfields so).
"""

from __future__ import annotations

import numpy as np

from .kernels import active, i64

#: tops of columns with nothing above them (Recast's 0xffff in its filters)
OPEN = 1 << 15


def _next_in_column(col: np.ndarray, values: np.ndarray, fill: int) -> np.ndarray:
    """values[k + 1] where span k + 1 is in the same column as span k, else ``fill``."""
    out = np.full(len(col), fill, dtype=values.dtype)
    same = col[1:] == col[:-1]
    out[:-1][same] = values[1:][same]
    return out


def column_starts(col: np.ndarray, ncols: int) -> np.ndarray:
    """(ncols + 1,) index of each column's first span in a column-sorted span array."""
    start = np.zeros(ncols + 1, dtype=np.int64)
    np.cumsum(np.bincount(col, minlength=ncols), out=start[1:])
    return start


def neighbour_columns(col: np.ndarray, shape: tuple[int, int]) -> list[np.ndarray]:
    """For each of +x, +z, -x, -z: the neighbour column of each span, -1 off the grid."""
    nz, nx = shape
    i, j = np.divmod(col, nx)
    out = []
    for di, dj in ((0, 1), (1, 0), (0, -1), (-1, 0)):
        ii, jj = i + di, j + dj
        ok = (ii >= 0) & (ii < nz) & (jj >= 0) & (jj < nx)
        out.append(np.where(ok, ii * nx + jj, -1))
    return out


def filter_spans(hf_col, smin, smax, walk, shape, headroom: int, climb: int):
    """Recast's three filters (see the module docstring); returns the new walkable flags
    and how many spans each filter took away."""
    w3, lifted, ledge, steep, low = filter_masks(hf_col, smin, smax, walk, shape, headroom, climb)
    # count_nonzero: a bool array's sum() casts every flag to int64 first (6% of the filters)
    counts = {k: int(np.count_nonzero(a)) for k, a in (("lifted", lifted), ("ledge", ledge), ("steep", steep),
                                                       ("low", low))}
    return w3, counts, low


def filter_masks(hf_col, smin, smax, walk, shape, headroom: int, climb: int):
    """The filters' result per span: (walkable after all three, lifted by the first,
    a ledge, too steep, too low)."""
    kern = active()
    if kern is not None:  # the three filters in one pass each (tanktool/_kernels.c)
        out = [np.empty(len(hf_col), dtype=bool) for _ in range(5)]
        kern.filters(i64(hf_col), i64(smin), i64(smax), np.ascontiguousarray(walk, dtype=bool), shape[0], shape[1],
                     int(headroom), int(climb), *out)
        return tuple(out)
    ceil = _next_in_column(hf_col, smin, OPEN)
    # 1. low hanging obstacles: walkable from the span below (its flag before this pass)
    w = walk.copy()
    below_walk = np.zeros(len(w), dtype=bool)
    below_top = np.zeros(len(w), dtype=np.int64)
    same = hf_col[1:] == hf_col[:-1]
    below_walk[1:] = walk[:-1] & same
    below_top[1:] = smax[:-1]
    w |= ~walk & below_walk & (np.abs(smax - below_top) <= climb)
    lifted = w & ~walk
    # 2. ledges and steep spans: each walkable span against every floor of each
    # neighbour column (_ledge_scan)
    s_idx = np.flatnonzero(w)
    minh, asmin, asmax = _ledge_scan(hf_col, smin, smax, ceil, s_idx, shape, headroom, climb)
    ledge = minh < -climb
    steep = ~ledge & ((asmax - asmin) > climb)
    w2 = w.copy()
    w2[s_idx[ledge | steep]] = False
    # 3. too little headroom
    low = w2 & ((ceil - smax) <= headroom)
    w3 = w2 & ~low
    ledge_all = np.zeros(len(w), dtype=bool)
    steep_all = np.zeros(len(w), dtype=bool)
    ledge_all[s_idx[ledge]] = True
    steep_all[s_idx[steep]] = True
    return w3, lifted, ledge_all, steep_all, low


def _ledge_scan(hf_col, smin, smax, ceil, s_idx, shape, headroom: int, climb: int):
    """For each span ``s_idx``: the lowest reachable neighbour floor relative to its own
    (minh) and the range of the neighbour floors within the climb (asmin, asmax), over
    every floor of each neighbour column, the empty space below a column's first span
    counting as a floor at -climb (a drop to the bottom of the world).  Neighbour spans
    are visited k-th by k-th (the k-th pass only sees columns with more than k spans:
    few beyond two); the compiled filters (tanktool/_kernels.c) do this in one pass."""
    nz, nx = shape
    start = column_starts(hf_col, nz * nx)
    bot = smax[s_idx]
    top = ceil[s_idx]
    minh = np.full(len(s_idx), OPEN, dtype=np.int64)
    asmin = bot.astype(np.int64)
    asmax = bot.astype(np.int64)
    count = np.diff(start)
    for ncol in neighbour_columns(hf_col[s_idx], shape):
        off = ncol < 0
        minh[off] = np.minimum(minh[off], -climb - bot[off])
        nc = np.where(off, 0, ncol)
        cnt = np.where(off, 0, count[nc])
        first = start[nc]
        # the virtual floor below the first span (or open sky over an empty column)
        ntop = np.where(cnt > 0, smin[np.minimum(first, len(smin) - 1)], OPEN)
        sel = ~off & (np.minimum(top, ntop) - np.maximum(bot, -climb) > headroom)
        minh[sel] = np.minimum(minh[sel], -climb - bot[sel])
        idx = np.arange(len(s_idx))
        k = 0
        while len(idx):
            idx = idx[cnt[idx] > k]
            if not len(idx):
                break
            kk = first[idx] + k
            nbot, ntop = smax[kk], ceil[kk]
            b = bot[idx]
            ok = np.minimum(top[idx], ntop) - np.maximum(b, nbot) > headroom
            i_ok = idx[ok]
            nb = nbot[ok]
            minh[i_ok] = np.minimum(minh[i_ok], nb - b[ok])
            near = np.abs(nb - b[ok]) <= climb
            i_n = i_ok[near]
            asmin[i_n] = np.minimum(asmin[i_n], nb[near])
            asmax[i_n] = np.maximum(asmax[i_n], nb[near])
            k += 1
    return minh, asmin, asmax


