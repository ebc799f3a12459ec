"""Thin walls clipped in one overlay give the walls the chain-by-chain reference gives."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
import shapely

from tanktool.geometry import thin_walls as tw
from tanktool.geometry import walls as cut

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
import make_levels  # noqa: E402


def _key(seg: np.ndarray) -> list:
    return sorted(tuple(np.round(s, 6).ravel()) for s in seg)


def _captured(level: list) -> list:
    """The (chains, free, tolerance) every thin-wall clip of an extraction gets."""
    m = make_levels.join(level)
    calls = []

    def spy(*a):
        calls.append(a)
        return tw.thin_walls(*a)

    saved, cut.thin_walls = cut.thin_walls, spy
    try:
        cut.extract_walls(np.asarray(m.vertices), np.asarray(m.faces))
    finally:
        cut.thin_walls = saved
    return calls


@pytest.mark.parametrize("level", ["fence_field", "junkyard"])
def test_one_overlay_gives_the_reference_walls(level):
    kw = {"fences": 250, "pillars": 60, "size": 80.0} if level == "fence_field" else {}
    calls = _captured(make_levels.LEVELS[level](**kw))
    assert calls
    for chains, free, tol in calls:
        fast, ref = tw.thin_walls(chains, free, tol), tw.thin_walls_reference(chains, free, tol)
        assert len(ref) > 10
        assert _key(fast) == _key(ref)


def test_chains_outside_free_space_or_on_its_outline_give_no_wall():
    free = shapely.box(0, 0, 10, 10)
    chains = [shapely.LineString([(20, 0), (30, 0)]),        # outside
              shapely.LineString([(0, 2), (0, 8)]),          # on the outline
              shapely.LineString([(5, -5), (5, 15)]),        # across: the inside part, off the outline
              shapely.LineString([(2, 2), (2, 2.001)])]      # shorter than the tolerance
    seg = tw.thin_walls(chains, free, 0.01)
    assert _key(seg) == _key(np.array([[[5, 0.01], [5, 9.99]]]))
    assert _key(tw.thin_walls_reference(chains, free, 0.01)) == _key(seg)
    assert tw.thin_walls([], free, 0.01).shape == (0, 2, 2)


def test_thin_walls_on_a_free_space_with_its_precision_grid_do_not_raise():
    """A random level's chains and free space (tests/data/thin_walls_topology.json) on
    which GEOS raised a topology exception clipping the chains off the free space's
    outline: the overlay is then done on the walls' precision grid."""
    import json
    from pathlib import Path

    import shapely

    from tanktool.geometry.thin_walls import thin_walls, thin_walls_reference

    doc = json.loads((Path(__file__).parent / "data" / "thin_walls_topology.json").read_text())
    tol = doc["tolerance"]
    free = shapely.set_precision(shapely.from_wkt(doc["free"]), tol)
    chains = [shapely.from_wkt(c) for c in doc["chains"]]
    walls = thin_walls(chains, free, tol)
    assert len(walls) > 0 and np.isfinite(walls).all()
    ref = thin_walls_reference(chains, free, tol)
    assert abs(np.hypot(*(walls[:, 1] - walls[:, 0]).T).sum() - np.hypot(*(ref[:, 1] - ref[:, 0]).T).sum()) < 0.5
