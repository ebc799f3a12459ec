"""The agent on relief keeps off what it cannot drive back from, and breaks stalemates.

* its grid has no link steeper than its vehicle climbs at a useful speed (the bridge
  level's 18 degree ramp, which the light tank climbs at 0.25 m/s: a tank gone down it
  stays down); the hills' 10 degree slopes and the fort's ramps are kept, and the
  yardsticks' grid (the map's) is unchanged;
* its free moves (fighting, evading) stop short of a plateau's edge: the world keeps a
  tank's centre on the surface, so one driven at the edge hangs over it, pitched up to
  40 degrees, its gun on the sky;
* fighting with the gun loaded and no shot fired for ``combat.QUIET`` s, it closes in
  along the A* way to the enemy (two tanks at 40 m on different heights, neither shot
  carrying, stared at each other for 100 s: a 0-0 draw); an enemy lost and seen again
  within ``combat.REGAIN`` s does not start that count again;
* pitched or rolled more than ``agent.WEDGED`` (up on a rock, not on a slope), it
  does not drive "up the slope" into the rock but leaves it to the pilot's unstick.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bot_helpers import view_of
from tanktool.bots import BotDriver
from tanktool.sim.agents import Agent
from tanktool.sim.agents.agent import GRADE, WEDGED
from tanktool.sim.agents.combat import QUIET, REGAIN, Attack
from tanktool.sim.agents.navigation import agent_grid
from tanktool.sim.match import load_match_arena, load_tank_spec
from tanktool.sim.rules import GRAVITY
from tanktool.sim.world import World

from level_helpers import ROOT


def _world(info, seed=0):
    spec = load_tank_spec("light")
    return World(info.walls, [spec] * 2, info.spawns_for(spec), seed=seed, bounds=info.bounds, ground=info.ground)


def _grade(spec) -> float:
    return GRADE * spec.engine_force / (spec.mass * GRAVITY)


@pytest.fixture(scope="module")
def bridge(imported_level):
    return load_match_arena(imported_level("bridge"))


def test_the_grid_cuts_a_ramp_too_steep_and_keeps_the_hills(bridge):
    w = _world(bridge)
    spec = w.tanks[0].spec
    plain = agent_grid(w, 1.0, spec.radius + 0.5)
    graded = agent_grid(w, 1.0, spec.radius + 0.5, _grade(spec))
    # the ramp (x 3-13, z 1-16, rising 5 m) is on the plain grid, not on the graded one
    # (its top row, a 0.3 m step from the plateau, may stay: heights come in 0.1 m voxel
    # steps, and the graded cut allows one step of slack for that)
    on_ramp = plain.layers.valid[:, 6:14, 6:10].sum()
    assert on_ramp > 0 and graded.layers.valid[:, 6:13, 6:10].sum() == 0
    assert graded.layers.valid[:, 20:50, 5:30].sum() > 500          # the plateau stays
    hills = load_match_arena(ROOT / "arenas" / "hills")
    wh = _world(hills)
    a = agent_grid(wh, 1.0, spec.radius + 0.5)
    b = agent_grid(wh, 1.0, spec.radius + 0.5, _grade(spec))
    assert np.array_equal(a.layers.valid, b.layers.valid)


def test_the_agent_uses_the_graded_grid_and_the_map_keeps_its_own(bridge):
    w = _world(bridge)
    drv = BotDriver(Agent("hard"), 1)
    drv(w, w.tanks[0])
    agent = drv.bot
    spec = w.tanks[0].spec
    half = 0.5 * (spec.box[3] - spec.box[1])
    assert agent.nav.grid is agent_grid(w, 1.0, spec.radius + 0.5, _grade(spec), narrow=half + 0.5)
    assert drv.perceiver.map.grid.layers.valid[:, 6:14, 6:10].sum() > 0


def _placed(w, x, z, heading, y=None):
    t = w.tanks[0]
    t.x, t.z, t.heading = x, z, heading
    t.vx = t.vz = t.omega = 0.0
    w.stand(t, y)
    o = w.tanks[1]
    o.x, o.z = 70.0, 40.0
    w.stand(o, 5.0)
    return t


def test_free_moves_stop_short_of_a_plateau_edge(bridge):
    w = _world(bridge)
    drv = BotDriver(Agent("hard"), 1)
    drv(w, w.tanks[0])
    agent = drv.bot
    # on the right plateau (x 46-79) 6 m from its west edge, facing it (-x)
    _placed(w, 52.0, 20.0, math.pi, 5.0)
    view = view_of(drv, w)
    assert agent.drive(view, 10.0, 0.0, 0.0).advance <= 0.0       # not over the edge
    assert agent.drive(view, -10.0, 0.0, 0.0).advance < -0.3      # away from it: yes
    # strafing: the edge on the right (+ = right of a tank facing +z is -x)
    _placed(w, 52.0, 20.0, math.pi / 2, 5.0)
    view = view_of(drv, w)
    assert agent.drive(view, 0.0, 7.0, 0.0).strafe <= 0.0
    assert agent.drive(view, 0.0, -7.0, 0.0).strafe < -0.3
    # in the middle of the plateau nothing is held back
    _placed(w, 62.0, 20.0, math.pi, 5.0)
    view = view_of(drv, w)
    assert agent.drive(view, 10.0, 0.0, 0.0).advance > 0.5


def test_a_quiet_fight_closes_in_along_the_way(bridge):
    """Hard sees the enemy 32 m off on its plateau and holds fire (the enemy under a
    long spawn protection): it backs off towards its fighting distance, stops at the
    top of the ramp (not down it), and after QUIET s drives the A* way towards the
    enemy, gun on it."""
    w = _world(bridge)
    drv = BotDriver(Agent("hard"), 1)
    t = _placed(w, 10.0, 24.0, 1.0, 5.0)
    o = w.tanks[1]
    o.x, o.z, o.heading = 26.0, 52.0, math.pi
    w.stand(o, 5.0)
    w.protected_until[1] = 1e9            # the agent holds its fire: a quiet fight
    from tanktool.sim.commands import Command
    seen_attack, far, low = False, 0.0, 9.0
    for _ in range(int((QUIET + 6.0) / w.dt)):
        cmd = drv(w, t)
        seen_attack |= drv.bot.state == "attack"
        w.step(None, [cmd, Command()])
        far = max(far, math.hypot(o.x - t.x, o.z - t.z))
        low = min(low, t.y)
    assert seen_attack and t.shots == 0
    assert low > 4.5                                    # never down the ramp
    assert far > 35.0 and math.hypot(o.x - t.x, o.z - t.z) < 20.0


def test_a_fight_regained_soon_keeps_its_quiet_count():
    """An enemy strafing in and out of sight over a crest: the time without a shot
    counts on through a loss of sight shorter than REGAIN s, and starts again after a
    longer one (it had reset at every loss, and the agent stared for 50 s unfired)."""
    from types import SimpleNamespace

    a = Attack()
    a.enter(None, SimpleNamespace(t=10.0), None, None)
    assert a.quiet_since == 10.0
    a.exit(None, SimpleNamespace(t=14.0))
    a.enter(None, SimpleNamespace(t=14.0 + 0.5 * REGAIN), None, None)
    assert a.quiet_since == 10.0
    a.exit(None, SimpleNamespace(t=20.0))
    a.enter(None, SimpleNamespace(t=20.0 + 2.0 * REGAIN), None, None)
    assert a.quiet_since == 20.0 + 2.0 * REGAIN


def test_at_the_top_of_a_ramp_too_steep_it_drives_up_first(bridge):
    """Spawned facing across the top of the bridge level's ramp (its back to the
    slope), it climbs onto the plateau before anything else: strafed or turned on
    the spot, the tank slid down the ramp and stayed at its foot for the duel."""
    w = _world(bridge)
    drv = BotDriver(Agent("hard"), 1)
    t = _placed(w, 6.6, 15.6, 0.41, 5.0)
    o = w.tanks[1]                  # in sight across the passage: it attacks
    o.x, o.z = 60.0, 8.0
    w.stand(o, 5.0)
    from tanktool.sim.commands import Command
    for _ in range(int(5.0 / w.dt)):
        w.step(None, [drv(w, t), Command()])
    assert t.y > 4.9 and t.z > 16.0


def test_up_on_a_rock_it_does_not_drive_up_the_slope(bridge):
    """At the top of the ramp (where it drives up first) but with the hull pitched
    more than any slope it climbs, it is wedged on something: no drive up (on the
    hills it pushed on up a rock at 34 degrees for 3 s, until shot)."""
    import dataclasses

    w = _world(bridge)
    drv = BotDriver(Agent("hard"), 1)
    _placed(w, 6.6, 15.6, 0.41, 5.0)
    view = view_of(drv, w)
    agent = drv.bot
    agent.act(view)
    assert agent.off_slope(view) is not None          # on the slope: up first
    me = view.me
    for k in ("pitch", "roll"):
        tilted = dataclasses.replace(view, me=dataclasses.replace(me, **{k: WEDGED + 0.1}))
        assert agent.off_slope(tilted) is None
