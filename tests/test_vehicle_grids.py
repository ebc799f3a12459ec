"""Every vehicle gets its arena (issue 25): one grid per bundled vehicle size.

``navgrid.npz`` stays the grid of the largest vehicle that fits; each smaller one gets
``navgrid.<vehicle>.npz`` (its clearance, reachable from its own spawns, recorded in
arena.toml ``[grids.<vehicle>]``), so a deck up a ramp too narrow for the heavy tank is
the light tank's: its grid has it, its spawns may be there, its agents drive up.  The
files are hashed: missing or stale, check says so and play rebuilds them."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from click.testing import CliRunner

from tanktool.cli.main import cli
from tanktool.formats.bundle import dumps_toml, read_toml
from tanktool.freshness import ensure_fresh
from tanktool.nav.navgrid import NavGrid
from tanktool.sim.agents.driving import trim
from tanktool.sim.agents.navigation import plan_path
from tanktool.sim.match import load_match_arena, load_tank_spec, make_bots, run_match
from tanktool.sim.world import World

from bot_helpers import view_of
from level_helpers import import_level

DECK = (52.0, 25.0, 4.0)       # the deck's centre (x, z, y): 4 m up, reached by the 9.2 m ramp only


@pytest.fixture(scope="module")
def bundle(tmp_path_factory):
    return import_level(tmp_path_factory.mktemp("grids"), "narrow_ramp")


def _deck(grid: NavGrid) -> int:
    """Reachable nodes of ``grid`` on the deck."""
    return int((grid.valid & grid.reachable & (grid.heights() > 3.9)).sum())


def test_each_smaller_vehicle_gets_its_own_grid_and_spawns(bundle):
    doc = read_toml(bundle / "arena.toml")
    assert doc["vehicles"]["largest"] == "heavy"
    light = doc["grids"]["light"]
    assert light["file"] == "navgrid.light.npz" and "navgrid.light.npz" in doc["derived"]
    assert 0 < light["clearance"] < doc["navgrid"]["clearance"]       # the light tank's footprint radius
    heavy_g, light_g = NavGrid.load(bundle / "navgrid.npz"), NavGrid.load(bundle / "navgrid.light.npz")
    assert _deck(heavy_g) == 0 and heavy_g.reachable.sum() > 3000     # the heavy tank's yard only
    assert _deck(light_g) > 1000                                        # the light tank's yard and deck
    info = load_match_arena(bundle)
    assert set(info.grids) == {"light"}
    assert np.array_equal(info.spawns_for("heavy"), info.spawns)
    assert len(info.spawns_for("light")) >= 2 and not np.array_equal(info.spawns_for("light")[:, :2],
                                                                      info.spawns[:, :2])


def test_a_smaller_vehicles_grid_of_the_shared_surface_is_its_grid_built_alone(bundle):
    import dataclasses

    from tanktool.formats.vehicle_grids import vehicle_grids
    from tanktool.grid_files import build_grid, open_target

    target = open_target(bundle)
    built = build_grid(target)          # the light tank's grid reseeds the heavy one's surface
    (clearance, spawns), = vehicle_grids(target.toml).values()
    own = {k: v for k, v in target.toml.items() if k != "grids"}
    alone = build_grid(dataclasses.replace(target, spawns=spawns, toml=own), clearance=clearance)
    assert built.vehicles["light"].grid.to_bytes() == alone.grid.to_bytes()
    assert (bundle / "navgrid.light.npz").read_bytes() == alone.grid.to_bytes()


def test_import_says_how_many_tanks_of_each_vehicle_fit(tmp_path, bundle):
    src = next(bundle.glob("*.obj"))
    r = CliRunner().invoke(cli, ["import-arena", str(src), "-o", str(tmp_path / "again")])
    assert r.exit_code == 0, r.output
    assert "navgrid.light.npz: clearance 3.2" in r.output
    assert "holds at once: heavy " in r.output and ", light " in r.output
    for f in ("navgrid.npz", "navgrid.light.npz"):     # the same model gives the same grids
        assert (tmp_path / "again" / f).read_bytes() == (bundle / f).read_bytes()


def test_a_light_agent_drives_up_to_the_deck_a_heavy_one_has_no_way(bundle):
    info = load_match_arena(bundle)
    light, heavy = load_tank_spec("light"), load_tank_spec("heavy")
    w = World(info.walls, [heavy], info.spawns_for(heavy), bounds=info.bounds, ground=info.ground)
    drv = make_bots(w)[0]
    t = w.tanks[0]
    drv(w, t)
    assert not plan_path(drv.bot.nav.grid, (t.x, t.z, t.y), DECK)        # no way up for the heavy tank
    own = info.spawns_for(light)
    yard = own[own[:, 3] < 0.5]                   # start in the yard, at the foot of the ramp's level
    w = World(info.walls, [light], yard, bounds=info.bounds, ground=info.ground)
    drv = make_bots(w)[0]
    t = w.tanks[0]
    drv(w, t)
    assert t.y < 0.5
    bot = drv.bot
    bot.path = plan_path(bot.nav.grid, (t.x, t.z, t.y), DECK)
    assert bot.path
    for _ in range(120 * 90):
        trim(bot.path, t.x, t.z)
        if not bot.path:
            break
        w.step(None, [bot.follow(view_of(drv, w), bot.path, speed=1.0, lookahead=4.0)])
    assert abs(t.y - 4.0) < 0.2 and t.x > 41.0, (t.x, t.z, t.y)


def test_a_match_spawns_each_vehicle_on_its_own_spawns(bundle):
    info = load_match_arena(bundle)
    light = load_tank_spec("light")
    w = run_match(info, light, bots=2, seconds=0.5, seed=1).world
    own = {tuple(np.round(s[:2], 3)) for s in info.spawns_for(light)}
    assert {tuple(np.round(s[:2], 3)) for s in w.spawns[:len(own)]} == own


def test_a_missing_or_stale_vehicle_grid_is_an_error_and_play_rebuilds_it(tmp_path, bundle):
    b = tmp_path / "b"
    shutil.copytree(bundle, b)
    want = (b / "navgrid.light.npz").read_bytes()
    (b / "navgrid.light.npz").unlink()
    r = CliRunner().invoke(cli, ["check", str(b)])
    assert r.exit_code == 1 and "B202" in r.output and "navgrid.light.npz" in r.output, r.output
    line = ensure_fresh(b)
    assert line and "navgrid.light.npz missing: rebuilt (build-navgrid" in line
    assert (b / "navgrid.light.npz").read_bytes() == want
    (b / "navgrid.light.npz").write_bytes(want[:-1] + b"x")
    r = CliRunner().invoke(cli, ["check", str(b)])
    assert r.exit_code == 1 and "B203" in r.output, r.output
    # a [grids] table gone wrong is one clear diagnostic, not a traceback
    text = (b / "arena.toml").read_text().replace('clearance = 3.229', 'clearance = "wide"')
    (b / "arena.toml").write_text(text)
    r = CliRunner().invoke(cli, ["check", str(b)])
    assert r.exit_code == 1 and "B102" in r.output and "[grids.light]" in r.output, r.output


def test_check_judges_each_vehicle_grid_with_its_own_spawns(tmp_path, bundle):
    b = tmp_path / "b"
    shutil.copytree(bundle, b)
    doc = read_toml(b / "arena.toml")
    doc["grids"]["light"]["spawns"][0] = [0.2, 0.2, 0.0, 0.0]    # in the yard's wall corner: no node there
    (b / "arena.toml").write_text(dumps_toml(doc))
    r = CliRunner().invoke(cli, ["check", str(b)])
    assert r.exit_code == 1 and "A314 error: light's spawn 0 at (0.20, 0.20) is on no node of navgrid.light.npz " \
        "where its tank fits (clearance 3.229 m)" in r.output, r.output


def test_the_judge_takes_a_vehicles_own_spawns(bundle):
    """net/judge.py judges a (re)spawn against the spawn places of the world's vehicle: a
    light tank may come back at the light tank's own spawn points, which the heavy
    tank's world does not have."""
    import math

    from tanktool.net.judge import Judge
    from tanktool.net.session import NET_RULES

    info = load_match_arena(bundle)
    worlds = {v: World(info.walls, [load_tank_spec(v)] * 2, info.spawns_for(v), bounds=info.bounds,
                       ground=info.ground, rules=NET_RULES) for v in ("light", "heavy")}
    heavy_places = Judge(worlds["heavy"]).spawn_places()
    own = [(float(x), float(z)) for x, z in info.spawns_for("light")[:, :2]
           if min(math.hypot(x - hx, z - hz) for hx, hz in heavy_places) > 5.0]
    assert own                                            # places only the light tank spawns at
    for x, z in own:
        assert Judge(worlds["light"]).near_spawn(x, z)
        assert not Judge(worlds["heavy"]).near_spawn(x, z)


def test_too_few_spawns_for_the_largest_vehicle_names_the_smaller_ones_own(tmp_path):
    from types import SimpleNamespace

    from tanktool.fleet import Fleet
    from tanktool.importer import _remark_fit

    said: list[str] = []
    result = SimpleNamespace(walls=SimpleNamespace(repairs=SimpleNamespace(remarks=lambda: [])),
                             spawns=np.zeros((2, 4)), fleet=Fleet(4.6, 8.4, 2.3, "heavy", "heavy", "heavy"),
                             too_big=[])
    _remark_fit(tmp_path / "m.obj", result, result.fleet, said.append,
                {"light": {"clearance": 3.2, "spawns": [[0.0, 0.0, 0.0, 0.0]] * 7}})
    assert said == [f"{tmp_path / 'm.obj'}: room for only 2 spawn point(s) where the largest bundled tank that "
                    f"fits (heavy) fits, at least 8.4 m apart; light has 7 of its own"]


def test_stacked_decks_are_the_light_tanks_and_get_spawns_of_their_own(tmp_path):
    # a car park: deck 1 on pillars over the ground floor, reached by a ramp that ends
    # beside the ground under it (nav/level_lift.py), deck 2 up a second ramp; the heavy
    # tank fits neither ramp's entry, the light one reaches all three levels and, with
    # the levels spread apart (arena_levels.LEVEL_SPREAD), starts on the decks too
    folder = import_level(tmp_path, "stacked_floors")
    light = NavGrid.load(folder / "navgrid.light.npz")
    assert light.levels == 3
    for lv in range(3):
        assert (light.valid[lv] & light.reachable[lv]).sum() > 1000, lv
    ys = np.array(read_toml(folder / "arena.toml")["grids"]["light"]["spawns"])[:, 3]
    assert (ys > 3.5).sum() >= 2 and (ys > 7.5).sum() >= 1
    r = CliRunner().invoke(cli, ["check", str(folder)])
    assert "0 errors" in r.output, r.output


def test_the_forts_roof_has_a_spawn_point():
    info = load_match_arena("fort")
    assert (info.spawns[:, 3] > 4.5).sum() >= 1 and (info.spawns[:4, 3] == 0.0).all()
