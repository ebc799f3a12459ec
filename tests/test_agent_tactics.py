"""Computer opponents (issue 7): hearing engines, watching from a vantage point in an
open arena, what the agent does after a kill, ambushing while it leads, returning fire."""

import dataclasses
import math
import random

import pytest

from bot_helpers import driver, happen, perceiver, view_of
from sim_fixtures import ROOT, box_world
from tanktool.bots import Senses
from tanktool.sim.agents import Agent
from tanktool.sim.agents.agent import GUARDS
from tanktool.sim.agents.combat import RETURN_FIRE
from tanktool.sim.agents.explore import STALE, SWEEP, WATCH_COVER, WATCH_STINT
from tanktool.sim.agents.sight import vantages_for
from tanktool.sim.agents.perception import ENGINE_FULL, ENGINE_QUIET, Percept, Sighting, can_see
from tanktool.sim.commands import IDLE
from tanktool.sim.match import load_match_arena, load_tank_spec
from tanktool.sim.world import World


# ------------------------------------------------------------------ hearing engines
def test_an_engine_is_heard_through_a_wall_within_the_radius_and_not_beyond():
    # me at x=50, the thin wall x=60 between me and a tank 20 m away; another 60 m away
    w = box_world([(50.0, 35.0), (70.0, 35.0), (110.0, 35.0)])
    me, near, far = w.tanks
    assert w.walls.blocked(me.x, me.z, near.x, near.z)
    eyes = perceiver(w, 0, Senses(math.radians(60), 90.0, 80.0, engine_radius=35.0), seed=2)
    # standing still: not heard
    assert eyes.listen_engines(w, me) == ()
    # moving fast: heard through the wall, roughly where it is
    near.vx = ENGINE_FULL
    view = eyes.view(w, random.Random(0))
    assert len(view.engines) == 1 and view.engines[0].engine
    heard = view.engines[0]
    assert math.hypot(heard.x - near.x, heard.z - near.z) < 4 * 0.15 * 20.0
    assert view.memory.heard is heard                  # remembered as the last thing heard
    # only the far one moving: 60 m is beyond the 35 m radius
    near.vx, far.vx = 0.0, ENGINE_FULL
    assert eyes.listen_engines(w, me) == ()
    # a dead tank makes no noise
    near.vx, near.alive = ENGINE_FULL, False
    assert eyes.listen_engines(w, me) == ()
    # no engine hearing at all with radius 0
    near.alive = True
    assert perceiver(w, 0, Senses(engine_radius=0.0)).listen_engines(w, me) == ()


def test_a_faster_engine_is_heard_farther():
    w = box_world([(20.0, 20.0), (50.0, 20.0)])
    me, o = w.tanks
    eyes = perceiver(w, 0, Senses(math.radians(60), 90.0, 80.0, engine_radius=40.0), seed=4)
    o.vx = ENGINE_QUIET + 0.1                 # crawling: heard over about half the radius
    assert eyes.listen_engines(w, me) == ()               # 30 m
    o.place(35.0, 20.0, 0.0)
    o.vx = ENGINE_QUIET + 0.1
    assert eyes.listen_engines(w, me) != ()               # 15 m
    o.place(50.0, 20.0, 0.0)
    o.vx = ENGINE_FULL                                    # full speed: 30 m < 40 m
    assert eyes.listen_engines(w, me) != ()


def _no_wait():
    """Normal without lying in wait (both levels wait now): a level that goes looking."""
    from tanktool.sim.agents.difficulty import DIFFICULTIES

    return dataclasses.replace(DIFFICULTIES["normal"], name="no-wait", wait=False)


def test_an_agent_goes_towards_an_engine_it_hears():
    w = box_world([(50.0, 35.0), (75.0, 35.0)], headings=[math.pi, 0.0])
    agent = driver(Agent(_no_wait()), 1)
    me, o = w.tanks
    o.vx = ENGINE_FULL
    agent(w, me)
    assert agent.bot.state == "search"
    gx, gz = agent.bot.machine.states["search"].plan.goals[0]
    assert math.hypot(gx - o.x, gz - o.z) < 15.0


# ------------------------------------------------------------------ watching
def bundled(name, n=1):
    arena = load_match_arena(ROOT / "arenas" / name)
    spec = load_tank_spec(ROOT / "vehicles" / "light")
    return World(arena.walls, [spec] * n, arena.spawns, seed=3, bounds=arena.bounds)


def alone(name, seed):
    """A bundled arena, our agent's tank and an enemy dead for good (until placed)."""
    w = bundled(name, 2)
    me, enemy = w.tanks
    enemy.alive, enemy.respawn_at = False, math.inf
    agent = driver(Agent("normal"), seed)
    agent.bot.memory.met = True      # it has met the enemy before: a watch is worth holding
    return w, me, enemy, agent


def drive(w, agent, me, seconds):
    for _ in range(int(seconds / w.dt)):
        w.step(None, [agent(w, me), IDLE])


def set_up(w):
    """An agent (its driver made it look once: its map is set up) and its driver."""
    drv = driver(Agent("normal"), 0)
    drv(w, w.tanks[0])
    return drv.bot, drv


def test_vantage_cover_counts_the_blocks_in_the_cone_and_in_sight():
    w = bundled("paper2002")
    agent, _ = set_up(w)
    views, v = agent.nav.views, agent.nav.vantages
    assert v is vantages_for(views, agent.senses.half_angle, agent.senses.vision_range)    # cached
    rng = random.Random(1)
    for _ in range(20):
        b, k = rng.randrange(len(views)), rng.randrange(len(v.headings))
        bx, bz = views.points[b]
        n = 0
        for c, (cx, cz) in enumerate(views.points):
            off = abs(math.remainder(math.atan2(cz - bz, cx - bx) - v.headings[k], 2 * math.pi))
            if c == b or off <= agent.senses.half_angle - 0.1 and views.visible[b, c] \
                    and math.hypot(cx - bx, cz - bz) <= agent.senses.vision_range:
                n += 1
        assert v.cover[b, k] == pytest.approx(n / len(views))


def test_open_arenas_have_a_vantage_and_the_maze_has_none():
    box, maze = set_up(bundled("box"))[0].nav, set_up(bundled("maze"))[0].nav
    assert box.vantages.top >= 0.7 > WATCH_COVER > maze.vantages.top
    # in the open box the best place is a corner, facing along the diagonal
    b, face = box.vantages.best(box.views.cell_at(30.0, 30.0), 0.0)
    x, z = box.views.points[b]
    assert min(x, 60 - x) < 10 and min(z, 60 - z) < 10
    assert abs(math.remainder(face - math.atan2(30.0 - z, 30.0 - x), 2 * math.pi)) < 0.3


def test_alone_in_the_box_an_agent_holds_a_vantage_and_sweeps_its_cone():
    w, me, _, agent = alone("box", 2)
    headings = []
    for k in range(int(20.0 / w.dt)):
        w.step(None, [agent(w, me), IDLE])
        if w.t > 12.0:
            headings.append(me.heading)
            assert agent.bot.state == "watch"
    gx, gz = agent.bot.machine.states["watch"].spot
    assert math.hypot(me.x - gx, me.z - gz) < 3.0 and me.wall_bumps == 0
    swing = max(headings) - min(headings)
    assert 0.4 < swing < 2 * SWEEP + 0.4                  # it sweeps, about the vantage's way


def test_until_a_first_contact_it_goes_looking_instead_of_watching():
    """Nobody seen or heard yet: a corner that sees the whole box is no place to wait
    (two watchers draw); after FIRST_CONTACT_PATIENCE it explores, and keeps exploring."""
    w, me, _, agent = alone("box", 2)
    agent.bot.memory.met = False
    watching = 0
    for k in range(int(12.0 / w.dt)):
        w.step(None, [agent(w, me), IDLE])
        watching += w.t > 4.0 and agent.bot.state == "watch"
    assert watching == 0 and me.distance > 20.0 and not agent.bot.memory.met


def test_the_first_demo_fights(tmp_path):
    """play --headless --seconds 10 --bots 2 with the default seed: both bots go out,
    meet and shoot (issue 30's first demo; it stood still and silent before)."""
    import json

    from click.testing import CliRunner

    from tanktool.cli.main import cli

    out = tmp_path / "r.json"
    r = CliRunner().invoke(cli, ["play", "--headless", "--seconds", "10", "--bots", "2", "--report", str(out)])
    assert r.exit_code == 0, r.output
    for t in json.loads(out.read_text())["tanks"]:
        assert t["shots"] >= 1 and t["distance"] >= 20.0, t


def test_an_enemy_coming_into_the_watched_box_is_seen_and_attacked():
    w, me, enemy, agent = alone("box", 2)
    drive(w, agent, me, 15.0)
    assert agent.bot.state == "watch"
    # the enemy appears far off, in the watched way (the cone less the sweep)
    cone = agent.senses.half_angle - 0.35
    face = agent.bot.machine.states["watch"].face
    # ... in plain sight from anywhere near by (it moves while it fights)
    near = [(me.x + dx, me.z + dz) for dx in (-4.0, 0.0, 4.0) for dz in (-4.0, 0.0, 4.0)]
    far = [(math.hypot(x - me.x, z - me.z), x, z) for x in range(10, 56, 2) for z in range(10, 56, 2)
           if can_see(w.walls, me.x, me.z, face, x, z, cone, 90.0)
           and not any(w.walls.blocked(nx, nz, x, z) for nx, nz in near)]
    d, ex, ez = max(far)
    assert d > 40.0
    enemy.place(ex, ez, 0.0)
    enemy.alive, enemy.hp = True, enemy.spec.hit_points
    shots, states = me.shots, set()
    for k in range(int(4.0 / w.dt)):
        w.step(None, [agent(w, me), IDLE])
        states.add(agent.bot.state)
    assert "attack" in states and me.shots > shots and enemy.hp < enemy.spec.hit_points


def test_the_watch_gives_way_to_exploring_what_has_gone_unseen():
    w = bundled("paper2002")
    agent, drv = set_up(w)
    watch = agent.machine.states["watch"]
    agent.machine.state, agent.machine.since = watch, 0.0
    agent.memory.met = True
    cov = agent.nav.coverage
    cov.seen[:] = 0.0                          # all seen at t=0

    def update():
        view = view_of(drv, w)
        return watch.update(agent, view, agent.memory.digest(view, agent.level)), view

    w.t = WATCH_STINT + 1.0                   # nothing stale yet: watch on
    assert cov.stale_fraction(w.t) == 0.0 and update()[0] is not None
    w.t = 61.0                                 # all stale: explore, until seen again
    assert cov.stale_fraction(w.t) > STALE
    cmd, view = update()
    assert cmd is None and agent.exploring
    assert not GUARDS["vantage"](agent, view, None)        # no watching while it is stale
    cov.seen[:] = w.t
    assert GUARDS["vantage"](agent, view, None) and not agent.exploring


# ------------------------------------------------------------------ after a kill
def test_after_a_kill_it_forgets_the_dead_enemy_and_does_not_search_for_it():
    w = box_world([(50.0, 35.0), (55.0, 70.0), (100.0, 80.0)])
    me = w.tanks[0]
    drv = driver(Agent("normal"), 0)
    drv(w, me)
    agent = drv.bot
    agent.memory.target = 1
    agent.machine.state = agent.machine.states["attack"]
    drv.perceiver.memory.last_seen[1] = Sighting(1, 55.0, 70.0, 0.0, 0.0, w.t, 35.0)
    me.kills = 1
    w.tanks[1].alive = False
    happen(w, ("kill", 0, 1))
    drv.next_think = -math.inf
    drv(w, me)
    assert 1 not in agent.memory.last_seen and agent.memory.killed_at == w.t
    assert agent.state == "ambush"                 # 1 kill, 0 deaths: it leads
    # a kill in the kill feed (tank 2 killed tank 1) forgets it too: it respawns
    # elsewhere; but it was not our kill
    drv.perceiver.memory.last_seen[1] = Sighting(1, 55.0, 70.0, 0.0, 0.0, w.t, 35.0)
    killed_at = agent.memory.killed_at
    happen(w, ("kill", 2, 1), dt=1.0)
    drv.next_think = -math.inf
    drv(w, me)
    assert 1 not in agent.memory.last_seen and agent.memory.killed_at == killed_at


# ------------------------------------------------------------------ ambush while leading
def test_safety_is_the_share_of_the_blocks_seeing_a_block_that_its_cone_sees():
    w = bundled("maze")
    agent, _ = set_up(w)
    views, v = agent.nav.views, agent.nav.vantages
    half, rng_ = agent.senses.half_angle, agent.senses.vision_range
    rng = random.Random(3)
    for _ in range(15):
        b = rng.randrange(len(views))
        bx, bz = views.points[b]
        watchers = [c for c in range(len(views)) if views.visible[b, c]]
        best = 0.0
        for h in v.headings:
            n = sum(1 for c in watchers
                    if c == b or abs(math.remainder(math.atan2(views.points[c][1] - bz, views.points[c][0] - bx) - h,
                                                    2 * math.pi)) <= half - 0.1
                    and math.hypot(views.points[c][0] - bx, views.points[c][1] - bz) <= rng_)
            best = max(best, n / len(watchers))
        assert v.safety[b] == pytest.approx(best)
    # the maze has dead ends that nothing sees into without being seen; a corridor
    # crossing is seen from several ways at once
    assert (v.safety >= 0.95).sum() >= 10
    assert v.safety[views.cell_at(52.0, 59.0)] < 0.8


def test_a_leading_agent_ambushes_from_a_safe_place_even_in_the_maze():
    w, me, enemy, drv = alone("maze", 4)
    agent = drv.bot
    drive(w, drv, me, 5.0)
    assert agent.state == "wander"             # no vantage in the maze, and not leading
    me.kills = 1                               # now it leads (1 kill, 0 deaths)
    drive(w, drv, me, 25.0)
    ambush = agent.machine.states["ambush"]
    views = agent.nav.views
    assert agent.state == "ambush" and me.wall_bumps == 0
    spot = views.cell_at(*ambush.spot)
    assert agent.nav.vantages.safety[spot] >= 0.9
    assert math.hypot(me.x - ambush.spot[0], me.z - ambush.spot[1]) < 3.0
    # an engine heard: it does not go looking, it moves away from the noise and turns
    # to face the way the noise would come in
    here = views.cell_at(me.x, me.z)
    ex, ez = next((float(x), float(z)) for x, z in views.points
                  if 12.0 < math.hypot(x - me.x, z - me.z) < 20.0
                  and w.walls.blocked(me.x, me.z, float(x), float(z)))
    enemy.place(ex, ez, 0.0)
    enemy.alive, enemy.vx = True, 8.0
    heard_block = views.cell_at(ex, ez)
    ambush.chosen = -math.inf
    for k in range(int(1.0 / w.dt)):
        enemy.vx, enemy.vz = 8.0, 0.0
        w.step(None, [drv(w, me), IDLE])
        assert agent.state == "ambush"
    assert ambush.faced is not None
    far = views.path_distances(heard_block)
    assert far[views.cell_at(*ambush.spot)] >= min(far[here], 80.0)


def test_hit_by_a_tank_it_cannot_see_it_turns_to_face_the_shot():
    # the shooter 30 m behind, in the open: heard, not seen
    w = box_world([(75.0, 82.0), (45.0, 82.0)], headings=[0.0, 0.0])
    me, shooter = w.tanks
    drv = driver(Agent("normal", watch=False), 7)
    drv(w, me)
    assert 1 not in drv.perceiver.memory.last_seen
    me.hp -= 25.0
    happen(w, ("shot", 1, -1), ("hit", 1, 0, 25.0), dt=0.1)
    drv.next_think = -math.inf
    drv(w, me)
    back = drv.bot.machine.states["return_fire"]
    assert drv.bot.state == "return_fire"
    assert back.until == pytest.approx(w.t + RETURN_FIRE)
    assert abs(math.remainder(back.face - math.pi, 2 * math.pi)) < 0.3
    states = set()
    for k in range(int(RETURN_FIRE / w.dt)):
        w.step(None, [drv(w, me), IDLE])
        states.add(drv.bot.state)
    assert "attack" in states and 1 in drv.perceiver.memory.last_seen
    # a shot heard from behind a wall is not returned
    w2 = box_world([(70.0, 35.0), (45.0, 35.0)], headings=[0.0, 0.0])
    d2 = driver(Agent("normal", watch=False), 7)
    d2(w2, w2.tanks[0])
    w2.tanks[0].hp -= 25.0
    happen(w2, ("shot", 1, -1), ("hit", 1, 0, 25.0), dt=0.1)
    d2.next_think = -math.inf
    d2(w2, w2.tanks[0])
    assert d2.bot.state != "return_fire"


def test_an_engine_heard_close_behind_in_the_open_is_faced_once_not_behind_a_wall():
    # the enemy drives 20 m behind us in the open: out of the cone, its engine heard
    w = box_world([(75.0, 82.0), (55.0, 82.0)], headings=[0.0, 0.0])
    me, other = w.tanks
    drv = driver(Agent("hard", watch=False), 3)
    states = []
    for _ in range(int(2.0 / w.dt)):
        other.vx = 6.0 * math.cos(w.t)
        other.vz = 6.0 * math.sin(w.t)
        w.step(None, [drv(w, me), IDLE])
        states.append(drv.bot.state)
    assert "return_fire" in states and math.isfinite(drv.bot.memory.faced_at)
    # once: turned to it, not again within FACED s
    starts = [k for k in range(len(states)) if states[k] == "return_fire" != (states[k - 1] if k else None)]
    assert len(starts) == 1
    # behind the thin wall x = 60 (z 20-50): not turned to
    w2 = box_world([(70.0, 35.0), (50.0, 35.0)], headings=[0.0, 0.0])
    d2 = driver(Agent("hard", watch=False), 3)
    for _ in range(int(2.0 / w2.dt)):
        w2.tanks[1].vx = 6.0
        w2.step(None, [d2(w2, w2.tanks[0]), IDLE])
        assert d2.bot.state != "return_fire"


def test_only_a_level_that_scoots_goes_back_to_cover_while_reloading(monkeypatch):
    """A level with ``scoot`` shuttles behind the corner it came round while its gun
    reloads; normal and hard (``scoot`` False: no level scoots) keep strafing."""
    import dataclasses

    from tanktool.sim.agents import combat
    from tanktool.sim.agents.difficulty import DIFFICULTIES

    assert not DIFFICULTIES["normal"].scoot and not DIFFICULTIES["hard"].scoot
    scooter = dataclasses.replace(DIFFICULTIES["normal"], name="scooter", scoot=True)
    asked = []

    def corner(agent, view, s):
        asked.append(agent.level.name)
        return view.me.x - 5.0, view.me.z

    monkeypatch.setattr(combat, "cover_behind", corner)
    for level in (scooter, "normal", "hard"):
        w = box_world([(20.0, 10.0), (50.0, 10.0)])
        me = w.tanks[0]
        drv = driver(Agent(level), 2)
        drv(w, me)
        me.reload = combat.SCOOT + 0.5                      # just fired
        s = Sighting(1, 50.0, 10.0, 0.0, 0.0, w.t, 30.0, heading=math.pi)
        p = Percept(w.t, s, True, None, None, False, (), False, False)
        cmd = drv.bot.machine.states["attack"].update(drv.bot, view_of(drv, w), p)
        assert not cmd.fire
    assert asked == ["scooter"]


# ------------------------------------------------------------------ hunting a camper
def _hunting(w, camp):
    """Our normal agent (tank 0) remembering an enemy (tank 1, dead for good) camping
    at ``camp``, hunting it."""
    me, enemy = w.tanks
    enemy.alive, enemy.respawn_at = False, math.inf
    drv = driver(Agent("normal"), 0)
    drv(w, me)
    agent = drv.bot
    agent.memory.met = True
    agent.memory.camps[1] = (camp[0], camp[1], w.t, math.pi)
    drv.next_think = -math.inf
    drv(w, me)
    return agent, drv


def test_a_hunt_ends_when_the_camp_is_in_its_cone_and_sight_and_nobody_is_there():
    # the camp 40 m ahead in the open box (past the end of the L): an enemy there would be seen, it has gone
    w = box_world([(20.0, 70.0), (100.0, 10.0)])
    agent, drv = _hunting(w, (60.0, 85.0))
    # it went hunting, looked, and gave it up in the same think
    assert ("camp_known", "hunt") in [(when, to) for _, _, when, to in agent.machine.trace]
    assert 1 not in agent.memory.camps and agent.state != "hunt"


def test_a_hunt_that_comes_no_nearer_goes_for_the_camp_itself_then_gives_up():
    # the camp behind the thin wall x=60; the tank held where it is (as on a hillside it
    # could not climb): after HUNT_STALL s it takes the way to the camp itself, and
    # when that comes no nearer either, gives it up
    from tanktool.sim.agents.combat import HUNT_STALL

    w = box_world([(40.0, 35.0), (100.0, 10.0)], headings=[math.pi])
    agent, drv = _hunting(w, (80.0, 35.0))
    assert agent.state == "hunt"
    me = w.tanks[0]
    hunted = 0.0
    closing = False
    for _ in range(int((2 * HUNT_STALL + 2.0) / w.dt)):
        cmd = drv(w, me)
        w.step(None, [cmd, IDLE])
        om = me.omega
        me.place(40.0, 35.0, me.heading)           # it cannot get anywhere, but turns
        me.omega = om
        hunted += w.dt * (agent.state == "hunt")
        closing = closing or agent.machine.states["hunt"].closing
        if agent.state != "hunt":
            break
    assert 1 not in agent.memory.camps and agent.state != "hunt", (hunted, agent.state, agent.machine.trace)
    assert hunted >= HUNT_STALL


# ------------------------------------------------------------------ lying in wait
def test_an_enemy_heard_coming_behind_cover_is_waited_for_with_the_gun_on_the_corner():
    # the enemy's engine behind the thin wall x=60 (z 20-50), nearer its north end: hard
    # stands, turned from facing away to that end, where the enemy's way round comes
    # past; a level that does not lie in wait goes looking
    from tanktool.sim.agents.combat import WAIT

    w = box_world([(50.0, 35.0), (75.0, 44.0)], headings=[math.pi, 0.0])
    me, o = w.tanks
    agent = driver(Agent("hard"), 1)
    o.vx = ENGINE_FULL
    agent(w, me)
    assert agent.bot.state == "lie_in_wait"
    end = math.atan2(52.0 - me.z, 60.0 - me.x)      # the nearer end of the wall
    for _ in range(int(0.75 * WAIT / w.dt)):
        o.vx = ENGINE_FULL                      # still heard coming
        w.step(None, [agent(w, me), IDLE])
        o.place(75.0, 44.0, 0.0)
    assert agent.bot.state == "lie_in_wait"
    assert me.speed() < 1.0
    assert abs(math.remainder(me.heading - end, 2 * math.pi)) < 0.35
    for _ in range(int(0.5 * WAIT / w.dt)):       # it does not come: search from the noise
        w.step(None, [agent(w, me), IDLE])
    assert agent.bot.state == "search"
    normal = driver(Agent(_no_wait()), 1)
    w2 = box_world([(50.0, 35.0), (75.0, 44.0)], headings=[math.pi, 0.0])
    w2.tanks[1].vx = ENGINE_FULL
    normal(w2, w2.tanks[0])
    assert normal.bot.state == "search"


# ------------------------------------------------------------------ outgunned on relief
def test_hard_breaks_off_when_no_shot_of_its_carries_and_it_is_hit():
    from tanktool.sim.agents.combat import OUTGUNNED

    guard = GUARDS["outgunned"]
    for level, expected in (("hard", True), ("normal", False)):
        w = box_world([(20.0, 10.0), (50.0, 10.0)])
        drv = driver(Agent(level), 2)
        drv(w, w.tanks[0])
        agent, view = drv.bot, view_of(drv, w)
        t = view.t + 10.0
        s = Sighting(1, 50.0, 10.0, 0.0, 0.0, t, 30.0, heading=math.pi)
        attack = agent.machine.states["attack"]
        attack.blind_since = t - OUTGUNNED - 0.1            # no shot carried for that long

        def percept(hits):
            return Percept(t, s, True, None, None, bool(hits), tuple(hits), False, False)

        assert bool(guard(agent, view, percept([t - 0.5]))) is expected
        assert not guard(agent, view, percept([]))                          # not hit: drive on
        assert not guard(agent, view, percept([t - OUTGUNNED - 1.0]))     # hit before, not since
        attack.blind_since = t - 0.5                                          # not long enough
        assert not guard(agent, view, percept([t - 0.2]))
