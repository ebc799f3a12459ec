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
