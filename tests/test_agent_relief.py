"""Shooting on relief (sim/agents/relief.py): the hull's pitch read from the ground,
and a place found from which a shot will not pass over or under the enemy."""

from __future__ import annotations

import math

from bot_helpers import driver, view_of
from sim_fixtures import ROOT
from tanktool.sim.agents import Agent, relief
from tanktool.sim.commands import IDLE
from tanktool.sim.match import load_match_arena, load_tank_spec
from tanktool.sim.world import World


def place(w, x0, z0, x1, z1):
    me, other = w.tanks
    me.place(x0, z0, math.atan2(z1 - z0, x1 - x0))
    other.place(x1, z1, 0.0)
    w.step(None, [IDLE, IDLE])          # the ground tilts them


def test_the_pitch_read_from_the_ground_is_the_worlds_and_a_place_to_shoot_from_is_found():
    arena = load_match_arena(ROOT / "arenas" / "hills")
    spec = load_tank_spec(ROOT / "vehicles" / "light")
    w = World(arena.walls, [spec] * 2, arena.spawns, seed=3, bounds=arena.bounds, ground=arena.ground)
    drv = driver(Agent("hard"), 1)
    found = 0
    for k in range(24):
        a = 2.0 * math.pi * k / 24
        place(w, 60.0 + 30.0 * math.cos(a), 60.0 + 30.0 * math.sin(a), 60.0, 60.0)
        view = view_of(drv, w)
        me = view.me
        eye, pitch = relief.pitch_at(view, me.x, me.z, me.heading)
        assert abs(pitch - me.pitch) < math.radians(1.5) and abs(eye - me.eye) < 0.3
        if not view.seen:
            continue
        s = view.seen[0]
        ev = s.vehicle
        if relief.miss_from(view, me.x, me.z, me.eye, me.pitch, s, ev) < relief.TOLERANCE:
            continue
        spot = relief.firing_spot(view, s, lambda x, z: True)
        if spot is None:
            continue
        found += 1
        h = math.atan2(s.z - spot[1], s.x - spot[0])
        e2, p2 = relief.pitch_at(view, *spot, h)
        assert relief.miss_from(view, *spot, e2, p2, s, ev) < relief.TOLERANCE
        assert relief.shell_clear(view, *spot, e2, p2, s)
        assert math.hypot(spot[0] - me.x, spot[1] - me.z) <= relief.RINGS[-1] + 1e-6
    assert found >= 3


def test_a_shot_judged_clear_is_one_the_world_lets_through():
    """``shell_clear`` against the world's own shell (``weapons.fire``: the model's
    triangles), from 400 random pairs of places 25-60 m apart on the hills, every
    other one driving at the enemy (the shell keeps that velocity): the sight solid
    lets a line graze a crest, and judged 6 of these wrongly (48 of hard's 174 shells
    at the hills' camper went into a slope it passed)."""
    import random

    from tanktool.sim.weapons import fire

    arena = load_match_arena(ROOT / "arenas" / "hills")
    spec = load_tank_spec(ROOT / "vehicles" / "light")
    w = World(arena.walls, [spec] * 2, arena.spawns, seed=3, bounds=arena.bounds, ground=arena.ground)
    drv = driver(Agent("hard"), 1)
    rng = random.Random(5)
    judged = blocked = 0
    for k in range(400):
        x1, z1 = rng.uniform(5.0, 115.0), rng.uniform(5.0, 115.0)
        a, r = rng.uniform(0.0, 2.0 * math.pi), rng.uniform(25.0, 60.0)
        x0, z0 = x1 + r * math.cos(a), z1 + r * math.sin(a)
        if not (3.0 < x0 < 117.0 and 3.0 < z0 < 117.0):
            continue
        place(w, x0, z0, x1, z1)
        me, other = w.tanks
        if k % 2:
            me.vx, me.vz = 5.0 * me.c, 5.0 * me.s
        view = view_of(drv, w)
        if not view.seen:
            continue
        s, v = view.seen[0], view.me
        clear = relief.shell_clear(view, v.x, v.z, v.eye, v.pitch, s, (v.heading, v.vx, v.vz))
        shell = fire(me, w.walls, w.rules, None, w.ground)
        reach = shell.stop_at * math.hypot(shell.vx, shell.vz)
        assert clear == (reach >= math.hypot(other.x - me.x, other.z - me.z) - s.vehicle.radius - 1e-6)
        judged += 1
        blocked += not clear
    assert judged >= 100 and blocked >= 10
