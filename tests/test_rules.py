"""Match rules (sim/rules.py): the gun every tank carries, spawn protection, spawns out
of sight, the match end, and how replays keep them."""

from __future__ import annotations

import dataclasses
import json
import math
import statistics

import numpy as np
import pytest
from click.testing import CliRunner
from sim_fixtures import box_arena

from tanktool.cli.main import cli
from tanktool.formats.walls_txt import WallList, aux_rectangle
from tanktool.sim.body import TankSpec
from tanktool.sim.commands import Command
from tanktool.sim.match import load_match_arena, load_tank_spec, run_match, scoreboard
from tanktool.sim.replay import decode, encode, play_replay, record_match
from tanktool.sim.rules import DEFAULT, Rules
from tanktool.sim.world import World

IDLE2 = [Command(), Command()]


def open_field(size: float = 400.0) -> WallList:
    return WallList(np.zeros((0, 2, 2)), np.zeros(0, np.int8), aux_rectangle(0.0, 0.0, size, size))


def duel_world(rules: Rules, gap: float = 40.0, spec: TankSpec | None = None) -> World:
    """Two box tanks ``gap`` m apart on an open field, tank 0 facing tank 1."""
    spec = spec or TankSpec.box("t")
    w = World(open_field(), [spec, spec], [(50.0, 100.0, 0.0), (50.0 + gap, 100.0, math.pi)], seed=1,
              rules=rules, bounds=[[0.0, 0.0], [400.0, 400.0]])
    w.tanks[0].place(50.0, 100.0, 0.0)
    w.tanks[1].place(50.0 + gap, 100.0, math.pi)
    return w


# ------------------------------------------------------------------ the rules object
def test_bad_rules_are_refused_naming_the_rule():
    for bad in (dict(shell_speed=-1.0), dict(shell_speed=math.nan), dict(spread=-0.1), dict(reload=0.0),
                dict(score_limit=0), dict(score_limit=2.5), dict(time_limit=-3.0), dict(shell_range=0.0),
                dict(shell_gravity=0.0, shell_range=math.inf)):
        with pytest.raises(ValueError, match="rules"):
            Rules(**bad)
    with pytest.raises(ValueError, match="unknown rule 'speed'"):
        Rules.from_dict({"speed": 3})


def test_rules_round_trip_through_json():
    for r in (DEFAULT, Rules.classic(), Rules(score_limit=5, time_limit=90.0, damage=30.0)):
        assert Rules.from_dict(json.loads(json.dumps(r.to_dict()))) == r
    assert Rules.classic().to_dict()["shell_range"] is None      # infinite: null in JSON


def test_every_tank_carries_the_rules_gun():
    spec = TankSpec.box("t", shell_speed=500.0, fire_interval=2.0, shell_damage=10.0)
    w = World(box_arena()[0], [spec, spec], box_arena()[1], rules=Rules(shell_speed=42.0, reload=0.5, damage=30.0))
    assert all((t.spec.shell_speed, t.spec.fire_interval, t.spec.shell_damage) == (42.0, 0.5, 30.0) for t in w.tanks)
    assert w.tanks[0].spec is w.tanks[1].spec and spec.shell_speed == 500.0     # the caller's spec untouched
    own = World(box_arena()[0], [spec], box_arena()[1], rules=Rules(shell_speed=None))
    assert own.tanks[0].spec is spec


def test_default_shells_fly_straight_at_the_rule_speed_and_are_spent_at_their_range():
    rules = dataclasses.replace(DEFAULT, spread=0.0)
    w = duel_world(rules, gap=190.0)            # nothing in the way within range
    w.step(None, [Command(fire=True), Command()])
    s = w.shells[0]
    assert math.hypot(s.vx, s.vz) == pytest.approx(rules.shell_speed) and s.vy == 0.0
    y0, flown = s.y, 0
    while w.shells:
        w.step(None, IDLE2)
        flown += 1
        if w.shells:
            assert w.shells[0].y == y0           # no gravity: level flight
    assert flown * w.dt == pytest.approx(rules.shell_range / rules.shell_speed, abs=2 * w.dt)


def test_spread_throws_shots_off_the_gun_line_by_about_the_rule():
    rules = Rules(spread=math.radians(2.0), spawn_protection=0.0)
    w = duel_world(rules)
    angles = []
    for _ in range(300):
        w.tanks[0].reload = 0.0
        w.step(None, [Command(fire=True), Command()])
        s = w.shells[-1]
        angles.append(math.atan2(s.vz, s.vx))
        w.shells.clear()
    sd = statistics.pstdev(angles)
    assert 0.8 * rules.spread < sd < 1.2 * rules.spread and abs(statistics.fmean(angles)) < 0.3 * rules.spread


# ------------------------------------------------------------------ spawn protection
def test_spawn_protection_takes_no_damage_until_it_ends():
    rules = dataclasses.replace(DEFAULT, spread=0.0, spawn_protection=3.0)
    w = duel_world(rules, gap=20.0)
    a, b = w.tanks
    assert w.protection_left(1) == pytest.approx(3.0)
    a.reload = 0.0
    w.protected_until[0] = -math.inf            # the shooter's own protection is not the point here
    kinds = []
    while w.t < 1.5:
        kinds += [e.kind for e in w.step(None, [Command(fire=a.reload <= 0.0), Command()])]
    assert "shielded" in kinds and "hit" not in kinds and b.hp == b.spec.hit_points
    while w.t < 6.0:
        kinds += [e.kind for e in w.step(None, [Command(fire=a.reload <= 0.0), Command()])]
    assert "hit" in kinds and b.hp < b.spec.hit_points
    assert w.protection_left(1) == 0.0


def test_firing_ends_spawn_protection():
    w = duel_world(DEFAULT, gap=20.0)
    assert w.protection_left(0) > 2.9
    w.step(None, [Command(fire=True), Command()])
    assert w.protection_left(0) == 0.0 and w.protection_left(1) > 2.9


def test_respawn_is_protected_and_out_of_the_enemies_sight_when_possible():
    """A box with a wall hiding two of the spawn points from the shooter."""
    walls = WallList(np.array([[[60.0, 0.0], [60.0, 70.0]]]), np.ones(1, np.int8), aux_rectangle(0, 0, 120, 90))
    spawns = [(20.0, 20.0, 0.0), (30.0, 50.0, 0.0), (100.0, 20.0, 0.0), (100.0, 50.0, 0.0)]
    for seed in range(6):
        w = World(walls, [TankSpec.box("t")] * 2, spawns, seed=seed, respawn_delay=0.5)
        shooter, victim = w.tanks
        shooter.place(10.0, 60.0, 0.0)
        victim.hp, victim.alive, victim.respawn_at = 0.0, False, w.t + 0.1
        events = []
        while not victim.alive:
            events += w.step(None, IDLE2)
        assert victim.position[0] > 60.0, f"seed {seed}: respawned in the shooter's sight"
        assert w.protection_left(1) == pytest.approx(DEFAULT.spawn_protection, abs=w.dt)
        classic = World(walls, [TankSpec.box("t")] * 2, spawns, seed=seed, rules=Rules.classic())
        assert classic.protection_left(0) == 0.0


def test_first_spawns_see_each_other_as_little_as_the_arena_allows():
    walls = WallList(np.array([[[60.0, 0.0], [60.0, 70.0]]]), np.ones(1, np.int8), aux_rectangle(0, 0, 120, 90))
    spawns = [(20.0, 20.0, 0.0), (30.0, 50.0, 0.0), (100.0, 20.0, 0.0), (100.0, 50.0, 0.0)]
    for seed in range(10):
        w = World(walls, [TankSpec.box("t")] * 2, spawns, seed=seed)
        xs = sorted(t.position[0] for t in w.tanks)
        assert xs[0] < 60.0 < xs[1], f"seed {seed}: both first spawns on one side of the wall"


# ------------------------------------------------------------------ the match end
def _kill(w: World, killer: int, victim: int) -> None:
    w.tanks[killer].kills += 1
    w.tanks[victim].deaths += 1


def test_score_limit_ends_the_match_and_the_world_stops():
    walls, spawns = box_arena()
    w = World(walls, [TankSpec.box("t")] * 2, spawns, seed=1, rules=Rules(score_limit=2))
    _kill(w, 1, 0)
    w.step(None, IDLE2)
    assert not w.match.over
    _kill(w, 1, 0)
    events = w.step(None, IDLE2)
    assert w.match.over and w.match.reason == "score" and w.match.winner == 1
    assert [e.kind for e in events][-1] == "match_end" and events[-1].tank == 1
    t, steps = w.t, w.steps
    assert w.step(None, [Command(advance=1.0)] * 2) == [] and (w.t, w.steps) == (t, steps)
    s = w.match.standings(w)
    assert [(x.index, x.place) for x in s] == [(1, 1), (0, 2)]


def test_time_limit_ends_the_match_a_tie_is_a_draw():
    walls, spawns = box_arena()
    w = World(walls, [TankSpec.box("t")] * 3, spawns, seed=2, rules=Rules(time_limit=0.5))
    _kill(w, 0, 1)
    _kill(w, 2, 1)
    while not w.match.over:
        w.step(None, [Command()] * 3)
    assert w.t == pytest.approx(0.5) and w.match.reason == "time" and w.match.winner is None
    assert [s.place for s in w.match.standings(w)] == [1, 1, 3]
    assert w.match.time_left(w.t) == 0.0


def test_run_match_stops_at_the_score_limit_and_reports_it():
    arena, spec = load_match_arena("box"), load_tank_spec("light")
    r = run_match(arena, spec, bots=4, seconds=120, seed=2, score_limit=1).report
    m = r["match"]
    assert m["over"] and m["reason"] == "score" and r["seconds"] == m["ended_at"] < 120
    assert m["winner"] == r["winner"] and max(t["kills"] for t in r["tanks"]) == 1
    assert r["rules"]["score_limit"] == 1 and r["rules"]["shell_speed"] == DEFAULT.shell_speed
    assert r["events"][-1]["kind"] == "match_end" and r["events"][-1]["tank"] == m["winner"]
    assert [s["place"] for s in m["standings"]][0] == 1
    assert "match over at" in scoreboard(r) and f"{m['winner']} wins" in scoreboard(r)


def test_a_recording_keeps_its_rules_and_an_old_one_plays_back_under_the_classic_rules():
    arena, spec = load_match_arena("box"), load_tank_spec("light")
    result, tape = record_match(arena, spec, bots=3, seconds=60, seed=4, score_limit=1)
    assert tape.header["rules"]["score_limit"] == 1 and result.world.match.over
    back = play_replay(decode(encode(tape)), arena, spec)
    assert back.matches and back.result.world.match.over
    # a recording made before matches had rules: no "rules" in its header
    old, old_tape = record_match(arena, spec, bots=3, seconds=3, seed=4, rules=Rules.classic())
    del old_tape.header["rules"]
    again = play_replay(decode(encode(old_tape)), arena, spec)
    assert again.matches and again.result.world.rules == Rules.classic()


# ------------------------------------------------------------------ the command line
def test_cli_limits(tmp_path):
    run = CliRunner().invoke
    out = tmp_path / "r.json"
    res = run(cli, ["play", "--headless", "--arena", "box", "--bots", "4", "--score-limit", "1", "--seed", "2",
                    "--report", str(out)])
    assert res.exit_code == 0, res.output
    report = json.loads(out.read_text())
    assert report["match"]["over"] and report["match"]["reason"] == "score"
    assert "match over at" in res.output
    res = run(cli, ["play", "--headless", "--arena", "box", "--bots", "2", "--time-limit", "2"])
    assert res.exit_code == 0 and "time limit 2 s reached" in res.output and "240 steps" in res.output
    for bad in (["--score-limit", "0"], ["--time-limit", "-1"], ["--score-limit", "x"]):
        res = run(cli, ["play", "--headless", "--arena", "box", *bad])
        assert res.exit_code == 2 and "Traceback" not in res.output
    res = run(cli, ["play", "--headless", "--host", "127.0.0.1:0", "--score-limit", "3"])
    assert res.exit_code == 2 and "network matches" in res.output
