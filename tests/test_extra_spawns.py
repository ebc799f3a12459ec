"""Spawning beyond the spawn points (issue 25): more tanks than spawn points start at
free places of the ground a tank's length apart, on its grid; an arena too small for
them is refused saying how many it holds."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tanktool.errors import ArenaError
from tanktool.geometry.segments import point_segment_distance
from tanktool.sim.match import load_match_arena, load_tank_spec, run_match
from tanktool.sim.world import World


def _two_spawns(name: str):
    info = load_match_arena(name)
    info.spawns = info.spawns[:2]
    return info


@pytest.mark.parametrize("name", ["maze", "fort"])
def test_eight_tanks_on_an_arena_with_two_spawn_points(name: str):
    info = _two_spawns(name)
    spec = load_tank_spec("light")
    w = World(info.walls, [spec] * 8, info.spawns, bounds=info.bounds, ground=info.ground, seed=3)
    assert len(w.spawns) == 8 and w.spawns[:2] == [tuple(map(float, s[:3])) for s in info.spawns]
    length = spec.box[2] - spec.box[0]
    xz = np.array([(t.x, t.z) for t in w.tanks])
    gaps = np.hypot(*(xz[:, None] - xz[None]).transpose(2, 0, 1))[np.triu_indices(8, 1)]
    assert gaps.min() >= length - 1e-9
    g = w.ground
    for t in w.tanks:
        assert g.locate(t.x, t.z) >= 0              # on a level of the ground
        assert abs(t.y - g.height(t.x, t.z, t.level)) < 0.3
    for x, z, _ in w.spawns[2:]:    # the free places keep the tank's radius from every wall
        seg = w.walls.segments
        assert point_segment_distance(np.array([[x, z]]), seg[:, 0], seg[:, 1]).min() >= spec.radius - 1e-6
    # the same arena gives the same places; a whole match plays, respawns included
    w2 = World(info.walls, [spec] * 8, info.spawns, bounds=info.bounds, ground=info.ground, seed=3)
    assert w2.spawns == w.spawns
    report = run_match(info, spec, bots=8, seconds=10.0, seed=1).report
    assert len(report["tanks"]) == 8 and sum(t["distance"] for t in report["tanks"]) > 50


def test_an_arena_too_small_says_how_many_it_holds():
    info = _two_spawns("box")
    spec = load_tank_spec("heavy")
    with pytest.raises(ArenaError, match=r"holds \d+ tanks of heavy at once .*, 64 asked for"):
        World(info.walls, [spec] * 64, info.spawns, bounds=info.bounds, ground=info.ground)
