"""The input layer: synthetic keyboard, mouse and joystick events become Commands;
bindings survive a restart through the user's config folder."""

import pygame
import pytest

from tanktool.errors import FormatError
from tanktool.game.input import (
    Bindings,
    InputState,
    bindings_path,
    config_dir,
    describe,
    input_name,
    load_bindings,
    save_bindings,
)
from tanktool.sim.commands import Command


@pytest.fixture(autouse=True)
def _pygame(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "cfg"))
    pygame.init()
    yield


def key(k, down=True):
    return pygame.event.Event(pygame.KEYDOWN if down else pygame.KEYUP, key=k, mod=0, unicode="", scancode=0)


def axis(a, v, joy=0):
    return pygame.event.Event(pygame.JOYAXISMOTION, instance_id=joy, joy=joy, axis=a, value=v)


def button(b, down=True, joy=0):
    return pygame.event.Event(pygame.JOYBUTTONDOWN if down else pygame.JOYBUTTONUP, instance_id=joy, joy=joy, button=b)


def test_default_keys_make_the_right_commands():
    s = InputState()
    assert s.command() == Command()
    s.handle(key(pygame.K_w))
    assert s.command() == Command(advance=1.0)
    s.handle(key(pygame.K_d))
    s.handle(key(pygame.K_SPACE))
    assert s.command() == Command(advance=1.0, rotate=1.0, fire=True)
    s.handle(key(pygame.K_w, down=False))
    s.handle(key(pygame.K_DOWN))        # arrows work too
    s.handle(key(pygame.K_q))
    assert s.command() == Command(advance=-1.0, rotate=1.0, strafe=-1.0, fire=True)
    s.handle(key(pygame.K_e))           # both strafe keys cancel
    s.handle(key(pygame.K_LEFT))        # and both turns
    assert s.command() == Command(advance=-1.0, rotate=0.0, strafe=0.0, fire=True)
    s.release_all()
    assert s.command() == Command()


def test_joystick_axes_and_buttons_with_deadzone():
    s = InputState()
    s.handle(axis(1, -1.0))             # stick fully forward
    s.handle(axis(0, 0.1))              # inside the dead zone: nothing
    assert s.command() == Command(advance=1.0)
    s.handle(axis(0, 0.575))            # half-way past the dead zone
    assert s.command().rotate == pytest.approx(0.5)
    s.handle(button(0))
    s.handle(button(5))
    c = s.command()
    assert c.fire and c.strafe == 1.0
    s.handle(button(0, down=False))
    assert not s.command().fire


def test_joystick_unplugged_forgets_its_state():
    s = InputState()
    s.handle(axis(1, -1.0, joy=3))
    s.handle(button(0, joy=3))
    assert s.command().advance == 1.0
    s.handle(pygame.event.Event(pygame.JOYDEVICEREMOVED, instance_id=3))
    assert s.command() == Command()
    # plugging a device index that does not exist is ignored, not a crash
    s.handle(pygame.event.Event(pygame.JOYDEVICEADDED, device_index=99))
    assert s.joysticks == {}


def test_mouse_button_fires_and_menu_actions_come_back():
    s = InputState()
    s.handle(pygame.event.Event(pygame.MOUSEBUTTONDOWN, button=1, pos=(0, 0)))
    assert s.command().fire
    assert s.handle(key(pygame.K_p)) == ["pause"]
    assert s.handle(key(pygame.K_c)) == ["camera"]
    assert s.handle(key(pygame.K_F3)) == ["overlay_navgrid"]
    assert s.handle(key(pygame.K_F1)) == ["help"]
    assert s.handle(key(pygame.K_w)) == []


def test_input_names_for_the_remap_screen():
    assert input_name(key(pygame.K_SPACE)) == "key:space"
    assert input_name(button(3)) == "joybutton:3"
    assert input_name(axis(2, 0.9)) == "joyaxis:2+"
    assert input_name(axis(2, 0.2)) is None          # a drifting stick is not a choice
    assert describe(["key:space", "joyaxis:1-"]) == "SPACE, axis 1-"


def test_remapped_bindings_survive_a_restart(tmp_path):
    assert config_dir() == tmp_path / "cfg" / "tanktool"
    assert load_bindings().actions["fire"] == ["key:space", "joybutton:0", "mouse:1"]   # no file: defaults
    b = load_bindings()
    b.remap("fire", "key:f")
    b.remap("advance", "joybutton:2")
    b.remap("reverse", "key:w")         # taken from nowhere: w was advance's, now reverse's only
    path = save_bindings(b)
    assert path == bindings_path() and path.is_file()
    # "restart": a fresh process state reads the file back
    s = InputState(load_bindings())
    assert s.bindings.actions["fire"] == ["key:f"]
    s.handle(key(pygame.K_f))
    s.handle(key(pygame.K_w))
    assert s.command() == Command(advance=-1.0, fire=True)
    s.handle(key(pygame.K_SPACE))       # space no longer fires
    s.handle(key(pygame.K_f, down=False))
    assert not s.command().fire
    s.handle(button(2))
    assert s.command().advance == 0.0   # advance (button 2) and reverse (w) cancel


def test_bad_bindings_file_names_the_file_and_key(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text('[actions]\nfire = ["banana"]\n')
    with pytest.raises(FormatError, match=r"b\.toml: \[actions\] fire"):
        load_bindings(p)
    p.write_text('[actions]\nfly = ["key:f"]\n')
    with pytest.raises(FormatError, match="fly: unknown action"):
        load_bindings(p)
    p.write_text('deadzone = 2\n')
    with pytest.raises(FormatError, match="deadzone"):
        load_bindings(p)
    p.write_text('[actions\n')
    with pytest.raises(FormatError, match="invalid TOML"):
        load_bindings(p)


def test_bindings_roundtrip_keeps_every_action():
    b = Bindings()
    save_bindings(b)
    assert load_bindings().to_dict() == b.to_dict()


def test_mouse_motion_turns_when_bound_and_stops_with_the_frame():
    b = Bindings()
    b.remap("turn_right", "mouse:x+")
    b.remap("turn_left", "mouse:x-")
    s = InputState(b)
    move = lambda dx, dy=0: pygame.event.Event(pygame.MOUSEMOTION, rel=(dx, dy), pos=(0, 0), buttons=(0, 0, 0))
    s.handle(move(6))
    s.handle(move(6))
    assert s.command().rotate == pytest.approx(0.5)        # 12 px of 24 px for full strength
    s.handle(move(-100))
    assert s.command().rotate == -1.0
    s.end_frame()                                          # the mouse stopped: so does the turn
    assert s.command().rotate == 0.0
    assert input_name(move(3)) is None                     # a nudge is not a remap choice
    assert input_name(move(-60, 5)) == "mouse:x-"
    assert input_name(move(2, 50)) == "mouse:y+"
    assert describe(["mouse:x+"]) == "mouse x+"
