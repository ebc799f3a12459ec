"""Recording the game window's match (the player's keys included) and playing it back:
headless (``--replay --headless --report`` / ``--screenshot``) and in the window."""

from __future__ import annotations

import json

import pygame
import pytest
from app_helpers import goto, key, press
from click.testing import CliRunner

from tanktool.cli.main import cli
from tanktool.sim.match import load_match_arena, load_tank_spec
from tanktool.sim.replay import play_replay, read_replay, state_digest


@pytest.fixture
def window(make_app):
    return lambda **kw: make_app(bots=2, seed=3, **kw)


def drive(app, script):
    """(keys held, frames of 1/60 s) in turn: the player's hands, as events."""
    held = set()
    for keys, frames in script:
        for k in held - set(keys):
            app.handle(key(k, down=False))
        for k in set(keys) - held:
            app.handle(key(k))
        held = set(keys)
        for _ in range(frames):
            app.frame(1 / 60)
    for k in held:
        app.handle(key(k, down=False))


SCRIPT = [((pygame.K_w,), 40), ((pygame.K_w, pygame.K_d), 25), ((pygame.K_SPACE,), 5), ((), 10),
          ((pygame.K_s, pygame.K_a, pygame.K_q), 30), ((pygame.K_SPACE, pygame.K_e), 20), ((pygame.K_w,), 21)]


def _without_timing(report):
    return {k: v for k, v in report.items() if k != "timing"}


def test_window_match_recorded_and_replayed_bit_for_bit(window, tmp_path):
    tape_path = tmp_path / "w.ttr"
    app = window(record=tape_path)
    goto(app, "start")
    press(app, pygame.K_RETURN)
    assert app.state == "playing" and app.session.recorder is not None
    drive(app, SCRIPT)
    s = app.session
    steps = s.world.steps
    assert steps == 2 * sum(f for _, f in SCRIPT)          # 1/60 s frames, 1/120 s steps
    final = repr(s.world.snapshot())
    digest = state_digest(s.world)
    report = s.report()
    app.handle(pygame.event.Event(pygame.QUIT))
    assert app.state == "quit"
    app.stop()                                               # run_window's finally: writes the file
    assert len(app.saved) == 1 and str(tape_path) in app.saved[0] and tape_path.is_file()
    tape = read_replay(tape_path)
    h = tape.header
    assert h["source"] == "window" and h["player"] == 0 and h["names"] == ["you", "bot1", "bot2"]
    assert h["steps"] == steps and h["final_state"] == digest and h["arena_ref"] == "box"
    # the player's own commands are on the tape: it advanced, turned, strafed, fired
    _, mine = tape.timeline(0)
    assert any(c.advance > 0 for c in mine) and any(c.advance < 0 for c in mine)
    assert any(c.rotate != 0 for c in mine) and any(c.strafe != 0 for c in mine) and any(c.fire for c in mine)
    assert report["tanks"][0]["shots"] >= 1 and report["tanks"][0]["distance"] > 1.0

    # headless playback (run_match with the tape driving every tank): same state, same report
    playback = play_replay(tape, load_match_arena("box"), load_tank_spec("light"))
    assert playback.matches and repr(playback.result.world.snapshot()) == final
    assert _without_timing(playback.result.report) == report

    run = CliRunner().invoke
    rep = tmp_path / "r.json"
    res = run(cli, ["play", "--replay", str(tape_path), "--headless", "--report", str(rep)])
    assert res.exit_code == 0, res.output
    assert "replay: final state matches the recording bit for bit" in res.output
    assert _without_timing(json.loads(rep.read_text())) == json.loads(json.dumps(report))

    # the last frame of --screenshot is the final state
    shot = tmp_path / "s.png"
    frames = steps // 2
    res = run(cli, ["play", "--replay", str(tape_path), "--headless", "--screenshot", str(shot), "--view", "top",
                    "--size", "320x240", "--frames", str(frames)])
    assert res.exit_code == 0, res.output
    assert f"at frame {frames} of {frames}" in res.output and shot.stat().st_size > 1000
    from tanktool.game.headless import run_frames
    from tanktool.game.replay_session import replay_session

    session = replay_session(tape)
    run_frames(session, frames)
    assert repr(session.world.snapshot()) == final


def test_restart_and_menu_each_write_the_last_match(window, tmp_path):
    tape_path = tmp_path / "w.ttr"
    app = window(record=tape_path)
    goto(app, "start")
    press(app, pygame.K_RETURN)
    drive(app, [((pygame.K_w,), 30)])
    press(app, pygame.K_p)
    press(app, pygame.K_r)                     # restart: the first match is written
    assert len(app.saved) == 1 and read_replay(tape_path).header["steps"] == 60
    assert app.session.recorder is not None and app.session.world.steps == 0
    drive(app, [((pygame.K_a,), 10)])
    press(app, pygame.K_p)
    press(app, pygame.K_m)                     # back to the menu: the second one replaces it
    assert len(app.saved) == 2
    tape = read_replay(tape_path)
    assert tape.header["steps"] == 20 and any(c.rotate < 0 for c in tape.timeline(0)[1])
    assert play_replay(tape, load_match_arena("box"), load_tank_spec("light")).matches
    press(app, pygame.K_RETURN)                # start again, quit at once: nothing to write
    app.stop()
    assert len(app.saved) == 2 and read_replay(tape_path).header["steps"] == 20


def test_replay_in_the_window(window, tmp_path):
    tape_path = tmp_path / "w.ttr"
    rec = window(record=tape_path)
    goto(rec, "start")
    press(rec, pygame.K_RETURN)
    drive(rec, SCRIPT[:3])
    final = repr(rec.session.world.snapshot())
    rec.stop()
    tape = read_replay(tape_path)
    app = window(replay=tape, replay_name="w.ttr")
    app.start_replay()
    assert app.state == "playing" and app.session.player is None and app.session.focus() == 0
    # the player's driving keys do nothing; pause stops the tape; views still toggle
    drive(app, [((pygame.K_w, pygame.K_SPACE), 20)])
    press(app, pygame.K_p)
    assert app.state == "paused" and app.advance(1.0) == 0
    press(app, pygame.K_m)                     # no menu in a replay
    assert app.state == "paused"
    press(app, pygame.K_p)
    press(app, pygame.K_F2)
    press(app, pygame.K_TAB)
    assert app.session.focus() == 1 and "bot1" in app.match_notice
    drive(app, [((), 400)])                    # past the end: it stops there
    assert app.replay_done and "bit for bit" in app.notice
    assert app.session.world.steps == tape.header["steps"] and repr(app.session.world.snapshot()) == final
    press(app, pygame.K_p)
    press(app, pygame.K_r)                     # watch again from the start
    assert app.state == "playing" and app.session.world.steps == 0 and not app.replay_done
    app.handle(pygame.event.Event(pygame.QUIT))
    assert app.state == "quit"
