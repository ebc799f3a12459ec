"""``play --watch MODEL`` (game/watch.py): the model re-imported when its file changes
and the arena reloaded in the running (headless) window; a broken save keeps the last
good arena and says why."""

from __future__ import annotations

import time

import pygame
from app_helpers import goto, press
from click.testing import CliRunner
from level_helpers import make_levels

from tanktool.cli.main import cli
from tanktool.game.watch import ModelWatch


def write_yard(path, crates):
    """A 60 x 60 m walled yard with box crates at the given (x, z) corners (4 m square)."""
    parts = make_levels.walled_yard(60, 60)
    parts += [("wall", make_levels.box(x, z, x + 4, z + 4, 0.0, 2.5)) for x, z in crates]
    make_levels.write_obj(make_levels.join(parts), path)


def wait_for_reload(app, watcher, what):
    for _ in range(200):
        app.frame(0.016)
        watcher.wait()
        app.frame(0.016)
        if what in app.notice:
            return
        time.sleep(0.05)
    raise AssertionError(f"no {what!r}: {app.notice!r}")


def test_saving_the_model_reloads_the_arena_in_the_window(tmp_path, make_app):
    model = tmp_path / "yard.obj"
    write_yard(model, [(28, 28)])
    watcher = ModelWatch(model)
    try:
        bundle = watcher.import_now()
        app = make_app((320, 240), arena=str(bundle), bots=2, watch=watcher)
        goto(app, "start")
        press(app, pygame.K_RETURN)
        s = app.session
        for _ in range(30):
            app.frame(1 / 60)
        walls_before = len(s.info.walls)
        me = s.world.tanks[0]
        where = me.position
        crowded = s.world.tanks[1]
        cx, cz = crowded.position
        # the edit: two more crates, one right where bot1 stands
        write_yard(model, [(28, 28), (10, 45), (cx - 2, cz - 2)])
        wait_for_reload(app, watcher, "reloaded")
        new = app.session
        assert new is not s and str(new.info.path) != str(bundle)
        assert len(new.info.walls) > walls_before                      # the new crates are walls
        assert "2 of 3 tanks" in app.notice
        assert abs(new.world.tanks[0].position[0] - where[0]) < 1e-6    # you stay where you were
        assert (new.world.tanks[1].x - cx) ** 2 + (new.world.tanks[1].z - cz) ** 2 > 4.0   # bot1 moved off the crate
        assert app.state == "playing" and app.advance(0.1) > 0          # and the match goes on
        # a broken save: the error in the window, the last good arena plays on
        model.write_text("v 0 0 0\nv 1 0 0\nf 1 2 9\n")
        wait_for_reload(app, watcher, "last good arena")
        assert app.session is new and "yard.obj" in app.notice and "\n" not in app.notice
        assert app.advance(0.1) > 0
    finally:
        watcher.close()
    assert not watcher.root.exists()                                    # the scratch bundles are gone


def test_watch_needs_a_window_and_a_model(tmp_path):
    r = CliRunner().invoke(cli, ["play", "--watch", str(tmp_path / "nothing.obj")])
    assert r.exit_code == 2 and "no such model" in r.output
    model = tmp_path / "yard.obj"
    write_yard(model, [])
    r = CliRunner().invoke(cli, ["play", "--watch", str(model)])
    assert r.exit_code == 2 and "needs the game window" in r.output          # SDL's dummy driver: no display
    r = CliRunner().invoke(cli, ["play", "--watch", str(model), "--headless"])
    assert r.exit_code == 2 and "--watch" in r.output
