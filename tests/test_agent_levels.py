"""Computer agents on arenas with relief and levels, and on degenerate ones.

* the agent grid on a ground is layered: built from the walkable surface (clearance
  along its links), coarse nodes linked by walking the surface, reachable from spawns;
* paths cross levels (up the fort's ramp onto its roof) and pick the level by height;
* sight is 3D: a hill or a deck between two tanks hides them (perception and the
  agents' map of which places see which), a low wall does not hide a tank above it;
* the search goes by quadrants on every level, the target's level first;
* agents run without an error on degenerate arenas: one corridor, a catwalk in the
  air, platforms apart from each other, walls around tiny rooms with spawns inside,
  spawns with no valid node near.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from click.testing import CliRunner

from tanktool.cli.main import cli
from tanktool.formats.walls_txt import WallList
from tanktool.sim.agents.navigation import SearchPlan, agent_grid, plan_path
from tanktool.sim.agents.sight import views_for
from bot_helpers import perceiver, view_of
from tanktool.bots import Senses
from tanktool.sim.match import load_match_arena, load_tank_spec, make_bots, run_match
from tanktool.sim.world import World

from level_helpers import ROOT, import_level  # noqa: E402


@pytest.fixture(scope="module")
def fort():
    return load_match_arena(ROOT / "arenas" / "fort")


@pytest.fixture(scope="module")
def hills():
    return load_match_arena(ROOT / "arenas" / "hills")


def _world(info, n=2, seed=0, vehicle="light"):
    spec = load_tank_spec(vehicle)
    return World(info.walls, [spec] * n, info.spawns, seed=seed, bounds=info.bounds, ground=info.ground)


def test_the_fort_agent_grid_is_layered_and_reaches_the_roof(fort):
    w = _world(fort)
    g = agent_grid(w, 1.0, w.tanks[0].spec.radius + 0.5)
    lay = g.layers
    assert lay is not None and lay.levels == 2
    v = lay.valid
    assert v[1].sum() > 200 and v[0].sum() > 1000        # the roof and the yard
    assert np.array_equal(g.valid[0], v.any(axis=0))      # the projection: one level
    # links only between valid nodes, and some from level 0 up to level 1 (the ramps)
    link = lay.links()
    assert ((link[0] == 1) & v[0][..., None]).any()
    assert not (link[~v] >= 0).any()
    # heights: the roof at 5 m, the yard at 0
    h = lay.height
    assert np.allclose(h[1][v[1]], 5.0, atol=0.15)


def test_paths_cross_levels_and_pick_the_level_by_height(fort):
    w = _world(fort)
    g = agent_grid(w, 1.0, w.tanks[0].spec.radius + 0.5)
    start = (8.0, 50.0, 0.0)                 # the west yard
    up = plan_path(g, start, (70.0, 50.0, 5.0))      # on the roof over the gate passage
    down = plan_path(g, start, (70.0, 50.0, 0.0))    # in the passage under it
    assert up and down
    # the way up goes over a ramp (x 24..50, z 30..44 or 56..70), the way into the
    # passage does not need one
    on_ramp = [p for p in up if 24.0 <= p[0] <= 50.0 and (30.0 <= p[1] <= 44.0 or 56.0 <= p[1] <= 70.0)]
    assert on_ramp
    assert sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip([start[:2], *up], up)) > \
        sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip([start[:2], *down], down))


def test_a_tank_follows_the_planned_path_onto_the_roof(fort):
    """The waypoints of a layered path, driven by the agent's own follower, bring the
    tank up the ramp to level 1."""
    w = _world(fort, n=1)
    drv = make_bots(w)[0]
    t = w.tanks[0]
    drv(w, t)                                 # sets the agent up
    bot = drv.bot
    bot.path = plan_path(bot.nav.grid, (t.x, t.z, t.y), (70.0, 36.0, 5.0))
    assert bot.path
    for _ in range(120 * 60):
        if not bot.path:
            break
        from tanktool.sim.agents.driving import trim
        trim(bot.path, t.x, t.z)
        if not bot.path:
            break
        cmd = bot.follow(view_of(drv, w), bot.path, speed=1.0, lookahead=4.0)
        w.step(None, [cmd])
    assert t.level == 1 and abs(t.y - 5.0) < 0.2, (t.x, t.z, t.y, t.level)


def test_sight_is_3d_a_hill_hides_a_deck_hides(hills, fort):
    w = _world(hills)
    g = w.ground
    a, b = w.tanks
    # find two places on the hills whose 2-D line crosses no wall but a crest hides
    hidden = seen = 0
    rng = np.random.default_rng(3)
    for _ in range(400):
        (x0, z0), (x1, z1) = rng.uniform(10, 110, (2, 2))
        a.place(x0, z0, 0.0)
        w.stand(a, None)
        b.place(x1, z1, 0.0)
        w.stand(b, None)
        if w.walls.blocked(a.x, a.z, b.x, b.z) or g.locate(a.x, a.z) < 0 or g.locate(b.x, b.z) < 0:
            continue          # a rock between them (its walls), or off the surface
        if w.sees(a, b):
            seen += 1
        else:
            hidden += 1
            # the line really passes below the terrain somewhere
            ts = np.linspace(0.05, 0.95, 60)
            ea, eb = w.eye(a), w.eye(b)
            under = [g.height(a.x + t * (b.x - a.x), a.z + t * (b.z - a.z), 0) > ea + t * (eb - ea) for t in ts]
            assert any(under), ((a.x, a.z), (b.x, b.z))
    assert hidden >= 10 and seen >= 10
    # the fort: under the roof (the gate passage) and on the roof, nearly above
    w = _world(fort)
    a, b = w.tanks
    a.place(70.0, 50.0, 0.0)
    w.stand(a, 0.0)
    b.place(78.0, 40.0, 0.0)
    w.stand(b, 5.0)
    assert a.level == 0 and b.level == 1
    assert not w.sees(a, b) and not w.sees(b, a)
    assert perceiver(w, 0, Senses(math.pi, 160.0, 50.0)).look(w, a) == ()


def test_the_sight_map_sees_in_3d(hills):
    w = _world(hills)
    g = agent_grid(w, 1.0, w.tanks[0].spec.radius + 0.5)
    v = views_for(w, g)
    two_d = np.zeros_like(v.visible)
    p = v.points
    for i in range(len(p)):
        for j in range(i + 1, len(p)):
            two_d[i, j] = two_d[j, i] = not w.walls.blocked(p[i][0], p[i][1], p[j][0], p[j][1])
    # terrain hides pairs the walls alone would let see each other; never the reverse
    # by much (the voxels are a little coarser than the walls' exact test)
    assert (two_d & ~v.visible).sum() > 0.05 * two_d.sum()
    assert np.allclose(v.visible, v.visible.T)


def test_the_search_goes_on_every_level_the_estimates_first(fort):
    w = _world(fort)
    g = agent_grid(w, 1.0, w.tanks[0].spec.radius + 0.5)
    plan = SearchPlan(g, 70.0, 50.0, y=5.0)
    assert len(plan.goals[0]) == 3 and abs(plan.goals[0][2] - 5.0) < 0.2
    levels = {round(goal[2]) for goal in plan.goals}
    assert {0, 5} <= levels
    plan = SearchPlan(g, 70.0, 50.0, y=0.0)
    assert abs(plan.goals[0][2]) < 0.2


@pytest.mark.parametrize("name", ["fort", "hills"])
def test_matches_on_levels_run_and_fight(name):
    info = load_match_arena(ROOT / "arenas" / name)
    res = run_match(info, load_tank_spec("light"), bots=4, seconds=40, seed=1)
    rows = res.report["tanks"]
    assert sum(r["shots"] for r in rows) > 0 and sum(r["distance"] for r in rows) > 100
    assert all(math.isfinite(r["height"]) for r in rows)


@pytest.fixture(scope="module")
def degenerate(imported_level):
    return {name: load_match_arena(imported_level(name)) for name in ("corridor", "narrow_deck", "islands", "bridge")}


@pytest.mark.parametrize("name", ["corridor", "narrow_deck", "islands", "bridge"])
def test_agents_run_on_degenerate_arenas(degenerate, name):
    info = degenerate[name]
    for seed in range(4):
        res = run_match(info, load_tank_spec("light"), bots=min(4, len(info.spawns)), seconds=6, seed=seed)
        assert res.world.steps == 720


def _rooms_world(seed: int) -> World:
    """Walls around tiny rooms (2 m: no tank fits), each with a spawn inside, and one
    open yard: spawns with no valid node near, islands of free space."""
    seg = [[[0, 0], [60, 0]], [[60, 0], [60, 60]], [[60, 60], [0, 60]], [[0, 60], [0, 0]]]
    spawns = [[45.0, 45.0, 0.0], [15.0, 45.0, 0.0]]
    for k in range(4):
        x, z = 8.0 + 12 * k, 10.0
        seg += [[[x, z], [x + 2, z]], [[x + 2, z], [x + 2, z + 2]], [[x + 2, z + 2], [x, z + 2]], [[x, z + 2], [x, z]]]
        spawns.append([x + 1.0, z + 1.0, 0.0])
    walls = WallList(np.asarray(seg, dtype=np.float64), np.ones(len(seg), dtype=np.int8))
    spec = load_tank_spec("light")
    return World(walls, [spec] * 6, spawns, seed=seed, bounds=np.array([[0.0, 0.0], [60.0, 60.0]]))


def test_agents_with_no_valid_node_near_their_spawn():
    for seed in range(3):
        w = _rooms_world(seed)
        bots = make_bots(w)
        for _ in range(600):
            w.step(None, [b(w, t) for b, t in zip(bots, w.tanks)])
        assert all(math.isfinite(t.x) and math.isfinite(t.z) for t in w.tanks)


def test_an_agent_grid_falls_back_to_less_clearance():
    """A corridor barely wider than the tank: the agent's clearance (radius + margin)
    leaves no node, so the grid keeps less; never an empty grid by a spawn."""
    length, width = 60.0, 7.0
    seg = [[[0, 0], [length, 0]], [[length, 0], [length, width]], [[length, width], [0, width]], [[0, width], [0, 0]]]
    walls = WallList(np.asarray(seg, dtype=np.float64), np.ones(4, dtype=np.int8))
    spec = load_tank_spec("light")
    w = World(walls, [spec] * 2, [[10.0, 3.5, 0.0], [50.0, 3.5, math.pi]], seed=0,
              bounds=np.array([[0.0, 0.0], [length, width]]))
    g = agent_grid(w, 1.0, spec.radius + 0.5)
    assert g.valid.any() and g.spawn_nodes and g.clearance < spec.radius + 0.5
    assert plan_path(g, (10.0, 3.5), (50.0, 3.5))
    bots = make_bots(w)
    for _ in range(600):
        w.step(None, [b(w, t) for b, t in zip(bots, w.tanks)])


def test_play_refuses_a_vehicle_too_big_for_the_arena_and_picks_one_that_fits(tmp_path, monkeypatch):
    """An arena imported too small for the heavy tank records the largest that fits
    ([vehicles]); play refuses the heavy one by name and, with no --vehicle, takes the
    one that fits and says so."""
    out = import_level(tmp_path, "corridor")
    info = load_match_arena(out)
    assert info.vehicles.get("largest") == "light" and "heavy" in info.vehicles.get("too_big", [])
    r = CliRunner().invoke(cli, ["play", "--headless", "--arena", str(out), "--vehicle", "heavy",
                                 "--seconds", "1", "--bots", "2"])
    assert r.exit_code == 2 and "too big for arena" in r.output and "--vehicle light" in r.output, r.output
    assert "Traceback" not in r.output
    r = CliRunner().invoke(cli, ["play", "--headless", "--arena", str(out), "--seconds", "1", "--bots", "2",
                                 "--report", str(tmp_path / "r.json")])
    assert r.exit_code == 0, r.output
    import json

    assert {t["vehicle"] for t in json.loads((tmp_path / "r.json").read_text())["tanks"]} == {"light"}
    # a default vehicle too big for it gives way to the largest that fits, with a word
    from tanktool.sim import match

    monkeypatch.setattr(match, "default_vehicle", lambda: "heavy")
    said = []
    assert match.choose_vehicle(info, None, said.append) == "light"
    assert said and "playing with light" in said[0]
