"""Shells: no tunnelling through walls or tanks at any speed; damage, kills, respawns."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_fixtures import box_arena, bundled_arenas, maze_arena, start_beside

from tanktool.formats.walls_txt import read_walls
from tanktool.sim.body import TankSpec
from tanktool.sim.collide import BruteWallIndex
from tanktool.sim.commands import Command
from tanktool.sim.rules import Rules
from tanktool.sim.world import World


def _arenas():
    out = [("box-fixture", box_arena()[0]), ("maze-fixture", maze_arena()[0])]
    out += [(p.name, read_walls(p / "walls.txt")) for p in bundled_arenas()]
    return out


@pytest.mark.parametrize("name,walls", _arenas(), ids=[n for n, _ in _arenas()])
def test_shells_at_500_never_pass_through_a_wall(name, walls):
    spec = TankSpec.box("gunner", shell_speed=500.0, fire_interval=0.01)
    seg = walls.all_segments()
    brute = BruteWallIndex(seg)
    world = None
    shots = 0
    for k in range(len(seg)):
        if math.hypot(*(seg[k, 1] - seg[k, 0])) < 1e-6:
            continue
        # from 2 m away and pressed against it (5 cm), at several angles
        for gap in (2.0, 0.05):
            start = start_beside(seg, k, brute, walls.bounds, spec.radius, gaps=(gap,))
            if start is None:
                continue
            px, pz, fx, fz = start
            for deg in (0, 35, -35, 70, -70):
                h = math.atan2(fz, fx) + math.radians(deg)
                if world is None:
                    world = World(walls, [spec], [(px, pz, h)], seed=0)
                t = world.tanks[0]
                t.place(px, pz, h)
                world.shells.clear()
                world.step(None, [Command(fire=True)])
                assert len(world.shells) == 1 or t.shots
                shots += 1
                for _ in range(400):
                    for s in world.shells:
                        # a segment the shell flew without being stopped crosses no wall
                        assert len(brute.query_segment(np.array((s.px, s.pz)), np.array((s.x, s.z)))) == 0, \
                            f"wall {k}: shell flew through a wall"
                        (x0, z0), (x1, z1) = walls.bounds
                        assert x0 - 1e-6 <= s.x <= x1 + 1e-6 and z0 - 1e-6 <= s.z <= z1 + 1e-6
                    if not world.shells:
                        break
                    world.step(None, [Command()])
                assert not world.shells
    assert shots >= len(seg)


@pytest.mark.parametrize("speed", [500.0, 5000.0])
def test_fast_shell_hits_a_thin_tank(speed):
    """At 5000 m/s a shell moves 42 m a step, far more than the target is deep."""
    walls, _ = box_arena()
    shooter = TankSpec.box("s", shell_speed=speed)
    target = TankSpec.box("t", width=2.0, length=5.0)
    # the vehicle's own gun, no spawn protection: the classic rules
    w = World(walls, [shooter, target], [(5, 10, 0), (115, 10, 0)], seed=0, rules=Rules.classic())
    w.tanks[0].place(5.0, 10.0, 0.0)
    w.tanks[1].place(110.0, 10.0, math.pi / 2)     # broadside-on: 2 m deep along the shot
    events = w.step(None, [Command(fire=True), Command()])
    assert [e.kind for e in events] == ["shot"]
    kinds = []
    for _ in range(60):
        kinds += [e.kind for e in w.step(None, [Command(), Command()])]
    assert kinds == ["hit"]
    assert w.tanks[1].hp == target.hit_points - shooter.shell_damage
    assert w.tanks[0].hits == 1


def test_damage_kill_respawn_and_score():
    walls, spawns = box_arena()
    shooter = TankSpec.box("s", shell_damage=40.0, fire_interval=0.5)
    target = TankSpec.box("t", hit_points=100.0)
    w = World(walls, [shooter, target], spawns, seed=4, respawn_delay=2.0, rules=Rules.classic())
    a, b = w.tanks
    a.place(10.0, 30.0, 0.0)
    b.place(50.0, 30.0, 0.0)
    log = []
    for i in range(int(6.0 / w.dt)):
        ev = w.step(None, [Command(fire=b.alive), Command()])
        log += ev
        if not b.alive:
            # the dead neither move nor collide nor take hits
            assert b.hp <= 0
    kinds = [e.kind for e in log]
    assert kinds.count("hit") == 3
    assert kinds.count("kill") == 1
    assert kinds.count("respawn") == 1
    kill = next(e for e in log if e.kind == "kill")
    respawn = next(e for e in log if e.kind == "respawn")
    assert respawn.t == pytest.approx(kill.t + 2.0, abs=w.dt * 1.01)
    assert (respawn.x, respawn.z) in [(float(x), float(z)) for x, z, _ in spawns]
    # respawned where no live tank is near
    assert math.hypot(respawn.x - a.x, respawn.z - a.z) > a.spec.radius + b.spec.radius + 1.0
    assert b.alive and b.hp == 100.0
    assert (a.kills, a.hits, b.deaths) == (1, 3, 1) and a.shots >= 3


def test_own_shells_never_hit_the_shooter():
    walls, spawns = box_arena()
    spec = TankSpec.box("s", fire_interval=0.05)
    w = World(walls, [spec], spawns, seed=0)
    w.tanks[0].place(110.0, 45.0, 0.0)     # facing the east wall, 10 m away
    hits = []
    for i in range(600):
        hits += [e for e in w.step(None, [Command(advance=1.0, rotate=0.5, fire=True)]) if e.kind == "hit"]
    assert hits == [] and w.tanks[0].hp == spec.hit_points and w.tanks[0].shots > 50
