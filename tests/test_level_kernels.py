"""The compiled surface passes (tanktool/_kernels_surface.c) against the numpy code
they replace: the same levels from stack_levels and level_lift.lift_to_portals, the
same chamfer clearance from the sweeps near the changes, the same open spans and
snapped heights, on random span graphs and on generated levels (decks over walkable
ground, bumps, terraces)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from tanktool.geometry import kernels
from tanktool.geometry.kernels import use_kernels
from tanktool.nav.level_lift import lift_to_portals
from tanktool.nav.level_stack import stack_levels
from tanktool.nav.walkable import WalkableParams, chamfer_clearance, link_spans, walkable_surface

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))

needs_kernels = pytest.mark.skipif(not kernels.available(), reason="tanktool._kernels not built (no C compiler)")


def _graph(seed: int, nz: int = 27, nx: int = 33):
    """Columns of 0-4 spans, close enough in height to link across storeys."""
    rng = np.random.default_rng(seed)
    counts = rng.integers(0, 5, nz * nx)
    col = np.repeat(np.arange(nz * nx), counts)
    floor = rng.integers(0, 60, len(col))
    order = np.lexsort((floor, col))
    col, floor = col[order], floor[order]
    ceil = floor + rng.integers(2, 25, len(col))
    return rng, col, link_spans(col, floor, ceil, (nz, nx), 3, 12)


@needs_kernels
@pytest.mark.parametrize("seed", range(8))
def test_random_span_graphs_stack_the_same_levels(seed):
    rng, col, link = _graph(seed)
    for share in (1.0, 0.8, 0.5):
        keep = rng.random(len(col)) < share
        for rounds, lift in ((64, 0), (64, 3), (2, 9), (0, 2)):
            with use_kernels(True):
                a = stack_levels(col, keep, link, rounds=rounds, lift=lift)
            with use_kernels(False):
                b = stack_levels(col, keep, link, rounds=rounds, lift=lift)
            assert np.array_equal(a, b), (share, rounds, lift)
            assert a.max() >= 1


@needs_kernels
@pytest.mark.parametrize("seed", range(8))
def test_random_levels_are_lifted_the_same(seed):
    """Levels drawn at random (spans outside the region, several of a column on one
    level): every branch of the lift, conflicts included."""
    rng, col, link = _graph(seed)
    moved = 0
    for top in (2, 4):
        level = rng.integers(-1, top, len(col)).astype(np.int64)
        for steps in (0, 1, 5):
            a, b = level.copy(), level.copy()
            with use_kernels(True):
                lift_to_portals(col, a, link, steps)
            with use_kernels(False):
                lift_to_portals(col, b, link, steps)
            assert np.array_equal(a, b), (top, steps)
            moved += int((a != level).sum())
    assert moved > 50


def _storeys(rng, nz: int, nx: int):
    """A ground with holes and a deck over part of it (one or two spans a column): wide
    open areas, edges inside the level too."""
    ground = rng.random((nz, nx)) > 0.04
    deck = np.zeros((nz, nx), dtype=bool)
    for _ in range(4):
        i, j = rng.integers(0, nz), rng.integers(0, nx)
        deck[max(i - 6, 0):i + 7, max(j - 9, 0):j + 10] = True
    cells = np.arange(nz * nx)
    col = np.concatenate([cells[ground.ravel()], cells[deck.ravel()]])
    floor = np.concatenate([np.zeros(ground.sum(), np.int64), np.full(deck.sum(), 30)])
    order = np.lexsort((floor, col))
    col, floor = col[order], floor[order]
    ceil = np.where((floor == 0) & np.isin(col, cells[deck.ravel()]), 25, 1000)
    return col, link_spans(col, floor, ceil, (nz, nx), 3, 12)


@needs_kernels
@pytest.mark.parametrize("seed", range(8))
def test_random_span_graphs_have_the_same_clearance_near_the_changes(seed):
    rng = np.random.default_rng(seed)
    shape = (41 + seed, 23 + 3 * seed)
    col, link = _storeys(rng, *shape)
    for share in (0.0, 0.02):  # links cut at random too: one-way links
        cut = np.where(rng.random(link.shape) < share, -1, link).astype(np.int32)
        for limit in (1, 3, 6, 20, 200):
            with use_kernels(True):
                a = chamfer_clearance(cut, limit, col, shape)
                assert np.array_equal(a, chamfer_clearance(cut, limit))
            with use_kernels(False):
                b = chamfer_clearance(cut, limit, col, shape)
            assert np.array_equal(a, b), (share, limit)
            assert limit != 20 or ((a > 6) & (a < limit)).any()  # distances well inside


@needs_kernels
@pytest.mark.parametrize("name", ["stacked_floors", "bridge", "two_storeys", "bumpy_floor", "terraces"])
def test_generated_levels_stack_the_same(name):
    import make_levels

    m = make_levels.level(name)
    V, F = np.asarray(m.vertices, np.float64), np.asarray(m.faces, np.int64)
    params = WalkableParams(0.5, 0.1, 35.0, 0.9, 2.0)
    with use_kernels(True):
        a = walkable_surface(V, F, params, 1.0)
    with use_kernels(False):
        b = walkable_surface(V, F, params, 1.0)
    assert np.array_equal(a.level, b.level) and a.levels == b.levels
    for key in ("col", "floor", "ceil", "link", "clearance", "height"):  # open spans, snapped heights
        assert np.array_equal(getattr(a, key), getattr(b, key)), key


@needs_kernels
@pytest.mark.parametrize("seed", range(4))
def test_random_faces_have_the_same_flags_and_flat_heights(seed):
    """Faces of every slope, flat ones at a few heights (some just off flat), degenerate
    ones (repeated corners, a NaN vertex): walkable_faces and flat_heights alike."""
    from tanktool.geometry.heightfield import flat_heights, walkable_faces

    rng = np.random.default_rng(seed)
    n = 3000
    V = rng.normal(0, 5, (3 * n, 3))
    flat = rng.random(n) < 0.4
    for k in range(3):  # flat faces: three corners at one of a few heights, a hair off for some
        V[3 * np.flatnonzero(flat) + k, 1] = rng.choice([0.0, 1.25, 4.0], flat.sum()) + rng.normal(0, 1e-4) * (k == 2)
    V[7] = np.nan
    F = np.arange(3 * n).reshape(n, 3)
    F[5] = [4, 4, 9]  # a repeated corner: no normal
    for slope in (30.0, 45.0, 89.0):
        with use_kernels(True):
            a = walkable_faces(V, F, slope)
        with use_kernels(False):
            b = walkable_faces(V, F, slope)
        assert all(np.array_equal(x, y) for x, y in zip(a, b)) and a[0].any() and not a[0].all()
    with use_kernels(True):
        a = flat_heights(V, F), flat_heights(V, F, 0.9)
    with use_kernels(False):
        b = flat_heights(V, F), flat_heights(V, F, 0.9)
    for x, y in zip(a, b):
        assert np.array_equal(x[0], y[0]) and np.array_equal(x[1], y[1]) and len(x[0]) >= 3
