"""The bundled arenas are complete, playable, and not stale.

Stale means: re-importing the bundle's source model with the parameters in its
arena.toml gives a different walls.txt or different spawn points, or a sha256 in
[derived] / [source] no longer matches its file.  Fix with ``make arenas``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from tanktool.arena import MIN_SPAWNS, load_arena
from tanktool.formats.bundle import read_toml, sha256_file
from tanktool.geometry.segments import point_segment_distance

ROOT = Path(__file__).resolve().parent.parent
BUNDLES = sorted(p.parent for p in (ROOT / "arenas").glob("*/arena.toml"))
STALE = "stale bundled arena: run `make arenas`"


def test_the_three_arenas_are_bundled():
    names = {p.name for p in BUNDLES}
    assert {"box", "maze", "paper2002"} <= names
    fmts = {read_toml(p / "arena.toml")["source"]["file"].rsplit(".", 1)[-1] for p in BUNDLES}
    assert "3ds" in fmts


@pytest.mark.parametrize("folder", BUNDLES, ids=[p.name for p in BUNDLES])
def test_bundle_hashes_match(folder: Path):
    doc = read_toml(folder / "arena.toml")
    assert sha256_file(folder / doc["source"]["file"]) == doc["source"]["sha256"], STALE
    assert {"walls.txt", "model.glb", "preview.png"} <= set(doc["derived"])
    for name, digest in doc["derived"].items():
        assert (folder / name).is_file(), f"{folder.name}/{name} missing: {STALE}"
        assert sha256_file(folder / name) == digest, f"{folder.name}/{name}: {STALE}"


@pytest.mark.parametrize("folder", BUNDLES, ids=[p.name for p in BUNDLES])
def test_rebuilding_gives_the_same_walls_and_spawns(folder: Path, tmp_path: Path):
    # the very code `make arenas` runs, into a temporary folder, without the navgrid
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        from build_arenas import rebuild
    finally:
        sys.path.remove(str(ROOT / "tools"))
    doc = read_toml(folder / "arena.toml")
    out = tmp_path / folder.name
    rebuild(folder, out, navgrid=False)
    fresh = read_toml(out / "arena.toml")
    assert (out / "walls.txt").read_bytes() == (folder / "walls.txt").read_bytes(), STALE
    assert fresh["derived"]["walls.txt"] == doc["derived"]["walls.txt"], STALE
    assert fresh["spawns"] == doc["spawns"], STALE
    assert fresh["bounds"] == doc["bounds"] and fresh["floor_y"] == doc["floor_y"], STALE
    assert fresh["walls"]["count"] == doc["walls"]["count"], STALE


@pytest.mark.parametrize("folder", BUNDLES, ids=[p.name for p in BUNDLES])
def test_bundle_is_playable(folder: Path):
    a = load_arena(folder)
    assert len(a.spawns) >= MIN_SPAWNS
    seg = a.walls.all_segments()
    if a.walls.layered:  # clear of every wall of its own level (a deck's edge above does not count)
        from tanktool.nav.navgrid import NavGrid

        grid = NavGrid.load(folder / "navgrid.npz")
        node = grid.nodes_of(a.spawns[:, :2])
        hts = grid.heights()[:, node[:, 0], node[:, 1]]
        level = np.nanargmin(np.where(np.isfinite(hts), np.abs(hts - a.spawns[:, 3]), np.inf), axis=0)
        d = np.array([point_segment_distance(p[None], a.walls.segments[a.walls.level == lv][:, 0],
                                             a.walls.segments[a.walls.level == lv][:, 1]).min()
                      for p, lv in zip(a.spawns[:, :2], level)])
    else:
        d = point_segment_distance(a.spawns[:, None, :2], seg[None, :, 0], seg[None, :, 1]).min(axis=1)
    assert d.min() >= 2.5  # clear of every wall
    lo, hi = a.bounds
    assert ((a.spawns[:, :2] > lo) & (a.spawns[:, :2] < hi)).all()
    # no degenerate walls: every one at least the tolerance long
    length = np.hypot(*(a.walls.segments[:, 1] - a.walls.segments[:, 0]).T)
    assert length.min() >= read_toml(folder / "arena.toml")["walls"]["tolerance"]


def test_paper2002_reproduces_the_paper_table():
    a = load_arena(ROOT / "arenas" / "paper2002")
    # table 3.4.4.1 of the 2002 paper, at 0.2 m per unit
    table = np.array([[0, 0, 0, 200], [0, 200, 50, 200], [50, 200, 50, 300], [50, 300, 0, 300],
                      [0, 300, 0, 450], [0, 450, 50, 500], [50, 500, 200, 500]], dtype=np.float64) * 0.2
    have = {tuple(sorted([tuple(p), tuple(q)])) for p, q in np.round(a.walls.segments, 6)}
    for x1, z1, x2, z2 in table:
        assert tuple(sorted([(x1, z1), (x2, z2)])) in have
    # normals point into the arena: the first wall (x = 0) faces +x
    k = [i for i, (p, q) in enumerate(a.walls.segments) if p[0] == q[0] == 0 and min(p[1], q[1]) == 0][0]
    assert np.allclose(a.walls.normals[k], [1, 0])
