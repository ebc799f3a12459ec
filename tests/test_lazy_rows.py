"""The ground's rows made on first use read as the whole array's nested lists did."""

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
