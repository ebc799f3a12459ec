"""Computer opponents (issue 7): hearing engines, protecting a lead (score, clock,
hit points), the spawn points as where danger comes from, the hits seen land on an enemy."""

import math
import random

import pytest

from sim_fixtures import box_world
from tanktool.sim.agents import Agent
from tanktool.sim.agents.agent import LATE
from tanktool.sim.agents.perception import ENGINE_FULL, ENGINE_QUIET, Senses
from tanktool.sim.commands import IDLE


# ------------------------------------------------------------------ hearing engines
def test_an_engine_is_heard_through_a_wall_within_the_radius_and_not_beyond():
    # me at x=50, the thin wall x=60 between me and a tank 20 m away; another 60 m away
    w = box_world([(50.0, 35.0), (70.0, 35.0), (110.0, 35.0)])
    me, near, far = w.tanks
    assert w.walls.blocked(me.x, me.z, near.x, near.z)
    senses = Senses(math.radians(60), 90.0, 80.0, 0.15, random.Random(2), engine_radius=35.0)
    # standing still: not heard
    assert senses.listen_engines(w, me) is None
    # moving fast: heard through the wall, roughly where it is
    near.vx = ENGINE_FULL
    heard = senses.listen_engines(w, me)
    assert heard is not None and heard.engine
    assert math.hypot(heard.x - near.x, heard.z - near.z) < 4 * 0.15 * 20.0
    assert senses.heard is heard                       # remembered as the last thing heard
    # only the far one moving: 60 m is beyond the 35 m radius
    near.vx, far.vx = 0.0, ENGINE_FULL
    assert senses.listen_engines(w, me) is None
    # a dead tank makes no noise
    near.vx, near.alive = ENGINE_FULL, False
    assert senses.listen_engines(w, me) is None
    # no engine hearing at all with radius 0 (the default)
    near.alive = True
    assert Senses(math.radians(60), 90.0, 80.0, 0.15, random.Random(2)).listen_engines(w, me) is None


def test_a_faster_engine_is_heard_farther():
    w = box_world([(20.0, 20.0), (50.0, 20.0)])
    me, o = w.tanks
    senses = Senses(math.radians(60), 90.0, 80.0, 0.15, random.Random(4), engine_radius=40.0)
    o.vx = ENGINE_QUIET + 0.1                 # crawling: heard over about half the radius
    assert senses.listen_engines(w, me) is None           # 30 m
    o.place(35.0, 20.0, 0.0)
    o.vx = ENGINE_QUIET + 0.1
    assert senses.listen_engines(w, me) is not None       # 15 m
    o.place(50.0, 20.0, 0.0)
    o.vx = ENGINE_FULL                                    # full speed: 30 m < 40 m
    assert senses.listen_engines(w, me) is not None


def test_an_agent_goes_towards_an_engine_it_hears():
    w = box_world([(50.0, 35.0), (75.0, 35.0)], headings=[math.pi, 0.0])
    agent = Agent(random.Random(1), "normal")
    me, o = w.tanks
    o.vx = ENGINE_FULL
    agent(w, me)
    assert agent.state == "search"
    assert agent.plan is not None
    gx, gz = agent.plan.goals[0]
    assert math.hypot(gx - o.x, gz - o.z) < 15.0


# ------------------------------------------------------------------ protecting a lead
def lead_world(agent_kills=1, enemy_kills=0, hp=50.0, enemy_heading=math.pi / 2):
    """Me at (45, 30) looking +z at an enemy 50 m away in the open, between the thin
    wall (x = 60) and the L (x = 40 from z = 60 to 75)."""
    w = box_world([(45.0, 30.0), (45.0, 80.0)], headings=[math.pi / 2, enemy_heading])
    me, enemy = w.tanks
    me.kills, enemy.kills = agent_kills, enemy_kills
    me.hp = hp
    return w


def run(agent, w, seconds):
    me, enemy = w.tanks
    states, fired = set(), False
    for _ in range(int(round(seconds / w.dt))):
        cmd = agent(w, me)
        fired |= bool(cmd.fire)
        states.add(agent.state)
        w.step(None, [cmd, IDLE])
    return states, fired


def test_protecting_reads_the_score_the_clock_and_its_hit_points():
    agent = Agent(random.Random(0), "normal", match_seconds=60.0)
    w = lead_world(1, 0, hp=50.0)
    me = w.tanks[0]
    assert agent.protecting(w, me)                       # ahead and damaged
    me.hp = me.spec.hit_points
    assert not agent.protecting(w, me)                   # ahead, unhurt, early
    w.t = 60.0 - LATE + 1.0
    assert agent.protecting(w, me)                       # ahead, unhurt, late
    w.t = 0.0
    me.hp = 50.0
    w.tanks[1].kills = 1
    assert not agent.protecting(w, me)                   # level: seek
    w.tanks[1].kills = 2
    assert not agent.protecting(w, me)                   # behind: seek
    w.tanks[1].kills = 0
    # the enemy it fights is nearer death than it is (it saw 3 of its 4 hits land)
    agent.target, agent.enemy_hits = 1, {1: 3}
    assert not agent.protecting(w, me)
    # without a clock, only damage counts
    w.t = 59.0
    me.hp = me.spec.hit_points
    assert not Agent(random.Random(0), "normal").protecting(w, me)


def test_a_damaged_agent_that_leads_retreats_out_of_sight_instead_of_attacking():
    w = lead_world(1, 0, hp=50.0)                        # the enemy's gun points away (+z)
    agent = Agent(random.Random(5), "normal", match_seconds=60.0)
    enemy = w.tanks[1]
    states, fired = run(agent, w, 6.0)
    assert "hide" in states and "attack" not in states and not fired
    me = w.tanks[0]
    gx, gz = agent.hide_goal
    assert w.walls.blocked(enemy.x, enemy.z, gx, gz)     # the spot is out of its sight
    assert math.hypot(me.x - gx, me.z - gz) < math.hypot(45.0 - gx, 30.0 - gz) - 5.0  # on the way there


def test_the_same_agent_attacks_when_level_or_cornered():
    # level on the score: it fights
    w = lead_world(1, 1, hp=50.0)
    states, fired = run(Agent(random.Random(5), "normal", match_seconds=60.0), w, 3.0)
    assert "attack" in states and fired
    # leading, but the enemy's gun points at it: turning away would give free shots
    w = lead_world(1, 0, hp=50.0, enemy_heading=-math.pi / 2)
    states, fired = run(Agent(random.Random(5), "normal", match_seconds=60.0), w, 3.0)
    assert "attack" in states and "hide" not in states and fired


def test_hits_seen_land_are_counted_on_the_target_and_forgotten_at_its_death():
    w = lead_world(0, 0, hp=100.0)
    me = w.tanks[0]
    agent = Agent(random.Random(0), "normal")
    agent.target = 1
    me.hits = 2
    agent._score(me)
    assert agent.enemy_hits == {1: 2}
    me.hits, me.kills = 4, 1
    agent._score(me)
    assert agent.enemy_hits == {}


# ------------------------------------------------------------------ hiding
def test_the_hide_spot_is_out_of_the_threats_sight():
    w = box_world([(50.0, 35.0)])
    agent = Agent(random.Random(0), "normal")
    agent(w, w.tanks[0])
    spot = agent.hide_spot(w.tanks[0], [(30.0, 35.0)])
    assert spot is not None and agent.hide_exposure == pytest.approx(0.0)
    assert w.walls.blocked(30.0, 35.0, spot[0], spot[1])
