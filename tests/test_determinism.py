"""Issue 26: nothing in the simulation depends on id(), hash order or wall-clock time.
The same seed gives the same report through the CLI, through sim.match.run_match and
through a world stepped by hand, in this process and in another one with another
hash seed."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from click.testing import CliRunner

ARENA, BOTS, SECONDS, SEED = "fort", 4, 6.0, 11


def _plain(report: dict) -> dict:
    return json.loads(json.dumps({k: v for k, v in report.items() if k != "timing"}))


def _by_hand() -> dict:
    """What a user's script does: its own World and agents, stepped in its own loop."""
    from tanktool.sim.match import load_match_arena, load_tank_spec, make_bots, make_report, match_rules
    from tanktool.sim.world import World

    arena = load_match_arena(ARENA)
    spec = load_tank_spec("light")
    world = World(arena.walls, [spec] * BOTS, arena.spawns, seed=SEED, names=[f"bot{i + 1}" for i in range(BOTS)],
                  bounds=arena.bounds, ground=arena.ground, rules=match_rules())
    drivers = make_bots(world)
    events = []
    for _ in range(int(round(SECONDS / world.dt))):
        events.extend(world.step(None, [d(world, t) for d, t in zip(drivers, world.tanks)]))
        if world.match.over:
            break
    report = make_report(world, arena.name, spec.name, SEED, events)
    report["bots"], report["difficulty"] = "agent", "normal"
    return report


def test_cli_api_and_hand_stepped_world_give_the_same_report(tmp_path):
    from tanktool.cli.main import cli
    from tanktool.sim.match import load_match_arena, load_tank_spec, run_match

    out = tmp_path / "cli.json"
    res = CliRunner().invoke(cli, ["play", "--headless", "--arena", ARENA, "--vehicle", "light", "--bots", str(BOTS),
                                   "--seconds", str(SECONDS), "--seed", str(SEED), "--report", str(out), "-q"])
    assert res.exit_code == 0, res.output
    from_cli = _plain(json.loads(out.read_text()))
    api = _plain(run_match(load_match_arena(ARENA), load_tank_spec("light"), bots=BOTS, seconds=SECONDS,
                           seed=SEED).report)
    hand = _plain(_by_hand())
    assert api == from_cli
    assert {k: hand[k] for k in api if k in hand} == {k: api[k] for k in api if k in hand}
    assert hand["tanks"] == api["tanks"] and hand["events"] == api["events"]
    # another process with another hash seed: the same match
    code = ("import json, sys; sys.path.insert(0, sys.argv[1]); import test_determinism as t; "
            "print(json.dumps(t._plain(t._by_hand())))")
    env = {**os.environ, "PYTHONHASHSEED": "12345"}
    other = subprocess.run([sys.executable, "-c", code, str(Path(__file__).parent)], capture_output=True,
                           text=True, env=env, timeout=600)
    assert other.returncode == 0, other.stderr
    assert json.loads(other.stdout) == hand


def test_the_sight_cache_never_serves_another_worlds_ground(monkeypatch):
    """The views cache was keyed by id(world.ground): a later world whose ground got a
    freed ground's id was served the old world's views.  Forced here by making every
    id() the same."""
    from tanktool.sim.agents import sight
    from tanktool.sim.match import load_match_arena, load_tank_spec
    from tanktool.sim.world import World

    monkeypatch.setattr(sight, "id", lambda _obj: 7, raising=False)
    monkeypatch.setattr(sight, "_VIEWS", {})
    spec = load_tank_spec("light")
    worlds = []
    for _ in range(2):
        arena = load_match_arena(ARENA)            # a ground object of its own each time
        worlds.append(World(arena.walls, [spec] * 2, arena.spawns, seed=1, bounds=arena.bounds, ground=arena.ground))
    from tanktool.sim.agents.navigation import agent_grid

    grids = [agent_grid(w, 2.0, 2.5) for w in worlds]
    first = sight.views_for(worlds[0], grids[0])
    second = sight.views_for(worlds[1], grids[1])
    assert worlds[0].ground is not worlds[1].ground
    assert second is not first and sight.views_for(worlds[1], grids[1]) is second
