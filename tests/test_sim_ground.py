"""Tanks on arenas with relief and levels: on the surface, between levels, contained.

Every arena with a ground -- the bundled hills and fort, and levels tools/make_levels.py
generates (terrain, a bridge over a passage, two storeys, ramps and decks) -- gets
tanks driven hard (random commands, full throttle into walls, slopes and drop-offs);
after every step each live tank must stand on a node of its own level at the ground's
height, must not have crossed a wall of its level, and nothing may be NaN.
"""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from tanktool.sim.commands import Command
from tanktool.sim.match import load_match_arena, load_tank_spec, run_match
from tanktool.sim.world import World
from tanktool.sim.weapons import fire

from level_helpers import ROOT  # noqa: E402

GENERATED = ("rolling_terrain", "bridge", "two_storeys", "ramps_and_decks")


@pytest.fixture(scope="module")
def arenas(imported_level):
    """name -> ArenaInfo of the bundled arenas with a ground and the generated levels."""
    out = {}
    for name in ("hills", "fort"):
        out[name] = load_match_arena(ROOT / "arenas" / name)
    for name in GENERATED:
        out[name] = load_match_arena(imported_level(name))
    for name, info in out.items():
        assert info.ground is not None, name
    return out


def _world(info, n=8, seed=0, spec=None):
    spec = spec or load_tank_spec("light")
    n = min(n, len(info.spawns))
    return World(info.walls, [spec] * n, info.spawns, seed=seed, bounds=info.bounds, ground=info.ground)


def _check(world: World, prev: dict) -> None:
    """Every live tank on a node of its level at the ground's height, its centre's move
    crossing no wall of its level, nothing NaN."""
    g = world.ground
    for t in world.tanks:
        vals = (t.x, t.z, t.y, t.heading, t.vx, t.vz, t.omega, t.pitch, t.roll)
        assert all(math.isfinite(v) for v in vals), (t.name, vals)
        if not t.alive:
            prev.pop(t.index, None)
            continue
        i, j = g.cell_of(t.x, t.z)
        assert g.exists[t.level, i, j], f"{t.name} left the walkable surface at ({t.x:.2f}, {t.z:.2f})"
        assert abs(t.y - g.height(t.x, t.z, t.level)) < 1e-6
        p = prev.get(t.index)
        if p is not None and p[2] == t.level:
            seg = world.walls_of(t).segments
            a, b = np.array(p[:2]), np.array((t.x, t.z))
            A, B = seg[:, 0], seg[:, 1]
            d, e = b - a, B - A
            den = d[0] * e[:, 1] - d[1] * e[:, 0]
            with np.errstate(divide="ignore", invalid="ignore"):
                s = ((A[:, 0] - a[0]) * e[:, 1] - (A[:, 1] - a[1]) * e[:, 0]) / den
                u = ((A[:, 0] - a[0]) * d[1] - (A[:, 1] - a[1]) * d[0]) / den
            crossed = (den != 0) & (s > 1e-9) & (s < 1 - 1e-9) & (u > 1e-9) & (u < 1 - 1e-9)
            if crossed.any():
                # a crossing of a wall of another surface of this level (a deck's edge
                # seen from the passage) is no crossing: the wall stands at another height
                ys = world._wall_y[t.level]
                tol = g.climb + t.spec.height
                real = [k for k in np.flatnonzero(crossed) if ys[k][0] - tol <= t.y <= ys[k][1] + tol]
                assert not real, f"{t.name} crossed wall {real[0]} of level {t.level}"
        prev[t.index] = (t.x, t.z, t.level)


def _soak(info, steps: int, seed: int, full_throttle: bool = False) -> World:
    world = _world(info, seed=seed)
    rng = random.Random(seed)
    cmds = [Command() for _ in world.tanks]
    prev: dict = {}
    for k in range(steps):
        if k % 60 == 0:
            cmds = [Command(advance=1.0 if full_throttle else rng.uniform(-0.6, 1.0),
                            rotate=rng.uniform(-0.4, 0.4) if full_throttle else rng.uniform(-1, 1),
                            fire=rng.random() < 0.3) for _ in world.tanks]
        world.step(None, cmds)
        _check(world, prev)
    return world


@pytest.mark.parametrize("name", ("hills", "fort", *GENERATED))
def test_eight_tanks_stay_on_the_surface(arenas, name):
    world = _soak(arenas[name], 1200, seed=3)
    assert sum(t.distance for t in world.tanks) > 3 * len(world.tanks)  # they did drive


@pytest.mark.parametrize("name", ("hills", "fort", *GENERATED))
def test_full_throttle_into_walls_slopes_and_drops(arenas, name):
    _soak(arenas[name], 1500, seed=5, full_throttle=True)


@pytest.mark.slow
@pytest.mark.parametrize("name", ("hills", "fort", *GENERATED))
def test_full_throttle_10000_steps(arenas, name):
    _soak(arenas[name], 10_000, seed=7, full_throttle=True)


@pytest.mark.parametrize("name", ("hills", "fort", *GENERATED))
def test_spawns_never_overlap(arenas, name):
    world = _world(arenas[name])
    for a in world.tanks:
        for b in world.tanks:
            if a.index < b.index and abs(a.y - b.y) < a.spec.height:
                assert math.hypot(a.x - b.x, a.z - b.z) > 2 * a.spec.radius - 1e-6 or \
                    math.hypot(a.x - b.x, a.z - b.z) >= 0.9 * 5.0


def test_a_tank_drives_up_the_ramp_onto_the_fort_roof(arenas):
    info = arenas["fort"]
    world = _world(info, n=1)
    t = world.tanks[0]
    # before the foot of the southern ramp (x 24..50, z 30..44), facing up it (+x)
    t.place(23.0, 37.0, 0.0)
    world.stand(t, 0.0)
    assert t.level == 0 and abs(t.y) < 0.3
    seen_pitch = 0.0
    for _ in range(1500):
        world.step(None, [Command(advance=1.0)])
        seen_pitch = max(seen_pitch, t.pitch)
        if t.x > 60:
            break
    assert t.x > 55 and abs(t.y - 5.0) < 0.2, (t.x, t.y, t.level)
    assert world.ground.levels == 2 and t.level == 1  # on the roof, over the gate passage
    assert seen_pitch > math.radians(5)  # nose up on the ramp


def test_tanks_on_a_bridge_and_under_it_do_not_collide(arenas):
    info = arenas["bridge"]
    world = _world(info, n=2)
    a, b = world.tanks
    a.place(40.0, 30.0, 0.0)
    world.stand(a, 5.0)
    b.place(40.0, 30.0, 0.0)
    world.stand(b, 0.0)
    assert abs(a.y - 5.0) < 0.1 and abs(b.y) < 0.1 and a.level != b.level
    col = world.detect_collisions(range(2))
    assert not col.pairs
    start = [(t.x, t.z) for t in world.tanks]
    for _ in range(120):
        world.step(None, [Command(), Command()])
    assert [(t.x, t.z) for t in world.tanks] == start  # nothing pushed them apart


def test_a_shell_fired_into_a_hill_stops_on_it(arenas):
    info = arenas["rolling_terrain"]
    world = _world(info, n=1)
    t = world.tanks[0]
    g = world.ground
    # find a place with a rise ahead: the terrain 20 m in front higher than the muzzle
    for x in np.arange(10, 80, 3.0):
        for z in np.arange(10, 80, 3.0):
            t.place(float(x), float(z), 0.0)
            world.stand(t, None)
            ahead = g.height(x + 20, z, t.level)
            if g.exists[t.level][g.cell_of(x + 20, z)] and ahead > t.y + t.spec.muzzle_local[1] + 1.0 \
                    and abs(t.pitch) < math.radians(3):
                s = fire(t, world.walls, world.rules, None, g)
                assert math.isfinite(s.stop_at) and s.stop_at < 20.0 / t.spec.shell_speed * 1.5
                return
    pytest.skip("no rise found ahead of a level spot")


def test_a_match_on_the_fort_reports_heights_and_replays_bit_for_bit(arenas):
    from tanktool.sim.replay import decode, encode, play_replay, record_match

    info = arenas["fort"]
    spec = load_tank_spec("light")
    res = run_match(info, spec, bots=4, seconds=8, seed=2)
    for r, t in zip(res.report["tanks"], res.world.tanks):
        assert r["height"] == pytest.approx(t.y, abs=1e-3)
    result, replay = record_match(info, spec, bots=4, seconds=6, seed=4)
    back = play_replay(decode(encode(replay)), info, spec)
    assert back.matches, "a replay on the fort did not end in the recorded state"


@pytest.mark.parametrize("name", ("hills", "fort"))
def test_the_three_sight_tests_agree(arenas, name):
    """SolidField.blocked (one line, block by block), visible_from (one point to many)
    and visible (all pairs) sample the same points: the same answers, line for line;
    and a line through a deck or under a hill is blocked while one well above is not."""
    g = arenas[name].ground
    sf = g.solids
    rng = np.random.default_rng(5)
    li, ii, jj = np.nonzero(g.exists)
    k = rng.choice(len(li), 60, replace=False)
    pts = np.array([(g.ox + (jj[a] + 0.5) * g.cell, g.h[li[a], ii[a], jj[a]] + 1.2, g.oz + (ii[a] + 0.5) * g.cell)
                    for a in k])
    vis = sf.visible(pts)
    for a in range(len(pts)):
        row = sf.visible_from(tuple(pts[a]), pts)
        for b in range(len(pts)):
            if a != b:
                assert row[b] == vis[a, b] == (not sf.blocked(tuple(pts[a]), tuple(pts[b])))
    assert 0.05 < vis.mean() < 0.98
    hi = pts.copy()
    hi[:, 1] = g.h[np.isfinite(g.h)].max() + 20.0      # above everything: all visible
    assert sf.visible(hi).all()
