"""The ground made lighter for large arenas: rows made on first use read as the whole
array's nested lists did, and the solid voxels filled from the spans are the same."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tanktool.sim.lazy_rows import heights_row, lazy_levels, plain_row


def test_lazy_rows_read_as_the_nested_lists():
    rng = np.random.default_rng(3)
    h = rng.normal(size=(2, 5, 7))
    h[rng.random(h.shape) < 0.3] = np.nan
    link = rng.integers(-1, 2, size=(2, 5, 7, 4))
    eager_h = [[[None if not math.isfinite(v) else float(v) for v in row] for row in lv] for lv in h.tolist()]
    lazy_h = lazy_levels(h, heights_row)
    lazy_l = lazy_levels(link, plain_row)
    for lv in range(2):
        for i in (3, 0, 4, -1, 3):     # any order, again, negative as a list's
            assert lazy_h[lv][i] == eager_h[lv][i]
            assert lazy_l[lv][i] == link.tolist()[lv][i]
        assert [r for r in lazy_h[lv]] == eager_h[lv] and len(lazy_h[lv]) == 5
    with pytest.raises(IndexError):
        lazy_h[0][5]
    assert type(lazy_h[1][2][0]) in (float, type(None)) and type(lazy_l[0][0][0][0]) is int


@pytest.mark.parametrize("name", ["two_storeys", "rolling_terrain"])
def test_the_solid_voxels_are_the_spans_filled_in(name):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))
    import make_levels

    from tanktool.geometry.heightfield import grid_for, rasterize
    from tanktool.sim.ground import SolidField

    m = make_levels.level(name)
    V, F = np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64)
    sf = SolidField(V, F)
    # the voxels one by one, as the field was filled before
    origin, (nz, nx) = grid_for(V, sf.cs)
    none = np.zeros(len(F), dtype=bool)
    (col, smin, smax, *_), _ = rasterize(V, F, sf.cs, sf.ch, none, none, origin, (nz, nx), 0)
    first = np.ones(len(col), dtype=bool)
    first[1:] = col[1:] != col[:-1]
    smin = np.where(first, 0, smin)
    smax = np.minimum(np.maximum(smax, smin + 1), sf.ny)
    want = np.zeros(nz * nx * sf.ny, dtype=bool)
    for c, a, b in zip(col, smin, smax):
        want[c * sf.ny + a:c * sf.ny + b] = True
    assert np.array_equal(sf.solid, want) and want.sum() > 1000


@pytest.mark.parametrize("dtype, width", [(np.int8, 4), (np.int8, 3), (np.int16, 4), (np.int8, 2)])
def test_rows_by_their_distinct_nodes_are_the_comprehensions(dtype, width):
    # tuple_row picks each node's tuple among the row's distinct ones (the bytes of a
    # node as one integer; other widths the per-node path); heights_row through an
    # object array: both read as the plain comprehensions, types and shared tuples too
    from tanktool.sim.lazy_rows import tuple_row

    rng = np.random.default_rng(5)
    row = rng.integers(-1, 3, size=(301, width)).astype(dtype)
    got = tuple_row(row)
    assert got == [tuple(r) for r in row.tolist()]
    assert all(type(t) is tuple and type(t[0]) is int for t in got)
    same = {}
    assert all(same.setdefault(t, t) is t for t in got)     # equal tuples are one object
    assert tuple_row(row[:0]) == []
    h = rng.normal(size=301)
    h[::7] = np.nan
    h[3] = np.inf
    want = [None if not math.isfinite(v) else float(v) for v in h.tolist()]
    got_h = heights_row(h)
    assert got_h == want and [type(v) for v in got_h] == [type(v) for v in want]
    assert heights_row(h.astype(np.float32)) == [None if not math.isfinite(v) else float(v)
                                                for v in h.astype(np.float32).tolist()]
