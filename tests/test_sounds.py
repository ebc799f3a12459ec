"""Game sounds follow the session: engines per tank, one-shots per event, the listener
on the followed tank."""

import math

import numpy as np
import pytest

from tanktool.audio import Sound
from tanktool.game.headless import run_frames
from tanktool.game.session import GameSession
from tanktool.game.sounds import GameAudio
from tanktool.sim.world import Event


def test_engines_events_and_listener_silent():
    s = GameSession("box", bots=3, seed=4, player=True)
    audio = GameAudio(s, Sound(device=False))
    assert len(audio.engines) == 4
    run_frames(s, 30)
    audio.on_events([Event(1, 0.1, "shot", 1, 10.0, 20.0), Event(1, 0.1, "respawn", 2, 0.0, 0.0)])
    shots = [v for v in audio.sound.voices.values() if v.name == "shot"]
    assert len(shots) == 1 and np.allclose(shots[0].position, (10.0, 1.5, 20.0))
    audio.update()
    x, z, h = s.pose(0)
    assert np.allclose(audio.sound.listener_pos, (x, 2.0, z))
    assert np.allclose(audio.sound.listener_facing, (math.cos(h), 0.0, math.sin(h)))
    # a faster tank revs higher
    t = s.world.tanks[1]
    t.vx, t.vz = t.spec.top_speed, 0.0
    audio.update()
    assert audio.sound.voices[audio.engines[1]].pitch > audio.sound.voices[audio.engines[2]].pitch
    audio.close()


def test_engines_play_on_the_dummy_device():
    snd = Sound()
    if not snd.enabled:
        pytest.skip(f"pygame.mixer unavailable: {snd.reason}")
    s = GameSession("maze", bots=2, seed=1, player=False)
    audio = GameAudio(s, snd)
    try:
        for _ in range(3):
            s.step()
            audio.update()
        assert all(snd.voices[v].channel is not None for v in audio.engines)
        s.world.tanks[0].alive = False
        audio.update()
        assert snd.voices[audio.engines[0]].gain == 0.0       # a wreck's engine is muted
    finally:
        audio.close()


def test_no_audio_device_is_one_line_and_the_game_goes_on_silent(make_app, monkeypatch, capfd):
    """The mixer cannot open a device (as on a machine without sound, where ALSA prints
    a line per device it tries): the library lines are swallowed, the game says one
    line, once a run, and plays on silent."""
    import os

    import pygame
    from app_helpers import goto, press

    def no_device(*a, **kw):
        os.write(2, b"ALSA lib confmisc.c:855:(parse_card) cannot find card '0'\n")
        raise pygame.error("ALSA: Couldn't open audio device: No such file or directory")

    monkeypatch.setattr(pygame.mixer, "get_init", lambda: None)
    monkeypatch.setattr(pygame.mixer, "init", no_device)
    app = make_app((320, 240), bots=1, sound=True)
    for _ in range(2):                                   # two matches, one line
        goto(app, "start")
        press(app, pygame.K_RETURN)
        assert app.state == "playing" and not app.audio.sound.enabled
        app.frame(0.05)
        assert app.advance(0.1) > 0                      # the match goes on
        press(app, pygame.K_ESCAPE)
        press(app, pygame.K_m)
    err = capfd.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert lines == [lines[0]] and lines[0].startswith("sound: off, no sound device (ALSA: Couldn't open")
    assert "goes on silent" in lines[0] and "ALSA lib" not in err


def test_hits_and_kills_are_layered_and_louder():
    s = GameSession("box", bots=1, seed=4, player=True)
    audio = GameAudio(s, Sound(device=False))
    audio.on_events([Event(1, 0.1, "kill", 1, 10.0, 20.0, 0)])
    kill = [v for v in audio.sound.voices.values() if not v.loop]
    assert {v.name for v in kill} == {"explosion", "shot", "impact"} and max(v.gain for v in kill) > 1.0
    assert min(v.pitch for v in kill) < 0.6                      # the deep crack under the blast
    audio.close()
