"""Yardsticks and agents on levels of ramps and decks (issue 28, the generated bridge):

* the grids join parts apart by straight runs as wide as the hull (the bridge's 8 m
  deck, left out by the footprint circle's clearance), and only there;
* the yardsticks' grid keeps a ramp too steep one way: down it, not up;
* a yardstick driving and getting nowhere backs out and plans round the spot.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bot_helpers import driver
from tanktool.sim.agents import robots
from tanktool.sim.agents.agent import GRADE
from tanktool.sim.agents.navigation import agent_grid, plan_path
from tanktool.sim.agents.robots import Robot
from tanktool.sim.commands import IDLE
from tanktool.sim.match import load_match_arena, load_tank_spec
from tanktool.sim.rules import GRAVITY
from tanktool.sim.world import World


def _world(info, seed=0):
    spec = load_tank_spec("light")
    return World(info.walls, [spec] * 2, info.spawns_for(spec), seed=seed, bounds=info.bounds, ground=info.ground)


@pytest.fixture(scope="module")
def bridge(imported_level):
    return load_match_arena(imported_level("bridge"))


def _grids(w, **kw):
    spec = w.tanks[0].spec
    grade = GRADE * spec.engine_force / (spec.mass * GRAVITY)
    half = 0.5 * (spec.box[3] - spec.box[1])
    return (agent_grid(w, 1.0, spec.radius + 0.5, grade),
            agent_grid(w, 1.0, spec.radius + 0.5, grade, narrow=half + 0.5, **kw))


WEST, EAST = (20.0, 40.0, 5.0), (60.0, 20.0, 5.0)     # on the two plateaus


def test_the_deck_joins_the_plateaus_and_nothing_else_is_added(bridge):
    w = _world(bridge)
    before, after = _grids(w)
    assert not plan_path(before, WEST, EAST) and plan_path(after, WEST, EAST)
    added = after.layers.valid & ~before.layers.valid
    _, i, j = np.nonzero(added)
    xz = np.array([after.layers.centre(a, b) for a, b in zip(i, j)])
    # the deck: x 34-46, z 26-34 (its runs start a little back on each plateau)
    assert len(xz) and (np.abs(xz[:, 1] - 30.0) < 2.5).all() and (np.abs(xz[:, 0] - 40.0) < 10.0).all()


def test_the_yardsticks_grid_keeps_a_ramp_too_steep_one_way(bridge):
    w = _world(bridge)
    _, grid = _grids(w, one_way=True)
    on_ramp = (8.0, 8.0, 2.3)           # the west ramp (x 3-13, z 1-16, up to the north)
    assert plan_path(grid, WEST, on_ramp)   # down it
    assert not plan_path(grid, on_ramp, WEST)
    assert plan_path(grid, WEST, EAST)  # across the deck


def test_a_yardstick_getting_nowhere_backs_out_and_plans_round_the_spot():
    arena, spec = load_match_arena("maze"), load_tank_spec("light")
    w = World(arena.walls, [spec, spec], arena.spawns, seed=0, bounds=arena.bounds)
    w.tanks[0].place(5.65, 5.65, 0.785)
    w.tanks[1].place(98.26, 98.26, -2.356)
    drv = driver(Robot(), 1)
    backed = False
    for _ in range(int((robots.NO_PROGRESS_S + 1.0) / w.dt)):
        cmd = drv(w, w.tanks[0])
        w.step(None, [cmd, IDLE])
        w.tanks[0].place(5.65, 5.65, w.tanks[0].heading)      # wedged: it goes nowhere
        bot = drv.bot
        backed |= bot.avoid is not None and cmd.advance < 0.0
    bot = drv.bot
    assert bot.avoid is not None and backed
    until, ax, az = bot.avoid
    assert until > w.t and math.hypot(ax - 5.65, az - 5.65) <= robots.AVOID_R + 1e-6
    # its next way keeps round the spot
    w.tanks[0].place(5.65, 5.65, 0.785)
    path = bot.plan(drv.perceiver.view(w, drv.rng), (98.26, 98.26))
    assert path and all(math.hypot(x - ax, z - az) > robots.AVOID_R - 1.0 for x, z in path[:-1])


def test_a_yardstick_spawned_at_a_ramps_top_stays_up_and_fights(bridge):
    """The spawn at the west ramp's top (18 degrees, steeper than the light tank climbs):
    the robot, shooting at an enemy on the other plateau, slid down it and was stranded
    at its foot; now it drives up onto its grid first and its moves stop short of the ramp."""
    w = _world(bridge)
    me, other = w.tanks
    me.x, me.z, me.heading = 6.589, 15.6209, 0.406411
    w.stand(me, 4.95)
    other.x, other.z = 55.7, 23.9
    w.stand(other, 5.0)
    drv = driver(Robot(), 1)
    lowest = me.y
    for _ in range(int(20.0 / w.dt)):
        w.step(None, [drv(w, me), IDLE])
        w.protected_until = [math.inf, math.inf]     # nobody dies: where it drives is the point
        lowest = min(lowest, me.y)
    assert lowest > 3.5 and me.y > 4.5


def test_a_corridor_narrower_than_the_footprint_joins_a_pocket_a_step_or_two_aside(imported_level):
    """ramps_and_decks: a spawn in the pocket between a ramp's side and the yard's wall,
    whose only way out is a 6 m corridor along the deck's block: its run of nodes meets
    the pocket's and the yard's nodes a step or two aside (1 m nodes), not ahead."""
    w = _world(load_match_arena(imported_level("ramps_and_decks")))
    before, after = _grids(w)
    pocket, yard = (64.0, 42.5, 0.0), (6.2, 6.2, 0.0)
    assert not plan_path(before, pocket, yard)
    assert plan_path(after, pocket, yard) and plan_path(after, yard, pocket)
