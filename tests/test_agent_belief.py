"""The hunt's belief (sim/agents/belief.py): where an enemy may be, from the spawn
points, sightings and sounds, spread as a front at a tank's pace, minus what was
looked at; and the goal it gives."""

import math

import numpy as np

from sim_fixtures import box_arena
from tanktool.sim.agents.belief import DECAY, MISSED, PACE, Belief
from tanktool.sim.agents.navigation import agent_grid
from tanktool.sim.agents.sight import Coverage, Views
from tanktool.sim.body import TankSpec
from tanktool.sim.world import World


def views():
    walls, spawns = box_arena()
    w = World(walls, [TankSpec.box("t")] * 2, spawns, seed=1)
    grid = agent_grid(w, 1.0, w.tanks[0].spec.radius + 0.5)
    return Views(grid, w.walls.segments), [(x, z, None) for x, z, _ in spawns]


def test_it_starts_on_the_other_spawn_points_and_spreads_as_a_front():
    v, spawns = views()
    b = Belief(v, spawns)
    mine = v.cell_at(spawns[0][0], spawns[0][1])
    b.start(0.0, mine)
    assert b.p[mine] < 0.05 and b.p[v.cell_at(spawns[1][0], spawns[1][1])] == 1.0
    far = [c for c in range(len(v)) if b.p[c] < 0.05]
    dist = v.path_distances(v.cell_at(spawns[1][0], spawns[1][1]))
    b.spread(4.0, 10.0)                     # 24 m of the enemy's way at PACE
    reached = b.p > 0.5
    assert reached.sum() > 5
    # a front: it got about as far as the way driven, not a random walk's sqrt
    assert np.max(dist[reached & np.isfinite(dist)]) > 0.5 * 4.0 * PACE * 10.0
    assert all(b.p[c] <= 1.0 for c in far)


def test_a_look_empties_what_it_saw_a_sighting_moves_it_a_kill_sends_it_to_the_spawns():
    v, spawns = views()
    b = Belief(v, spawns)
    b.p[:] = 1.0
    b.looked(np.array([0, 1, 2]))
    assert b.p[0] == MISSED and b.p[3] == 1.0
    c = v.cell_at(75.0, 35.0)
    b.at([c], 0.9)
    assert b.p[c] == 1.0 and math.isclose(b.p[3], 0.1)
    b.spread(0.0, 10.0)
    b.spread(1.0, 10.0)     # its neighbours fill from it, a link's DECAY less
    nb = [n for n, _ in v.neighbours[c]]
    assert max(b.p[nb]) == DECAY
    b.respawned()
    assert all(b.p[s] == 1.0 for s in b.spawn_cells)


def test_the_goal_sees_the_most_of_it_per_metre():
    v, spawns = views()
    b = Belief(v, spawns)
    b.p[:] = 0.0
    c = v.cell_at(75.0, 35.0)
    b.p[c] = 1.0
    cov = Coverage(v, math.radians(60.0), 90.0)
    here = v.cell_at(45.0, 35.0)            # behind the thin wall from it
    goal, gain = b.goal(cov.sees, here)
    assert cov.sees[goal, c] == 1.0 and gain == 1.0
    assert b.goal(cov.sees, -1) is None


def test_two_enemies_seen_at_once_are_both_kept():
    v, spawns = views()
    b = Belief(v, spawns)
    b.p[:] = 1.0
    b.at([3, 40, -1], 0.9)      # -1: off the blocks
    assert b.p[3] == b.p[40] == 1.0 and math.isclose(b.p[5], 0.1)
    assert not b.spread_out()
