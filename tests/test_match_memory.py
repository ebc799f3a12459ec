"""The agents' clearance of a ground in the compiled kernel on the ground's own links
(layers.chamfer_grid: no compact graph) gives the numpy path's values exactly."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from tanktool.geometry import kernels
from tanktool.geometry.kernels import use_kernels
from tanktool.sim.agents.layers import _clear_enough, clear_enough, surface_clearance

ROOT = Path(__file__).resolve().parent.parent
needs_kernels = pytest.mark.skipif(not kernels.available(), reason="compiled kernels not built")


def _random_ground(seed: int, L: int = 2, nz: int = 37, nx: int = 29) -> SimpleNamespace:
    """Levels of scattered nodes whose links go to random levels (some to no node)."""
    rng = np.random.default_rng(seed)
    exists = rng.random((L, nz, nx)) < 0.8
    link = rng.integers(-1, L, size=(L, nz, nx, 4)).astype(np.int8)
    link[~exists] = -1
    return SimpleNamespace(exists=exists, link=link, cell=0.5)


def _both(ground, limit: float):
    with use_kernels(False):
        slow, slow_ok = surface_clearance(ground, limit), _clear_enough(ground, limit)
    with use_kernels(True):
        fast, fast_ok = surface_clearance(ground, limit), _clear_enough(ground, limit)
    return slow, fast, slow_ok, fast_ok


@needs_kernels
@pytest.mark.parametrize("seed", range(6))
def test_random_grounds_have_the_same_clearance(seed):
    g = _random_ground(seed)
    if seed % 2:  # few missing links: distances grow far from the edges
        g.link = np.repeat(np.where(g.exists[..., None], np.int8(0), np.int8(-1)), 4, axis=3)[:1]
        g.exists = g.exists[:1]
    for limit in (0.3, 1.0, 4.6):
        slow, fast, slow_ok, fast_ok = _both(g, limit)
        np.testing.assert_array_equal(slow, fast)   # NaN where no node, in both
        np.testing.assert_array_equal(slow_ok, fast_ok)


@needs_kernels
@pytest.mark.parametrize("name", ["fort", "hills"])
def test_bundled_grounds_have_the_same_clearance(name):
    from tanktool.sim.match import load_match_arena

    ground = load_match_arena(ROOT / "arenas" / name).ground
    slow, fast, slow_ok, fast_ok = _both(ground, 3.2)
    np.testing.assert_array_equal(slow, fast)
    np.testing.assert_array_equal(slow_ok, fast_ok)
    assert fast_ok.any()
    kept = clear_enough(ground, 3.2)   # the last mask, kept per ground
    assert np.array_equal(kept, fast_ok) and clear_enough(ground, 3.2) is kept
    assert clear_enough(ground, 2.0) is not kept


@pytest.mark.parametrize("name", ["two_storeys", "rolling_terrain"])
def test_the_solid_field_in_bands_is_the_solid_field_in_one_go(name, monkeypatch):
    import sys

    sys.path.insert(0, str(ROOT / "tools"))
    import make_levels

    from tanktool.sim.solid import SolidField

    m = make_levels.level(name)
    V, F = np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64)
    whole = SolidField(V, F)
    monkeypatch.setattr(SolidField, "BAND_VOXELS", 1)   # a row at a time
    rows = SolidField(V, F)
    assert bytes(rows._bytes) == bytes(whole._bytes) and whole.solid.any()
    assert rows._tops == whole._tops


@pytest.mark.parametrize("name", ["fort", "hills"])
def test_level_ground_in_bands_is_level_ground_in_one_go(name, monkeypatch):
    from tanktool.sim import ground as ground_mod
    from tanktool.sim.match import load_match_arena

    h = load_match_arena(ROOT / "arenas" / name).ground.h
    h = np.floor(h / 3.0) * 3.0   # terraces: level ground beside its edges
    whole = ground_mod.Ground._level_ground(h)
    monkeypatch.setattr(ground_mod, "GROUND_BAND", 7)
    assert np.array_equal(ground_mod.Ground._level_ground(h), whole) and whole.any()
    stacked = np.concatenate([h, h - 5.0])   # two levels over each other: near another level
    monkeypatch.setattr(ground_mod, "GROUND_BAND", 256)
    whole2 = ground_mod.Ground._level_ground(stacked)
    monkeypatch.setattr(ground_mod, "GROUND_BAND", 5)
    assert np.array_equal(ground_mod.Ground._level_ground(stacked), whole2)


def test_lazy_rows_keep_at_most_their_rows_and_read_the_same():
    from tanktool.sim.lazy_rows import LazyRows, plain_row, tuple_row

    rng = np.random.default_rng(3)
    link = rng.integers(-1, 2, size=(40, 9, 4)).astype(np.int8)
    rows = LazyRows(link, tuple_row, keep=5)
    for i in rng.integers(0, 40, size=300).tolist():
        assert [list(t) for t in rows[i]] == link[i].tolist()
        assert dict.__len__(rows) <= 5
    assert rows[3][4][2] == int(link[3, 4, 2]) and type(rows[3][4][2]) is int
    whole = LazyRows(link, plain_row)
    assert [whole[i] for i in range(40)] and dict.__len__(whole) == 40 and len(whole) == 40
