"""One world model (issue 25): every arena has a ground.  A flat arena is a one-level
FlatGround at its floor's real height (not 0), and the simulation's callers hold no
``ground is None`` branch."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import trimesh
from click.testing import CliRunner

from tanktool.cli.main import cli
from tanktool.sim.flat_ground import FlatGround
from tanktool.sim.ground import Ground
from tanktool.sim.match import load_match_arena, load_tank_spec, run_match
from tanktool.sim.world import World

ROOT = Path(__file__).resolve().parent.parent
FLOOR = -2.37


def _sunken_room(path: Path, size: float = 40.0) -> Path:
    """A walled room whose floor's top is at y = FLOOR (as Recast's nav_test.obj)."""
    def box(x0, z0, x1, z1, y0, y1):
        return trimesh.creation.box(extents=[x1 - x0, y1 - y0, z1 - z0]).apply_translation(
            [(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2])
    f = FLOOR
    parts = [box(0, 0, size, size, f - 0.5, f), box(0, 0, size, 1, f, f + 3), box(0, size - 1, size, size, f, f + 3),
             box(0, 0, 1, size, f, f + 3), box(size - 1, 0, size, size, f, f + 3), box(18, 18, 22, 22, f, f + 3)]
    trimesh.util.concatenate(parts).export(path)
    return path


def test_a_flat_floor_below_zero_stands_at_its_height(tmp_path):
    model = _sunken_room(tmp_path / "sunken.obj")
    out = tmp_path / "sunken"
    r = CliRunner().invoke(cli, ["-q", "import-arena", str(model), "-o", str(out)])
    assert r.exit_code == 0, r.output
    info = load_match_arena(out)
    assert isinstance(info.ground, FlatGround) and not info.ground.relief
    assert abs(info.ground.y - FLOOR) < 0.05
    report = run_match(info, load_tank_spec("light"), bots=2, seconds=3.0, seed=1).report
    for t in report["tanks"]:       # every tank reports the floor's height, none 0.0
        assert abs(t["height"] - FLOOR) < 0.05, t


def test_every_arena_has_a_ground():
    for name in ("box", "maze", "paper2002"):
        g = load_match_arena(name).ground
        assert isinstance(g, FlatGround) and g.y == 0.0 and g.levels == 1
    for name in ("fort", "hills"):
        assert isinstance(load_match_arena(name).ground, Ground)
    # a world made without one stands on a flat ground at y = 0 (tests, tools)
    w = World([[[0.0, 0.0], [10.0, 0.0]]], [load_tank_spec("light")], [[5.0, 5.0, 0.0]],
              bounds=[[-20.0, -20.0], [20.0, 20.0]])
    assert isinstance(w.ground, FlatGround) and w.tanks[0].y == 0.0


def test_no_ground_is_none_branches_left():
    pattern = re.compile(r"ground is (not )?None")
    hits = [f"{p.relative_to(ROOT)}:{k}" for pkg in ("sim", "net", "game")
            for p in sorted((ROOT / "tanktool" / pkg).rglob("*.py"))
            for k, line in enumerate(p.read_text().splitlines(), 1) if pattern.search(line)]
    assert not hits, hits


def test_a_spawn_where_the_ground_has_no_level_is_put_on_the_nearest_node():
    info = load_match_arena("fort")
    g = info.ground
    from scipy import ndimage

    # cells with no level at all, nor in the cells around them
    holes = np.argwhere(~ndimage.maximum_filter(np.isfinite(g.h).any(axis=0), size=3))
    i, j = holes[len(holes) // 2]
    x, z = g.ox + (j + 0.5) * g.cell, g.oz + (i + 0.5) * g.cell
    assert g.locate(x, z) < 0 and g.near_level(x, z, 0.0) < 0
    spawns = np.array([[x, z, 0.0, -2.0]] + info.spawns[1:].tolist())    # 2 m under the surface
    w = World(info.walls, [load_tank_spec("light")], spawns[:1], bounds=info.bounds, ground=g)
    t = w.tanks[0]
    assert g.locate(t.x, t.z) >= 0 and math.hypot(t.x - x, t.z - z) < 10.0
    assert abs(t.y - g.height(t.x, t.z, t.level)) < 1e-9 and g.node_height(t.level, *g.cell_of(t.x, t.z)) is not None
