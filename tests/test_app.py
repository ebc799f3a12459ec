"""The window's state machine driven by synthetic events on SDL's dummy video driver:
menu, remap screen, fixed-timestep play, pause, restart, quit; and the fallback of
``tanktool play`` when there is no display."""

import pygame
import pytest
from app_helpers import goto, key, match_config, press
from click.testing import CliRunner

from tanktool.cli.main import cli
from tanktool.game.app import App, NoDisplay, display_problem, run_window
from tanktool.game.input import load_bindings


@pytest.fixture
def app(make_app):
    return make_app((480, 320), bots=2)


def test_menu_choices_and_start(app):
    assert app.state == "menu"
    assert app.menu.arena.value == "box" and app.menu.vehicle.value == "light" and app.menu.difficulty.value == "normal"
    app.frame(0.016)                       # draws the menu without error
    goto(app, "bots")
    press(app, pygame.K_RIGHT)
    assert app.menu.bots.value == 3
    goto(app, "difficulty")
    press(app, pygame.K_RIGHT)
    assert app.menu.difficulty.value == "hard"
    goto(app, "start")
    press(app, pygame.K_RETURN)
    assert app.state == "playing"
    assert len(app.session.world.tanks) == 4 and app.session.player == 0
    assert app.session.difficulty == "hard" and app.session.drivers[0] is None
    assert app.view == "top"               # no OpenGL on the dummy driver's plain window


def test_fixed_timestep_and_player_drives(app):
    goto(app, "start")
    press(app, pygame.K_RETURN)
    s = app.session
    x0, z0, h0 = s.pose(0)
    app.handle(key(pygame.K_w))
    # 0.1 s of real time is 12 steps of 1/120 s; a huge stall is capped at 0.25 s
    assert app.advance(0.1) == 12
    assert app.advance(5.0) == 30
    app.frame(1 / 60)
    assert 0.0 <= app.alpha < 1.0
    x1, z1, _ = s.pose(0)
    fx, fz = pygame.math.Vector2(x1 - x0, z1 - z0), pygame.math.Vector2(1, 0).rotate_rad(h0)
    assert fx.dot(fz) > 0.1                # it moved forwards (0.35 s from rest: ~0.2 m)
    assert abs(fx.cross(fz)) < 0.02         # and straight
    app.handle(key(pygame.K_w, down=False))


def test_pause_restart_menu_quit(app):
    goto(app, "start")
    press(app, pygame.K_RETURN)
    app.advance(0.5)
    press(app, pygame.K_p)
    assert app.state == "paused"
    assert app.advance(1.0) == 0           # time stands still
    app.frame(0.016)
    press(app, pygame.K_r)                 # restart: same match from the start
    assert app.state == "playing" and app.session.t == 0.0
    press(app, pygame.K_ESCAPE)
    assert app.state == "paused"
    press(app, pygame.K_m)
    assert app.state == "menu"
    app.handle(pygame.event.Event(pygame.QUIT))
    assert app.state == "quit"


def test_seconds_ends_a_window_match(make_app, tmp_path):
    # --seconds in the window: the match ends after that much simulated time, the end
    # screen says why over the final scoreboard (the recording, if any, is written
    # then), and Enter goes back to the menu
    rec = tmp_path / "m.ttr"
    app = make_app((480, 320), bots=1, seconds=0.5, record=rec)
    goto(app, "start")
    press(app, pygame.K_RETURN)
    taken = sum(app.advance(0.25) for _ in range(4))
    assert taken == 60                      # 0.5 s at 120 steps/s, then no more
    assert app.session.world.steps == 60
    assert app.state == "over" and "time up" in app.over_reason and "0.5 s" in app.over_reason
    assert rec.is_file() and any("60 steps" in line for line in app.saved)
    app.frame(0.016)                        # the end screen draws: reason and scoreboard
    from tanktool.game.scoreboard import final_rows

    rows = final_rows(app.session)
    assert {r["name"] for r in rows} == {"you", "bot1"} and all(r["shots"] >= r["hits"] >= 0 for r in rows)
    press(app, pygame.K_RETURN)
    assert app.state == "menu" and "time up" in app.notice
    app.frame(0.016)                        # the menu draws with the notice
    goto(app, "start")                      # a new match gets the same length
    press(app, pygame.K_RETURN)
    assert app.state == "playing" and app.session.world.steps == 0


def test_views_and_overlays_toggle(app):
    goto(app, "start")
    press(app, pygame.K_RETURN)
    press(app, pygame.K_F2)
    press(app, pygame.K_F4)
    assert app.top.overlays == {"quadtree", "agents"}
    press(app, pygame.K_v)                 # 3D is not available on a plain window
    assert app.view == "top" and "OpenGL" in app.notice
    app.frame(0.02)


def test_remap_screen_saves_and_survives_restart(app, tmp_path):
    goto(app, "bindings")
    press(app, pygame.K_RETURN)
    assert app.state == "remap"
    while app.remap.cursor != 6:           # FIRE
        press(app, pygame.K_DOWN)
    press(app, pygame.K_RETURN)
    assert app.remap.waiting
    app.frame(0.016)                       # "press the button for FIRE"
    app.handle(pygame.event.Event(pygame.JOYBUTTONDOWN, instance_id=0, joy=0, button=2))
    assert not app.remap.waiting and "FIRE" in app.notice
    assert load_bindings().actions["fire"] == ["joybutton:2"]
    press(app, pygame.K_ESCAPE)
    assert app.state == "menu"
    # a new App (a restart of the game) reads the saved bindings
    again = App(app.presenter, match_config(bots=1, size=(480, 320)))
    assert again.input.bindings.actions["fire"] == ["joybutton:2"]


def test_no_display_is_a_clear_fallback(tmp_path, monkeypatch):
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    assert display_problem() == "SDL_VIDEODRIVER=dummy"
    with pytest.raises(NoDisplay):
        run_window(match_config())
    pic = tmp_path / "m.png"
    r = CliRunner().invoke(cli, ["play", "--arena", "box", "--seconds", "1", "--picture", str(pic)])
    assert r.exit_code == 0, r.output
    assert "no display to open the game window (SDL_VIDEODRIVER=dummy)" in r.output
    assert pic.is_file()


def test_the_rules_end_a_window_match_with_the_winner(make_app):
    # a score limit of the match's rules (tanktool play --score-limit): the world says the
    # match is over and who won; the window shows the end screen with it
    from tanktool.sim.rules import DEFAULT

    app = make_app((480, 320), bots=1, rules=DEFAULT.with_limits(score_limit=1))
    goto(app, "start")
    press(app, pygame.K_RETURN)
    w = app.session.world
    assert w.rules.score_limit == 1
    w.tanks[1].kills = 1                    # bot1 scores: the next step ends the match
    app.advance(0.05)
    assert w.match.over and app.state == "over"
    assert "score limit" in app.over_reason and "bot1 wins" in app.over_reason
    app.frame(0.016)                        # the end screen draws


def test_remap_on_an_unwritable_config_folder_says_so_and_goes_on(app, tmp_path, monkeypatch):
    """The config folder cannot be made (its parent is a file; tests run as root, so a
    read-only mode would not stop the write): the new binding holds for this session,
    the failure is the screen's notice, naming the file, and the game keeps running."""
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("a file where the config folder's parent should be\n")
    monkeypatch.setenv("XDG_CONFIG_HOME", str(blocker / "cfg"))
    goto(app, "bindings")
    press(app, pygame.K_RETURN)
    while app.remap.cursor != 6:           # FIRE
        press(app, pygame.K_DOWN)
    press(app, pygame.K_RETURN)
    app.handle(pygame.event.Event(pygame.JOYBUTTONDOWN, instance_id=0, joy=0, button=3))
    assert app.state == "remap" and not app.remap.waiting
    assert app.input.bindings.actions["fire"] == ["joybutton:3"]       # in use until the game ends
    assert "not saved" in app.notice and str(blocker) in app.notice and "\n" not in app.notice, app.notice
    app.frame(0.016)                       # the remap screen draws the notice
    press(app, pygame.K_ESCAPE)
    assert app.state == "menu"
    assert blocker.read_text().startswith("a file")       # nothing written over it


def test_a_tie_at_the_top_is_a_draw_everywhere(make_app):
    """2-2 with equal deaths: the end screen names no winner and says a draw, as the
    match report does."""
    from tanktool.game.scoreboard import winner
    from tanktool.sim.match import make_report

    app = make_app((480, 320), bots=1, seconds=0.05)
    goto(app, "start")
    press(app, pygame.K_RETURN)
    w = app.session.world
    for t in w.tanks:
        t.kills, t.deaths = 2, 1
    app.advance(0.2)
    assert app.state == "over" and "a draw" in app.over_reason and "wins" not in app.over_reason
    assert winner(app.session) is None
    assert make_report(w, "box", "light", 0, [])["winner"] is None
    app.frame(0.016)                        # the end screen draws, nobody marked
    w.tanks[1].kills = 3
    assert winner(app.session) == 1


def test_view_notices_stay_over_the_match(make_app):
    """The camera/overlay notice is the match's: the menu does not show it."""
    app = make_app((480, 320), bots=1)
    goto(app, "start")
    press(app, pygame.K_RETURN)
    app.view = "3d"                        # as if in the 3D view: an overlay key says where overlays show
    press(app, pygame.K_F4)
    assert "overlays" in app.match_notice
    app.frame(0.016)
    press(app, pygame.K_ESCAPE)
    press(app, pygame.K_m)
    assert app.state == "menu" and "overlays" not in app.notice


def test_a_first_start_offers_easy_and_shows_the_controls_once(make_app):
    """No settings yet: the menu offers easy; the first match shows the controls
    overlay (gone after its seconds, back on F1); the next start remembers both."""
    from tanktool.game.controls import FIRST_S
    from tanktool.game.quality import load_settings

    app = make_app((480, 320), bots=1, difficulty=None)          # no --difficulty given
    assert app.menu.difficulty.value == "easy"
    goto(app, "difficulty")
    press(app, pygame.K_RIGHT)                # normal
    goto(app, "start")
    press(app, pygame.K_RETURN)
    assert app.help_on
    app.frame(0.016)
    saved = load_settings()
    assert saved.difficulty == "normal" and saved.controls_seen
    for _ in range(int(FIRST_S / 0.25) + 2):
        app.frame(0.25)
    assert not app.help_on                    # it went by itself
    press(app, pygame.K_F1)
    assert app.help_on
    app.frame(0.016)
    press(app, pygame.K_F1)
    assert not app.help_on
    again = make_app((480, 320), bots=1, difficulty=None)
    assert again.menu.difficulty.value == "normal"
    goto(again, "start")
    press(again, pygame.K_RETURN)
    assert not again.help_on                  # seen once: only on F1 now
