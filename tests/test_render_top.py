"""The top view: what is drawn where, overlays, and the headless screenshot CLI."""

import math

import numpy as np
import pygame
import pytest
from click.testing import CliRunner

from tanktool.cli.main import cli
from tanktool.game.headless import run_frames, screenshot
from tanktool.game.render_top import WALL, TopView, agent_view
from tanktool.game.session import GameSession, tank_colour

SIZE = (640, 400)


@pytest.fixture(scope="module")
def box_frame():
    pygame.init()
    s = GameSession("box", bots=8, seed=1, player=False)
    run_frames(s, 30)                    # half a second: everybody still alive
    view = TopView(s, SIZE)
    surf = pygame.Surface(SIZE)
    view.draw(surf)
    return s, view, pygame.surfarray.array3d(surf).transpose(1, 0, 2)   # (h, w, 3)


def near(img, px, py, colour, r=3):
    y0, x0 = int(round(py)), int(round(px))
    patch = img[max(y0 - r, 0):y0 + r + 1, max(x0 - r, 0):x0 + r + 1].reshape(-1, 3)
    return bool((np.abs(patch.astype(int) - colour).sum(axis=1) <= 3).any())


def test_every_tank_is_drawn_in_its_colour_where_it_is(box_frame):
    s, view, img = box_frame
    assert all(t.alive for t in s.world.tanks)
    for t in s.world.tanks:
        x, z, h = s.pose(t.index)
        # a little behind the vehicle origin, away from the gun line
        px, py = view.to_px(x - 0.6 * math.cos(h), z - 0.6 * math.sin(h))
        assert near(img, px, py, tank_colour(t.index)), t.name


def test_the_walls_are_drawn(box_frame):
    s, view, img = box_frame
    segs = s.world.walls.segments
    seen = sum(near(img, *view.to_px(*((a + b) / 2)), WALL, r=2) for a, b in segs)
    assert seen >= 0.8 * len(segs)
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 20       # not blank


def test_overlays_add_quadtree_navgrid_and_agents(box_frame):
    s, view, img = box_frame
    for o in ("quadtree", "navgrid", "agents"):
        v = TopView(s, SIZE)
        v.toggle(o)
        surf = pygame.Surface(SIZE)
        v.draw(surf)
        other = pygame.surfarray.array3d(surf).transpose(1, 0, 2)
        changed = np.mean(np.any(other != img, axis=2))
        assert changed > 0.01, o
    with pytest.raises(ValueError):
        view.toggle("weather")
    info = agent_view(s.drivers[1], s.world, s.world.tanks[1])
    from tanktool.sim.agents import STATES

    assert info["state"] in STATES and info["sight"] > 0 and 0 < info["fov"] < 3.2
    scripted = GameSession("box", bots=2, seed=1, player=False, bot="scripted")
    info = agent_view(scripted.drivers[0], scripted.world, scripted.world.tanks[0])
    assert info["state"] in ("roaming", "attacking", "backing off") and info["sight"] > 0


def test_headless_top_screenshot_cli(tmp_path):
    out = tmp_path / "top.png"
    r = CliRunner().invoke(cli, ["play", "--headless", "--frames", "20", "--screenshot", str(out), "--view", "top",
                                 "--arena", "maze", "--bots", "4", "--size", "480x320"])
    assert r.exit_code == 0, r.output
    img = pygame.image.load(str(out))
    assert img.get_size() == (480, 320)
    assert [p.name for p in tmp_path.iterdir()] == ["top.png"]        # no temporary left behind


def test_headless_screenshot_with_scripted_bots(tmp_path):
    out = tmp_path / "s.png"
    r = CliRunner().invoke(cli, ["play", "--headless", "--frames", "5", "--screenshot", str(out), "--view", "top",
                                 "--arena", "box", "--bots", "3", "--size", "320x200", "--bot-driver", "scripted",
                                 "--difficulty", "easy"])
    assert r.exit_code == 0, r.output
    assert pygame.image.load(str(out)).get_size() == (320, 200)


def test_headless_screenshot_bad_input_exits_2(tmp_path):
    runner = CliRunner()
    r = runner.invoke(cli, ["play", "--headless", "--screenshot", str(tmp_path / "no" / "x.png"), "--view", "top"])
    assert r.exit_code == 2 and "does not exist" in r.output and "Traceback" not in r.output
    r = runner.invoke(cli, ["play", "--headless", "--screenshot", str(tmp_path / "x.jpg"), "--view", "top"])
    assert r.exit_code == 2 and "PNG" in r.output
    r = runner.invoke(cli, ["play", "--headless", "--frames", "3"])
    assert r.exit_code == 2 and "--screenshot" in r.output
    r = runner.invoke(cli, ["play", "--headless", "--screenshot", str(tmp_path / "x.png"), "--size", "big"])
    assert r.exit_code == 2 and "WIDTHxHEIGHT" in r.output
    r = runner.invoke(cli, ["play", "--headless", "--screenshot", str(tmp_path / "x.png"), "--view", "top",
                            "--arena", str(tmp_path / "nowhere")])
    assert r.exit_code == 2 and "nowhere" in r.output
    assert list(tmp_path.iterdir()) == []


def test_screenshot_function_reports_what_it_drew(tmp_path):
    info = screenshot(tmp_path / "s.png", view="top", frames=5, arena="paper2002", bots=3, size=(320, 240))
    assert info["view"] == "top" and len(info["tanks"]) == 3 and (tmp_path / "s.png").is_file()


def test_the_top_view_shades_a_layered_arena_by_height(tmp_path):
    """The fort: the roof (5 m) lighter than the yard (0 m), every overlay draws on a
    layered grid, each tank's height beside it."""
    from tanktool.game.render_top import HEIGHT_HIGH, HEIGHT_LOW

    pygame.init()
    s = GameSession("fort", bots=4, seed=1, player=False)
    run_frames(s, 10)
    for overlays in ((), ("quadtree", "navgrid", "agents")):
        v = TopView(s, SIZE)
        for o in overlays:
            v.toggle(o)
        surf = pygame.Surface(SIZE)
        v.draw(surf)
    v = TopView(s, SIZE)
    surf = pygame.Surface(SIZE)
    v.draw(surf)
    img = pygame.surfarray.array3d(surf).transpose(1, 0, 2).astype(int)
    roof = img[int(v.to_px(70, 36)[1]), int(v.to_px(70, 36)[0])]
    yard = img[int(v.to_px(30, 20)[1]), int(v.to_px(30, 20)[0])]
    assert np.abs(roof - HEIGHT_HIGH).sum() < np.abs(roof - HEIGHT_LOW).sum()
    assert np.abs(yard - HEIGHT_LOW).sum() < np.abs(yard - HEIGHT_HIGH).sum()
    pygame.image.save(surf, str(tmp_path / "fort-top.png"))


@pytest.mark.parametrize("name, overlay", [("navgrid.npz", "navgrid"), ("quadtree.npz", "quadtree")])
@pytest.mark.parametrize("damage", ["flip", "truncate", "garbage"])
def test_a_damaged_overlay_file_is_said_on_the_overlay_not_a_crash(tmp_path, name, overlay, damage):
    """The overlays read their file when first shown, mid-match: a damaged one (a byte
    flipped, cut short, garbage) is one line naming the file on the overlay, the game
    goes on (it was BadZipFile / zlib.error out of the window's loop)."""
    import shutil

    from tanktool.content import bundled_dir

    box = tmp_path / "box"
    shutil.copytree(bundled_dir("arenas") / "box", box)
    pygame.init()
    s = GameSession(str(box), bots=1, seed=1, player=False)
    f = box / name
    data = bytearray(f.read_bytes())
    if damage == "flip":
        data[len(data) // 2] ^= 0xFF
    elif damage == "truncate":
        del data[len(data) // 2:]
    else:
        data[:] = b"PK\x03\x04" + bytes(range(256)) * 8
    f.write_bytes(bytes(data))
    view = TopView(s, SIZE)
    view.toggle(overlay)
    surf = pygame.Surface(SIZE)
    view.draw(surf)
    view.draw(surf)                          # the layer is kept: no second read, no second error
    msg = view.problems[overlay]
    assert str(f) in msg and "\n" not in msg
