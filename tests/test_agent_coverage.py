"""The agent's sight memory (issue 7): blocks, line of sight between them, what a look
marks as seen, and the exploration goal it gives."""

import math
import random

import numpy as np

from sim_fixtures import box_arena
from tanktool.sim.agents import Agent
from tanktool.sim.agents.navigation import agent_grid
from tanktool.sim.agents.sight import Coverage, Views, views_for
from bot_helpers import driver, perceiver
from tanktool.bots import Senses
from tanktool.sim.body import TankSpec
from tanktool.sim.world import World


def box():
    walls, spawns = box_arena()
    w = World(walls, [TankSpec.box("t")] * 2, spawns, seed=1)
    return w, agent_grid(w, 1.0, w.tanks[0].spec.radius + 0.5)


def test_views_blocks_and_line_of_sight_match_the_walls():
    w, grid = box()
    v = Views(grid, w.walls.segments)
    assert len(v) > 50 and v.k == 4
    # every representative point is a valid node inside its block
    for c, (i, j) in enumerate(v.nodes):
        assert grid.valid[0, i, j] and v.cell_of[i, j] == c
    # the pairwise sight agrees with the walls' own test, both ways
    rng = np.random.default_rng(0)
    for a, b in rng.integers(0, len(v), size=(200, 2)):
        (ax, az), (bx, bz) = v.points[a], v.points[b]
        assert v.visible[a, b] == (not w.walls.blocked(ax, az, bx, bz))
        assert v.visible[a, b] == v.visible[b, a]
    # behind the thin wall x = 60 (z 20..50): not in sight of each other
    a, b = v.cell_at(45.0, 35.0), v.cell_at(75.0, 35.0)
    assert not v.visible[a, b]
    # path distances: at least the straight line, finite in a connected arena
    d = v.path_distances(a)
    assert np.isfinite(d).all()
    assert d[b] >= v.distance[a, b] - 1e-9
    assert views_for(w, grid) is views_for(w, grid)      # cached


def test_a_look_marks_the_cone_in_sight_and_nothing_behind_a_wall():
    w, grid = box()
    v = views_for(w, grid)
    cov = Coverage(v, math.radians(60), 100.0)
    cov.look(45.0, 35.0, 0.0, t=5.0)                  # looking +x, at the thin wall
    seen = np.isfinite(cov.seen)
    assert seen[v.cell_at(45.0, 35.0)]                   # where it stands
    assert seen[v.cell_at(55.0, 35.0)]                   # ahead, this side of the wall
    assert not seen[v.cell_at(75.0, 35.0)]               # ahead, behind the wall
    assert not seen[v.cell_at(15.0, 35.0)]               # behind it: outside the cone
    assert cov.since(55.0, 35.0, 7.0) == 2.0 and cov.since(75.0, 35.0, 7.0) == math.inf
    # staleness: 0 while fresh, up to 1 for never seen
    st = cov.staleness(10.0)
    assert st[v.cell_at(55.0, 35.0)] == 0.0 and st[v.cell_at(75.0, 35.0)] == 1.0


def test_exploration_goal_heads_for_what_was_not_seen():
    w, grid = box()
    v = views_for(w, grid)
    cov = Coverage(v, math.radians(60), 100.0)
    # everything seen just now except the far side of the thin wall (x > 62)
    cov.seen[:] = 100.0
    far = v.points[:, 0] > 62.0
    cov.seen[far] = -math.inf
    cell, gain = cov.goal(20.0, 35.0, t=101.0)
    assert gain >= 1.0
    # the goal sees blocks not seen, and it is not where the agent stands
    assert (v.visible[cell] & far).any()
    assert cell != v.cell_at(20.0, 35.0)
    # nothing unseen anywhere: no goal
    cov.seen[:] = 100.0
    assert cov.goal(20.0, 35.0, t=101.0) is None


def test_wandering_agent_drives_to_unseen_parts_and_sees_more_of_the_arena():
    walls, spawns = box_arena()
    w = World(walls, [TankSpec.box("t")], spawns, seed=1)     # alone
    agent = driver(Agent("normal", watch=False), 4)
    me = w.tanks[0]
    me.place(10.0, 10.0, 0.0)
    for _ in range(int(30.0 / w.dt)):
        w.step(None, [agent(w, me)])
    assert agent.bot.state == "wander"
    assert np.isfinite(agent.bot.nav.coverage.seen).mean() > 0.8    # most of the box seen in 30 s
    assert me.wall_bumps <= 1


def test_a_sighting_carries_the_enemy_hull_heading():
    w, _ = box()
    w.tanks[0].place(40.0, 10.0, 0.0)
    w.tanks[1].place(55.0, 10.0, 2.0)
    (s,) = perceiver(w, 0, Senses(math.radians(60), 100.0, 80.0)).look(w, w.tanks[0])
    assert s.index == 1 and s.heading == w.tanks[1].heading


def test_a_block_never_looked_at_is_worth_more_than_one_looked_at_long_ago():
    from tanktool.sim.agents.sight import NEVER_SEEN

    w, grid = box()
    v = views_for(w, grid)
    cov = Coverage(v, math.radians(60), 100.0)
    west, east = v.cell_at(15.0, 35.0), v.cell_at(105.0, 35.0)
    cov.seen[:] = 0.0                                   # everything looked at long ago
    cov.seen[east] = -math.inf                          # but one block never
    worth = cov.worth(1000.0)
    assert worth[east] == NEVER_SEEN > 1.0 and worth[west] == 1.0
    assert cov.gain(east, 1000.0) == float(cov.sees[east] @ worth)
    # all fresh but two blocks: one looked at long ago by us, one far off never
    cov.seen[:] = 990.0
    cov.seen[west], cov.seen[east] = 0.0, -math.inf
    cell, gain = cov.goal(20.0, 35.0, 1000.0)
    assert cov.sees[cell, east] and gain >= NEVER_SEEN
