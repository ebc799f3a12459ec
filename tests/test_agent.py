"""Computer opponents (issue 7): sight, the paper's decision, search order, finding and
fighting, wall bumps, determinism."""

import math
import random

import numpy as np
import pytest

from bot_helpers import driver, happen, perceiver, view_of
from sim_fixtures import box_world
from tanktool.bots import Senses
from tanktool.nav.navgrid import grid_from_mask
from tanktool.nav.steering import choose_next, heading_of_move
from tanktool.sim.agents import DIFFICULTIES, Agent, difficulty, make_agents
from tanktool.sim.agents.navigation import Memory, SearchPlan, Wanderer, agent_grid, search_order
from tanktool.sim.agents.perception import can_see, in_cone
from tanktool.sim.commands import IDLE, Command
from tanktool.sim.match import load_match_arena, load_tank_spec, run_match
from tanktool.sim.world import World


# ------------------------------------------------------------------ perception
def test_visibility_behind_a_wall_outside_the_cone_and_in_plain_sight():
    w = box_world([(40.0, 35.0), (80.0, 35.0), (52.0, 35.0), (40.0, 55.0)])
    walls = w.walls
    half, rng = math.radians(60), 100.0
    # behind the thin wall x = 60: in the cone and in range, but the line crosses the wall
    assert in_cone(40, 35, 0.0, 80, 35, half, rng)
    assert not can_see(walls, 40, 35, 0.0, 80, 35, half, rng)
    # in plain sight ahead
    assert can_see(walls, 40, 35, 0.0, 52, 35, half, rng)
    # 90 degrees to the side: outside the cone, though nothing is in between
    assert not walls.blocked(40, 35, 40, 55)
    assert not can_see(walls, 40, 35, 0.0, 40, 55, half, rng)
    # the cone's edge: 59 degrees seen, 61 not
    for deg, seen in ((59.0, True), (61.0, False)):
        a = math.radians(deg)
        assert can_see(walls, 40, 35, 0.0, 40 + 10 * math.cos(a), 35 + 10 * math.sin(a), half, rng) is seen
    # range
    assert not can_see(walls, 40, 35, 0.0, 52, 35, half, 10.0)
    # the view shows exactly the tank in plain sight, and remembers it
    eyes = perceiver(w, 0, Senses(half, rng, 80.0))
    view = eyes.view(w, random.Random(0))
    assert [s.index for s in view.seen] == [2]
    assert view.memory.last_seen[2].x == pytest.approx(w.tanks[2].x)


def test_hearing_reveals_a_shot_roughly_and_only_within_the_radius():
    w = box_world([(20.0, 20.0), (50.0, 20.0), (110.0, 80.0)], headings=[0.0, math.pi, math.pi])
    eyes = perceiver(w, 0, Senses(math.radians(60), 90.0, 60.0))
    happen(w, ("shot", 1, -1), ("shot", 2, -1))  # a shot 30 m away, and one 108 m away (beyond 60 m)
    eyes.collect(w)
    view = eyes.view(w, random.Random(0))
    assert len(view.heard) == 1 and not view.heard[0].engine
    heard = view.heard[0]
    assert math.hypot(heard.x - 50.0, heard.z - 20.0) < 4 * 0.15 * 30.0
    assert view.memory.heard is heard and view.events == ()     # others' shots are heard, not events
    assert eyes.view(w, random.Random(0)).heard == ()           # nothing new
    happen(w, ("shot", 2, -1))
    eyes.collect(w)
    assert eyes.view(w, random.Random(0)).heard == ()           # too far to hear


# ------------------------------------------------------------------ the paper's decision
def mask(text):
    return np.array([[c != "#" for c in line.strip()] for line in text.strip().splitlines()])


PAPER_FIGURE = """
    ###############
    ######.########
    ######G########
    ####..........#
    ######.########
    ###############
"""


def test_wander_decision_picks_the_papers_child():
    """nav.steering's grid shaped like the paper's figure: from the grey node heading
    down (-z), HIJO 1 (ahead-right, leading along the row of 10) is chosen, and the
    agent turns right (+x).  Without memory or jitter the wanderer is the paper's tree;
    with an empty memory (everything new) it still is."""
    g = grid_from_mask(mask(PAPER_FIGURE)[::-1])
    node, heading = (3, 6), "-z"
    assert Wanderer(g).choose(node, heading) == ((2, 7), "+x")
    fresh = Wanderer(g, Memory(g), rng=None)
    assert fresh.choose(node, heading, t=0.0) == ((2, 7), "+x")


def test_wander_decision_equals_choose_next_without_memory():
    rng = np.random.default_rng(4)
    valid = rng.random((30, 40)) < 0.75
    valid[0], valid[-1], valid[:, 0], valid[:, -1] = False, False, False, False
    g = grid_from_mask(valid)
    w = Wanderer(g)
    for i, j in zip(*np.nonzero(valid)):
        for h in ("+x", "+z", "-x", "-z"):
            got = w.choose((int(i), int(j)), h)
            want = choose_next(g, (int(i), int(j)), h)
            assert (got[0] if got else None) == want
            if got:
                assert got[1] == heading_of_move((int(i), int(j)), want, h)


def test_memory_steers_away_from_where_it_has_just_been():
    """A crossroads: straight ahead leads to a region just visited, the right turn to
    one never seen; the wanderer with memory turns right, the paper's tree goes on."""
    g = grid_from_mask(np.ones((41, 41), bool) & ~np.pad(np.zeros((39, 39), bool), 1, constant_values=True))
    mem = Memory(g, region=8.0)
    node, heading = (20, 20), "+x"
    x, z = g.centre(20, 20 + 13)
    mem.visit(x, z, t=100.0)
    assert Wanderer(g).choose(node, heading)[1] == "+x"
    assert Wanderer(g, mem, rng=None, straight=1.0).choose(node, heading, t=101.0)[1] in ("+z", "-z")


# ------------------------------------------------------------------ search
def test_quadrant_search_starts_where_the_enemy_was_and_recurses():
    leaves = list(search_order((0.0, 0.0, 100.0, 100.0), 80.0, 10.0, leaf=30.0))
    assert len(leaves) == 16
    # the first leaf holds the estimate; the first four are the sub-quadrants of its quadrant
    x0, z0, x1, z1 = leaves[0]
    assert x0 <= 80 <= x1 and z0 <= 10 <= z1
    assert all(q[0] >= 50 and q[3] <= 50 for q in leaves[:4])
    # every leaf once, covering the square
    assert len(set(leaves)) == 16
    assert sum((q[2] - q[0]) * (q[3] - q[1]) for q in leaves) == pytest.approx(100 * 100)


def test_search_plan_goals_are_valid_reachable_nodes():
    arena = load_match_arena("maze")
    w = World(arena.walls, [load_tank_spec("light")], arena.spawns, seed=0, bounds=arena.bounds)
    g = agent_grid(w, 1.0, w.tanks[0].spec.radius + 0.5)
    plan = SearchPlan(g, 90.0, 90.0)
    assert len(plan.goals) >= 8
    for x, z in plan.goals:
        assert g.is_valid(g.node_of(x, z))
    # the first goal is next to the estimate
    assert math.hypot(plan.goals[0][0] - 90.0, plan.goals[0][1] - 90.0) < 8.0


# ------------------------------------------------------------------ behaviour in worlds
def run(world, drivers, seconds, until=None):
    for _ in range(int(seconds / world.dt)):
        world.step(None, [d(world, t) if d else IDLE for d, t in zip(drivers, world.tanks)])
        if until is not None and until():
            return True
    return False


def test_agent_finds_a_stationary_enemy_in_the_maze():
    """Wandering only (nothing seen or heard): across the maze, from one corner spawn
    to the far corner, within 150 simulated seconds."""
    arena = load_match_arena("maze")
    spec = load_tank_spec("light")
    w = World(arena.walls, [spec, spec], arena.spawns, seed=0, bounds=arena.bounds)
    w.tanks[0].place(5.65, 5.65, 0.785)
    w.tanks[1].place(98.26, 98.26, -2.356)
    agent = driver(Agent("normal"), 1)
    assert run(w, [agent, None], 150.0, until=lambda: 1 in agent.perceiver.memory.last_seen)
    assert w.t < 150.0


def test_agent_shoots_an_enemy_in_plain_sight():
    """The target is under spawn protection for its first 3 s: no shell may reach it
    then (none is shielded); then 4 hits kill it."""
    w = box_world([(20.0, 10.0), (50.0, 14.0)], headings=[0.3, math.pi])
    agent = driver(Agent("normal"), 2)
    events = []
    for _ in range(int(12.0 / w.dt)):
        events += w.step(None, [agent(w, w.tanks[0]), IDLE])
        if not w.tanks[1].alive:
            break
    assert not w.tanks[1].alive and w.tanks[0].kills == 1
    assert w.tanks[0].hits >= 4 and w.tanks[0].shots <= 8
    assert not [e for e in events if e.kind == "shielded"]
    assert min(e.t for e in events if e.kind == "shot") > 3.0 - 60.0 / w.tanks[0].spec.shell_speed
    assert agent.bot.state == "attack"


def test_hit_by_an_unseen_enemy_searches_where_the_shot_came_from():
    w = box_world([(30.0, 10.0), (30.0, 40.0)], headings=[0.0, -math.pi / 2])
    agent = driver(Agent("normal"), 5)
    agent(w, w.tanks[0])
    assert agent.bot.state in ("wander", "watch")
    happen(w, ("shot", 1, -1), dt=0.2)         # heard, 30 m away, 90 degrees to the left
    agent(w, w.tanks[0])
    assert agent.bot.state == "search"
    gx, gz = agent.bot.machine.states["search"].plan.goals[0]
    assert math.hypot(gx - 30.0, gz - 40.0) < 15.0


def test_hit_repeatedly_evades_to_cover_out_of_the_threats_sight():
    # the thin wall x = 60 stands between the threat and us (a shot from a place in
    # sight is turned on instead: tests/test_agent_tactics.py)
    w = box_world([(65.0, 35.0), (20.0, 35.0)], headings=[0.0, 0.0])
    agent = driver(Agent("normal"), 6)
    agent(w, w.tanks[0])
    for k in range(2):                          # two hits, the shooter behind us, unseen
        w.tanks[0].hp -= 25.0
        happen(w, ("shot", 1, -1), ("hit", 1, 0, 25.0), dt=0.5)
        agent(w, w.tanks[0])
    bot = agent.bot
    assert bot.state == "evade"
    cover, threat = bot.path[-1], bot.machine.states["evade"].handoff
    assert w.walls.blocked(threat[0], threat[1], cover[0], cover[1])
    assert bot.machine.trace[-1][2:] == ("ambushed", "evade")


@pytest.mark.parametrize("name", ["box", "maze", "paper2002"])
def test_long_wander_has_few_wall_bumps(name):
    """One agent alone wandering (not watching) for two simulated minutes: at most one bump.
    (Seed 4: on the bot API the agent's random streams differ; over seeds 3-8 on these
    arenas one run of 18 has two bumps, paper2002 seed 3, turning in a dead end.)"""
    arena = load_match_arena(name)
    spec = load_tank_spec("light")
    w = World(arena.walls, [spec], arena.spawns, seed=4, bounds=arena.bounds)
    agent = driver(Agent("normal", watch=False), 4)
    run(w, [agent], 120.0)
    assert w.tanks[0].wall_bumps <= 1
    assert w.tanks[0].distance > 300.0         # and it did drive around


def test_matches_replay_exactly_and_agents_are_the_default_bots():
    arena = load_match_arena("paper2002")
    spec = load_tank_spec("light")
    a = run_match(arena, spec, bots=4, seconds=6, seed=11).report
    b = run_match(arena, spec, bots=4, seconds=6, seed=11).report
    a.pop("timing"), b.pop("timing")
    assert a == b and a["bots"] == "agent" and a["difficulty"] == "normal"
    c = run_match(arena, spec, bots=4, seconds=6, seed=11, bot="scripted").report
    assert c["bots"] == "scripted" and c["difficulty"] is None


def test_difficulty_levels():
    assert set(DIFFICULTIES) == {"easy", "normal", "hard"}
    e, n, h = (DIFFICULTIES[k] for k in ("easy", "normal", "hard"))
    assert e.reaction > n.reaction > h.reaction
    assert e.aim_noise > n.aim_noise > h.aim_noise
    assert e.vision_range < n.vision_range < h.vision_range
    with pytest.raises(ValueError, match="difficulty must be one of"):
        difficulty("godlike")
    w = box_world([(20.0, 10.0), (50.0, 14.0)])
    assert [a.bot.level.name for a in make_agents(w, "hard")] == ["hard", "hard"]


def test_play_cli_difficulty_and_bot_driver(tmp_path):
    import json

    from click.testing import CliRunner

    from tanktool.cli.main import cli

    out = tmp_path / "r.json"
    r = CliRunner().invoke(cli, ["play", "--headless", "--arena", "box", "--bots", "3", "--seconds", "3",
                                 "--difficulty", "hard", "--report", str(out)])
    assert r.exit_code == 0, r.output
    rep = json.loads(out.read_text())
    assert rep["bots"] == "agent" and rep["difficulty"] == "hard"
    r = CliRunner().invoke(cli, ["play", "--headless", "--arena", "box", "--bots", "2", "--seconds", "2",
                                 "--bot-driver", "scripted", "--report", str(out)])
    assert r.exit_code == 0, r.output
    assert json.loads(out.read_text())["bots"] == "scripted"
    r = CliRunner().invoke(cli, ["play", "--headless", "--difficulty", "insane"])
    assert r.exit_code == 2 and "insane" in r.output and "Traceback" not in r.output


def test_held_still_on_a_path_it_backs_out_and_replans():
    """A wall feeler can hold the tank still facing its next waypoint past a corner
    (no push, no turn): after a second of that it backs out and plans again."""
    w = box_world([(30.0, 30.0)])
    drv = driver(Agent("normal"), 0)
    drv(w, w.tanks[0])
    agent = drv.bot
    agent.path = [(40.0, 30.0), (50.0, 30.0)]
    held = Command(advance=0.0, rotate=0.0)
    assert agent.unstick(view_of(drv, w), held) is held
    w.t += 1.2
    out = agent.unstick(view_of(drv, w), held)
    assert out is not held and agent.reverse_until > w.t and agent.path == []
    # turning in place towards the path is not being stuck
    drv = driver(Agent("normal"), 0)
    drv(w, w.tanks[0])
    agent = drv.bot
    agent.path = [(40.0, 30.0)]
    turning = Command(advance=0.0, rotate=1.0)
    agent.unstick(view_of(drv, w), turning)
    w.t += 1.2
    assert agent.unstick(view_of(drv, w), turning) is turning
