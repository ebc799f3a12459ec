"""play --bot: a bot written only from docs/bots.md (tests/data/bots/hunter.py) in a
headless match (recorded and played back without its file) and in a window match
(SDL's dummy driver); the other tanks are --difficulty agents."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pygame
import pytest
from click.testing import CliRunner

from app_helpers import goto, press
from tanktool.cli.main import cli

HERE = Path(__file__).resolve().parent
HUNTER = str(HERE / "data" / "bots" / "hunter.py") + ":Hunter"


def test_headless_match_with_a_bot_from_a_file_records_and_plays_back(tmp_path):
    rec, rep = tmp_path / "m.ttr", tmp_path / "m.json"
    bot = tmp_path / "hunter.py"
    shutil.copy(HERE / "data" / "bots" / "hunter.py", bot)
    r = CliRunner().invoke(cli, ["play", "--headless", "--bot", f"{bot}:Hunter", "--bot", "hard", "--bots", "3",
                                 "--seconds", "10", "--seed", "2", "--record", str(rec), "--report", str(rep)])
    assert r.exit_code == 0, r.output
    report = json.loads(rep.read_text())
    assert [t["name"] for t in report["tanks"]] == ["Hunter", "hard", "bot3"]
    assert report["tanks"][0]["distance"] > 1.0              # the bot drove its tank
    assert "Hunter" in report["timing"]["bots"] and "bot_errors" not in report
    bot.unlink()                          # the replay needs no bot file
    r = CliRunner().invoke(cli, ["play", "--headless", "--replay", str(rec)])
    assert r.exit_code == 0 and "bit for bit" in r.output, r.output


@pytest.mark.parametrize("args, message", [
    (["--bot", "nosuch"], "no such built-in bot"),
    (["--bot", "easy", "--bot", "hard", "--bots", "1"], "--bots 1 leaves no tank"),
    (["--bot", "easy", "--join", "127.0.0.1:9"], "computer opponents run on the host"),
])
def test_bad_bot_options_are_one_error_line(args, message):
    r = CliRunner().invoke(cli, ["play", "--headless", "--seconds", "1", *args])
    assert r.exit_code == 2 and message in r.output and "Traceback" not in r.output


def test_a_window_match_with_the_docs_bot(make_app):
    from tanktool.game.app import App, Presenter
    from tanktool.game.config import MatchConfig, Opponents, ViewConfig

    make_app()                            # the window's test setup (dummy driver, private config folder)
    cfg = MatchConfig(arena="box", opponents=Opponents(2, "easy", "agent", (HUNTER,)), seed=3,
                      view=ViewConfig("top", (320, 240), False, None), sound=False)
    app = App(Presenter((320, 240), fullscreen=False, want_gl=False), cfg)
    try:
        goto(app, "start")
        press(app, pygame.K_RETURN)
        assert app.state == "playing"
        names = app.session.world.names
        assert names[:2] == ["you", "Hunter"] and len(names) == 3
        for _ in range(8):
            app.advance(0.25)
        app.frame(0.016)
        hunter = app.session.world.tanks[1]
        assert hunter.distance > 1.0 and app.session.drivers[1].stats.calls > 0
        assert app.session.drivers[1].stats.errors == 0
        app.session.restart()                 # the pause menu's restart keeps the bot
        assert app.session.world.names[1] == "Hunter" and app.session.world.steps == 0
    finally:
        app.stop()


def test_a_network_match_hosts_the_docs_bot():
    from net_helpers import match_kw
    from tanktool.net.peer import Peer
    from tanktool.net.session import NetMatch
    from tanktool.sim.bots import BotDriver
    from tanktool.sim.match import load_match_arena, load_tank_spec

    peer = Peer.host(("127.0.0.1", 0), "host", **match_kw("box", "light"))
    try:
        match = NetMatch(peer, load_match_arena("box"), load_tank_spec("light"), seed=4, bots=2,
                         bot_specs=(HUNTER,))
        report = match.run(2.0)
    finally:
        peer.close()
    n = next(k for k, name in match.names.items() if name == "Hunter")
    driver = match.drivers[n]
    assert isinstance(driver, BotDriver) and driver.stats.calls > 0 and driver.stats.errors == 0
    assert match.world.tanks[n - 1].distance > 1.0                  # it drove
    assert {p["name"] for p in report["peers"]} >= {"host", "Hunter", "bot2"}


def test_play_hosts_bots_headless_only():
    r = CliRunner().invoke(cli, ["play", "--bot", "easy", "--host", "127.0.0.1:0", "--seconds", "1"])
    assert r.exit_code == 2 and "--headless" in r.output
