"""The yardstick opponents (sim/agents/robots.py) and the ladder's Elo fit
(bench/ladder.py), on short runs."""

from __future__ import annotations

import importlib.util
import math
import random
from pathlib import Path

import pytest
from sim_fixtures import box_world

from tanktool.sim.agents import Agent
from tanktool.sim.agents.robots import YARDSTICKS, Camper, Novice, Robot
from tanktool.sim.commands import IDLE, Command
from tanktool.sim.match import load_match_arena, load_tank_spec
from tanktool.sim.world import World

ROOT = Path(__file__).resolve().parent.parent


def _ladder():
    spec = importlib.util.spec_from_file_location("ladder", ROOT / "bench" / "ladder.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)  # type: ignore[union-attr]
    return mod


def _maze_world(seed: int = 0) -> World:
    arena, spec = load_match_arena("maze"), load_tank_spec("light")
    return World(arena.walls, [spec, spec], arena.spawns, seed=seed, bounds=arena.bounds)


def test_the_robot_drives_to_an_enemy_it_cannot_see_and_fires_only_in_sight():
    """It knows where the enemy is: across the maze, corner to corner, it gets it in
    sight and kills it; no shot is fired without a line of sight."""
    w = _maze_world()
    w.tanks[0].place(5.65, 5.65, 0.785)
    w.tanks[1].place(98.26, 98.26, -2.356)
    robot = Robot(random.Random(1))
    blind_shots = 0
    for _ in range(int(90.0 / w.dt)):
        me, other = w.tanks
        sees = not w.walls.blocked(me.x, me.z, other.x, other.z)
        for e in w.step(None, [robot(w, me), IDLE]):
            if e.kind == "shot" and not sees:
                blind_shots += 1
        if w.tanks[0].kills:
            break
    assert w.tanks[0].kills == 1 and blind_shots == 0
    assert w.tanks[0].wall_bumps <= 2


def test_the_robot_strafes_away_from_a_shell_coming_at_it():
    w = box_world([(20.0, 45.0), (60.0, 47.0)], headings=[0.0, math.pi])   # the thin wall is at x=60, z 20..50
    w.tanks[1].place(80.0, 70.0, math.pi)
    shooter, robot_tank = w.tanks
    robot_tank.place(50.0, 75.0, -math.pi / 2)         # facing away, right of the shell's line
    shooter.place(50.0, 35.0, math.pi / 2)
    w.protected_until = [-math.inf, -math.inf]
    robot = Robot(random.Random(0))
    x0 = robot_tank.x
    w.step(None, [Command(fire=True), IDLE])
    assert w.shells
    for _ in range(90):
        w.step(None, [IDLE, robot(w, robot_tank)])
    # the shell flies up +z at x = 50: the robot strafed off that line
    assert abs(robot_tank.x - x0) > 0.3


def test_the_camper_holds_a_spot_near_its_spawn_and_turns_to_a_shot_it_hears():
    w = _maze_world(seed=3)
    camper = Camper(random.Random(2))
    me = w.tanks[0]
    sx, sz = me.x, me.z
    for _ in range(int(25.0 / w.dt)):
        w.step(None, [camper(w, me), IDLE])
    spot = camper.spot
    assert spot is not None and math.hypot(spot[0] - sx, spot[1] - sz) <= camper.near + 5.0
    assert math.hypot(me.x - spot[0], me.z - spot[1]) < 3.5 and me.speed() < 0.5
    # a shot from behind it, through walls: it turns to face it and does not leave its spot
    other = w.tanks[1]
    other.place(me.x - 30.0 * me.c, me.z - 30.0 * me.s, 0.0)
    other.reload = 0.0
    w.protected_until[1] = -math.inf
    w.step(None, [camper(w, me), Command(fire=True)])
    bearing = math.atan2(other.z - me.z, other.x - me.x)
    best = math.inf
    for _ in range(int(3.0 / w.dt)):
        w.step(None, [camper(w, me), IDLE])
        best = min(best, abs(math.remainder(bearing - me.heading, 2 * math.pi)))
    assert best < 0.6             # the heard place is noisy: 15 % of the distance
    assert math.hypot(me.x - spot[0], me.z - spot[1]) < 3.5


def test_the_novice_reacts_late_aims_badly_and_does_not_lead():
    w = box_world([(20.0, 10.0), (50.0, 10.0)], headings=[0.0, math.pi])
    novice = Novice(random.Random(4))
    w.protected_until = [-math.inf, -math.inf]
    first = None
    for _ in range(int(3.0 / w.dt)):
        for e in w.step(None, [novice(w, w.tanks[0]), IDLE]):
            if e.kind == "shot" and first is None:
                first = e.t
    assert first is not None and first >= 0.4                  # its reaction time
    # a target crossing at speed: without lead it misses where the hard agent hits
    def crossing(driver, seed):
        w = box_world([(20.0, 10.0), (50.0, 30.0)], headings=[0.0, -math.pi / 2], seed=seed)
        w.protected_until = [-math.inf, -math.inf]
        for _ in range(int(8.0 / w.dt)):
            t = w.tanks[1]
            cross = Command(advance=1.0 if t.z > 40.0 or t.z < 20.0 else 0.6)
            if t.z > 80.0:
                t.place(50.0, 30.0, -math.pi / 2)
            w.step(None, [driver(w, w.tanks[0]), Command(advance=1.0, rotate=0.0) if t.z > 5 else cross])
        return w.tanks[0].hits / max(w.tanks[0].shots, 1)
    assert crossing(Novice(random.Random(5)), 1) <= crossing(Agent(random.Random(5), "hard"), 1)


def test_yardsticks_are_drivers_with_their_own_seeded_generators():
    for name, make in YARDSTICKS.items():
        a, b = _maze_world(), _maze_world()
        da, db = make(random.Random(7)), make(random.Random(7))
        for _ in range(240):
            a.step(None, [da(a, a.tanks[0]), IDLE])
            b.step(None, [db(b, b.tanks[0]), IDLE])
        assert a.state() == b.state(), name


def test_elo_fit_orders_players_and_matches_the_expected_score():
    lad = _ladder()
    games = [(0, 1, 1.0)] * 70 + [(0, 1, 0.0)] * 30 + [(1, 2, 1.0)] * 70 + [(1, 2, 0.0)] * 30
    r = lad.fit_elo(["a", "b", "c"], games, prior=0.0)
    assert r[0] > r[1] > r[2] and abs(r.mean() - 1500.0) < 1e-6
    # a 70 % score is 147 Elo
    assert r[0] - r[1] == pytest.approx(400 * math.log10(0.7 / 0.3), abs=2.0)
    # a clean sweep stays finite with the prior
    r = lad.fit_elo(["a", "b"], [(0, 1, 1.0)] * 10)
    assert math.isfinite(r[0]) and r[0] > r[1]


def test_a_short_ladder_runs_and_reports_its_goals(capsys):
    lad = _ladder()
    assert lad.main(["--duels", "1", "--seconds", "4", "--arenas", "box", "--players", "novice,easy,robot",
                     "--boot", "5", "--json"]) == 0
    import json

    out = json.loads(capsys.readouterr().out)
    assert {c["a"] + "-" + c["b"] for c in out["cells"]} == {"novice-easy", "novice-robot", "easy-robot"}
    assert [g for g in out["goals"] if g["goal"].startswith("novice wins")]
    assert all(r["lo"] <= r["elo"] <= r["hi"] for r in out["elo"])
