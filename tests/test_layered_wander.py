"""The wander heuristic on a ground walks the layered agent grid (issue 25): nodes are
(level, i, j), every step follows the grid's links, and the walk starts on the tank's
own level -- not on a deck over it -- so a tank under a deck is never routed into a
column only the deck has.  On a flat arena it is the 2002 heuristic on (i, j), as before."""

from __future__ import annotations

import random

import pytest

from tanktool.nav.steering import STEPS, children3
from tanktool.sim.agents.navigation import Memory, Wanderer, agent_grid, wander_start
from tanktool.sim.match import load_match_arena, load_tank_spec
from tanktool.sim.world import World

from level_helpers import ROOT


@pytest.fixture(scope="module")
def fort_grid():
    info = load_match_arena(ROOT / "arenas" / "fort")
    spec = load_tank_spec("light")
    w = World(info.walls, [spec] * 2, info.spawns, bounds=info.bounds, ground=info.ground)
    return w, agent_grid(w, 1.0, spec.radius + 0.5)


def _linked(lay, a, b) -> bool:
    """Whether ``b`` is one step from ``a`` along the grid's links: straight along one
    (the level it reaches), or diagonal along two (either way round)."""
    links = lay.links()
    di, dj = b[1] - a[1], b[2] - a[2]
    dirs = {s: d for d, s in enumerate(STEPS.values())}

    def follow(n, step):
        d = dirs[step]
        to = int(links[n][d])
        return (to, n[1] + step[0], n[2] + step[1]) if to >= 0 else None

    if (di, dj) in dirs:
        return follow(a, (di, dj)) == b
    for s1, s2 in (((di, 0), (0, dj)), ((0, dj), (di, 0))):
        mid = follow(a, s1)
        if mid is not None and lay.valid[mid] and follow(mid, s2) == b:
            return True
    return False


def test_the_walk_starts_on_the_tanks_level(fort_grid):
    _, g = fort_grid
    lay = g.layers
    under = wander_start(g, 70.0, 50.0, 0.0)      # the gate passage, under the roof
    over = wander_start(g, 70.0, 50.0, 5.0)       # the roof over it
    assert under is not None and over is not None
    assert under[0] == 0 and abs(lay.height[under] - 0.0) < 0.2
    assert over[0] == 1 and abs(lay.height[over] - 5.0) < 0.2


def test_every_step_follows_a_link_and_the_ramps_lead_up(fort_grid):
    w, g = fort_grid
    lay = g.layers
    mem = Memory(g)
    wand = Wanderer(g, mem, random.Random(3))
    t = w.tanks[0]
    node, heading = wander_start(g, t.x, t.z, t.y), "+x"
    for k in range(4000):
        nxt = wand.choose(node, heading, 0.1 * k)
        assert nxt is not None
        new, heading = nxt
        assert len(new) == 3 and lay.valid[new] and _linked(lay, node, new), (node, new)
        node = new
        mem.visit(*g.centre(*node[1:]), 0.1 * k)
    # at a ramp's top the roof is among the choices (the link up to level 1)
    links = lay.links()
    tops = [(0, int(i), int(j)) for i, j in zip(*((links[0] == 1).any(axis=-1) & lay.valid[0]).nonzero())]
    assert tops
    kids = [c.node for top in tops for h in STEPS for c in children3(lay, top, h)]
    assert any(n[0] == 1 for n in kids)


def test_on_a_flat_arena_the_walk_is_the_2002_one():
    info = load_match_arena("box")
    spec = load_tank_spec("light")
    w = World(info.walls, [spec] * 2, info.spawns, bounds=info.bounds, ground=info.ground)
    g = agent_grid(w, 1.0, spec.radius + 0.5)
    assert g.layers is None
    n = wander_start(g, 30.0, 30.0, 0.0)
    assert n is not None and len(n) == 2
    nxt = Wanderer(g).choose(n, "+x")
    assert nxt is not None and len(nxt[0]) == 2
