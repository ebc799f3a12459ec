"""Heightfields built in bands of rows (tanktool/geometry/tiles.py) are the whole
build's, span for span and count for count, with or without the compiled kernels,
in turn or on worker threads."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from tanktool.geometry.heightfield import build_heightfield
from tanktool.geometry.kernels import available, use_kernels
from tanktool.geometry.tiles import bands

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))

KEYS = ("col", "smin", "smax", "walkable", "flat", "top_walkable", "low_headroom")


def _same(a, b):
    assert a.shape == b.shape and a.counts == b.counts
    for key in KEYS:
        assert np.array_equal(getattr(a, key), getattr(b, key)), key


def _mesh(name):
    import make_levels
    import trimesh

    if name == "dungeon":
        m = trimesh.load(ROOT / "tests" / "data" / "arenas_obj" / "dungeon.obj", force="mesh", process=False)
    else:
        m = make_levels.level(name)
    return np.asarray(m.vertices, np.float64), np.asarray(m.faces, np.int64)


@pytest.mark.parametrize("kernels", [True, False] if available() else [False], ids=["compiled", "numpy"][:2])
@pytest.mark.parametrize("name", ["dungeon", "two_storeys", "rolling_terrain"])
def test_bands_give_the_whole_build(name, kernels):
    V, F = _mesh(name)
    with use_kernels(kernels):
        whole = build_heightfield(V, F, 0.3, 0.2, 45.0, 2.0, 0.9)
        for rows in (1, 7, 64):  # one-row bands: every band all border
            _same(build_heightfield(V, F, 0.3, 0.2, 45.0, 2.0, 0.9, band_rows=rows, workers=1), whole)
    assert whole.walkable.sum() > 1000 and whole.counts["ledge"] > 0


@pytest.mark.parametrize("kernels", [True, False] if available() else [False], ids=["compiled", "numpy"][:2])
def test_bands_on_worker_threads_give_the_whole_build(kernels):
    V, F = _mesh("dungeon")
    with use_kernels(kernels):
        whole = build_heightfield(V, F, 0.3, 0.2, 45.0, 2.0, 0.9)
        _same(build_heightfield(V, F, 0.3, 0.2, 45.0, 2.0, 0.9, band_rows=40, workers=2), whole)


def test_concurrent_tiled_builds_keep_apart():
    """Two levels tiled at once in one process (a server's threads): each its own."""
    from concurrent.futures import ThreadPoolExecutor

    meshes = [_mesh("dungeon"), _mesh("two_storeys")]
    whole = [build_heightfield(V, F, 0.3, 0.2, 45.0, 2.0, 0.9) for V, F in meshes]
    with ThreadPoolExecutor(2) as pool:
        tiled = list(pool.map(lambda m: build_heightfield(*m, 0.3, 0.2, 45.0, 2.0, 0.9, band_rows=9, workers=2),
                              meshes))
    for a, b in zip(tiled, whole):
        _same(a, b)


def test_bands_cover_the_rows_once():
    assert bands(10, 5, 4) == [(0, 4), (4, 8), (8, 10)]
    assert bands(3, 2_000_000) == [(0, 1), (1, 2), (2, 3)]


def test_a_daemonic_worker_builds_its_bands_in_turn():
    """A pool worker (daemonic: it may not start processes) importing a large level
    builds its bands on threads."""
    import multiprocessing as mp

    V, F = _mesh("two_storeys")
    whole = build_heightfield(V, F, 0.3, 0.2, 45.0, 2.0, 0.9)
    with mp.get_context("fork").Pool(1) as pool:
        counts = pool.apply(_tiled_counts, (V, F))
        pool.close()      # the worker leaves on its own: terminate (the with's exit) would
        pool.join()       # wait for ever on one whose inherited SIGTERM handler does not exit
    assert counts == whole.counts


def _tiled_counts(V, F):
    return build_heightfield(V, F, 0.3, 0.2, 45.0, 2.0, 0.9, band_rows=16, workers=2).counts
