"""The start menu with the mouse, the name field, the settings page and the previews
(game/menu.py, game/thumbnails.py), on SDL's dummy video driver."""

import ctypes.util
import math

import numpy as np
import pygame
import pytest
from app_helpers import goto, match_config, press

from tanktool.game.quality import load_settings


def mouse(kind, pos, button=1):
    return pygame.event.Event(kind, pos=pos, button=button, rel=(0, 0), buttons=(0, 0, 0))


def centre_of(app, item):
    i = app.menu.ITEMS.index(item)
    return dict(app.menu.hits)[i]


def test_mouse_points_clicks_and_turns(make_app):
    app = make_app((800, 450), bots=2)
    app.frame(0.016)                                  # lays out the items
    r = centre_of(app, "difficulty")
    app.handle(mouse(pygame.MOUSEMOTION, r.center))
    assert app.menu.item() == "difficulty"
    app.handle(mouse(pygame.MOUSEBUTTONDOWN, (r.right - 5, r.centery)))
    assert app.menu.difficulty.value == "hard"        # right half: on
    app.handle(mouse(pygame.MOUSEBUTTONDOWN, (r.x + 5, r.centery)))
    assert app.menu.difficulty.value == "normal"      # left half: back
    app.handle(mouse(pygame.MOUSEBUTTONDOWN, r.center, button=3))
    assert app.menu.difficulty.value == "easy"        # the right button: back
    app.handle(pygame.event.Event(pygame.MOUSEWHEEL, x=0, y=1, flipped=False))
    assert app.menu.difficulty.value == "normal"      # the wheel turns the selected choice
    app.handle(mouse(pygame.MOUSEBUTTONDOWN, centre_of(app, "start").center))
    assert app.state == "playing"                     # a click on START starts


def test_name_field_typed_and_saved(make_app):
    app = make_app((480, 320), bots=1)
    goto(app, "name")
    press(app, pygame.K_RETURN)
    assert app.menu.editing and app.menu.field == "name"
    for ch in "al ice!":                              # a space and "!" are not name characters
        press(app, pygame.K_a, uni=ch)
    app.frame(0.016)
    press(app, pygame.K_RETURN)
    assert not app.menu.editing and app.menu.name == "alice" and app.player_name == "alice"
    assert load_settings().name == "alice"            # remembered for the next start
    again = type(app)(app.presenter, match_config(bots=1, size=(480, 320)))
    assert again.player_name == "alice"


def test_settings_page_changes_quality_and_saves(make_app):
    app = make_app((640, 360), bots=1)
    goto(app, "settings")
    press(app, pygame.K_RETURN)
    assert app.state == "settings"
    app.frame(0.016)
    press(app, pygame.K_RIGHT)                        # quality: medium -> high
    assert app.settings.quality == "high" and app.quality.name == "high"
    press(app, pygame.K_DOWN)
    press(app, pygame.K_RIGHT)                        # shadows: as the preset -> off
    assert app.settings.shadows == "off" and app.quality.shadows == "off" and app.quality.name == "custom"
    saved = load_settings()
    assert saved.quality == "high" and saved.shadows == "off"
    app.frame(0.016)
    # the mouse on the settings page: "back"
    from tanktool.game.menu import SETTINGS_ITEMS

    app.handle(mouse(pygame.MOUSEBUTTONDOWN, dict(app.menu.hits)[SETTINGS_ITEMS.index("back")].center))
    assert app.state == "menu"
    # a later start reads them
    again = type(app)(app.presenter, match_config(bots=1, size=(480, 320)))
    assert again.quality.shadows == "off" and again.quality.particles == "high"


def test_broken_settings_file_is_one_error(make_app, tmp_path):
    from tanktool.errors import FormatError
    from tanktool.game.quality import settings_path

    f = settings_path()
    f.parent.mkdir(parents=True, exist_ok=True)
    f.write_text('particles = "lots"\n')
    with pytest.raises(FormatError, match=r"settings.toml: particles must be one of"):
        make_app((320, 240))


@pytest.mark.skipif(ctypes.util.find_library("EGL") is None, reason="libEGL is not installed")
def test_previews_are_rendered_and_clickable(make_app):
    app = make_app((800, 450), bots=1)
    app.frame(0.016)                                  # the first frame shows the menu at once
    app.frame(0.016)                                  # the next renders the previews
    kinds = [k for k, _ in app.menu.preview_hits]
    assert kinds == ["arenas", "vehicles"]
    rect = dict(app.menu.preview_hits)["arenas"]
    pix = pygame.surfarray.array3d(app.presenter.canvas.subsurface(rect)).astype(int)
    assert pix.std() > 15                              # a picture, not a card
    before = app.menu.arena.value
    app.handle(mouse(pygame.MOUSEBUTTONDOWN, rect.center))
    assert app.menu.arena.value != before              # a click shows the next arena
    app.frame(0.016)
    app.frame(0.016)


def test_end_screen_plays_again(make_app):
    app = make_app((480, 320), bots=1, seconds=0.25)
    goto(app, "start")
    press(app, pygame.K_RETURN)
    while app.state == "playing":
        app.advance(0.25)
    assert app.state == "over"
    app.frame(0.016)
    press(app, pygame.K_r)
    assert app.state == "playing" and app.session.world.steps == 0
    np.testing.assert_equal(len(app.session.world.tanks), 2)


def test_sound_settings_on_the_page_saved_and_heard(make_app):
    """Master, effects and music volumes and mute: on the settings page, in
    settings.toml, and applied to the playing sound at once."""
    from tanktool.game.menu import SETTINGS_ITEMS

    app = make_app((640, 360), bots=1, sound=True)
    goto(app, "start")
    press(app, pygame.K_RETURN)                       # a match with sound on the dummy device
    assert app.audio is not None
    if not app.audio.sound.enabled:   # as tests/test_audio.py: SDL in a long test process can lose its device
        pytest.skip(f"pygame.mixer unavailable: {app.audio.sound.reason}")
    assert app.audio.sound.music_volume == pytest.approx(0.8 * 0.5)     # the defaults: master 80 %, music 50 %
    press(app, pygame.K_ESCAPE)
    press(app, pygame.K_m)                            # the menu (the audio stops with the match)
    app.state = "settings"                            # reached from the menu; the page only is tested here
    for item, presses in (("master_volume", -3), ("music_volume", 2), ("effects_volume", -10)):
        app.menu.settings_cursor = SETTINGS_ITEMS.index(item)
        for _ in range(abs(presses)):
            press(app, pygame.K_RIGHT if presses > 0 else pygame.K_LEFT)
    app.frame(0.016)
    s = load_settings()
    assert (s.master_volume, s.music_volume, s.effects_volume, s.mute) == (0.5, 0.7, 0.0, False)
    assert app.settings.volumes() == pytest.approx((0.0, 0.35))
    app.menu.settings_cursor = SETTINGS_ITEMS.index("mute")
    press(app, pygame.K_RETURN)
    assert load_settings().mute and app.settings.volumes() == (0.0, 0.0)
    press(app, pygame.K_ESCAPE)
    goto(app, "start")
    press(app, pygame.K_RETURN)
    assert app.audio.sound.volume == 0.0 and app.audio.sound.music_volume == 0.0


def test_a_bot_file_of_the_users_bots_folder_is_an_opponent(make_app, tmp_path):
    """The menu lists the bot files of the user's bots folder and the examples (parsed,
    not run); the one chosen drives the first opponent; a broken one is one notice."""
    folder = tmp_path / "cfg" / "tanktool" / "bots"          # make_app's XDG_CONFIG_HOME
    folder.mkdir(parents=True)
    (folder / "circler.py").write_text(
        "from tanktool.bots import Bot, Command\n\n"
        "class Circler(Bot):\n"
        "    def act(self, view):\n"
        "        return Command(advance=1.0, rotate=0.5)\n")
    (folder / "helpers.py").write_text("def aim(x):\n    return x\n")      # no bot class: not listed
    (folder / "broken.py").write_text("class Broken(:\n")
    app = make_app((800, 450), bots=1)
    app.frame(0.016)
    goto(app, "bot_file")
    shown = [app.menu.bot_file.value]
    for _ in range(len(app.menu.bot_file.options) - 1):
        press(app, pygame.K_RIGHT)
        shown.append(app.menu.bot_file.value)
    specs = [s[0] for s in shown if s]
    assert shown[0] == ()                                         # the built-in players first
    assert specs[0] == f"{folder / 'broken.py'}" and specs[1] == f"{folder / 'circler.py'}:Circler"
    assert not any("helpers" in s for s in specs)
    assert any(s.endswith("charger.py:Charger") for s in specs)  # the examples too
    app.frame(0.016)                                              # its label is drawn
    press(app, pygame.K_RIGHT)                                    # round to the built-in players
    press(app, pygame.K_RIGHT)                                    # broken.py
    goto(app, "start")
    press(app, pygame.K_RETURN)
    assert app.state == "menu" and "broken.py" in app.notice and "syntax error" in app.notice
    goto(app, "bot_file")
    press(app, pygame.K_RIGHT)                                    # circler.py
    goto(app, "start")
    press(app, pygame.K_RETURN)
    assert app.state == "playing"
    tanks = app.session.world.tanks
    assert len(tanks) == 2 and tanks[1].name == "Circler"
    x, z = tanks[1].x, tanks[1].z
    for _ in range(60):
        app.frame(1 / 30)
    assert math.hypot(tanks[1].x - x, tanks[1].z - z) > 1.0        # the user's bot drives it
